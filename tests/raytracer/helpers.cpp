#include "helpers.hpp"

#include <unistd.h>

#include <cmath>
#include <fstream>

namespace rt_test {

void FilesTest::SetUp() {
  const testing::TestInfo* test = testing::UnitTest::GetInstance()->current_test_info();
  dir_ = std::filesystem::temp_directory_path() /
         ("sh_" + std::string(test->test_suite_name()) + "_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir_);
}

void FilesTest::TearDown() { std::filesystem::remove_all(dir_); }

std::string FilesTest::write(const std::string& name, const std::string& bytes) {
  std::string path = (dir_ / name).string();
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

using sh::rt::Vec3;

Rays random_rays(const sh::rt::Scene& scene, std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  Vec3 lo = scene.bounds_min(), hi = scene.bounds_max(), centre = (lo + hi) * 0.5f;
  Vec3 extent = hi - lo;
  float radius = std::max(sh::rt::length(extent), 1e-30f);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  Rays rays;
  for (std::size_t i = 0; i < n; ++i) {
    // Half from outside the bounds, half from inside.
    Vec3 o;
    if (i % 2 == 0) {
      Vec3 dir = sh::rt::normalize({u(rng) - 0.5f, u(rng) - 0.5f, u(rng) - 0.5f});
      o = centre + dir * radius;
    } else {
      o = lo + Vec3{extent.x * u(rng), extent.y * u(rng), extent.z * u(rng)};
    }
    Vec3 target = lo + Vec3{extent.x * u(rng), extent.y * u(rng), extent.z * u(rng)};
    Vec3 d = sh::rt::normalize(target - o);
    if (sh::rt::length(d) == 0) d = {0, 0, 1};
    rays.add(o, d);
  }
  return rays;
}

std::string Walked::name() const {
  std::string n = sh::rt::accel_name(accel);
  if (accel != sh::rt::Accel::Bvh || walk == sh::rt::BvhWalk::Threaded) return n;
  return n + "-" + sh::rt::bvh_walk_name(walk) + (large ? "-large" : "");
}

sh::rt::RenderSettings Walked::settings() const {
  sh::rt::RenderSettings s;
  s.accel = accel;
  s.bvh.walk = walk;
  if (large) {
    s.bvh.prefetch_above = 0;
    s.bvh.node_cost = sh::rt::kBvhLargeTreeNodeCost;
  }
  return s;
}

std::vector<Walked> every_accelerator() {
  using sh::rt::Accel;
  return {Accel::Grid, Accel::Octree, Accel::LazyOctree, Accel::Bvh, {Accel::Bvh, sh::rt::BvhWalk::Stack},
          {Accel::Bvh, sh::rt::BvhWalk::Wide}, {Accel::Bvh, sh::rt::BvhWalk::Wide, true}};
}

Hits trace(const sh::rt::Scene& scene, const Rays& rays, const std::string& backend, Walked accel) {
  sh::rt::Renderer r(scene, accel.settings());
  return r.intersect(rays.origins, rays.directions, sh::backend(backend));
}

namespace {

// Barycentrics (in double) of where the ray meets triangle `k`'s plane.
bool near_edge(const sh::rt::Scene& s, int k, Vec3 o, Vec3 d, double tolerance) {
  auto dv = [](Vec3 v) { return std::array<double, 3>{v.x, v.y, v.z}; };
  auto a = dv(s.mesh.positions[3 * k]), b = dv(s.mesh.positions[3 * k + 1]), c = dv(s.mesh.positions[3 * k + 2]);
  auto sub = [](auto x, auto y) { return std::array<double, 3>{x[0] - y[0], x[1] - y[1], x[2] - y[2]}; };
  auto crs = [](auto x, auto y) {
    return std::array<double, 3>{x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2], x[0] * y[1] - x[1] * y[0]};
  };
  auto dt = [](auto x, auto y) { return x[0] * y[0] + x[1] * y[1] + x[2] * y[2]; };
  auto e1 = sub(b, a), e2 = sub(c, a), dd = dv(d), p = crs(dd, e2);
  double det = dt(e1, p);
  if (det == 0) return true;
  auto sv = sub(dv(o), a);
  double u = dt(sv, p) / det;
  auto q = crs(sv, e1);
  double v = dt(dd, q) / det;
  return std::min({std::fabs(u), std::fabs(v), std::fabs(1 - u - v)}) < tolerance;
}

}  // namespace

Agreement compare_with_embree(const sh::rt::Scene& scene, const Rays& rays, const Hits& ours) {
  oracle::Embree embree(scene);
  // t agrees within 1e-4 relative, or within what the coordinates' own
  // precision allows for a ray starting on or near a surface.
  float slack = 1e-5f * sh::rt::length(scene.bounds_max() - scene.bounds_min()) +
                1e-6f * std::max(sh::rt::length(scene.bounds_max()), sh::rt::length(scene.bounds_min()));
  Agreement a;
  a.rays = rays.size();
  for (std::size_t i = 0; i < rays.size(); ++i) {
    Vec3 o = rays.origin(i), d = rays.direction(i);
    oracle::Hit e = embree.intersect(o, d);
    float t = ours.t[i];
    int tri = ours.triangle[i];
    bool we_hit = t >= 0, they_hit = e.t >= 0;
    auto close = [&](float x, float y) { return std::fabs(x - y) <= 1e-4f * std::max(std::fabs(x), std::fabs(y)) + slack; };
    if ((!we_hit && !they_hit) || (we_hit && they_hit && tri == e.triangle && close(t, e.t))) {
      ++a.agree;
    } else if (we_hit && they_hit && close(t, e.t)) {
      ++a.ties;  // two triangles at the same distance (a shared edge or vertex)
    } else if ((we_hit && !they_hit && near_edge(scene, tri, o, d, 2e-5)) ||
               (!we_hit && they_hit && near_edge(scene, e.triangle, o, d, 2e-5))) {
      ++a.edge_grazes;
    } else if ((they_hit && e.t <= slack) || (we_hit && t <= slack)) {
      ++a.starts_on_surface;
    } else if (a.disagreements.size() < 5) {
      a.disagreements.push_back("ray " + std::to_string(i) + ": ours t=" + std::to_string(t) + " tri " +
                                std::to_string(tri) + ", Embree t=" + std::to_string(e.t) + " tri " +
                                std::to_string(e.triangle));
    }
  }
  return a;
}

std::vector<std::string> every_backend() { return sh::backend_names(); }

std::vector<std::string> backends_beside_interp() {
  std::vector<std::string> out;
  for (const std::string& b : sh::backend_names())
    if (b != "interp") out.push_back(b);
  return out;
}

}  // namespace rt_test
