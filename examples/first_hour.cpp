// The program docs/first-hour.md walks through: write a kernel, run it,
// compare the backends, read its IR, count what it costs.  The guide quotes
// the parts between the [name] and [end name] markers; a test checks that
// every quote is still here, word for word.
#include <algorithm>
#include <cstdio>
#include <iostream>
#include <vector>

#include <sh/sh.hpp>

using namespace sh;

// [kernel]
Attrib1f falloff = 1.5f;  // declared outside a program: a uniform

Program glow_program() {
  return SH_BEGIN_PROGRAM("glow") {
    InputAttrib2f p;       // a point in the plane
    OutputAttrib1f light;  // how bright the glow is there
    light.name("light");   // the name printouts and compare's table use
    Attrib1f angle = atan2(p(1), p(0));
    Attrib1f rays = 0.0f, k;
    SH_FOR(k = 1.0f, k <= 4.0f, k += 1.0f) {  // recorded: a loop in the kernel
      rays += cos(3.0f * k * angle) / k;
    } SH_ENDFOR;
    light = exp(-falloff * dot(p, p)) * (1.0f + 0.25f * rays) / 3.0f;
  } SH_END;
}
// [end kernel]

// Points on a grid over [-2, 2] x [-2, 2], two floats each.
std::vector<float> grid_points(int n) {
  std::vector<float> xy;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      xy.push_back(-2.0f + 4.0f * (x + 0.5f) / n);
      xy.push_back(-2.0f + 4.0f * (y + 0.5f) / n);
    }
  return xy;
}

int main() {
  // [run]
  Program glow = glow_program();
  Channel<Attrib2f> points(grid_points(64));  // 4096 points
  Channel<Attrib1f> light;                    // sized by the run
  light = glow << points;                     // on the default backend
  std::printf("light at the centre: %g\n", light[64 * 32 + 32]);

  falloff = 3.0f;  // a new uniform value: nothing recompiles
  RunStats s = run(glow, {points}, {light}, backend("interp"));
  std::printf("on %s: %g (compile %.1f ms, run %.1f ms)\n", s.backend.c_str(), light[64 * 32 + 32], s.compile_ms, s.run_ms);
  // [end run]

  // [compare]
  Comparison table = compare(glow, {points});  // every backend, variant, math mode
  std::cout << table;
  const CompareRow* precise = table.find("interp", "", MathMode::Precise);
  std::printf("interp in f32 is within %g ULPs of interp in f64\n", precise->max_ulps());
  // [end compare]

  // [ir]
  std::cout << print(glow);            // as recorded
  std::cout << print_optimized(glow);  // after the passes: what backends compile
  std::string code = kernel_for(glow)->listing();  // what the default backend made of it
  std::printf("%s code: %td lines\n", default_backend_name().c_str(), std::count(code.begin(), code.end(), '\n'));
  // [end ir]

  // [cost]
  analysis::Cost cost = analysis::count_operations(optimize(glow.ir()));
  std::cout << analysis::describe(cost);
  // [end cost]
  return 0;
}
