#pragma once
// Watertightness, measured: closed meshes, rays aimed exactly at their
// vertices and edge midpoints from outside and from inside, and the count
// of rays that slip through.  Shared by the suite's test (a small set on
// every backend) and watertight_bench (10^6 rays and more, Embree beside).
#include <cstdint>
#include <string>
#include <vector>

#include <sh/raytracer.hpp>

namespace watertight {

using sh::rt::Vec3;

// A closed, consistently wound mesh, a point inside it, and which corners
// of the triangle soup are one vertex.  The makers throw sh::Error for a
// mesh that is not closed.
struct ClosedMesh {
  std::string name;
  sh::rt::Scene scene;
  Vec3 inside;
  std::vector<std::int32_t> corners;  // a vertex id for each of scene.mesh.positions
};

ClosedMesh uv_sphere(int segments);        // radius 1 at the origin
ClosedMesh tessellated_cube(int tiles);    // [-1, 1]^3, tiles x tiles quads a face, vertices shared exactly
// A model file that is closed once equal positions are taken as one
// vertex; its inside point is where a ray through its centre is between
// its first two crossings.
ClosedMesh closed_model(const std::string& path);

// The same mesh scaled about the origin, then translated by (offset,
// offset, offset), every coordinate rounded to float once.
ClosedMesh transformed(const ClosedMesh& m, float scale, float offset);

// Rays aimed exactly at vertices and edge midpoints, two a target: from
// outside (a random point three bounding radii out) and from the inside
// point; at most `most` rays, targets taken in random order.  A float ray
// misses its target by its rounding, so a ray is kept only where (in
// double) it meets a triangle around the target, and crosses each of them
// at more than a grazing angle, all from one side; its distance is where
// it meets them.
struct AimedRays {
  std::vector<float> origins, directions;  // 3 floats a ray
  std::vector<float> distance;             // to where it meets the target's triangles
  std::size_t targets_skipped = 0;         // grazing, or next to a degenerate triangle, or missed by rounding
  std::size_t size() const { return distance.size(); }
};
AimedRays aimed_rays(const ClosedMesh& m, std::size_t most, unsigned seed);

// Rays whose nearest hit (t < 0: none) is missing or lies beyond where they
// meet the target's triangles: they went through the surface.
std::size_t leaks(const AimedRays& rays, const std::vector<float>& t);

}  // namespace watertight
