#pragma once
// The tracer's kernels, written in the DSL after the seed: ray generation,
// the intersector (scene-box entry, 3D-DDA walk of the grid, ray-triangle
// tests in each cell, a hit counting only inside the current cell) and the
// tracer (shadow rays to each light, Phong with interpolated normals and
// colours, reflections to a set depth, ambient, background).  The scene
// reaches them as tables and uniforms, so one compiled kernel serves every
// scene with the same features.
#include <string>

#include <sh/dsl.hpp>

#include "sh/raytracer/grid.hpp"
#include "sh/raytracer/sampling.hpp"
#include "sh/raytracer/scene.hpp"

namespace sh::rt {

// What a kernel is built to do.  Specialised kernels hold only what the
// scene needs: no shadow code without lights, no reflection loop without
// reflective materials, no colour reads without per-vertex colours.
struct Features {
  bool shadows = true;
  bool soft_shadows = true;
  bool reflections = true;
  bool vertex_colors = true;

  static Features of(const Scene& s, int reflection_depth);
  static Features all() { return {}; }
  std::string left_out() const;  // "shadows (no lights), ..." or "nothing"
};

// The scene as tables and uniforms.  Build it outside any program.
class SceneTables {
 public:
  SceneTables(const Scene& scene, const Grid& grid);
  void set_camera(const Camera& c, int width, int height);
  void set_reflection_depth(int depth) { max_bounces = static_cast<float>(depth); }
  void set_light_count(int n) { light_count = n; }
  // The disk samples every shading point uses (rotated per pixel).
  void set_samples(SamplePattern pattern, int n, unsigned seed);

  // Grid.
  Table3D<Attrib1i> cell_start;
  Table1D<Attrib1i> cell_triangles;
  Attrib3f grid_lo, grid_cell, grid_dims;
  // Triangles: first vertex and two edges (for the intersection), vertex
  // normals and colours (three per triangle), material per triangle.
  Table1D<Attrib3f> v0, e1, e2, normals, colors;
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
  Attrib1f max_bounces, ambient, surface_offset;
  Attrib3f background;
  // Camera.
  Attrib3f eye, forward, right, up;
  Attrib2f image_size;
  Attrib1f tan_half_fov;
};

// Traces o + t d for t in (0, t_limit): 1 where something is hit, with the
// nearest t, its triangle and barycentrics.  A C++ function inlined into
// whichever kernel calls it, as the seed's intersector is.
Attrib1f intersect(const SceneTables& s, const Point3f& o, const Vector3f& d, const Attrib1f& t_limit, Attrib1f& t,
                   Attrib1i& triangle, Attrib2f& uv);

Program raygen_program(const SceneTables& s);       // pixel centre -> origin, direction, pixel centre
Program intersector_program(const SceneTables& s);  // origin, direction -> t, triangle
Program tracer_program(const SceneTables& s, Features f);  // origin, direction, pixel -> colour, t, triangle

}  // namespace sh::rt
