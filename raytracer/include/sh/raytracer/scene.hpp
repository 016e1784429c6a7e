#pragma once
// What a scene is: camera, lights, materials and triangles.  How it is
// traced lives elsewhere (grid.hpp, render.hpp).
//
// Conventions that let any other tracer check ours ray by ray: the camera
// is a pinhole; the primary ray of pixel (x, y) goes through the pixel's
// centre (x + 0.5, y + 0.5), row 0 at the top.  Triangles are numbered in
// the order the scene lists meshes and each file lists faces (polygons
// fanned in order).
#include <cstdint>
#include <string>
#include <vector>

#include "sh/raytracer/vec.hpp"

namespace sh::rt {

struct Camera {
  Vec3 eye{0, 0, 5};
  Vec3 look_at{0, 0, 0};
  Vec3 up{0, 1, 0};
  float fov_degrees = 45;  // vertical
};

struct PointLight {
  Vec3 position;
  Vec3 color{1, 1, 1};
  // Radiant intensity for the light pass of bidirectional tracing (energy
  // per steradian, times colour).  0: the mean squared distance from the
  // light to the scene's surfaces, so that they are lit on average about as
  // the direct tracer lights them (it has no fall-off).
  float intensity = 0;
};

// A disk light (soft shadows): sampled with several shadow rays per
// shading point.  A radius of zero is a point light.
struct DiskLight {
  Vec3 centre;
  Vec3 normal{0, -1, 0};
  float radius = 0.02f;
  Vec3 color{1, 1, 1};
};

struct Material {
  std::string name;
  Vec3 diffuse{0.8f, 0.8f, 0.8f};
  float specular = 0;
  float shininess = 32;
  float reflectivity = 0;
  // Of the light that reaches a surface: a share `reflectivity` is
  // mirrored, a share `transparency` goes through, refracted by Snell's law
  // with index `ior` (all of it reflected past the critical angle), and
  // the rest is shaded.
  float transparency = 0;
  float ior = 1;
};

// The largest coordinate magnitude a scene may hold.  Squared distances
// (framing, light fall-off, intersection determinants) must stay finite in
// single precision (FLT_MAX is 3.4e38); 1e18 squared leaves a factor of
// 340 for sums and products of a few such terms.
inline constexpr float kMaxCoordinate = 1e18f;

// The least a scene may span (its largest extent).  Below it the products
// of its triangles' coordinates that the intersection tests (edge
// functions, about the square of a triangle's size) fall into float's
// denormals, which fast hardware flushes to zero: a sphere 1e-18 across
// loses a tenth of its hits, one 1e-20 across all of them (Embree's too).
inline constexpr float kMinSceneExtent = 1e-16f;

// Triangle soup, three vertices per triangle.
struct Mesh {
  std::vector<Vec3> positions;  // 3 per triangle
  std::vector<Vec3> normals;    // 3 per triangle (face normal where a file has none)
  std::vector<Vec3> colors;     // 3 per triangle, or empty
  std::vector<std::int32_t> material;  // 1 per triangle

  std::size_t triangles() const { return positions.size() / 3; }
  // Appends `other`'s triangles with the given material; where one of the
  // two has vertex colours and the other none, the other's are white.
  void append(const Mesh& other, std::int32_t material_of_other);
};

struct Scene {
  std::string name;
  Camera camera;
  std::vector<PointLight> lights;
  std::vector<DiskLight> disk_lights;
  std::vector<Material> materials;
  Mesh mesh;
  Vec3 background{0.05f, 0.05f, 0.08f};
  float ambient = 0.1f;
  std::vector<std::string> warnings;  // e.g. degenerate triangles dropped
  std::vector<std::string> files;     // read to make it: a scene file, the models it names

  bool has_vertex_colors() const { return !mesh.colors.empty(); }
  bool has_reflections() const;
  bool has_transparency() const;
  Vec3 bounds_min() const;
  Vec3 bounds_max() const;
};

// Appends one triangle; a zero-area one is counted, not added (a warning).
// Coloured and plain triangles mix in any order: plain ones are white.
class MeshBuilder {
 public:
  MeshBuilder(Scene& scene, int material) : scene_(scene), material_(material) {}
  void triangle(Vec3 a, Vec3 b, Vec3 c);
  void triangle(Vec3 a, Vec3 b, Vec3 c, Vec3 na, Vec3 nb, Vec3 nc);
  void colored(Vec3 a, Vec3 b, Vec3 c, Vec3 na, Vec3 nb, Vec3 nc, Vec3 ca, Vec3 cb, Vec3 cc);
  std::size_t degenerate() const { return degenerate_; }

 private:
  bool add(Vec3 a, Vec3 b, Vec3 c, Vec3 na, Vec3 nb, Vec3 nc);
  Scene& scene_;
  int material_;
  std::size_t degenerate_ = 0;
};

// Built-in shapes, tessellated into the scene with a material.  Each
// returns how many of its triangles had zero area in single precision and
// were left out (all of them when the shape is too small for its place).
std::size_t add_sphere(Scene& s, Vec3 centre, float radius, int material, int segments = 24);
std::size_t add_quad(Scene& s, Vec3 corner, Vec3 edge_u, Vec3 edge_v, int material);
std::size_t add_box(Scene& s, Vec3 lo, Vec3 hi, int material);
// A quad cut into tiles x tiles quads: light-pass elements small enough to
// show a caustic.
std::size_t add_tiled_quad(Scene& s, Vec3 corner, Vec3 edge_u, Vec3 edge_v, int tiles, int material);

// Built-in scenes: "cornell", "spheres" (the flagship), "procedural"
// (about `triangles` triangles), and the soft-shadow paper's "soft" (a
// sphere on a plane under a 4 cm disk light) and "soft2" (two such
// lights), and the bidirectional seed's "magg-mirror" (a mirror throwing
// the light onto a diffuse room) and "magg-glass" (a glass sphere with its
// caustic on the floor), meant for 200x200 with one reflection.  Unknown
// names throw sh::Error.
Scene builtin_scene(const std::string& name, std::size_t triangles = 100000);
std::vector<std::string> builtin_scene_names();
std::string builtin_scene_list();  // the names, comma-separated, for messages

// How a model file is loaded.  By default in a child process (see
// isolated_load.cpp) under these limits, so that a crash, hang or runaway
// allocation in the model library is an error naming the file, not the end
// of this process.
struct LoadLimits {
  std::size_t memory_mib = 4096;  // address space the load may add, MiB
  double seconds = 20;            // CPU time and wall-clock time of the load
  bool in_process = false;        // no child, no limits (debuggers); not from two threads at once
  // Tests only: runs in the loading child before the file is read (to make
  // it crash, hang or allocate).
  void (*in_child)() = nullptr;
};

// A JSON scene file, a bare model file (framed by a default camera and
// light) or a built-in name.  Errors name the file and the field or line.
Scene load_scene(const std::string& what, const LoadLimits& limits = {});
Scene load_scene_file(const std::string& path, const LoadLimits& limits = {});
Scene load_model_as_scene(const std::string& path, const LoadLimits& limits = {});

// Loads a model file into the scene with transform and material; throws
// sh::Error naming the file (and the mesh, face or vertex) when the file
// cannot be loaded or holds what the tracer cannot use.
struct Transform {
  Vec3 translate{0, 0, 0};
  Vec3 scale{1, 1, 1};
  Vec3 rotate_degrees{0, 0, 0};  // about x, then y, then z
  Vec3 apply(Vec3 p) const;
  Vec3 apply_normal(Vec3 n) const;
};
void load_model(Scene& scene, const std::string& path, const Transform& t, int material, const LoadLimits& limits = {});

// What is wrong with a point for the tracer ("coordinate x = 1e+30 is
// outside the range ..."), or "" when it is finite and within
// kMaxCoordinate.
std::string coordinate_problem(Vec3 p);

// What is wrong with a material ("reflectivity 2 must be in [0, 1]"), or
// "": colours and numbers finite and not negative, the shares of light
// mirrored and transmitted in [0, 1] and together at most 1, the index of
// refraction in [1, 4].
std::string material_problem(const Material& m);

// Throws sh::Error if the scene cannot be traced, naming `where` and what:
// no triangles; a coordinate NaN, infinite or beyond kMaxCoordinate; the
// mesh's normals, colours or materials not one per corner or triangle, or
// not numbers the shading can use; a material, light, the background or
// the ambient light out of range; the camera or a light beyond 1e19 or
// without a frame.
void validate(const Scene& s, const std::string& where);

}  // namespace sh::rt
