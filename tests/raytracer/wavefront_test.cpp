// A wavefront render: paths carried from run to run, one bounce a run, the
// live ones side by side.  It must give the image of the whole tracer on
// every backend and accelerator, keep lanes busier in the bounce loop, and
// count lane use exactly.
#include <gtest/gtest.h>

#include <sh/raytracer.hpp>
#include <sh/sh.hpp>

#include "helpers.hpp"

namespace {

sh::rt::RenderSettings settings(const std::string& backend, sh::rt::Accel accel, bool wavefront) {
  sh::rt::RenderSettings s;
  s.width = 64;
  s.height = 48;
  s.backend = backend;
  s.accel = accel;
  s.wavefront = wavefront;
  return s;
}

class Wavefront : public testing::TestWithParam<std::string> {};

TEST_P(Wavefront, GivesTheWholeTracersImageWithLanesAtLeastAsBusy) {
  // spheres: mirrors to depth 3 and shadows; magg-glass: refraction too.
  std::pair<const char*, sh::rt::Accel> cases[] = {{"spheres", sh::rt::Accel::Bvh}, {"magg-glass", sh::rt::Accel::Grid}};
  for (const auto& [name, accel] : cases) {
    sh::rt::Scene scene = sh::rt::builtin_scene(name);
    std::string what = std::string(name) + " over " + sh::rt::accel_name(accel) + " on " + GetParam();
    sh::rt::Image whole = sh::rt::Renderer(scene, settings(GetParam(), accel, false)).render();
    sh::rt::RenderReport report;
    sh::rt::Image waves = sh::rt::Renderer(scene, settings(GetParam(), accel, true)).render(&report);
    EXPECT_EQ(sh::rt::share_within(whole, waves, 0.0f), 1.0) << what;
    EXPECT_EQ(whole.distance, waves.distance) << what;
    EXPECT_EQ(whole.triangle, waves.triangle) << what;
    EXPECT_GE(report.waves, 2u) << what << ": paths bounce more than once";
    ASSERT_TRUE(report.lanes.has_value()) << what;
    const sh::rt::LaneUse& lanes = *report.lanes;
    EXPECT_EQ(lanes.busy, 64u * 48u + report.resumed) << what << ": one bounce per path and wave";
    if (lanes.lanes > 1) {
      EXPECT_GT(lanes.waves(), lanes.whole()) << what;
    } else {
      EXPECT_EQ(lanes.waves(), 1.0) << what;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Backends, Wavefront, testing::ValuesIn(rt_test::every_backend()),
                         [](const testing::TestParamInfo<std::string>& i) { return i.param; });

TEST(LaneUse, CountsBatchesAsOneKernelAndWavesOfLivePaths) {
  sh::rt::LaneUse use{4};
  // Two batches of four, one long path in each: as one kernel each batch
  // loops four times (32 lane slots); in waves the three short paths of
  // each batch are gone after the first (8, then 2 paths: 4 slots each).
  use.count({1, 1, 1, 4, 1, 1, 1, 4});
  EXPECT_EQ(use.busy, 14u);
  EXPECT_EQ(use.slots_whole, 32u);
  EXPECT_EQ(use.slots_waves, 8u + 4 + 4 + 4);
  // A ragged last batch counts its idle lanes too.
  use.count({2, 2, 2, 2, 3});
  EXPECT_EQ(use.busy, 14u + 11);
  EXPECT_EQ(use.slots_whole, 32u + 8 + 12);
  EXPECT_EQ(use.slots_waves, 20u + 8 + 8 + 4);
  EXPECT_DOUBLE_EQ(use.whole(), 25.0 / 52);
  EXPECT_DOUBLE_EQ(use.waves(), 25.0 / 40);
}

TEST(Wavefront, OverALazyOctreeIsRefusedWithAReason) {
  sh::rt::Scene scene = sh::rt::builtin_scene("spheres");
  try {
    sh::rt::Renderer r(scene, settings("interp", sh::rt::Accel::LazyOctree, true));
    FAIL() << "a wavefront over a lazy octree was accepted";
  } catch (const sh::Error& e) {
    EXPECT_NE(std::string(e.what()).find("lazy octree"), std::string::npos) << e.what();
  }
}

TEST(Wavefront, WithoutBouncesToTakeRunsTheWholeTracer) {
  sh::rt::Scene scene = sh::rt::builtin_scene("spheres");
  sh::rt::RenderSettings s = settings("interp", sh::rt::Accel::Bvh, true);
  s.reflections = 0;
  sh::rt::RenderReport report;
  sh::rt::Renderer(scene, s).render(&report);
  EXPECT_FALSE(report.lanes.has_value());
  EXPECT_EQ(report.waves, 0u);
}

}  // namespace
