#include <algorithm>
#include <chrono>
#include <cmath>
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
  if (settings_.accel == Accel::Auto) {
    chosen_share_ = filled_share(scene_);
    lanes_ = lanes_of(backend(settings_.backend, settings_.options));
    settings_.accel = choose_accel(*chosen_share_, lanes_);
  }
  switch (settings_.accel) {
    case Accel::Grid:
      grid_ = build_grid(scene_, settings_.grid_density);
      tables_ = std::make_unique<SceneTables>(scene_, *grid_);
      break;
    case Accel::Octree:
    case Accel::LazyOctree: {
      bool lazy = settings_.accel == Accel::LazyOctree;
      octree_ = std::make_shared<Octree>(lazy ? Octree::lazy(scene_, settings_.octree) : Octree::full(scene_, settings_.octree));
      tables_ = std::make_unique<SceneTables>(scene_, *octree_, lazy);
      if (lazy)
        refiner_ = std::make_unique<OctreeRefiner>(octree_, tables_->octree->nodes.storage()->id,
                                                   tables_->octree->triangles.storage()->id);
      break;
    }
    case Accel::Bvh:
      bvh_ = build_bvh(scene_, settings_.bvh);
      tables_ = std::make_unique<SceneTables>(scene_, *bvh_);
      break;
    case Accel::Auto: throw Error("internal: auto was not resolved to an accelerator");
  }
  if (!tables_)
    throw Error("accelerator " + std::to_string(static_cast<int>(settings_.accel)) +
                " is none of grid, octree, lazy-octree, bvh or auto");
  tables_->set_samples(settings_.pattern, settings_.shadow_samples, settings_.seed);
  tables_->set_camera(scene_.camera, settings_.width, settings_.height);
  tables_->set_reflection_depth(settings_.reflections);
  features_ = settings_.specialise ? Features::of(scene_, settings_.reflections) : Features::all();
  if (settings_.bidirectional) {
    light_pass_ = std::make_unique<LightPass>(scene_, *tables_, settings_.light_pass);
    int k = settings_.light_pass.subdivision;
    tables_->luminance = std::make_unique<LuminanceTables>(
        k, std::vector<float>(side_slot(scene_.mesh.triangles(), 0, lattice_slots(k)) * 3, 0.0f));
    features_.luminance = true;
  }
  if (settings_.wavefront && refiner_)
    throw Error("a wavefront render cannot run over a lazy octree, which runs in waves of its own: use --accel bvh, "
                "grid or octree");
  wavefront_ = settings_.wavefront && (features_.reflections || features_.refractions);
  if (wavefront_ && lanes_ == 0) lanes_ = lanes_of(backend(settings_.backend, settings_.options));
  auto recording = std::chrono::steady_clock::now();
  if (refiner_ || wavefront_) {
    program_ = tracer_program(*tables_, features_, wavefront_);
    path_start_ = path_start_program() << raygen_program(*tables_);
  } else {
    program_ = tracer_program(*tables_, features_) << raygen_program(*tables_);
  }
  record_ms_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - recording).count();
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
  r.record_ms = record_ms_;
  if (light_pass_ && !light_) {
    std::string on = choice.name.empty() ? default_backend_name() : choice.name;
    if (show) std::fprintf(stderr, "light pass on %s: %zu rays\n", on.c_str(), light_pass_->rays());
    light_ = luminance_of(scene_, settings_.light_pass.subdivision, light_pass_->run(choice, &r.light));
    tables_->luminance->vertex.assign(light_->vertex);
  }
  double built_before = octree_ ? octree_->build_ms() : 0;
  auto t0 = std::chrono::steady_clock::now();
  for (int y0 = 0; y0 < image.height; y0 += band) {
    int rows = std::min(band, image.height - y0);
    std::vector<float> centres = pixel_centres_in_tiles(image.width, rows, kTile);
    for (std::size_t i = 1; i < centres.size(); i += 2) centres[i] += static_cast<float>(y0);
    Channel<Color3f> color;
    Channel<Attrib1f> distance;
    Channel<Attrib1i> triangle;
    trace_band(centres, color, distance, triangle, choice, r);
    // Element k is the pixel whose centre it was given.
    for (std::size_t k = 0; k < distance.size(); ++k) {
      std::size_t at = static_cast<std::size_t>(centres[2 * k + 1]) * image.width + static_cast<std::size_t>(centres[2 * k]);
      std::copy(color.data() + 3 * k, color.data() + 3 * k + 3, image.rgb.begin() + static_cast<long>(3 * at));
      image.distance[at] = distance[k];
      image.triangle[at] = triangle[k];
    }
    if (show) std::fprintf(stderr, "\rrendering on %s: %3d%%", r.backend.c_str(), 100 * (y0 + rows) / image.height);
  }
  if (show) std::fprintf(stderr, "\n");
  r.render_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count() - r.compile_ms;
  r.rays = pixels;
  if (octree_) r.build_ms = octree_->build_ms() - built_before;
  if (report) *report = r;
  return image;
}

void Renderer::count(const RunStats& s, RenderReport& r) const {
  r.backend = s.backend;
  add_compiled(r.compiled, r.compile_from_disk, s);
  r.compile_ms += s.compile_ms;
  r.compile_cpu_ms += s.compile_cpu_ms;
  add_phases(r.compile_phases, s.compile_phases);
  r.waves = std::max(r.waves, s.waves);  // the deepest band, as one run over the image would count
  r.resumed += s.resumed;
  if (!s.refined.empty()) r.refined = s.refined;
  add_details(r.details, s.details);
}

void LaneUse::count(const std::vector<int>& bounces) {
  auto lane_slots = [this](std::size_t paths) { return (paths + lanes - 1) / lanes * lanes; };
  for (std::size_t first = 0; first < bounces.size(); first += lanes) {
    auto end = bounces.begin() + static_cast<long>(std::min(bounces.size(), first + lanes));
    slots_whole += static_cast<std::size_t>(*std::max_element(bounces.begin() + static_cast<long>(first), end)) * lanes;
  }
  for (int bounce = 0;; ++bounce) {
    auto going = static_cast<std::size_t>(std::count_if(bounces.begin(), bounces.end(), [&](int b) { return b > bounce; }));
    if (going == 0) break;
    busy += going;
    slots_waves += lane_slots(going);
  }
}

// Over a lazy octree the tracer runs in waves, each pixel's path carried
// from one to the next; so it does in a wavefront, one bounce a wave.
void Renderer::trace_band(const std::vector<float>& centres, Channel<Color3f>& color, Channel<Attrib1f>& distance,
                          Channel<Attrib1i>& triangle, const BackendChoice& choice, RenderReport& r) {
  Channel<Attrib2f> in(centres);
  if (!refiner_ && !wavefront_) {
    count(run(program_, {in}, {color, distance, triangle}, choice), r);
    return;
  }
  if (!carried_) carried_ = std::make_unique<CarriedPaths>(refiner_ != nullptr);
  CarriedPaths& c = *carried_;
  c.resize(in.size());
  std::vector<std::shared_ptr<detail::Buffer>> inputs = {c.pixel}, outputs = {color, distance, triangle, c.request};
  for (const auto& channel : c.path.all()) inputs.push_back(channel);
  count(run(path_start_, {in}, inputs, choice), r);
  Waves waves{refiner_.get(), 3, {}};
  for (const auto& channel : c.path_out.all()) {
    waves.carried.push_back({static_cast<int>(outputs.size()), static_cast<int>(waves.carried.size()) + 1});
    outputs.push_back(channel);
  }
  count(run(program_, inputs, outputs, waves, choice), r);
  if (wavefront_) {
    if (!r.lanes) r.lanes = LaneUse{lanes_};
    std::vector<int> bounces(in.size());
    for (std::size_t k = 0; k < bounces.size(); ++k) bounces[k] = static_cast<int>(c.path_out.origin_bounce[4 * k + 3]);
    r.lanes->count(bounces);
  }
}

// A lazy octree's requests name a node; a wavefront's say only "again".
Renderer::CarriedPaths::CarriedPaths(bool lazy) : request(Channel<Attrib1i>()) {
  if (lazy) request = Channel<Attrib4i>();
}

// The same size as the band, their memory kept: fresh pages for every band
// cost more than the waves' copies.
void Renderer::CarriedPaths::resize(std::size_t n) {
  pixel.resize(n);
  request->resize(n);
  for (const auto& channel : path.all()) channel->resize(n);
  for (const auto& channel : path_out.all()) channel->resize(n);
}

Hits Renderer::intersect(const std::vector<float>& origins, const std::vector<float>& directions,
                         const BackendChoice& choice, RunStats* stats) {
  Program p = intersector_program(*tables_);
  Channel<Point3f> o(origins);
  Channel<Vector3f> d(directions);
  Channel<Attrib1f> t;
  Channel<Attrib1i> tri;
  RunStats s;
  if (refiner_) {
    std::vector<float> from_entry(4 * o.size(), -1.0f);
    for (std::size_t i = 3; i < from_entry.size(); i += 4) from_entry[i] = kFar;
    Channel<Attrib4f> resume(from_entry), resume_out;
    Channel<Attrib1i> resume_triangle(std::vector<std::int32_t>(o.size(), -1)), resume_triangle_out;
    Channel<Attrib4i> request;
    s = run(p, {o, d, resume, resume_triangle}, {t, tri, request, resume_out, resume_triangle_out},
            Waves{refiner_.get(), 2, {{3, 2}, {4, 3}}}, choice);
  } else {
    s = run(p, {o, d}, {t, tri}, choice);
  }
  if (stats) *stats = s;
  return {t.values(), tri.values()};
}

std::vector<float> Renderer::occluded(const std::vector<float>& origins, const std::vector<float>& directions,
                                      const std::vector<float>& limits, const BackendChoice& choice, bool any_hit,
                                      RunStats* stats) {
  Channel<Point3f> o(origins);
  Channel<Vector3f> d(directions);
  Channel<Attrib1f> limit(limits), blocked;
  RunStats s = run(occlusion_program(*tables_, any_hit), {o, d, limit}, {blocked}, choice);
  if (stats) *stats = s;
  return blocked.values();
}

WalkLanes Renderer::walk_lanes(const std::vector<float>& origins, const std::vector<float>& directions,
                               const std::vector<float>& limits, bool any_hit, const BackendChoice& choice) {
  Channel<Point3f> o(origins);
  Channel<Vector3f> d(directions);
  Channel<Attrib1f> limit(limits);
  Channel<Attrib4i> lanes;
  run(walk_lanes_program(*tables_, any_hit), {o, d, limit}, {lanes}, choice);
  WalkLanes sum;
  for (std::size_t k = 0; k < limit.size(); ++k) {
    sum.steps += lanes[4 * k];
    sum.met += lanes[4 * k + 1];
    sum.leaves += lanes[4 * k + 2];
    sum.own_leaves += lanes[4 * k + 3];
  }
  return sum;
}

std::string Renderer::describe_accelerator() const {
  char line[256];
  if (grid_) {
    std::snprintf(line, sizeof line, "grid %dx%dx%d (%.1f ms, %.2f MiB)", grid_->dims[0], grid_->dims[1], grid_->dims[2],
                  grid_->build_ms, grid_->bytes() / 1048576.0);
  } else if (bvh_) {
    std::snprintf(line, sizeof line, "bvh depth %d, leaves of at most %d, node cost %g: %zu nodes (%.1f ms, %.2f MiB%s)",
                  bvh_->depth, settings_.bvh.max_leaf, bvh_->node_cost, bvh_->nodes(), bvh_->build_ms, bvh_->bytes() / 1048576.0,
                  bvh_->prefetch ? ", children asked ahead" : "");
  } else {
    std::snprintf(line, sizeof line, "%s depth %d, leaves of %d: %zu nodes (%.1f ms, %.2f MiB%s)", accel_name(settings_.accel),
                  octree_->limits().max_depth, octree_->limits().leaf_size, octree_->nodes().size(), octree_->build_ms(),
                  octree_->bytes() / 1048576.0, refiner_ ? ", built so far" : "");
  }
  std::string out = line;
  if (chosen_share_) {
    std::snprintf(line, sizeof line, " (auto: the backend runs %d element%s side by side, the triangles fill %.2f of the cells they could)",
                  lanes_, lanes_ == 1 ? "" : "s", *chosen_share_);
    out += line;
  }
  std::string warning = accelerator_warning();
  return warning.empty() ? out : out + "; warning: " + warning;
}

// A BVH's build is bounded without changing what it holds: no warning.
std::string Renderer::accelerator_warning() const {
  return grid_ ? grid_->warning : octree_ ? octree_->warning() : std::string();
}

double Renderer::accelerator_build_ms() const {
  return grid_ ? grid_->build_ms : bvh_ ? bvh_->build_ms : octree_->build_ms();
}

std::size_t Renderer::accelerator_bytes() const {
  return grid_ ? grid_->bytes() : bvh_ ? bvh_->bytes() : octree_->bytes() + octree_->pending_bytes();
}

NanPixels nan_pixels(const Image& image) {
  NanPixels found;
  for (std::size_t p = 0; 3 * p + 2 < image.rgb.size(); ++p)
    if (std::isnan(image.rgb[3 * p]) || std::isnan(image.rgb[3 * p + 1]) || std::isnan(image.rgb[3 * p + 2])) {
      if (found.count++ == 0) found.first = static_cast<long long>(p);
    }
  return found;
}

namespace {

void check_same_size(const Image& a, const Image& b) {
  if (a.rgb.size() != b.rgb.size()) throw Error("images of different sizes cannot be compared");
}

// Channel i of a less b's, each as a PNG holds it (clamped to [0, 1]).
float clamped_difference(const Image& a, const Image& b, std::size_t i) {
  return std::clamp(a.rgb[i], 0.f, 1.f) - std::clamp(b.rgb[i], 0.f, 1.f);
}

}  // namespace

double share_within(const Image& a, const Image& b, float tolerance) {
  check_same_size(a, b);
  std::size_t close = 0, pixels = a.rgb.size() / 3;
  for (std::size_t p = 0; p < pixels; ++p) {
    bool ok = true;
    for (std::size_t c = 0; c < 3; ++c) ok = ok && std::fabs(clamped_difference(a, b, 3 * p + c)) <= tolerance;
    close += ok;
  }
  return pixels ? static_cast<double>(close) / pixels : 1.0;
}

double psnr(const Image& a, const Image& b) {
  check_same_size(a, b);
  double sum = 0;
  for (std::size_t i = 0; i < a.rgb.size(); ++i) {
    double d = clamped_difference(a, b, i);
    sum += d * d;
  }
  double mse = sum / std::max<std::size_t>(a.rgb.size(), 1);
  return mse == 0 ? INFINITY : 10 * std::log10(1.0 / mse);
}

float max_difference(const Image& a, const Image& b) {
  check_same_size(a, b);
  float largest = 0;
  for (std::size_t i = 0; i < a.rgb.size(); ++i) {
    float d = std::fabs(clamped_difference(a, b, i));
    // std::max would pass over a NaN, which the clamp keeps.
    if (std::isnan(d)) return INFINITY;
    largest = std::max(largest, d);
  }
  return largest;
}

}  // namespace sh::rt
