// The benchmark kernels on every backend that can run them at speed (cpu,
// opencl), all threads, in one run: elements per second, plus each
// backend's cold build time (no cache of any kind) and cached build time
// (the in-process kernel cache).  Ratios go in BENCHMARKS.md.  The cold
// build is Backend::compile: for cpu the machine code; for opencl
// clBuildProgram and clCreateKernel, while PoCL makes a kernel's
// work-group function and machine code at its first launch, which the
// untimed first run of each `run/` benchmark pays and this leaves out.
#include <benchmark/benchmark.h>

#include <cstdlib>

#include "kernels.hpp"

namespace {

using namespace sh;

constexpr std::size_t kSaxpyN = 1 << 22;
constexpr int kMandelbrotSize = 512;
constexpr std::size_t kRays = 1 << 16;
constexpr int kBlurSize = 2048;

struct Case {
  Program program;
  std::vector<std::shared_ptr<detail::Buffer>> inputs, outputs;
  std::size_t items;
};

Attrib1f saxpy_a = 2.5f;

Case make_case(const std::string& kernel) {
  if (kernel == "saxpy") {
    Channel<Attrib1f> x(std::vector<float>(kSaxpyN, 1.0f)), y(std::vector<float>(kSaxpyN, 2.0f)), r(kSaxpyN);
    return {bench::saxpy_program(saxpy_a), {x, y}, {r}, kSaxpyN};
  }
  if (kernel == "mandelbrot") {
    Channel<Attrib2f> c(bench::mandelbrot_coordinates(kMandelbrotSize));
    Channel<Attrib1f> shade;
    return {bench::mandelbrot_program(), {c}, {shade}, static_cast<std::size_t>(kMandelbrotSize * kMandelbrotSize)};
  }
  if (kernel == "blur") {
    static Table2D<Attrib1f> image = [] {
      Table2D<Attrib1f> t(kBlurSize, kBlurSize);
      t.assign(bench::blur_image(kBlurSize, kBlurSize));
      return t;
    }();
    Channel<Attrib1f> out;
    out.shape(kBlurSize, kBlurSize);
    return {bench::blur_program(image), {}, {out}, static_cast<std::size_t>(kBlurSize) * kBlurSize};
  }
  static bench::TriangleScene scene = bench::triangle_scene(kRays);
  static Table1D<Attrib3f> vertices = [] {
    Table1D<Attrib3f> t(bench::kTriangles * 3);
    t.assign(scene.vertices);
    return t;
  }();
  Channel<Point3f> o(scene.origins);
  Channel<Vector3f> d(scene.directions);
  Channel<Attrib1f> t;
  return {bench::triangles_program(vertices), {o, d}, {t}, kRays * bench::kTriangles};
}

void run_kernel(benchmark::State& state, const std::string& kernel, const std::string& backend_name) {
  Case c = make_case(kernel);
  run(c.program, c.inputs, c.outputs, backend(backend_name));
  for (auto _ : state) run(c.program, c.inputs, c.outputs, backend(backend_name));
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * c.items));
}

void build_cold(benchmark::State& state, const std::string& kernel, const std::string& backend_name) {
  Case c = make_case(kernel);
  Backend& b = find_backend(backend_name);
  for (auto _ : state) benchmark::DoNotOptimize(bench::compile_cold(b, c.program, Options{}));
}

void build_cached(benchmark::State& state, const std::string& kernel, const std::string& backend_name) {
  Case c = make_case(kernel);
  kernel_for(c.program, backend(backend_name));
  for (auto _ : state) benchmark::DoNotOptimize(kernel_for(c.program, backend(backend_name)));
}

}  // namespace

int main(int argc, char** argv) {
  // A cold build means no compiler cache either: PoCL keeps one on disk.
  setenv("POCL_KERNEL_CACHE", "0", 1);
  for (const char* kernel : {"saxpy", "mandelbrot", "triangles", "blur"})
    for (const char* b : {"cpu", "opencl"}) {
      std::string k = kernel, n = b;
      benchmark::RegisterBenchmark(("run/" + k + "/" + n).c_str(), [k, n](benchmark::State& s) { run_kernel(s, k, n); })
          ->UseRealTime()
          ->Unit(benchmark::kMillisecond);
      benchmark::RegisterBenchmark(("build_cold/" + k + "/" + n).c_str(), [k, n](benchmark::State& s) { build_cold(s, k, n); })
          ->Unit(benchmark::kMillisecond);
      benchmark::RegisterBenchmark(("build_cached/" + k + "/" + n).c_str(),
                                   [k, n](benchmark::State& s) { build_cached(s, k, n); })
          ->Unit(benchmark::kMicrosecond);
    }
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
