#pragma once
// What the tracer and the light pass share about a surface a ray has hit:
// its point, normal and material, where rays leave it, and where a path
// goes on from a mirror or through glass.  Recorded into whichever kernel
// calls them.
#include "sh/raytracer/kernels.hpp"

namespace sh::rt {

struct Surface {
  Point3f p;
  Normal3f n;        // faces the incoming ray
  Color3f diffuse;   // material times vertex colour
  Attrib1f specular, shininess, reflectivity, transparency;
  Attrib1f eta;      // index of refraction it is entered with: 1/ior on the way in, ior on the way out
  // The share of arriving light that is shaded (neither mirrored nor
  // transmitted).
  Attrib1f shaded() const { return 1.0f - reflectivity - transparency; }
};

Surface surface_at(const SceneTables& s, const Point3f& o, const Vector3f& d, const Attrib1f& t,
                   const Attrib1i& tri, const Attrib2f& uv, const Features& f);

// Where rays leave a surface: pushed along the normal (side 1, towards the
// ray that came; -1, through), by at least a few ulps of the point's
// coordinates so that scenes far from the origin do not shadow themselves.
Point3f lift(const SceneTables& s, const Surface& x, float side = 1.0f);

// Where a path goes on from a surface that mirrors or transmits, and with
// what share of its light: through it (refracted) where it is transparent
// and the ray is inside the critical angle, else mirrored.  One way only: a
// surface that both mirrors and transmits goes on through.
struct Continuation {
  Point3f o;
  Vector3f d;
  Attrib1f share;
};
Continuation go_on(const SceneTables& s, const Surface& x, const Vector3f& d, const Features& f);

}  // namespace sh::rt
