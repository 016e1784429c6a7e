// The reference interpreter's own features (checked mode) and the run
// call's handling of bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>

#include <sh/sh.hpp>

#include "../common/expect_error.hpp"

namespace {

using namespace sh;

TEST(CheckedMode, ReportsFirstNanAndFirstOutOfRangeRead) {
  Table1D<Attrib1f> t(3);
  t.assign({1, 2, 3});
  Program p = SH_BEGIN_PROGRAM("checked") {
    Input<Attrib1f> x;
    Output<Attrib1f> r;
    Attrib1f s = sqrt(x);
    r = s + t[x];
  } SH_END;
  Channel<Attrib1f> in(std::vector<float>{1, 2, -4, 7}), out;
  Options o;
  o.checked = true;
  RunStats s = run(p, {in}, {out}, backend("interp", o));
  ASSERT_EQ(s.diagnostics.size(), 2u);
  std::string all = s.diagnostics[0] + "\n" + s.diagnostics[1];
  EXPECT_NE(all.find("first NaN: element 2"), std::string::npos) << all;
  EXPECT_NE(all.find("sqrt"), std::string::npos) << all;
  EXPECT_NE(all.find("first out-of-range table read: element 2"), std::string::npos) << all;
  EXPECT_NE(all.find("load #0"), std::string::npos) << all;  // the legal form of the fetch

  RunStats unchecked = run(p, {in}, {out}, backend("interp"));
  EXPECT_TRUE(unchecked.diagnostics.empty());
}

// A NaN made from constants is left to the run by the passes, so that a
// checked run still names the instruction that made it.
TEST(CheckedMode, ReportsANanMadeFromConstants) {
  Program p = SH_BEGIN_PROGRAM("constant_nan") {
    Input<Attrib1f> x;
    Output<Attrib1f> r;
    r = x + ConstAttrib<1>(0.f) / ConstAttrib<1>(0.f);
  } SH_END;
  Channel<Attrib1f> in(std::vector<float>{1, 2}), out;
  Options o;
  o.checked = true;
  RunStats s = run(p, {in}, {out}, backend("interp", o));
  EXPECT_TRUE(std::isnan(out[0]));
  ASSERT_EQ(s.diagnostics.size(), 1u);
  EXPECT_NE(s.diagnostics[0].find("first NaN: element 0"), std::string::npos) << s.diagnostics[0];
  EXPECT_NE(s.diagnostics[0].find("div"), std::string::npos) << s.diagnostics[0];
}

TEST(RunErrors, StreamsOfDifferentLengths) {
  Program p = SH_BEGIN_PROGRAM("two_inputs") {
    Input<Attrib1f> a;
    Input<Attrib1f> b;
    Output<Attrib1f> r;
    r = a + b;
  } SH_END;
  Channel<Attrib1f> a(std::vector<float>{1, 2, 3}), b(std::vector<float>{1, 2}), r;
  expect_error([&] { run(p, {a, b}, {r}); }, {"two_inputs", "input channel 1 holds 2 elements", "holds 3"});
  expect_error([&] { run(p, {a}, {r}); }, {"two_inputs", "takes 2 input channels; 1 were given"});
  expect_error([&] { run(p, {a, nullptr}, {r}); }, {"input channel 1 is missing"});
  Channel<Attrib2f> wide(std::vector<float>{1, 2, 3, 4, 5, 6});
  expect_error([&] { run(p, {a, wide}, {r}); }, {"input 1 is f32 but its channel holds f32x2"});
  Channel<Attrib1f> wrong_size(5);
  expect_error([&] { run(p, {a, a}, {wrong_size}); }, {"output channel 0 holds 5 elements"});
}

TEST(RunErrors, TableNeverFilled) {
  Table2D<Attrib1f> empty(2, 2);
  empty.name("heights");
  Program p = SH_BEGIN_PROGRAM("reads_table") {
    Input<Attrib2i> c;
    Output<Attrib1f> r;
    r = empty[c];
  } SH_END;
  Channel<Attrib2i> c(std::vector<std::int32_t>{0, 0}), r;
  Channel<Attrib1f> out;
  expect_error([&] { run(p, {c}, {out}); }, {"reads_table", "table 0 'heights' was never filled"});
}

TEST(RunErrors, UnknownBackend) {
  Program p = SH_BEGIN_PROGRAM("any") {
    Output<Attrib1f> r;
    r = 1.0f;
  } SH_END;
  Channel<Attrib1f> out(1);
  expect_error([&] { run(p, {}, {out}, backend("no-such-backend")); }, {"unknown backend 'no-such-backend'", "interp"});
  expect_error([&] { use_backend("nope"); }, {"unknown backend 'nope'"});
}

TEST(RunErrors, EmptyProgramHandle) {
  Program none;
  Channel<Attrib1f> out(1);
  expect_error([&] { run(none, {}, {out}); }, {"empty sh::Program"});
}

// The environment names the default until use_backend chooses, and a
// choice of a backend that does not exist is refused and changes nothing.
// use_backend's choice lasts for the process, so the sequence runs in a
// fresh one (a second run of this test, or one after another that chose,
// would find the choice made).
TEST(Registry, DefaultBackendFollowsEnvironmentAndUseBackend) {
  std::vector<std::string> names = backend_names();
  EXPECT_NE(std::find(names.begin(), names.end(), "interp"), names.end());
  const std::string style = GTEST_FLAG_GET(death_test_style);
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  auto sequence = [] {
    auto expect_default = [](const std::string& name, const char* why) {
      if (default_backend_name() == name) return;
      std::fprintf(stderr, "%s: the default is %s, not %s\n", why, default_backend_name().c_str(), name.c_str());
      std::exit(1);
    };
    setenv("SH_BACKEND", "elsewhere", 1);
    expect_default("elsewhere", "the environment's");
    try {
      use_backend("no-such-backend");
      std::exit(2);
    } catch (const Error&) {
    }
    expect_default("elsewhere", "after a refused choice");
    use_backend("interp");
    expect_default("interp", "use_backend's choice comes before the environment's");
    unsetenv("SH_BACKEND");
    expect_default("interp", "use_backend's choice lasts");
    std::exit(0);
  };
  EXPECT_EXIT(sequence(), testing::ExitedWithCode(0), "");
  GTEST_FLAG_SET(death_test_style, style);
}

TEST(Precision, F64ComputesFloatsAsDouble) {
  Program p = SH_BEGIN_PROGRAM("cancel") {
    Input<Attrib1f> x;
    Output<Attrib1f> r;
    r = (x + 1e8f) - 1e8f;
  } SH_END;
  Channel<Attrib1f> in(std::vector<float>{1.0f}), out;
  run(p, {in}, {out}, backend("interp"));
  EXPECT_EQ(out[0], 0.f);  // 1e8 + 1 rounds to 1e8 in binary32
  Options o;
  o.precision = Precision::F64;
  run(p, {in}, {out}, backend("interp", o));
  EXPECT_EQ(out[0], 1.f);
}

}  // namespace
