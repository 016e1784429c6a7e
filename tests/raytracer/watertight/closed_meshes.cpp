#include "closed_meshes.hpp"

#include <algorithm>
#include <array>
#include <cstdio>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <tuple>

#include <embree_scene.hpp>
#include <sh/error.hpp>

namespace watertight {
namespace {

using Key = std::tuple<float, float, float>;
Key key(Vec3 p) { return {p.x, p.y, p.z}; }

// The soup's corners welded by exact position: one id per vertex.
std::vector<std::int32_t> weld(const sh::rt::Mesh& mesh) {
  std::map<Key, std::int32_t> ids;
  std::vector<std::int32_t> corners;
  for (const Vec3& p : mesh.positions)
    corners.push_back(ids.emplace(key(p), static_cast<std::int32_t>(ids.size())).first->second);
  return corners;
}

// What touches each vertex and each edge.  The ids come from the mesh
// before it was moved, where rounding may since have merged vertices.
struct Topology {
  bool consistently_wound = true;  // every edge run through once each way
  std::vector<Vec3> vertices;
  std::vector<std::vector<std::int32_t>> vertex_faces;
  std::map<std::pair<std::int32_t, std::int32_t>, std::vector<std::int32_t>> edge_faces;
};

Topology topology(const sh::rt::Mesh& mesh, const std::vector<std::int32_t>& corners) {
  Topology t;
  std::int32_t count = corners.empty() ? 0 : *std::max_element(corners.begin(), corners.end()) + 1;
  t.vertices.resize(count);
  t.vertex_faces.resize(count);
  std::map<std::pair<std::int32_t, std::int32_t>, int> directed;
  for (std::size_t f = 0; f < mesh.triangles(); ++f) {
    const std::int32_t* corner = &corners[3 * f];
    for (int k = 0; k < 3; ++k) {
      t.vertices[corner[k]] = mesh.positions[3 * f + k];
      t.vertex_faces[corner[k]].push_back(static_cast<std::int32_t>(f));
    }
    for (int k = 0; k < 3; ++k) {
      std::int32_t a = corner[k], b = corner[(k + 1) % 3];
      ++directed[{a, b}];
      t.edge_faces[{std::min(a, b), std::max(a, b)}].push_back(static_cast<std::int32_t>(f));
    }
  }
  for (const auto& [edge, n] : directed) {
    auto back = directed.find({edge.second, edge.first});
    t.consistently_wound &= n == 1 && back != directed.end() && back->second == 1;
  }
  return t;
}

// Closed, and wound one way throughout (so that the faces' normals all
// point out, or all in: what `crosses` compares).
bool closed(const Topology& t) {
  return t.consistently_wound && std::all_of(t.edge_faces.begin(), t.edge_faces.end(), [](const auto& e) { return e.second.size() == 2; });
}

Vec3 face_normal(const sh::rt::Mesh& m, std::int32_t f) {
  Vec3 a = m.positions[3 * f], b = m.positions[3 * f + 1], c = m.positions[3 * f + 2];
  Vec3 n = sh::rt::cross(b - a, c - a);
  float len = sh::rt::length(n);
  return len > 0 ? n * (1 / len) : Vec3{0, 0, 0};
}

// Does a ray along d cross every face around the target at more than a
// grazing angle, all of them from the same side (the mesh is consistently
// wound)?
bool crosses(const sh::rt::Mesh& m, const std::vector<std::int32_t>& faces, Vec3 d) {
  constexpr float kLeastCosine = 0.05f;
  int sign = 0;
  for (std::int32_t f : faces) {
    float c = sh::rt::dot(face_normal(m, f), d);
    if (std::fabs(c) < kLeastCosine) return false;
    int s = c > 0 ? 1 : -1;
    if (sign != 0 && s != sign) return false;
    sign = s;
  }
  return true;
}

// Where the ray o + t d meets the inside of triangle f, in double (products
// of floats are exact there, sums nearly): -1 where it does not.  Exactly on
// an edge does not count: far from the origin, where rounding has folded a
// fine mesh, such a ray may only touch the surface there.
double exact_hit(const sh::rt::Mesh& m, std::int32_t f, Vec3 o, Vec3 d) {
  using D3 = std::array<double, 3>;
  auto from_o = [&](Vec3 v) { return D3{double(v.x) - o.x, double(v.y) - o.y, double(v.z) - o.z}; };
  auto cross = [](D3 a, D3 b) { return D3{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]}; };
  auto dot = [](D3 a, D3 b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; };
  D3 a = from_o(m.positions[3 * f]), b = from_o(m.positions[3 * f + 1]), c = from_o(m.positions[3 * f + 2]);
  D3 dd{d.x, d.y, d.z};
  double u = dot(dd, cross(b, c)), v = dot(dd, cross(c, a)), w = dot(dd, cross(a, b));
  if (!((u > 0 && v > 0 && w > 0) || (u < 0 && v < 0 && w < 0))) return -1;
  D3 n = cross({b[0] - a[0], b[1] - a[1], b[2] - a[2]}, {c[0] - a[0], c[1] - a[1], c[2] - a[2]});
  double along = dot(n, dd);
  return along == 0 ? -1 : dot(n, a) / along;
}

ClosedMesh closed_scene(const std::string& what, sh::rt::Scene s, Vec3 inside) {
  std::string name = what + " (" + std::to_string(s.mesh.triangles()) + " triangles)";
  s.name = name;
  s.camera = {{0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 45};
  std::vector<std::int32_t> corners = weld(s.mesh);
  if (!closed(topology(s.mesh, corners))) throw sh::Error(name + ": not closed and consistently wound");
  return {std::move(name), std::move(s), inside, std::move(corners)};
}

}  // namespace

ClosedMesh uv_sphere(int segments) {
  sh::rt::Scene s;
  s.materials.push_back({});
  sh::rt::add_sphere(s, {0, 0, 0}, 1, 0, segments);
  return closed_scene("uv sphere", std::move(s), {0, 0, 0});
}

ClosedMesh tessellated_cube(int tiles) {
  sh::rt::Scene s;
  s.materials.push_back({});
  sh::rt::MeshBuilder b(s, 0);
  // Every coordinate comes from one function of its lattice index, so the
  // faces meet at exactly the same vertices.
  auto at = [&](int i) { return -1.0f + 2.0f * static_cast<float>(i) / static_cast<float>(tiles); };
  for (int axis = 0; axis < 3; ++axis)
    for (int side : {0, tiles}) {
      auto point = [&](int i, int j) {
        float c[3];
        c[axis] = at(side);
        c[(axis + 1) % 3] = at(i);
        c[(axis + 2) % 3] = at(j);
        return Vec3{c[0], c[1], c[2]};
      };
      // Wound so that every face's normal points out.
      auto triangle = [&](Vec3 a, Vec3 p, Vec3 q) { side == 0 ? b.triangle(a, q, p) : b.triangle(a, p, q); };
      for (int i = 0; i < tiles; ++i)
        for (int j = 0; j < tiles; ++j) {
          triangle(point(i, j), point(i + 1, j), point(i + 1, j + 1));
          triangle(point(i, j), point(i + 1, j + 1), point(i, j + 1));
        }
    }
  return closed_scene("tessellated cube", std::move(s), {0.1f, 0.2f, 0.3f});
}

ClosedMesh closed_model(const std::string& path) {
  sh::rt::Scene s = sh::rt::load_model_as_scene(path);
  Vec3 lo = s.bounds_min(), hi = s.bounds_max(), centre = (lo + hi) * 0.5f;
  Vec3 from = centre - Vec3{0, 0, 4 * sh::rt::length(hi - lo)};
  sh::rt::EmbreeScene embree(s);
  RTCRayHit first = embree.intersect(from, {0, 0, 1});
  if (first.hit.geomID == RTC_INVALID_GEOMETRY_ID) throw sh::Error(path + ": no ray through its centre meets it");
  RTCRayHit second = embree.intersect(from, {0, 0, 1}, std::nextafter(first.ray.tfar, INFINITY));
  Vec3 inside = from + Vec3{0, 0, 0.5f * (first.ray.tfar + second.ray.tfar)};
  return closed_scene(path.substr(path.find_last_of('/') + 1), std::move(s), inside);
}

ClosedMesh transformed(const ClosedMesh& m, float scale, float offset) {
  ClosedMesh out = m;
  auto move = [&](Vec3 p) { return p * scale + Vec3{offset, offset, offset}; };
  for (Vec3& p : out.scene.mesh.positions) p = move(p);
  out.inside = move(m.inside);
  char label[64];
  std::snprintf(label, sizeof label, " x%g +%g", scale, offset);
  out.name += label;
  out.scene.name = out.name;
  return out;
}

AimedRays aimed_rays(const ClosedMesh& m, std::size_t most, unsigned seed) {
  const sh::rt::Mesh& mesh = m.scene.mesh;
  Topology t = topology(mesh, m.corners);
  struct Target {
    Vec3 at;
    const std::vector<std::int32_t>* faces;
  };
  std::vector<Target> targets;
  for (std::size_t v = 0; v < t.vertices.size(); ++v) targets.push_back({t.vertices[v], &t.vertex_faces[v]});
  for (const auto& [edge, faces] : t.edge_faces)
    targets.push_back({(t.vertices[edge.first] + t.vertices[edge.second]) * 0.5f, &faces});
  std::mt19937 rng(seed);
  std::shuffle(targets.begin(), targets.end(), rng);

  Vec3 lo = m.scene.bounds_min(), hi = m.scene.bounds_max(), centre = (lo + hi) * 0.5f;
  float radius = 3 * sh::rt::length(hi - lo);
  std::normal_distribution<float> gauss;
  AimedRays rays;
  auto aim = [&](Vec3 from, const Target& target) {
    Vec3 d = sh::rt::normalize(target.at - from);
    // The float ray misses its target by its rounding: it must meet the
    // surface only where it really meets a triangle around the target.
    double meets = -1;
    for (std::int32_t f : *target.faces) {
      double t = exact_hit(mesh, f, from, d);
      if (t > 0 && (meets < 0 || t < meets)) meets = t;
    }
    if (meets < 0 || !crosses(mesh, *target.faces, d)) {
      ++rays.targets_skipped;
      return;
    }
    rays.origins.insert(rays.origins.end(), {from.x, from.y, from.z});
    rays.directions.insert(rays.directions.end(), {d.x, d.y, d.z});
    rays.distance.push_back(static_cast<float>(meets));
  };
  for (std::size_t i = 0; i < targets.size() && rays.size() + 1 < most; ++i) {
    Vec3 away = sh::rt::normalize({gauss(rng), gauss(rng), gauss(rng)});
    aim(centre + away * radius, targets[i]);
    aim(m.inside, targets[i]);
  }
  return rays;
}

std::size_t leaks(const AimedRays& rays, const std::vector<float>& t) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    float d = rays.distance[i];
    // Where the ray crosses at the target, t may differ from the distance by
    // the rounding of the coordinates.
    float o = std::max({std::fabs(rays.origins[3 * i]), std::fabs(rays.origins[3 * i + 1]),
                        std::fabs(rays.origins[3 * i + 2])});
    float slack = 1e-4f * d + 64 * std::numeric_limits<float>::epsilon() * (o + d);
    n += t[i] < 0 || t[i] > d + slack;
  }
  return n;
}

}  // namespace watertight
