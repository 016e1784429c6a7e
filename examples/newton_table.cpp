// A data-dependent loop reading a table: each element picks a cubic from a
// table of coefficients and runs Newton's method until it converges.
#include <cmath>
#include <cstdio>
#include <vector>

#include <sh/sh.hpp>

using namespace sh;

int main() {
  // a x^3 + b x^2 + c x + d, one polynomial per table element.
  Table1D<Attrib4f> cubics(3);
  cubics.assign({1, 0, 0, -8,      // x^3 = 8
                 1, -6, 11, -6.2f,  // near (x-1)(x-2)(x-3)
                 2, 0, -1, -1});
  Attrib1f tolerance = 1e-6f;

  Program newton = SH_BEGIN_PROGRAM("newton") {
    InputAttrib1f which;
    InputAttrib1f start;
    OutputAttrib1f root;
    OutputAttrib1f steps;
    Attrib4f k = cubics[which];
    Attrib1f x = start;
    steps = 0.0f;
    SH_DO {
      Attrib1f f = ((k(0) * x + k(1)) * x + k(2)) * x + k(3);
      Attrib1f df = (3.0f * k(0) * x + 2.0f * k(1)) * x + k(2);
      SH_BREAK(abs(df) < 1e-12f);
      Attrib1f dx = f / df;
      x -= dx;
      steps += 1.0f;
      SH_BREAK(abs(dx) < tolerance * max(abs(x), 1.0f));
    } SH_UNTIL(steps >= 100.0f);
    root = x;
  } SH_END;

  Channel<Attrib1f> which(std::vector<float>{0, 1, 1, 2}), start(std::vector<float>{1, 0, 4, 1}), root, steps;
  run(newton, {which, start}, {root, steps});
  for (std::size_t i = 0; i < root.size(); ++i)
    std::printf("cubic %g from %g: root %.6f after %g steps\n", which[i], start[i], root[i], steps[i]);
  return 0;
}
