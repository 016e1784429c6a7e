// shtrace: render a scene on any backend, compare backends, list devices.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <limits>
#include <optional>
#include <sstream>

#include <sh/raytracer.hpp>
#include <sh/sh.hpp>
#include <tbb/global_control.h>
#ifdef SHTRACE_WITH_MPI
#include <sh/mpi.hpp>
#endif

#include "accel_compare.hpp"
#include "backend_compare.hpp"
#include "embree_anchor.hpp"
#include "ray_kinds.hpp"
#include "output_file.hpp"
#include "tradeoff.hpp"

namespace {

using namespace sh;
using namespace sh::rt;

struct Common {
  std::string scene = "spheres";
  std::string size = "640x480";
  int reflections = 3;
  int samples = 16;
  std::string pattern = "random";
  double grid_density = 2.0;
  std::string accel = "auto";
  OctreeLimits octree;
  BvhSettings bvh;
  std::string bvh_walk = "wide";
  std::size_t triangles = 100000;
  std::string precision = "f32", math = "precise";
  int threads = 0;
  std::vector<std::string> settings;  // KEY=VALUE: a backend's own option (Options::set)
  bool bidirectional = false;
  bool wavefront = false;
  LightPassSettings light_pass;
  LoadLimits load;
};

// More is surely a slip of the keyboard (and some 30 GB of scene).
constexpr std::size_t kMostProceduralTriangles = std::size_t{1} << 28;

// CLI11's ranges pass a NaN (every comparison with it is false).
const CLI::Validator kFinite(
    [](std::string& text) {
      double v = 0;
      return CLI::detail::lexical_cast(text, v) && std::isfinite(v) ? std::string() : "not a finite number: " + text;
    },
    "FINITE");

// A list of backends is one argument split at its commas (CLI11 drops the
// empty names a stray comma makes).  An empty list ("--backends ,") has
// CLI11 read the next option as a name: no name starts with a dash.
const CLI::Validator kBackendName(
    [](std::string& name) {
      return !name.empty() && name[0] == '-'
                 ? "'" + name + "' is an option, not a backend name: the list before it is empty"
                 : std::string();
    },
    "NAME");

void add_common(CLI::App* app, Common& c) {
  app->add_option("--scene", c.scene,
                  "scene file (.json), model file, or built-in: cornell, spheres, procedural, soft, soft2, magg-mirror, magg-glass")
      ->capture_default_str();
  app->add_option("--size", c.size, "image size WIDTHxHEIGHT")->capture_default_str();
  app->add_option("--reflections", c.reflections, "reflection bounces")->capture_default_str()->check(CLI::Range(0, 64));
  app->add_option("--triangles", c.triangles, "triangles of the procedural scene")->capture_default_str()
      ->check(CLI::Range(std::size_t{1}, kMostProceduralTriangles));
  app->add_option("--precision", c.precision, "f32 or f64")->check(CLI::IsMember({"f32", "f64"}))->capture_default_str();
  app->add_option("--math", c.math, "precise or fast")->check(CLI::IsMember({"precise", "fast"}))->capture_default_str();
  app->add_option("--threads", c.threads, "CPU threads, for tracing and for building accelerators (0: all)")
      ->capture_default_str()->check(CLI::Range(0, sh::kMostThreads));
  app->add_option("--set", c.settings, "a backend's setting KEY=VALUE or BACKEND.KEY=VALUE, repeatable (cpu: "
                  "width=scalar|4|8|16; mpi: chunk=N, schedule=dynamic|static, split_tables=BYTES; `shtrace info` lists all)");
  app->add_option("--samples", c.samples, "shadow rays per disk light and shading point")
      ->capture_default_str()->check(CLI::Range(1, kMaxShadowSamples));
  app->add_option("--pattern", c.pattern, "disk sample pattern: random or pseudo")
      ->check(CLI::IsMember({"random", "pseudo"}))->capture_default_str();
  app->add_option("--grid-density", c.grid_density, "grid cells per triangle")->capture_default_str()
      ->check(kFinite & CLI::Range(0.01, 64.0));
  app->add_option("--accel", c.accel,
                  "accelerator: grid, octree (built before tracing), lazy-octree (built where rays go), bvh, or auto "
                  "(the BVH where the backend runs elements side by side in SIMD lanes; where it runs each alone, the grid "
                  "where the triangles fill the scene's box evenly, else the BVH)")
      ->check(CLI::IsMember({"grid", "octree", "lazy-octree", "bvh", "auto"}))->capture_default_str();
  app->add_option("--octree-depth", c.octree.max_depth, "octree depth limit")
      ->capture_default_str()->check(CLI::Range(0, kMaxOctreeDepth));
  app->add_option("--leaf-size", c.octree.leaf_size, "octree: most triangles in a leaf above the depth limit")
      ->capture_default_str()->check(CLI::Range(1, 1 << 20));
  app->add_option("--bvh-leaf", c.bvh.max_leaf, "bvh: most triangles in a leaf")
      ->capture_default_str()->check(CLI::Range(1, kBvhMaxLeaf));
  app->add_option("--bvh-node-cost", c.bvh.node_cost,
                  "bvh: the build's cost of visiting a node against testing a triangle (0: by the tree's size, 1, or 3 "
                  "where the tree outgrows the cache)")
      ->capture_default_str()->check(CLI::Range(0.0, kBvhMaxNodeCost));
  app->add_option("--bvh-prefetch-above", c.bvh.prefetch_above,
                  "bvh: the wide walk asks for each node's children ahead of visiting them where the tree is larger than "
                  "this many bytes (0: always)")
      ->capture_default_str()->check(CLI::Range(std::size_t{0}, std::size_t{1} << 50));
  app->add_option("--bvh-walk", c.bvh_walk,
                  "bvh: threaded (no stack; rays side by side walk together), stack (each ray its own path, with a stack) or wide (nodes of 4 children, rays side by side together, with a stack)")
      ->check(CLI::IsMember({"threaded", "stack", "wide"}))->capture_default_str();
  app->add_flag("--bidirectional", c.bidirectional,
                "a light pass first (rays from the point lights to every element, through mirrors and glass), whose "
                "luminance gives the diffuse light");
  app->add_flag("--wavefront", c.wavefront,
                "paths one bounce a run, each run after the first holding only the paths still going (not over a lazy "
                "octree)");
  app->add_option("--elements", c.light_pass.subdivision, "light pass: elements per triangle side (k: k*k per triangle)")
      ->capture_default_str()->check(CLI::Range(1, 64));
  app->add_option("--light-samples", c.light_pass.samples, "light pass: rays per light and element")
      ->capture_default_str()->check(CLI::Range(1, 4096));
  app->add_option("--load-memory", c.load.memory_mib, "model files are read in a child process: memory it may use, MiB")
      ->capture_default_str()->check(CLI::Range(std::size_t{16}, std::size_t{1} << 30));
  app->add_option("--load-seconds", c.load.seconds, "model files are read in a child process: CPU and wall-clock seconds it may take")
      ->capture_default_str()->check(kFinite & CLI::Range(0.1, 1e6));
  app->add_flag("--load-in-process", c.load.in_process,
                "read model files in this process, without the child or its limits (for debuggers)");
}

// The most pixels an image may have: each takes some 100 bytes across the
// ray streams and the image (16384 x 16384, some 27 GB).
constexpr long long kMostPixels = 1LL << 28;

std::pair<int, int> parse_size(const std::string& s) {
  int w = 0, h = 0;
  char x = 0;
  std::istringstream in(s);
  if (!(in >> w >> x >> h) || x != 'x' || w < 1 || h < 1 || !(in >> std::ws).eof())
    throw Error("--size: expected WIDTHxHEIGHT, got '" + s + "'");
  if (static_cast<long long>(w) * h > kMostPixels)
    throw Error("--size " + s + ": " + std::to_string(static_cast<long long>(w) * h) + " pixels, more than the " +
                std::to_string(kMostPixels) + " (16384x16384) an image may have");
  return {w, h};
}

Vec3 parse_vec3(const std::string& option, const std::string& s) {
  Vec3 v;
  char c1 = 0, c2 = 0;
  std::istringstream in(s);
  if (!(in >> v.x >> c1 >> v.y >> c2 >> v.z) || c1 != ',' || c2 != ',' || !(in >> std::ws).eof())
    throw Error(option + ": expected x,y,z, got '" + s + "'");
  return v;
}

Scene scene_for(const Common& c) {
  Scene scene = c.scene == "procedural" ? builtin_scene("procedural", c.triangles) : load_scene(c.scene, c.load);
  for (const std::string& w : scene.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  return scene;
}

RenderSettings settings_for(const Common& c, const std::string& backend_name) {
  RenderSettings s;
  std::tie(s.width, s.height) = parse_size(c.size);
  s.reflections = c.reflections;
  s.backend = backend_name;
  s.options.precision = c.precision == "f64" ? Precision::F64 : Precision::F32;
  s.options.math = c.math == "fast" ? MathMode::Fast : MathMode::Precise;
  s.options.threads = c.threads;
  for (const std::string& kv : c.settings) {
    auto eq = kv.find('=');
    if (eq == std::string::npos || eq == 0) throw Error("--set: expected KEY=VALUE, got '" + kv + "'");
    s.options.set(kv.substr(0, eq), kv.substr(eq + 1));
  }
  s.shadow_samples = c.samples;
  s.pattern = parse_pattern(c.pattern);
  s.grid_density = c.grid_density;
  s.accel = parse_accel(c.accel);
  s.octree = c.octree;
  s.bvh = c.bvh;
  s.bvh.walk = parse_bvh_walk(c.bvh_walk);
  s.bidirectional = c.bidirectional;
  s.wavefront = c.wavefront;
  s.light_pass = c.light_pass;
  s.light_pass.depth = c.reflections;
  return s;
}

// What the backend reports of its own over a pass (mpi: each rank's work
// and each split table's cache).
void print_details(const char* pass, const std::shared_ptr<RunDetails>& details) {
  if (!details) return;
  for (const std::string& line : details->describe()) std::printf("%s: %s\n", pass, line.c_str());
}

// The kernel's program in its serialized form (names kept): the bytes the
// mpi backend sends its ranks and, without the names, the kernel cache's key.
void write_program_bytes(const std::string& path, const Program& p) {
  std::string bytes = ir::serialize(p.ir());
  shtrace::check_output_path(path);
  shtrace::say_if_replacing(path);
  shtrace::write_through_temp(path, bytes);
  std::printf("program %s: %zu bytes of serialized IR in %s\n", p.name().c_str(), bytes.size(), path.c_str());
}

std::string hash_line(std::uint64_t hash) {
  char line[96];
  std::snprintf(line, sizeof line, "-- structural hash %016llx (the kernel cache's key) --\n",
                static_cast<unsigned long long>(hash));
  return line;
}

// A program's bytes are a few hundred KiB at most: far past that, the file
// is something else (and /dev/zero would read until memory ran out).
constexpr std::uintmax_t kMostProgramBytes = 64u << 20;

// `shtrace ir FILE`: a program written by --dump-ir-bytes, read back (every
// value range-checked, the program verified) and printed, with its hash.
int ir_command(const std::string& path, bool optimized) {
  std::error_code failed;
  if (!std::filesystem::is_regular_file(path, failed))
    throw Error(path + ": not a regular file (`shtrace ir` reads what render --dump-ir-bytes wrote)");
  if (std::uintmax_t size = std::filesystem::file_size(path, failed); !failed && size > kMostProgramBytes)
    throw Error(path + ": " + std::to_string(size) + " bytes, more than a program's bytes take (at most " +
                std::to_string(kMostProgramBytes) + ")");
  std::ifstream f(path, std::ios::binary);
  if (!f) throw Error(path + ": cannot open the file");
  std::string bytes{std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
  ir::Program p;
  try {
    p = ir::deserialize(bytes);
  } catch (const Error& e) {
    throw Error(path + ": " + e.what());
  }
  std::printf("%s%s", ir::print(p).c_str(), hash_line(ir::structural_hash(p)).c_str());
  if (optimized) std::printf("-- after the passes --\n%s", ir::print(optimize(std::move(p))).c_str());
  return 0;
}

// Where a first render's compile went, phase by phase over its kernels.
void print_phases(const RenderReport& r) {
  std::printf("  compile phases: record %.1f (once per renderer)", r.record_ms);
  for (const CompilePhase& phase : r.compile_phases) std::printf(", %s %.1f", phase.name.c_str(), phase.ms);
  std::printf(" ms; CPU time %.1f ms\n", r.compile_cpu_ms);
}

int render_command(const Common& c, const std::string& backend_name, const std::string& output, const std::string& aov,
                   const std::string& eye, const std::string& look_at, const std::string& up, float fov, bool dump_ir,
                   const std::string& dump_ir_bytes, bool general, bool analyze, int frames, bool phases) {
  // Every file named is checked before the work, so that a bad one does
  // not fail the command after the image is written.
  std::vector<std::string> outputs;
  for (const std::string& named : {output, dump_ir_bytes})
    if (!named.empty()) outputs.push_back(named);
  if (!aov.empty())
    for (const char* suffix : {"_distance.pfm", "_triangle.pfm"}) outputs.push_back(aov + suffix);
  shtrace::check_outputs(outputs, {c.scene});
  Scene scene = scene_for(c);
  shtrace::check_not_inputs(outputs, scene.files);  // the models a scene file names are inputs too
  if (!eye.empty()) scene.camera.eye = parse_vec3("--eye", eye);
  if (!look_at.empty()) scene.camera.look_at = parse_vec3("--look-at", look_at);
  if (!up.empty()) scene.camera.up = parse_vec3("--up", up);
  if (!std::isnan(fov)) scene.camera.fov_degrees = fov;  // the scene's checks name a bad one
  RenderSettings s = settings_for(c, backend_name);
  s.specialise = !general;
  s.progress = true;
  Renderer r(std::move(scene), s);
  std::printf("scene %s: %zu triangles, %s; kernel leaves out: %s\n", r.scene().name.c_str(), r.scene().mesh.triangles(),
              r.describe_accelerator().c_str(), r.features().left_out().c_str());
  if (dump_ir)
    std::printf("%s%s\n-- after the passes --\n%s", print(r.program()).c_str(), hash_line(r.program().hash()).c_str(),
                print_optimized(r.program()).c_str());
  if (!dump_ir_bytes.empty()) write_program_bytes(dump_ir_bytes, r.program());
  if (analyze) {
    for (const Program& k : {raygen_program(r.tables()), intersector_program(r.tables()), r.program()})
      std::printf("kernel %s (after the passes):\n%s", k.name().c_str(),
                  analysis::describe(analysis::count_operations(optimize(k.ir()))).c_str());
  }
  RenderReport report;
  Image image = r.render(&report);
  double compile_ms = report.compile_ms, best_ms = report.render_ms;
  for (int f = 1; f < frames; ++f) {  // later frames: warm, the kernel cached
    RenderReport again;
    r.render(&again);
    best_ms = std::min(best_ms, again.render_ms);
  }
  report.compile_ms = compile_ms;
  report.render_ms = best_ms;
  std::string written = shtrace::write_image(output, c.scene, [&](const std::string& path) { write_png(path, image); });
  if (NanPixels nan = nan_pixels(image); nan.count > 0)
    std::fprintf(stderr, "warning: %zu of %d pixels are NaN, written black; the first at x %lld, y %lld\n", nan.count,
                 image.width * image.height, nan.first % image.width, nan.first / image.width);
  if (!aov.empty()) {
    std::vector<float> ids(image.triangle.begin(), image.triangle.end());
    for (const auto& [suffix, values] : {std::pair{"_distance.pfm", &image.distance}, std::pair{"_triangle.pfm", &ids}})
      shtrace::write_image(aov + suffix, c.scene,
                           [&](const std::string& path) { write_pfm(path, image.width, image.height, *values); });
  }
  std::printf("rendered %dx%d on %s: compile %.1f ms%s, render %.1f ms%s (%.2f Mrays/s primary, %.2f fps)\nimage: %s\n",
              image.width, image.height, report.backend.c_str(), report.compile_ms,
              report.compile_from_disk ? " (loaded from the disk cache)" : "", report.render_ms,
              frames > 1 ? " (best warm frame)" : "", report.rays / (report.render_ms * 1e3), 1000.0 / report.render_ms,
              std::filesystem::absolute(written).c_str());
  if (phases && report.compile_ms > 0) print_phases(report);
  if (!aov.empty()) std::printf("aov: %s_distance.pfm, %s_triangle.pfm\n", aov.c_str(), aov.c_str());
  if (report.light.rays > 0) {
    Vec3 e = r.element_light()->total();
    std::printf("light pass on %s: %zu rays (%d elements per triangle, %d per element and light), compile %.1f ms, run %.1f ms "
                "(%.2f Mrays/s); energy arrived (rgb) %.4g %.4g %.4g\n",
                report.light.backend.c_str(), report.light.rays, c.light_pass.subdivision * c.light_pass.subdivision,
                c.light_pass.samples, report.light.compile_ms, report.light.run_ms,
                report.light.rays / (report.light.run_ms * 1e3), e.x, e.y, e.z);
  }
  print_details("light pass", report.light.details);
  print_details("render", report.details);
  shtrace::print_lazy_builds(report);
  if (report.lanes)
    std::printf("wavefront: %zu waves after the first, %zu path runs in them; lanes busy in the bounce loop: %.0f %% as one "
                "kernel, %.0f %% in waves (modelled: each wave's paths as one stream in batches of %d)\n",
                report.waves, report.resumed, 100 * report.lanes->whole(), 100 * report.lanes->waves(), report.lanes->lanes);
  return 0;
}

// Mrays/s of the intersector kernel alone on the given rays (warm).
double intersect_rate(sh::rt::Renderer& r, const BackendChoice& b, const std::vector<float>& origins,
                      const std::vector<float>& directions, int repeats) {
  r.intersect(origins, directions, b);
  double ms = 0;
  for (int i = 0; i < repeats; ++i) {
    RunStats s;
    r.intersect(origins, directions, b, &s);
    ms += s.run_ms;
  }
  return origins.size() / 3.0 * repeats / (ms * 1e3);
}

int bench_command(const Common& c, std::vector<std::string> backends, bool phases) {
  if (backends.empty()) backends = backend_names();
  Scene scene = scene_for(c);
  auto [w, h] = parse_size(c.size);
  RenderSettings ref_settings = settings_for(c, "interp");
  ref_settings.options.precision = Precision::F64;
  Renderer reference(scene, ref_settings);
  std::printf("scene %s, %s, %zu triangles, %s; reference: interp f64\n", scene.name.c_str(), c.size.c_str(),
              scene.mesh.triangles(), reference.describe_accelerator().c_str());
  Image ref = reference.render();
  auto [origins, directions] = shtrace::primary_rays(reference, w, h);
  std::printf("%-11s %11s %11s %15s %17s %11s %9s\n", "backend", "compile ms", "render ms", "primary Mrays/s",
              "intersect Mrays/s", "max error", "PSNR dB");
  // Each backend in each of its variants (cpu: scalar and every SPMD width).
  double default_cpu = 0;
  std::string default_cpu_accel;
  for (const std::string& b : backends) {
    if (b == "mpi") {
      std::printf("mpi: left out (bench runs in one process; mpirun -np N shtrace render --backend mpi renders on ranks)\n");
      continue;
    }
    for (const Backend::Variant& v : find_backend(b).variants()) {
      RenderSettings s = settings_for(c, b);
      s.options.set(v.options);
      Renderer r(scene, s);
      RenderReport first, second;
      r.render(&first);
      Image img = r.render(&second);  // warm: the kernel is cached
      float max_error = max_difference(ref, img);
      double rate = intersect_rate(r, BackendChoice{b, s.options}, origins, directions, b == "interp" ? 1 : 5);
      std::string name = v.name.empty() ? b : b + ":" + v.name;
      std::printf("%-11s %11.1f %11.1f %15.2f %17.2f %11.5f %9.1f%s\n", name.c_str(), first.compile_ms, second.render_ms,
                  second.rays / (second.render_ms * 1e3), rate, max_error, psnr(ref, img),
                  first.compile_from_disk ? "  compile: loaded from the disk cache" : "");
      if (phases) print_phases(first);
    }
    // The default cpu renderer's own accelerator (`auto` chooses by the
    // backend's lanes), not the interp reference's.
    if (b == "cpu") {
      RenderSettings s = settings_for(c, "cpu");
      Renderer r(scene, s);
      default_cpu = intersect_rate(r, BackendChoice{"cpu", s.options}, origins, directions, 5);
      default_cpu_accel = sh::rt::accel_name(r.accel());
    }
  }
  std::vector<std::pair<int, double>> embree;
  sh::rt::EmbreeScene embree_scene(scene);
  for (int packet : {1, 4, 8, 16}) {
    shtrace::AnchorResult a = shtrace::embree_rays(embree_scene, {origins, directions, {}, {}}, 5, packet);
    std::string name = "embree:" + std::to_string(packet);
    if (a.mrays_per_s > 0) std::printf("%-11s %11s %11s %15s %17.2f\n", name.c_str(), "-", "-", "-", a.mrays_per_s);
    else std::printf("%-11s  rtcIntersect%d: not native on this CPU\n", name.c_str(), packet);
    embree.emplace_back(packet, a.mrays_per_s);
  }
  if (default_cpu > 0)
    for (auto [packet, rate] : embree)
      if (rate > 0)
        std::printf("cpu (default width, %s) intersector / Embree rtcIntersect%d on the same %zu primary rays: %.3fx\n",
                    default_cpu_accel.c_str(), packet, origins.size() / 3, default_cpu / rate);
  return 0;
}

int info_command() {
  std::printf("backends (default: %s):\n", default_backend_name().c_str());
  for (const BackendInfo& b : backends()) {
    for (const std::string& line : find_backend(b.name).describe()) std::printf("  %s\n", line.c_str());
    for (const Backend::Setting& s : b.settings) std::printf("    --set %s=...: %s\n", s.name.c_str(), s.values.c_str());
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"shtrace: the stream ray tracer of the sh language"};
  app.require_subcommand(1);
  Common common;
  std::string backend_name, output, aov, eye, look_at, up;
  float fov = std::numeric_limits<float>::quiet_NaN();  // the scene's unless given
  bool dump_ir = false, general = false, analyze = false, ir_optimized = false;
  std::string dump_ir_bytes, ir_file;
  int frames = 1;
  std::vector<std::string> bench_backends;

  CLI::App* render = app.add_subcommand("render", "render a scene to PNG");
  add_common(render, common);
  std::string built;
  for (const std::string& b : backend_names()) built += (built.empty() ? "" : ", ") + b;
  render->add_option("--backend", backend_name, built + " (default: SH_BACKEND, else cpu)");
  render->add_option("--output,-o", output,
                     "PNG to write; if it exists it is replaced, and the output says \"replacing FILE\" (default: "
                     "out/SCENE.png, SCENE the built-in scene's name or the scene or model file's name without its "
                     "extension; if that exists, the first free of out/SCENE-2.png, -3, ..., never replacing a file)");
  render->add_option("--aov", aov, "also write PREFIX_distance.pfm and PREFIX_triangle.pfm");
  render->add_option("--eye", eye, "camera position x,y,z");
  render->add_option("--look-at", look_at, "point looked at x,y,z");
  render->add_option("--up", up, "up vector x,y,z");
  render->add_option("--fov", fov, "vertical field of view, degrees")->check(kFinite);
  render->add_flag("--dump-ir", dump_ir, "print the kernel's IR before and after the passes");
  render->add_option("--dump-ir-bytes", dump_ir_bytes,
                     "write the kernel's IR to FILE as the bytes the kernel cache hashes and the mpi backend sends "
                     "(`shtrace ir FILE` prints it)");
  render->add_flag("--general", general, "use the general kernel, not one specialised to the scene");
  render->add_flag("--analyze", analyze, "print the kernels' operation counts, per loop iteration too");
  render->add_option("--frames", frames, "render this many frames and report the best warm one")->check(CLI::Range(1, 1000));
  bool render_phases = false;
  render->add_flag("--phases", render_phases,
                   "where the compile went: recording, passes, lowering, cache key, LLVM optimisation, JIT setup, "
                   "machine code, storing and linking (summed over the render's kernels), and its CPU time");

  CLI::App* bench = app.add_subcommand("bench", "each backend on one scene: compile, render, error against interp f64");
  add_common(bench, common);
  bench->add_option("--backends", bench_backends, "backends to run, comma-separated (default: all built)")
      ->delimiter(',')->allow_extra_args(false)->check(kBackendName);
  bool bench_phases = false;
  bench->add_flag("--phases", bench_phases,
                  "under each backend, where its compile went: passes, lowering, cache key, LLVM optimisation, JIT "
                  "setup, machine code, storing and linking (summed over the render's kernels), after recording the kernels");

  shtrace::CompareRequest compare_request;
  std::vector<std::string> compare_backend_names;
  CLI::App* compare = app.add_subcommand("compare", "one kernel of the scene on every backend, variant and math mode: "
                                         "compile and run time, largest difference from interp in f64 (sh::compare)");
  add_common(compare, common);
  compare->get_option("--size")->default_str("160x120");  // the interpreter runs every pixel, thrice
  compare->add_option("--backends", compare_backend_names, "backends to run, comma-separated (default: all built)")
      ->delimiter(',')->allow_extra_args(false)->check(kBackendName);
  compare->add_option("--kernel", compare_request.kernel, "render (the whole kernel over every pixel) or intersect "
                      "(the intersector on the primary rays)")->check(CLI::IsMember({"render", "intersect"}))->capture_default_str();
  compare->add_option("--runs", compare_request.runs, "runs per row; the fastest counts")->capture_default_str()
      ->check(CLI::Range(1, 100));

  shtrace::TradeoffOptions tradeoff_options;
  std::string tradeoff_size = "200x150";
  CLI::App* trade = app.add_subcommand("tradeoff", "a grid of settings against a converged reference: CSV and plot");
  trade->add_option("--scene", tradeoff_options.scene, "scene (default: soft)")->capture_default_str();
  trade->add_option("--size", tradeoff_size, "image size")->capture_default_str();
  trade->add_option("--backends", tradeoff_options.backends, "backends, comma-separated (default: cpu and opencl)")
      ->delimiter(',')->allow_extra_args(false)->check(kBackendName);
  trade->add_option("--out", tradeoff_options.out, "writes OUT.csv, OUT.gp and OUT.png")->capture_default_str();

  std::string view = "full";
  CLI::App* accel = app.add_subcommand("accel", "grid, octree, lazy octree and BVH on one scene: memory, build, trace, first image");
  add_common(accel, common);
  accel->add_option("--backend", backend_name, "backend to trace on (default: SH_BACKEND, else cpu)");
  accel->add_option("--view", view, "full, or half (turned to one side, narrower)")->check(CLI::IsMember({"full", "half"}))
      ->capture_default_str();

  int ray_repeats = 5;
  CLI::App* rays = app.add_subcommand("rays", "camera, shadow and reflection rays of one scene: the kernels (shadow rays "
                                      "with the any-hit and the nearest-hit walk) against Embree and a hand-written C++ walk "
                                      "of the same BVH on the same rays");
  add_common(rays, common);
  rays->add_option("--backend", backend_name, "backend to trace on (default: SH_BACKEND, else cpu)");
  rays->add_option("--repeats", ray_repeats,
                   "rounds, each running our kernel and Embree's calls once in turn after an untimed run; rates are "
                   "of the median round")->capture_default_str()
      ->check(CLI::Range(1, 1000));
  bool ray_lanes = false;
  rays->add_flag("--lanes", ray_lanes,
                 "also how busy the lanes are in the BVH's walk for each kind: the share of the box steps and of the "
                 "leaf tests that a lane's own ray wanted");

  CLI::App* ir_cmd = app.add_subcommand("ir", "print a program written by render --dump-ir-bytes, and its hash");
  ir_cmd->add_option("file", ir_file, "the file")->required();
  ir_cmd->add_flag("--optimized", ir_optimized, "print it after the passes too");

  app.add_subcommand("info", "backends and OpenCL devices found");
  CLI11_PARSE(app, argc, argv);
  shtrace::ignore_file_size_limit();
  auto command = [&]() -> int {
    try {
      // The backend runs kernels on --threads; this holds the rest (building
      // accelerators) to as many, on every rank.
      std::optional<tbb::global_control> threads;
      if (common.threads > 0)
        threads.emplace(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(common.threads));
#ifdef SHTRACE_WITH_MPI
      // Under mpirun, serving ranks wait for rank 0 from here on.
      bool compares_mpi =
          compare->parsed() && (compare_backend_names.empty() ||
                                std::count(compare_backend_names.begin(), compare_backend_names.end(), "mpi") > 0);
      if (backend_name == "mpi" || compares_mpi) sh::mpi::start();
#endif
      if (render->parsed())
        return render_command(common, backend_name, output, aov, eye, look_at, up, fov, dump_ir, dump_ir_bytes, general,
                              analyze, frames, render_phases);
      if (ir_cmd->parsed()) return ir_command(ir_file, ir_optimized);
      if (bench->parsed()) return bench_command(common, bench_backends, bench_phases);
      if (compare->parsed()) {
        // Its rows are every math mode: a mode asked for would be ignored.
        if (compare->get_option("--math")->count() > 0)
          throw Error("compare: every backend runs in every math mode, a row each; --math does not apply");
        if (compare->get_option("--size")->count() == 0) common.size = "160x120";
        compare_request.scene = scene_for(common);
        compare_request.settings = settings_for(common, "");
        compare_request.backends = compare_backend_names;
        return shtrace::compare_backends(compare_request);
      }
      if (rays->parsed())
        return shtrace::compare_ray_kinds(
            {scene_for(common), settings_for(common, backend_name), ray_repeats, ray_lanes});
      if (accel->parsed())
        return shtrace::compare_accelerators({scene_for(common), settings_for(common, backend_name), view});
      if (trade->parsed()) {
        std::tie(tradeoff_options.width, tradeoff_options.height) = parse_size(tradeoff_size);
        return shtrace::tradeoff(tradeoff_options);
      }
      return info_command();
    } catch (const Error& e) {
      std::fprintf(stderr, "shtrace: %s\n", e.what());
      return 1;
    } catch (const std::bad_alloc&) {
      std::fprintf(stderr, "shtrace: out of memory: a smaller --size, scene or --triangles takes less\n");
      return 1;
    } catch (const std::exception& e) {  // the file system: still a message, not a crash
      std::fprintf(stderr, "shtrace: %s\n", e.what());
      return 1;
    }
  };
  int status = command();
  // What was printed is part of the result: a full disk under `> file` is
  // a failure, not a silent success.
  if (std::fflush(stdout) != 0 || std::ferror(stdout)) {
    std::fprintf(stderr, "shtrace: cannot write standard output: %s\n", std::strerror(errno));
    return 1;
  }
  return status;
}
