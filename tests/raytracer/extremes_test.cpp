// Numerical extremes of the tracer, each checked against Embree or a
// closed-form answer: axis-parallel rays, rays along cell faces, edges and
// corners of the grid, rays through a closed mesh's edges and vertices,
// grazing rays, rays leaving a surface, scenes far from the origin and very
// small or large, degenerate triangles, the camera inside and outside the
// grid.  Every check runs each accelerator: grid, octree, lazy octree and
// BVH.
#include <gtest/gtest.h>

#include <cmath>

#include "helpers.hpp"

namespace {

using sh::rt::Vec3;

sh::rt::Scene closed_box_scene() {
  sh::rt::Scene s;
  s.name = "closed box";
  s.materials.push_back({});
  sh::rt::add_box(s, {-1, -1, -1}, {1, 1, 1}, 0);
  sh::rt::add_sphere(s, {3, 0, 0}, 1, 0, 16);
  s.lights.push_back({{0, 5, 5}, {1, 1, 1}});
  return s;
}

// Returns the agreement of the accelerator that agreed on fewest rays.
rt_test::Agreement check(const sh::rt::Scene& s, const rt_test::Rays& rays) {
  rt_test::Agreement least;
  least.agree = SIZE_MAX;
  for (const rt_test::Walked& accel : rt_test::every_accelerator()) {
    rt_test::Hits hits = rt_test::trace(s, rays, "cpu", accel);
    rt_test::Agreement a = rt_test::compare_with_embree(s, rays, hits);
    std::string detail;
    for (const std::string& d : a.disagreements) detail += "\n  " + d;
    EXPECT_EQ(a.unexplained(), 0u) << s.name << ", " << accel.name() << detail;
    if (a.agree < least.agree) least = a;
  }
  return least;
}

TEST(Extremes, AxisParallelRays) {
  sh::rt::Scene s = closed_box_scene();
  rt_test::Rays rays;
  for (float y = -1.5f; y <= 1.5f; y += 0.125f)
    for (float z = -1.5f; z <= 1.5f; z += 0.125f) {
      rays.add({-5, y, z}, {1, 0, 0});
      rays.add({y, 5, z}, {0, -1, 0});
      rays.add({y, z, 5}, {0, 0, -1});
      rays.add({y, z, -5}, {0, 0, 1});
    }
  check(s, rays);
  rt_test::Hits hits = rt_test::trace(s, rays);
  for (float t : hits.t) EXPECT_FALSE(std::isnan(t));
}

TEST(Extremes, RaysAlongCellFacesEdgesAndCorners) {
  sh::rt::Scene s = closed_box_scene();
  sh::rt::Grid g = sh::rt::build_grid(s);
  rt_test::Rays rays;
  // Rays lying in cell faces, along cell edges, and through cell corners.
  for (int i = 0; i <= g.dims[0]; ++i)
    for (int j = 0; j <= g.dims[1]; j += 2) {
      float x = g.lo.x + i * g.cell.x, y = g.lo.y + j * g.cell.y;
      rays.add({x, y, -10}, {0, 0, 1});
      rays.add({x, -10, g.lo.z + j * g.cell.z}, {0, 1, 0});
      rays.add({g.lo.x - 1, g.lo.y - 1, g.lo.z - 1} , sh::rt::normalize(Vec3{x, y, g.lo.z + i * g.cell.z} - Vec3{g.lo.x - 1, g.lo.y - 1, g.lo.z - 1}));
    }
  check(s, rays);
}

TEST(Extremes, RaysAlongOctreeNodeFacesEdgesAndCorners) {
  sh::rt::Scene s = closed_box_scene();
  sh::rt::Octree tree = sh::rt::Octree::lazy(s, {});
  Vec3 lo = tree.bounds().lo, side = tree.bounds().hi - tree.bounds().lo;
  rt_test::Rays rays;
  // The planes between nodes of the first four levels.
  for (int i = 0; i <= 16; ++i)
    for (int j = 0; j <= 16; ++j) {
      float x = lo.x + side.x * i / 16, y = lo.y + side.y * j / 16, z = lo.z + side.z * j / 16;
      rays.add({x, y, lo.z - 1}, {0, 0, 1});
      rays.add({x, lo.y - 1, z}, {0, 1, 0});
      Vec3 corner = lo - Vec3{1, 1, 1};
      rays.add(corner, sh::rt::normalize(Vec3{x, y, lo.z + side.z * i / 16} - corner));
    }
  check(s, rays);
}

TEST(Extremes, ClosedMeshIsWatertightAtEdgesAndVertices) {
  // Rays aimed exactly at every vertex and edge midpoint of a closed
  // sphere mesh, from outside: none may pass through.
  sh::rt::Scene s;
  s.name = "closed sphere";
  s.materials.push_back({});
  sh::rt::add_sphere(s, {0.3f, -0.2f, 0.1f}, 1.3f, 0, 20);
  rt_test::Rays rays;
  Vec3 centre{0.3f, -0.2f, 0.1f};
  for (std::size_t t = 0; t < s.mesh.triangles(); ++t)
    for (int k = 0; k < 3; ++k) {
      Vec3 a = s.mesh.positions[3 * t + k], b = s.mesh.positions[3 * t + (k + 1) % 3];
      for (Vec3 target : {a, (a + b) * 0.5f}) {
        Vec3 from = centre + sh::rt::normalize(target - centre) * 5.0f + Vec3{0.01f, 0.02f, -0.015f};
        rays.add(from, sh::rt::normalize(target - from));
      }
    }
  for (const rt_test::Walked& accel : rt_test::every_accelerator()) {
    rt_test::Hits hits = rt_test::trace(s, rays, "cpu", accel);
    std::size_t leaks = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) leaks += hits.t[i] < 0;
    EXPECT_EQ(leaks, 0u) << "rays passed through the closed mesh (" << accel.name() << ")";
  }
  // And from inside, towards the same points: every one hits the shell.
  rt_test::Rays inside;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    Vec3 target = rays.origin(i) + rays.direction(i) * 5.0f;
    inside.add(centre, sh::rt::normalize(target - centre));
  }
  rt_test::Hits in_hits = rt_test::trace(s, inside);
  for (std::size_t i = 0; i < inside.size(); ++i) EXPECT_GE(in_hits.t[i], 0.f) << "inside ray " << i << " escaped";
}

TEST(Extremes, GrazingRays) {
  sh::rt::Scene s = closed_box_scene();
  rt_test::Rays rays;
  for (int i = 0; i < 2000; ++i) {
    float angle = 1e-6f * static_cast<float>(i + 1);  // nearly parallel to the top face y = 1
    rays.add({-3, 1 + 1e-4f * (i % 7), -0.5f + 0.0005f * i}, sh::rt::normalize({1, -angle * (i % 3), 0}));
  }
  check(s, rays);
}

TEST(Extremes, ScenesFarAwaySmallAndLarge) {
  for (auto [scale, offset] : {std::pair{1.0f, 1e5f}, std::pair{1e-4f, 0.0f}, std::pair{1e4f, 0.0f}}) {
    sh::rt::Scene s = sh::rt::builtin_scene("spheres");
    for (Vec3& p : s.mesh.positions) p = p * scale + Vec3{offset, offset, offset};
    s.name = "spheres x" + std::to_string(scale) + " +" + std::to_string(offset);
    rt_test::Rays rays = rt_test::random_rays(s, 20000, 11);
    rt_test::Agreement a = check(s, rays);
    EXPECT_GT(a.agree, 2000u) << s.name;
  }
}

// Every accelerator hits what Embree hits, ray for ray (where check()'s
// allowance for rays starting on a surface would excuse a near miss).
void expect_embree_hits(const sh::rt::Scene& s, const rt_test::Rays& rays) {
  oracle::Embree embree(s);
  std::size_t theirs = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) theirs += embree.intersect(rays.origin(i), rays.direction(i)).t >= 0;
  ASSERT_GT(theirs, rays.size() / 4) << s.name;
  for (const rt_test::Walked& accel : rt_test::every_accelerator()) {
    rt_test::Hits hits = rt_test::trace(s, rays, "cpu", accel);
    std::size_t ours = 0;
    for (float t : hits.t) ours += t >= 0;
    EXPECT_EQ(ours, theirs) << s.name << ", " << accel.name();
  }
  check(s, rays);
}

// Rays aimed at a unit sphere from far along them (a narrow field of view):
// the float bound on the distance's error grows as the square of the
// distance over the triangle's size and once turned every such hit away.
TEST(Extremes, SmallObjectsFarAlongTheRay) {
  for (float far : {1e4f, 1e5f}) {
    sh::rt::Scene s;
    s.name = "unit sphere from " + std::to_string(far);
    s.materials.push_back({});
    sh::rt::add_sphere(s, {0, 0, 0}, 1, 0, 64);
    rt_test::Rays rays;
    for (float x = -0.95f; x <= 0.95f; x += 0.1f)
      for (float y = -0.95f; y <= 0.95f; y += 0.1f) rays.add({0.3f, 0.2f, far}, sh::rt::normalize(Vec3{x - 0.3f, y - 0.2f, -far}));
    expect_embree_hits(s, rays);
  }
}

// A ground of four quads a million wide meeting under the camera: rays
// hit them a few units away, where their corners lie a million away.
TEST(Extremes, LargeTrianglesNearTheOrigin) {
  sh::rt::Scene s;
  s.name = "ground 1e6 wide";
  s.materials.push_back({});
  for (Vec3 corner : {Vec3{-1e6f, 0, -1e6f}, Vec3{0, 0, 0}, Vec3{-1e6f, 0, 0}, Vec3{0, 0, -1e6f}})
    sh::rt::add_quad(s, corner, {0, 0, 1e6f}, {1e6f, 0, 0}, 0);
  rt_test::Rays rays;
  for (float x = -2; x <= 2; x += 0.25f)
    for (float z = -2; z <= 2; z += 0.25f) rays.add({0, 1, 5}, sh::rt::normalize(Vec3{x, -1, z - 5}));
  expect_embree_hits(s, rays);
}

// The nearest hit along o + t d by every triangle in double (Moller and
// Trumbore): t, or -1 where none, or NaN where the ray passes within
// `margin` (barycentric) of an edge of the triangle it hits or misses
// first, where float tracers may differ.
double nearest_in_double(const sh::rt::Scene& s, Vec3 o, Vec3 d, double margin) {
  using D3 = std::array<double, 3>;
  auto of = [](Vec3 v) { return D3{v.x, v.y, v.z}; };
  auto sub = [](D3 a, D3 b) { return D3{a[0] - b[0], a[1] - b[1], a[2] - b[2]}; };
  auto cross = [](D3 a, D3 b) { return D3{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]}; };
  auto dot = [](D3 a, D3 b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; };
  double best = -1;
  bool near_edge = false;
  for (std::size_t t = 0; t < s.mesh.triangles(); ++t) {
    D3 v0 = of(s.mesh.positions[3 * t]), e1 = sub(of(s.mesh.positions[3 * t + 1]), v0),
       e2 = sub(of(s.mesh.positions[3 * t + 2]), v0);
    D3 p = cross(of(d), e2), q = cross(sub(of(o), v0), e1);
    double det = dot(e1, p);
    if (det == 0) continue;
    double u = dot(sub(of(o), v0), p) / det, v = dot(of(d), q) / det, at = dot(e2, q) / det;
    double inside = std::min({u, v, 1 - u - v});
    if (at <= 0 || inside < -margin || (best >= 0 && at > best)) continue;
    near_edge = inside < margin;
    best = at;
  }
  return near_edge ? std::nan("") : best;
}

// Every accelerator's hit distances against the double-precision answer,
// for the rays that pass no edge within 1e-4 (barycentric).
void expect_double_precision_hits(const sh::rt::Scene& s, const rt_test::Rays& rays) {
  for (const rt_test::Walked& accel : rt_test::every_accelerator()) {
    rt_test::Hits hits = rt_test::trace(s, rays, "cpu", accel);
    std::size_t compared = 0, hit = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
      double want = nearest_in_double(s, rays.origin(i), rays.direction(i), 1e-4);
      if (std::isnan(want)) continue;
      ++compared;
      hit += want >= 0;
      if (want < 0)
        EXPECT_LT(hits.t[i], 0.0f) << s.name << ", " << accel.name() << ", ray " << i;
      else
        EXPECT_NEAR(hits.t[i], want, 1e-5 * want) << s.name << ", " << accel.name() << ", ray " << i;
    }
    EXPECT_GT(compared, rays.size() / 2);
    EXPECT_GT(hit, compared / 4);
  }
}

// Spheres 1e13 across: an edge function times a coordinate passes the
// float range, so the distance takes the barycentrics first.  Embree
// itself misses some near triangles at this size (a ray that meets one
// well inside its edges, by exact arithmetic, it reports on a farther
// one), so the answer here is the double-precision one.
TEST(Extremes, CoordinatesNearTheLoadersLimit) {
  sh::rt::Scene s;
  s.name = "spheres 1e13 across";
  s.materials.push_back({});
  sh::rt::add_sphere(s, {0, 0, 0}, 1e13f, 0, 8);
  sh::rt::add_sphere(s, {0, -3e13f, 0}, 1.5e13f, 0, 8);
  rt_test::Rays rays;
  for (float x = -0.9f; x <= 0.9f; x += 0.1f)
    for (float y = -0.9f; y <= 0.9f; y += 0.1f) rays.add({0, 0, 4e13f}, sh::rt::normalize(Vec3{x, y, -3}));
  expect_double_precision_hits(s, rays);
}

// Spheres 2e11 across seen from 1e17 away: the float bound cannot place
// these hits, and the plane's products (edges squared times the distance)
// passed float's range until they were taken at unit size.
TEST(Extremes, SmallObjectsFarAlongTheRayNearTheLoadersLimit) {
  sh::rt::Scene s;
  s.name = "sphere 2e11 across from 1e17";
  s.materials.push_back({});
  sh::rt::add_sphere(s, {0, 0, 0}, 1e11f, 0, 8);
  rt_test::Rays rays;
  for (float x = -0.9f; x <= 0.9f; x += 0.1f)
    for (float y = -0.9f; y <= 0.9f; y += 0.1f)
      rays.add({0, 0, 1e17f}, sh::rt::normalize(Vec3{x * 1e11f, y * 1e11f, -1e17f}));
  expect_double_precision_hits(s, rays);
}

// Grid cells 1e11 wide and a ray whose y component is 1e-28: the step
// along y is infinite, and stepping along x once made it NaN, after which
// the walk never left its cell (the backend's loop cap ended the render).
TEST(Extremes, GridCellsFarWiderThanADirectionComponent) {
  sh::rt::Scene s;
  s.name = "boxes 1e11 wide";
  s.materials.push_back({});
  sh::rt::add_box(s, {0, 5e11f, 5e11f}, {1e11f, 6e11f, 6e11f}, 0);
  sh::rt::add_box(s, {9e11f, -1e11f, -1e11f}, {1e12f, 1e11f, 1e11f}, 0);
  sh::rt::add_box(s, {9e11f, -6e11f, -6e11f}, {1e12f, -5e11f, -5e11f}, 0);
  rt_test::Rays rays;
  for (float z : {0.0f, 1e-3f, -1e-3f, 1e-2f}) rays.add({-1e11f, 0, 0}, sh::rt::normalize(Vec3{1, 1e-28f, z}));
  rt_test::Hits hits = rt_test::trace(s, rays, "cpu", sh::rt::Accel::Grid);
  for (std::size_t i = 0; i < rays.size(); ++i) EXPECT_GT(hits.t[i], 0.0f) << "ray " << i << " meets the box at x 9e11";
  check(s, rays);
}

// The scene's own vectors at the ends of the float range: a quad 1e10
// wide got zero normals (the squared length overflowed) and rendered
// unlit; one 1e-12 wide was refused as spanning no area.
TEST(Extremes, SceneNormalsOfHugeAndTinyQuads) {
  for (float size : {2e10f, 1e18f, 2e-12f}) {
    sh::rt::Scene s;
    s.materials.push_back({});
    sh::rt::add_quad(s, {-size / 2, 0, -size / 2}, {0, 0, size}, {size, 0, 0}, 0);
    ASSERT_EQ(s.mesh.triangles(), 2u) << size;
    for (Vec3 n : s.mesh.normals) {
      EXPECT_NEAR(n.y, 1.0f, 1e-6f) << "quad " << size << " wide";
      EXPECT_NEAR(sh::rt::length(n), 1.0f, 1e-6f);
    }
  }
  EXPECT_NEAR(sh::rt::normalize(Vec3{3e-30f, 4e-30f, 0}).y, 0.8f, 1e-6f);
  EXPECT_NEAR(sh::rt::length(Vec3{3e30f, 4e30f, 0}), 5e30f, 1e24f);
}

TEST(Extremes, RaysLeavingASurfaceDoNotShadowThemselves) {
  // A lit floor with nothing above it: every floor pixel must be lit the
  // same, far from the origin too (no acne).
  for (float offset : {0.0f, 1e5f}) {
    sh::rt::Scene s;
    s.name = "floor";
    s.materials.push_back({});
    Vec3 o{offset, offset, offset};
    sh::rt::add_quad(s, o + Vec3{-5, 0, -5}, {0, 0, 10}, {10, 0, 0}, 0);
    s.lights.push_back({o + Vec3{0, 1000, 0}, {1, 1, 1}});
    s.camera = {o + Vec3{0, 3, 6}, o, {0, 1, 0}, 40};
    s.ambient = 0;
    sh::rt::RenderSettings settings;
    settings.width = 64;
    settings.height = 48;
    settings.backend = "cpu";
    sh::rt::Image img = sh::rt::Renderer(s, settings).render();
    std::size_t floor_pixels = 0, dark = 0;
    for (std::size_t p = 0; p < img.triangle.size(); ++p)
      if (img.triangle[p] >= 0) {
        ++floor_pixels;
        dark += img.rgb[3 * p] < 0.5f;
      }
    EXPECT_GT(floor_pixels, 1000u);
    EXPECT_EQ(dark, 0u) << "self-shadowed floor pixels at offset " << offset;
  }
}

TEST(Extremes, DegenerateTrianglesWarnAndLeaveTheImageAlone) {
  sh::rt::Scene clean = closed_box_scene();
  sh::rt::Scene dirty = clean;
  sh::rt::MeshBuilder b(dirty, 0);
  b.triangle({0, 0, 0}, {0, 0, 0}, {1, 1, 1});      // two equal vertices
  b.triangle({0, 0, 0}, {1, 1, 1}, {2, 2, 2});      // collinear
  EXPECT_EQ(b.degenerate(), 2u);
  EXPECT_EQ(dirty.mesh.triangles(), clean.mesh.triangles());
  sh::rt::RenderSettings settings;
  settings.width = 32;
  settings.height = 24;
  settings.backend = "cpu";
  sh::rt::Image a = sh::rt::Renderer(clean, settings).render(), c = sh::rt::Renderer(dirty, settings).render();
  EXPECT_EQ(a.rgb, c.rgb);
}

TEST(Extremes, CameraInsideAndOutsideTheGrid) {
  sh::rt::Scene s = sh::rt::builtin_scene("cornell");
  sh::rt::RenderSettings settings;
  settings.width = 48;
  settings.height = 36;
  settings.backend = "cpu";
  for (Vec3 eye : {Vec3{0, 0, 0.9f}, Vec3{0, 0, 3.4f}}) {
    s.camera.eye = eye;
    s.camera.look_at = {0, 0, -1};
    sh::rt::Image img = sh::rt::Renderer(s, settings).render();
    // Primary hit distances agree with Embree for every pixel.
    oracle::Embree embree(s);
    std::vector<float> centres = sh::rt::pixel_centres(settings.width, settings.height);
    std::size_t agree = 0;
    for (std::size_t p = 0; p < img.distance.size(); ++p) {
      Vec3 f = sh::rt::normalize(s.camera.look_at - s.camera.eye), right = sh::rt::normalize(sh::rt::cross(f, s.camera.up));
      Vec3 up = sh::rt::cross(right, f);
      float th = std::tan(s.camera.fov_degrees * 3.14159265f / 360), aspect = 48.0f / 36.0f;
      float x = (2 * centres[2 * p] / 48 - 1) * th * aspect, y = -(2 * centres[2 * p + 1] / 36 - 1) * th;
      oracle::Hit e = embree.intersect(s.camera.eye, sh::rt::normalize(f + right * x + up * y));
      agree += std::fabs(e.t - img.distance[p]) <= 1e-3f * std::max(1.0f, e.t);
    }
    EXPECT_GE(agree, img.distance.size() * 999 / 1000) << "eye at z = " << eye.z;
  }
}

}  // namespace
