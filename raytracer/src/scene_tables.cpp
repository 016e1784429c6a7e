#include <cmath>
#include <numbers>

#include "sh/raytracer/kernels.hpp"

namespace sh::rt {
namespace {

std::vector<float> flatten(const std::vector<Vec3>& v) {
  std::vector<float> out;
  out.reserve(v.size() * 3);
  for (const Vec3& p : v) out.insert(out.end(), {p.x, p.y, p.z});
  return out;
}

int at_least_one(std::size_t n) { return static_cast<int>(std::max<std::size_t>(n, 1)); }

}  // namespace

Features Features::of(const Scene& s, int reflection_depth) {
  return {!s.lights.empty(), !s.disk_lights.empty(), s.has_reflections() && reflection_depth > 0, s.has_vertex_colors(),
          s.has_transparency() && reflection_depth > 0};
}

void SceneTables::set_samples(SamplePattern pattern, int n, unsigned seed) {
  std::vector<float> xy = disk_samples(pattern, n, seed);
  xy.resize(2 * kMaxShadowSamples, 0.0f);
  samples.assign(xy);
  sample_count = n;
}

std::string Features::left_out() const {
  std::string out;
  auto add = [&](bool present, const char* what) {
    if (!present) out += (out.empty() ? "" : ", ") + std::string(what);
  };
  add(shadows, "shadow rays to point lights (none)");
  add(soft_shadows, "soft shadows (no disk lights)");
  add(reflections, "reflection loop (no reflective material, or depth 0)");
  add(vertex_colors, "vertex colours (none in the scene)");
  add(refractions, "refraction (no transparent material, or depth 0)");
  if (luminance) out += std::string(out.empty() ? "" : ", ") + "diffuse shadow rays (light comes from the light pass)";
  return out.empty() ? "nothing" : out;
}

LuminanceTables::LuminanceTables(int k_, const std::vector<float>& v)
    : vertex(at_least_one(v.size() / 3)), subdivision(static_cast<float>(k_)), k(k_) {
  vertex.name("vertex_luminance").assign(v.empty() ? std::vector<float>{0, 0, 0} : v);
}

GridTables::GridTables(const Grid& g)
    : cell_start(g.dims[0], g.dims[1], g.dims[2]), cell_triangles(at_least_one(g.cell_triangles.size())) {
  cell_start.name("cell_start").assign(g.cell_start);
  cell_triangles.name("cell_triangles").assign(g.cell_triangles);
  lo = Attrib3f(g.lo.x, g.lo.y, g.lo.z);
  cell = Attrib3f(g.cell.x, g.cell.y, g.cell.z);
  dims = Attrib3f(static_cast<float>(g.dims[0]), static_cast<float>(g.dims[1]), static_cast<float>(g.dims[2]));
}

OctreeTables::OctreeTables(const Octree& tree, bool is_lazy)
    : nodes(at_least_one(tree.nodes().size())), triangles(at_least_one(tree.triangles().size())), lazy(is_lazy) {
  nodes.name("octree_nodes").assign(tree.nodes());
  triangles.name("octree_triangles").assign(tree.triangles());
  Vec3 f = tree.finest_cell();
  lo = Attrib3f(tree.bounds().lo.x, tree.bounds().lo.y, tree.bounds().lo.z);
  finest_cell = Attrib3f(f.x, f.y, f.z);
  resolution = static_cast<float>(tree.resolution());
}

// A layout the walk does not read, or one that is empty (a tree that is
// one leaf has no inner node), stays one zero element: a kernel may name
// it without reading it.
BvhTables::BvhTables(const Bvh& b)
    : walk(b.walk),
      depth(b.depth),
      prefetch(b.prefetch),
      lo(at_least_one(b.lo.size() / 3)),
      hi(at_least_one(b.hi.size() / 3)),
      links(at_least_one(b.links.size() / 2)),
      nodes(static_cast<std::int32_t>(b.nodes())),
      pair_lo(at_least_one(b.pair_lo.size() / 3)),
      pair_hi(at_least_one(b.pair_hi.size() / 3)),
      children(at_least_one(b.children.size())),
      wide_box(at_least_one(b.wide_box.size() / 4)),
      wide_children(at_least_one(b.wide_children.size() / kBvhWidth)),
      wide_order(at_least_one(b.wide_order.size())),
      root(b.root),
      triangles(at_least_one(b.triangles.size())),
      corners(at_least_one(b.corners.size() / 3)) {
  auto fill = [](auto& table, const char* name, const auto& values) {
    table.name(name);
    if (values.empty())
      table.assign(std::vector<typename std::decay_t<decltype(table)>::scalar>(table.size() * table.components));
    else
      table.assign(values);
  };
  fill(lo, "bvh_lo", b.lo);
  fill(hi, "bvh_hi", b.hi);
  fill(links, "bvh_links", b.links);
  fill(pair_lo, "bvh_pair_lo", b.pair_lo);
  fill(pair_hi, "bvh_pair_hi", b.pair_hi);
  fill(children, "bvh_children", b.children);
  fill(wide_box, "bvh_wide_box", b.wide_box);
  fill(wide_children, "bvh_wide_children", b.wide_children);
  fill(wide_order, "bvh_wide_order", b.wide_order);
  fill(triangles, "bvh_triangles", b.triangles);
  fill(corners, "bvh_corners", b.corners);
}

SceneTables::SceneTables(const Scene& scene, const Bvh& b) : SceneTables(scene) { bvh = std::make_unique<BvhTables>(b); }

SceneTables::SceneTables(const Scene& scene, const Grid& g) : SceneTables(scene) {
  grid = std::make_unique<GridTables>(g);
}

SceneTables::SceneTables(const Scene& scene, const Octree& tree, bool lazy) : SceneTables(scene) {
  octree = std::make_unique<OctreeTables>(tree, lazy);
}

SceneTables::SceneTables(const Scene& scene)
    : v0(at_least_one(scene.mesh.triangles())),
      v1(at_least_one(scene.mesh.triangles())),
      v2(at_least_one(scene.mesh.triangles())),
      normals(at_least_one(scene.mesh.normals.size())),
      colors(at_least_one(scene.mesh.colors.size())),
      material(at_least_one(scene.mesh.triangles())),
      materials(at_least_one(2 * scene.materials.size())),
      lights(at_least_one(2 * scene.lights.size())),
      disks(at_least_one(4 * scene.disk_lights.size())),
      samples(kMaxShadowSamples) {
  // Kernels trust their tables: a scene built by hand is checked here, as
  // the renderer checks it, before anything is copied into them.
  validate(scene, scene.name);
  const Mesh& m = scene.mesh;
  std::vector<Vec3> corner[3];
  for (int k = 0; k < 3; ++k) {
    corner[k].resize(m.triangles());
    for (std::size_t t = 0; t < m.triangles(); ++t) corner[k][t] = m.positions[3 * t + k];
  }
  v0.name("v0").assign(flatten(corner[0]));
  v1.name("v1").assign(flatten(corner[1]));
  v2.name("v2").assign(flatten(corner[2]));
  normals.name("normals").assign(flatten(m.normals));
  colors.name("colors").assign(m.colors.empty() ? std::vector<float>{1, 1, 1} : flatten(m.colors));
  material.name("material").assign(m.material);

  std::vector<float> mats;
  for (const Material& mt : scene.materials)
    mats.insert(mats.end(), {mt.diffuse.x, mt.diffuse.y, mt.diffuse.z, mt.specular, mt.shininess, mt.reflectivity,
                             mt.transparency, mt.ior});
  materials.name("materials").assign(mats);
  std::vector<Vec3> ls;
  for (const PointLight& l : scene.lights) {
    ls.push_back(l.position);
    ls.push_back(l.color);
  }
  lights.name("lights").assign(ls.empty() ? std::vector<float>{0, 0, 0} : flatten(ls));
  light_count = static_cast<std::int32_t>(scene.lights.size());
  std::vector<Vec3> ds;
  for (const DiskLight& d : scene.disk_lights) {
    Vec3 n = normalize(d.normal);
    Vec3 u = normalize(cross(n, std::fabs(n.x) < 0.9f ? Vec3{1, 0, 0} : Vec3{0, 1, 0})), v = cross(n, u);
    ds.insert(ds.end(), {d.centre, u * d.radius, v * d.radius, d.color});
  }
  disks.name("disks").assign(ds.empty() ? std::vector<float>{0, 0, 0} : flatten(ds));
  disk_count = static_cast<std::int32_t>(scene.disk_lights.size());
  samples.name("samples");
  set_samples(SamplePattern::Random, 16, 1);
  use_vertex_colors = scene.has_vertex_colors() ? 1.0f : 0.0f;
  ambient = scene.ambient;
  background = Attrib3f(scene.background.x, scene.background.y, scene.background.z);
  max_bounces = 0.0f;
  set_camera(scene.camera, 1, 1);
}

void SceneTables::set_camera(const Camera& c, int width, int height) {
  Vec3 f = normalize(c.look_at - c.eye), r = normalize(cross(f, c.up)), u = cross(r, f);
  eye = Attrib3f(c.eye.x, c.eye.y, c.eye.z);
  forward = Attrib3f(f.x, f.y, f.z);
  right = Attrib3f(r.x, r.y, r.z);
  up = Attrib3f(u.x, u.y, u.z);
  image_size = Attrib2f(static_cast<float>(width), static_cast<float>(height));
  tan_half_fov = std::tan(c.fov_degrees * std::numbers::pi_v<float> / 360.0f);
}

}  // namespace sh::rt
