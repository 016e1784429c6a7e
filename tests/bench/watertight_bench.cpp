// Watertightness at scale: rays aimed exactly at the vertices and edge
// midpoints of closed meshes (a UV sphere of 80 k triangles, a tessellated
// cube, a closed real model), from outside and inside, at the origin,
// translated to 1e3 and 1e5 and scaled by 1e-4 and 1e4; the rays that slip
// through, per backend, and Embree's in its default and robust modes on
// the same rays.  Usage: watertight_bench [rays per mesh and placement]
// [backends...]
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <closed_meshes.hpp>
#include <embree_scene.hpp>
#include <sh/sh.hpp>

namespace {

constexpr const char* kClosedModel = "/usr/share/assimp/models/Collada/duck.dae";

struct Tally {
  std::size_t rays = 0, leaks = 0;
  double ms = 0;
};

std::vector<float> embree_nearest(const sh::rt::Scene& s, const watertight::AimedRays& rays, bool robust) {
  sh::rt::EmbreeScene embree(s, "threads=1", robust);
  std::vector<float> t(rays.size());
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const float* o = &rays.origins[3 * i];
    const float* d = &rays.directions[3 * i];
    RTCRayHit h = embree.intersect({o[0], o[1], o[2]}, {d[0], d[1], d[2]});
    t[i] = h.hit.geomID == RTC_INVALID_GEOMETRY_ID ? -1.0f : h.ray.tfar;
  }
  return t;
}

void add(Tally& tally, const watertight::AimedRays& rays, const std::vector<float>& t, double ms) {
  tally.rays += rays.size();
  tally.leaks += watertight::leaks(rays, t);
  tally.ms += ms;
}

template <class F>
double timed(F&& f) {
  auto t0 = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

int main(int argc, char** argv) {
  std::size_t per = argc > 1 ? std::strtoull(argv[1], nullptr, 10) : 70000;
  std::vector<std::string> backends;
  for (int i = 2; i < argc; ++i) backends.push_back(argv[i]);
  if (backends.empty()) backends = sh::backend_names();
  const std::pair<float, float> placements[] = {{1, 0}, {1, 1e3f}, {1, 1e5f}, {1e-4f, 0}, {1e4f, 0}};
  std::vector<watertight::ClosedMesh> meshes = {watertight::uv_sphere(284), watertight::tessellated_cube(40),
                                                watertight::closed_model(kClosedModel)};
  std::vector<Tally> ours(backends.size());
  Tally embree_default, embree_robust;
  std::printf("%-44s %8s", "mesh and placement", "rays");
  for (const std::string& b : backends) std::printf(" %8s", b.c_str());
  std::printf(" %8s %8s   (leaks)\n", "embree", "robust");
  for (const watertight::ClosedMesh& base : meshes)
    for (auto [scale, offset] : placements) {
      watertight::ClosedMesh m = watertight::transformed(base, scale, offset);
      watertight::AimedRays rays = watertight::aimed_rays(m, per, 1);
      std::printf("%-44s %8zu", m.name.c_str(), rays.size());
      sh::rt::Renderer renderer(m.scene, sh::rt::RenderSettings{});
      for (std::size_t b = 0; b < backends.size(); ++b) {
        sh::Options one_thread;
        one_thread.threads = 1;
        sh::BackendChoice backend = sh::backend(backends[b], one_thread);
        renderer.intersect(rays.origins, rays.directions, backend);  // compiled, warm
        std::vector<float> t;
        double ms = timed([&] { t = renderer.intersect(rays.origins, rays.directions, backend).t; });
        add(ours[b], rays, t, ms);
        std::printf(" %8zu", watertight::leaks(rays, t));
      }
      std::vector<float> t;
      double ms = timed([&] { t = embree_nearest(m.scene, rays, false); });
      add(embree_default, rays, t, ms);
      std::printf(" %8zu", watertight::leaks(rays, t));
      ms = timed([&] { t = embree_nearest(m.scene, rays, true); });
      add(embree_robust, rays, t, ms);
      std::printf(" %8zu\n", watertight::leaks(rays, t));
      std::fflush(stdout);
    }
  std::printf("\ntotals (rays, leaks, leak rate, ms for the batches incl. Embree's build)\n");
  auto total = [](const char* name, const Tally& t) {
    std::printf("  %-10s %9zu rays %6zu leaks %8.4f %% %9.0f ms\n", name, t.rays, t.leaks,
                t.rays ? 100.0 * static_cast<double>(t.leaks) / static_cast<double>(t.rays) : 0.0, t.ms);
  };
  for (std::size_t b = 0; b < backends.size(); ++b) total(backends[b].c_str(), ours[b]);
  total("embree", embree_default);
  total("robust", embree_robust);
  std::size_t leaks = 0;
  for (const Tally& t : ours) leaks += t.leaks;
  return leaks == 0 ? 0 : 1;
}
