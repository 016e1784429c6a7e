#pragma once
// The best hand-written C++ on the kernels' own tree, as a baseline of
// `shtrace rays`: one ray at a time down the renderer's wide BVH, a node's
// four children's boxes tested against it in one vector and the met
// ones visited nearest first by the ray's own entry distances (Embree's
// single-ray walk, on our layout), each leaf's triangles with the kernels'
// watertight test written out in C++.  Beside the kernels it says how far
// their walk is from a one-ray walk of the same tree; beside Embree, how
// the tree compares with Embree's.
#include <cstdint>
#include <vector>

#include <sh/raytracer.hpp>

#include "embree_anchor.hpp"

namespace shtrace {

class HandWalk {
 public:
  // Whether it can walk this renderer's tree: a BVH laid out for the wide walk.
  static bool walks(const sh::rt::Renderer& r);
  explicit HandWalk(const sh::rt::Bvh& bvh);
  // Into `triangles`, on oneTBB's threads, each ray's nearest triangle
  // (Query::Nearest: walked to kFar, as Renderer::intersect walks them) or
  // the first one found before its t_far (Query::Any, as
  // Renderer::occluded's any-hit walk); -1 where none.  Returns how many
  // rays hit.
  std::size_t run(const RayBatch& rays, Query query, std::vector<std::int32_t>& triangles) const;

 private:
  const sh::rt::Bvh& bvh_;
};

}  // namespace shtrace
