#pragma once
// How a scene is traced: the accelerator (grid, octree, an octree built
// lazily while tracing, or a BVH) is made on the host, the scene becomes tables and
// uniforms, and one program (the tracer composed with ray generation) runs
// over the stream of pixel centres on a backend.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <sh/dsl.hpp>

#include "sh/raytracer/bidirectional.hpp"
#include "sh/raytracer/bvh.hpp"
#include "sh/raytracer/grid.hpp"
#include "sh/raytracer/kernels.hpp"
#include "sh/raytracer/octree_refiner.hpp"
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
  Accel accel = Accel::Grid;   // Auto: chosen from the scene (choose_accel of filled_share)
  double grid_density = 2.0;   // grid cells per triangle
  OctreeLimits octree;
  BvhSettings bvh;
  bool progress = false;       // a progress line on stderr (when it is a terminal)
  // Bidirectional: a light pass first (once per renderer), whose luminance
  // the view pass's diffuse term reads.
  bool bidirectional = false;
  LightPassSettings light_pass;
  // A wavefront: the tracer takes every path one bounce a run, and each
  // run after the first holds only the paths still going, side by side
  // (not over a lazy octree, which runs in waves of its own).
  bool wavefront = false;
};

// How busy a render's SIMD lanes were in the bounce loop, counted from its
// paths' bounces (a wavefront render's): batches of `lanes` neighbouring
// elements of each run's stream, as one kernel (a batch loops as long as its
// longest path, lanes of finished paths idle) and in waves (each wave's
// paths side by side).  busy / slots is the share of lanes at work.
struct LaneUse {
  int lanes = 1;
  std::size_t busy = 0;          // bounces taken, one lane each
  std::size_t slots_whole = 0;   // lane slots as one kernel
  std::size_t slots_waves = 0;   // lane slots in waves
  void count(const std::vector<int>& bounces);  // one band's paths, in stream order
  double whole() const { return slots_whole ? static_cast<double>(busy) / slots_whole : 1.0; }
  double waves() const { return slots_waves ? static_cast<double>(busy) / slots_waves : 1.0; }
};

struct RenderReport {
  std::string backend;
  double record_ms = 0;   // recording the kernels (C++ to IR), once, when the renderer was made
  double compile_ms = 0;  // zero when the kernel came from the cache
  // A kernel was made, and every one made was loaded from the disk cache
  // (RunStats::from_disk): compile_ms is a load, not a compile.
  bool compiled = false, compile_from_disk = false;
  double compile_cpu_ms = 0;
  std::vector<CompilePhase> compile_phases;  // where compile_ms went
  double render_ms = 0;
  std::size_t rays = 0;   // primary rays
  // A lazy octree or a wavefront: waves after the first and element runs
  // they took; a lazy octree's time spent building nodes (inside
  // render_ms), and what each part (rank 0 first) holds afterwards
  // (OctreeSummary).
  std::size_t waves = 0, resumed = 0;
  std::optional<LaneUse> lanes;  // a wavefront render's
  double build_ms = 0;
  std::vector<std::string> refined;
  LightPassReport light;  // bidirectional: the light pass, when this render ran it
  std::shared_ptr<RunDetails> details;  // the backend's own figures over the render's runs (mpi: per rank, per split table)
};

// How busy the lanes were in the BVH's walk, rays side by side walking
// together: of the box steps rays were walking at, those where their own
// box test met the box; of the leaves tested for rays, those they met
// themselves (Intersector::lanes).
struct WalkLanes {
  std::int64_t steps = 0, met = 0, leaves = 0, own_leaves = 0;
  double box_share() const { return steps ? static_cast<double>(met) / steps : 1.0; }
  double leaf_share() const { return leaves ? static_cast<double>(own_leaves) / leaves : 1.0; }
};

struct Hits {
  std::vector<float> t;                 // -1 where nothing is hit
  std::vector<std::int32_t> triangle;   // -1 where nothing is hit
};

class Renderer {
 public:
  Renderer(Scene scene, RenderSettings settings);
  Image render(RenderReport* report = nullptr);
  // The intersector alone on rays (3 floats each), in waves over a lazy
  // octree.
  Hits intersect(const std::vector<float>& origins, const std::vector<float>& directions, const BackendChoice& choice,
                 RunStats* stats = nullptr);

  // The occlusion kernel (kernels.hpp) on rays with limits: 1 where
  // something is in the way.  Not over a lazy octree.
  std::vector<float> occluded(const std::vector<float>& origins, const std::vector<float>& directions,
                              const std::vector<float>& limits, const BackendChoice& choice, bool any_hit = true,
                              RunStats* stats = nullptr);

  // The BVH walk's lane counts on rays with limits, summed over the rays
  // (walk_lanes_program, kernels.hpp).  Only over a BVH.
  WalkLanes walk_lanes(const std::vector<float>& origins, const std::vector<float>& directions,
                       const std::vector<float>& limits, bool any_hit, const BackendChoice& choice);

  const Scene& scene() const { return scene_; }
  const RenderSettings& settings() const { return settings_; }
  Accel accel() const { return settings_.accel; }  // the one built: never Auto
  const Grid* grid() const { return grid_ ? &*grid_ : nullptr; }
  const Octree* octree() const { return octree_.get(); }
  const Bvh* bvh() const { return bvh_ ? &*bvh_ : nullptr; }
  std::string describe_accelerator() const;  // kind, size, build time, memory, and the warning below
  // Where a bound on the build's work changed the accelerator (see grid.hpp,
  // octree.hpp); empty otherwise.  A lazy octree's may appear as it grows.
  std::string accelerator_warning() const;
  double accelerator_build_ms() const;  // before rendering (a lazy octree: its root)
  std::size_t accelerator_bytes() const;
  const Features& features() const { return features_; }
  const Program& program() const { return program_; }
  SceneTables& tables() { return *tables_; }
  // Bidirectional: what the light pass left (after the first render).
  const ElementLight* element_light() const { return light_ ? &*light_ : nullptr; }

 private:
  void trace_band(const std::vector<float>& centres, Channel<Color3f>& color, Channel<Attrib1f>& distance,
                  Channel<Attrib1i>& triangle, const BackendChoice& choice, RenderReport& r);
  void count(const RunStats& s, RenderReport& r) const;

  Scene scene_;
  RenderSettings settings_;
  std::optional<Grid> grid_;
  std::shared_ptr<Octree> octree_;
  std::optional<Bvh> bvh_;
  // Where auto chose: filled_share() of the scene.
  std::optional<double> chosen_share_;
  int lanes_ = 0;  // the backend's, where auto chose or for a wavefront's LaneUse
  std::unique_ptr<SceneTables> tables_;
  std::unique_ptr<OctreeRefiner> refiner_;  // a lazy octree's
  Features features_;
  bool wavefront_ = false;  // asked for, and the paths have bounces to take
  Program program_;
  Program path_start_;  // carried paths' (lazy octree, wavefront): pixel centre -> where its path starts
  // A band's carried paths, kept from band to band and frame to frame.
  struct CarriedPaths {
    explicit CarriedPaths(bool lazy);
    void resize(std::size_t n);
    Channel<Attrib2f> pixel;
    PathChannels path, path_out;
    std::shared_ptr<detail::Buffer> request;
  };
  std::unique_ptr<CarriedPaths> carried_;
  double record_ms_ = 0;
  std::unique_ptr<LightPass> light_pass_;
  std::optional<ElementLight> light_;
};

// The pixel centres of a width x height image, row by row from the top.
std::vector<float> pixel_centres(int width, int height);
// The same centres in square tiles of `tile` x `tile` pixels (row by row
// inside a tile, tiles row by row): neighbouring stream elements, which the
// cpu backend runs side by side in SIMD lanes, then look at neighbouring
// pixels and tend to walk the same grid cells.
std::vector<float> pixel_centres_in_tiles(int width, int height, int tile = 4);

// Writes through a temporary file renamed into place; throws sh::Error.
// A NaN channel is written as 0 (nan_pixels counts the pixels that hold one).
void write_png(const std::string& path, const Image& image);
void write_pfm(const std::string& path, int width, int height, const std::vector<float>& values);

// Share of pixels whose channels all differ by at most `tolerance`, the
// peak signal-to-noise ratio (dB) of b against a, and the largest
// difference of any channel: each on the colours as a PNG holds them,
// clamped to [0, 1].  A NaN against anything is an infinite difference.
double share_within(const Image& a, const Image& b, float tolerance);
double psnr(const Image& a, const Image& b);
float max_difference(const Image& a, const Image& b);

// Pixels with a NaN channel, and the first of them (row-major index; -1
// where there is none).
struct NanPixels {
  std::size_t count = 0;
  long long first = -1;
};
NanPixels nan_pixels(const Image& image);

}  // namespace sh::rt
