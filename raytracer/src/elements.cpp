#include "elements.hpp"

namespace sh::rt {

// Points a hair outside the triangle (rounding) fall in the nearest cell;
// past the diagonal of the last cell of a row they count as its up
// element.
ElementAt element_at(const Attrib2f& uv, const Attrib1f& k) {
  Attrib2f a = uv * k;
  Attrib1f i = clamp(floor(a(0)), 0.0f, k - 1.0f);
  Attrib1f j = clamp(floor(a(1)), 0.0f, k - 1.0f - i);
  Attrib1f fa = a(0) - i, fb = a(1) - j;
  Attrib1f down = fa + fb > 1.0f && i + j < k - 1.0f;
  Attrib1f row = k + 1.0f;
  Attrib1f here = j * row + i;
  Attrib3f up_corners = join(join(here, here + 1.0f), here + row);
  Attrib3f down_corners = join(join(here + row + 1.0f, here + row), here + 1.0f);
  Attrib3f up_weights = join(join(1.0f - fa - fb, fa), fb);
  Attrib3f down_weights = join(join(fa + fb - 1.0f, 1.0f - fa), 1.0f - fb);
  ElementAt e;
  e.slot = (2.0f * (j * k + i) + down).cast<std::int32_t>();
  e.corners = cond(down, down_corners, up_corners).cast<std::int32_t>();
  e.weights = cond(down, down_weights, up_weights);
  return e;
}

Attrib1i side_met(const Vector3f& ng, const Vector3f& d) {
  return (dot(ng, d) > 0.0f).cast<std::int32_t>();
}

}  // namespace sh::rt
