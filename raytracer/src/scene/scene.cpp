#include <algorithm>
#include <cmath>
#include <cstdio>

#include "sh/error.hpp"
#include "sh/raytracer/scene.hpp"

namespace sh::rt {

bool Scene::has_reflections() const {
  for (const Material& m : materials)
    if (m.reflectivity > 0) return true;
  return false;
}

bool Scene::has_transparency() const {
  for (const Material& m : materials)
    if (m.transparency > 0) return true;
  return false;
}

Vec3 Scene::bounds_min() const {
  Vec3 lo{1e30f, 1e30f, 1e30f};
  for (const Vec3& p : mesh.positions) lo = min(lo, p);
  return lo;
}

Vec3 Scene::bounds_max() const {
  Vec3 hi{-1e30f, -1e30f, -1e30f};
  for (const Vec3& p : mesh.positions) hi = max(hi, p);
  return hi;
}

void Mesh::append(const Mesh& other, std::int32_t material_of_other) {
  const Vec3 white{1, 1, 1};
  if (colors.empty() && !other.colors.empty()) colors.assign(positions.size(), white);
  positions.insert(positions.end(), other.positions.begin(), other.positions.end());
  normals.insert(normals.end(), other.normals.begin(), other.normals.end());
  if (!other.colors.empty()) colors.insert(colors.end(), other.colors.begin(), other.colors.end());
  else if (!colors.empty()) colors.resize(positions.size(), white);
  material.insert(material.end(), other.triangles(), material_of_other);
}

void MeshBuilder::triangle(Vec3 a, Vec3 b, Vec3 c) {
  Vec3 n = normalize(cross(b - a, c - a));
  triangle(a, b, c, n, n, n);
}

void MeshBuilder::triangle(Vec3 a, Vec3 b, Vec3 c, Vec3 na, Vec3 nb, Vec3 nc) {
  if (add(a, b, c, na, nb, nc) && scene_.has_vertex_colors()) scene_.mesh.colors.resize(scene_.mesh.positions.size(), {1, 1, 1});
}

void MeshBuilder::colored(Vec3 a, Vec3 b, Vec3 c, Vec3 na, Vec3 nb, Vec3 nc, Vec3 ca, Vec3 cb, Vec3 cc) {
  if (!add(a, b, c, na, nb, nc)) return;
  // The first coloured triangle gives every earlier one white vertices.
  std::vector<Vec3>& colors = scene_.mesh.colors;
  colors.resize(scene_.mesh.positions.size() - 3, {1, 1, 1});
  colors.insert(colors.end(), {ca, cb, cc});
}

bool MeshBuilder::add(Vec3 a, Vec3 b, Vec3 c, Vec3 na, Vec3 nb, Vec3 nc) {
  if (length(cross(b - a, c - a)) == 0) {
    ++degenerate_;
    return false;
  }
  for (Vec3 p : {a, b, c}) scene_.mesh.positions.push_back(p);
  Vec3 face = normalize(cross(b - a, c - a));
  for (Vec3 n : {na, nb, nc}) scene_.mesh.normals.push_back(length(n) > 0 && finite(n) ? normalize(n) : face);
  scene_.mesh.material.push_back(material_);
  return true;
}

std::string coordinate_problem(Vec3 p) {
  for (int k = 0; k < 3; ++k)
    if (!(std::fabs(p[k]) <= kMaxCoordinate)) {
      char text[96];
      std::snprintf(text, sizeof text, "coordinate %c = %g is %s", "xyz"[k], static_cast<double>(p[k]),
                    std::isfinite(p[k]) ? "outside the range the tracer supports (|x|, |y|, |z| <= 1e18)"
                                        : "not a finite number");
      return text;
    }
  return "";
}

void validate(const Scene& s, const std::string& where) {
  if (s.mesh.triangles() == 0) throw Error(where + ": the scene has no triangles (nothing to trace)");
  for (std::size_t i = 0; i < s.mesh.positions.size(); ++i)
    if (std::string problem = coordinate_problem(s.mesh.positions[i]); !problem.empty())
      throw Error(where + ": triangle " + std::to_string(i / 3) + ", vertex " + std::to_string(i % 3) + ": " + problem);
  Vec3 extent = s.bounds_max() - s.bounds_min();
  if (float largest = std::max({extent.x, extent.y, extent.z}); !(largest >= kMinSceneExtent)) {
    char spans[96];
    std::snprintf(spans, sizeof spans, "%g (its largest extent), under %g", largest, kMinSceneExtent);
    throw Error(where + ": the scene spans only " + spans + ", where single precision loses its triangles' hits; scale it up");
  }
  for (std::int32_t m : s.mesh.material)
    if (m < 0 || m >= static_cast<std::int32_t>(s.materials.size()))
      throw Error(where + ": a triangle names material " + std::to_string(m) + ", which does not exist");
  // The camera and lights may lie a little beyond the vertices' range (a
  // model's framing does): they need only be finite.
  const std::pair<const char*, Vec3> camera[] = {{"eye", s.camera.eye}, {"look_at", s.camera.look_at}, {"up", s.camera.up}};
  for (const auto& [field, v] : camera)
    if (!finite(v)) throw Error(where + ": camera." + field + ": NaN or infinite coordinate");
  for (std::size_t i = 0; i < s.lights.size(); ++i)
    if (!finite(s.lights[i].position)) throw Error(where + ": lights[" + std::to_string(i) + "].position: NaN or infinite coordinate");
  if (length(s.camera.look_at - s.camera.eye) == 0) throw Error(where + ": camera: eye and look_at coincide");
  // As the camera makes its frame: a side vector of length one, or none.
  Vec3 side = normalize(cross(normalize(s.camera.look_at - s.camera.eye), s.camera.up));
  if (!finite(side) || !(length(side) > 0.5f))
    throw Error(where + ": camera: up is parallel to the view direction, or too short to give one");
  if (!(s.camera.fov_degrees > 0 && s.camera.fov_degrees < 180))
    throw Error(where + ": camera: fov must be between 0 and 180 degrees");
}

}  // namespace sh::rt
