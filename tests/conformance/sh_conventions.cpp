// Sh 0.8's conventions that Sh code depends on, on every backend and mode:
// a program writes its inputs through a local copy (the input stream is
// untouched), assignment converts between scalar types with the defined
// float-to-int results, && and || are min and max and any and all the
// largest and smallest component on values other than 0 and 1, and
// reflect, refract and faceforward are Sh's (docs/sh-differences.md).
#include <array>
#include <limits>

#include "harness.hpp"

namespace conformance {
namespace {

using V3 = std::array<double, 3>;

double dot3(V3 a, V3 b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
V3 unit(V3 a) {
  double l = std::sqrt(dot3(a, a));
  return {a[0] / l, a[1] / l, a[2] / l};
}
V3 at3(const sh::Channel<sh::Attrib3f>& c, std::size_t e) { return {c[3 * e], c[3 * e + 1], c[3 * e + 2]}; }

TEST_P(Conformance, WritesToAnInputGoToALocalCopy) {
  sh::Program p = SH_BEGIN_PROGRAM("writes_inputs") {
    sh::Input<sh::Attrib1f> x;
    sh::Input<sh::Attrib2f> y;
    sh::Output<sh::Attrib1f> r, before;
    sh::Output<sh::Attrib2f> s;
    before = x;
    x += 1.0f;
    SH_IF(x > 2.0f) { y(1) = x * 10.0f; }
    SH_ENDIF;
    x *= 2.0f;
    r = x;
    s = y;
  } SH_END;
  std::vector<float> xs = {0.5f, 1.5f, -3.0f, 4.0f}, ys = {1, 2, 3, 4, 5, 6, 7, 8};
  sh::Channel<sh::Attrib1f> cx(xs), r, before;
  sh::Channel<sh::Attrib2f> cy(ys), s;
  run(p, {cx, cy}, {r, before, s});
  for (std::size_t e = 0; e < xs.size(); ++e) {
    float x1 = xs[e] + 1.0f;
    EXPECT_EQ(before[e], xs[e]) << "element " << e;
    EXPECT_EQ(r[e], 2.0f * x1) << "element " << e;
    EXPECT_EQ(s[2 * e], ys[2 * e]) << "element " << e;
    EXPECT_EQ(s[2 * e + 1], x1 > 2.0f ? x1 * 10.0f : ys[2 * e + 1]) << "element " << e;
    EXPECT_EQ(cx[e], xs[e]) << "the input stream was written at element " << e;
    EXPECT_EQ(cy[2 * e + 1], ys[2 * e + 1]) << "the input stream was written at element " << e;
  }
}

TEST_P(Conformance, AssignmentConvertsBetweenScalarTypes) {
  sh::Program p = SH_BEGIN_PROGRAM("converts") {
    sh::Input<sh::Attrib1f> x;
    sh::Input<sh::Attrib1i> n;
    sh::Output<sh::Attrib1i> truncated;
    sh::Output<sh::Attrib1f> widened, mask;
    truncated = x;
    sh::Attrib1f f = n;
    widened = f + 0.5f;
    sh::Attrib1b b = x;
    mask = b;
  } SH_END;
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  std::vector<float> xs = {2.75f, -2.75f, 0.0f, 3e9f, -3e9f, inf, -inf, nan, 0.25f, -0.f};
  std::vector<std::int32_t> ns = {0, 1, -1, 7, 1 << 24, -(1 << 20), 100, 42, -5, 3};
  const std::int32_t big = std::numeric_limits<std::int32_t>::max(), small = std::numeric_limits<std::int32_t>::min();
  std::vector<std::int32_t> want_int = {2, -2, 0, big, small, big, small, 0, 0, 0};
  sh::Channel<sh::Attrib1f> cx(xs), widened, mask;
  sh::Channel<sh::Attrib1i> cn(ns), truncated;
  run(p, {cx, cn}, {truncated, widened, mask});
  for (std::size_t e = 0; e < xs.size(); ++e) {
    if (!fast() || std::isfinite(xs[e])) {
      EXPECT_EQ(truncated[e], want_int[e]) << "cast of " << xs[e];
    }
    EXPECT_EQ(widened[e], static_cast<float>(ns[e]) + 0.5f) << "element " << e;
    if (!fast() || !std::isnan(xs[e])) {
      EXPECT_EQ(mask[e], xs[e] > 0 ? 1.0f : 0.0f) << "bool of " << xs[e];
    }
  }
}

TEST_P(Conformance, LogicOperatorsAreMinAndMax) {
  sh::Program p = SH_BEGIN_PROGRAM("logic") {
    sh::Input<sh::Attrib3f> a, b;
    sh::Output<sh::Attrib3f> both, either, neither;
    sh::Output<sh::Attrib1f> any_, all_;
    both = a && b;
    either = a || b;
    neither = !a;
    any_ = sh::any(a);
    all_ = sh::all(a);
  } SH_END;
  std::vector<float> as = {2, 0.5f, -1, 0, 1, 1, -3, -2, -0.5f, 0.25f, 4, 9};
  std::vector<float> bs = {0.5f, 3, -2, 1, 0, 1, -1, 5, 0, 7, 0.125f, -9};
  sh::Channel<sh::Attrib3f> ca(as), cb(bs), both, either, neither;
  sh::Channel<sh::Attrib1f> any_, all_;
  run(p, {ca, cb}, {both, either, neither, any_, all_});
  for (std::size_t e = 0; e < as.size() / 3; ++e) {
    const float* x = &as[3 * e];
    for (int c = 0; c < 3; ++c) {
      std::size_t k = 3 * e + c;
      EXPECT_EQ(both[k], std::min(as[k], bs[k])) << as[k] << " && " << bs[k];
      EXPECT_EQ(either[k], std::max(as[k], bs[k])) << as[k] << " || " << bs[k];
      EXPECT_EQ(neither[k], as[k] > 0 ? 0.0f : 1.0f) << "!" << as[k];
    }
    EXPECT_EQ(any_[e], std::max({x[0], x[1], x[2]})) << "any at element " << e;
    EXPECT_EQ(all_[e], std::min({x[0], x[1], x[2]})) << "all at element " << e;
  }
}

// Vectors of every length, none of them unit: Sh normalises the normal in
// reflect, both vectors in refract, and nothing in faceforward.
TEST_P(Conformance, GeometryFunctionsAreShs) {
  sh::Program p = SH_BEGIN_PROGRAM("sh_geometry") {
    sh::Input<sh::Attrib3f> a, n;
    sh::Output<sh::Attrib3f> refl, into, out_of, ff;
    refl = sh::reflect(a, n);
    into = sh::refract(a, n, 1.5f);
    out_of = sh::refract(a, n, 1.0f / 1.5f);
    ff = sh::faceforward(a, n);
  } SH_END;
  std::vector<float> as = {3, 4, 5, 1, 0, 1, 0.1f, -0.2f, 0.05f, 1, 0, 0.2f, -2, 1, 7};
  std::vector<float> ns = {0, 0, 5, 0, 0, 3, 0.3f, 0.1f, 2, 0, 0, 0.5f, 1, 1, -1};
  sh::Channel<sh::Attrib3f> ca(as), cn(ns), refl, into, out_of, ff;
  run(p, {ca, cn}, {refl, into, out_of, ff});
  double tol = fast() ? 1e-3 : 1e-5;
  for (std::size_t e = 0; e < as.size() / 3; ++e) {
    V3 a{as[3 * e], as[3 * e + 1], as[3 * e + 2]}, n{ns[3 * e], ns[3 * e + 1], ns[3 * e + 2]};
    V3 un = unit(n), ua = unit(a);
    double an = dot3(a, un), la = std::sqrt(dot3(a, a));
    V3 got_refl = at3(refl, e), got_ff = at3(ff, e), got_into = at3(into, e), got_out = at3(out_of, e);
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(got_refl[c], 2 * an * un[c] - a[c], tol * la) << "reflect at element " << e;
      EXPECT_EQ(got_ff[c], dot3(a, n) > 0 ? n[c] : -n[c]) << "faceforward at element " << e;
    }
    const std::pair<double, V3> cases[] = {{1.5, got_into}, {1 / 1.5, got_out}};
    for (const auto& [eta, got] : cases) {
      double cosv = dot3(ua, un), r = 1 / eta, k = 1 + r * r * (cosv * cosv - 1);
      for (int c = 0; c < 3; ++c) {
        double want = k < 0 ? 0 : (r * cosv - std::sqrt(k)) * un[c] - r * ua[c];
        EXPECT_NEAR(got[c], want, tol) << "refract, eta " << eta << ", at element " << e;
      }
    }
  }
}

}  // namespace
}  // namespace conformance
