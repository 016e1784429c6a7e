#pragma once
// Elements of triangles (bidirectional.hpp) inside kernels: which element
// a hit falls in, and the lattice points around it, for the light pass to
// leave energy on and the view pass to interpolate vertex luminance.
#include <sh/dsl.hpp>

namespace sh::rt {

struct ElementAt {
  Attrib1i slot;      // the element's slot in its triangle
  Attrib3i corners;   // its lattice slots
  Attrib3f weights;   // of the corners at the point
};

// uv: barycentrics along e1 and e2; k: the subdivision.
ElementAt element_at(const Attrib2f& uv, const Attrib1f& k);

// The side (bidirectional.hpp) a ray going along d meets of a triangle
// whose geometric normal is ng: the back where it goes the way ng points.
Attrib1i side_met(const Vector3f& ng, const Vector3f& d);

}  // namespace sh::rt
