// The any-hit query shadow rays use (the occlusion kernel): on every
// backend and accelerator it answers what the nearest-hit query answers (is anything hit before the
// limit?) on random rays with random limits, some short of every surface
// and some beyond.  (A lazy octree answers it with the nearest-hit walk.)
#include <gtest/gtest.h>

#include <random>

#include "helpers.hpp"

namespace {

using sh::rt::Accel;

class AnyHit : public testing::TestWithParam<std::string> {};

TEST_P(AnyHit, AnswersWhatTheNearestHitAnswers) {
  sh::rt::Scene scene = sh::rt::builtin_scene("procedural", 5000);
  rt_test::Rays rays = rt_test::random_rays(scene, 4000, 11);
  std::mt19937 rng(5);
  float size = sh::rt::length(scene.bounds_max() - scene.bounds_min());
  std::uniform_real_distribution<float> u(0.0f, 1.5f * size);
  std::vector<float> limits(rays.size());
  for (float& l : limits) l = u(rng);
  for (rt_test::Walked accel : {rt_test::Walked(Accel::Grid), rt_test::Walked(Accel::Octree), rt_test::Walked(Accel::Bvh),
                                rt_test::Walked(Accel::Bvh, sh::rt::BvhWalk::Stack),
                                rt_test::Walked(Accel::Bvh, sh::rt::BvhWalk::Wide),
                                rt_test::Walked(Accel::Bvh, sh::rt::BvhWalk::Wide, true)}) {
    sh::rt::Renderer r(scene, accel.settings());
    sh::BackendChoice on = sh::backend(GetParam());
    std::vector<float> any = r.occluded(rays.origins, rays.directions, limits, on, true),
                       nearest = r.occluded(rays.origins, rays.directions, limits, on, false);
    std::size_t blocked = 0, differ = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
      blocked += nearest[i] > 0;
      differ += nearest[i] != any[i];
    }
    EXPECT_EQ(differ, 0u) << accel.name() << " on " << GetParam();
    EXPECT_GT(blocked, rays.size() / 10) << "too few rays blocked to mean much";
    EXPECT_LT(blocked, rays.size() * 9 / 10) << "too few rays free to mean much";
  }
}

// Two squares at the same distance to rounding (the intersector's ties),
// the higher numbered just short of the limit and the lower just beyond
// it: each ray is blocked, whichever of the two a walk tests first (the
// BVH's leaves of one triangle put the nearer first), by both walks on
// every accelerator.
TEST_P(AnyHit, ATieJustBeyondTheLimitLeavesTheRayBlocked) {
  const float limit = 10.0f;
  sh::rt::Scene s;
  s.name = "tie at the limit";
  auto square = [&](float z) {
    for (sh::rt::Vec3 v : {sh::rt::Vec3{-1, -1, z}, {1, -1, z}, {1, 1, z}, {-1, -1, z}, {1, 1, z}, {-1, 1, z}})
      s.mesh.positions.push_back(v);
  };
  square(limit * (1 + 5e-7f));  // triangles 0 and 1
  square(limit * (1 - 3e-7f));  // triangles 2 and 3
  s.materials.push_back({});
  s.mesh.material.assign(s.mesh.triangles(), 0);
  s.mesh.normals.assign(s.mesh.positions.size(), sh::rt::Vec3{0, 0, 1});
  s.lights.push_back({{0, 0, 2 * limit}, {1, 1, 1}});
  std::vector<float> origins, directions, limits;
  for (float x : {-0.5f, 0.25f})
    for (float y : {-0.75f, 0.5f}) {
      origins.insert(origins.end(), {x, y, 0});
      directions.insert(directions.end(), {0, 0, 1});
      limits.push_back(limit);
    }
  for (const rt_test::Walked& accel : rt_test::every_accelerator()) {
    if (accel.accel == Accel::LazyOctree) continue;  // occluded() runs over the others
    sh::rt::RenderSettings settings = accel.settings();
    settings.bvh.max_leaf = 1;
    sh::rt::Renderer r(s, settings);
    for (bool any_hit : {true, false}) {
      std::vector<float> blocked = r.occluded(origins, directions, limits, sh::backend(GetParam()), any_hit);
      EXPECT_EQ(blocked, std::vector<float>(limits.size(), 1.0f))
          << accel.name() << (any_hit ? ", any hit" : ", nearest hit") << " on " << GetParam();
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Backends, AnyHit, testing::ValuesIn(rt_test::every_backend()), [](const auto& info) { return info.param; });

}  // namespace
