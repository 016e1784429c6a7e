// saxpy with a uniform: the scale is a run-time parameter of the kernel, so
// changing it between runs recompiles nothing.
#include <cstdio>
#include <vector>

#include <sh/sh.hpp>

using namespace sh;

Attrib1f scale = 2.0f;  // declared outside any program: a uniform

int main() {
  Program saxpy = SH_BEGIN_PROGRAM("saxpy") {
    InputAttrib1f x;
    InputAttrib1f y;
    OutputAttrib1f r;
    r = scale * x + y;
  } SH_END;

  std::vector<float> xs = {1, 2, 3, 4}, ys = {10, 20, 30, 40};
  Channel<Attrib1f> x(xs), y(ys), r(xs.size());
  r = saxpy << (x & y);  // runs on the default backend
  std::printf("scale 2 on %s:", default_backend_name().c_str());
  for (std::size_t i = 0; i < r.size(); ++i) std::printf(" %g", r[i]);

  scale = 3.0f;  // a new value, no recompilation
  RunStats s = run(saxpy, {x, y}, {r}, backend("interp"));
  std::printf("\nscale 3 on %s:", s.backend.c_str());
  for (std::size_t i = 0; i < r.size(); ++i) std::printf(" %g", r[i]);
  std::printf("\n\n%s", print(saxpy).c_str());
  return 0;
}
