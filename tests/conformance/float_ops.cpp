// Every float operation and library function of one or two arguments, on
// every width, in float and double, over the special values: results agree
// with <cmath> in double within the bounds of ulp_bounds.hpp.
#include "harness.hpp"

namespace conformance {
namespace {

bool ordinary(double v) {
  // What fast math still promises: finite, normal magnitudes.
  double a = std::fabs(v);
  return std::isfinite(v) && (a == 0 || (a > 1e-30 && a < 1e30));
}

template <class T>
T expected_as(double r) {
  return static_cast<T>(r);
}

template <class T>
void expect_close(bool fast, const char* fn, std::string_view bound_name, double ref, T got,
                  const std::string& where) {
  UlpBound b = ulp_bound(bound_name);
  T want = expected_as<T>(ref);
  std::uint64_t d = ulp_distance<T>(want, got);
  if (fast) {
    double tol = 1e-4 * std::max(1.0, std::fabs(ref));
    EXPECT_TRUE(d <= b.fast || std::fabs(static_cast<double>(got) - ref) <= tol)
        << fn << where << ": got " << got << ", want " << want << " (" << d << " ulp)";
  } else {
    EXPECT_LE(d, b.precise) << fn << where << ": got " << got << ", want " << want;
  }
}

template <class T, int N, class Dsl, class RefFn>
void check_unary(const Conformance& t, bool fast, const char* name, Dsl dsl, RefFn ref, bool trig = false) {
  using A = sh::Attrib<N, T>;
  sh::Program p = SH_BEGIN_PROGRAM(name) {
    sh::Input<A> x;
    sh::Output<A> r;
    r = dsl(x);
  } SH_END;
  std::vector<T> values = extreme_values<T>();
  std::vector<T> xs = spread(values, N, values.size());
  sh::Channel<A> in(xs), out;
  sh::run(p, {in}, {out}, t.choice());
  for (std::size_t k = 0; k < xs.size(); ++k) {
    double x = xs[k];
    if (fast && (!ordinary(x) || (trig && std::fabs(x) > 1e4))) continue;
    double want = ref(x);
    if (fast && !ordinary(want)) continue;
    expect_close<T>(fast, name, name, want, out[k], "(" + std::to_string(x) + ") width " + std::to_string(N));
  }
}

template <class T, int N, class Dsl, class RefFn>
void check_binary(const Conformance& t, bool fast, const char* name, Dsl dsl, RefFn ref) {
  using A = sh::Attrib<N, T>;
  using S = sh::Attrib<1, T>;
  sh::Program p = SH_BEGIN_PROGRAM(name) {
    sh::Input<A> x;
    sh::Input<A> y;
    sh::Input<S> s;
    sh::Output<A> r;
    sh::Output<A> rs;  // scalar broadcast on the right
    r = dsl(x, y);
    rs = dsl(x, s);
  } SH_END;
  std::vector<T> values = extreme_values<T>();
  std::size_t n = values.size();
  std::vector<T> xs(n * n * N), ys(n * n * N), ss(n * n);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j) {
      std::size_t e = i * n + j;
      ss[e] = values[j];
      for (int c = 0; c < N; ++c) {
        xs[e * N + c] = values[(i + c) % n];
        ys[e * N + c] = values[(j + 2 * c) % n];
      }
    }
  sh::Channel<A> cx(xs), cy(ys), r, rs;
  sh::Channel<S> cs(ss);
  sh::run(p, {cx, cy, cs}, {r, rs}, t.choice());
  for (std::size_t k = 0; k < xs.size(); ++k) {
    double x = xs[k], y = ys[k], s = ss[k / N];
    for (auto [b, got] : {std::pair{y, r[k]}, std::pair{s, rs[k]}}) {
      if (fast && (!ordinary(x) || !ordinary(b))) continue;
      double want = ref(x, b);
      if (fast && !ordinary(want)) continue;
      expect_close<T>(fast, name, name, want, got,
                      "(" + std::to_string(x) + ", " + std::to_string(b) + ") width " + std::to_string(N));
    }
  }
}

double sign_ref(double x) { return x > 0 ? 1.0 : x < 0 ? -1.0 : x; }

// Sh's round (halves toward +Inf) and mod (the sign of the divisor), in
// double; mod_round.cpp pins their cases.
double round_ref(double x) {
  double f = std::floor(x);
  return x - f >= 0.5 ? f + 1 : f;
}
double mod_ref(double x, double y) {
  double r = std::fmod(x, y);
  return r != 0 && (r < 0) != (y < 0) ? r + y : r;
}

template <class T, int N>
void all_functions(const Conformance& t, bool fast) {
  using namespace sh;
  auto U = [&](const char* name, auto dsl, auto ref, bool trig = false) { check_unary<T, N>(t, fast, name, dsl, ref, trig); };
  U("neg", [](const auto& x) { return -x; }, [](double x) { return -x; });
  U("abs", [](const auto& x) { return abs(x); }, [](double x) { return std::fabs(x); });
  U("sign", [](const auto& x) { return sign(x); }, sign_ref);
  U("floor", [](const auto& x) { return floor(x); }, [](double x) { return std::floor(x); });
  U("ceil", [](const auto& x) { return ceil(x); }, [](double x) { return std::ceil(x); });
  U("round", [](const auto& x) { return round(x); }, round_ref);
  U("frac", [](const auto& x) { return frac(x); }, [](double x) {
    double f = x - std::floor(x);  // at most the T just below 1
    return static_cast<T>(f) >= T(1) ? static_cast<double>(T(1) - std::numeric_limits<T>::epsilon() / 2) : f;
  });
  U("sqrt", [](const auto& x) { return sqrt(x); }, [](double x) { return std::sqrt(x); });
  U("rsqrt", [](const auto& x) { return rsqrt(x); }, [](double x) { return 1.0 / std::sqrt(x); });
  U("rcp", [](const auto& x) { return rcp(x); }, [](double x) { return 1.0 / x; });
  U("exp", [](const auto& x) { return exp(x); }, [](double x) { return std::exp(x); });
  U("exp2", [](const auto& x) { return exp2(x); }, [](double x) { return std::exp2(x); });
  U("log", [](const auto& x) { return log(x); }, [](double x) { return std::log(x); });
  U("log2", [](const auto& x) { return log2(x); }, [](double x) { return std::log2(x); });
  U("sin", [](const auto& x) { return sin(x); }, [](double x) { return std::sin(x); }, true);
  U("cos", [](const auto& x) { return cos(x); }, [](double x) { return std::cos(x); }, true);
  U("tan", [](const auto& x) { return tan(x); }, [](double x) { return std::tan(x); }, true);
  U("asin", [](const auto& x) { return asin(x); }, [](double x) { return std::asin(x); });
  U("acos", [](const auto& x) { return acos(x); }, [](double x) { return std::acos(x); });
  U("atan", [](const auto& x) { return atan(x); }, [](double x) { return std::atan(x); });

  auto B = [&](const char* name, auto dsl, auto ref) { check_binary<T, N>(t, fast, name, dsl, ref); };
  B("add", [](const auto& x, const auto& y) { return x + y; }, [](double x, double y) { return x + y; });
  B("sub", [](const auto& x, const auto& y) { return x - y; }, [](double x, double y) { return x - y; });
  B("mul", [](const auto& x, const auto& y) { return x * y; }, [](double x, double y) { return x * y; });
  B("div", [](const auto& x, const auto& y) { return x / y; }, [](double x, double y) { return x / y; });
  B("mod", [](const auto& x, const auto& y) { return x % y; }, mod_ref);
  B("min", [](const auto& x, const auto& y) { return min(x, y); }, [](double x, double y) { return std::fmin(x, y); });
  B("max", [](const auto& x, const auto& y) { return max(x, y); }, [](double x, double y) { return std::fmax(x, y); });
  B("pow", [](const auto& x, const auto& y) { return pow(x, y); }, [](double x, double y) { return std::pow(x, y); });
  B("atan2", [](const auto& x, const auto& y) { return atan2(x, y); }, [](double x, double y) { return std::atan2(x, y); });
}

TEST_P(Conformance, FloatFunctionsEveryWidth) {
  all_functions<float, 1>(*this, fast());
  all_functions<float, 2>(*this, fast());
  all_functions<float, 3>(*this, fast());
  all_functions<float, 4>(*this, fast());
}

TEST_P(Conformance, DoubleFunctionsEveryWidth) {
  all_functions<double, 1>(*this, fast());
  all_functions<double, 4>(*this, fast());
}

}  // namespace
}  // namespace conformance
