// Compound library functions (vector geometry, interpolation, reductions,
// matrices) against references computed here in double.
#include <array>
#include <cmath>
#include <limits>

#include "harness.hpp"

namespace conformance {
namespace {

using V3 = std::array<double, 3>;
double dot3(V3 a, V3 b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// Relative tolerance for results of a few float operations.
void expect_near_rel(double got, double want, const std::string& what, double rel = 4e-6) {
  if (std::isnan(want)) {
    EXPECT_TRUE(std::isnan(got)) << what;
    return;
  }
  EXPECT_NEAR(got, want, rel * std::max(1e-30, std::fabs(want)) + 1e-37) << what;
}

struct Vectors {
  std::vector<float> a, b;
};

Vectors sample_vectors() {
  Vectors v;
  const float cases[][6] = {{1, 0, 0, 0, 1, 0},        {1, 2, 3, -4, 5, 0.5f},   {0, 0, 0, 1, 1, 1},
                            {1e30f, 2e30f, -1e30f, 1, 0, 0}, {1e-30f, -2e-30f, 3e-30f, 0, 0, 1},
                            {0.3f, -0.7f, 0.2f, 0.1f, 0.9f, -0.4f}, {-5, 0, 5, 2, 2, 2},
                            {1e38f, -2e38f, 1, 0, 1, 0}};
  for (const auto& c : cases) {
    v.a.insert(v.a.end(), c, c + 3);
    v.b.insert(v.b.end(), c + 3, c + 6);
  }
  return v;
}

TEST_P(Conformance, GeometryFunctions) {
  using sh::Attrib1f;
  using sh::Attrib3f;
  sh::Program p = SH_BEGIN_PROGRAM("geometry") {
    sh::Input<Attrib3f> a;
    sh::Input<Attrib3f> b;
    sh::Output<Attrib1f> d, len, dist;
    sh::Output<Attrib3f> crs, nrm, refl, refr, ff, lrp;
    d = sh::dot(a, b);
    len = sh::length(a);
    dist = sh::distance(a, b);
    crs = a ^ b;
    nrm = sh::normalize(a);
    refl = sh::reflect(a, sh::normalize(b));
    refr = sh::refract(a, b, 1.25f);
    ff = sh::faceforward(b, a);
    lrp = sh::lerp(0.25f, a, b);
  } SH_END;
  Vectors v = sample_vectors();
  sh::Channel<Attrib3f> ca(v.a), cb(v.b), crs, nrm, refl, refr, ff, lrp;
  sh::Channel<Attrib1f> d, len, dist;
  run(p, {ca, cb}, {d, len, dist, crs, nrm, refl, refr, ff, lrp});
  double rel = fast() ? 1e-3 : 4e-6;
  for (std::size_t e = 0; e < v.a.size() / 3; ++e) {
    V3 a{v.a[3 * e], v.a[3 * e + 1], v.a[3 * e + 2]}, b{v.b[3 * e], v.b[3 * e + 1], v.b[3 * e + 2]};
    double la = std::sqrt(dot3(a, a)), lb = std::sqrt(dot3(b, b));
    bool tiny = la < 1e-20 && la > 0, huge_or_tiny = la > 1e20 || tiny;
    std::string at = " at element " + std::to_string(e);
    // Fast math too for huge vectors (2e38: a divisor past 2^126, whose
    // reciprocal fast division flushes to 0, is not taken).
    if (!(fast() && tiny)) {
      expect_near_rel(len[e], la, "length" + at, rel);
      for (int c = 0; c < 3; ++c) expect_near_rel(nrm[3 * e + c], la > 0 ? a[c] / la : 0.0, "normalize" + at, rel);
    }
    if (huge_or_tiny) continue;
    expect_near_rel(d[e], dot3(a, b), "dot" + at, rel * 10);
    V3 diff{a[0] - b[0], a[1] - b[1], a[2] - b[2]};
    expect_near_rel(dist[e], std::sqrt(dot3(diff, diff)), "distance" + at, rel);
    V3 cr{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
    V3 nb{b[0] / lb, b[1] / lb, b[2] / lb};
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(crs[3 * e + c], cr[c], 1e-5 * (1 + la * lb)) << "cross" + at;
      EXPECT_NEAR(refl[3 * e + c], 2 * dot3(a, nb) * nb[c] - a[c], 1e-5 * (1 + la)) << "reflect" + at;
      EXPECT_NEAR(ff[3 * e + c], dot3(b, a) > 0 ? a[c] : -a[c], 1e-6 * (1 + la)) << "faceforward" + at;
      EXPECT_NEAR(lrp[3 * e + c], 0.25 * a[c] + 0.75 * b[c], 1e-5 * (1 + la + lb)) << "lerp" + at;
    }
    if (la > 0) {
      // Sh's refract(v, n, eta): v points away from the surface, eta is the
      // index entered over the index left (1.25: 0.8 the other way).
      V3 nv{a[0] / la, a[1] / la, a[2] / la};
      double cosv = dot3(nb, nv), r = 0.8, k = 1 - r * r * (1 - cosv * cosv);
      for (int c = 0; c < 3; ++c) {
        double want = k < 0 ? 0 : (r * cosv - std::sqrt(k)) * nb[c] - r * nv[c];
        EXPECT_NEAR(refr[3 * e + c], want, fast() ? 1e-3 : 1e-5) << "refract" + at;
      }
    }
  }
}

// Nothing to bend: refract of a zero view vector or normal is zero, not a
// vector of some other length.
TEST_P(Conformance, RefractOfAZeroVectorIsZero) {
  sh::Program p = SH_BEGIN_PROGRAM("refract_zero") {
    sh::Input<sh::Vector3f> v;
    sh::Input<sh::Vector3f> n;
    sh::Output<sh::Vector3f> r;
    r = sh::refract(v, n, 1.25f);
  } SH_END;
  sh::Channel<sh::Vector3f> cv(std::vector<float>{0, 0, 0, 1, 0, 0}), cn(std::vector<float>{0, 0, 1, 0, 0, 0}), out;
  run(p, {cv, cn}, {out});
  for (int k = 0; k < 6; ++k) EXPECT_EQ(out[k], 0.f) << k;
}

// frac lies in [0, 1) where the kernel computes (a tiny negative a gives
// a - floor(a) = 1 once rounded), so the cell it picks of four is the
// last, not one past it.
TEST_P(Conformance, FracOfATinyNegativeIsBelowOne) {
  sh::Program p = SH_BEGIN_PROGRAM("frac_tiny") {
    sh::Input<sh::Attrib1f> x;
    sh::Output<sh::Attrib1f> below, cell;
    sh::Attrib1f f = sh::frac(x);
    below = f < 1.0f;
    cell = sh::floor(f * 4.0f);
  } SH_END;
  sh::Channel<sh::Attrib1f> in(std::vector<float>{-1e-8f, -1e-20f, -0x1p-25f, 2.5f}), below, cell;
  run(p, {in}, {below, cell});
  for (int k = 0; k < 4; ++k) EXPECT_EQ(below[k], 1.0f) << k;
  for (int k = 0; k < 3; ++k) EXPECT_EQ(cell[k], 3.0f) << k;
  EXPECT_EQ(cell[3], 2.0f);
}

TEST_P(Conformance, NormalizeOfZeroIsZero) {
  sh::Program p = SH_BEGIN_PROGRAM("normalize_zero") {
    sh::Input<sh::Vector3f> v;
    sh::Output<sh::Vector3f> n;
    n = sh::normalize(v);
  } SH_END;
  sh::Channel<sh::Vector3f> in(std::vector<float>{0, 0, 0, -0.f, 0, -0.f}), out;
  run(p, {in}, {out});
  for (int k = 0; k < 6; ++k) EXPECT_EQ(out[k], 0.f);
}

// A NaN anywhere is NaN everywhere: the largest magnitude, which scales
// the vector, may pass over it, so a NaN beside zeros once gave zero.
TEST_P(Conformance, NormalizeAndLengthOfANaNAreNaN) {
  if (fast()) GTEST_SKIP() << "fast math does not promise NaNs (documented in ulp_bounds.hpp)";
  sh::Program p = SH_BEGIN_PROGRAM("normalize_nan") {
    sh::Input<sh::Vector3f> v;
    sh::Output<sh::Vector3f> n;
    sh::Output<sh::Attrib1f> len;
    n = sh::normalize(v);
    len = sh::length(v);
  } SH_END;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  sh::Channel<sh::Vector3f> in(
      std::vector<float>{nan, 0, 0, 0, 0, nan, 3, nan, 4, nan, 1e30f, 0, inf, nan, 0, nan, -inf, 0}),
      n;
  sh::Channel<sh::Attrib1f> len;
  run(p, {in}, {n, len});
  for (int e = 0; e < 6; ++e) {
    EXPECT_TRUE(std::isnan(len[e])) << "element " << e;
    for (int c = 0; c < 3; ++c) EXPECT_TRUE(std::isnan(n[3 * e + c])) << "element " << e << " component " << c;
  }
}

TEST_P(Conformance, ScalarHelpersAndReductions) {
  using sh::Attrib1f;
  using sh::Attrib4f;
  sh::Program p = SH_BEGIN_PROGRAM("helpers") {
    sh::Input<Attrib4f> x;
    sh::Output<Attrib4f> clamped, saturated, positive, madded;
    sh::Output<Attrib1f> any_, all_, lo, hi, total;
    sh::Output<Attrib4f> filled, joined;
    clamped = sh::clamp(x, -1.0f, 2.0f);
    saturated = sh::sat(x);
    positive = sh::pos(x);
    madded = sh::mad(x, 2.0f, 1.0f);
    any_ = sh::any(x);
    all_ = sh::all(x);
    lo = sh::min_component(x);
    hi = sh::max_component(x);
    total = sh::sum(x);
    filled = sh::fillcast<4>(x(0, 1));
    joined = sh::join(x(3), x(0, 1, 2));
  } SH_END;
  std::vector<float> xs = {-3, 0.5f, 4, 1, 1, 2, 3, 4, -1, -2, -0.5f, 0, 0.25f, 0.75f, 10, -10};
  sh::Channel<Attrib4f> cx(xs), clamped, saturated, positive, madded, filled, joined;
  sh::Channel<Attrib1f> any_, all_, lo, hi, total;
  run(p, {cx}, {clamped, saturated, positive, madded, any_, all_, lo, hi, total, filled, joined});
  for (std::size_t e = 0; e < 4; ++e) {
    const float* v = &xs[4 * e];
    for (int c = 0; c < 4; ++c) {
      EXPECT_EQ(clamped[4 * e + c], std::min(std::max(v[c], -1.f), 2.f));
      EXPECT_EQ(saturated[4 * e + c], std::min(std::max(v[c], 0.f), 1.f));
      EXPECT_EQ(positive[4 * e + c], std::max(v[c], 0.f));
      EXPECT_EQ(madded[4 * e + c], v[c] * 2 + 1);
      EXPECT_EQ(filled[4 * e + c], v[std::min(c, 1)]);
      EXPECT_EQ(joined[4 * e + c], c == 0 ? v[3] : v[c - 1]);
    }
    // Sh's any and all: the largest and the smallest component.
    EXPECT_EQ(any_[e], *std::max_element(v, v + 4));
    EXPECT_EQ(all_[e], *std::min_element(v, v + 4));
    EXPECT_EQ(lo[e], *std::min_element(v, v + 4));
    EXPECT_EQ(hi[e], *std::max_element(v, v + 4));
    EXPECT_EQ(total[e], ((v[0] + v[1]) + v[2]) + v[3]);
  }
}

TEST_P(Conformance, MatrixTransformsBySemantic) {
  // A uniform matrix: translate by (1, 2, 3) after scaling x by 2.
  sh::Matrix4x4f m(2.f, 0.f, 0.f, 1.f,  //
                   0.f, 1.f, 0.f, 2.f,  //
                   0.f, 0.f, 1.f, 3.f,  //
                   0.f, 0.f, 0.f, 1.f);
  sh::Program p = SH_BEGIN_PROGRAM("transforms") {
    sh::Input<sh::Point3f> pt;
    sh::Output<sh::Point3f> pt_out;
    sh::Output<sh::Vector3f> v_out;
    sh::Output<sh::Normal3f> n_out;
    sh::Output<sh::Attrib4f> h_out;
    pt_out = m | pt;
    v_out = m | sh::Vector3f(pt);
    n_out = m | sh::Normal3f(pt);
    h_out = m | sh::join(pt, sh::ConstAttrib1f(1.f));
  } SH_END;
  sh::Channel<sh::Point3f> in(std::vector<float>{1, 1, 1, -2, 0.5f, 4}), pt_out;
  sh::Channel<sh::Vector3f> v_out;
  sh::Channel<sh::Normal3f> n_out;
  sh::Channel<sh::Attrib4f> h_out;
  run(p, {in}, {pt_out, v_out, n_out, h_out});
  for (int e = 0; e < 2; ++e) {
    float x = in[3 * e], y = in[3 * e + 1], z = in[3 * e + 2];
    EXPECT_EQ(pt_out[3 * e], 2 * x + 1);
    EXPECT_EQ(pt_out[3 * e + 1], y + 2);
    EXPECT_EQ(v_out[3 * e], 2 * x);
    EXPECT_EQ(v_out[3 * e + 2], z);
    // Cofactor of diag(2, 1, 1) is diag(1, 2, 2): normals stay normal.
    EXPECT_EQ(n_out[3 * e], x);
    EXPECT_EQ(n_out[3 * e + 1], 2 * y);
    EXPECT_EQ(h_out[4 * e + 3], 1.f);
    EXPECT_EQ(h_out[4 * e], 2 * x + 1);
  }
}

}  // namespace
}  // namespace conformance
