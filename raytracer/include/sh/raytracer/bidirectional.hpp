#pragma once
// Bidirectional ray tracing after the MAGG seed.  The light pass splits
// every triangle into k x k elements and shoots, from every point light, n
// rays to sample points of every element; each brings I s / n, with I the
// light's intensity and s the element's solid angle from the light.  A ray
// that first meets another surface than its element brings nothing there
// (that surface's own rays carry that light); one that meets a mirror or
// glass goes on and leaves its energy on the shaded surfaces it reaches
// next (caustics), to a set depth.  The energy lands in an accumulator, the
// language's scatter-add, on every backend.  Element luminance is energy /
// area; vertex luminance the mean of the elements around a vertex; the
// view pass (the tracer) takes its diffuse light from them.
//
// Elements of a triangle: its barycentric square (u along e1, v along e2)
// cut into k x k cells, each cell an "up" triangle and, inside the
// triangle, a "down" one.  Element slot 2 (j k + i) + down; lattice point
// (i, j) at v0 + (i e1 + j e2) / k, slot j (k + 1) + i.
//
// Each side of a triangle keeps its own light, so that a single-layer
// surface lit from one side stays dark seen from the other: side 0 is the
// one its geometric normal (e1 x e2) faces, side 1 the back.  A triangle's
// slots are its front's, then its back's (side_slot).
#include <memory>
#include <vector>

#include <sh/dsl.hpp>

#include "sh/raytracer/kernels.hpp"
#include "sh/raytracer/scene.hpp"

namespace sh::rt {

struct LightPassSettings {
  int subdivision = 2;  // k: elements per triangle k^2
  int samples = 16;     // n: rays per light and element
  int depth = 3;        // bounces off mirrors and through glass
};

inline int element_slots(int k) { return 2 * k * k; }         // of one side
inline int lattice_slots(int k) { return (k + 1) * (k + 1); }  // of one side
constexpr int kSides = 2;

// The first of a side's `slots` (element or lattice) in a table of every
// triangle's.
inline std::size_t side_slot(std::size_t triangle, int side, int slots) {
  return (kSides * triangle + static_cast<std::size_t>(side)) * static_cast<std::size_t>(slots);
}

// Calls f(i, j, down) for each element of a triangle split k x k.
template <class F>
void for_each_element(int k, F f) {
  for (int j = 0; j < k; ++j)
    for (int i = 0; i + j < k; ++i)
      for (int down = 0; down < (i + j < k - 1 ? 2 : 1); ++down) f(i, j, down);
}

// What a light pass left on the scene, per triangle's and side's slots
// (rgb each).
struct ElementLight {
  int subdivision = 0;
  std::vector<float> energy;     // element slots: what arrived
  std::vector<float> luminance;  // element slots: energy / area
  std::vector<float> vertex;     // lattice slots: mean luminance of the elements around the point on its side
  Vec3 total() const;            // sum of energy
};

// The light's intensity as the light pass uses it (PointLight::intensity,
// or its default) times its colour.
Vec3 light_intensity(const Scene& s, const PointLight& l);

struct LightPassReport {
  std::size_t rays = 0;
  double run_ms = 0, compile_ms = 0;
  std::string backend;
  std::shared_ptr<RunDetails> details;  // the backend's own figures over the pass's runs
};

// The pass over a scene whose tables are `tables` (grid or static octree).
class LightPass {
 public:
  LightPass(const Scene& scene, const SceneTables& tables, LightPassSettings settings);
  // The energy each element slot of each side received (rgb).
  std::vector<float> run(const BackendChoice& choice, LightPassReport* report = nullptr);
  std::size_t rays() const { return lights_ * (elements_.size() / 4) * settings_.samples; }
  const LightPassSettings& settings() const { return settings_; }
  const Program& program() const { return program_; }

 private:
  std::size_t lights_;
  LightPassSettings settings_;
  std::vector<std::int32_t> elements_;  // triangle, i, j, down per element
  Table1D<Attrib4i> element_table_;
  Table1D<Attrib3f> emitters_;          // position, intensity per light
  Accumulator<Attrib3f> energy_;
  Attrib1i element_count_, sample_count_;
  Attrib1f subdivision_, depth_;
  Program program_;
};

// Vertex luminance from the elements' energy: what the view pass reads.
ElementLight luminance_of(const Scene& scene, int subdivision, std::vector<float> energy);

}  // namespace sh::rt
