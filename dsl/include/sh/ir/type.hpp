#pragma once
// Value types of the IR: a scalar kind and a width of 1 to 4 components, and
// the swizzles that select or permute components of a register.
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>

namespace sh::ir {

enum class Scalar : std::uint8_t { F32, F64, I32, Bool };

const char* scalar_name(Scalar s);
inline bool is_float(Scalar s) { return s == Scalar::F32 || s == Scalar::F64; }
// Bytes one component takes in a channel, table or uniform buffer.  Bools are
// stored as int32 0/1 so that every target (OpenCL included) can hold them.
inline int storage_bytes(Scalar s) { return s == Scalar::F64 ? 8 : 4; }

struct Type {
  Scalar scalar = Scalar::F32;
  int width = 1;

  friend bool operator==(const Type&, const Type&) = default;
};

// The bytes one element of type t takes, as stored.
inline std::size_t element_bytes(Type t) { return static_cast<std::size_t>(t.width) * storage_bytes(t.scalar); }

std::string type_name(Type t);  // "f32x3", "i32", "bool"

// An ordered list of 1..4 component indices.  As a read it selects
// components (v(2,1,0)); as a write mask it names the components written, in
// the order the operation's result components land in them.
struct Swizzle {
  int size = 0;
  std::array<std::uint8_t, 4> index{0, 0, 0, 0};

  static Swizzle identity(int width);
  bool is_identity(int width) const;
  std::uint8_t operator[](int i) const { return index[i]; }
  bool has_repeats() const;
  // The components it names, bit c for component c (the analyses' sets).
  std::uint8_t bits() const;

  // Only the first `size` indices mean anything.
  friend bool operator==(const Swizzle& a, const Swizzle& b) {
    if (a.size != b.size) return false;
    for (int i = 0; i < a.size; ++i)
      if (a.index[i] != b.index[i]) return false;
    return true;
  }
};

}  // namespace sh::ir
