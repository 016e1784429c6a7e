// A table's edge mode: what a read outside it gives.  Clamp (the default,
// tables.cpp) takes the nearest element; repeat wraps the coordinates
// around, as a tiled texture, however far outside they are; zero gives 0.
// Read at scattered coordinates, by [0, 1] coordinates, and as a stencil
// whose runs of consecutive coordinates cross the table's edges mid-batch.
#include <algorithm>
#include <cstdint>
#include <limits>

#include "harness.hpp"

namespace conformance {
namespace {

using sh::Attrib1f;
using sh::Attrib1i;
using sh::Attrib2i;
using sh::Attrib3i;

// The coordinate a read lands on, or -1 where zero is read.
int landing(long long v, int n, sh::Edge edge) {
  switch (edge) {
    case sh::Edge::Clamp: return static_cast<int>(std::min<long long>(std::max<long long>(v, 0), n - 1));
    case sh::Edge::Repeat: return static_cast<int>(((v % n) + n) % n);
    case sh::Edge::Zero: return v < 0 || v >= n ? -1 : static_cast<int>(v);
  }
  return -1;
}

constexpr sh::Edge kOutsideModes[] = {sh::Edge::Repeat, sh::Edge::Zero};

TEST_P(Conformance, Table1DFetchAndSampleOutsideRepeatOrGiveZero) {
  const int n = 5;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::vector<std::int32_t> is = {0, 4, 5, -1, -5, -6, 12, -13, std::numeric_limits<std::int32_t>::min(),
                                  std::numeric_limits<std::int32_t>::max()};
  std::vector<float> us = {0.f, 0.99f, 1.f, 1.3f, -0.1f, -1.f, -2.3f, 0.5f, nan, 2.f};
  for (sh::Edge edge : kOutsideModes) {
    sh::Table1D<sh::Attrib2f> t(n);
    t.edge(edge);
    std::vector<float> data;
    for (int i = 0; i < n; ++i) data.insert(data.end(), {10.f * (i + 1), -1.f * (i + 1)});
    t.assign(data);
    sh::Program p = SH_BEGIN_PROGRAM("table1d_edges") {
      sh::Input<Attrib1i> i;
      sh::Input<Attrib1f> u;
      sh::Output<sh::Attrib2f> fetched, sampled;
      fetched = t[i];
      sampled = t(u);
    } SH_END;
    sh::Channel<Attrib1i> ci(is);
    sh::Channel<Attrib1f> cu(us);
    sh::Channel<sh::Attrib2f> fetched, sampled;
    run(p, {ci, cu}, {fetched, sampled});
    for (std::size_t k = 0; k < is.size(); ++k) {
      int e = landing(is[k], n, edge);
      EXPECT_EQ(fetched[2 * k], e < 0 ? 0.f : 10.f * (e + 1)) << sh::ir::edge_name(edge) << " fetch " << is[k];
      EXPECT_EQ(fetched[2 * k + 1], e < 0 ? 0.f : -1.f * (e + 1)) << sh::ir::edge_name(edge) << " fetch " << is[k];
      if (fast() && std::isnan(us[k])) continue;
      float scaled = us[k] * static_cast<float>(n);
      int s = landing(std::isnan(scaled) ? 0 : static_cast<long long>(std::floor(scaled)), n, edge);
      EXPECT_EQ(sampled[2 * k], s < 0 ? 0.f : 10.f * (s + 1)) << sh::ir::edge_name(edge) << " sample " << us[k];
    }
  }
}

TEST_P(Conformance, Table3DFetchOutsideRepeatsOrGivesZeroPerDimension) {
  const int w = 3, h = 2, d = 4;
  std::vector<std::array<int, 3>> at = {{0, 0, 0}, {2, 1, 3}, {3, 0, 0}, {0, -1, 0}, {1, 1, 4}, {-4, 5, -9}, {7, -3, 2}};
  for (sh::Edge edge : kOutsideModes) {
    sh::Table3D<Attrib1i> t(w, h, d);
    t.edge(edge);
    std::vector<std::int32_t> data;
    for (int i = 0; i < w * h * d; ++i) data.push_back(100 + i);
    t.assign(data);
    sh::Program p = SH_BEGIN_PROGRAM("table3d_edges") {
      sh::Input<Attrib3i> c;
      sh::Output<Attrib1i> v;
      v = t[c];
    } SH_END;
    std::vector<std::int32_t> coords;
    for (const auto& a : at) coords.insert(coords.end(), a.begin(), a.end());
    sh::Channel<Attrib3i> cc(coords);
    sh::Channel<Attrib1i> v;
    run(p, {cc}, {v});
    for (std::size_t k = 0; k < at.size(); ++k) {
      int x = landing(at[k][0], w, edge), y = landing(at[k][1], h, edge), z = landing(at[k][2], d, edge);
      int want = x < 0 || y < 0 || z < 0 ? 0 : 100 + x + w * (y + h * z);
      EXPECT_EQ(v[k], want) << sh::ir::edge_name(edge) << " at " << at[k][0] << ", " << at[k][1] << ", " << at[k][2];
    }
  }
}

float pixel(int x, int y) { return static_cast<float>((x * 7 + y * 13) % 17 + 1); }

// A w x h table of pixel(x, y) with edge mode `edge`.
sh::Table2D<Attrib1f> pixels(int w, int h, sh::Edge edge) {
  sh::Table2D<Attrib1f> image(w, h);
  image.edge(edge);
  std::vector<float> values;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) values.push_back(pixel(x, y));
  image.assign(values);
  return image;
}

// A 7 x 3 box, wider than the narrowest rows, so that a tap wraps more
// than once; rows of odd lengths so that runs meet the edges mid-batch.
TEST_P(Conformance, StencilOutsideTheTableRepeatsOrReadsZero) {
  for (sh::Edge edge : kOutsideModes)
    for (int w : {1, 3, 19, 40, 67}) {
      const int h = 4;
      sh::Table2D<Attrib1f> image = pixels(w, h, edge);
      sh::Program p = SH_BEGIN_PROGRAM("box_edges") {
        sh::Output<Attrib1f> box;
        Attrib2i at = sh::position<2>();
        box = 0.0f;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -3; dx <= 3; ++dx) box += image[at + sh::ConstAttrib2i(dx, dy)];
      } SH_END;
      sh::Channel<Attrib1f> box;
      box.shape(static_cast<std::size_t>(w), h);
      run(p, {}, {box});
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
          float sum = 0;
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -3; dx <= 3; ++dx) {
              int sx = landing(x + dx, w, edge), sy = landing(y + dy, h, edge);
              sum += sx < 0 || sy < 0 ? 0.f : pixel(sx, sy);
            }
          ASSERT_EQ(box[static_cast<std::size_t>(y * w + x)], sum)
              << sh::ir::edge_name(edge) << " width " << w << " at " << x << ", " << y;
        }
    }
}

// A stencil's run whose coordinates wrap past INT_MAX mid-batch: an offset
// from a uniform near the ends of the int range, so that some lanes of a
// batch ask far past the row's end and the others (wrapped) far before its
// start, in either order.  Each lane reads what its own coordinate gives,
// whatever its neighbours ask.
TEST_P(Conformance, StencilRunWrappingPastTheIntRangeReadsEachLanesOwnEdge) {
  const int w = 40, h = 2;
  const std::int32_t int_max = std::numeric_limits<std::int32_t>::max(), int_min = std::numeric_limits<std::int32_t>::min();
  for (sh::Edge edge : {sh::Edge::Clamp, sh::Edge::Repeat, sh::Edge::Zero})
    for (std::int32_t offset : {int_max - 20, int_min}) {
      sh::Table2D<Attrib1f> image = pixels(w, h, edge);
      Attrib2i shift = sh::ConstAttrib2i(offset, 0);
      sh::Program p = SH_BEGIN_PROGRAM("wrapping_run") {
        sh::Output<Attrib1f> out;
        out = image[sh::position<2>() + shift + sh::ConstAttrib2i(-1, 0)];
      } SH_END;
      sh::Channel<Attrib1f> out;
      out.shape(static_cast<std::size_t>(w), h);
      run(p, {}, {out});
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
          auto asked = static_cast<std::int32_t>(static_cast<std::uint32_t>(x) + static_cast<std::uint32_t>(offset) - 1u);
          int sx = landing(asked, w, edge);
          ASSERT_EQ(out[static_cast<std::size_t>(y * w + x)], sx < 0 ? 0.f : pixel(sx, y))
              << sh::ir::edge_name(edge) << " offset " << offset << " at " << x << ", " << y;
        }
    }
}

// A tap INT_MAX elements along the row, each edge mode: the reach of the
// taps, worked out on the host, passed what an int holds and crashed the
// opencl backend's host process.
TEST_P(Conformance, StencilTapAtTheLargestOffsetIsReadAtTheEdge) {
  const int w = 37, h = 5;
  const int far = std::numeric_limits<std::int32_t>::max();
  for (sh::Edge edge : {sh::Edge::Clamp, sh::Edge::Zero, sh::Edge::Repeat}) {
    sh::Table2D<Attrib1f> image = pixels(w, h, edge);
    sh::Program p = SH_BEGIN_PROGRAM("far_tap") {
      sh::Output<Attrib1f> out;
      out = image[sh::position<2>() + sh::ConstAttrib2i(far, 0)];
    } SH_END;
    sh::Channel<Attrib1f> out;
    out.shape(static_cast<std::size_t>(w), h);
    run(p, {}, {out});
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        // int32 arithmetic: past x = 0 the sum wraps below zero.
        auto at = static_cast<std::int32_t>(static_cast<std::uint32_t>(x) + static_cast<std::uint32_t>(far));
        float want = edge == sh::Edge::Clamp  ? pixel(std::clamp(at, 0, w - 1), y)
                     : edge == sh::Edge::Zero ? (at >= 0 && at < w ? pixel(at, y) : 0.0f)
                                              : pixel(((at % w) + w) % w, y);
        ASSERT_EQ(out[static_cast<std::size_t>(y * w + x)], want) << "edge " << static_cast<int>(edge) << " at " << x;
      }
  }
}

}  // namespace
}  // namespace conformance
