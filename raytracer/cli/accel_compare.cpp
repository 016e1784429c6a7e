#include "accel_compare.hpp"

#include <chrono>
#include <cstdio>
#include <set>

namespace shtrace {

using namespace sh::rt;

void print_lazy_builds(const RenderReport& r) {
  if (r.refined.empty()) return;
  std::printf("lazy octree: %zu waves after the first, %zu element runs in them, %.1f ms building on rank 0\n", r.waves,
              r.resumed, r.build_ms);
  std::vector<std::vector<std::uint64_t>> keys;
  for (std::size_t part = 0; part < r.refined.size(); ++part) {
    OctreeSummary s = OctreeSummary::read(r.refined[part]);
    std::printf("  rank %zu: %zu nodes built, %zu nodes in all, %.2f MiB (+ %.2f MiB of lists for unbuilt nodes)\n", part,
                s.built.size(), s.nodes, s.bytes / 1048576.0, s.pending_bytes / 1048576.0);
    keys.push_back(std::move(s.built));
  }
  if (keys.size() < 2) return;
  BuildOverlap o = build_overlap(keys);
  std::size_t total = 0;
  for (std::size_t n : o.per_part) total += n;
  std::printf("  overlap: %zu distinct nodes built, %zu of them by more than one rank (%.1f %%); %zu builds in all (%.2fx the distinct)\n",
              o.distinct, o.shared, o.distinct ? 100.0 * o.shared / o.distinct : 0.0, total,
              o.distinct ? static_cast<double>(total) / o.distinct : 0.0);
}

namespace {

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

double visible_share(const Image& image, std::size_t triangles) {
  std::set<std::int32_t> seen(image.triangle.begin(), image.triangle.end());
  seen.erase(-1);
  return static_cast<double>(seen.size()) / static_cast<double>(triangles);
}

}  // namespace

int compare_accelerators(AccelOptions o) {
  if (o.view == "half") {
    // Turned towards one side of the scene, with a narrower field of view.
    Camera& c = o.scene.camera;
    Vec3 side = normalize(cross(c.look_at - c.eye, c.up));
    c.look_at = c.look_at - side * (0.25f * length(o.scene.bounds_max() - o.scene.bounds_min()));
    c.fov_degrees *= 0.75f;
  } else if (o.view != "full") {
    throw sh::Error("--view must be full or half, not '" + o.view + "'");
  }
  std::printf("scene %s, %zu triangles, %dx%d, view %s, octree depth %d, leaves of %d\n", o.scene.name.c_str(),
              o.scene.mesh.triangles(), o.settings.width, o.settings.height, o.view.c_str(), o.settings.octree.max_depth,
              o.settings.octree.leaf_size);
  std::printf("%-12s %10s %10s %11s %11s %12s %12s %9s %10s\n", "accelerator", "nodes", "MiB", "build ms", "first ms",
              "warm ms", "2nd builds", "waves", "visible");
  for (Accel a : {Accel::Grid, Accel::Octree, Accel::LazyOctree, Accel::Bvh}) {
    RenderSettings s = o.settings;
    s.accel = a;
    auto t0 = std::chrono::steady_clock::now();
    Renderer r(o.scene, s);
    RenderReport first, warm;
    Image image = r.render(&first);
    double first_ms = ms_since(t0);
    std::size_t built = r.octree() ? r.octree()->built_count() : 0;
    r.render(&warm);
    std::size_t second = r.octree() ? r.octree()->built_count() - built : 0;
    std::size_t nodes = r.grid() ? r.grid()->cells() : r.bvh() ? r.bvh()->nodes() : r.octree()->nodes().size();
    double build_ms = r.accelerator_build_ms();
    std::printf("%-12s %10zu %10.2f %11.1f %11.1f %12.1f %12zu %9zu %9.1f%%\n", accel_name(a), nodes,
                r.accelerator_bytes() / 1048576.0, build_ms, first_ms, warm.render_ms, second, first.waves,
                100 * visible_share(image, o.scene.mesh.triangles()));
    if (first.compile_from_disk)
      std::printf("  first ms: the kernels' machine code loaded from the disk cache, not compiled (SH_CACHE_DIR=off "
                  "compiles)\n");
    if (a == Accel::LazyOctree) print_lazy_builds(first);
  }
  return 0;
}

}  // namespace shtrace
