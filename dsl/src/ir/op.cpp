#include "sh/ir/op.hpp"

#include <cstring>

namespace sh::ir {

const char* domain_name(Domain d) {
  switch (d) {
    case Domain::Any: return "any scalar";
    case Domain::Numeric: return "numbers (f32, f64, i32)";
    case Domain::Float: return "floats (f32, f64)";
    case Domain::Integer: return "integers (i32)";
  }
  return "?";
}

bool op_named(const char* name, Op& out) {
  for (int i = 0; i < kOpCount; ++i)
    if (std::strcmp(op_name(op_at(i)), name) == 0) {
      out = op_at(i);
      return true;
    }
  return false;
}

}  // namespace sh::ir
