#include <chrono>
#include <cstdio>
#include <unistd.h>

#include "sh/error.hpp"
#include "sh/raytracer/render.hpp"

namespace sh::rt {

std::vector<float> pixel_centres(int width, int height) {
  std::vector<float> c;
  c.reserve(static_cast<std::size_t>(width) * height * 2);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      c.push_back(x + 0.5f);
      c.push_back(y + 0.5f);
    }
  return c;
}

std::vector<float> pixel_centres_in_tiles(int width, int height, int tile) {
  std::vector<float> c;
  c.reserve(static_cast<std::size_t>(width) * height * 2);
  for (int ty = 0; ty < height; ty += tile)
    for (int tx = 0; tx < width; tx += tile)
      for (int y = ty; y < std::min(ty + tile, height); ++y)
        for (int x = tx; x < std::min(tx + tile, width); ++x) {
          c.push_back(x + 0.5f);
          c.push_back(y + 0.5f);
        }
  return c;
}

Renderer::Renderer(Scene scene, RenderSettings settings)
    : scene_(std::move(scene)), settings_(std::move(settings)) {
  if (settings_.width < 1 || settings_.height < 1 || settings_.width > 32768 || settings_.height > 32768)
    throw Error("image size must be 1..32768 on each side, got " + std::to_string(settings_.width) + "x" +
                std::to_string(settings_.height));
  if (settings_.reflections < 0 || settings_.reflections > 64)
    throw Error("reflection depth must be 0..64, got " + std::to_string(settings_.reflections));
  validate(scene_, scene_.name);
  grid_ = build_grid(scene_, settings_.grid_density);
  tables_ = std::make_unique<SceneTables>(scene_, grid_);
  tables_->set_samples(settings_.pattern, settings_.shadow_samples, settings_.seed);
  tables_->set_camera(scene_.camera, settings_.width, settings_.height);
  tables_->set_reflection_depth(settings_.reflections);
  features_ = settings_.specialise ? Features::of(scene_, settings_.reflections) : Features::all();
  program_ = tracer_program(*tables_, features_) << raygen_program(*tables_);
}

Image Renderer::render(RenderReport* report) {
  Image image;
  image.width = settings_.width;
  image.height = settings_.height;
  std::size_t pixels = static_cast<std::size_t>(image.width) * image.height;
  image.rgb.resize(pixels * 3);
  image.distance.resize(pixels);
  image.triangle.resize(pixels);
  BackendChoice choice = backend(settings_.backend, settings_.options);
  bool show = settings_.progress && isatty(fileno(stderr));
  // Bands of rows (whole tiles high): the progress line moves, and no
  // buffer is the whole image.
  constexpr int kTile = 4;
  int band = std::max(kTile, std::min(image.height, static_cast<int>((1 << 18) / image.width)) / kTile * kTile);
  RenderReport r;
  auto t0 = std::chrono::steady_clock::now();
  for (int y0 = 0; y0 < image.height; y0 += band) {
    int rows = std::min(band, image.height - y0);
    std::vector<float> centres = pixel_centres_in_tiles(image.width, rows, kTile);
    for (std::size_t i = 1; i < centres.size(); i += 2) centres[i] += static_cast<float>(y0);
    Channel<Attrib2f> in(centres);
    Channel<Color3f> color;
    Channel<Attrib1f> distance;
    Channel<Attrib1i> triangle;
    RunStats s = run(program_, {in}, {color, distance, triangle}, choice);
    r.backend = s.backend;
    r.compile_ms += s.compile_ms;
    // Element k is the pixel whose centre it was given.
    for (std::size_t k = 0; k < distance.size(); ++k) {
      std::size_t at = static_cast<std::size_t>(centres[2 * k + 1]) * image.width + static_cast<std::size_t>(centres[2 * k]);
      std::copy(color.data() + 3 * k, color.data() + 3 * k + 3, image.rgb.begin() + static_cast<long>(3 * at));
      image.distance[at] = distance[k];
      image.triangle[at] = triangle[k];
    }
    if (show) std::fprintf(stderr, "\rrendering on %s: %3d%%", s.backend.c_str(), 100 * (y0 + rows) / image.height);
  }
  if (show) std::fprintf(stderr, "\n");
  r.render_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count() - r.compile_ms;
  r.rays = pixels;
  if (report) *report = r;
  return image;
}

double share_within(const Image& a, const Image& b, float tolerance) {
  if (a.rgb.size() != b.rgb.size()) throw Error("images of different sizes cannot be compared");
  std::size_t close = 0, pixels = a.rgb.size() / 3;
  for (std::size_t p = 0; p < pixels; ++p) {
    bool ok = true;
    for (int c = 0; c < 3; ++c) {
      float x = std::clamp(a.rgb[3 * p + c], 0.f, 1.f), y = std::clamp(b.rgb[3 * p + c], 0.f, 1.f);
      ok = ok && std::fabs(x - y) <= tolerance;
    }
    close += ok;
  }
  return pixels ? static_cast<double>(close) / pixels : 1.0;
}

double psnr(const Image& a, const Image& b) {
  if (a.rgb.size() != b.rgb.size()) throw Error("images of different sizes cannot be compared");
  double sum = 0;
  for (std::size_t i = 0; i < a.rgb.size(); ++i) {
    double d = std::clamp(a.rgb[i], 0.f, 1.f) - std::clamp(b.rgb[i], 0.f, 1.f);
    sum += d * d;
  }
  double mse = sum / std::max<std::size_t>(a.rgb.size(), 1);
  return mse == 0 ? INFINITY : 10 * std::log10(1.0 / mse);
}

}  // namespace sh::rt
