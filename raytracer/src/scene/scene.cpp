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

std::string material_problem(const Material& m) {
  auto shown = [](float v) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", static_cast<double>(v));
    return std::string(text);
  };
  if (!finite(m.diffuse) || m.diffuse.x < 0 || m.diffuse.y < 0 || m.diffuse.z < 0)
    return "diffuse must be finite and not negative";
  if (!(m.specular >= 0 && std::isfinite(m.specular)))
    return "specular " + shown(m.specular) + " must be finite and not negative";
  if (!(m.shininess >= 0 && std::isfinite(m.shininess)))
    return "shininess " + shown(m.shininess) + " must be finite and not negative";
  if (!(m.reflectivity >= 0 && m.reflectivity <= 1))
    return "reflectivity " + shown(m.reflectivity) + " must be in [0, 1]";
  if (!(m.transparency >= 0 && m.transparency <= 1))
    return "transparency " + shown(m.transparency) + " must be in [0, 1]";
  if (m.reflectivity + m.transparency > 1) return "reflectivity + transparency must not exceed 1";
  if (!(m.ior >= 1 && m.ior <= 4)) return "ior " + shown(m.ior) + " must be in [1, 4]";
  return "";
}

namespace {

bool colour(Vec3 c) { return finite(c) && c.x >= 0 && c.y >= 0 && c.z >= 0; }

// Where the camera and lights may lie: beyond the vertices (a model's
// framing puts them there), but not so far that the rays lose the scene.
constexpr float kMaxPlacement = 10 * kMaxCoordinate;

void check_placed(Vec3 p, const std::string& where, const std::string& field) {
  if (!finite(p)) throw Error(where + ": " + field + ": NaN or infinite coordinate");
  if (std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)}) > kMaxPlacement)
    throw Error(where + ": " + field + ": a coordinate beyond 1e19, where the tracer's rays lose the scene");
}

// What the kernels read per corner and per triangle: as many entries as
// there are triangles, each a number the shading can use.
void check_mesh(const Mesh& m, const std::string& where) {
  std::size_t corners = m.positions.size();
  if (corners % 3 != 0)
    throw Error(where + ": mesh.positions holds " + std::to_string(corners) + " points, not 3 a triangle");
  if (m.normals.size() != corners)
    throw Error(where + ": mesh.normals holds " + std::to_string(m.normals.size()) + " normals for " +
                std::to_string(corners) + " corners");
  if (!m.colors.empty() && m.colors.size() != corners)
    throw Error(where + ": mesh.colors holds " + std::to_string(m.colors.size()) + " colours for " +
                std::to_string(corners) + " corners (or none)");
  if (m.material.size() != corners / 3)
    throw Error(where + ": mesh.material holds " + std::to_string(m.material.size()) + " entries for " +
                std::to_string(corners / 3) + " triangles");
  auto corner = [&](std::size_t i) {
    return where + ": triangle " + std::to_string(i / 3) + ", vertex " + std::to_string(i % 3) + ": ";
  };
  for (std::size_t i = 0; i < corners; ++i) {
    if (!finite(m.normals[i]) || !(length(m.normals[i]) > 0))
      throw Error(corner(i) + "its normal is zero or not finite");
    if (!m.colors.empty() && !colour(m.colors[i])) throw Error(corner(i) + "its colour is negative or not finite");
  }
}

}  // namespace

void validate(const Scene& s, const std::string& where) {
  if (s.mesh.triangles() == 0) throw Error(where + ": the scene has no triangles (nothing to trace)");
  check_mesh(s.mesh, where);
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
  for (std::size_t i = 0; i < s.materials.size(); ++i)
    if (std::string problem = material_problem(s.materials[i]); !problem.empty())
      throw Error(where + ": material " + std::to_string(i) + " '" + s.materials[i].name + "': " + problem);
  check_placed(s.camera.eye, where, "camera.eye");
  check_placed(s.camera.look_at, where, "camera.look_at");
  if (!finite(s.camera.up)) throw Error(where + ": camera.up: NaN or infinite coordinate");
  for (std::size_t i = 0; i < s.lights.size(); ++i) {
    std::string at = "lights[" + std::to_string(i) + "]";
    check_placed(s.lights[i].position, where, at + ".position");
    if (!colour(s.lights[i].color)) throw Error(where + ": " + at + ".color: negative or not finite");
    if (!(s.lights[i].intensity >= 0 && std::isfinite(s.lights[i].intensity)))
      throw Error(where + ": " + at + ".intensity: must be finite and not negative (0: the default)");
  }
  for (std::size_t i = 0; i < s.disk_lights.size(); ++i) {
    const DiskLight& d = s.disk_lights[i];
    std::string at = "disk_lights[" + std::to_string(i) + "]";
    check_placed(d.centre, where, at + ".centre");
    if (!finite(d.normal) || !(length(d.normal) > 0))
      throw Error(where + ": " + at + ".normal: zero or not finite");
    if (!(d.radius >= 0 && d.radius <= kMaxCoordinate))
      throw Error(where + ": " + at + ".radius: must be 0 .. 1e18");
    if (!colour(d.color)) throw Error(where + ": " + at + ".color: negative or not finite");
  }
  if (!colour(s.background)) throw Error(where + ": background: negative or not finite");
  if (!(s.ambient >= 0 && std::isfinite(s.ambient)))
    throw Error(where + ": ambient: must be finite and not negative");
  if (length(s.camera.look_at - s.camera.eye) == 0) throw Error(where + ": camera: eye and look_at coincide");
  // As the camera makes its frame: a side vector of length one, or none.
  Vec3 side = normalize(cross(normalize(s.camera.look_at - s.camera.eye), s.camera.up));
  if (!finite(side) || !(length(side) > 0.5f))
    throw Error(where + ": camera: up is parallel to the view direction, or too short to give one");
  if (!(s.camera.fov_degrees > 0 && s.camera.fov_degrees < 180))
    throw Error(where + ": camera: fov must be between 0 and 180 degrees");
}

}  // namespace sh::rt
