// run_fused: a producer and a stencil consumer that reads its output as a
// table, run together in strips of rows where the backend runs in place,
// give what the two runs one after the other give, on every backend: at
// every edge mode, with taps above and below an element's row, only below
// or only above it, in strips of one row, of a few and of the default
// height (one strip or several), over rows of odd lengths, for elements of
// one component and of three.
#include <algorithm>
#include <cstdint>
#include <limits>

#include "harness.hpp"

namespace conformance {
namespace {

using sh::Attrib1f;
using sh::Attrib1i;
using sh::Attrib2i;

std::vector<float> picture(int w, int h) {
  std::vector<float> v(static_cast<std::size_t>(w) * h);
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = static_cast<float>(i % 17) * 0.25f - static_cast<float>(i % 5);
  return v;
}

// Rows: five taps along x of the image, plus the row's place, so that a
// producer run at the wrong rows gives other values.
sh::Program rows_program(const sh::Table2D<Attrib1f>& image) {
  return SH_BEGIN_PROGRAM("fused_rows") {
    sh::OutputAttrib1f out;
    Attrib2i at = sh::position<2>();
    Attrib1f sum = 0.0f;
    for (int dx = -2; dx <= 2; ++dx) sum += image[at + sh::ConstAttrib2i(dx, 0)];
    out = sum + 0.125f * at(1).cast<float>();
  } SH_END;
}

// Columns: taps dy in [low, high] of the rows' table, weighted by their
// offset, and the element's row as a second output.
sh::Program columns_program(const sh::Table2D<Attrib1f>& rows, int low, int high) {
  return SH_BEGIN_PROGRAM("fused_columns") {
    sh::OutputAttrib1f out;
    sh::OutputAttrib1i row;
    Attrib2i at = sh::position<2>();
    Attrib1f sum = 0.0f;
    for (int dy = low; dy <= high; ++dy) sum += static_cast<float>(dy + 4) * rows[at + sh::ConstAttrib2i(1, dy)];
    out = sum;
    row = at(1);
  } SH_END;
}

struct Outputs {
  sh::Channel<Attrib1f> value;
  sh::Channel<Attrib1i> row;
  Outputs(int w, int h) {
    value.shape(w, h);
    row.shape(w, h);
  }
};

// What the two programs give run one after the other: the producer's
// output in a channel whose memory the consumer's table then views.
template <class E>
void run_apart(const sh::Program& along, sh::Table2D<E>& rows, const sh::Program& down,
               const std::vector<std::shared_ptr<sh::detail::Buffer>>& outputs, const sh::BackendChoice& choice) {
  sh::Channel<E> middle;
  middle.shape(static_cast<std::size_t>(rows.dims()[0]), static_cast<std::size_t>(rows.dims()[1]));
  sh::run(along, {}, {middle}, choice);
  rows.memory(middle.memory());
  sh::run(down, {}, outputs, choice);
}

// run_fused of a consumer the strips cannot serve: no strips, and the
// outputs of the two runs one after the other.
void expect_runs_apart(const sh::Program& along, sh::Table2D<Attrib1f>& rows, const sh::Program& down, int w, int h,
                       const sh::BackendChoice& choice) {
  sh::Channel<Attrib1f> fused, apart;
  fused.shape(w, h);
  EXPECT_EQ(sh::run_fused(along, rows, down, {fused}, choice, 2).strips, 0u);
  apart.shape(w, h);
  run_apart(along, rows, down, {apart}, choice);
  EXPECT_EQ(fused.values(), apart.values());
}

// Rows the producer has not written read as NaN, so that a consumer that
// reads the table's stale contents shows.
void spoil(sh::Table2D<Attrib1f>& rows, int w, int h) {
  rows.assign(std::vector<float>(static_cast<std::size_t>(w) * h, std::numeric_limits<float>::quiet_NaN()));
}

TEST_P(Conformance, FusedStencilsGiveWhatTheirRunsOneAfterTheOtherGive) {
  bool in_place = sh::find_backend(mode().backend).runs_in_place();
  struct Case {
    int w, h;
    sh::Edge edge;
    int low, high;
    std::vector<int> strip_rows;
  };
  std::vector<Case> cases;
  for (auto [w, h] : {std::pair{37, 29}, std::pair{19, 6}})
    for (sh::Edge edge : {sh::Edge::Clamp, sh::Edge::Zero, sh::Edge::Repeat})
      for (auto [low, high] : {std::pair{-2, 2}, std::pair{1, 3}, std::pair{-3, -1}})
        cases.push_back({w, h, edge, low, high, {1, 3, 0}});
  // 16 KiB rows: the default strips are 32 rows, three of them here.
  cases.push_back({4096, 70, sh::Edge::Clamp, -2, 2, {0}});
  for (const Case& k : cases) {
    auto [w, h, edge, low, high, strip_rows_tried] = k;
    sh::Table2D<Attrib1f> image(w, h), rows(w, h);
    image.assign(picture(w, h));
    rows.edge(edge);
    sh::Program along = rows_program(image), down = columns_program(rows, low, high);
    for (int strip_rows : strip_rows_tried) {
      spoil(rows, w, h);
      Outputs fused(w, h);
      sh::RunStats s = sh::run_fused(along, rows, down, {fused.value, fused.row}, choice(), strip_rows);
      std::string what = std::to_string(w) + "x" + std::to_string(h) + ", edge " + std::to_string(static_cast<int>(edge)) +
                         ", taps " + std::to_string(low) + ".." + std::to_string(high) + ", strips of " +
                         std::to_string(strip_rows);
      int rows_per_strip = strip_rows ? strip_rows : std::min(h, (512 * 1024) / (4 * w));
      std::size_t strips = static_cast<std::size_t>((h + rows_per_strip - 1) / rows_per_strip);
      EXPECT_EQ(s.strips, in_place && edge != sh::Edge::Repeat ? strips : 0u) << what;
      Outputs apart(w, h);
      run_apart(along, rows, down, {apart.value, apart.row}, choice());
      ASSERT_EQ(fused.value.values(), apart.value.values()) << what;
      ASSERT_EQ(fused.row.values(), apart.row.values()) << what;
    }
  }
}

// Elements of three components: a strip's rows are three times as long in
// bytes.
TEST_P(Conformance, FusedStencilsOfThreeComponentsGiveWhatTheirRunsApartGive) {
  const int w = 21, h = 13;
  sh::Table2D<Attrib1f> image(w, h);
  sh::Table2D<sh::Attrib3f> rows(w, h);
  image.assign(picture(w, h));
  sh::Program along = SH_BEGIN_PROGRAM("fused_rows3") {
    sh::Output<sh::Attrib3f> out;
    Attrib2i at = sh::position<2>();
    Attrib1f left = image[at + sh::ConstAttrib2i(-1, 0)], right = image[at + sh::ConstAttrib2i(1, 0)];
    out = sh::join(sh::join(left, right), left - right + 0.5f * at(1).cast<float>());
  } SH_END;
  sh::Program down = SH_BEGIN_PROGRAM("fused_columns3") {
    sh::Output<sh::Attrib3f> out;
    Attrib2i at = sh::position<2>();
    out = rows[at + sh::ConstAttrib2i(0, -1)] * 2.0f + rows[at + sh::ConstAttrib2i(0, 2)];
  } SH_END;
  sh::Channel<sh::Attrib3f> fused, apart;
  fused.shape(w, h);
  sh::RunStats s = sh::run_fused(along, rows, down, {fused}, choice(), 4);
  EXPECT_EQ(s.strips, sh::find_backend(mode().backend).runs_in_place() ? 4u : 0u);
  apart.shape(w, h);
  run_apart(along, rows, down, {apart}, choice());
  EXPECT_EQ(fused.values(), apart.values());
}

// A tap INT_MAX rows down wraps, in the kernel's int32 arithmetic, to a row
// above the image, read clamped to its first: the strips, which hold the
// rows a tap reaches in 64 bits, would not hold it, so the two run apart.
TEST_P(Conformance, FusedStencilsWithATapPastWhatInt32HoldsGiveWhatTheirRunsApartGive) {
  const int w = 8, h = 8;
  sh::Table2D<Attrib1f> image(w, h), rows(w, h);
  image.assign(picture(w, h));
  sh::Program along = rows_program(image);
  sh::Program down = SH_BEGIN_PROGRAM("fused_far_tap") {
    sh::OutputAttrib1f out;
    out = rows[sh::position<2>() + sh::ConstAttrib2i(0, std::numeric_limits<std::int32_t>::max())];
  } SH_END;
  expect_runs_apart(along, rows, down, w, h, choice());
}

// Outputs written into a table the producer reads (an in-place blur), and
// checked runs, keep the two apart, with the outputs of the runs apart.
TEST_P(Conformance, FusedStencilsRunApartWhereStripsWouldNotDo) {
  const int w = 17, h = 9;
  sh::Channel<Attrib1f> value;
  sh::Channel<Attrib1i> row;
  value.shape(w, h);
  row.shape(w, h);
  std::vector<float> start = picture(w, h);
  std::copy(start.begin(), start.end(), value.data());
  sh::Table2D<Attrib1f> image(w, h), rows(w, h), fresh(w, h), fresh_rows(w, h);
  image.memory(value.memory());
  sh::Program along = rows_program(image), down = columns_program(rows, -2, 2);
  EXPECT_EQ(sh::run_fused(along, rows, down, {value, row}, choice(), 2).strips, 0u) << "in place";
  fresh.assign(start);
  sh::Program fresh_along = rows_program(fresh), fresh_down = columns_program(fresh_rows, -2, 2);
  Outputs apart(w, h);
  sh::run_fused(fresh_along, fresh_rows, fresh_down, {apart.value, apart.row}, choice(), 2);
  EXPECT_EQ(value.values(), apart.value.values());
  sh::Options checked;
  checked.checked = true;
  Outputs watched(w, h);
  EXPECT_EQ(sh::run_fused(fresh_along, fresh_rows, fresh_down, {watched.value, watched.row}, choice(checked), 2).strips, 0u);
  EXPECT_EQ(watched.value.values(), apart.value.values());
}

// A consumer that also reads the table through a second view of its
// memory reads the producer's rows there: the two run one after the
// other, as the strips would leave that memory unwritten.
TEST_P(Conformance, FusedStencilsReadingTheTableThroughAnotherViewRunApart) {
  const int w = 13, h = 10;
  sh::Table2D<Attrib1f> image(w, h), rows(w, h), view(w, h);
  image.assign(picture(w, h));
  spoil(rows, w, h);
  view.memory(rows.memory());
  auto columns = [](const sh::Table2D<Attrib1f>& taps, const sh::Table2D<Attrib1f>& here) {
    return SH_BEGIN_PROGRAM("fused_two_views") {
      sh::OutputAttrib1f out;
      Attrib2i at = sh::position<2>();
      out = taps[at + sh::ConstAttrib2i(0, -1)] + 3.0f * here[at];
    } SH_END;
  };
  sh::Program along = rows_program(image);
  sh::Channel<Attrib1f> fused;
  fused.shape(w, h);
  EXPECT_EQ(sh::run_fused(along, rows, columns(rows, view), {fused}, choice(), 2).strips, 0u);
  sh::Channel<Attrib1f> middle, apart;
  middle.shape(w, h);
  apart.shape(w, h);
  sh::run(along, {}, {middle}, choice());
  sh::Table2D<Attrib1f> taps(w, h), here(w, h);
  taps.memory(middle.memory());
  here.memory(middle.memory());
  sh::run(columns(taps, here), {}, {apart}, choice());
  EXPECT_EQ(fused.values(), apart.values());
}

// A read at a row the analysis cannot bound (from a value read in the
// table) keeps the two runs apart, with the same outputs.
TEST_P(Conformance, FusedStencilsReadingAnywhereRunOneAfterTheOther) {
  const int w = 23, h = 11;
  sh::Table2D<Attrib1f> image(w, h), rows(w, h);
  image.assign(picture(w, h));
  sh::Program along = rows_program(image);
  sh::Program down = SH_BEGIN_PROGRAM("fused_anywhere") {
    sh::OutputAttrib1f out;
    Attrib2i at = sh::position<2>();
    Attrib1i jump = sh::abs(rows[at]).cast<std::int32_t>();
    out = rows[at + sh::join(Attrib1i(0), jump)];
  } SH_END;
  expect_runs_apart(along, rows, down, w, h, choice());
}

// An element that runs a loop past the cap is named by its place in the
// whole grid, not in its strip.
TEST_P(Conformance, FusedStencilsNameARunawayElementByItsPlaceInTheGrid) {
  const int w = 11, h = 8;
  sh::Table2D<Attrib1f> image(w, h), rows(w, h);
  image.assign(picture(w, h));
  sh::Program along = rows_program(image);
  sh::Program down = SH_BEGIN_PROGRAM("fused_runaway") {
    sh::OutputAttrib1f out;
    Attrib2i at = sh::position<2>();
    Attrib1f r = rows[at] * 0.0f + 1.0f;
    Attrib1f here = (at(0) == 3 && at(1) == 5).cast<float>();
    SH_WHILE(r > 0.0f && here) { r += 1.0f; } SH_ENDWHILE;  // endless at (3, 5) alone
    out = r;
  } SH_END;
  sh::Options o;
  o.max_loop_iterations = 1000;
  sh::Channel<Attrib1f> out;
  out.shape(w, h);
  try {
    sh::run_fused(along, rows, down, {out}, choice(o), 2);
    FAIL() << "an endless loop must be an error";
  } catch (const sh::Error& e) {
    EXPECT_NE(std::string(e.what()).find("element 58 "), std::string::npos) << e.what();
  }
}

TEST_P(Conformance, FusedStencilsThatDoNotFitTogetherAreErrors) {
  sh::Table2D<Attrib1f> image(8, 4), rows(8, 4), other(8, 4);
  image.assign(picture(8, 4));
  sh::Program along = rows_program(image), down = columns_program(rows, -1, 1);
  sh::Channel<Attrib1f> value, small_value;
  sh::Channel<Attrib1i> row, small_row;
  value.shape(8, 4);
  row.shape(8, 4);
  small_value.shape(8, 3);
  small_row.shape(8, 3);
  auto message = [](const auto& call) {
    try {
      call();
    } catch (const sh::Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message([&] { sh::run_fused(along, other, down, {value, row}, choice()); }).find("does not read the table"),
            std::string::npos);
  EXPECT_NE(message([&] { sh::run_fused(along, rows, down, {small_value, small_row}, choice()); }).find("grid of the table"), std::string::npos);
  // The failed call did not run the producer: the table is as unfilled as before.
  EXPECT_NE(message([&] { sh::run(down, {}, {value, row}, choice()); }).find("never filled"), std::string::npos);
  EXPECT_NE(message([&] { sh::run_fused(down, rows, down, {value, row}, choice()); }).find("one output"), std::string::npos);
  // A producer that reads the table it fills would meet its own writes in
  // an order each backend picks (opencl's answer differed from cpu's).
  sh::Program reads_its_own = SH_BEGIN_PROGRAM("reads_its_own") {
    sh::OutputAttrib1f out;
    out = rows[sh::position<2>()] + 1.0f;
  } SH_END;
  sh::Program reads_rows = columns_program(rows, 0, 0);
  EXPECT_NE(message([&] { sh::run_fused(reads_its_own, rows, reads_rows, {value, row}, choice()); })
                .find("program 'reads_its_own': run_fused's producer reads the table"),
            std::string::npos);
}

}  // namespace
}  // namespace conformance
