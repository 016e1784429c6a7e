// The ray tracer on the mpi backend, for BENCHMARKS.md.  Run under mpirun:
//   mpirun -np R build/tests/mpi_bench [scene] [WxH] [schedule] [chunk]
// One band (one run) per frame; prints the warm frame time and what each
// rank did.
#include <cstdio>
#include <cstdlib>
#include <string>

#include <sh/raytracer.hpp>
#include <sh/mpi.hpp>
#include <sh/sh.hpp>

int main(int argc, char** argv) {
  using namespace sh;
  mpi::start();
  std::string scene_name = argc > 1 ? argv[1] : "spheres";
  int w = 512, h = 384;
  if (argc > 2) std::sscanf(argv[2], "%dx%d", &w, &h);
  rt::RenderSettings settings;
  settings.width = w;
  settings.height = h;
  settings.backend = "mpi";
  settings.options.set("mpi.local", "cpu");
  settings.options.threads = 1;  // one core per rank, as on a cluster node slot
  if (argc > 3) settings.options.set("mpi.schedule", argv[3]);
  if (argc > 4) settings.options.set("mpi.chunk", argv[4]);
  // "uneven": the spheres scene seen from above the grid, looking level:
  // the upper half of the image is sky whose rays never enter the grid,
  // the lower half floor and spheres (reflections, shadow rays), so a
  // static split by halves is unbalanced.
  rt::Scene scene = rt::builtin_scene(scene_name == "uneven" ? "spheres" : scene_name, 100000);
  if (scene_name == "uneven") scene.camera = {{0, 3, 6}, {0, 3, 0}, {0, 1, 0}, 60};
  rt::Renderer r(std::move(scene), settings);
  r.render();  // compile and first broadcast
  double best = 1e30;
  for (int i = 0; i < 5; ++i) {
    rt::RenderReport report;
    r.render(&report);
    best = std::min(best, report.render_ms);
  }
  // The last frame's parts, through a direct run of the same program.
  Channel<Attrib2f> pixels(rt::pixel_centres(w, h));
  Channel<Color3f> color;
  Channel<Attrib1f> distance;
  Channel<Attrib1i> triangle;
  RunStats s = run(r.program(), {pixels}, {color, distance, triangle}, backend("mpi", settings.options));
  std::printf("ranks %d scene %s %dx%d schedule %s chunk %s: best frame %.1f ms\n", mpi::size(), scene_name.c_str(), w, h,
              argc > 3 ? argv[3] : "dynamic", argc > 4 ? argv[4] : "auto", best);
  for (const mpi::PartStats& p : s.details_as<mpi::RunDetails>()->parts)
    std::printf("  rank %d: %zu elements, %zu chunks, busy %.1f ms, idle %.1f ms, sent %zu B, received %zu B\n", p.part,
                p.elements, p.chunks, p.busy_s * 1e3, p.idle_s * 1e3, p.bytes_sent, p.bytes_received);
  return 0;
}
