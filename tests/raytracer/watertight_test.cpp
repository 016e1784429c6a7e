// Watertightness and rays leaving surfaces, on every backend: no ray aimed
// at a closed mesh's vertex or edge slips through it, at the origin, far
// from it and at tiny and huge scales; no reflection or shadow ray meets
// the surface it leaves.  (watertight_bench runs the same check on 10^6
// rays and more, with Embree beside.)
#include <gtest/gtest.h>

#include <cmath>
#include <tuple>

#include <closed_meshes.hpp>

#include "helpers.hpp"
#include <sh/sh.hpp>

namespace {

using sh::rt::Vec3;

constexpr const char* kClosedModel = "/usr/share/assimp/models/Collada/duck.dae";
constexpr std::pair<float, float> kPlacements[] = {{1, 0}, {1, 1e3f}, {1, 1e5f}, {1e-4f, 0}, {1e4f, 0}};

std::vector<float> nearest(const sh::rt::Scene& s, const watertight::AimedRays& rays, const std::string& backend,
                           const rt_test::Walked& accel, sh::MathMode math = sh::MathMode::Precise) {
  sh::rt::RenderSettings settings = accel.settings();
  sh::Options options;
  options.math = math;
  return sh::rt::Renderer(s, settings).intersect(rays.origins, rays.directions, sh::backend(backend, options)).t;
}

std::vector<watertight::ClosedMesh> closed_meshes() {
  return {watertight::uv_sphere(48), watertight::tessellated_cube(5), watertight::closed_model(kClosedModel)};
}

// Fast math too: there the cpu backend contracts a*b - c*d into an FMA,
// which an edge function in float does not survive.
class Watertight : public testing::TestWithParam<std::tuple<std::string, sh::MathMode>> {};

TEST_P(Watertight, NoRayAimedAtAVertexOrEdgeSlipsThrough) {
  auto [backend, math] = GetParam();
  for (const watertight::ClosedMesh& base : closed_meshes())
    for (auto [scale, offset] : kPlacements) {
      watertight::ClosedMesh m = watertight::transformed(base, scale, offset);
      watertight::AimedRays rays = watertight::aimed_rays(m, 600, 7);
      ASSERT_GT(rays.size(), 400u) << m.name;
      EXPECT_EQ(watertight::leaks(rays, nearest(m.scene, rays, backend, sh::rt::Accel::Grid, math)), 0u) << m.name;
    }
}

std::vector<std::string> backends() { return sh::backend_names(); }

INSTANTIATE_TEST_SUITE_P(Backends, Watertight,
                         testing::Combine(testing::ValuesIn(backends()),
                                          testing::Values(sh::MathMode::Precise, sh::MathMode::Fast)),
                         [](const testing::TestParamInfo<std::tuple<std::string, sh::MathMode>>& i) {
                           return std::get<0>(i.param) + (std::get<1>(i.param) == sh::MathMode::Fast ? "_fast" : "");
                         });

TEST(WatertightAccelerators, EveryAcceleratorHoldsTheSphere) {
  watertight::ClosedMesh m = watertight::transformed(watertight::uv_sphere(96), 1, 1e3f);
  watertight::AimedRays rays = watertight::aimed_rays(m, 20000, 3);
  for (const rt_test::Walked& accel : rt_test::every_accelerator())
    EXPECT_EQ(watertight::leaks(rays, nearest(m.scene, rays, "cpu", accel)), 0u) << accel.name();
}

TEST(WatertightMeasure, ARayThroughTheGapBetweenTwoTrianglesIsALeak) {
  // The measure itself: a crack (one triangle of the cube removed) is seen.
  watertight::ClosedMesh m = watertight::tessellated_cube(3);
  watertight::AimedRays rays = watertight::aimed_rays(m, 4000, 1);
  m.scene.mesh.positions.resize(m.scene.mesh.positions.size() - 3);
  m.scene.mesh.normals.resize(m.scene.mesh.normals.size() - 3);
  m.scene.mesh.material.pop_back();
  EXPECT_GT(watertight::leaks(rays, nearest(m.scene, rays, "cpu", sh::rt::Accel::Grid)), 0u);
}

// A convex sphere with flat normals: a ray that leaves it towards where it
// faces cannot meet it again.
sh::rt::Scene faceted_sphere(float scale, float offset, const sh::rt::Material& look) {
  sh::rt::Scene s;
  s.materials.push_back(look);
  Vec3 centre{offset, offset, offset};
  sh::rt::add_sphere(s, centre, scale, 0, 32);
  for (std::size_t f = 0; f < s.mesh.triangles(); ++f) {
    Vec3 a = s.mesh.positions[3 * f], b = s.mesh.positions[3 * f + 1], c = s.mesh.positions[3 * f + 2];
    Vec3 n = sh::rt::normalize(sh::rt::cross(b - a, c - a));
    for (int k = 0; k < 3; ++k) s.mesh.normals[3 * f + k] = n;
  }
  s.camera = {centre + Vec3{0, 0, 4 * scale}, centre, {0, 1, 0}, 40};
  s.ambient = 0;
  s.background = {0.2f, 0.4f, 0.6f};
  return s;
}

sh::rt::Image render(const sh::rt::Scene& s, const std::string& backend) {
  sh::rt::RenderSettings settings;
  settings.width = 24;
  settings.height = 24;
  settings.backend = backend;
  settings.reflections = 1;
  return sh::rt::Renderer(s, settings).render();
}

class LeavingRays : public testing::TestWithParam<std::string> {};

TEST_P(LeavingRays, ReflectionsOffAConvexMirrorSeeOnlyTheBackground) {
  sh::rt::Material mirror;
  mirror.diffuse = {0, 0, 0};
  mirror.reflectivity = 1;
  for (auto [scale, offset] : kPlacements) {
    sh::rt::Scene s = faceted_sphere(scale, offset, mirror);
    sh::rt::Image img = render(s, GetParam());
    std::size_t on_sphere = 0, wrong = 0;
    for (std::size_t p = 0; p < img.triangle.size(); ++p) {
      if (img.triangle[p] < 0) continue;
      ++on_sphere;
      for (int c = 0; c < 3; ++c) wrong += std::fabs(img.rgb[3 * p + c] - s.background[c]) > 1e-3f;
    }
    EXPECT_GT(on_sphere, 100u);
    EXPECT_EQ(wrong, 0u) << "reflections that met the mirror again, x" << scale << " +" << offset;
  }
}

TEST_P(LeavingRays, ShadowRaysDoNotShadowTheSurfaceTheyLeave) {
  sh::rt::Material matte;
  matte.diffuse = {0.8f, 0.8f, 0.8f};
  for (auto [scale, offset] : kPlacements) {
    sh::rt::Scene s = faceted_sphere(scale, offset, matte);
    Vec3 light = Vec3{offset, offset, offset} + Vec3{1, 2, 3} * (10 * scale);
    s.lights.push_back({light, {1, 1, 1}});
    sh::rt::Image img = render(s, GetParam());
    std::size_t facing = 0, dark = 0;
    for (std::size_t p = 0; p < img.triangle.size(); ++p) {
      int f = img.triangle[p];
      if (f < 0) continue;
      Vec3 a = s.mesh.positions[3 * f], b = s.mesh.positions[3 * f + 1], c = s.mesh.positions[3 * f + 2];
      Vec3 n = sh::rt::normalize(sh::rt::cross(b - a, c - a)), centre{offset, offset, offset};
      if (sh::rt::dot(n, a - centre) < 0) n = n * -1.0f;  // outwards
      if (sh::rt::dot(n, sh::rt::normalize(light - (a + b + c) * (1.0f / 3))) < 0.1f) continue;
      ++facing;
      dark += img.rgb[3 * p] < 0.01f;
    }
    EXPECT_GT(facing, 50u);
    EXPECT_EQ(dark, 0u) << "lit facets shadowed by themselves, x" << scale << " +" << offset;
  }
}

INSTANTIATE_TEST_SUITE_P(Backends, LeavingRays, testing::ValuesIn(backends()),
                         [](const testing::TestParamInfo<std::string>& i) { return i.param; });

}  // namespace
