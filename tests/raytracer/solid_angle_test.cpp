// The solid angle of a triangle seen from a point, as the light pass will
// weigh each element's rays, on every backend against a numerical integral
// in double precision: ordinary, tiny, grazing, far, close to and seen from
// just above triangles, and degenerate ones.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <sh/raytracer.hpp>
#include <sh/sh.hpp>

namespace {

using D3 = std::array<double, 3>;

D3 sub(D3 a, D3 b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
D3 mix(D3 a, D3 b) { return {(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2}; }
double dot(D3 a, D3 b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
D3 cross(D3 a, D3 b) { return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]}; }

// |n . (x - p)| / |x - p|^3 over the triangle, by the edge-midpoint rule
// (exact for quadratics) on a triangle split in four until the halves
// agree.
double integrand(D3 p, D3 x, D3 normal) {
  D3 r = sub(x, p);
  double len = std::sqrt(dot(r, r));
  return std::fabs(dot(normal, r)) / (len * len * len);
}

double midpoint_rule(D3 p, D3 a, D3 b, D3 c, D3 unit_normal, double area) {
  return area / 3 * (integrand(p, mix(a, b), unit_normal) + integrand(p, mix(b, c), unit_normal) +
                     integrand(p, mix(c, a), unit_normal));
}

// Each piece may err by its share (by area) of 1e-6 of the whole: pieces
// far from the point stop early, those under it go on splitting (to a
// depth where a miss would show as a failed comparison, not a hang).
double integral(D3 p, D3 a, D3 b, D3 c, D3 unit_normal, double area, double budget, int depth = 0) {
  D3 ab = mix(a, b), bc = mix(b, c), ca = mix(c, a);
  double coarse = midpoint_rule(p, a, b, c, unit_normal, area);
  double fine = midpoint_rule(p, a, ab, ca, unit_normal, area / 4) + midpoint_rule(p, ab, b, bc, unit_normal, area / 4) +
                midpoint_rule(p, ca, bc, c, unit_normal, area / 4) + midpoint_rule(p, ab, bc, ca, unit_normal, area / 4);
  if (std::fabs(fine - coarse) <= budget || depth == 16) return fine;
  return integral(p, a, ab, ca, unit_normal, area / 4, budget / 4, depth + 1) +
         integral(p, ab, b, bc, unit_normal, area / 4, budget / 4, depth + 1) +
         integral(p, ca, bc, c, unit_normal, area / 4, budget / 4, depth + 1) +
         integral(p, ab, bc, ca, unit_normal, area / 4, budget / 4, depth + 1);
}

double numerical_solid_angle(D3 p, D3 a, D3 b, D3 c) {
  D3 n = cross(sub(b, a), sub(c, a));
  double twice_area = std::sqrt(dot(n, n));
  if (twice_area == 0) return 0;
  D3 unit{n[0] / twice_area, n[1] / twice_area, n[2] / twice_area};
  // A rough pass first: the rule on the whole triangle misses a peak under
  // a point close above it, and a budget from it would be far too fine.
  double rough = integral(p, a, b, c, unit, twice_area / 2, 1e-3 * midpoint_rule(p, a, b, c, unit, twice_area / 2));
  return integral(p, a, b, c, unit, twice_area / 2, 1e-6 * rough);
}

struct Case {
  const char* what;
  D3 point, a, b, c;
};

std::vector<Case> cases() {
  return {
      {"ordinary", {0, 0, 0}, {1, 0, 2}, {0, 1, 2}, {-1, -1, 2}},
      {"tiny (edges 1e-4, at distance 1)", {0, 0, 0}, {0, 0, 1}, {1e-4, 0, 1}, {0, 1e-4, 1}},
      {"very tiny (edges 1e-6)", {0, 0, 0}, {0.3, 0.2, 1}, {0.3 + 1e-6, 0.2, 1}, {0.3, 0.2 + 1e-6, 1.000001}},
      {"grazing (seen 1e-3 rad above its plane)", {0, 0, 0}, {1, 0, 1e-3}, {2, 0, 1e-3}, {1.5, 1, 1e-3}},
      {"grazing and tiny", {0, 0, 0}, {1, 0, 1e-3}, {1.001, 0, 1e-3}, {1.0005, 0.001, 1e-3}},
      {"far (size 1 at 1e4)", {0, 0, 0}, {1e4, 0, 0}, {1e4, 1, 0}, {1e4, 0, 1}},
      {"large, seen from close above", {0.1, 0.1, 0.05}, {-1, -1, 0}, {3, -1, 0}, {-1, 3, 0}},
      {"seen from just above (near 2 pi)", {0, 0, 1e-2}, {-10, -10, 0}, {30, -10, 0}, {-10, 30, 0}},
      {"far from the origin", {1000, 2000, 3000}, {1001, 2000, 3000}, {1000, 2001, 3000}, {1000, 2000, 3001}},
      {"1e13 across (cubes of distances pass float's range)", {0, 0, 0}, {1e13, 0, 2e13}, {0, 1e13, 2e13},
       {-1e13, -1e13, 2e13}},
  };
}

sh::Program solid_angle_program() {
  return SH_BEGIN_PROGRAM("solid_angle") {
    sh::InputAttrib3f to_a, e1, e2;
    sh::OutputAttrib1f s;
    s = sh::rt::solid_angle(to_a, e1, e2);
  } SH_END;
}

// The kernel's inputs (differences in double, then rounded: what a light
// pass hands the kernel, element vertices relative to the light) and the
// integral from the same float inputs, so only the formula is judged.
struct Inputs {
  std::vector<float> to_a, e1, e2;
  std::vector<double> expected;
};

const Inputs& inputs() {
  static const Inputs in = [] {
    Inputs r;
    auto put = [](std::vector<float>& v, D3 x) { v.insert(v.end(), {float(x[0]), float(x[1]), float(x[2])}); };
    for (const Case& c : cases()) {
      put(r.to_a, sub(c.a, c.point));
      put(r.e1, sub(c.b, c.a));
      put(r.e2, sub(c.c, c.a));
      std::size_t i = r.expected.size();
      D3 a{r.to_a[3 * i], r.to_a[3 * i + 1], r.to_a[3 * i + 2]};
      D3 b{a[0] + r.e1[3 * i], a[1] + r.e1[3 * i + 1], a[2] + r.e1[3 * i + 2]};
      D3 cc{a[0] + r.e2[3 * i], a[1] + r.e2[3 * i + 1], a[2] + r.e2[3 * i + 2]};
      r.expected.push_back(numerical_solid_angle({0, 0, 0}, a, b, cc));
    }
    return r;
  }();
  return in;
}

class SolidAngle : public testing::TestWithParam<std::string> {};

TEST_P(SolidAngle, AgreesWithANumericalIntegral) {
  const Inputs& in = inputs();
  sh::Channel<sh::Attrib3f> a(in.to_a), b(in.e1), c(in.e2);
  sh::Channel<sh::Attrib1f> s;
  sh::run(solid_angle_program(), {a, b, c}, {s}, sh::backend(GetParam()));
  const std::vector<Case> all = cases();
  for (std::size_t i = 0; i < all.size(); ++i)
    EXPECT_NEAR(s[i], in.expected[i], 2e-5 * in.expected[i]) << all[i].what << " on " << GetParam();
}

TEST_P(SolidAngle, DegenerateAndEdgeOnTrianglesSubtendNothing) {
  sh::Channel<sh::Attrib3f> a(std::vector<float>{0, 0, 1, 1, 0, 0}), e1(std::vector<float>{1, 1, 0, 1, 0, 0}),
      e2(std::vector<float>{2, 2, 0, 0, 1, 0});
  sh::Channel<sh::Attrib1f> s;
  sh::run(solid_angle_program(), {a, e1, e2}, {s}, sh::backend(GetParam()));
  EXPECT_EQ(s[0], 0.0f) << "a triangle with parallel edges";
  EXPECT_EQ(s[1], 0.0f) << "a triangle seen exactly edge-on";
}

INSTANTIATE_TEST_SUITE_P(Backends, SolidAngle, testing::ValuesIn(sh::backend_names()),
                         [](const auto& info) { return info.param; });

}  // namespace
