#include "sh/raytracer/solid_angle.hpp"

namespace sh::rt {

Attrib1f solid_angle(const Attrib3f& a, const Attrib3f& e1, const Attrib3f& e2) {
  Attrib3f b = a + e1, c = a + e2;
  Attrib1f la = length(a), lb = length(b), lc = length(c);
  Attrib1f triple = abs(dot(a, cross(e1, e2)));
  Attrib1f across = la * lb * lc + dot(a, b) * lc + dot(a, c) * lb + dot(b, c) * la;
  return 2.0f * atan2(triple, across);
}

}  // namespace sh::rt
