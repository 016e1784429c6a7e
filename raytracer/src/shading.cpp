#include "shading.hpp"

namespace sh::rt {

Surface surface_at(const SceneTables& s, const Point3f& o, const Vector3f& d, const Attrib1f& t,
                   const Attrib1i& tri, const Attrib2f& uv, const Features& f) {
  Surface out;
  out.p = o + d * t;
  Attrib1f w = 1.0f - uv(0) - uv(1);
  Attrib3f n = w * s.normals[3 * tri] + uv(0) * s.normals[3 * tri + 1] + uv(1) * s.normals[3 * tri + 2];
  out.n = faceforward(normalize(n), -d);
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
  out.eta = cond(entering, 1.0f / b(3), b(3));
  return out;
}

Point3f lift(const SceneTables& s, const Surface& x, float side) {
  Attrib1f offset = max(s.surface_offset, max_component(abs(x.p)) * 1e-6f);
  return x.p + x.n * (side * offset);
}

Vector3f refract_or_mirror(const Vector3f& d, const Normal3f& n, const Attrib1f& eta, Attrib1f& mirrored) {
  Vector3f through = refract(d, n, eta);
  mirrored = dot(through, through) == 0.0f;
  return cond(mirrored, reflect(-d, n), normalize(through));
}

Continuation go_on(const SceneTables& s, const Surface& x, const Vector3f& d, const Features& f) {
  Continuation c{lift(s, x), reflect(-d, x.n), x.reflectivity};
  if (f.refractions) {
    Attrib1f mirrored;
    Vector3f onward = refract_or_mirror(d, x.n, x.eta, mirrored);
    Attrib1f transmits = x.transparency > 0.0f;
    c.share = cond(transmits, x.transparency, c.share);
    c.d = cond(transmits, onward, c.d);
    c.o = cond(transmits && !mirrored, lift(s, x, -1.0f), c.o);
  }
  return c;
}

}  // namespace sh::rt
