// Bidirectional tracing: the light pass conserves energy in a closed box,
// a mirror sends light where geometry says, glass refracts by Snell's law
// and mirrors past the critical angle, and the images agree across
// backends.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sh/raytracer.hpp>
#include <sh/sh.hpp>

namespace {

using sh::rt::Vec3;

// The solid angle of a triangle from p, in double (Van Oosterom-Strackee).
double solid_angle(Vec3 p, Vec3 a, Vec3 b, Vec3 c) {
  auto d = [](Vec3 x, Vec3 y) { return std::array<double, 3>{double(x.x) - y.x, double(x.y) - y.y, double(x.z) - y.z}; };
  auto ra = d(a, p), rb = d(b, p), rc = d(c, p);
  auto dot = [](auto x, auto y) { return x[0] * y[0] + x[1] * y[1] + x[2] * y[2]; };
  auto len = [&](auto x) { return std::sqrt(dot(x, x)); };
  std::array<double, 3> bc{rb[1] * rc[2] - rb[2] * rc[1], rb[2] * rc[0] - rb[0] * rc[2], rb[0] * rc[1] - rb[1] * rc[0]};
  double num = std::fabs(dot(ra, bc));
  double den = len(ra) * len(rb) * len(rc) + dot(ra, rb) * len(rc) + dot(ra, rc) * len(rb) + dot(rb, rc) * len(ra);
  return 2 * std::atan2(num, den);
}

sh::rt::Scene closed_box() {
  sh::rt::Scene s;
  s.name = "closed box";
  sh::rt::Material wall;
  s.materials.push_back(wall);
  sh::rt::add_box(s, {-1, -1, -1}, {1, 1.5f, 2}, 0);
  s.lights.push_back({{0.2f, 0.1f, 0.3f}, {1, 0.5f, 0.25f}, 3.0f});
  return s;
}

// The side of triangle t (bidirectional.hpp) that faces the way `up` points.
int side_facing(const sh::rt::Scene& s, std::size_t t, Vec3 up) {
  const std::vector<Vec3>& p = s.mesh.positions;
  return dot(cross(p[3 * t + 1] - p[3 * t], p[3 * t + 2] - p[3 * t]), up) > 0 ? 0 : 1;
}

std::vector<float> light_pass(const sh::rt::Scene& scene, const sh::BackendChoice& choice, sh::rt::LightPassSettings lp) {
  sh::rt::Grid grid = sh::rt::build_grid(scene, 2.0);
  sh::rt::SceneTables tables(scene, grid);
  sh::rt::LightPass pass(scene, tables, lp);
  return pass.run(choice);
}

// Elements whose slots a kernel could not number are refused by name,
// before any table is sized: 2^17 triangles of 64 x 64 elements, on two
// sides, are 2^31.
TEST(LightPass, TooManyElementSlotsAreRefusedByName) {
  sh::rt::Scene many;
  many.materials.push_back({});
  for (int t = 0; t < (1 << 17); ++t) {
    float x = static_cast<float>(t % 512), y = static_cast<float>(t / 512);
    many.mesh.positions.insert(many.mesh.positions.end(), {{x, y, 0}, {x + 1, y, 0}, {x, y + 1, 0}});
  }
  many.mesh.normals.assign(many.mesh.positions.size(), Vec3{0, 0, 1});
  many.mesh.material.assign(many.mesh.triangles(), 0);
  many.lights.push_back({{0, 0, 5}, {1, 1, 1}});
  sh::rt::Grid grid = sh::rt::build_grid(many, 0.05);
  sh::rt::SceneTables tables(many, grid);
  sh::rt::LightPassSettings lp;
  lp.subdivision = 64;
  try {
    sh::rt::LightPass pass(many, tables, lp);
    FAIL() << "2^31 element slots were accepted";
  } catch (const sh::Error& e) {
    EXPECT_NE(std::string(e.what()).find("131072 triangles of 64 x 64 elements take 2147483648 slots"), std::string::npos)
        << e.what();
  }
}

class LightPassOn : public testing::TestWithParam<std::string> {};

// Every ray reaches its element (nothing else is inside the box), so each
// element receives I s_e, on the side that faces the light, and the box
// I * 4 pi, whatever n: no sampling error, only the solid angle's and float
// sums' rounding.
// A scene without point lights (disk lights only, or none) has nothing to
// shoot from: the pass runs and leaves every element dark (its table of
// emitters was one element short of what it was given).
TEST_P(LightPassOn, WithoutPointLightsLeavesEveryElementDark) {
  sh::rt::Scene box = closed_box();
  box.lights.clear();
  sh::rt::LightPassSettings lp;
  lp.subdivision = 2;
  lp.samples = 2;
  std::vector<float> energy = light_pass(box, sh::backend(GetParam()), lp);
  ASSERT_FALSE(energy.empty());
  EXPECT_EQ(*std::max_element(energy.begin(), energy.end()), 0.0f);
}

TEST_P(LightPassOn, ConservesEnergyInAClosedDiffuseBox) {
  sh::rt::Scene box = closed_box();
  sh::rt::LightPassSettings lp;
  lp.subdivision = 3;
  lp.samples = 8;
  std::vector<float> energy = light_pass(box, sh::backend(GetParam()), lp);
  int k = lp.subdivision;
  const sh::rt::PointLight& light = box.lights[0];
  double total = 0, expected_total = 0;
  for (std::size_t t = 0; t < box.mesh.triangles(); ++t) {
    Vec3 v0 = box.mesh.positions[3 * t], e1 = box.mesh.positions[3 * t + 1] - v0, e2 = box.mesh.positions[3 * t + 2] - v0;
    auto at = [&](int i, int j) { return v0 + e1 * (float(i) / k) + e2 * (float(j) / k); };
    for (int j = 0; j < k; ++j)
      for (int i = 0; i + j < k; ++i)
        for (int down = 0; down < (i + j < k - 1 ? 2 : 1); ++down) {
          double s = down ? solid_angle(light.position, at(i + 1, j + 1), at(i, j + 1), at(i + 1, j))
                          : solid_angle(light.position, at(i, j), at(i + 1, j), at(i, j + 1));
          int lit_side = side_facing(box, t, light.position - v0);
          std::size_t element = 2 * (j * k + i) + down;
          std::size_t slot = sh::rt::side_slot(t, lit_side, sh::rt::element_slots(k)) + element;
          std::size_t dark = sh::rt::side_slot(t, 1 - lit_side, sh::rt::element_slots(k)) + element;
          double got = energy[3 * slot];
          EXPECT_NEAR(got, 3.0 * s, 1e-4 * 3.0 * s + 1e-7) << "triangle " << t << " element " << i << "," << j << "," << down;
          EXPECT_NEAR(energy[3 * slot + 1], 0.5 * got, 1e-6 * got + 1e-9);
          EXPECT_EQ(energy[3 * dark], 0.0f) << "triangle " << t << " element " << element << ": the side away from the light";
          total += got;
          expected_total += 3.0 * s;
        }
  }
  EXPECT_NEAR(expected_total, 3.0 * 4 * std::numbers::pi, 1e-5);
  EXPECT_NEAR(total, 3.0 * 4 * std::numbers::pi, 3e-4 * total) << "light power times the solid angle around it";
}

// A glass slab (transparency 1, no Fresnel loss) between a light and a
// floor takes nothing away: what would reach the floor goes through the
// slab, refracted twice, and reaches it still (the slab's footprint is well
// inside the floor; a ray bent out past its edge is rare).
TEST_P(LightPassOn, GlassPassesTheLightOnToTheFloor) {
  auto floor_total = [&](bool slab) {
    sh::rt::Scene s;
    s.materials.push_back({});
    sh::rt::Material glass;
    glass.transparency = 1;
    glass.ior = 1.5f;
    s.materials.push_back(glass);
    sh::rt::add_tiled_quad(s, {-2, 0, -2}, {0, 0, 4}, {4, 0, 0}, 8, 0);
    if (slab) sh::rt::add_box(s, {-0.5f, 0.5f, -0.5f}, {0.5f, 0.7f, 0.5f}, 1);
    s.lights.push_back({{0.1f, 2, 0.05f}, {1, 1, 1}, 1});
    sh::rt::LightPassSettings lp;
    lp.subdivision = 4;
    lp.samples = 16;
    lp.depth = 6;
    std::vector<float> e = light_pass(s, sh::backend(GetParam()), lp);
    double floor = 0;
    for (std::size_t slot = 0; slot < sh::rt::side_slot(2 * 8 * 8, 0, sh::rt::element_slots(4)); ++slot) floor += e[3 * slot];
    return floor;
  };
  double without = floor_total(false), with = floor_total(true);
  ASSERT_GT(without, 0.0);
  EXPECT_NEAR(with, without, 0.01 * without);
}

INSTANTIATE_TEST_SUITE_P(Backends, LightPassOn, testing::ValuesIn(sh::backend_names()),
                         [](const auto& info) { return info.param; });

// A vertical mirror at x = 1 (y in [0.2, 1.2], z in [-0.5, 0.5]) facing a
// light at (0, 2, 0): the floor points it lights are those whose line to
// the light's image (2, 2, 0) crosses the mirror.  The mirror's light is
// the difference from a run with the mirror black.
TEST(LightPass, AMirrorSendsLightWhereGeometrySays) {
  auto floor_energy = [](bool mirror) {
    sh::rt::Scene s;
    s.materials.push_back({});
    sh::rt::Material m;
    m.diffuse = {0, 0, 0};
    m.reflectivity = mirror ? 1.0f : 0.0f;
    s.materials.push_back(m);
    sh::rt::add_tiled_quad(s, {-3, 0, -2}, {0, 0, 4}, {4, 0, 0}, 32, 0);
    sh::rt::add_tiled_quad(s, {1, 0.2f, -0.5f}, {0, 1, 0}, {0, 0, 1}, 16, 1);
    s.lights.push_back({{0, 2, 0}, {1, 1, 1}, 1});
    sh::rt::LightPassSettings lp;
    lp.subdivision = 1;
    lp.samples = 64;
    lp.depth = 1;
    sh::Options one_thread;
    one_thread.threads = 1;
    return std::pair{light_pass(s, sh::backend("cpu", one_thread), lp), s};
  };
  auto [plain, scene] = floor_energy(false);
  auto [mirrored, ignored] = floor_energy(true);
  auto lit = [](Vec3 p) {
    double s = 1.0 / (2.0 - p.x);  // where the line from (2, 2, 0) to p meets x = 1
    double y = 2 - 2 * s, z = s * p.z;
    return p.x < 1 && y >= 0.2 && y <= 1.2 && std::fabs(z) <= 0.5;
  };
  std::size_t inside = 0, outside = 0;
  for (std::size_t t = 0; t < 2 * 32 * 32; ++t) {
    int corners_lit = 0;
    for (int c = 0; c < 3; ++c) corners_lit += lit(scene.mesh.positions[3 * t + c]);
    std::size_t top = 3 * sh::rt::side_slot(t, side_facing(scene, t, {0, 1, 0}), sh::rt::element_slots(1));
    double extra = mirrored[top] - plain[top];
    if (corners_lit == 3) {
      ++inside;
      EXPECT_GT(extra, 1e-4 * plain[top]) << "floor triangle " << t << " lies in the mirror's light";
    } else if (corners_lit == 0) {
      ++outside;
      EXPECT_NEAR(extra, 0.0, 1e-6 * (plain[top] + 1e-6)) << "floor triangle " << t << " lies outside the mirror's light";
    }
  }
  EXPECT_GT(inside, 20u);
  EXPECT_GT(outside, 1000u);
}

// A single-layer floor lit from above and seen from below: the light pass
// leaves its energy on the side the light's rays arrive at, so the view
// from below finds only the ambient light there, and the view from above
// finds the light.
TEST(Bidirectional, ASingleLayerSurfaceIsLitOnlyOnTheLightsSide) {
  sh::rt::Scene s;
  sh::rt::Material floor;
  floor.diffuse = {1, 1, 1};
  s.materials.push_back(floor);
  s.ambient = 0;
  s.background = {0, 0, 0};
  sh::rt::add_tiled_quad(s, {-2, 0, -2}, {0, 0, 4}, {4, 0, 0}, 4, 0);
  s.lights.push_back({{0.1f, 1, 0.05f}, {1, 1, 1}, 1});
  auto mean_red = [&](float eye_y) {
    s.camera.eye = {0, eye_y, 0.01f};
    s.camera.look_at = {0, 0, 0};
    s.camera.up = {0, 0, 1};
    sh::rt::RenderSettings settings;
    settings.width = settings.height = 16;
    settings.reflections = 0;
    settings.bidirectional = true;
    settings.light_pass.samples = 4;
    settings.backend = "cpu";
    sh::rt::Image image = sh::rt::Renderer(s, settings).render();
    double sum = 0;
    for (std::size_t p = 0; p < image.rgb.size(); p += 3) sum += image.rgb[p];
    return sum / static_cast<double>(image.rgb.size() / 3);
  };
  EXPECT_GT(mean_red(2), 0.05) << "seen from the light's side";
  EXPECT_EQ(mean_red(-2), 0.0) << "seen from below, where no light arrives";
}

class Refraction : public testing::TestWithParam<std::string> {};

// Into glass (eta 1.5, the index entered over the index left, as in Sh's
// refract) at 0 and 30 degrees, and out of it (eta 1/1.5) at 30 degrees
// (refracted) and 60 degrees (past the critical angle of 41.8 degrees:
// mirrored).
TEST_P(Refraction, SnellsLawAndTotalInternalReflection) {
  sh::Program p = SH_BEGIN_PROGRAM("refraction") {
    sh::InputVector3f d;
    sh::InputAttrib1f eta;
    sh::OutputVector3f out;
    sh::OutputAttrib1f mirrored;
    sh::Attrib1f m;
    out = sh::rt::refract_or_mirror(d, sh::Normal3f(0.0f, 1.0f, 0.0f), eta, m);
    mirrored = m;
  } SH_END;
  const double deg = std::numbers::pi / 180;
  std::vector<double> angles{0, 30, 30, 60}, etas{1.5, 1.5, 1 / 1.5, 1 / 1.5};
  std::vector<float> ds, es;
  for (std::size_t i = 0; i < angles.size(); ++i) {
    ds.insert(ds.end(), {float(std::sin(angles[i] * deg)), float(-std::cos(angles[i] * deg)), 0.f});
    es.push_back(float(etas[i]));
  }
  sh::Channel<sh::Vector3f> d(ds), out;
  sh::Channel<sh::Attrib1f> eta(es), mirrored;
  sh::run(p, {d, eta}, {out, mirrored}, sh::backend(GetParam()));
  EXPECT_NEAR(out[0], 0.0f, 1e-7);
  EXPECT_NEAR(out[1], -1.0f, 1e-7) << "normal incidence goes straight on";
  EXPECT_EQ(mirrored[0], 0.0f);
  for (std::size_t i = 1; i < 3; ++i) {
    double sin_t = std::sin(angles[i] * deg) / etas[i];
    EXPECT_NEAR(out[3 * i], sin_t, 1e-6) << "Snell's law at " << angles[i] << " degrees, eta " << etas[i];
    EXPECT_NEAR(out[3 * i + 1], -std::sqrt(1 - sin_t * sin_t), 1e-6);
    EXPECT_EQ(mirrored[i], 0.0f);
  }
  EXPECT_EQ(mirrored[3], 1.0f) << "past the critical angle";
  EXPECT_NEAR(out[9], std::sin(60 * deg), 1e-6);
  EXPECT_NEAR(out[10], std::cos(60 * deg), 1e-6) << "mirrored back up";
}

INSTANTIATE_TEST_SUITE_P(Backends, Refraction, testing::ValuesIn(sh::backend_names()),
                         [](const auto& info) { return info.param; });

// The glass scene's caustic and image on every backend against cpu's: the
// light pass's sums differ only in the order of their additions.
TEST(Bidirectional, ImagesAgreeAcrossBackendsAndShowTheCaustic) {
  sh::rt::RenderSettings settings;
  settings.width = 40;
  settings.height = 40;
  settings.reflections = 3;
  settings.bidirectional = true;
  settings.light_pass.samples = 4;
  sh::rt::Scene scene = sh::rt::builtin_scene("magg-glass");
  settings.backend = "cpu";
  sh::rt::Renderer reference(scene, settings);
  sh::rt::Image want = reference.render();
  // The caustic: floor elements under the sphere hold more light than
  // the floor's mean (they would be in shadow without the glass).
  const sh::rt::ElementLight& light = *reference.element_light();
  const int k = light.subdivision;
  double under = 0, all = 0;
  std::size_t n_under = 0, n_all = 0;
  for (std::size_t t = 0; t < 2 * 40 * 40; ++t) {
    Vec3 c = (scene.mesh.positions[3 * t] + scene.mesh.positions[3 * t + 1] + scene.mesh.positions[3 * t + 2]) * (1.f / 3);
    for (int e = 0; e < sh::rt::element_slots(k); ++e) {
      float l = light.luminance[3 * (sh::rt::side_slot(t, side_facing(scene, t, {0, 1, 0}), sh::rt::element_slots(k)) + e)];
      all += l, ++n_all;
      if (std::hypot(c.x + 0.1f, c.z + 0.075f) < 0.1f) under += l, ++n_under;
    }
  }
  ASSERT_GT(n_under, 0u);
  EXPECT_GT(under / n_under, 2 * all / n_all) << "a caustic under the glass sphere";
  for (const std::string& b : sh::backend_names()) {
    if (b == "cpu") continue;
    settings.backend = b;
    sh::rt::Renderer other(scene, settings);
    sh::rt::Image got = other.render();
    EXPECT_GE(sh::rt::share_within(want, got, 2.0f / 255), 0.995) << b;
    EXPECT_GT(sh::rt::psnr(want, got), 45.0) << b;
  }
}

}  // namespace
