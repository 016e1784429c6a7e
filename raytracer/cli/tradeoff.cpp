#include "tradeoff.hpp"

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <sh/sh.hpp>

#include "output_file.hpp"

namespace shtrace {
namespace {

using namespace sh;
using namespace sh::rt;

struct Setting {
  std::string backend = "cpu";
  SamplePattern pattern = SamplePattern::Random;
  int samples = 16;
  Precision precision = Precision::F32;
  MathMode math = MathMode::Precise;
  int depth = 3;
  double density = 2.0;
  unsigned seed = 1;  // of the random sample set
};

struct Result {
  Setting s;
  double ms = 0, rmse = 0, psnr = 0;
  int penumbra = 0;
  bool pareto = false;
};

float luminance(const Image& img, std::size_t p) {
  return 0.2126f * img.rgb[3 * p] + 0.7152f * img.rgb[3 * p + 1] + 0.0722f * img.rgb[3 * p + 2];
}

double rmse(const Image& a, const Image& b) {
  double sum = 0;
  for (std::size_t i = 0; i < a.rgb.size(); ++i) {
    double d = std::clamp(a.rgb[i], 0.f, 1.f) - std::clamp(b.rgb[i], 0.f, 1.f);
    sum += d * d;
  }
  return std::sqrt(sum / a.rgb.size());
}

Image render(const Scene& scene, const TradeoffOptions& o, const Setting& s, double* warm_ms) {
  RenderSettings rs;
  rs.width = o.width;
  rs.height = o.height;
  rs.backend = s.backend;
  rs.options.precision = s.precision;
  rs.options.math = s.math;
  rs.shadow_samples = s.samples;
  rs.pattern = s.pattern;
  rs.reflections = s.depth;
  rs.grid_density = s.density;
  rs.seed = s.seed;
  Renderer r(scene, rs);
  Image img = r.render();  // compile
  if (!warm_ms) return img;
  // The fastest of three warm renders: settings of equal work (the two
  // patterns, the densities, fast math) would otherwise be ordered on the
  // front by one run's noise.
  *warm_ms = INFINITY;
  for (int run = 0; run < 3; ++run) {
    RenderReport report;
    img = r.render(&report);
    *warm_ms = std::min(*warm_ms, report.render_ms);
  }
  return img;
}

std::vector<Setting> grid(const std::vector<std::string>& backends) {
  std::vector<Setting> out;
  for (const std::string& b : backends)
    for (SamplePattern p : {SamplePattern::Random, SamplePattern::PseudoRandom})
      for (int n : {1, 4, 16, 64, 256}) {
        Setting s;
        s.backend = b;
        s.pattern = p;
        s.samples = n;
        out.push_back(s);
      }
  // One axis at a time around 16 random samples on the first backend, f32,
  // precise.
  Setting base;
  base.backend = backends.front();
  Setting f64 = base, fast = base, flat = base, one = base, coarse = base, fine = base;
  f64.precision = Precision::F64;
  fast.math = MathMode::Fast;
  flat.depth = 0;
  one.depth = 1;
  coarse.density = 0.25;
  fine.density = 8;
  for (const Setting& s : {f64, fast, flat, one, coarse, fine}) out.push_back(s);
  return out;
}

// A setting joins the front where it lowers the error of every faster one
// by more than 1 %: a slower one whose error differs only in rounding
// (another backend's run of the same setting) does not.
void mark_pareto(std::vector<Result>& results) {
  std::vector<Result*> by_time;
  for (Result& r : results) by_time.push_back(&r);
  std::sort(by_time.begin(), by_time.end(), [](const Result* a, const Result* b) { return a->ms < b->ms; });
  double best = INFINITY;
  for (Result* r : by_time)
    if (r->rmse < 0.99 * best) {
      r->pareto = true;
      best = r->rmse;
    }
}

std::string label(const Setting& s) {
  char buf[128];
  std::snprintf(buf, sizeof buf, "%s %s %d %s%s d%d g%g", s.backend.c_str(), pattern_name(s.pattern), s.samples,
                s.precision == Precision::F64 ? "f64" : "f32", s.math == MathMode::Fast ? " fast" : "", s.depth, s.density);
  return buf;
}

bool control_character(char c) { return static_cast<unsigned char>(c) < 0x20 || c == 0x7f; }

// A gnuplot string of any text: single-quoted, a quote in it doubled, and
// a control character shown as '?' (a newline would end the string and
// the command: what follows it would run as gnuplot's own).
std::string gnuplot_string(const std::string& text) {
  std::string quoted = "'";
  for (char c : text) quoted += c == '\'' ? std::string("''") : std::string(1, control_character(c) ? '?' : c);
  return quoted + "'";
}

// gnuplot running one command, then a script, with no shell between (the
// script's name may hold any character): whether it ran and succeeded.
bool run_gnuplot(const std::string& first, const std::string& script) {
  std::string program = "gnuplot", e = "-e";
  char* argv[] = {program.data(), e.data(), const_cast<char*>(first.c_str()), const_cast<char*>(script.c_str()),
                  nullptr};
  pid_t child = 0;
  if (posix_spawnp(&child, "gnuplot", nullptr, nullptr, argv, environ) != 0) return false;
  int status = 0;
  while (waitpid(child, &status, 0) < 0)
    if (errno != EINTR) return false;
  return WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

}  // namespace

int shadow_row(const Image& reference, const Scene& scene) {
  int floor_material = scene.mesh.material.empty() ? 0 : scene.mesh.material[0];
  int best_row = reference.height / 2;
  float darkest = INFINITY;
  for (int y = 0; y < reference.height; ++y)
    for (int x = 0; x < reference.width; ++x) {
      std::size_t p = static_cast<std::size_t>(y) * reference.width + x;
      int t = reference.triangle[p];
      if (t < 0 || scene.mesh.material[t] != floor_material) continue;
      bool clear_row = true;  // only the floor on this row: its edges are shadow edges
      for (int xx = 0; xx < reference.width && clear_row; ++xx) {
        int u = reference.triangle[static_cast<std::size_t>(y) * reference.width + xx];
        clear_row = u >= 0 && scene.mesh.material[u] == floor_material;
      }
      if (!clear_row) continue;
      if (luminance(reference, p) < darkest) {
        darkest = luminance(reference, p);
        best_row = y;
      }
    }
  return best_row;
}

int penumbra_width(const Image& image, const Image& reference, int row) {
  // The shadow edge is the steepest change of the reference along the row;
  // around it, in a window of 24 pixels each side, count the pixels whose
  // brightness lies between 10 % and 90 % of the reference's range there.
  auto lum = [&](const Image& img, int x) { return luminance(img, static_cast<std::size_t>(row) * img.width + x); };
  int edge = 1;
  float steepest = -1;
  for (int x = 1; x + 1 < reference.width; ++x) {
    float g = std::fabs(lum(reference, x + 1) - lum(reference, x - 1));
    if (g > steepest) {
      steepest = g;
      edge = x;
    }
  }
  constexpr int kWindow = 24;
  int from = std::max(0, edge - kWindow), to = std::min(reference.width - 1, edge + kWindow);
  float lo = INFINITY, hi = -INFINITY;
  for (int x = from; x <= to; ++x) {
    lo = std::min(lo, lum(reference, x));
    hi = std::max(hi, lum(reference, x));
  }
  float a = lo + 0.1f * (hi - lo), b = hi - 0.1f * (hi - lo);
  int width = 0;
  for (int x = from; x <= to; ++x) width += lum(image, x) > a && lum(image, x) < b;
  return width;
}

int tradeoff(const TradeoffOptions& o) {
  Scene scene = o.scene == "procedural" ? builtin_scene("procedural", 100000) : load_scene(o.scene);
  std::vector<std::string> backends = o.backends;
  if (backends.empty())
    for (const std::string& b : backend_names())
      if (b == "cpu" || b == "opencl") backends.push_back(b);
  if (backends.empty()) throw Error("tradeoff: no backend to sweep (cpu and opencl are not built); name one with --backends");
  // The plot's file is named in gnuplot's script, where a control
  // character cannot be written.
  if (o.out.empty() || std::any_of(o.out.begin(), o.out.end(), control_character))
    throw Error("tradeoff: --out '" + o.out + "': an empty name, or one with a control character");
  check_outputs({o.out + ".csv", o.out + ".gp", o.out + ".png"}, scene.files);

  if (scene.disk_lights.empty())
    std::fprintf(stderr, "tradeoff: %s has no disk light: the sample settings change nothing in its image\n",
                 o.scene.c_str());
  // The reference's random samples are sets of their own: the settings'
  // sets would otherwise be its first samples, which flatters them.  It
  // averages four renders of the most samples a render takes (1024), 4096
  // in all, 16 times the most a setting takes, so that its own noise adds
  // about 3 % to that setting's error (with 1024 it added 12 %).
  Setting converged;
  converged.backend = backends.front();
  converged.precision = Precision::F64;
  converged.samples = 1024;
  std::fprintf(stderr, "tradeoff: reference (%s, f64, precise, 4 x 1024 random samples of their own)...\n",
               converged.backend.c_str());
  Image reference;
  constexpr int kReferenceRenders = 4;
  for (int k = 0; k < kReferenceRenders; ++k) {
    converged.seed = 2 + static_cast<unsigned>(k);
    Image one = render(scene, o, converged, nullptr);
    if (k == 0) reference = one;
    else
      for (std::size_t i = 0; i < one.rgb.size(); ++i) reference.rgb[i] += one.rgb[i];
  }
  for (float& c : reference.rgb) c /= kReferenceRenders;
  int row = shadow_row(reference, scene);

  std::vector<Result> results;
  std::vector<Setting> settings = grid(backends);
  for (std::size_t i = 0; i < settings.size(); ++i) {
    Result r;
    r.s = settings[i];
    Image img = render(scene, o, r.s, &r.ms);
    r.rmse = rmse(img, reference);
    r.psnr = psnr(reference, img);
    r.penumbra = penumbra_width(img, reference, row);
    results.push_back(r);
    std::fprintf(stderr, "\rtradeoff: %zu/%zu settings", i + 1, settings.size());
  }
  std::fprintf(stderr, "\n");
  mark_pareto(results);

  std::string csv = "backend,pattern,samples,precision,math,reflection_depth,grid_density,render_ms,rmse,psnr_db,penumbra_px,pareto\n";
  char line[256];
  for (const Result& r : results) {
    std::snprintf(line, sizeof line, "%s,%s,%d,%s,%s,%d,%g,%.3f,%.6f,%.2f,%d,%d\n", r.s.backend.c_str(),
                  pattern_name(r.s.pattern), r.s.samples, r.s.precision == Precision::F64 ? "f64" : "f32",
                  r.s.math == MathMode::Fast ? "fast" : "precise", r.s.depth, r.s.density, r.ms, r.rmse, r.psnr, r.penumbra,
                  r.pareto ? 1 : 0);
    csv += line;
  }
  std::snprintf(line, sizeof line, "# reference penumbra on row %d: %d px\n", row, penumbra_width(reference, reference, row));
  csv += line;
  write_through_temp(o.out + ".csv", csv);

  // The plot: every setting, the Pareto front joined, labels on the front.
  std::string front, points;
  std::vector<const Result*> sorted;
  for (const Result& r : results) sorted.push_back(&r);
  std::sort(sorted.begin(), sorted.end(), [](const Result* a, const Result* b) { return a->ms < b->ms; });
  for (const Result* r : sorted) {
    std::snprintf(line, sizeof line, "%.3f %.6f \"%s\"\n", r->ms, r->rmse, label(r->s).c_str());
    points += line;
    if (r->pareto) front += line;
  }
  // The script names the plot; this run has gnuplot draw it under a
  // temporary name, moved into place once whole.
  std::string png = temp_name(o.out + ".png");
  std::string gp = "set terminal pngcairo size 1100,700 noenhanced\nif (!exists('plot_file')) plot_file = " +
                   gnuplot_string(o.out + ".png") + "\nset output plot_file\nset title " +
                   gnuplot_string("Error against render time, scene " + o.scene) +
                   "\nset xlabel 'render time (ms, warm)'\nset ylabel 'RMSE against the converged reference'\n"
                   "set logscale xy\nset grid\nset key top right\n"
                   "$all << EOD\n" + points + "EOD\n$front << EOD\n" + front + "EOD\n"
                   "plot $all using 1:2 with points pt 7 ps 1 lc rgb '#7f7f7f' title 'settings', \\\n"
                   "     $front using 1:2 with linespoints pt 7 ps 1.3 lw 2 lc rgb '#d62728' title 'Pareto front', \\\n"
                   "     $front using 1:2:3 with labels offset 1,0.6 left font ',8' notitle\n";
  write_through_temp(o.out + ".gp", gp);
  if (run_gnuplot("plot_file = " + gnuplot_string(png), o.out + ".gp")) {
    move_into_place(png, o.out + ".png");
    std::printf("%zu settings; csv: %s.csv, plot: %s.png\n", results.size(), o.out.c_str(), o.out.c_str());
    return 0;
  }
  std::remove(png.c_str());
  std::fprintf(stderr, "tradeoff: gnuplot failed or is missing (apt-get install gnuplot-nox); the script is %s.gp%s\n",
               o.out.c_str(), std::filesystem::exists(o.out + ".png") ? "; the plot there is an earlier run's" : "");
  std::printf("%zu settings; csv: %s.csv, no plot\n", results.size(), o.out.c_str());
  return 0;
}

}  // namespace shtrace
