#pragma once
// The tracer's kernels, written in the DSL after the seed: ray generation,
// the intersector (scene-box entry, a walk of the accelerator's cells front
// to back -- the grid's 3D-DDA or the octree's leaves --, ray-triangle tests
// in each cell, a hit counting only inside the current cell) and the
// tracer (shadow rays to each light, Phong with interpolated normals and
// colours, reflections to a set depth, ambient, background).  The scene
// reaches them as tables and uniforms, so one compiled kernel serves every
// scene with the same features.
#include <memory>
#include <string>

#include <sh/dsl.hpp>

#include "sh/raytracer/bvh.hpp"
#include "sh/raytracer/grid.hpp"
#include "sh/raytracer/octree.hpp"
#include "sh/raytracer/sampling.hpp"
#include "sh/raytracer/scene.hpp"

namespace sh::rt {

// What a kernel is built to do.  Specialised kernels hold only what the
// scene needs: no shadow code without lights, no reflection loop without
// reflective materials, no refraction without transparent ones, no colour
// reads without per-vertex colours.
struct Features {
  bool shadows = true;
  bool soft_shadows = true;
  bool reflections = true;
  bool vertex_colors = true;
  bool refractions = true;
  // Bidirectional: diffuse light comes from the light pass's vertex
  // luminance (SceneTables::luminance), not from shadow rays.
  bool luminance = false;

  static Features of(const Scene& s, int reflection_depth);
  static Features all() { return {}; }
  std::string left_out() const;  // "shadows (no lights), ..." or "nothing"
};

struct GridTables {
  explicit GridTables(const Grid& grid);
  Table3D<Attrib1i> cell_start;
  Table1D<Attrib1i> cell_triangles;
  Attrib3f lo, cell, dims;
};

// The BVH's tables (bvh.hpp), its walk's layout only.  Threaded: links
// holds the six orders one after the other, `nodes` entries each.  Stack:
// child k of inner node i at 2 i + k.  Wide: node i's six rows of child
// box coordinates at 6 i ...  6 i + 5; its children at row i of
// wide_children.  Every walk: list entry k's triangle's corners at 3 k,
// 3 k + 1 and 3 k + 2 of `corners`.
struct BvhTables {
  explicit BvhTables(const Bvh& bvh);
  BvhWalk walk;
  int depth;
  bool prefetch;  // Bvh::prefetch
  Table1D<Attrib3f> lo, hi;
  Table1D<Attrib2i> links;
  Attrib1i nodes;
  Table1D<Attrib3f> pair_lo, pair_hi;
  Table1D<Attrib1i> children;
  Table1D<Attrib4f> wide_box;
  Table1D<Attrib4i> wide_children;
  Table1D<Attrib1i> wide_order;
  Attrib1i root;
  Table1D<Attrib1i> triangles;
  Table1D<Attrib3f> corners;
};

// A lazy octree's tables are what was built when they were made; running
// in waves, its refiner shows the kernels what has been built since.
struct OctreeTables {
  OctreeTables(const Octree& tree, bool lazy);
  Table1D<Attrib1i> nodes, triangles;
  Attrib3f lo, finest_cell;
  Attrib1f resolution;
  bool lazy;
};

// What a light pass left, for the view pass: luminance (rgb) at each
// triangle's lattice points (bidirectional.hpp).
struct LuminanceTables {
  LuminanceTables(int subdivision, const std::vector<float>& vertex);
  Table1D<Attrib3f> vertex;
  Attrib1f subdivision;
  int k;
};

// The scene as tables and uniforms.  Build it outside any program.
class SceneTables {
 public:
  SceneTables(const Scene& scene, const Grid& grid);
  SceneTables(const Scene& scene, const Octree& tree, bool lazy);
  SceneTables(const Scene& scene, const Bvh& bvh);
  void set_camera(const Camera& c, int width, int height);
  void set_reflection_depth(int depth) { max_bounces = static_cast<float>(depth); }
  void set_light_count(int n) { light_count = n; }
  // The disk samples every shading point uses (rotated per pixel).
  void set_samples(SamplePattern pattern, int n, unsigned seed);

  // The accelerator: one of the three.
  std::unique_ptr<GridTables> grid;
  std::unique_ptr<OctreeTables> octree;
  std::unique_ptr<BvhTables> bvh;
  std::unique_ptr<LuminanceTables> luminance;  // bidirectional tracing only
  // Triangles: the three vertices as the scene has them (the watertight
  // test needs a shared vertex to be the same number in every triangle),
  // vertex normals and colours (three per triangle), material per triangle.
  Table1D<Attrib3f> v0, v1, v2, normals, colors;
  Table1D<Attrib1i> material;
  // Materials, two entries each: (diffuse rgb, specular), (shininess,
  // reflectivity, transparency, ior).  Lights, two each: position, colour.
  Table1D<Attrib4f> materials;
  Table1D<Attrib3f> lights;
  Attrib1i light_count;
  // Disk lights, four entries each: centre, radius * u, radius * v (u, v
  // spanning the disk), colour; and the unit-disk samples.
  Table1D<Attrib3f> disks;
  Attrib1i disk_count;
  Table1D<Attrib2f> samples;
  Attrib1i sample_count;
  Attrib1f use_vertex_colors;  // 0 or 1: the general kernel's switch
  Attrib1f max_bounces, ambient;
  Attrib3f background;
  // Camera.
  Attrib3f eye, forward, right, up;
  Attrib2f image_size;
  Attrib1f tan_half_fov;

 private:
  explicit SceneTables(const Scene& scene);
};

// Beyond anything in a scene: the limit of a ray that may go on forever.
inline constexpr float kFar = 1e30f;

// Where a ray's walk of an octree is: the finest-level cell it visits next
// (x < 0: where it enters) and the nearest hit so far.
struct WalkState {
  static WalkState fresh();  // not started
  Attrib3f cell;
  Attrib1f best;
  Attrib1i triangle;
  Attrib2f uv;
};

// Traces rays inside a program being recorded: C++ inlined into whichever
// kernel calls it, as the seed's intersector is.  Over a lazy octree the
// first ray that reaches an unbuilt node stops and leaves the node and the
// cell it was in in request() (-1 first where none); the calls after it do
// nothing (the element runs again once the node is built).
class Intersector {
 public:
  explicit Intersector(const SceneTables& s);
  // From here on its BVH walks count their lanes into lanes(): box steps
  // the ray was walking at (in the wide walk, each child box tested),
  // those where its own box test met the box,
  // leaves tested for it, and those it met itself.  Rays side by side walk
  // together, so the shares say how many of the lanes at work wanted it.
  void count_lanes();
  const Attrib4i& lanes() const { return lanes_; }
  // o + t d for t in (0, t_limit): 1 where something is hit, with the
  // nearest t, its triangle and barycentrics.
  Attrib1f operator()(const Point3f& o, const Vector3f& d, const Attrib1f& t_limit, Attrib1f& t, Attrib1i& triangle,
                      Attrib2f& uv);
  // 1 where anything is hit for t in (0, t_limit): the same answer as the
  // nearest hit's, but the walk ends at the first hit it finds (over a lazy
  // octree it walks as for the nearest).
  Attrib1f occluded(const Point3f& o, const Vector3f& d, const Attrib1f& t_limit);
  // The nearest hit along o + t d, t > 0, into `state`: over a lazy octree
  // going on from where the walk stopped, elsewhere from the start.
  Attrib1f resume(const Point3f& o, const Vector3f& d, WalkState& state);
  const Attrib4i& request() const { return request_; }
  Attrib1f stopped() const { return (request_(0) >= 0).cast<float>(); }
  bool may_stop() const;  // over a lazy octree

 private:
  void walk(const Point3f& o, const Vector3f& d, const Attrib1f& t_limit, WalkState& state, bool any_hit = false);
  const SceneTables& s_;
  Attrib4i request_;
  bool counting_ = false;
  Attrib4i lanes_;
};

// Where a ray going along d goes on at a surface of normal n (facing the
// side d comes from), eta the ratio of indices (from / into): refracted by
// Snell's law, or mirrored past the critical angle (then `mirrored` is 1).
Vector3f refract_or_mirror(const Vector3f& d, const Normal3f& n, const Attrib1f& eta, Attrib1f& mirrored);

Program raygen_program(const SceneTables& s);  // pixel centre -> origin, direction, pixel centre
// origin, direction -> t, triangle; over a lazy octree also a resumable
// walk: origin, direction, resume (cell, best t), resume triangle -> t,
// triangle, request, resume, resume triangle (Renderer::intersect runs it
// in waves).
Program intersector_program(const SceneTables& s);
// origin, direction, limit -> lane counts (Intersector::lanes) of the BVH's
// walk for the nearest hit, or (any_hit) for any hit: what `shtrace rays
// --lanes` reports.  Only over a BVH.
Program walk_lanes_program(const SceneTables& s, bool any_hit);
// origin, direction, limit -> 1 where anything is hit for t in (0, limit),
// else 0: the shadow-ray query, walked for any hit, or (any_hit false) for
// the nearest, to measure what stopping early buys.  Not over a lazy
// octree (its walks run in waves: the tracer's shadow rays do that).
Program occlusion_program(const SceneTables& s, bool any_hit = true);
// origin, direction, pixel -> colour, t, triangle.  Over a lazy octree:
// pixel, path -> colour, t, triangle, request, path, where `path` is the
// seven channels of PathChannels: a pixel that stops resumes the bounce it
// stopped in, its ray's walk where it stopped.  With `one_bounce` (a
// wavefront; not over a lazy octree) the same inputs and outputs, the
// request an int: each run takes every path one bounce on, and the request
// is 0 where the path goes on, -1 where it ended.
Program tracer_program(const SceneTables& s, Features f, bool one_bounce = false);
// origin, direction, pixel -> pixel, path: where a carried path starts.
Program path_start_program();

// A carried path's state, as channels.
struct PathChannels {
  Channel<Attrib4f> origin_bounce, direction_distance, color_best, weight_u, cell_v;
  Channel<Attrib1i> triangle, walk_triangle;
  std::vector<std::shared_ptr<detail::Buffer>> all() const {
    return {origin_bounce, direction_distance, color_best, weight_u, cell_v, triangle, walk_triangle};
  }
};

}  // namespace sh::rt
