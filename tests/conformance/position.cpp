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

// A 5 x 3 box over a W x H image, edges clamped; a row of taps of the
// 3-component table (x - 1, x and x + 2); in odd columns only, from
// inside an if, its neighbour to the right.
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
      sh::Output<Attrib3f> right, smear;
      sh::Attrib2i at = sh::position<2>();
      box = 0.0f;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -2; dx <= 2; ++dx) box += image[at + sh::ConstAttrib2i(dx, dy)];
      smear = colour[at + sh::ConstAttrib2i(-1, 0)] + colour[at] + colour[at + sh::ConstAttrib2i(2, 0)];
      right = sh::ConstAttrib3f(0.0f, 0.0f, 0.0f);
      SH_IF((at(0) % 2).cast<float>() > 0.5f) { right = colour[at + sh::ConstAttrib2i(1, 0)]; } SH_ENDIF;
    } SH_END;
    sh::Channel<Attrib1f> box;
    sh::Channel<Attrib3f> right, smear;
    box.shape(static_cast<std::size_t>(w), h);
    run(p, {}, {box, right, smear});
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        std::size_t e = static_cast<std::size_t>(y * w + x);
        ASSERT_EQ(box[e], clamped_box(x, y, w, h, -2, 2, -1, 1)) << "width " << w << " at " << x << ", " << y;
        int rx = std::min(x + 1, w - 1);
        auto colour_at = [&](int cx, int c) { return colours[3 * static_cast<std::size_t>(y * w + std::clamp(cx, 0, w - 1)) + c]; };
        for (int c = 0; c < 3; ++c) {
          float smeared = colour_at(x - 1, c) + colour_at(x, c) + colour_at(x + 2, c);
          ASSERT_EQ(smear[3 * e + c], smeared) << "width " << w << " at " << x << ", " << y << " component " << c;
          float want = x % 2 ? colours[3 * static_cast<std::size_t>(y * w + rx) + c] : 0.0f;
          ASSERT_EQ(right[3 * e + c], want) << "width " << w << " at " << x << ", " << y << " component " << c;
        }
      }
  }
}

// Taps before and past a row's ends on tables of one, two and three
// dimensions, of elements of 2 and 4 components and of ints, that clamp
// or read zero: a lane outside the row reads its first or last element
// (or zero), whatever its neighbours read; inside an if too, where a
// batch's first lane may not run.  The doubles, a fraction apart from a
// float, are 64-bit elements, which the cpu backend reads otherwise.  Rows
// of 21: a batch of 16 lanes holds both ends of the taps' reach, and the
// next a short one; rows of 3, shorter than any batch.
TEST_P(Conformance, StencilTapsPastARowsEndsOnTablesOfEveryRankAndElement) {
  const int h = 3, d = 2;
  auto value = [](int x, int y, int z, int c) { return 1 + x * 5 + y * 31 + z * 97 + c * 1000; };
  for (int w : {21, 3})
    for (sh::Edge edge : {sh::Edge::Clamp, sh::Edge::Zero}) {
      sh::Table1D<sh::Attrib2f> line(w);
      sh::Table3D<sh::Attrib4f> volume(w, h, d);
      sh::Table2D<Attrib1i> ints(w, h);
      sh::Table2D<sh::Attrib1d> doubles(w, h);
      constexpr double kFraction = 1e-9;
      line.edge(edge);
      volume.edge(edge);
      ints.edge(edge);
      doubles.edge(edge);
      std::vector<float> line_values, volume_values;
      std::vector<std::int32_t> int_values;
      std::vector<double> double_values;
      for (int z = 0; z < d; ++z)
        for (int y = 0; y < h; ++y)
          for (int x = 0; x < w; ++x) {
            for (int c = 0; c < 4; ++c) volume_values.push_back(static_cast<float>(value(x, y, z, c)));
            if (z == 0) int_values.push_back(value(x, y, 0, 0));
            if (z == 0) double_values.push_back(value(x, y, 0, 0) + kFraction);
            if (z == 0 && y == 0)
              for (int c = 0; c < 2; ++c) line_values.push_back(static_cast<float>(value(x, 0, 0, c)));
          }
      line.assign(line_values);
      volume.assign(volume_values);
      ints.assign(int_values);
      doubles.assign(double_values);
      sh::Program p = SH_BEGIN_PROGRAM("taps_every_rank") {
        sh::Output<sh::Attrib2f> from_line;
        sh::Output<sh::Attrib4f> from_volume;
        sh::Output<Attrib1i> from_ints;
        sh::Output<sh::Attrib1d> from_doubles;
        Attrib3i at = sh::position<3>();
        from_line = line[at(0) + sh::ConstAttrib1i(-3)] + line[at(0) + sh::ConstAttrib1i(2)];
        from_volume = volume[at + sh::ConstAttrib3i(-2, 1, -1)];
        from_ints = 0;
        SH_IF(at(0) % 3 == 1) { from_ints = ints[at(0, 1) + sh::ConstAttrib2i(-4, 0)]; } SH_ENDIF;
        from_doubles = doubles[at(0, 1) + sh::ConstAttrib2i(3, 0)];
      } SH_END;
      sh::Channel<sh::Attrib2f> from_line;
      sh::Channel<sh::Attrib4f> from_volume;
      sh::Channel<Attrib1i> from_ints;
      sh::Channel<sh::Attrib1d> from_doubles;
      from_line.shape(w, h, d);
      run(p, {}, {from_line, from_volume, from_ints, from_doubles});
      // The element at (x, y, z) as the table's edge mode reads it.
      auto read = [&](int x, int y, int z, int c, std::array<int, 3> extent) {
        std::array<int, 3> at{x, y, z};
        for (int k = 0; k < 3; ++k) {
          if (edge == sh::Edge::Zero && (at[k] < 0 || at[k] >= extent[k])) return 0;
          at[k] = std::min(std::max(at[k], 0), extent[k] - 1);
        }
        return value(at[0], at[1], at[2], c);
      };
      for (int z = 0; z < d; ++z)
        for (int y = 0; y < h; ++y)
          for (int x = 0; x < w; ++x) {
            std::size_t e = static_cast<std::size_t>(x + w * (y + h * z));
            std::string where = std::string(sh::ir::edge_name(edge)) + ", rows of " + std::to_string(w) + ", at " +
                                std::to_string(x) + ", " + std::to_string(y) + ", " + std::to_string(z);
            for (int c = 0; c < 2; ++c)
              ASSERT_EQ(from_line[2 * e + c], static_cast<float>(read(x - 3, 0, 0, c, {w, 1, 1}) +
                                                                 read(x + 2, 0, 0, c, {w, 1, 1})))
                  << where << " component " << c;
            for (int c = 0; c < 4; ++c)
              ASSERT_EQ(from_volume[4 * e + c], static_cast<float>(read(x - 2, y + 1, z - 1, c, {w, h, d})))
                  << where << " component " << c;
            ASSERT_EQ(from_ints[e], x % 3 == 1 ? read(x - 4, y, 0, 0, {w, h, 1}) : 0) << where;
            int from_double = read(x + 3, y, 0, 0, {w, h, 1});
            ASSERT_EQ(from_doubles[e], from_double ? from_double + kFraction : 0.0) << where;
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

// Stencils whose taps reach several rows, over rows that a run on one
// thread and on two splits between calls mid-row, a call holding a few
// rows (the cpu backend's SPMD kernels run two rows of batches at a time
// where both lie in a call, and a call may end among them or start
// mid-row), in layers of an odd number of rows (a layer's last row has
// none below it to go with), reading a table of one and one of three
// components; a table of a layer that reads zero past its edges.
TEST_P(Conformance, StencilRowsSplitBetweenCallsAndLayersGiveEveryElementItsTaps) {
  const int w = 100, h = 33, d = 3;
  auto value = [](int x, int y, int z, int c) {
    return static_cast<float>(1 + (x * 5 + y * 31 + z * 97) % 211 + c * 1000);
  };
  sh::Table2D<Attrib1f> image(w, h);
  sh::Table2D<Attrib3f> colour(w, h);
  sh::Table3D<Attrib1f> volume(w, h, d);
  volume.edge(sh::Edge::Zero);
  std::vector<float> image_values, colour_values, volume_values;
  for (int z = 0; z < d; ++z)
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        volume_values.push_back(value(x, y, z, 0));
        if (z > 0) continue;
        image_values.push_back(value(x, y, 0, 0));
        for (int c = 0; c < 3; ++c) colour_values.push_back(value(x, y, 0, c));
      }
  image.assign(image_values);
  colour.assign(colour_values);
  volume.assign(volume_values);
  sh::Program p = SH_BEGIN_PROGRAM("rows_together") {
    sh::Output<Attrib1f> box, layer;
    sh::Output<Attrib3f> column;
    Attrib3i at = sh::position<3>();
    box = 0.0f;
    for (int dy = -2; dy <= 1; ++dy)
      for (int dx = -3; dx <= 2; ++dx) box += image[at(0, 1) + sh::ConstAttrib2i(dx, dy)];
    column = colour[at(0, 1) + sh::ConstAttrib2i(0, -1)] + colour[at(0, 1) + sh::ConstAttrib2i(1, 1)];
    layer = volume[at + sh::ConstAttrib3i(-1, -1, 0)] + volume[at + sh::ConstAttrib3i(1, 1, 0)];
  } SH_END;
  auto clamp = [](int v, int n) { return std::min(std::max(v, 0), n - 1); };
  auto in_layer = [&](int x, int y, int z) { return x < 0 || x >= w || y < 0 || y >= h ? 0.0f : value(x, y, z, 0); };
  for (int threads : {1, 2}) {
    sh::Channel<Attrib1f> box, layer;
    sh::Channel<Attrib3f> column;
    box.shape(w, h, d);
    sh::Options o;
    o.threads = threads;
    sh::run(p, {}, {box, layer, column}, choice(o));
    for (int z = 0; z < d; ++z)
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
          std::size_t e = static_cast<std::size_t>(x + w * (y + h * z));
          std::string where = std::to_string(threads) + " threads, at " + std::to_string(x) + ", " +
                              std::to_string(y) + ", " + std::to_string(z);
          float want = 0;
          for (int dy = -2; dy <= 1; ++dy)
            for (int dx = -3; dx <= 2; ++dx) want += value(clamp(x + dx, w), clamp(y + dy, h), 0, 0);
          ASSERT_EQ(box[e], want) << where;
          for (int c = 0; c < 3; ++c)
            ASSERT_EQ(column[3 * e + c],
                      value(x, clamp(y - 1, h), 0, c) + value(clamp(x + 1, w), clamp(y + 1, h), 0, c))
                << where << " component " << c;
          ASSERT_EQ(layer[e], in_layer(x - 1, y - 1, z) + in_layer(x + 1, y + 1, z)) << where;
        }
  }
}

}  // namespace
}  // namespace conformance
