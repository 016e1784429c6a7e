#pragma once
// How a scene is traced: the grid is built on the host, the scene becomes
// tables and uniforms, and one program (the tracer composed with ray
// generation) runs over the stream of pixel centres on a backend.
#include <memory>
#include <string>
#include <vector>

#include <sh/dsl.hpp>

#include "sh/raytracer/grid.hpp"
#include "sh/raytracer/kernels.hpp"
#include "sh/raytracer/scene.hpp"

namespace sh::rt {

struct Image {
  int width = 0, height = 0;
  std::vector<float> rgb;          // linear, row 0 at the top
  std::vector<float> distance;     // primary hit distance, -1 where none
  std::vector<std::int32_t> triangle;  // primary hit triangle, -1 where none
};

struct RenderSettings {
  int width = 640, height = 480;
  int reflections = 3;         // bounces after the primary hit
  std::string backend;         // empty: the default backend
  Options options;
  bool specialise = true;      // kernels hold only what the scene needs
  int shadow_samples = 16;     // per disk light and shading point
  SamplePattern pattern = SamplePattern::Random;
  unsigned seed = 1;           // of the sample set
  double grid_density = 2.0;   // grid cells per triangle
  bool progress = false;       // a progress line on stderr (when it is a terminal)
};

struct RenderReport {
  std::string backend;
  double compile_ms = 0;  // zero when the kernel came from the cache
  double render_ms = 0;
  std::size_t rays = 0;   // primary rays
};

class Renderer {
 public:
  Renderer(Scene scene, RenderSettings settings);
  Image render(RenderReport* report = nullptr);

  const Scene& scene() const { return scene_; }
  const Grid& grid() const { return grid_; }
  const Features& features() const { return features_; }
  const Program& program() const { return program_; }
  SceneTables& tables() { return *tables_; }

 private:
  Scene scene_;
  RenderSettings settings_;
  Grid grid_;
  std::unique_ptr<SceneTables> tables_;
  Features features_;
  Program program_;
};

// The pixel centres of a width x height image, row by row from the top.
std::vector<float> pixel_centres(int width, int height);
// The same centres in square tiles of `tile` x `tile` pixels (row by row
// inside a tile, tiles row by row): neighbouring stream elements, which the
// cpu backend runs side by side in SIMD lanes, then look at neighbouring
// pixels and tend to walk the same grid cells.
std::vector<float> pixel_centres_in_tiles(int width, int height, int tile = 4);

// Writes through a temporary file renamed into place; throws sh::Error.
void write_png(const std::string& path, const Image& image);
void write_pfm(const std::string& path, int width, int height, const std::vector<float>& values);

// Share of pixels whose channels all differ by at most `tolerance`, and
// the peak signal-to-noise ratio (dB) of b against a.
double share_within(const Image& a, const Image& b, float tolerance);
double psnr(const Image& a, const Image& b);

}  // namespace sh::rt
