// position(): each element's place in its run's launch domain, and the
// stencils written with it.  Rows are of odd lengths, shorter and longer
// than any SIMD width, so that runs of lanes meet a row's end mid-batch;
// neighbours read past the table's edge clamp, inside divergent ifs too.
#include "harness.hpp"

namespace conformance {
namespace {

using sh::Attrib1f;
using sh::Attrib1i;
using sh::Attrib3f;
using sh::Attrib3i;

std::array<int, 3> place(std::size_t e, std::size_t row, std::size_t rows) {
  return {static_cast<int>(e % row), static_cast<int>(e / row % rows), static_cast<int>(e / row / rows)};
}

TEST_P(Conformance, PositionIsTheElementsPlaceInTheLaunchDomain) {
  sh::Program p = SH_BEGIN_PROGRAM("position") {
    sh::Output<Attrib3i> where;
    where = sh::position<3>();
  } SH_END;
  struct Shape {
    std::size_t w, h, d;
  };
  for (Shape s : {Shape{1000, 1, 1}, Shape{37, 5, 1}, Shape{3, 7, 4}, Shape{1, 9, 2}, Shape{17, 1, 3}}) {
    sh::Channel<Attrib3i> where;
    where.shape(s.w, s.h, s.d);
    run(p, {}, {where});
    ASSERT_EQ(where.size(), s.w * s.h * s.d);
    for (std::size_t e = 0; e < where.size(); ++e) {
      std::array<int, 3> at = place(e, s.w, s.h);
      for (int c = 0; c < 3; ++c)
        ASSERT_EQ(where[3 * e + c], at[c]) << s.w << "x" << s.h << "x" << s.d << " element " << e << " component " << c;
    }
  }
}

TEST_P(Conformance, PositionWithoutAShapeIsTheElementsIndex) {
  sh::Program p = SH_BEGIN_PROGRAM("index") {
    sh::Input<Attrib1f> x;
    sh::Output<Attrib1i> i;
    i = sh::position() + x.cast<std::int32_t>();
  } SH_END;
  sh::Channel<Attrib1f> x(std::vector<float>(777, 2.0f));
  sh::Channel<Attrib1i> i;
  run(p, {x}, {i});
  for (std::size_t e = 0; e < i.size(); ++e) ASSERT_EQ(i[e], static_cast<int>(e) + 2) << "element " << e;
}

// Streams a little shorter and longer than whole work-groups and batches
// (the opencl backend launches groups of up to 1024 and runs a partial
// last group as a whole one that ends at the stream's end): every element
// gets its own value and place, in one row and in a 2-D domain.
TEST_P(Conformance, EveryElementOfAStreamAroundWholeGroupsGetsItsValue) {
  sh::Program p = SH_BEGIN_PROGRAM("long_stream") {
    sh::Input<Attrib1f> x;
    sh::Output<Attrib1i> i;
    sh::Output<Attrib3i> where;
    i = x.cast<std::int32_t>() * 3 - sh::position();
    where = sh::position<3>();
  } SH_END;
  for (std::size_t length : {1023, 1024, 1025, 2048, 3077, 5000}) {
    std::vector<float> xs(length);
    for (std::size_t e = 0; e < length; ++e) xs[e] = static_cast<float>((e * 7) % 1000);
    sh::Channel<Attrib1f> x(xs);
    sh::Channel<Attrib1i> i;
    sh::Channel<Attrib3i> where;
    if (length % 1000 == 0) where.shape(1000, length / 1000);
    run(p, {x}, {i, where});
    ASSERT_EQ(i.size(), length);
    for (std::size_t e = 0; e < length; ++e) {
      std::array<int, 3> at = length % 1000 == 0 ? place(e, 1000, length / 1000) : place(e, length, 1);
      ASSERT_EQ(i[e], static_cast<int>(xs[e]) * 3 - at[0]) << "length " << length << " element " << e;
      for (int c = 0; c < 3; ++c) ASSERT_EQ(where[3 * e + c], at[c]) << "length " << length << " element " << e;
    }
  }
}

// Values small integers, so that every sum is exact in f32 whatever order
// a backend adds in (fast math reassociates).
float pixel(int x, int y) { return static_cast<float>((x * 7 + y * 13) % 17); }

// The box [x + dx0, x + dx1] x [y + dy0, y + dy1] over a w x h image of
// pixel(), coordinates clamped to its edges, added in the programs' order.
float clamped_box(int x, int y, int w, int h, int dx0, int dx1, int dy0, int dy1) {
  auto clamp = [](int v, int n) { return std::min(std::max(v, 0), n - 1); };
  float sum = 0;
  for (int dy = dy0; dy <= dy1; ++dy)
    for (int dx = dx0; dx <= dx1; ++dx) sum += pixel(clamp(x + dx, w), clamp(y + dy, h));
  return sum;
}

// A 5 x 3 box over a W x H image, edges clamped; in odd columns only,
// from inside an if, the 3-component table's neighbour to the right.
TEST_P(Conformance, StencilReadsNeighboursAndClampsAtTheEdges) {
  for (int w : {1, 3, 19, 40, 67}) {
    const int h = 5;
    sh::Table2D<Attrib1f> image(w, h);
    sh::Table2D<Attrib3f> colour(w, h);
    std::vector<float> values, colours;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        values.push_back(pixel(x, y));
        colours.insert(colours.end(), {pixel(x, y), -pixel(y, x), static_cast<float>(x)});
      }
    image.assign(values);
    colour.assign(colours);
    sh::Program p = SH_BEGIN_PROGRAM("box") {
      sh::Output<Attrib1f> box;
      sh::Output<Attrib3f> right;
      sh::Attrib2i at = sh::position<2>();
      box = 0.0f;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -2; dx <= 2; ++dx) box += image[at + sh::ConstAttrib2i(dx, dy)];
      right = sh::ConstAttrib3f(0.0f, 0.0f, 0.0f);
      SH_IF((at(0) % 2).cast<float>() > 0.5f) { right = colour[at + sh::ConstAttrib2i(1, 0)]; } SH_ENDIF;
    } SH_END;
    sh::Channel<Attrib1f> box;
    sh::Channel<Attrib3f> right;
    box.shape(static_cast<std::size_t>(w), h);
    run(p, {}, {box, right});
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        std::size_t e = static_cast<std::size_t>(y * w + x);
        ASSERT_EQ(box[e], clamped_box(x, y, w, h, -2, 2, -1, 1)) << "width " << w << " at " << x << ", " << y;
        int rx = std::min(x + 1, w - 1);
        for (int c = 0; c < 3; ++c) {
          float want = x % 2 ? colours[3 * static_cast<std::size_t>(y * w + rx) + c] : 0.0f;
          ASSERT_EQ(right[3 * e + c], want) << "width " << w << " at " << x << ", " << y << " component " << c;
        }
      }
  }
}

// Long rows, which a run splits between calls mid-row, so that batches
// inside the table follow one another and a call's end falls among them;
// the table narrower, as wide, and wider than the launch domain.  Each
// element also counts itself into its row's sum: an element run twice (a
// call going on past its end) would count twice.
TEST_P(Conformance, StencilAlongLongRowsSplitBetweenCallsReadsEveryNeighbour) {
  const int w = 1000, h = 23;
  for (int table_w : {993, 1000, 1009}) {
    const int table_h = h + 2;
    sh::Table2D<Attrib1f> image(table_w, table_h);
    std::vector<float> values;
    for (int y = 0; y < table_h; ++y)
      for (int x = 0; x < table_w; ++x) values.push_back(pixel(x, y));
    image.assign(values);
    sh::Accumulator<Attrib1i> visits(h, "visits");
    sh::Program p = SH_BEGIN_PROGRAM("long_rows") {
      sh::Output<Attrib1f> box;
      sh::Attrib2i at = sh::position<2>();
      box = 0.0f;
      for (int dy = -2; dy <= 1; ++dy)
        for (int dx = -3; dx <= 2; ++dx) box += image[at + sh::ConstAttrib2i(dx, dy)];
      visits.add(at(1), sh::ConstAttrib1i(1));
    } SH_END;
    sh::Channel<Attrib1f> box;
    box.shape(static_cast<std::size_t>(w), h);
    run(p, {}, {box});
    EXPECT_EQ(visits.values(), std::vector<std::int32_t>(h, w)) << "table width " << table_w;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        ASSERT_EQ(box[static_cast<std::size_t>(y * w + x)], clamped_box(x, y, table_w, table_h, -3, 2, -2, 1))
            << "table width " << table_w << " at " << x << ", " << y;
  }
}

}  // namespace
}  // namespace conformance
