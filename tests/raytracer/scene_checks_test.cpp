// A scene built in code, not read from a file, is held to what the tracer
// can use before anything is built or traced: every value the shading
// reads, the mesh's vectors one per corner or triangle, the camera and
// lights where rays reach them; and what writes images and builds
// accelerators refuses what would read past a buffer or overflow.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>

#include <sh/raytracer.hpp>

namespace {

using sh::rt::Vec3;

const float kNan = std::numeric_limits<float>::quiet_NaN();

// A quad, one material, one point light: a scene validate() takes.
sh::rt::Scene quad() {
  sh::rt::Scene s;
  s.name = "quad";
  s.materials.push_back({});
  s.mesh.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
  s.mesh.normals.assign(6, Vec3{0, 0, 1});
  s.mesh.material.assign(2, 0);
  s.lights.push_back({{0, 0, 5}, {1, 1, 1}});
  s.camera = {{0, 0, 4}, {0, 0, 0}, {0, 1, 0}, 45};
  return s;
}

void expect_refused(const std::function<void(sh::rt::Scene&)>& spoil, const char* says) {
  sh::rt::Scene s = quad();
  spoil(s);
  try {
    sh::rt::validate(s, "built");
    ADD_FAILURE() << "accepted: " << says;
  } catch (const sh::Error& e) {
    EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
  }
}

TEST(SceneChecks, EveryValueTheShadingReadsIsChecked) {
  sh::rt::validate(quad(), "built");
  using S = sh::rt::Scene;
  expect_refused([](S& s) { s.materials[0].diffuse.x = kNan; }, "material 0 '': diffuse must be finite");
  expect_refused([](S& s) { s.materials[0].shininess = kNan; }, "shininess nan must be finite");
  expect_refused([](S& s) { s.materials[0].shininess = -5; }, "shininess -5 must be finite and not negative");
  expect_refused([](S& s) { s.materials[0].reflectivity = 2; }, "reflectivity 2 must be in [0, 1]");
  expect_refused([](S& s) { s.materials[0].reflectivity = s.materials[0].transparency = 0.6f; },
                 "reflectivity + transparency must not exceed 1");
  expect_refused([](S& s) { s.materials[0].ior = 0; }, "ior 0 must be in [1, 4]");
  expect_refused([](S& s) { s.mesh.normals[4] = {0, 0, 0}; }, "triangle 1, vertex 1: its normal is zero or not finite");
  expect_refused([](S& s) { s.mesh.normals[0].y = kNan; }, "triangle 0, vertex 0: its normal is zero or not finite");
  expect_refused([](S& s) { s.mesh.colors.assign(6, Vec3{1, kNan, 1}); }, "its colour is negative or not finite");
  expect_refused([](S& s) { s.mesh.colors.assign(3, Vec3{1, 1, 1}); }, "mesh.colors holds 3 colours for 6 corners");
  expect_refused([](S& s) { s.mesh.normals.pop_back(); }, "mesh.normals holds 5 normals for 6 corners");
  expect_refused([](S& s) { s.mesh.material.push_back(0); }, "mesh.material holds 3 entries for 2 triangles");
  expect_refused([](S& s) { s.lights[0].color.z = kNan; }, "lights[0].color: negative or not finite");
  expect_refused([](S& s) { s.lights[0].intensity = kNan; }, "lights[0].intensity: must be finite");
  expect_refused([](S& s) { s.lights[0].position = {0, 0, 1e30f}; }, "lights[0].position: a coordinate beyond 1e19");
  expect_refused([](S& s) { s.camera.eye = {0, 0, 1e30f}; }, "camera.eye: a coordinate beyond 1e19");
  expect_refused([](S& s) { s.disk_lights.push_back({{0, 0, 3}, {0, 0, -1}, kNan, {1, 1, 1}}); },
                 "disk_lights[0].radius: must be 0 .. 1e18");
  expect_refused([](S& s) { s.disk_lights.push_back({{0, 0, 3}, {0, 0, 0}, 0.1f, {1, 1, 1}}); },
                 "disk_lights[0].normal: zero or not finite");
  expect_refused([](S& s) { s.ambient = kNan; }, "ambient: must be finite and not negative");
  expect_refused([](S& s) { s.background = {-1, 0, 0}; }, "background: negative or not finite");
}

// Kernels' tables built without the renderer check the scene too.
TEST(SceneChecks, TablesBuiltAloneCheckTheScene) {
  sh::rt::Scene s = quad();
  s.materials[0].reflectivity = 2;
  sh::rt::Grid grid = sh::rt::build_grid(s);
  EXPECT_THROW(sh::rt::SceneTables(s, grid), sh::Error);
}

// Numbers of the accelerators' settings out of range are errors, not a
// grid of one cell or the smallest reference budget.
TEST(SceneChecks, AcceleratorSettingsOutOfRange) {
  sh::rt::Scene s = quad();
  for (double density : {static_cast<double>(kNan), 1e30, -1.0, 0.0})
    EXPECT_THROW(sh::rt::build_grid(s, density), sh::Error) << density;
  sh::rt::OctreeLimits unbounded;
  unbounded.references_per_triangle = 1e300;
  EXPECT_GT(sh::rt::Octree::full(s, unbounded).reference_budget(), sh::rt::kMinReferenceBudget);
  sh::rt::RenderSettings settings;
  settings.width = 8;
  settings.height = 6;
  settings.backend = "interp";
  settings.accel = static_cast<sh::rt::Accel>(9);
  try {
    sh::rt::Renderer r(s, settings);
    ADD_FAILURE() << "accelerator 9 was taken";
  } catch (const sh::Error& e) {
    EXPECT_NE(std::string(e.what()).find("accelerator 9 is none of"), std::string::npos) << e.what();
  }
}

// An image's values must be as many as its pixels: a shorter buffer was
// read past its end (a crash, or a file of what lay beyond).
TEST(SceneChecks, ImagesWhoseValuesDoNotFillThemAreRefused) {
  std::filesystem::path dir = std::filesystem::path(testing::TempDir()) / "sh_scene_checks";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  sh::rt::Image im;
  im.width = 200;
  im.height = 200;
  im.rgb.resize(30);
  std::string png = (dir / "short.png").string();
  EXPECT_THROW(sh::rt::write_png(png, im), sh::Error);
  EXPECT_THROW(sh::rt::write_pfm((dir / "short.pfm").string(), 2000, 2000, {1.0f}), sh::Error);
  EXPECT_TRUE(std::filesystem::is_empty(dir)) << "nothing written, not even a temporary";
  im.rgb.resize(3 * 200 * 200);
  sh::rt::write_png(png, im);
  EXPECT_TRUE(std::filesystem::exists(png));
  std::filesystem::remove_all(dir);
}

}  // namespace
