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

std::vector<std::string> backends() {
  std::vector<std::string> names;
  for (const std::string& b : sh::backend_names())
    if (b != "mpi") names.push_back(b);  // mpi: tests/mpi/same_image.sh renders with shadows under mpirun
  return names;
}

INSTANTIATE_TEST_SUITE_P(Backends, AnyHit, testing::ValuesIn(backends()), [](const auto& info) { return info.param; });

}  // namespace
