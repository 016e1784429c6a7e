#pragma once
// The solid angle a triangle subtends from a point: the share of a point
// light's energy an element receives in the light pass of bidirectional
// ray tracing (each of n rays to the element carries E·s/n).  The seed's
// spherical excess a + b + c - pi subtracts pi from a sum close to pi and
// loses every digit for small or grazing elements.  This is the
// tangent-half-angle form
//   tan(s/2) = |a.(b x c)| / (|a||b||c| + (a.b)|c| + (a.c)|b| + (b.c)|a|)
// with the triple product taken from the triangle's edges, a.(e1 x e2)
// (the same number: a.(a x e) = 0), which no longer cancels however small
// or far the triangle is.
#include <sh/dsl.hpp>

namespace sh::rt {

// a: from the point to the triangle's first vertex; e1, e2: the edges from
// that vertex to the other two.  0 for a degenerate triangle or one seen
// exactly edge-on; up to 2 pi for a triangle seen from just above it.
Attrib1f solid_angle(const Attrib3f& a, const Attrib3f& e1, const Attrib3f& e2);

}  // namespace sh::rt
