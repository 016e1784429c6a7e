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

void MeshBuilder::triangle(Vec3 a, Vec3 b, Vec3 c) {
  Vec3 n = normalize(cross(b - a, c - a));
  triangle(a, b, c, n, n, n);
}

void MeshBuilder::triangle(Vec3 a, Vec3 b, Vec3 c, Vec3 na, Vec3 nb, Vec3 nc) {
  if (length(cross(b - a, c - a)) == 0) {
    ++degenerate_;
    return;
  }
  for (Vec3 p : {a, b, c}) scene_.mesh.positions.push_back(p);
  Vec3 face = normalize(cross(b - a, c - a));
  for (Vec3 n : {na, nb, nc}) scene_.mesh.normals.push_back(length(n) > 0 ? normalize(n) : face);
  if (scene_.has_vertex_colors())
    for (int i = 0; i < 3; ++i) scene_.mesh.colors.push_back({1, 1, 1});
  scene_.mesh.material.push_back(material_);
}

void MeshBuilder::colored(Vec3 a, Vec3 b, Vec3 c, Vec3 na, Vec3 nb, Vec3 nc, Vec3 ca, Vec3 cb, Vec3 cc) {
  // The first coloured triangle gives every earlier one white vertices.
  if (!scene_.has_vertex_colors()) scene_.mesh.colors.assign(scene_.mesh.positions.size(), {1, 1, 1});
  std::size_t before = scene_.mesh.positions.size();
  triangle(a, b, c, na, nb, nc);
  if (scene_.mesh.positions.size() == before) return;
  std::size_t at = scene_.mesh.colors.size() - 3;
  scene_.mesh.colors[at] = ca;
  scene_.mesh.colors[at + 1] = cb;
  scene_.mesh.colors[at + 2] = cc;
}

void validate(const Scene& s, const std::string& where) {
  if (s.mesh.triangles() == 0) throw Error(where + ": the scene has no triangles (nothing to trace)");
  for (std::size_t i = 0; i < s.mesh.positions.size(); ++i)
    if (!finite(s.mesh.positions[i]))
      throw Error(where + ": triangle " + std::to_string(i / 3) + " has a NaN or infinite vertex coordinate");
  for (std::int32_t m : s.mesh.material)
    if (m < 0 || m >= static_cast<std::int32_t>(s.materials.size()))
      throw Error(where + ": a triangle names material " + std::to_string(m) + ", which does not exist");
  if (!finite(s.camera.eye) || !finite(s.camera.look_at) || !finite(s.camera.up))
    throw Error(where + ": camera: NaN or infinite coordinate");
  if (length(s.camera.look_at - s.camera.eye) == 0) throw Error(where + ": camera: eye and look_at coincide");
  if (length(cross(s.camera.look_at - s.camera.eye, s.camera.up)) == 0)
    throw Error(where + ": camera: up is parallel to the view direction");
  if (!(s.camera.fov_degrees > 0 && s.camera.fov_degrees < 180))
    throw Error(where + ": camera: fov must be between 0 and 180 degrees");
}

}  // namespace sh::rt
