#include "shading.hpp"

#include "sh/raytracer/walk_bounds.hpp"

namespace sh::rt {

Surface surface_at(const SceneTables& s, const Vector3f& d, const Attrib1i& tri, const Attrib2f& uv,
                   const Features& f) {
  Surface out;
  Attrib1f w = 1.0f - uv(0) - uv(1);
  Attrib3f v0 = s.v0[tri], v1 = s.v1[tri], v2 = s.v2[tri];
  Attrib3f p0 = w * v0, p1 = uv(0) * v1, p2 = uv(1) * v2;
  out.p = p0 + p1 + p2;
  // The error of p is within gamma(7) of the terms' sizes (the barycentric
  // interpolation's bound); adding the offset rounds by at most an ulp of
  // p's largest coordinate more.
  Attrib3f error = gamma(7) * (abs(p0) + abs(p1) + abs(p2));
  out.ng = normalize(cross(v1 - v0, v2 - v0));
  out.clearance = dot(abs(out.ng), error) + max_component(abs(out.p)) * 0x1p-22f;
  Attrib3f n = w * s.normals[3 * tri] + uv(0) * s.normals[3 * tri + 1] + uv(1) * s.normals[3 * tri + 2];
  out.n = faceforward(-d, normalize(n));
  Attrib1f entering = dot(n, d) < 0.0f;
  Attrib1i m = 2 * s.material[tri];
  Attrib4f a = s.materials[m], b = s.materials[m + 1];
  out.diffuse = a(0, 1, 2);
  if (f.vertex_colors) {
    Color3f c = w * s.colors[3 * tri] + uv(0) * s.colors[3 * tri + 1] + uv(1) * s.colors[3 * tri + 2];
    out.diffuse = cond(s.use_vertex_colors, out.diffuse * c, out.diffuse);
  }
  out.specular = a(3);
  out.shininess = b(0);
  out.reflectivity = b(1);
  out.transparency = b(2);
  out.eta = cond(entering, b(3), 1.0f / b(3));
  return out;
}

Point3f leave(const Surface& x, const Vector3f& dir) {
  Attrib1f side = cond(dot(x.ng, dir) < 0.0f, ConstAttrib1f(-1.0f), ConstAttrib1f(1.0f));
  return x.p + x.ng * (side * x.clearance);
}

Vector3f refract_or_mirror(const Vector3f& d, const Normal3f& n, const Attrib1f& eta, Attrib1f& mirrored) {
  Vector3f through = refract(-d, n, eta);
  mirrored = dot(through, through) == 0.0f;
  return cond(mirrored, reflect(-d, n), normalize(through));
}

Vector3f mirror(const Vector3f& a, const Normal3f& unit_n) { return 2.0f * dot(a, unit_n) * unit_n - a; }

Continuation go_on(const Surface& x, const Vector3f& d, const Features& f) {
  Vector3f mirrored_d = mirror(-d, x.n);
  Continuation c{leave(x, mirrored_d), mirrored_d, x.reflectivity};
  if (f.refractions) {
    Attrib1f mirrored;
    Vector3f onward = refract_or_mirror(d, x.n, x.eta, mirrored);
    Attrib1f transmits = x.transparency > 0.0f;
    c.share = cond(transmits, x.transparency, c.share);
    c.d = cond(transmits, onward, c.d);
    c.o = cond(transmits, leave(x, onward), c.o);
  }
  return c;
}

}  // namespace sh::rt
