// The ray tracer on the mpi backend under mpirun (-np 3 in CTest): the
// bidirectional images agree with cpu's at this rank count, with whole
// tables and with tables split over the ranks and read through caches.
#include <gtest/gtest.h>

#include <sh/raytracer/render.hpp>
#include <sh/raytracer/scene.hpp>
#include <sh/sh.hpp>

namespace {

sh::rt::RenderSettings glass_settings(const std::string& backend) {
  sh::rt::RenderSettings s;
  s.width = 48;
  s.height = 48;
  s.reflections = 3;
  s.bidirectional = true;
  s.light_pass.samples = 4;
  s.backend = backend;
  return s;
}

TEST(RaytracerOnRanks, BidirectionalImagesAgreeWithCpuWholeAndSplit) {
  sh::rt::Scene scene = sh::rt::builtin_scene("magg-glass");
  sh::rt::Image want = sh::rt::Renderer(scene, glass_settings("cpu")).render();
  for (bool split : {false, true}) {
    sh::rt::RenderSettings s = glass_settings("mpi");
    if (split) s.options.settings = {{"split_tables", "0"}, {"cache_blocks", "8"}};
    sh::rt::Renderer on_ranks(scene, s);
    sh::rt::RenderReport report;
    sh::rt::Image got = on_ranks.render(&report);
    EXPECT_GE(sh::rt::share_within(want, got, 2.0f / 255), 0.995) << "split " << split;
    EXPECT_GT(sh::rt::psnr(want, got), 45.0) << "split " << split;
    EXPECT_EQ(report.caches.empty(), !split);
    if (split && sh::mpi::size() > 1) {
      std::size_t remote = 0;
      for (const sh::TableCacheStats& c : report.caches) remote += c.counts.remote_misses;
      EXPECT_GT(remote, 0u) << "blocks came from other ranks";
    }
  }
}

}  // namespace
