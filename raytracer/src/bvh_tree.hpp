#pragma once
// Between the BVH's build and its layout: the tree as nodes that own their
// children, and the box arithmetic both use.
#include <array>
#include <memory>
#include <vector>

#include "sh/raytracer/bvh.hpp"

namespace sh::rt::bvh {

Box empty_box();
Box merge(const Box& a, const Box& b);
Box grow(const Box& a, Vec3 p);
Vec3 centre(const Box& b);
double area(const Box& b);  // 0 for an empty box

struct Node {
  Box box = empty_box();
  std::array<std::unique_ptr<Node>, 2> child;  // none: a leaf
  std::vector<std::int32_t> triangles;         // a leaf's, in increasing order
  bool leaf() const { return !child[0]; }
};

std::unique_ptr<Node> build_tree(const Scene& scene, BvhLimits limits);
// Nodes depth-first, boxes widened by a hair relative to `bounds`, links
// for every order.
Bvh lay_out(const Node& root, const Box& bounds);

}  // namespace sh::rt::bvh
