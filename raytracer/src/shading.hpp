#pragma once
// What the tracer and the light pass share about a surface a ray has hit:
// its point, normal and material, where rays leave it, and where a path
// goes on from a mirror or through glass.  Recorded into whichever kernel
// calls them.
#include "sh/raytracer/kernels.hpp"

namespace sh::rt {

struct Surface {
  Point3f p;         // from the barycentrics: closer to the plane than o + t d
  Normal3f n;        // shading normal, facing the incoming ray
  Normal3f ng;       // geometric normal (unit)
  Attrib1f clearance;  // along ng, beyond the rounding error of p
  Color3f diffuse;   // material times vertex colour
  Attrib1f specular, shininess, reflectivity, transparency;
  Attrib1f eta;      // index entered over index left (Sh's refract): ior on the way in, 1/ior on the way out
  // The share of arriving light that is shaded (neither mirrored nor
  // transmitted).
  Attrib1f shaded() const { return 1.0f - reflectivity - transparency; }
};

// The surface a ray going along d met at barycentrics uv of triangle tri.
Surface surface_at(const SceneTables& s, const Vector3f& d, const Attrib1i& tri, const Attrib2f& uv,
                   const Features& f);

// Where a ray going along `dir` leaves the surface: the hit point pushed
// along the geometric normal, to the side `dir` goes, by its clearance.
// The point is then strictly on that side of the triangle's plane, so the
// ray cannot meet its own triangle again, at any distance from the origin.
Point3f leave(const Surface& x, const Vector3f& dir);

// Where a path goes on from a surface that mirrors or transmits, and with
// what share of its light: through it (refracted) where it is transparent
// and the ray is inside the critical angle, else mirrored.  One way only: a
// surface that both mirrors and transmits goes on through.
struct Continuation {
  Point3f o;
  Vector3f d;
  Attrib1f share;
};
Continuation go_on(const Surface& x, const Vector3f& d, const Features& f);

// `a` mirrored about a unit normal: the library's reflect less its
// normalize, which a shading normal (unit already) does not need at every
// light and bounce.
Vector3f mirror(const Vector3f& a, const Normal3f& unit_n);

}  // namespace sh::rt
