// DSL kernels on the cpu backend, scalar and SPMD at each width, against
// the same kernels hand-written in scalar C++ (built -O3 -march=native), on
// one thread and on all, and the JIT's compile latency.  Arguments: threads,
// then lanes (1 = scalar).  Ratios go in BENCHMARKS.md.  The environment's
// CPU_BENCH_STORES (auto, cached, streamed) sets the DSL kernels' stores,
// so that one binary compares them.
#include <benchmark/benchmark.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <sh/cpu.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <map>
#include <memory>
#include <string>

#include "kernels.hpp"

namespace {

using namespace sh;

constexpr std::size_t kSaxpyN = 1 << 22;
constexpr int kMandelbrotSize = 512;
constexpr std::size_t kRays = 1 << 16;
constexpr int kBlurSize = 2048;

// The C++ forms' arrays come from the allocator of the DSL's tables and
// channels: each starts a cache line, so that a store of a vector at a
// multiple of its lanes is never split across two lines, and a large one
// starts at another place in its page than the one before, so that a
// store and the next loads do not share the low 12 bits of their
// addresses (which made a load wait for the store: BENCHMARKS.md, issue 25).
using Floats = std::vector<float, detail::CacheLineAllocator<float>>;

// Floating-point operations per Mandelbrot iteration as recorded: z*z's
// three products and two sums, 2*x*y + c's two products and a sum, the
// loop test's |z|^2 (two products, a sum) and the counter's increment.
constexpr double kMandelbrotFlopsPerIteration = 11;

// The rate of Mandelbrot's floating-point operations over the benchmark's
// iterations, from the per-pixel iteration counts one run produced.
template <class Shades>
void count_mandelbrot_flops(benchmark::State& state, const Shades& shade) {
  double iterations = 0;
  for (float i : shade) iterations += i;
  state.counters["flops"] = benchmark::Counter(kMandelbrotFlopsPerIteration * iterations * static_cast<double>(state.iterations()),
                                               benchmark::Counter::kIsRate);
}

Options with_lanes(std::int64_t lanes) {
  Options o;
  o.set(cpu::Options{.width = static_cast<cpu::Width>(lanes)});
  if (const char* stores = std::getenv("CPU_BENCH_STORES"); stores && *stores) o.set("cpu.stores", stores);
  return o;
}

BackendChoice cpu_with(const benchmark::State& state) {
  Options o = with_lanes(state.range(1));
  o.threads = static_cast<int>(state.range(0));
  return backend("cpu", o);
}

// One arena per thread count for the whole program, as the cpu backend
// keeps its own: an arena made per run would charge the C++ forms its
// threads' start on every run.
tbb::task_arena& arena_of(int threads) {
  static std::map<int, std::unique_ptr<tbb::task_arena>> arenas;
  std::unique_ptr<tbb::task_arena>& arena = arenas[threads];
  int concurrency = threads > 0 ? threads : int{tbb::task_arena::automatic};
  if (!arena) arena = std::make_unique<tbb::task_arena>(concurrency);
  return *arena;
}

// Runs body(begin, end) over n elements on `threads` threads (0 = all).
template <class F>
void hand_parallel(int threads, std::size_t n, F body) {
  arena_of(threads).execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1024),
                      [&](const tbb::blocked_range<std::size_t>& r) { body(r.begin(), r.end()); });
  });
}

// A form's results against the C++ form's: the compiler may fuse a
// multiply and an add (GCC's default contraction) where the DSL's precise
// f32 does not, so values agree to rounding, and a Mandelbrot pixel at the
// set's edge may take another iteration count.  A NaN is a difference.
template <class Values>
void check_close(benchmark::State& state, const Values& got, const std::vector<float>& cpp, double largest_relative,
                 double share_off, const char* form) {
  std::size_t off = got.size() == cpp.size() ? 0 : got.size() + cpp.size();
  for (std::size_t i = 0; i < std::min(got.size(), cpp.size()); ++i)
    off += !(std::fabs(got[i] - cpp[i]) <= largest_relative * std::max(1.0f, std::fabs(cpp[i])));
  if (static_cast<double>(off) > share_off * static_cast<double>(cpp.size()))
    state.SkipWithError((std::string(form) + " differs from the C++ form's").c_str());
}

// saxpy's inputs: x varies, so that a wrong element shows.
template <class V>
void saxpy_inputs(V& x, V& y) {
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = 0.001f * static_cast<float>(i % 1000), y[i] = 2.0f;
}

template <class V>
std::vector<float> saxpy_expected(const V& x, const V& y) {
  std::vector<float> r(x.size());
  bench::saxpy_cpp(2.5f, x.data(), y.data(), r.data(), 0, r.size());
  return r;
}

void BM_saxpy_dsl(benchmark::State& state) {
  Attrib1f a = 2.5f;
  Program p = bench::saxpy_program(a);
  std::vector<float> xs(kSaxpyN), ys(kSaxpyN);
  saxpy_inputs(xs, ys);
  Channel<Attrib1f> x(xs), y(ys), r(kSaxpyN);
  BackendChoice cpu = cpu_with(state);
  run(p, {x, y}, {r}, cpu);
  check_close(state, r.values(), saxpy_expected(xs, ys), 1e-6, 0, "the DSL kernel");
  for (auto _ : state) run(p, {x, y}, {r}, cpu);
  state.SetItemsProcessed(state.iterations() * kSaxpyN);
}

void BM_saxpy_cpp(benchmark::State& state) {
  Floats x(kSaxpyN, 1.0f), y(kSaxpyN, 2.0f), r(kSaxpyN);
  for (auto _ : state) {
    hand_parallel(static_cast<int>(state.range(0)), kSaxpyN,
                  [&](std::size_t b, std::size_t e) { bench::saxpy_cpp(2.5f, x.data(), y.data(), r.data(), b, e); });
    benchmark::DoNotOptimize(r.data());
  }
  state.SetItemsProcessed(state.iterations() * kSaxpyN);
}

void BM_mandelbrot_dsl(benchmark::State& state) {
  Program p = bench::mandelbrot_program();
  Channel<Attrib2f> c(bench::mandelbrot_coordinates(kMandelbrotSize));
  Channel<Attrib1f> shade;
  BackendChoice cpu = cpu_with(state);
  run(p, {c}, {shade}, cpu);
  std::vector<float> expected(shade.size());
  bench::mandelbrot_cpp(c.values().data(), expected.data(), 0, expected.size());
  check_close(state, shade.values(), expected, 0, 0.01, "the DSL kernel");
  for (auto _ : state) run(p, {c}, {shade}, cpu);
  state.SetItemsProcessed(state.iterations() * kMandelbrotSize * kMandelbrotSize);
  count_mandelbrot_flops(state, shade.values());
}

void BM_mandelbrot_cpp(benchmark::State& state) {
  std::vector<float> coordinates = bench::mandelbrot_coordinates(kMandelbrotSize);
  Floats c(coordinates.begin(), coordinates.end()), shade(c.size() / 2);
  for (auto _ : state) {
    hand_parallel(static_cast<int>(state.range(0)), shade.size(),
                  [&](std::size_t b, std::size_t e) { bench::mandelbrot_cpp(c.data(), shade.data(), b, e); });
    benchmark::DoNotOptimize(shade.data());
  }
  state.SetItemsProcessed(state.iterations() * shade.size());
  count_mandelbrot_flops(state, shade);
}

void BM_triangles_dsl(benchmark::State& state) {
  bench::TriangleScene s = bench::triangle_scene(kRays);
  Table1D<Attrib3f> vertices(bench::kTriangles * 3);
  vertices.assign(s.vertices);
  Program p = bench::triangles_program(vertices);
  Channel<Point3f> o(s.origins);
  Channel<Vector3f> d(s.directions);
  Channel<Attrib1f> t;
  BackendChoice cpu = cpu_with(state);
  run(p, {o, d}, {t}, cpu);
  std::vector<float> expected(kRays);
  bench::triangles_cpp(s, expected.data(), 0, kRays);
  check_close(state, t.values(), expected, 1e-4, 0.001, "the DSL kernel");
  for (auto _ : state) run(p, {o, d}, {t}, cpu);
  state.SetItemsProcessed(state.iterations() * kRays * bench::kTriangles);
}

void BM_triangles_cpp(benchmark::State& state) {
  bench::TriangleScene s = bench::triangle_scene(kRays);
  Floats t(kRays);
  for (auto _ : state) {
    hand_parallel(static_cast<int>(state.range(0)), kRays,
                  [&](std::size_t b, std::size_t e) { bench::triangles_cpp(s, t.data(), b, e); });
    benchmark::DoNotOptimize(t.data());
  }
  state.SetItemsProcessed(state.iterations() * kRays * bench::kTriangles);
}

// ---- the hand-vectorised forms of saxpy, Mandelbrot and the triangles ------------

void BM_saxpy_simd(benchmark::State& state) {
  Floats x(kSaxpyN), y(kSaxpyN), r(kSaxpyN);
  saxpy_inputs(x, y);
  std::vector<float> expected = saxpy_expected(x, y);
  auto saxpy = [&] {
    hand_parallel(static_cast<int>(state.range(0)), kSaxpyN,
                  [&](std::size_t b, std::size_t e) { bench::saxpy_simd(2.5f, x.data(), y.data(), r.data(), b, e); });
  };
  saxpy();
  check_close(state, r, expected, 1e-6, 0, "the hand-vectorised form");
  for (auto _ : state) {
    saxpy();
    benchmark::DoNotOptimize(r.data());
  }
  state.SetItemsProcessed(state.iterations() * kSaxpyN);
}

void BM_mandelbrot_simd(benchmark::State& state) {
  std::vector<float> c = bench::mandelbrot_coordinates(kMandelbrotSize), shade(c.size() / 2), expected(c.size() / 2);
  bench::mandelbrot_cpp(c.data(), expected.data(), 0, expected.size());
  auto mandelbrot = [&] {
    hand_parallel(static_cast<int>(state.range(0)), shade.size(),
                  [&](std::size_t b, std::size_t e) { bench::mandelbrot_simd(c.data(), shade.data(), b, e); });
  };
  mandelbrot();
  check_close(state, shade, expected, 0, 0.01, "the hand-vectorised form");
  for (auto _ : state) {
    mandelbrot();
    benchmark::DoNotOptimize(shade.data());
  }
  state.SetItemsProcessed(state.iterations() * shade.size());
  count_mandelbrot_flops(state, shade);
}

void BM_triangles_simd(benchmark::State& state) {
  bench::TriangleScene s = bench::triangle_scene(kRays);
  std::vector<float> t(kRays), expected(kRays);
  bench::triangles_cpp(s, expected.data(), 0, kRays);
  auto triangles = [&] {
    hand_parallel(static_cast<int>(state.range(0)), kRays,
                  [&](std::size_t b, std::size_t e) { bench::triangles_simd(s, t.data(), b, e); });
  };
  triangles();
  check_close(state, t, expected, 1e-4, 0.001, "the hand-vectorised form");
  for (auto _ : state) {
    triangles();
    benchmark::DoNotOptimize(t.data());
  }
  state.SetItemsProcessed(state.iterations() * kRays * bench::kTriangles);
}

// ---- the 5 x 5 blur over a 2048 x 2048 image -----------------------------------

struct BlurImages {
  Floats in = aligned(bench::blur_image(kBlurSize, kBlurSize));
  static Floats aligned(const std::vector<float>& v) { return Floats(v.begin(), v.end()); }
  Table2D<Attrib1f> image{kBlurSize, kBlurSize};
  BlurImages() { image.assign(std::vector<float>(in.begin(), in.end())); }
  // What the auto-vectorised C++ gives: every form must give these bits.
  std::vector<float> expected() const {
    std::vector<float> out(in.size());
    bench::blur_cpp({in.data(), out.data(), kBlurSize, kBlurSize}, 0, kBlurSize);
    return out;
  }
  // The separable forms add rows first: these bits.
  std::vector<float> separable_expected() const {
    std::vector<float> middle(in.size()), out(in.size());
    bench::blur_rows_cpp({in.data(), middle.data(), kBlurSize, kBlurSize}, 0, kBlurSize);
    bench::blur_columns_cpp({middle.data(), out.data(), kBlurSize, kBlurSize}, 0, kBlurSize);
    return out;
  }
};

// Whether `out` holds exactly `expected`, read in place: a copy of its
// values compared with != draws a false -Wfree-nonheap-object from g++ 12
// at -O3.
bool holds(const Channel<Attrib1f>& out, const std::vector<float>& expected) {
  return out.size() == expected.size() && std::equal(expected.begin(), expected.end(), out.data());
}

// The direct blur of the images' table on the benchmark's backend,
// compiled and checked against the C++ form's bits by its first run.
struct DslBlur {
  DslBlur(benchmark::State& state, const BlurImages& images)
      : program(bench::blur_program(images.image)), cpu(cpu_with(state)) {
    out.shape(kBlurSize, kBlurSize);
    run();
    if (!holds(out, images.expected())) state.SkipWithError("the blur differs from the C++ form's");
  }
  void run() { sh::run(program, {}, {out}, cpu); }
  Program program;
  BackendChoice cpu;
  Channel<Attrib1f> out;
};

void BM_blur_dsl(benchmark::State& state) {
  BlurImages images;
  DslBlur blur(state, images);
  for (auto _ : state) blur.run();
  state.SetItemsProcessed(state.iterations() * kBlurSize * kBlurSize);
}

// Rows into an image that the columns' program reads as a table, in place:
// the channel's memory is the table's.
void BM_blur_separable_dsl(benchmark::State& state) {
  BlurImages images;
  Channel<Attrib1f> rows, out;
  rows.shape(kBlurSize, kBlurSize);
  out.shape(kBlurSize, kBlurSize);
  Table2D<Attrib1f> rows_table(kBlurSize, kBlurSize);
  rows_table.memory(rows.memory());
  Program along = bench::blur_rows_program(images.image), down = bench::blur_columns_program(rows_table);
  BackendChoice cpu = cpu_with(state);
  auto blur = [&] {
    run(along, {}, {rows}, cpu);
    run(down, {}, {out}, cpu);
  };
  blur();
  if (!holds(out, images.separable_expected())) state.SkipWithError("the separable blur differs from the C++ form's");
  for (auto _ : state) blur();
  state.SetItemsProcessed(state.iterations() * kBlurSize * kBlurSize);
}

// The same two passes fused in strips of rows (run_fused): a strip's rows
// stay in the cache for its columns.  Checked against the separable C++.
void BM_blur_fused_dsl(benchmark::State& state) {
  BlurImages images;
  Channel<Attrib1f> out;
  out.shape(kBlurSize, kBlurSize);
  Table2D<Attrib1f> rows(kBlurSize, kBlurSize);
  Program along = bench::blur_rows_program(images.image), down = bench::blur_columns_program(rows);
  BackendChoice cpu = cpu_with(state);
  RunStats first = run_fused(along, rows, down, {out}, cpu);
  if (first.strips == 0) state.SkipWithError("the passes ran one after the other, not in strips");
  if (!holds(out, images.separable_expected())) state.SkipWithError("the fused blur differs from the separable C++ form's");
  for (auto _ : state) run_fused(along, rows, down, {out}, cpu);
  state.SetItemsProcessed(state.iterations() * kBlurSize * kBlurSize);
}

using BlurRows = void (*)(const bench::Image&, int, int);

// `separable`: the passes add rows first, and give the separable bits.
void blur_cpp(benchmark::State& state, std::initializer_list<BlurRows> passes, bool separable) {
  BlurImages images;
  Floats middle(images.in.size()), out(images.in.size());
  auto blur = [&] {
    const float* from = images.in.data();
    for (BlurRows pass : passes) {
      float* to = pass == *std::prev(passes.end()) ? out.data() : middle.data();
      hand_parallel(static_cast<int>(state.range(0)), kBlurSize, [&](std::size_t b, std::size_t e) {
        pass({from, to, kBlurSize, kBlurSize}, static_cast<int>(b), static_cast<int>(e));
      });
      from = to;
    }
  };
  blur();
  std::vector<float> want = separable ? images.separable_expected() : images.expected();
  if (!std::equal(out.begin(), out.end(), want.begin(), want.end()))
    state.SkipWithError("the blur differs from the C++ form's");
  for (auto _ : state) {
    blur();
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * kBlurSize * kBlurSize);
}

void BM_blur_plain_cpp(benchmark::State& state) { blur_cpp(state, {bench::blur_plain_cpp}, false); }
void BM_blur_cpp(benchmark::State& state) { blur_cpp(state, {bench::blur_cpp}, false); }
void BM_blur_simd(benchmark::State& state) { blur_cpp(state, {bench::blur_simd}, false); }
void BM_blur_separable_cpp(benchmark::State& state) {
  blur_cpp(state, {bench::blur_rows_cpp, bench::blur_columns_cpp}, true);
}
void BM_blur_separable_simd(benchmark::State& state) {
  blur_cpp(state, {bench::blur_rows_simd, bench::blur_columns_simd}, true);
}
void BM_blur_fused_cpp(benchmark::State& state) { blur_cpp(state, {bench::blur_fused_cpp}, true); }

// The direct blur and the C++ loop for the vectoriser in turns, each on
// its own image and output, so that both run under the same conditions:
// the host's other tenants and the caches (each run finds its data evicted
// by the other's).  Counters: each one's median run and their ratio (above
// 1: the DSL is faster).
void BM_blur_dsl_against_cpp(benchmark::State& state) {
  BlurImages images;
  DslBlur dsl(state, images);
  Floats cpp_in = images.in, cpp_out(images.in.size());
  auto cpp = [&] {
    hand_parallel(static_cast<int>(state.range(0)), kBlurSize, [&](std::size_t b, std::size_t e) {
      bench::blur_cpp({cpp_in.data(), cpp_out.data(), kBlurSize, kBlurSize}, static_cast<int>(b), static_cast<int>(e));
    });
  };
  auto ms_of = [](auto&& f) {
    auto t0 = std::chrono::steady_clock::now();
    f();
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  };
  std::vector<double> dsl_ms, cpp_ms;
  for (auto _ : state) {
    dsl_ms.push_back(ms_of([&] { dsl.run(); }));
    cpp_ms.push_back(ms_of(cpp));
    state.SetIterationTime((dsl_ms.back() + cpp_ms.back()) / 1000);
  }
  auto median = [](std::vector<double> v) {
    std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
    return v[v.size() / 2];
  };
  state.counters["dsl_ms"] = median(dsl_ms);
  state.counters["cpp_ms"] = median(cpp_ms);
  state.counters["cpp_over_dsl"] = median(cpp_ms) / median(dsl_ms);
}

// Optimisation passes + lowering + LLVM + machine code, uncached.
void compile_latency(benchmark::State& state, const Program& p) {
  Backend& cpu = find_backend("cpu");
  Options o = with_lanes(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(bench::compile_cold(cpu, p, o));
}

void BM_compile_saxpy(benchmark::State& state) {
  Attrib1f a = 2.0f;
  compile_latency(state, bench::saxpy_program(a));
}
void BM_compile_mandelbrot(benchmark::State& state) { compile_latency(state, bench::mandelbrot_program()); }
void BM_compile_triangles(benchmark::State& state) {
  Table1D<Attrib3f> vertices(bench::kTriangles * 3);
  compile_latency(state, bench::triangles_program(vertices));
}

}  // namespace

// Every width on one thread; scalar and the host's width on two.
void widths(benchmark::internal::Benchmark* b) {
  for (int lanes : {1, 4, 8, 16}) b->Args({1, lanes});
  b->Args({2, 1})->Args({2, 16})->ArgNames({"threads", "lanes"});
}

BENCHMARK(BM_saxpy_dsl)->Apply(widths)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_saxpy_cpp)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_mandelbrot_dsl)->Apply(widths)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_mandelbrot_cpp)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_triangles_dsl)->Apply(widths)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_triangles_cpp)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_saxpy_simd)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_mandelbrot_simd)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_triangles_simd)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_blur_dsl)->Apply(widths)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_blur_separable_dsl)->Apply(widths)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_blur_fused_dsl)->Apply(widths)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_blur_dsl_against_cpp)->Args({1, 16})->Args({1, 8})->Args({2, 16})->ArgNames({"threads", "lanes"})
    ->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_blur_plain_cpp)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_blur_cpp)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_blur_simd)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_blur_separable_cpp)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_blur_separable_simd)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_blur_fused_cpp)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_compile_saxpy)->Arg(1)->Arg(16)->ArgName("lanes")->Unit(benchmark::kMillisecond);
BENCHMARK(BM_compile_mandelbrot)->Arg(1)->Arg(16)->ArgName("lanes")->Unit(benchmark::kMillisecond);
BENCHMARK(BM_compile_triangles)->Arg(1)->Arg(16)->ArgName("lanes")->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
