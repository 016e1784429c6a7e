#pragma once
// Shared by the ray tracer's tests: running the intersector kernel on a
// batch of rays, and comparing its hits with Embree's.
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <sh/raytracer.hpp>
#include <sh/sh.hpp>

#include "embree_oracle.hpp"

namespace rt_test {

// A test that writes files: a directory of its own (named after the
// process, so tests running side by side under ctest -j never meet),
// removed afterwards.
class FilesTest : public testing::Test {
 protected:
  void SetUp() override;
  void TearDown() override;
  // Writes `bytes` as they are to `name` in the directory; returns the path.
  std::string write(const std::string& name, const std::string& bytes);
  std::filesystem::path dir_;
};

struct Rays {
  std::vector<float> origins, directions;  // 3 floats each
  std::size_t size() const { return origins.size() / 3; }
  void add(sh::rt::Vec3 o, sh::rt::Vec3 d) {
    origins.insert(origins.end(), {o.x, o.y, o.z});
    directions.insert(directions.end(), {d.x, d.y, d.z});
  }
  sh::rt::Vec3 origin(std::size_t i) const { return {origins[3 * i], origins[3 * i + 1], origins[3 * i + 2]}; }
  sh::rt::Vec3 direction(std::size_t i) const { return {directions[3 * i], directions[3 * i + 1], directions[3 * i + 2]}; }
};

using sh::rt::Hits;

// Every backend linked in; mpi renders in this process as one rank (its
// ranks under mpirun are tests/mpi's).
std::vector<std::string> every_backend();
// The same less interp: for tests that hold a backend's image against
// interp's.
std::vector<std::string> backends_beside_interp();

// Random rays from around the scene's bounds towards random points inside.
Rays random_rays(const sh::rt::Scene& scene, std::size_t n, unsigned seed);

// An accelerator as a test walks it: the BVH with either of its walks.
// large: built and walked as a tree that outgrows the cache is, whatever
// its size: the large tree's node cost, children asked ahead (the suite's
// scenes are all below kBvhLargeTree and kBvhPrefetchBytes).
struct Walked {
  Walked(sh::rt::Accel a, sh::rt::BvhWalk w = sh::rt::BvhWalk::Threaded, bool large = false)
      : accel(a), walk(w), large(large) {}
  sh::rt::Accel accel;
  sh::rt::BvhWalk walk;
  bool large;
  std::string name() const;  // grid, octree, lazy-octree, bvh, bvh-stack, bvh-wide, bvh-wide-large
  sh::rt::RenderSettings settings() const;
};
// Every accelerator and walk the suite checks against each other.
std::vector<Walked> every_accelerator();

Hits trace(const sh::rt::Scene& scene, const Rays& rays, const std::string& backend = "cpu",
           Walked accel = sh::rt::Accel::Grid);

struct Agreement {
  // starts_on_surface: one tracer's hit lies within the coordinates'
  // precision of the origin, which the other counts as behind it (ours
  // rejects hits nearer than the intersection's error bound).
  std::size_t rays = 0, agree = 0, ties = 0, edge_grazes = 0, starts_on_surface = 0;
  std::size_t unexplained() const { return rays - agree - ties - edge_grazes - starts_on_surface; }
  std::vector<std::string> disagreements;  // the first few, described
};

// Our hits against Embree's: the same triangle and t within 1e-4 relative,
// or a tie (another triangle at the same t), or a ray grazing an edge
// within the intersector's tolerance.
Agreement compare_with_embree(const sh::rt::Scene& scene, const Rays& rays, const Hits& ours);

}  // namespace rt_test
