// Accelerator builds are bounded where splitting cannot separate triangles:
// coincident and zero-area triangles, a scene far from the origin, large
// triangles in a soup.  The tests count work (nodes, references), never
// time; hits stay Embree's on every accelerator, a scaled scene builds the
// structure the unscaled one does, a lazy octree obeys the same bounds, and
// clean scenes are built as before, without a warning.
#include <gtest/gtest.h>

#include <functional>
#include <limits>
#include <random>

#include "helpers.hpp"

namespace {

using sh::rt::Accel;
using sh::rt::Vec3;

sh::rt::Scene with_light(sh::rt::Scene s, const std::string& name) {
  s.name = name;
  s.materials.push_back({});
  s.mesh.material.assign(s.mesh.triangles(), 0);
  s.mesh.normals.assign(s.mesh.positions.size(), Vec3{0, 0, 1});
  s.lights.push_back({{0, 5, 5}, {1, 1, 1}});
  return s;
}

void add_triangle(sh::rt::Scene& s, Vec3 a, Vec3 b, Vec3 c) { s.mesh.positions.insert(s.mesh.positions.end(), {a, b, c}); }

sh::rt::Scene coincident(int copies, float size = 1, Vec3 at = {0, 0, 0}) {
  sh::rt::Scene s;
  for (int i = 0; i < copies; ++i) add_triangle(s, at, at + Vec3{size, 0.2f * size, 0.1f * size}, at + Vec3{0.3f, 1, 0.7f} * size);
  return s;
}

// What every accelerator returns for random rays agrees with Embree.
void expect_embree_hits(const sh::rt::Scene& s) {
  rt_test::Rays rays = rt_test::random_rays(s, 400, 3);
  for (Accel accel : {Accel::Grid, Accel::Octree, Accel::LazyOctree, Accel::Bvh}) {
    rt_test::Agreement a = rt_test::compare_with_embree(s, rays, rt_test::trace(s, rays, "cpu", accel));
    EXPECT_EQ(a.unexplained(), 0u) << s.name << ", " << sh::rt::accel_name(accel);
  }
}

// Builds every node a lazy tree could be asked for, a few at a time in a
// random order, as rays would.
void build_lazily(sh::rt::Octree& tree) {
  std::mt19937 rng(5);
  for (std::vector<std::int32_t> todo = tree.unbuilt(); !todo.empty(); todo = tree.unbuilt()) {
    std::shuffle(todo.begin(), todo.end(), rng);
    todo.resize((todo.size() + 2) / 3);
    tree.build(todo);
  }
}

// Uncapped, 200 coincident triangles split to the depth limit wherever the
// triangle is (150 000 nodes, 11 million references at depth 8).
TEST(BoundedBuilds, CoincidentTrianglesMakeALeafNotADeepTree) {
  sh::rt::Scene s = with_light(coincident(200), "coincident");
  sh::rt::Octree tree = sh::rt::Octree::full(s, {});
  EXPECT_LE(tree.nodes().size(), 9u);
  EXPECT_LE(tree.references(), 8u * 200);
  EXPECT_GE(tree.unseparated(), 1u);
  EXPECT_NE(tree.warning().find("not separate"), std::string::npos) << tree.warning();
  sh::rt::Grid grid = sh::rt::build_grid(s);
  EXPECT_LE(grid.cell_triangles.size(), 64u * 200);
  expect_embree_hits(s);
}

// Small coincident triangles in a large scene: the tree goes down to them
// (one child holding all of them is a smaller box, worth splitting) and
// stops where a split no longer separates them, at any depth limit.
TEST(BoundedBuilds, CoincidentTrianglesInALargeSceneStopWhereTheySpreadOverChildren) {
  sh::rt::Scene s = coincident(200, 0.01f, {3.1f, 2.7f, 1.3f});
  add_triangle(s, {-10, -10, 0}, {10, -10, 0}, {10, 10, 8});
  add_triangle(s, {-10, -10, 0}, {10, 10, 8}, {-10, 10, 8});
  s = with_light(s, "coincident in a large scene");
  for (int depth : {8, 12, sh::rt::kMaxOctreeDepth}) {
    sh::rt::Octree tree = sh::rt::Octree::full(s, {depth, 4});
    EXPECT_LE(tree.nodes().size(), 1u + 8 * 8 * static_cast<std::size_t>(depth)) << "depth " << depth;
    EXPECT_LE(tree.references(), 8u * 202 + 2 * tree.nodes().size()) << "depth " << depth;
  }
  expect_embree_hits(s);
}

// Triangles of zero area (a loader's or a transform's) on one segment.
TEST(BoundedBuilds, ZeroAreaTrianglesOnOneSegment) {
  sh::rt::Scene s;
  for (int i = 0; i < 200; ++i) {
    float t = static_cast<float>(i) / 200;
    add_triangle(s, {0, 0, 0}, {1, 0.5f, 0.25f}, {t, 0.5f * t, 0.25f * t});
  }
  sh::rt::Octree tree = sh::rt::Octree::full(with_light(s, "segment"), {sh::rt::kMaxOctreeDepth, 1});
  EXPECT_LE(tree.nodes().size(), 9u);
  EXPECT_LE(tree.references(), 8u * 200);
}

sh::rt::Scene moved(const sh::rt::Scene& from, float scale, float offset) {
  sh::rt::Scene s = from;
  for (Vec3& p : s.mesh.positions) p = p * scale + Vec3{offset, offset, offset};
  return s;
}

// Single precision is relative: a scene scaled by 1e7 or 1e-7 builds the
// structure of the unscaled one, give or take a few triangles on a
// boundary (rounding of the scaled coordinates).
TEST(BoundedBuilds, AScaledSceneBuildsTheStructureTheUnscaledOneBuilds) {
  sh::rt::Scene base = sh::rt::builtin_scene("procedural", 5000);
  sh::rt::OctreeLimits limits{10, 4};
  sh::rt::Octree unscaled = sh::rt::Octree::full(base, limits);
  sh::rt::Grid unscaled_grid = sh::rt::build_grid(base);
  for (float scale : {1e7f, 1e-7f}) {
    sh::rt::Scene s = moved(base, scale, 0);
    sh::rt::Octree tree = sh::rt::Octree::full(s, limits);
    EXPECT_NEAR(static_cast<double>(tree.nodes().size()), static_cast<double>(unscaled.nodes().size()),
                0.01 * static_cast<double>(unscaled.nodes().size()))
        << "scale " << scale;
    EXPECT_NEAR(static_cast<double>(tree.references()), static_cast<double>(unscaled.references()),
                0.01 * static_cast<double>(unscaled.references()))
        << "scale " << scale;
    EXPECT_EQ(tree.warning(), "") << "scale " << scale;
    sh::rt::Grid grid = sh::rt::build_grid(s);
    EXPECT_EQ(grid.dims, unscaled_grid.dims) << "scale " << scale;
    EXPECT_NEAR(static_cast<double>(grid.cell_triangles.size()), static_cast<double>(unscaled_grid.cell_triangles.size()),
                0.01 * static_cast<double>(unscaled_grid.cell_triangles.size()))
        << "scale " << scale;
  }
}

// Far from the origin the cells reach the coordinates' rounding error and
// widened cells overlap: builds stop at the bounds and say so.
TEST(BoundedBuilds, ASceneFarFromTheOriginStaysWithinTheBudget) {
  sh::rt::Scene s = moved(sh::rt::builtin_scene("procedural", 5000), 1, 1e7f);
  sh::rt::Octree tree = sh::rt::Octree::full(s, {12, 4});
  EXPECT_LE(tree.references(), tree.reference_budget());
  EXPECT_LE(tree.reference_budget(), std::max<std::size_t>(sh::rt::kMinReferenceBudget, 64 * s.mesh.triangles()));
  EXPECT_NE(tree.warning(), "");
  sh::rt::Grid grid = sh::rt::build_grid(s);
  EXPECT_LE(grid.cell_triangles.size(), std::max<std::size_t>(sh::rt::kMinGridTests, 64 * s.mesh.triangles()) + grid.cells());
  EXPECT_NE(grid.warning, "");
}

// One large triangle in a thousand, over a soup of small ones: the grid's
// cells under the large ones' bounds would be the work; the grid is made
// coarser instead, and the octree keeps to its budget.
TEST(BoundedBuilds, LargeTrianglesInASoup) {
  sh::rt::Scene s;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> box(0, 40), near(-1, 1);
  for (int t = 0; t < 20000; ++t) {
    if (t % 100 == 0) {
      add_triangle(s, {box(rng), box(rng), box(rng)}, {box(rng), box(rng), box(rng)}, {box(rng), box(rng), box(rng)});
      continue;
    }
    Vec3 c{box(rng), box(rng), box(rng)};
    add_triangle(s, c + Vec3{near(rng), near(rng), near(rng)}, c + Vec3{near(rng), near(rng), near(rng)},
                 c + Vec3{near(rng), near(rng), near(rng)});
  }
  s = with_light(s, "soup");
  sh::rt::Grid grid = sh::rt::build_grid(s);
  EXPECT_LE(grid.cell_triangles.size(), 64u * 20000 + grid.cells());
  sh::rt::Octree tree = sh::rt::Octree::full(s, {12, 4});
  EXPECT_LE(tree.references(), tree.reference_budget());
  expect_embree_hits(s);
}

// Built on request, a lazy tree makes the same leaves where splits do not
// separate: the bounds act on the node being built.
TEST(BoundedBuilds, ALazyOctreeObeysTheSameBounds) {
  sh::rt::Scene s = coincident(200, 0.01f, {3.1f, 2.7f, 1.3f});
  add_triangle(s, {-10, -10, 0}, {10, -10, 0}, {10, 10, 8});
  s = with_light(s, "coincident, lazily");
  sh::rt::Octree whole = sh::rt::Octree::full(s, {12, 4});
  sh::rt::Octree lazy = sh::rt::Octree::lazy(s, {12, 4});
  build_lazily(lazy);
  EXPECT_EQ(lazy.nodes().size(), whole.nodes().size());
  EXPECT_EQ(lazy.references(), whole.references());
  EXPECT_EQ(lazy.unseparated(), whole.unseparated());
  EXPECT_GE(lazy.unseparated(), 1u);
}

// The bounds leave clean scenes alone: nothing said, the grid as asked.
TEST(BoundedBuilds, CleanScenesAreBuiltWithoutAWarning) {
  for (std::string name : {"cornell", "spheres", "procedural", "soft"}) {
    sh::rt::Scene s = sh::rt::builtin_scene(name, 20000);
    sh::rt::Octree tree = sh::rt::Octree::full(s, {});
    EXPECT_EQ(tree.warning(), "") << name;
    EXPECT_EQ(tree.over_budget(), 0u) << name;
    EXPECT_EQ(sh::rt::build_grid(s).warning, "") << name;
  }
}

// Built alone, without the renderer's check of the scene, every build still
// refuses a vertex that is not a finite number in the tracer's range, and
// names it.
TEST(BoundedBuilds, EveryBuildRefusesAVertexOutOfRangeByName) {
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  for (Vec3 bad : {Vec3{nan, 0, 0}, Vec3{0, inf, 0}, Vec3{0, 0, 2e18f}}) {
    sh::rt::Scene s = coincident(3);
    add_triangle(s, {0, 0, 0}, {1, 0, 0}, bad);
    s = with_light(s, "one vertex out of range");
    auto names_vertex = [](const std::function<void()>& build, const char* what) {
      try {
        build();
        ADD_FAILURE() << what << " built over a vertex out of range";
      } catch (const sh::Error& e) {
        EXPECT_NE(std::string(e.what()).find("triangle 3, vertex 2"), std::string::npos) << what << ": " << e.what();
      }
    };
    names_vertex([&] { sh::rt::build_bvh(s); }, "bvh");
    names_vertex([&] { sh::rt::build_grid(s); }, "grid");
    names_vertex([&] { sh::rt::Octree::full(s, {}); }, "octree");
    names_vertex([&] { sh::rt::Octree::lazy(s, {}); }, "lazy octree");
  }
}

}  // namespace
