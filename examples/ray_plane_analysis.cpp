// The cost analysis on the paper's ray-plane kernel: operation counts, the
// critical path with 1, 3 and 9 multipliers, and the paper's Table 2 (one
// ray against 100..1000 planes) from those figures.
#include <algorithm>
#include <cstdio>
#include <vector>

#include "ray_plane.hpp"

int main() {
  using namespace sh;
  using analysis::Unit;
  Program p = ray_plane_program();
  analysis::Cost cost = analysis::count_operations(p.ir());
  std::printf("ray-plane kernel, as recorded: %s\n", cost.outside_loops.describe().c_str());

  // The paper's latencies: t_m = 4 loops (stated); t_a = 1 and
  // t_d + 2 t_l = 11 follow from its tables; we take t_d = 9, t_l = 1.
  analysis::Machine m;
  m.latency = {4, 1, 9, 1, 1, 1, 1};
  m.one_at_a_time = true;
  std::uint64_t sequential = analysis::critical_path(p.ir(), m);
  m.one_at_a_time = false;
  m.units = {3, 1, 1, 1, 1, 1, 1};
  std::uint64_t three = analysis::critical_path(p.ir(), m);
  m.units = {9, 3, 1, 1, 1, 1, 1};
  std::uint64_t nine = analysis::critical_path(p.ir(), m);
  m.units = {0, 0, 0, 0, 0, 0, 0};
  std::uint64_t unbounded = analysis::critical_path(p.ir(), m);
  std::printf("cycles per plane: one unit for everything %llu; 3 multipliers %llu; 9 multipliers, 3 adders %llu; unbounded %llu\n",
              static_cast<unsigned long long>(sequential), static_cast<unsigned long long>(three),
              static_cast<unsigned long long>(nine), static_cast<unsigned long long>(unbounded));

  // The paper's per-ray cost (29 t_m + 26 t_a sequential, 10 t_m + 9 t_a
  // and 4 t_m + 7 t_a in parallel) is not a kernel it shows; it is added as
  // printed so that the columns compare.
  const std::uint64_t ray[] = {29 * 4 + 26, 10 * 4 + 9, 4 * 4 + 7};
  const std::uint64_t plane[] = {sequential, three, nine};
  std::printf("\n| planes | sequential | 3 multipliers | decrease | 9 multipliers | decrease |\n|---|---|---|---|---|---|\n");
  for (int n = 100; n <= 1000; n += 100) {
    std::uint64_t s = ray[0] + n * plane[0], a = ray[1] + n * plane[1], b = ray[2] + n * plane[2];
    std::printf("| %d | %llu | %llu | %.2f %% | %llu | %.2f %% |\n", n, static_cast<unsigned long long>(s),
                static_cast<unsigned long long>(a), 100.0 * (s - a) / s, static_cast<unsigned long long>(b),
                100.0 * (s - b) / s);
  }

  // The counts against time: the kernel over a million rays and planes on
  // each backend (warm), in nanoseconds per element and per counted op.
  std::size_t n = 1 << 20;
  std::vector<float> a(3 * n), b(3 * n), c(3 * n), d(3 * n);
  for (std::size_t i = 0; i < 3 * n; ++i) {
    a[i] = 0.001f * static_cast<float>(i % 997);
    b[i] = 1.0f + 0.001f * static_cast<float>(i % 991);
    c[i] = 0.5f + 0.002f * static_cast<float>(i % 983);
    d[i] = 3.0f + 0.001f * static_cast<float>(i % 977);
  }
  Channel<Point3f> o(a), p0(d);
  Channel<Vector3f> v(b);
  Channel<Normal3f> nn(c);
  Channel<Attrib1f> t;
  std::uint64_t ops = cost.outside_loops.total();
  std::printf("\n| backend | ns per element | ns per counted op |\n|---|---|---|\n");
  for (const std::string& name : backend_names()) {
    if (name == "mpi") continue;
    run(p, {o, v, nn, p0}, {t}, backend(name));
    double ms = 1e30;
    for (int r = 0; r < 3; ++r) ms = std::min(ms, run(p, {o, v, nn, p0}, {t}, backend(name)).run_ms);
    std::printf("| %s | %.3f | %.4f |\n", name.c_str(), ms * 1e6 / n, ms * 1e6 / n / ops);
  }
  return 0;
}
