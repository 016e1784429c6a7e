// Sh-era code compiles with cosmetic edits only: the seed's style of
// intersector (a C++ function with Sh types, output parameters by
// reference, SH_DECL, ShArray tables) records and runs.
#include <gtest/gtest.h>

#include <sh/compat.hpp>

namespace {

ShAttrib1f gain = 2.0f;

// After the seed: writes its results through reference parameters.
ShAttrib1f nearest_root(ShAttrib1f a, ShAttrib1f b, ShAttrib1f c, ShAttrib1f& root, ShAttrib1f& count) {
  ShAttrib1f disc = b * b - 4.0f * a * c;
  ShAttrib1f SH_DECL(hit) = disc >= 0.0f;
  count = 0.0f;
  SH_IF(hit) {
    root = (-b - sqrt(disc)) / (2.0f * a);
    count = cond(disc > 0.0f, ShConstAttrib1f(2.0f), ShConstAttrib1f(1.0f));
  } SH_ENDIF;
  return hit;
}

// Each of Sh's SH_DECL forms: with an expression, with a number, and with
// no initial value; each variable keeps its name.
TEST(Compat, EverySHDeclFormRecordsANamedVariable) {
  ShProgram p = SH_BEGIN_PROGRAM("decl_forms") {
    ShInputAttrib1f x;
    ShOutputAttrib3f out;
    ShAttrib1f SH_DECL(twice) = x * 2.0f;
    ShAttrib1f SH_DECL(one) = 1.0f;
    ShAttrib3f SH_DECL(later);
    later = join(join(twice, one), x);
    out = later;
  } SH_END;
  std::string printed = sh::print(p);
  for (const char* name : {"twice", "one", "later"})
    EXPECT_NE(printed.find(name), std::string::npos) << name << printed;
  ShChannel<ShAttrib1f> x(std::vector<float>{3});
  ShChannel<ShAttrib3f> out;
  sh::run(p, {x}, {out}, sh::backend("interp"));
  EXPECT_EQ(out.values(), (std::vector<float>{6, 1, 3}));
}

// Integer streams in Sh's spelling, as float ones.
TEST(Compat, IntegerInputsAndOutputs) {
  ShProgram p = SH_BEGIN_PROGRAM("twice") {
    ShInputAttrib1i i;
    ShOutputAttrib2i out;
    out = join(i * 2, i + ShConstAttrib1i(1));
  } SH_END;
  ShChannel<ShAttrib1i> in(std::vector<std::int32_t>{3, -4});
  ShChannel<ShAttrib2i> out;
  sh::run(p, {in}, {out}, sh::backend("interp"));
  EXPECT_EQ(out.values(), (std::vector<std::int32_t>{6, 4, -8, -3}));
}

TEST(Compat, SeedStyleCodeRecordsAndRuns) {
  ShArray1D<ShAttrib3f> coefficients(2);
  coefficients.assign({1, -3, 2, 1, 2, 5});
  ShProgram p = SH_BEGIN_PROGRAM("roots") {
    ShInputAttrib1f which;
    ShOutputAttrib3f out;
    ShAttrib3f k = coefficients[which];
    ShAttrib1f root, count;
    ShAttrib1f hit = nearest_root(k(0), k(1), k(2), root, count);
    out = join(hit * gain, join(root, count));
  } SH_END;
  EXPECT_NE(sh::print(p).find("hit"), std::string::npos) << "SH_DECL names the variable";
  shUseBackend("interp");
  ShChannel<ShAttrib1f> which(std::vector<float>{0, 1});
  ShChannel<ShAttrib3f> out;
  out = p << which;
  EXPECT_EQ(out[0], 2.f);
  EXPECT_EQ(out[1], 1.f);
  EXPECT_EQ(out[2], 2.f);
  EXPECT_EQ(out[3], 0.f);
  EXPECT_EQ(out[5], 0.f);
}

}  // namespace
