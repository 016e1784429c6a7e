#include "sh/print.hpp"

#include "sh/passes.hpp"

namespace sh {

std::string print(const Program& p) { return ir::print(p.ir()); }

std::string print_optimized(const Program& p, ir::Precision precision) {
  return ir::print(optimize(p.ir(), precision));
}

}  // namespace sh
