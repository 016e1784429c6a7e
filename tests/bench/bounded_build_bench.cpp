// Accelerator builds at the edges, for BENCHMARKS.md ("Bounded builds"):
//   bounded_build_bench CASE [grid|octree|all] [--depth D] [--leaf L]
// CASE: coincident (200 copies of one triangle), sliver (200 zero-area
// triangles on one segment), procedural, procedural-1e7, procedural-1e-7
// (the built-in procedural scene of 70 000 triangles, coordinates scaled),
// procedural-far (translated by 1e7), soup (10^6 random triangles in a
// box, one in a thousand as large as the box).  Prints the build time,
// the structure's size and what a cap changed.  One case per process, so
// that a runaway build can be stopped from outside (timeout).
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>

#include <sh/raytracer.hpp>

namespace {

using namespace sh::rt;

Scene coincident() {
  Scene s;
  for (int i = 0; i < 200; ++i) s.mesh.positions.insert(s.mesh.positions.end(), {{0, 0, 0}, {1, 0.2f, 0.1f}, {0.3f, 1, 0.7f}});
  return s;
}

// Zero-area triangles (what a loader might let through): all on one segment.
Scene sliver() {
  Scene s;
  for (int i = 0; i < 200; ++i) {
    float t = static_cast<float>(i) / 200;
    s.mesh.positions.insert(s.mesh.positions.end(), {{0, 0, 0}, {1, 0.5f, 0.25f}, {t, 0.5f * t, 0.25f * t}});
  }
  return s;
}

Scene transformed(float scale, float offset) {
  Scene s = builtin_scene("procedural", 70000);
  for (Vec3& p : s.mesh.positions) p = p * scale + Vec3{offset, offset, offset};
  return s;
}

// Small triangles (edges about the mean spacing) and a few as large as the box.
Scene soup(std::size_t n) {
  Scene s;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> box(0, 100), near(-1, 1);
  s.mesh.positions.reserve(3 * n);
  for (std::size_t t = 0; t < n; ++t) {
    if (t % 1000 == 0) {
      for (int k = 0; k < 3; ++k) s.mesh.positions.push_back({box(rng), box(rng), box(rng)});
      continue;
    }
    Vec3 c{box(rng), box(rng), box(rng)};
    for (int k = 0; k < 3; ++k) s.mesh.positions.push_back(c + Vec3{near(rng), near(rng), near(rng)});
  }
  return s;
}

Scene make(const std::string& name) {
  if (name == "coincident") return coincident();
  if (name == "sliver") return sliver();
  if (name == "procedural") return transformed(1, 0);
  if (name == "procedural-1e7") return transformed(1e7f, 0);
  if (name == "procedural-1e-7") return transformed(1e-7f, 0);
  if (name == "procedural-far") return transformed(1, 1e7f);
  if (name == "soup") return soup(1'000'000);
  std::fprintf(stderr, "unknown case '%s'\n", name.c_str());
  std::exit(2);
}

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: bounded_build_bench CASE [grid|octree|all] [--depth D] [--leaf L]\n");
    return 2;
  }
  std::string name = argv[1], which = argc > 2 && argv[2][0] != '-' ? argv[2] : "all";
  OctreeLimits limits;
  for (int i = 2; i + 1 < argc; ++i) {
    if (std::string(argv[i]) == "--depth") limits.max_depth = std::atoi(argv[i + 1]);
    if (std::string(argv[i]) == "--leaf") limits.leaf_size = std::atoi(argv[i + 1]);
  }
  Scene scene = make(name);
  std::size_t n = scene.mesh.triangles();
  if (which == "grid" || which == "all") {
    auto t0 = std::chrono::steady_clock::now();
    Grid g = build_grid(scene);
    std::printf("%-16s %8zu triangles  grid   %9.1f ms  %dx%dx%d cells, %zu references%s%s\n", name.c_str(), n, ms_since(t0),
                g.dims[0], g.dims[1], g.dims[2], g.cell_triangles.size(), g.warning.empty() ? "" : "; ", g.warning.c_str());
  }
  if (which == "octree" || which == "all") {
    auto t0 = std::chrono::steady_clock::now();
    Octree tree = Octree::full(scene, limits);
    std::printf("%-16s %8zu triangles  octree %9.1f ms  depth %d, leaves of %d: %zu nodes, %zu references%s%s\n", name.c_str(),
                n, ms_since(t0), limits.max_depth, limits.leaf_size, tree.nodes().size(), tree.triangles().size(),
                tree.warning().empty() ? "" : "; ", tree.warning().c_str());
  }
  return 0;
}
