#include "sh/ir/type.hpp"

namespace sh::ir {

const char* scalar_name(Scalar s) {
  switch (s) {
    case Scalar::F32: return "f32";
    case Scalar::F64: return "f64";
    case Scalar::I32: return "i32";
    case Scalar::Bool: return "bool";
  }
  return "?";
}

std::string type_name(Type t) {
  std::string name = scalar_name(t.scalar);
  if (t.width != 1) name += "x" + std::to_string(t.width);
  return name;
}

Swizzle Swizzle::identity(int width) {
  Swizzle s;
  s.size = width;
  for (int i = 0; i < width; ++i) s.index[i] = static_cast<std::uint8_t>(i);
  return s;
}

bool Swizzle::is_identity(int width) const {
  if (size != width) return false;
  for (int i = 0; i < size; ++i)
    if (index[i] != i) return false;
  return true;
}

std::uint8_t Swizzle::bits() const {
  std::uint8_t b = 0;
  for (int i = 0; i < size; ++i) b = static_cast<std::uint8_t>(b | 1u << index[i]);
  return b;
}

bool Swizzle::has_repeats() const {
  for (int i = 0; i < size; ++i)
    for (int j = i + 1; j < size; ++j)
      if (index[i] == index[j]) return true;
  return false;
}

}  // namespace sh::ir
