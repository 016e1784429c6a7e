// Stencils of random taps over random grids, on the cpu backend at every
// width and on one thread and two, against the interp backend's run of the
// same program: the lowering's paths for a stencil (batches inside their
// tables alone or two rows at a time, a row's edges, calls that start and
// end inside a row, layers) meet shapes that no hand-written case names.
// The tables hold small whole numbers, so every sum is exact and the runs
// agree bit for bit.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "sh/cpu.hpp"
#include "sh/sh.hpp"

namespace {

using namespace sh;

struct Grid {
  int w, h, d;
};

class RandomStencil {
 public:
  explicit RandomStencil(std::mt19937& rng) : rng_(rng) {
    grid_ = {between(1, 90), between(1, 48), between(1, 3)};
    int table_w = std::max(1, grid_.w + between(-3, 3)), table_h = std::max(1, grid_.h + between(-2, 2));
    image_ = Table2D<Attrib1f>(table_w, table_h);
    colour_ = Table2D<Attrib3f>(table_w, table_h);
    Edge edges[] = {Edge::Clamp, Edge::Zero, Edge::Repeat};
    image_.edge(edges[between(0, 2)]);
    colour_.edge(edges[between(0, 2)]);
    image_.assign(whole_numbers(table_w * table_h));
    colour_.assign(whole_numbers(3 * table_w * table_h));
    for (int k = between(1, 9); k > 0; --k) taps_.emplace_back(between(-3, 3), between(-3, 3));
    colour_tap_ = {between(-3, 3), between(-3, 3)};
  }

  Program program(const std::string& name) const {
    return SH_BEGIN_PROGRAM(name.c_str()) {
      OutputAttrib1f sum;
      OutputAttrib3f colour;
      Attrib3i at = position<3>();
      Attrib2i xy = at(0, 1);
      sum = 0.0f;
      for (auto [dx, dy] : taps_) sum += image_[xy + ConstAttrib2i(dx, dy)];
      colour = colour_[xy + ConstAttrib2i(colour_tap_.first, colour_tap_.second)];
    } SH_END;
  }

  // The outputs' values from a run of `p` on `choice`.
  std::pair<std::vector<float>, std::vector<float>> run_on(const Program& p, const BackendChoice& choice) const {
    Channel<Attrib1f> sum;
    Channel<Attrib3f> colour;
    sum.shape(static_cast<std::size_t>(grid_.w), static_cast<std::size_t>(grid_.h), static_cast<std::size_t>(grid_.d));
    run(p, {}, {sum, colour}, choice);
    return {sum.values(), colour.values()};
  }

  std::string describe() const {
    std::string s = std::to_string(grid_.w) + "x" + std::to_string(grid_.h) + "x" + std::to_string(grid_.d);
    s += ", table " + std::to_string(image_.dims()[0]) + "x" + std::to_string(image_.dims()[1]) + ", taps";
    for (auto [dx, dy] : taps_) s += " (" + std::to_string(dx) + ", " + std::to_string(dy) + ")";
    return s;
  }

 private:
  int between(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng_); }
  std::vector<float> whole_numbers(int n) {
    std::vector<float> v;
    for (int i = 0; i < n; ++i) v.push_back(static_cast<float>(between(0, 15)));
    return v;
  }

  std::mt19937& rng_;
  Grid grid_{};
  Table2D<Attrib1f> image_{1, 1};
  Table2D<Attrib3f> colour_{1, 1};
  std::vector<std::pair<int, int>> taps_;
  std::pair<int, int> colour_tap_;
};

TEST(CpuStencils, RandomTapsOverRandomGridsGiveTheInterpretersValues) {
  std::mt19937 rng(2026);  // grids up to 90 x 48 x 3: calls of one thread hold several rows
  for (int round = 0; round < 16; ++round) {
    RandomStencil stencil(rng);
    Program p = stencil.program("random_stencil_" + std::to_string(round));
    auto reference = stencil.run_on(p, backend("interp"));
    for (cpu::Width width : {cpu::Width::Scalar, cpu::Width::Lanes4, cpu::Width::Lanes8, cpu::Width::Lanes16})
      for (int threads : {1, 2}) {
        Options o;
        o.threads = threads;
        o.set(cpu::Options{.width = width});
        auto got = stencil.run_on(p, backend("cpu", o));
        std::string where = stencil.describe() + ", width " + cpu::Options{.width = width}.settings()["width"] + ", " +
                            std::to_string(threads) + " threads";
        ASSERT_EQ(got.first, reference.first) << where;
        ASSERT_EQ(got.second, reference.second) << where;
      }
  }
}

}  // namespace
