// Soft shadows at the extremes: a disk of radius 0 is a point light, huge
// disks, lights touching a surface, grazing light, one sample, f32 against
// f64 far from the origin; both sample patterns on every backend.
#include <gtest/gtest.h>

#include <cmath>

#include <sh/raytracer.hpp>
#include <sh/sh.hpp>

#include "helpers.hpp"

namespace {

using namespace sh::rt;

Image render(const Scene& s, const std::string& backend, int samples = 8, SamplePattern p = SamplePattern::Random,
             sh::Precision precision = sh::Precision::F32, int w = 48, int h = 36) {
  RenderSettings settings;
  settings.width = w;
  settings.height = h;
  settings.backend = backend;
  settings.shadow_samples = samples;
  settings.pattern = p;
  settings.options.precision = precision;
  return Renderer(s, settings).render();
}

void expect_finite(const Image& img, const std::string& what) {
  for (float v : img.rgb) ASSERT_TRUE(std::isfinite(v) && v >= 0) << what << ": " << v;
}

TEST(SoftShadows, DiskOfRadiusZeroIsAPointLight) {
  Scene disk = builtin_scene("soft");
  disk.disk_lights[0].radius = 0;
  Scene point = disk;
  point.lights.push_back({disk.disk_lights[0].centre, disk.disk_lights[0].color});
  point.disk_lights.clear();
  Image a = render(disk, "cpu", 4), b = render(point, "cpu");
  EXPECT_EQ(share_within(a, b, 0.0f), 1.0);
}

TEST(SoftShadows, ExtremeDisksStayFinite) {
  Scene huge = builtin_scene("soft");
  huge.disk_lights[0].radius = 100;
  expect_finite(render(huge, "cpu"), "huge disk");
  Scene touching = builtin_scene("soft");
  touching.disk_lights[0].centre = {0.6f, 0.0f, 0.3f};  // on the floor
  touching.disk_lights[0].normal = {0, 1, 0};
  expect_finite(render(touching, "cpu"), "light touching the floor");
  Scene grazing = builtin_scene("soft");
  grazing.disk_lights[0].centre = {-30.0f, 0.01f, 0.0f};  // the floor sees it edge on
  grazing.disk_lights[0].normal = {1, 0, 0};
  Image g = render(grazing, "cpu");
  expect_finite(g, "grazing light");
}

// A floor under a ceiling with a disk light set into it: the shadow rays
// end a hair short of the light, not on the ceiling around it.
TEST(SoftShadows, ADiskSetIntoTheCeilingLightsTheFloor) {
  Scene s;
  s.materials.push_back({});
  s.ambient = 0;
  add_quad(s, {-2, 0, -2}, {0, 0, 4}, {4, 0, 0}, 0);  // floor, facing up
  add_quad(s, {-2, 1, -2}, {4, 0, 0}, {0, 0, 4}, 0);  // ceiling at y = 1
  s.disk_lights.push_back({{0.3f, 1, 0.2f}, {0, -1, 0}, 0.2f, {1, 1, 1}});
  s.camera = {{0, 0.5f, 3}, {0, 0, 0}, {0, 1, 0}, 40};
  Image img = render(s, "cpu", 16);
  std::size_t floor = 0, lit = 0;
  for (std::size_t p = 0; p < img.triangle.size(); ++p)
    if (img.triangle[p] >= 0 && img.triangle[p] < 2) ++floor, lit += img.rgb[3 * p] > 0.05f;
  ASSERT_GT(floor, 100u);
  EXPECT_EQ(lit, floor);
}

// A disk standing on the floor, half of it below: only the samples above
// the floor's plane reach it, so it lights the floor about half as much as
// a point light at its centre (nothing stands between them and the floor).
TEST(SoftShadows, SamplesBehindTheSurfaceDoNotLightIt) {
  auto floor_light = [](bool disk) {
    Scene s;
    s.materials.push_back({});
    s.ambient = 0;
    add_quad(s, {-4, 0, -4}, {0, 0, 8}, {8, 0, 0}, 0);
    Vec3 centre{1.5f, 0.05f, 0};
    if (disk)
      s.disk_lights.push_back({centre, {1, 0, 0}, 1.0f, {1, 1, 1}});
    else
      s.lights.push_back({centre, {1, 1, 1}});
    s.camera = {{-1, 3, 3}, {0, 0, 0}, {0, 1, 0}, 40};
    Image img = render(s, "cpu", 64, SamplePattern::Random, sh::Precision::F32, 32, 24);
    double sum = 0;
    for (std::size_t p = 0; p < img.triangle.size(); ++p)
      if (img.triangle[p] >= 0) sum += img.rgb[3 * p];
    return sum;
  };
  double straddling = floor_light(true), point = floor_light(false);
  ASSERT_GT(point, 0.0);
  EXPECT_LT(straddling, 0.7 * point) << "samples under the floor counted as reaching it";
  EXPECT_GT(straddling, 0.3 * point);
}

TEST(SoftShadows, OneSampleGivesAHardShadowAndMoreSamplesConverge) {
  Scene s = builtin_scene("soft");
  Image reference = render(s, "cpu", 256);
  double one = psnr(reference, render(s, "cpu", 1)), many = psnr(reference, render(s, "cpu", 64));
  EXPECT_GT(many, one) << "64 samples are closer to 256 than 1 is";
}

TEST(SoftShadows, PseudoRandomPatternIsTheCentreThenARing) {
  std::vector<float> xy = disk_samples(SamplePattern::PseudoRandom, 9, 3);
  EXPECT_EQ(xy[0], 0.f);
  EXPECT_EQ(xy[1], 0.f);
  for (int i = 1; i < 9; ++i) {
    float r = std::hypot(xy[2 * i], xy[2 * i + 1]);
    EXPECT_GE(r, 0.3f - 1e-6f);
    EXPECT_LE(r, 1.0f + 1e-6f);
    float theta = 2 * 3.14159265f * static_cast<float>(i) / 8;  // evenly spaced angles
    EXPECT_NEAR(xy[2 * i] / r, std::cos(theta), 1e-5);
    EXPECT_NEAR(xy[2 * i + 1] / r, std::sin(theta), 1e-5);
  }
  std::vector<float> random = disk_samples(SamplePattern::Random, 64, 5);
  for (int i = 0; i < 64; ++i) EXPECT_LE(std::hypot(random[2 * i], random[2 * i + 1]), 1.0f);
  EXPECT_THROW(disk_samples(SamplePattern::Random, 0, 1), sh::Error);
}

TEST(SoftShadows, F32AgainstF64FarFromTheOrigin) {
  Scene s = builtin_scene("soft");
  Vec3 offset{1e4f, 1e4f, 1e4f};
  for (Vec3& p : s.mesh.positions) p = p + offset;
  for (DiskLight& d : s.disk_lights) d.centre = d.centre + offset;
  s.camera.eye = s.camera.eye + offset;
  s.camera.look_at = s.camera.look_at + offset;
  double db = psnr(render(s, "cpu", 16, SamplePattern::Random, sh::Precision::F64),
                   render(s, "cpu", 16, SamplePattern::Random, sh::Precision::F32));
  RecordProperty("psnr_f32_vs_f64_at_1e4", static_cast<int>(db));
  EXPECT_GT(db, 30.0) << "f32 at 1e4 from the origin";
}

class SoftShadowBackends : public testing::TestWithParam<std::string> {};

TEST_P(SoftShadowBackends, BothPatternsAgreeWithInterp) {
  for (SamplePattern p : {SamplePattern::Random, SamplePattern::PseudoRandom}) {
    Scene s = builtin_scene("soft2");
    Image reference = render(s, "interp", 8, p), image = render(s, GetParam(), 8, p);
    EXPECT_GE(share_within(reference, image, 1.0f / 255), 0.999) << pattern_name(p) << " on " << GetParam();
  }
}

INSTANTIATE_TEST_SUITE_P(Backends, SoftShadowBackends, testing::ValuesIn(rt_test::backends_beside_interp()),
                         [](const testing::TestParamInfo<std::string>& i) { return i.param; });

}  // namespace
