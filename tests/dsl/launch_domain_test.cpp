// The launch domain: a channel's shape sets it, position() reads it, and
// every misuse is an sh::Error naming the program and what is wrong.
#include <gtest/gtest.h>

#include <sh/sh.hpp>

#include "../common/expect_error.hpp"

namespace {

using namespace sh;

Program where() {
  return SH_BEGIN_PROGRAM("where") {
    OutputAttrib2i at;
    at = position<2>();
  } SH_END;
}

TEST(LaunchDomain, ShapeSetsTheGridAndACountChangeForgetsIt) {
  Channel<Attrib2i> at;
  at.shape(4, 3);
  EXPECT_EQ(at.size(), 12u);
  EXPECT_EQ(at.shape(), (std::array<std::size_t, 3>{4, 3, 1}));
  at = where();
  EXPECT_EQ(at[2 * 9], 1);      // element 9: x 1
  EXPECT_EQ(at[2 * 9 + 1], 2);  // y 2
  at.resize(5);
  EXPECT_EQ(at.shape(), (std::array<std::size_t, 3>{0, 1, 1})) << "one row again";
  at = where();
  EXPECT_EQ(at[2 * 4], 4);
  EXPECT_EQ(at[2 * 4 + 1], 0);
  at.resize(12);
  EXPECT_EQ(at.shape(), (std::array<std::size_t, 3>{0, 1, 1})) << "the old grid's count again is not its grid";
}

// A channel shaped after its data were given keeps them: a stencil's
// shaped input had run on zeros.
TEST(LaunchDomain, ShapingAChannelOfThatCountKeepsItsElements) {
  Channel<Attrib1f> x(std::vector<float>{1, 2, 3, 4, 5, 6});
  x.shape(3, 2);
  EXPECT_EQ(x.values(), (std::vector<float>{1, 2, 3, 4, 5, 6}));
  x.shape(6, 1);
  EXPECT_EQ(x.values(), (std::vector<float>{1, 2, 3, 4, 5, 6}));
  Program p = SH_BEGIN_PROGRAM("row_plus") {
    InputAttrib1f v;
    OutputAttrib1f y;
    y = v + position<2>()(1).cast<float>();
  } SH_END;
  x.shape(3, 2);
  Channel<Attrib1f> y;
  y = p << x;
  EXPECT_EQ(y.values(), (std::vector<float>{1, 2, 3, 5, 6, 7}));
  x.shape(2, 2);
  EXPECT_EQ(x.values(), (std::vector<float>(4, 0.0f))) << "a new count starts from zeros";
}

TEST(LaunchDomain, AShapedInputSetsTheDomainOfAnUnshapedOutput) {
  Program p = SH_BEGIN_PROGRAM("row_of") {
    InputAttrib1f x;
    OutputAttrib1i y;
    y = position<2>()(1) + x.cast<std::int32_t>();
  } SH_END;
  Channel<Attrib1f> x;
  x.shape(2, 3);
  Channel<Attrib1i> y;
  y = p << x;
  EXPECT_EQ(y.values(), (std::vector<std::int32_t>{0, 0, 1, 1, 2, 2}));
}

TEST(LaunchDomain, ShapesThatDisagreeOrCannotBeAreErrors) {
  Program p = SH_BEGIN_PROGRAM("copy") {
    InputAttrib1f x;
    OutputAttrib1f y;
    y = x;
  } SH_END;
  Channel<Attrib1f> x, y;
  x.shape(6, 2);
  y.shape(4, 3);
  expect_error([&] { y = p << x; }, {"copy", "input channel 0 is shaped 6 x 2 x 1", "output channel 0 is shaped 4 x 3 x 1"});
  expect_error([&] { x.shape(0, 5); }, {"shape 0 x 5 x 1", "outside [1, 2^31 - 1]"});
  expect_error([&] { x.shape(std::size_t{1} << 31); }, {"outside [1, 2^31 - 1]"});
  expect_error([&] { x.shape(1u << 30, 1u << 30, 1u << 30); }, {"more elements than memory can"});
}

TEST(LaunchDomain, PositionIsReadOnlyInsideAProgram) {
  expect_error([] { (void)position<2>(); }, {"position()", "inside a program"});
}

class Nothing : public Refiner {
 public:
  std::string kind() const override { return "launch_domain_test.nothing"; }
  std::string seed() const override { return {}; }
  void bind(std::vector<TableView>&) const override {}
  std::size_t refine(const std::vector<std::int32_t>&, int) override { return 0; }
  std::string summary() const override { return {}; }
};

TEST(LaunchDomain, WavesRefuseAProgramThatReadsPosition) {
  Program p = SH_BEGIN_PROGRAM("placed") {
    InputAttrib1i x;
    OutputAttrib1i request;
    request = x + position();
  } SH_END;
  Channel<Attrib1i> x(std::vector<std::int32_t>{1, 2}), request;
  Nothing refiner;
  expect_error([&] { run(p, {x}, {request}, Waves{&refiner, 0, {}}); }, {"placed", "reads position()", "waves"});
}

}  // namespace
