#pragma once
// `shtrace tradeoff`: one scene over a grid of settings, each render timed
// and compared with a converged reference; a CSV and a plot of error
// against time with the Pareto front marked.
#include <string>
#include <vector>

#include <sh/raytracer.hpp>

namespace shtrace {

struct TradeoffOptions {
  std::string scene = "soft";
  int width = 200, height = 150;
  std::vector<std::string> backends;  // empty: cpu and opencl where built
  std::string out = "out/tradeoff";   // writes OUT.csv, OUT.gp, OUT.png
};

int tradeoff(const TradeoffOptions& o);

// Pixels of a scanline across a shadow edge whose brightness lies between
// 10 % and 90 % of the way from the umbra to full light (thresholds taken
// from `reference` on the same row).
int penumbra_width(const sh::rt::Image& image, const sh::rt::Image& reference, int row);
// The row through the darkest shadow on the first object's surface.
int shadow_row(const sh::rt::Image& reference, const sh::rt::Scene& scene);

}  // namespace shtrace
