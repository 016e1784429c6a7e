#pragma once
// Local arrays: memory of an element's own, a fixed number of values it
// writes and reads back while it runs (a tree walk's stack of nodes still
// to visit).  The array is all zero where it is declared; nothing of it
// outlives the element.  An index outside [0, length) reads or writes the
// nearest end, as a table read clamps to its edge.
//
//   sh::LocalArray<sh::Attrib1i> stack(32);
//   stack.store(depth, node);
//   node = stack[depth - 1];
//
// On SIMD lanes an array that every lane writes alike (same index, same
// value) is one array for all of them, and reading it is one load.
#include <string>

#include "sh/attrib.hpp"

namespace sh {

template <class E>
class LocalArray {
 public:
  using element_type = E;

  // Only inside a program.  Every element is zero from here on, also where
  // the declaration runs again (in a loop).
  explicit LocalArray(int length, const std::string& name = "")
      : array_(detail::declare_array(E::ir_type(), length)), length_(length) {
    if (!name.empty()) detail::set_name(array_, name);
    detail::array_fill(array_, detail::constant(E::ir_type().scalar, 0));
  }

  int length() const { return length_; }

  template <class I>
  E operator[](const I& index) const {
    return E(detail::FromValue{}, detail::array_element(array_, detail::value_or_constant(index, ir::Scalar::I32)));
  }

  template <class I, class V>
  void store(const I& index, const V& value) const {
    detail::array_store(array_, detail::value_or_constant(index, ir::Scalar::I32),
                        detail::value_or_constant(value, E::ir_type().scalar));
  }

 private:
  detail::Value array_;
  int length_;
};

}  // namespace sh
