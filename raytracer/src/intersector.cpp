// The intersector of the seed: enter the accelerator's box, walk its cells
// front to back, test each cell's triangles, and accept a hit only inside
// the current cell (a nearer hit in a later cell cannot exist then).
#include "walk.hpp"

namespace sh::rt {
namespace walk {
namespace {

// Barycentric tolerance: a ray through a shared edge or vertex hits both
// sides rather than slipping between them (watertight closed meshes).
constexpr float kEdgeTolerance = 1e-6f;
constexpr float kTieTolerance = 1e-6f;

}  // namespace

Ray::Ray(const Point3f& origin, const Vector3f& direction) : o(origin), d(direction) {
  nonzero = abs(d) > kTinyDirection;
  inv = 1.0f / cond(nonzero, d, Attrib3f(kTinyDirection));
  step = sign(cond(nonzero, d, Attrib3f(0.0f)));
}

void clip(const Ray& r, const Attrib3f& lo, const Attrib3f& hi, const Attrib1f& t_limit, Attrib1f& t_enter,
          Attrib1f& t_leave) {
  Attrib3f ta = (lo - r.o) * r.inv, tb = (hi - r.o) * r.inv;
  t_enter = max(max_component(min(ta, tb)), 0.0f);
  t_leave = min(min_component(max(ta, tb)), t_limit);
}

void test_triangle(const SceneTables& s, const Ray& r, const Attrib1i& tri, Attrib1f& best, Attrib1i& best_tri,
                   Attrib2f& best_uv) {
  Attrib3f v0 = s.v0[tri], e1 = s.e1[tri], e2 = s.e2[tri];
  Attrib3f p = cross(r.d, e2);
  Attrib1f det = dot(e1, p);
  Attrib1f usable = det != 0.0f;
  Attrib1f inv = 1.0f / cond(usable, det, ConstAttrib1f(1.0f));
  Attrib3f sv = r.o - v0;
  Attrib1f u = dot(sv, p) * inv;
  Attrib3f q = cross(sv, e1);
  Attrib1f v = dot(r.d, q) * inv;
  Attrib1f t = dot(e2, q) * inv;
  // Of triangles at the same distance (to rounding: backends may differ in
  // the last bits) the lowest numbered wins, whatever order the accelerator
  // tests them in: every accelerator and backend gives the same hit.
  Attrib1f tie = (best_tri >= 0).cast<float>() && abs(t - best) <= best * kTieTolerance;
  Attrib1f nearer = cond(tie, (tri < best_tri).cast<float>(), t < best);
  Attrib1f hit = usable && u >= -kEdgeTolerance && v >= -kEdgeTolerance && u + v <= 1.0f + kEdgeTolerance &&
                 t > 0.0f && nearer;
  best = cond(hit, t, best);
  best_tri = cond(hit, tri, best_tri);
  best_uv = cond(hit, join(u, v), best_uv);
}

Attrib3f nearest_axis(const Attrib3f& t_exits) {
  Attrib1f along_x = t_exits(0) <= t_exits(1) && t_exits(0) <= t_exits(2);
  Attrib1f along_y = (1.0f - along_x) * (t_exits(1) <= t_exits(2));
  return join(join(along_x, along_y), 1.0f - along_x - along_y);
}

}  // namespace walk

WalkState WalkState::fresh() {
  return {ConstAttrib3f(-1.0f, -1.0f, -1.0f), ConstAttrib1f(kFar), ConstAttrib1i(-1), ConstAttrib2f(0.0f, 0.0f)};
}

Intersector::Intersector(const SceneTables& s) : s_(s) {
  if (may_stop()) request_ = ConstAttrib4i(-1, 0, 0, 0);
}

bool Intersector::may_stop() const { return s_.octree && s_.octree->lazy; }

Attrib1f Intersector::operator()(const Point3f& o, const Vector3f& d, const Attrib1f& t_limit, Attrib1f& t,
                                 Attrib1i& triangle, Attrib2f& uv) {
  WalkState w = WalkState::fresh();
  w.best = t_limit;
  walk(o, d, t_limit, w);
  t = w.best;
  triangle = w.triangle;
  uv = w.uv;
  return w.best < t_limit;
}

Attrib1f Intersector::resume(const Point3f& o, const Vector3f& d, WalkState& state) {
  walk(o, d, ConstAttrib1f(kFar), state);
  return state.best < kFar;
}

// Over a lazy octree a stopped element walks no more.
void Intersector::walk(const Point3f& o, const Vector3f& d, const Attrib1f& t_limit, WalkState& w) {
  if (s_.grid) {
    walk::grid(s_, walk::Ray(o, d), t_limit, w.best, w.triangle, w.uv);
  } else if (may_stop()) {
    SH_IF(!stopped()) { walk::octree(s_, walk::Ray(o, d), t_limit, w, &request_); } SH_ENDIF;
  } else {
    walk::octree(s_, walk::Ray(o, d), t_limit, w, nullptr);
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

}  // namespace sh::rt
