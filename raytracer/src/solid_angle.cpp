#include "sh/raytracer/solid_angle.hpp"

namespace sh::rt {

// The formula is the same for the triangle scaled about the point: scaled
// so that its farthest corner lies at distance one, its cubes of distances
// cannot overflow (scenes 1e13 across did).
Attrib1f solid_angle(const Attrib3f& a_far, const Attrib3f& e1_far, const Attrib3f& e2_far) {
  Attrib1f la_far = length(a_far), lb_far = length(a_far + e1_far), lc_far = length(a_far + e2_far);
  Attrib1f scale = 1.0f / max(max(la_far, lb_far), max(lc_far, 1e-30f));
  Attrib3f a = a_far * scale, e1 = e1_far * scale, e2 = e2_far * scale;
  Attrib3f b = a + e1, c = a + e2;
  Attrib1f la = la_far * scale, lb = lb_far * scale, lc = lc_far * scale;
  Attrib1f triple = abs(dot(a, cross(e1, e2)));
  Attrib1f across = la * lb * lc + dot(a, b) * lc + dot(a, c) * lb + dot(b, c) * la;
  return 2.0f * atan2(triple, across);
}

}  // namespace sh::rt
