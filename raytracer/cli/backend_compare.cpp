#include "backend_compare.hpp"

#include <cstdio>
#include <iostream>

#include <sh/sh.hpp>
#ifdef SHTRACE_WITH_MPI
#include <sh/mpi.hpp>
#endif

namespace shtrace {
namespace {

using namespace sh;
using namespace sh::rt;

// The tracer's kernels leave their outputs unnamed; the table names them.
void name_outputs(Comparison& c, const std::vector<std::string>& names) {
  for (CompareRow& row : c.rows)
    for (std::size_t k = 0; k < row.outputs.size() && k < names.size(); ++k) row.outputs[k].name = names[k];
}

// Kernels that need more than one run of one program are not compared:
// say which and why, before anything is built.
void check_comparable(const CompareRequest& r) {
  if (r.settings.accel == Accel::LazyOctree)
    throw Error("compare: the lazy octree is built between runs of the kernel (in waves), so one run of it is not the "
                "render; compare with --accel grid or octree");
  if (r.settings.bidirectional)
    throw Error("compare: --bidirectional renders in two passes (the light pass first), so one kernel is not the render; "
                "compare without it");
  if (r.settings.wavefront)
    throw Error("compare: --wavefront traces one bounce a run, so one run of the kernel is not the render; compare "
                "without it");
  if (r.kernel != "render" && r.kernel != "intersect")
    throw Error("compare: --kernel must be render or intersect, not '" + r.kernel + "'");
}

void print_mpi_ranks(const Comparison& c) {
#ifdef SHTRACE_WITH_MPI
  for (const CompareRow& row : c.rows)
    if (row.backend == "mpi" && !row.failed()) {
      int ranks = sh::mpi::size();
      std::printf("mpi ran on %d rank%s%s\n", ranks, ranks == 1 ? "" : "s",
                  ranks == 1 ? " in this process (under mpirun -np N it runs on N)" : "");
      return;
    }
#else
  (void)c;
#endif
}

}  // namespace

std::pair<std::vector<float>, std::vector<float>> primary_rays(Renderer& r, int width, int height) {
  Program raygen = raygen_program(r.tables());
  Channel<Attrib2f> pixels(pixel_centres_in_tiles(width, height));
  Channel<Point3f> o;
  Channel<Vector3f> d;
  Channel<Attrib2f> pixel;
  run(raygen, {pixels}, {o, d, pixel});
  return {o.values(), d.values()};
}

int compare_backends(const CompareRequest& request) {
  check_comparable(request);
  Renderer r(request.scene, request.settings);
  int w = request.settings.width, h = request.settings.height;
  CompareOptions o;
  o.backends = request.backends;
  o.options = request.settings.options;
  o.precision = request.settings.options.precision;
  o.runs = request.runs;
  std::printf("scene %s: %zu triangles, %s; kernel leaves out: %s\n", r.scene().name.c_str(), r.scene().mesh.triangles(),
              r.describe_accelerator().c_str(), r.features().left_out().c_str());
  Comparison c;
  if (request.kernel == "render") {
    std::printf("the whole render: ray generation and the tracer, one kernel, over %dx%d pixels\n", w, h);
    Channel<Attrib2f> pixels(pixel_centres_in_tiles(w, h));
    c = compare(r.program(), {pixels}, o);
    name_outputs(c, {"colour", "distance", "triangle"});
  } else {
    std::printf("the intersector on the %dx%d primary rays\n", w, h);
    auto [origins, directions] = primary_rays(r, w, h);
    Channel<Point3f> from(origins);
    Channel<Vector3f> along(directions);
    c = compare(intersector_program(r.tables()), {from, along}, o);
    name_outputs(c, {"distance", "triangle"});
  }
  std::cout << c;
  print_mpi_ranks(c);
  std::size_t failed = 0;
  for (const CompareRow& row : c.rows) failed += row.failed() ? 1 : 0;
  std::printf("%zu rows, %zu failed%s\n", c.rows.size(), failed, c.reference.failed() ? "; the reference failed" : "");
  return c.reference.failed() || failed > 0 ? 1 : 0;
}

}  // namespace shtrace
