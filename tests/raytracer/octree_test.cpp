// The octree, static and lazy, and the BVH: the same images as the grid
// on every backend; a lazy render builds only nodes its rays walk into, nothing
// when the view is rendered again, only what is new for a new view; depth
// limits from 0 to the deepest; the waves end where every ray escapes and
// where every ray hits; the order nodes are built in does not change them.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>
#include <set>

#include "helpers.hpp"

namespace {

using sh::rt::Accel;
using sh::rt::Vec3;

sh::rt::RenderSettings small(const std::string& backend, Accel accel, sh::rt::OctreeLimits limits = {}) {
  sh::rt::RenderSettings s;
  s.width = 48;
  s.height = 36;
  s.backend = backend;
  s.accel = accel;
  s.octree = limits;
  s.shadow_samples = 4;
  return s;
}

// Bit for bit: ties between triangles at the same distance go to the
// lowest numbered, whatever order an accelerator tests them in.
void expect_same_image(const sh::rt::Image& a, const sh::rt::Image& b, const std::string& what) {
  ASSERT_EQ(a.triangle, b.triangle) << what << ": a pixel's primary hit differs";
  ASSERT_EQ(a.distance, b.distance) << what << ": a primary distance differs";
  ASSERT_EQ(a.rgb, b.rgb) << what << ": a colour differs";
}

class AcceleratorsOnEveryBackend : public testing::TestWithParam<std::string> {};

TEST_P(AcceleratorsOnEveryBackend, ImagesAreTheGridsOnEveryBuiltinScene) {
  for (std::string name : {"cornell", "spheres", "soft"}) {
    sh::rt::Scene scene = sh::rt::builtin_scene(name);
    sh::rt::Image grid = sh::rt::Renderer(scene, small(GetParam(), Accel::Grid)).render();
    for (Accel accel : {Accel::Octree, Accel::LazyOctree, Accel::Bvh}) {
      sh::rt::Renderer r(scene, small(GetParam(), accel));
      expect_same_image(grid, r.render(), name + " with " + sh::rt::accel_name(accel) + " on " + GetParam());
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Backends, AcceleratorsOnEveryBackend, testing::ValuesIn(rt_test::every_backend()),
                         [](const auto& info) { return info.param; });

// Does the segment o + t d, t in [0, t_end], meet the box (slightly grown)?
bool segment_meets(Vec3 o, Vec3 d, float t_end, sh::rt::Box b) {
  float t0 = 0, t1 = t_end;
  for (int a = 0; a < 3; ++a) {
    float pad = 1e-4f * (b.hi[a] - b.lo[a]);
    if (std::fabs(d[a]) < 1e-12f) {
      if (o[a] < b.lo[a] - pad || o[a] > b.hi[a] + pad) return false;
      continue;
    }
    float ta = (b.lo[a] - pad - o[a]) / d[a], tb = (b.hi[a] + pad - o[a]) / d[a];
    t0 = std::max(t0, std::min(ta, tb));
    t1 = std::min(t1, std::max(ta, tb));
  }
  return t0 <= t1;
}

// Primary rays only (no lights, no mirrors): each built node must lie on
// some ray's path from the eye to its hit (or out of the scene).
void expect_only_touched_nodes(const sh::rt::Renderer& r, const std::vector<std::uint64_t>& keys,
                               const std::vector<float>& origins, const std::vector<float>& directions,
                               const sh::rt::Hits& hits) {
  for (std::uint64_t key : keys) {
    sh::rt::Box b = r.octree()->box_of(key);
    bool touched = false;
    for (std::size_t i = 0; i < hits.t.size() && !touched; ++i) {
      Vec3 o{origins[3 * i], origins[3 * i + 1], origins[3 * i + 2]}, d{directions[3 * i], directions[3 * i + 1], directions[3 * i + 2]};
      touched = segment_meets(o, d, hits.t[i] < 0 ? 1e30f : hits.t[i], b);
    }
    ASSERT_TRUE(touched) << "node " << std::hex << key << " was built but no ray walks into it";
  }
}

sh::rt::Scene unlit(const std::string& name) {
  sh::rt::Scene s = sh::rt::builtin_scene(name, 20000);
  s.lights.clear();
  s.disk_lights.clear();
  for (sh::rt::Material& m : s.materials) m.reflectivity = 0;
  return s;
}

struct Primary {
  std::vector<float> origins, directions;
};

Primary primary_rays(sh::rt::Renderer& r, int w, int h) {
  sh::Program raygen = sh::rt::raygen_program(r.tables());
  sh::Channel<sh::Attrib2f> pixels(sh::rt::pixel_centres(w, h));
  sh::Channel<sh::Point3f> o;
  sh::Channel<sh::Vector3f> d;
  sh::Channel<sh::Attrib2f> pixel;
  sh::run(raygen, {pixels}, {o, d, pixel}, sh::backend("cpu"));
  return {o.values(), d.values()};
}

TEST(LazyOctree, BuildsOnlyNodesRaysWalkIntoAndNothingTheSecondTime) {
  sh::rt::Scene scene = unlit("procedural");
  sh::rt::RenderSettings s = small("cpu", Accel::LazyOctree);
  sh::rt::Renderer r(scene, s);
  sh::rt::RenderReport first, second;
  sh::rt::Image image = r.render(&first);
  std::vector<std::uint64_t> keys = r.octree()->built_keys();
  ASSERT_FALSE(keys.empty());
  EXPECT_GT(first.waves, 0u);
  Primary p = primary_rays(r, s.width, s.height);
  sh::rt::Hits hits = r.intersect(p.origins, p.directions, sh::backend("cpu"));
  expect_only_touched_nodes(r, keys, p.origins, p.directions, hits);
  // Fewer nodes than the whole tree (the view sees all of the scene), and
  // the same picture as it gives.
  sh::rt::Octree full = sh::rt::Octree::full(scene, s.octree);
  EXPECT_LT(r.octree()->nodes().size(), full.nodes().size() * 3 / 4);
  s.accel = Accel::Octree;
  expect_same_image(sh::rt::Renderer(scene, s).render(), image, "static and lazy octree");

  r.render(&second);
  EXPECT_EQ(r.octree()->built_keys().size(), keys.size()) << "the second render of the same view built nodes";
  EXPECT_EQ(second.waves, 0u);
}

TEST(LazyOctree, ANewViewBuildsOnlyWhatIsNew) {
  sh::rt::Scene scene = unlit("procedural");
  scene.camera = {{-6, 4, 6}, {-6, 0, 0}, {0, 1, 0}, 30};
  sh::rt::RenderSettings s = small("cpu", Accel::LazyOctree);
  sh::rt::Renderer r(scene, s);
  r.render();
  std::size_t before = r.octree()->built_keys().size();
  scene.camera = {{6, 4, 6}, {6, 0, 0}, {0, 1, 0}, 30};
  r.tables().set_camera(scene.camera, s.width, s.height);
  r.render();
  std::vector<std::uint64_t> all = r.octree()->built_keys();
  ASSERT_GT(all.size(), before) << "the other half of the scene needed nothing new";
  std::set<std::uint64_t> distinct(all.begin(), all.end());
  EXPECT_EQ(distinct.size(), all.size()) << "a node was built twice";
  std::vector<std::uint64_t> fresh(all.begin() + static_cast<long>(before), all.end());
  Primary p = primary_rays(r, s.width, s.height);
  expect_only_touched_nodes(r, fresh, p.origins, p.directions, r.intersect(p.origins, p.directions, sh::backend("cpu")));
}

TEST(LazyOctree, DepthLimitsFromNoneToTheDeepest) {
  sh::rt::Scene scene = sh::rt::builtin_scene("cornell");
  sh::rt::Image grid = sh::rt::Renderer(scene, small("cpu", Accel::Grid)).render();
  for (int depth : {0, 1, sh::rt::kMaxOctreeDepth})
    for (Accel accel : {Accel::Octree, Accel::LazyOctree}) {
      sh::rt::Renderer r(scene, small("cpu", accel, {depth, depth == 0 ? 1 : 2}));
      expect_same_image(grid, r.render(), "depth " + std::to_string(depth) + ", " + sh::rt::accel_name(accel));
      if (depth == 0) {
        EXPECT_EQ(r.octree()->nodes().size(), 1u) << "depth 0 is a single leaf";
      }
    }
  EXPECT_THROW(sh::rt::Octree::lazy(scene, {sh::rt::kMaxOctreeDepth + 1, 8}), sh::Error);
  EXPECT_THROW(sh::rt::Octree::lazy(scene, {4, 0}), sh::Error);
}

TEST(LazyOctree, WavesEndWhereEveryRayEscapesAndWhereEveryRayHits) {
  sh::rt::Scene away = sh::rt::builtin_scene("spheres");
  away.camera.look_at = away.camera.eye + (away.camera.eye - away.camera.look_at);  // facing away from the scene
  sh::rt::Renderer escape(away, small("cpu", Accel::LazyOctree));
  sh::rt::Image out = escape.render();
  EXPECT_TRUE(std::all_of(out.triangle.begin(), out.triangle.end(), [](int t) { return t < 0; }));

  sh::rt::Scene inside;
  inside.name = "inside a box";
  inside.materials.push_back({});
  sh::rt::add_box(inside, {-1, -1, -1}, {1, 1, 1}, 0);
  sh::rt::add_sphere(inside, {0.3f, -0.2f, 0.1f}, 0.3f, 0, 24);
  inside.lights.push_back({{0, 0.8f, 0}, {1, 1, 1}});
  inside.camera = {{0, 0, 0.8f}, {0, 0, 0}, {0, 1, 0}, 60};
  sh::rt::RenderReport report;
  sh::rt::Renderer hit(inside, small("cpu", Accel::LazyOctree, {6, 2}));
  sh::rt::Image in = hit.render(&report);
  EXPECT_TRUE(std::all_of(in.triangle.begin(), in.triangle.end(), [](int t) { return t >= 0; }));
  EXPECT_GT(report.waves, 0u);
  expect_same_image(sh::rt::Renderer(inside, small("cpu", Accel::Grid)).render(), in, "inside a closed box");
}

}  // namespace

namespace {

// Every leaf of a tree by its place (level and corner), with its triangles.
std::map<std::array<int, 4>, std::vector<int>> leaves(const sh::rt::Octree& tree) {
  std::map<std::array<int, 4>, std::vector<int>> out;
  std::vector<std::pair<int, std::array<int, 4>>> todo{{0, {0, 0, 0, 0}}};
  while (!todo.empty()) {
    auto [node, at] = todo.back();
    todo.pop_back();
    int v = tree.nodes()[node];
    EXPECT_NE(v, 0) << "an unbuilt node after building everything";
    if (v >= 1) {
      int half = tree.resolution() >> (at[0] + 1);
      for (int c = 0; c < 8; ++c)
        todo.push_back({v + c, {at[0] + 1, at[1] + (c & 1) * half, at[2] + (c >> 1 & 1) * half, at[3] + (c >> 2 & 1) * half}});
      continue;
    }
    std::vector<int>& list = out[at];
    for (int k = -v - 2; v <= -2 && tree.triangles()[k] >= 0; ++k) list.push_back(tree.triangles()[k]);
  }
  return out;
}

// Independently of how the tree kept its lists: each leaf lists every
// triangle lying inside its box, and only triangles that reach into it.
void expect_leaves_hold_their_triangles(const sh::rt::Octree& tree) {
  const std::vector<Vec3>& p = tree.positions();
  Vec3 fine = tree.finest_cell(), lo = tree.bounds().lo;
  std::size_t inside_somewhere = 0;
  for (const auto& [at, list] : leaves(tree)) {
    float size = static_cast<float>(tree.resolution() >> at[0]);
    Vec3 box_lo = lo + Vec3{at[1] * fine.x, at[2] * fine.y, at[3] * fine.z};
    Vec3 box_hi = box_lo + Vec3{size * fine.x, size * fine.y, size * fine.z}, pad = 1e-3f * (box_hi - box_lo);
    std::set<int> listed(list.begin(), list.end());
    for (std::size_t t = 0; t < p.size() / 3; ++t) {
      Vec3 t_lo = sh::rt::min(sh::rt::min(p[3 * t], p[3 * t + 1]), p[3 * t + 2]);
      Vec3 t_hi = sh::rt::max(sh::rt::max(p[3 * t], p[3 * t + 1]), p[3 * t + 2]);
      bool inside = true, apart = false;
      for (int a = 0; a < 3; ++a) {
        inside = inside && t_lo[a] > box_lo[a] + pad[a] && t_hi[a] < box_hi[a] - pad[a];
        apart = apart || t_lo[a] > box_hi[a] + pad[a] || t_hi[a] < box_lo[a] - pad[a];
      }
      bool in_list = listed.count(static_cast<int>(t)) > 0;
      if (inside) ++inside_somewhere;
      ASSERT_TRUE(!inside || in_list) << "triangle " << t << " lies inside a leaf that does not list it";
      ASSERT_FALSE(apart && in_list) << "triangle " << t << " is listed in a leaf it does not reach";
    }
  }
  EXPECT_GT(inside_somewhere, p.size() / 3 / 2) << inside_somewhere << " of " << p.size() / 3 << "too few triangles inside a leaf for the check to mean much";
}

// Lazily, in a random order of small batches and walks towards random
// cells, so that the store of unbuilt nodes is compacted between batches
// that leave some of its entries alive.
void build_in_random_order(sh::rt::Octree& lazy) {
  std::mt19937 random(7);
  std::uniform_int_distribution<int> cell(0, lazy.resolution() - 1);
  for (int round = 0; !lazy.unbuilt().empty(); ++round) {
    std::vector<std::int32_t> unbuilt = lazy.unbuilt();
    std::shuffle(unbuilt.begin(), unbuilt.end(), random);
    unbuilt.resize((unbuilt.size() + 2) / 3);
    if (round % 2 == 0) {
      EXPECT_EQ(lazy.build(unbuilt), unbuilt.size());
      continue;
    }
    std::vector<std::int32_t> requests;
    for (std::int32_t node : unbuilt) requests.insert(requests.end(), {node, cell(random), cell(random), cell(random)});
    EXPECT_GE(lazy.build_towards(requests), unbuilt.size());
  }
  EXPECT_EQ(lazy.pending_bytes(), 0u);
}

TEST(LazyOctree, TheOrderNodesAreBuiltInDoesNotChangeThem) {
  sh::rt::Scene scene = sh::rt::builtin_scene("procedural", 3000);
  sh::rt::OctreeLimits limits{7, 3};
  sh::rt::Octree whole = sh::rt::Octree::full(scene, limits);
  sh::rt::Octree lazy = sh::rt::Octree::lazy(scene, limits);
  build_in_random_order(lazy);
  EXPECT_EQ(lazy.nodes().size(), whole.nodes().size());
  EXPECT_EQ(lazy.built_count(), whole.built_count());
  std::vector<std::uint64_t> lazy_keys = lazy.built_keys(), whole_keys = whole.built_keys();
  EXPECT_EQ(lazy_keys.size(), lazy.built_count());
  EXPECT_EQ(std::set<std::uint64_t>(lazy_keys.begin(), lazy_keys.end()), std::set<std::uint64_t>(whole_keys.begin(), whole_keys.end()));
  EXPECT_EQ(leaves(lazy), leaves(whole));
}

// Coarse leaves over a fine mesh, so that most triangles lie inside one.
TEST(LazyOctree, LeavesListTheTrianglesInsideThem) {
  sh::rt::Scene scene = sh::rt::builtin_scene("procedural", 20000);
  sh::rt::Octree lazy = sh::rt::Octree::lazy(scene, {4, 16});
  build_in_random_order(lazy);
  expect_leaves_hold_their_triangles(lazy);
}

}  // namespace
