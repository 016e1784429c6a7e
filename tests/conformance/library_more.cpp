// The library functions of Sh and GLSL that are expanded into operations
// while recording (library_more.hpp), and the user-facing names of the
// operations added through the table, on every backend, against references
// computed here in double from the same float inputs.
//
// Bounds.  u = 2^-24 is float's unit roundoff.  A result computed through at
// most k roundings of sums and products of the inputs is within
// gamma_k * S of the exact value, where S is the same expression with every
// term's magnitude (Higham, Accuracy and Stability of Numerical Algorithms,
// 3.1); gamma_k = k u / (1 - k u) < (k + 1) u here.  Each check below says
// its k and its S.  Precise mode promises IEEE roundings (f64 mode rounds
// only once, at the output, which the same bound covers); fast math may
// contract, reassociate and divide through a reciprocal, so fast checks
// allow 8 times the precise bound (and skip what fast math gives up: NaN,
// infinities, division by zero).
#include <algorithm>
#include <array>
#include <numeric>

#include "harness.hpp"

namespace conformance {
namespace {

constexpr double kU = 0x1p-24;

struct Checker {
  const Conformance& t;
  // gamma_k * scale, for k roundings, loosened for fast math.
  double gamma(int k, double scale) const { return (k + 1) * kU * scale * (t.fast() ? 8 : 1); }
  void near(double got, double want, double bound, const std::string& what) const {
    EXPECT_LE(std::fabs(got - want), bound) << what << ": got " << got << ", want " << want;
  }
};

std::string at(const char* what, std::size_t e) { return std::string(what) + " at element " + std::to_string(e); }

// ---- the operations added through the table, by their library names ----

TEST_P(Conformance, HyperbolicBaseTenAndCubeRootByTheirLibraryNames) {
  using sh::Attrib3f;
  sh::Program p = SH_BEGIN_PROGRAM("library_new_ops") {
    sh::Input<Attrib3f> x;
    sh::Output<Attrib3f> sh_, ch, th, ash, ach, ath, e10, l10, cr;
    sh_ = sh::sinh(x);
    ch = sh::cosh(x);
    th = sh::tanh(x);
    ash = sh::asinh(x);
    ach = sh::acosh(x);
    ath = sh::atanh(x);
    e10 = sh::exp10(x);
    l10 = sh::log10(x);
    cr = sh::cbrt(x);
  } SH_END;
  std::vector<float> xs = {0.5f, -0.75f, 1.5f, 2, 10, -3, 0.125f, 1e-3f, 30, -0.999f, 1.25f, 7.5f};
  sh::Channel<Attrib3f> in(xs);
  std::vector<sh::Channel<Attrib3f>> out(9);
  std::vector<std::shared_ptr<sh::detail::Buffer>> outs(out.begin(), out.end());
  run(p, {in}, outs);
  struct Fn {
    const char* name;
    double (*ref)(double);
  };
  const Fn fns[] = {{"sinh", [](double x) { return std::sinh(x); }},   {"cosh", [](double x) { return std::cosh(x); }},
                    {"tanh", [](double x) { return std::tanh(x); }},   {"asinh", [](double x) { return std::asinh(x); }},
                    {"acosh", [](double x) { return std::acosh(x); }}, {"atanh", [](double x) { return std::atanh(x); }},
                    {"exp10", [](double x) { return std::pow(10.0, x); }},
                    {"log10", [](double x) { return std::log10(x); }}, {"cbrt", [](double x) { return std::cbrt(x); }}};
  for (std::size_t f = 0; f < 9; ++f)
    for (std::size_t k = 0; k < xs.size(); ++k) {
      double want = fns[f].ref(xs[k]);
      float got = out[f][k];
      UlpBound b = ulp_bound(fns[f].name);
      std::string what = std::string(fns[f].name) + "(" + std::to_string(xs[k]) + ")";
      if (std::isnan(want)) {
        EXPECT_TRUE(fast() || std::isnan(got)) << what;
        continue;
      }
      std::uint64_t d = ulp_distance<float>(static_cast<float>(want), got);
      bool ok = fast() ? d <= b.fast || std::fabs(got - want) <= 1e-4 * std::max(1.0, std::fabs(want)) : d <= b.precise;
      EXPECT_TRUE(ok) << what << ": got " << got << ", want " << want << " (" << d << " ulp)";
    }
}

// ---- norms and reductions ----

TEST_P(Conformance, NormsAndReductions) {
  using sh::Attrib1f;
  using sh::Attrib4f;
  sh::Program p = SH_BEGIN_PROGRAM("norms") {
    sh::Input<Attrib4f> a, b;
    sh::Output<Attrib1f> l1, linf, d1, dinf, pr, hi, lo;
    l1 = sh::length_1(a);
    linf = sh::length_inf(a);
    d1 = sh::distance_1(a, b);
    dinf = sh::distance_inf(a, b);
    pr = sh::prod(a);
    hi = sh::max(a);
    lo = sh::min(a);
  } SH_END;
  std::vector<float> as = {1, -2, 3, -4, 0.1f, 0.2f, -0.3f, 0.4f, 1e3f, -1e-3f, 7, 0.5f, -0.f, 0, 2.5f, -2.5f, 1e10f, 3, -1e10f, 2};
  std::vector<float> bs = {0.5f, 2, -3, 4, 0.3f, -0.1f, 0.2f, 0.4f, 999, 1e-3f, -7, 0.25f, 0, -0.f, 2.5f, 1, 1, -1e10f, 5, 2};
  sh::Channel<Attrib4f> ca(as), cb(bs);
  sh::Channel<Attrib1f> l1, linf, d1, dinf, pr, hi, lo;
  run(p, {ca, cb}, {l1, linf, d1, dinf, pr, hi, lo});
  Checker c{*this};
  for (std::size_t e = 0; e < as.size() / 4; ++e) {
    const float* x = &as[4 * e];
    const float* y = &bs[4 * e];
    double sum = 0, diff_sum = 0, big = 0, diff_big = 0, product = 1;
    for (int k = 0; k < 4; ++k) {
      sum += std::fabs(x[k]);
      big = std::max(big, std::fabs(double(x[k])));
      diff_sum += std::fabs(double(x[k]) - y[k]);
      // Each difference rounds once to float, and max is exact: the rounded
      // largest difference.
      diff_big = std::max(diff_big, std::fabs(double(x[k]) - y[k]));
      product *= x[k];
    }
    c.near(l1[e], sum, c.gamma(3, sum), at("length_1", e));  // 3 additions of exact |a_i|
    EXPECT_EQ(linf[e], float(big)) << at("length_inf", e);
    c.near(d1[e], diff_sum, c.gamma(4, diff_sum), at("distance_1", e));  // a difference, 3 additions
    EXPECT_EQ(dinf[e], float(diff_big)) << at("distance_inf", e);
    c.near(pr[e], product, c.gamma(3, std::fabs(product)), at("prod", e));  // 3 products
    EXPECT_EQ(hi[e], *std::max_element(x, x + 4)) << at("max(a)", e);
    EXPECT_EQ(lo[e], *std::min_element(x, x + 4)) << at("min(a)", e);
  }
}

// ---- polynomial and lighting coefficients ----

TEST_P(Conformance, Poly) {
  using sh::Attrib4f;
  const std::array<float, 4> coeffs = {0.5f, -1.25f, 2, 0.75f};
  sh::Program p = SH_BEGIN_PROGRAM("poly") {
    sh::Input<Attrib4f> x;
    sh::Output<Attrib4f> cubic;
    sh::Output<sh::Attrib2f> line;
    cubic = sh::poly(x, sh::ConstAttrib4f(coeffs[0], coeffs[1], coeffs[2], coeffs[3]));
    line = sh::poly(x(0, 1), sh::ConstAttrib2f(coeffs[0], coeffs[1]));
  } SH_END;
  std::vector<float> xs = {0, 1, -1, 0.5f, 2, -3, 10, 0.1f, -0.7f, 1e3f, 3.75f, -2.5f};
  sh::Channel<Attrib4f> cx(xs), cubic;
  sh::Channel<sh::Attrib2f> line;
  run(p, {cx}, {cubic, line});
  Checker c{*this};
  for (std::size_t k = 0; k < xs.size(); ++k) {
    double x = xs[k], want = 0, scale = 0;
    for (int j = 3; j >= 0; --j) {
      want = want * x + coeffs[j];
      scale = scale * std::fabs(x) + std::fabs(coeffs[j]);
    }
    // Horner of degree n rounds 2n times (Higham 5.1): gamma_6 sum |c_j x^j|.
    c.near(cubic[k], want, c.gamma(6, scale), at("poly degree 3", k));
  }
  for (std::size_t k = 0; k < 6; ++k) {
    double x = xs[k / 2 * 4 + k % 2];
    c.near(line[k], coeffs[0] + coeffs[1] * x, c.gamma(2, std::fabs(coeffs[0]) + std::fabs(coeffs[1] * x)),
           at("poly degree 1", k));
  }
}

TEST_P(Conformance, Lit) {
  using sh::Attrib1f;
  sh::Program p = SH_BEGIN_PROGRAM("lit") {
    sh::Input<Attrib1f> a, b, e;
    sh::Output<sh::Attrib4f> lighting;
    lighting = sh::lit(a, b, e);
  } SH_END;
  // a <= 0, a > 0; b < 0, b = 0, b > 0; exponents inside and outside +-128.
  std::vector<float> as = {-1, 0, 0.5f, 0.5f, 0.5f, 2, 1, 0.25f, 1};
  std::vector<float> bs = {0.5f, 0.5f, -0.5f, 0, 0.75f, 1.01f, 1.01f, 2, 0.5f};
  std::vector<float> es = {2, 2, 3, 4, 10, 200, -300, 0.5f, 0};
  sh::Channel<Attrib1f> ca(as), cb(bs), ce(es);
  sh::Channel<sh::Attrib4f> lighting;
  run(p, {ca, cb, ce}, {lighting});
  UlpBound pow_bound = ulp_bound("pow");
  for (std::size_t e = 0; e < as.size(); ++e) {
    double x = std::max(double(as[e]), 0.0), y = std::max(double(bs[e]), 0.0);
    double w = std::clamp(double(es[e]), -128.0, 128.0);
    double z = x > 0 ? std::pow(y, w) : 0;
    EXPECT_EQ(lighting[4 * e], 1.f) << at("lit x", e);
    EXPECT_EQ(lighting[4 * e + 1], float(x)) << at("lit y", e);
    EXPECT_EQ(lighting[4 * e + 3], 1.f) << at("lit w", e);
    // z is one pow: the table's bound for pow.
    float got = lighting[4 * e + 2];
    std::uint64_t d = ulp_distance<float>(float(z), got);
    bool ok = fast() ? d <= pow_bound.fast || std::fabs(got - z) <= 1e-4 * std::max(1.0, z) : d <= pow_bound.precise;
    EXPECT_TRUE(ok) << at("lit z", e) << ": got " << got << ", want " << z << " (" << d << " ulp)";
  }
}

// ---- steps and pulses ----

double smoothstep_ref(double a, double b, double x) {
  double t = std::clamp((x - a) / (b - a), 0.0, 1.0);
  return t * t * (3 - 2 * t);
}
double linstep_ref(double t, double c, double w) { return std::clamp((t - c) / w + 0.5, 0.0, 1.0); }

TEST_P(Conformance, StepsAndPulses) {
  using sh::Attrib4f;
  sh::Program p = SH_BEGIN_PROGRAM("steps") {
    sh::Input<Attrib4f> x, lo, hi;
    sh::Output<Attrib4f> s, s_attrib, l, pulse;
    s = sh::smoothstep(0.25f, 0.75f, x);
    s_attrib = sh::smoothstep(lo, hi, x);
    l = sh::linstep(x, 0.5f, 0.25f);
    pulse = sh::smoothpulse(x, 0.25f, 0.75f, 0.125f);
  } SH_END;
  std::vector<float> xs = {-1, 0, 0.25f, 0.3f, 0.4375f, 0.5f, 0.6f, 0.75f, 0.8f, 1, 2, 0.2f, 0.7f, 0.36f, 0.64f, 1e3f};
  std::vector<float> los(xs.size()), his(xs.size());
  for (std::size_t k = 0; k < xs.size(); ++k) {
    los[k] = -0.5f + 0.25f * float(k % 4);
    his[k] = los[k] + 0.5f + 0.5f * float(k % 3);
  }
  sh::Channel<Attrib4f> cx(xs), clo(los), chi(his), s, s_attrib, l, pulse;
  run(p, {cx, clo, chi}, {s, s_attrib, l, pulse});
  Checker c{*this};
  for (std::size_t k = 0; k < xs.size(); ++k) {
    double x = xs[k];
    // smoothstep: t takes 3 roundings, and |d/dt 3t^2 - 2t^3| <= 1.5; the
    // cubic takes 3 more on values <= 1: 1.5 gamma_3 + gamma_3 < gamma_10.
    c.near(s[k], smoothstep_ref(0.25, 0.75, x), c.gamma(10, 1), at("smoothstep", k));
    c.near(s_attrib[k], smoothstep_ref(los[k], his[k], x), c.gamma(10, 1), at("smoothstep(Attrib edges)", k));
    // linstep: a difference and a quotient (gamma_2 on values <= 1/2 in the
    // ramp), then + 1/2 (one rounding of a value <= 1): gamma_2.
    c.near(l[k], linstep_ref(x, 0.5, 0.25), c.gamma(2, 1), at("linstep", k));
    double want = linstep_ref(x, 0.25, 0.125) - linstep_ref(x, 0.75, 0.125);
    c.near(pulse[k], want, c.gamma(6, 1), at("smoothpulse", k));  // two linsteps and their difference
  }
}

// ---- sort and cast ----

TEST_P(Conformance, SortAndCast) {
  using sh::Attrib4f;
  using sh::Attrib4i;
  sh::Program p = SH_BEGIN_PROGRAM("sort_cast") {
    sh::Input<Attrib4f> v;
    sh::Input<Attrib4i> iv;
    sh::Output<Attrib4f> s4, zero_padded, filled;
    sh::Output<sh::Attrib3f> s3, padded3;
    sh::Output<sh::Attrib2f> s2, truncated;
    sh::Output<Attrib4i> si;
    sh::Output<sh::Attrib3i> ipadded;
    s4 = sh::sort(v);
    s3 = sh::sort(v(0, 1, 2));
    s2 = sh::sort(v(0, 1));
    si = sh::sort(iv);
    truncated = sh::cast<2>(v);
    padded3 = sh::cast<3>(v(3));
    zero_padded = sh::cast<4>(v(0, 1));
    filled = sh::fillcast<4>(v(0, 1));
    ipadded = sh::cast<3>(iv(2, 3));
  } SH_END;
  std::vector<float> vs = {4, 3, 2, 1, 1, 2, 3, 4, 2, 2, 1, 1, -0.5f, 1e9f, -1e9f, 0, 3, -1, 3, -1, 0.25f, 0.125f, 0.5f, 0.375f};
  std::vector<std::int32_t> is = {3, -7, INT32_MAX, INT32_MIN, 0, 0, -1, 1, 5, 4, 3, 2, 9, 9, 9, -9, 1, 2, 3, 4, -4, -3, -2, -1};
  sh::Channel<Attrib4f> cv(vs), s4, zero_padded, filled;
  sh::Channel<Attrib4i> civ(is), si;
  sh::Channel<sh::Attrib3f> s3, padded3;
  sh::Channel<sh::Attrib2f> s2, truncated;
  sh::Channel<sh::Attrib3i> ipadded;
  run(p, {cv, civ}, {s4, zero_padded, filled, s3, padded3, s2, truncated, si, ipadded});
  for (std::size_t e = 0; e < vs.size() / 4; ++e) {
    const float* v = &vs[4 * e];
    const std::int32_t* iv = &is[4 * e];
    std::array<float, 4> w4{v[0], v[1], v[2], v[3]};
    std::array<float, 3> w3{v[0], v[1], v[2]};
    std::array<float, 2> w2{v[0], v[1]};
    std::array<std::int32_t, 4> wi{iv[0], iv[1], iv[2], iv[3]};
    std::sort(w4.begin(), w4.end());
    std::sort(w3.begin(), w3.end());
    std::sort(w2.begin(), w2.end());
    std::sort(wi.begin(), wi.end());
    for (int k = 0; k < 4; ++k) {
      EXPECT_EQ(s4[4 * e + k], w4[k]) << at("sort width 4", e);
      EXPECT_EQ(si[4 * e + k], wi[k]) << at("sort int width 4", e);
      EXPECT_EQ(zero_padded[4 * e + k], k < 2 ? v[k] : 0.f) << at("cast<4>", e);
      EXPECT_EQ(filled[4 * e + k], v[std::min(k, 1)]) << at("fillcast<4>", e);
    }
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(s3[3 * e + k], w3[k]) << at("sort width 3", e);
      EXPECT_EQ(padded3[3 * e + k], k == 0 ? v[3] : 0.f) << at("cast<3> of one", e);
      EXPECT_EQ(ipadded[3 * e + k], k < 2 ? iv[2 + k] : 0) << at("cast<3> int", e);
    }
    for (int k = 0; k < 2; ++k) {
      EXPECT_EQ(s2[2 * e + k], w2[k]) << at("sort width 2", e);
      EXPECT_EQ(truncated[2 * e + k], v[k]) << at("cast<2>", e);
    }
  }
}

}  // namespace
}  // namespace conformance
