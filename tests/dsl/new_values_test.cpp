// What cast<T>(), fillcast<N>() and the one-component folds (sum,
// min_component, max_component) return is a new value: writing it never
// writes their argument, inside a program (where the argument may be an
// input) or on the host (where it is a uniform).
#include <gtest/gtest.h>

#include <sh/sh.hpp>

namespace {

using namespace sh;

TEST(NewValues, InsideAProgramWritingTheResultLeavesTheInput) {
  Program p = SH_BEGIN_PROGRAM("writes_copies") {
    Input<Attrib3f> x;
    Input<Attrib1f> y;
    Output<Attrib3f> cast_out, fill_out, widened_out;
    Output<Attrib1f> sum_out, x_out;
    Attrib3f same_type = x.cast<float>();
    same_type += 1.0f;
    Attrib3f same_width = fillcast<3>(x);
    same_width *= 2.0f;
    Attrib3f wider = fillcast<3>(y);
    wider -= 1.0f;
    Attrib1f folded = sum(y);
    folded += 10.0f;
    cast_out = same_type;
    fill_out = same_width;
    widened_out = wider;
    sum_out = folded;
    x_out = x(0) + y;
  } SH_END;
  Channel<Attrib3f> x(std::vector<float>{1, 2, 3, 4, 5, 6});
  Channel<Attrib1f> y(std::vector<float>{10, 20});
  Channel<Attrib3f> cast_out, fill_out, widened_out;
  Channel<Attrib1f> sum_out, x_out;
  run(p, {x, y}, {cast_out, fill_out, widened_out, sum_out, x_out}, backend("interp"));
  EXPECT_EQ(cast_out.values(), (std::vector<float>{2, 3, 4, 5, 6, 7}));
  EXPECT_EQ(fill_out.values(), (std::vector<float>{2, 4, 6, 8, 10, 12}));
  EXPECT_EQ(widened_out.values(), (std::vector<float>{9, 9, 9, 19, 19, 19}));
  EXPECT_EQ(sum_out.values(), (std::vector<float>{20, 30}));
  EXPECT_EQ(x_out.values(), (std::vector<float>{11, 24}));
}

TEST(NewValues, OnTheHostWritingTheResultLeavesTheUniform) {
  Attrib3f x(1.0f, 2.0f, 3.0f);
  Attrib3i n(4, 5, 6);
  Attrib1f s = 7.0f;

  Attrib3f same_type = x.cast<float>();
  same_type += 1.0f;
  Attrib3i same_int = n.cast<std::int32_t>();
  same_int *= 2;
  Attrib3f same_width = fillcast<3>(x);
  same_width *= 3.0f;
  Attrib1f folded = max_component(s);
  folded -= 1.0f;

  EXPECT_EQ(same_type.get(0), 2.0f);
  EXPECT_EQ(same_int.get(2), 12);
  EXPECT_EQ(same_width.get(1), 6.0f);
  EXPECT_EQ(folded.get(), 6.0f);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(x.get(i), static_cast<float>(i + 1)) << "x." << i;
  for (int i = 0; i < 3; ++i) EXPECT_EQ(n.get(i), i + 4) << "n." << i;
  EXPECT_EQ(s.get(), 7.0f);

  // The copy is taken when the cast is made: a later write to the source
  // does not reach it.
  Attrib3f before = x.cast<float>();
  x = Attrib3f(9.0f, 9.0f, 9.0f);
  EXPECT_EQ(before.get(0), 1.0f);
}

}  // namespace
