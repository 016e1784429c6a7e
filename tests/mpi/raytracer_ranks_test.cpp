// The ray tracer on the mpi backend under mpirun (-np 3 in CTest): the
// bidirectional images agree with cpu's at this rank count, with whole
// tables and with tables split over the ranks and read through caches; a
// lazy octree that each rank builds for its own share gives cpu's image,
// and a second render of the view builds nothing on any rank; so does a
// wavefront.
#include <gtest/gtest.h>

#include <numeric>
#include <sh/raytracer/octree_refiner.hpp>
#include <sh/raytracer/render.hpp>
#include <sh/raytracer/scene.hpp>
#include <sh/mpi.hpp>
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
    if (split) s.options.set(sh::mpi::Options{.split_tables = 0, .cache_blocks = 8});
    sh::rt::Renderer on_ranks(scene, s);
    sh::rt::RenderReport report;
    sh::rt::Image got = on_ranks.render(&report);
    EXPECT_GE(sh::rt::share_within(want, got, 2.0f / 255), 0.995) << "split " << split;
    EXPECT_GT(sh::rt::psnr(want, got), 45.0) << "split " << split;
    auto* details = dynamic_cast<const sh::mpi::RunDetails*>(report.details.get());
    ASSERT_NE(details, nullptr) << "an mpi render reports its ranks";
    EXPECT_EQ(static_cast<int>(details->parts.size()), sh::mpi::size());
    EXPECT_EQ(details->caches.empty(), !split);
    if (split && sh::mpi::size() > 1) {
      std::size_t remote = 0;
      for (const sh::mpi::TableCacheStats& c : details->caches) remote += c.counts.remote_misses;
      EXPECT_GT(remote, 0u) << "blocks came from other ranks";
    }
  }
}

std::vector<sh::rt::OctreeSummary> summaries(const sh::rt::RenderReport& report) {
  std::vector<sh::rt::OctreeSummary> out;
  for (const std::string& bytes : report.refined) out.push_back(sh::rt::OctreeSummary::read(bytes));
  return out;
}

TEST(RaytracerOnRanks, LazyOctreeBuiltPerRankForItsShareAndKeptForTheNextRender) {
  sh::rt::Scene scene = sh::rt::builtin_scene("procedural", 20000);
  sh::rt::RenderSettings s;
  s.width = 64;
  s.height = 48;
  s.accel = sh::rt::Accel::LazyOctree;
  s.octree = {10, 4};
  s.backend = "cpu";
  sh::rt::Image want = sh::rt::Renderer(scene, s).render();
  s.backend = "mpi";
  sh::rt::Renderer on_ranks(scene, s);
  sh::rt::RenderReport first, second;
  sh::rt::Image got = on_ranks.render(&first);
  EXPECT_EQ(got.rgb, want.rgb);
  EXPECT_EQ(got.triangle, want.triangle);
  std::vector<sh::rt::OctreeSummary> built = summaries(first);
  ASSERT_EQ(built.size(), static_cast<std::size_t>(sh::mpi::size()));
  std::vector<std::vector<std::uint64_t>> keys;
  for (const sh::rt::OctreeSummary& rank : built) {
    EXPECT_GT(rank.built.size(), 0u) << "a rank built nothing for its share";
    keys.push_back(rank.built);
  }
  sh::rt::BuildOverlap overlap = sh::rt::build_overlap(keys);
  // Each rank traces a band of the image of its own, the same each render:
  // the nodes near the root are shared, most of the rest are not.
  if (sh::mpi::size() > 1) {
    EXPECT_LT(overlap.shared, overlap.distinct / 2);
  }

  on_ranks.render(&second);
  EXPECT_EQ(second.waves, 0u) << "the second render of the view stopped on unbuilt nodes";
  std::vector<sh::rt::OctreeSummary> again = summaries(second);
  ASSERT_EQ(again.size(), built.size());
  for (std::size_t r = 0; r < built.size(); ++r) EXPECT_EQ(again[r].built.size(), built[r].built.size()) << "rank " << r;
}

// Each rank runs the waves of its own chunks, with no refiner to make:
// the image is cpu's, and every path's later bounces ran in waves.
TEST(RaytracerOnRanks, WavefrontGivesCpusImage) {
  sh::rt::Scene scene = sh::rt::builtin_scene("spheres");
  sh::rt::RenderSettings s;
  s.width = 64;
  s.height = 48;
  s.accel = sh::rt::Accel::Bvh;
  s.backend = "cpu";
  sh::rt::Image want = sh::rt::Renderer(scene, s).render();
  s.backend = "mpi";
  s.wavefront = true;
  sh::rt::RenderReport report;
  sh::rt::Image got = sh::rt::Renderer(scene, s).render(&report);
  EXPECT_EQ(got.rgb, want.rgb);
  EXPECT_EQ(got.triangle, want.triangle);
  EXPECT_GT(report.resumed, 0u);
  EXPECT_TRUE(report.refined.empty());
  ASSERT_TRUE(report.lanes.has_value());
  EXPECT_EQ(report.lanes->busy, 64u * 48u + report.resumed);
}

}  // namespace
