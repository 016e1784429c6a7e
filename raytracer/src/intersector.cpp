// The intersector of the seed: enter the accelerator's box, walk its cells
// front to back, test each cell's triangles, and accept a hit only inside
// the current cell (a nearer hit in a later cell cannot exist then).
#include "sh/error.hpp"
#include "walk.hpp"

namespace sh::rt {
namespace walk {
namespace {

// The lesser and the greater as a compare and a choice: the machine's own
// minimum and maximum (one instruction), where the language's min and max
// must give the other operand for a NaN (three more each).  What they
// compare here is never NaN, or decides nothing where it is: a box's
// distances (its corners and the ray's origin are finite, the reciprocal
// direction capped: Ray), the sizes of finite coordinates, and the
// barycentrics of a hit whose distance, NaN with them, fails every test.
template <int N>
Attrib<N, float> lesser(const Attrib<N, float>& a, const Attrib<N, float>& b) {
  return cond(a < b, a, b);
}
template <int N>
Attrib<N, float> greater(const Attrib<N, float>& a, const Attrib<N, float>& b) {
  return cond(a > b, a, b);
}
Attrib1f greatest(const Attrib3f& v) { return greater(greater(v(0), v(1)), v(2)); }

// A vertex in the ray's space: translated to the origin, turned, sheared.
// Each vertex is carried there on its own, so the triangles that share a
// vertex or an edge see it at exactly the same place.
Attrib3f to_ray_space(const Ray& r, const Attrib3f& vertex) {
  Attrib3f p = r.turn(vertex - r.o);
  return join(p(0, 1) + r.shear(0, 1) * p(2), r.shear(2) * p(2));
}

// Twice the signed area of (origin, p, q) in the ray's xy plane: two
// products and a difference in float.  Its sign is right wherever |e|
// exceeds the rounding of those operations, which edge_rounding() bounds
// whether or not fast math contracted them into an FMA (one product exact,
// the other rounded: then the edge's other triangle does not get exactly
// the negation, and a ray along the edge could slip between them).
Attrib1f edge_function(const Attrib3f& p, const Attrib3f& q) { return p(0) * q(1) - p(1) * q(0); }

// At most two roundings of 2^-24 relative to the products and one of the
// difference, with room for the rounding of this bound itself: 2^-21.
Attrib1f edge_rounding(const Attrib3f& p, const Attrib3f& q) {
  return (abs(p(0) * q(1)) + abs(p(1) * q(0))) * 0x1p-21f;
}

// The same in double: products of floats are exact there, so the
// difference is the one rounding, its sign is exact, and the edge's other
// triangle gets exactly its negation, contracted or not.
Attrib1f exact_edge_function(const Attrib3f& p, const Attrib3f& q) {
  Attrib2d a = p(0, 1).cast<double>(), b = q(0, 1).cast<double>();
  return (a(0) * b(1) - a(1) * b(0)).cast<float>();
}

// The distance t from the barycentrics (u, v, w) / det, each before its
// product with a coordinate, so that nothing overflows where an edge
// function times a coordinate would (coordinates near 1e13 and beyond).
Attrib1f distance(const Attrib3f& a, const Attrib3f& b, const Attrib3f& c, const Attrib3f& barycentrics) {
  return barycentrics(0) * a(2) + barycentrics(1) * b(2) + barycentrics(2) * c(2);
}

// How far distance() may be from the exact distance, given the errors of
// the ray-space coordinates and edge functions: a hit nearer than this may
// lie behind the origin (a ray leaving a surface, or starting on one, must
// not meet it there).  Four roundings deep in each term (the barycentric,
// its product, two sums); the edge functions' sizes are taken over det
// (as barycentrics) first, for the same reason as in distance().
Attrib1f distance_error(const Attrib3f& a, const Attrib3f& b, const Attrib3f& c, const Attrib3f& barycentrics,
                        const Attrib1f& inv_det) {
  Attrib3f largest = greater(greater(abs(a), abs(b)), abs(c));
  Attrib1f x = largest(0), y = largest(1), z = largest(2);
  Attrib1f dz = gamma(3) * z, dx = gamma(5) * (x + z), dy = gamma(5) * (y + z);
  Attrib1f de = 2.0f * (gamma(2) * x * y + dy * x + dx * y);
  Attrib1f e = greatest(abs(barycentrics));
  return 3.0f * (gamma(4) * e * z + de * abs(inv_det) * z + dz * e);
}

// Whether a hit the bound above could not place lies in front of the
// origin, from the triangle's plane: t = n.(v0 - o) / n.d, n = e1 x e2,
// whose numerator and denominator each have a sign beyond their rounding
// (at most 16 roundings deep, of the terms' sizes), and agree.  The bound
// above grows as the square of the distance along the ray over the
// triangle's size, so it turns away small triangles far along the ray and
// large ones near its origin; the plane's terms stay the size of the
// distance to the plane.  The edges are scaled by the first one's size
// first (signs do not change), so that their products with v0 - o cannot
// overflow.  A ray leaving a surface is pushed off it to the
// side it goes, so its own triangle's plane lies behind it: n.(v0 - o)
// and n.d differ in sign there.
Attrib1f in_front_of_plane(const Ray& r, const Attrib3f& v0, const Attrib3f& v1, const Attrib3f& v2) {
  Attrib3f e1_far = v1 - v0, e2_far = v2 - v0, p = v0 - r.o;
  Attrib1f edge_scale = 1.0f / greater(greatest(abs(e1_far)), Attrib1f(ConstAttrib1f(1e-30f)));
  Attrib3f e1 = e1_far * edge_scale, e2 = e2_far * edge_scale;
  Attrib3f n = cross(e1, e2);
  Attrib3f size = abs(e1(1, 2, 0) * e2(2, 0, 1)) + abs(e1(2, 0, 1) * e2(1, 2, 0));  // of each component's terms
  Attrib1f num = dot(n, p), den = dot(n, r.d);
  Attrib1f sure_num = abs(num) > gamma(16) * dot(size, abs(p)), sure_den = abs(den) > gamma(16) * dot(size, abs(r.d));
  return sure_num && sure_den && (num > 0.0f) == (den > 0.0f);
}

}  // namespace

Ray::Ray(const Point3f& origin, const Vector3f& direction) : o(origin), d(direction) {
  nonzero = abs(d) > kTinyDirection;
  inv = 1.0f / cond(nonzero, d, Attrib3f(kTinyDirection));
  step = sign(cond(nonzero, d, Attrib3f(0.0f)));
  Attrib3f size = abs(d);
  last_is_x = size(0) > size(1) && size(0) > size(2);
  last_is_y = !last_is_x && size(1) > size(2);
  Attrib3f turned = turn(d);
  Attrib1f dz = cond(turned(2) != 0.0f, turned(2), ConstAttrib1f(1.0f));
  shear = join(-turned(0, 1) / dz, 1.0f / dz);
}

Attrib3f Ray::turn(const Attrib3f& v) const {
  return cond(last_is_x, v(1, 2, 0), cond(last_is_y, v(2, 0, 1), v));
}

// Each slab's distances are three roundings from exact (the difference,
// the reciprocal, the product): the leaving distance taken 2 gamma(3)
// beyond keeps a ray that grazes the box from passing it by, however far
// the box lies from the ray's origin.
void clip(const Ray& r, const Attrib3f& lo, const Attrib3f& hi, const Attrib1f& t_limit, Attrib1f& t_enter,
          Attrib1f& t_leave) {
  Attrib3f ta = (lo - r.o) * r.inv, tb = (hi - r.o) * r.inv;
  Attrib3f near = lesser(ta, tb), far = greater(ta, tb);
  Attrib1f near_x = near(0), near_y = near(1), near_z = near(2), far_x = far(0), far_y = far(1), far_z = far(2);
  t_enter = greater(greater(near_x, near_y), greater(near_z, Attrib1f(ConstAttrib1f(0.0f))));
  t_leave = lesser(lesser(lesser(far_x, far_y), far_z) * (1.0f + 2.0f * gamma(3)), t_limit);
}

// A ray through a shared edge or vertex meets every triangle around it
// whose edge functions are all >= 0 or all <= 0, so it cannot slip between
// them: the test is exact in the ray's space.
void test_triangle(const Ray& r, const Attrib3f& v0, const Attrib3f& v1, const Attrib3f& v2, const Attrib1i& tri,
                   Attrib1f& best, Attrib1i& best_tri, Attrib2f& best_uv) {
  Attrib3f a = to_ray_space(r, v0), b = to_ray_space(r, v1), c = to_ray_space(r, v2);
  Attrib1f u = edge_function(b, c), v = edge_function(c, a), w = edge_function(a, b);
  // Near an edge (rare) the float sign may be wrong: all three again in double.
  SH_IF(abs(u) <= edge_rounding(b, c) || abs(v) <= edge_rounding(c, a) || abs(w) <= edge_rounding(a, b)) {
    u = exact_edge_function(b, c);
    v = exact_edge_function(c, a);
    w = exact_edge_function(a, b);
  } SH_ENDIF;
  Attrib1f outside = (u < 0.0f || v < 0.0f || w < 0.0f) && (u > 0.0f || v > 0.0f || w > 0.0f);
  Attrib1f det = u + v + w;
  // Most tests end here: the distance, its error bound and the division
  // are for rays that pass through the triangle.
  SH_IF(det != 0.0f && !outside) {
    Attrib1f inv = 1.0f / det;
    Attrib3f barycentrics = join(join(u, v), w) * inv;
    Attrib1f t = distance(a, b, c, barycentrics);
    Attrib1f in_front = t > distance_error(a, b, c, barycentrics, inv);
    SH_IF(t > 0.0f && !in_front) { in_front = in_front_of_plane(r, v0, v1, v2); } SH_ENDIF;
    // Of triangles at the same distance (to rounding: backends may differ
    // in the last bits) the lowest numbered wins, whatever order the
    // accelerator tests them in: every accelerator and backend gives the
    // same hit.
    Attrib1f tie = (best_tri >= 0).cast<float>() && abs(t - best) <= best * kTieTolerance;
    Attrib1f nearer = cond(tie, (tri < best_tri).cast<float>(), t < best);
    Attrib1f hit = in_front && nearer;
    best = cond(hit, t, best);
    best_tri = cond(hit, tri, best_tri);
    best_uv = cond(hit, barycentrics(1, 2), best_uv);
  } SH_ENDIF;
}

void test_listed(const SceneTables& s, const Ray& r, const Table1D<Attrib1i>& list, Attrib1i& k, Attrib1i tri,
                 Attrib1f& best, Attrib1i& best_tri, Attrib2f& best_uv) {
  SH_WHILE(tri >= 0) {
    test_triangle(r, s.v0[tri], s.v1[tri], s.v2[tri], tri, best, best_tri, best_uv);
    k += 1;
    tri = list[k];
  } SH_ENDWHILE;
}

void test_leaf(const BvhTables& b, const Ray& r, Attrib1i k, Attrib1f& best, Attrib1i& best_tri, Attrib2f& best_uv) {
  Attrib1i more = 1;
  SH_WHILE(more) {
    Attrib1i entry = b.triangles[k], at = k * 3;
    more = entry >= 0;
    test_triangle(r, b.corners[at], b.corners[at + 1], b.corners[at + 2], cond(more, entry, -entry - 1), best, best_tri,
                  best_uv);
    k += 1;
  } SH_ENDWHILE;
}

Attrib3f nearest_axis(const Attrib3f& t_exits) {
  Attrib1f along_x = t_exits(0) <= t_exits(1) && t_exits(0) <= t_exits(2);
  Attrib1f along_y = (1.0f - along_x) * (t_exits(1) <= t_exits(2));
  return join(join(along_x, along_y), 1.0f - along_x - along_y);
}

}  // namespace walk

namespace {

// A walk that starts with the limit as its best takes only a triangle
// before it, but a tie may then give the hit to a lower-numbered triangle
// a rounding beyond the limit: whether a triangle was taken says so, not
// whether the best is still short of the limit.
Attrib1f hit_before_limit(const WalkState& w) { return (w.triangle >= 0).cast<float>(); }

}  // namespace

WalkState WalkState::fresh() {
  return {ConstAttrib3f(-1.0f, -1.0f, -1.0f), ConstAttrib1f(kFar), ConstAttrib1i(-1), ConstAttrib2f(0.0f, 0.0f)};
}

Intersector::Intersector(const SceneTables& s) : s_(s) {
  if (may_stop()) request_ = ConstAttrib4i(-1, 0, 0, 0);
}

bool Intersector::may_stop() const { return s_.octree && s_.octree->lazy; }

void Intersector::count_lanes() {
  if (!s_.bvh)
    throw Error(std::string("lane counts: the scene's accelerator is ") + (s_.grid ? "a grid" : "an octree") +
                "; lanes are counted in the BVH's walk, which rays side by side take together");
  if (s_.bvh->walk == BvhWalk::Stack)
    throw Error("lane counts: the BVH is walked with a stack by each lane alone; lanes are counted in the threaded and "
                "wide walks, which rays side by side take together");
  counting_ = true;
  lanes_ = ConstAttrib4i(0, 0, 0, 0);
}

Attrib1f Intersector::operator()(const Point3f& o, const Vector3f& d, const Attrib1f& t_limit, Attrib1f& t,
                                 Attrib1i& triangle, Attrib2f& uv) {
  WalkState w = WalkState::fresh();
  w.best = t_limit;
  walk(o, d, t_limit, w);
  t = w.best;
  triangle = w.triangle;
  uv = w.uv;
  return hit_before_limit(w);
}

Attrib1f Intersector::occluded(const Point3f& o, const Vector3f& d, const Attrib1f& t_limit) {
  WalkState w = WalkState::fresh();
  w.best = t_limit;
  walk(o, d, t_limit, w, !may_stop());
  return hit_before_limit(w);
}

Attrib1f Intersector::resume(const Point3f& o, const Vector3f& d, WalkState& state) {
  walk(o, d, ConstAttrib1f(kFar), state);
  return state.best < kFar;
}

// Over a lazy octree a stopped element walks no more.
void Intersector::walk(const Point3f& o, const Vector3f& d, const Attrib1f& t_limit, WalkState& w, bool any_hit) {
  if (s_.grid) {
    walk::grid(s_, walk::Ray(o, d), t_limit, w.best, w.triangle, w.uv, any_hit);
  } else if (s_.bvh) {
    walk::bvh(s_, walk::Ray(o, d), t_limit, w.best, w.triangle, w.uv, any_hit, counting_ ? &lanes_ : nullptr);
  } else if (may_stop()) {
    SH_IF(!stopped()) { walk::octree(s_, walk::Ray(o, d), t_limit, w, &request_, false); } SH_ENDIF;
  } else {
    walk::octree(s_, walk::Ray(o, d), t_limit, w, nullptr, any_hit);
  }
}

Program intersector_program(const SceneTables& s) {
  if (s.octree && s.octree->lazy)
    return SH_BEGIN_PROGRAM("intersector") {
      InputPoint3f o;
      InputVector3f d;
      InputAttrib4f resume;  // cell (x < 0: from the entry), best t
      InputAttrib1i resume_triangle;
      OutputAttrib1f t;
      OutputAttrib1i triangle;
      OutputAttrib4i request;
      OutputAttrib4f resume_out;
      OutputAttrib1i resume_triangle_out;
      Intersector intersect(s);
      WalkState w{resume(0, 1, 2), resume(3), resume_triangle, ConstAttrib2f(0.0f, 0.0f)};
      t = cond(intersect.resume(o, d, w), w.best, ConstAttrib1f(-1.0f));
      triangle = w.triangle;
      request = intersect.request();
      resume_out = join(w.cell, w.best);
      resume_triangle_out = w.triangle;
    } SH_END;
  return SH_BEGIN_PROGRAM("intersector") {
    InputPoint3f o;
    InputVector3f d;
    OutputAttrib1f t;
    OutputAttrib1i triangle;
    Attrib1f hit_t;
    Attrib1i hit_triangle;
    Attrib2f uv;
    Intersector intersect(s);
    Attrib1f hit = intersect(o, d, ConstAttrib1f(kFar), hit_t, hit_triangle, uv);
    t = cond(hit, hit_t, ConstAttrib1f(-1.0f));
    triangle = hit_triangle;
  } SH_END;
}

namespace {

// 1 where anything is in the way before limit: walked for any hit, or for
// the nearest.
Attrib1f blocked_along(Intersector& intersect, const Point3f& o, const Vector3f& d, const Attrib1f& limit, bool any_hit) {
  if (any_hit) return intersect.occluded(o, d, limit);
  Attrib1f t;
  Attrib1i triangle;
  Attrib2f uv;
  return intersect(o, d, limit, t, triangle, uv);
}

}  // namespace

Program walk_lanes_program(const SceneTables& s, bool any_hit) {
  return SH_BEGIN_PROGRAM(any_hit ? "walk_lanes_any" : "walk_lanes") {
    InputPoint3f o;
    InputVector3f d;
    InputAttrib1f limit;
    OutputAttrib4i lanes;
    Intersector intersect(s);
    intersect.count_lanes();
    blocked_along(intersect, o, d, limit, any_hit);
    lanes = intersect.lanes();
  } SH_END;
}

Program occlusion_program(const SceneTables& s, bool any_hit) {
  if (s.octree && s.octree->lazy) throw Error("the occlusion kernel does not run over a lazy octree");
  return SH_BEGIN_PROGRAM(any_hit ? "occlusion" : "occlusion_nearest") {
    InputPoint3f o;
    InputVector3f d;
    InputAttrib1f limit;
    OutputAttrib1f blocked;
    Intersector intersect(s);
    blocked = blocked_along(intersect, o, d, limit, any_hit);
  } SH_END;
}

}  // namespace sh::rt
