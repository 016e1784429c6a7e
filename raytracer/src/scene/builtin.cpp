// Built-in scenes that show every feature of the tracer.
#include <cmath>

#include "sh/error.hpp"
#include "sh/raytracer/scene.hpp"

namespace sh::rt {
namespace {

int material(Scene& s, const char* name, Vec3 diffuse, float specular = 0, float shininess = 32, float reflectivity = 0) {
  Material m;
  m.name = name;
  m.diffuse = diffuse;
  m.specular = specular;
  m.shininess = shininess;
  m.reflectivity = reflectivity;
  s.materials.push_back(m);
  return static_cast<int>(s.materials.size() - 1);
}

// A Cornell-style box: red and green side walls, a mirror sphere, a box.
Scene cornell() {
  Scene s;
  s.name = "cornell";
  int white = material(s, "white", {0.75f, 0.75f, 0.75f});
  int red = material(s, "red", {0.75f, 0.15f, 0.15f});
  int green = material(s, "green", {0.15f, 0.75f, 0.15f});
  int mirror = material(s, "mirror", {0.1f, 0.1f, 0.1f}, 0.9f, 200, 0.85f);
  add_quad(s, {-1, -1, -1}, {2, 0, 0}, {0, 0, 2}, white);   // floor
  add_quad(s, {-1, 1, -1}, {0, 0, 2}, {2, 0, 0}, white);    // ceiling
  add_quad(s, {-1, -1, -1}, {0, 2, 0}, {2, 0, 0}, white);   // back
  add_quad(s, {-1, -1, -1}, {0, 0, 2}, {0, 2, 0}, red);     // left
  add_quad(s, {1, -1, -1}, {0, 2, 0}, {0, 0, 2}, green);    // right
  add_sphere(s, {0.4f, -0.55f, -0.2f}, 0.42f, mirror, 32);
  add_box(s, {-0.8f, -1.0f, -0.6f}, {-0.2f, -0.1f, 0.0f}, white);
  s.lights.push_back({{0, 0.9f, 0.2f}, {1, 1, 1}});
  s.camera = {{0, 0, 3.4f}, {0, 0, 0}, {0, 1, 0}, 40};
  s.background = {0, 0, 0};
  return s;
}

// The flagship: reflective spheres on a chequered plane, two lights.
Scene spheres() {
  Scene s;
  s.name = "spheres";
  int light_tile = material(s, "tile light", {0.85f, 0.85f, 0.8f}, 0.1f, 16, 0.15f);
  int dark_tile = material(s, "tile dark", {0.25f, 0.25f, 0.3f}, 0.1f, 16, 0.15f);
  int chrome = material(s, "chrome", {0.2f, 0.2f, 0.2f}, 0.9f, 120, 0.8f);
  int gold = material(s, "gold", {0.8f, 0.6f, 0.2f}, 0.6f, 60, 0.35f);
  int blue = material(s, "blue", {0.2f, 0.3f, 0.9f}, 0.4f, 40, 0.1f);
  for (int i = -4; i < 4; ++i)
    for (int j = -4; j < 4; ++j)
      add_quad(s, {1.0f * i, 0, 1.0f * j}, {0, 0, 1}, {1, 0, 0}, (i + j) % 2 == 0 ? light_tile : dark_tile);
  add_sphere(s, {0, 0.8f, 0}, 0.8f, chrome, 48);
  add_sphere(s, {-1.7f, 0.5f, 0.6f}, 0.5f, gold, 32);
  add_sphere(s, {1.5f, 0.45f, 0.9f}, 0.45f, blue, 32);
  s.lights.push_back({{-3, 5, 4}, {0.8f, 0.8f, 0.75f}});
  s.lights.push_back({{4, 3, 2}, {0.45f, 0.45f, 0.55f}});
  s.camera = {{0, 2.2f, 5.5f}, {0, 0.5f, 0}, {0, 1, 0}, 45};
  s.background = {0.55f, 0.7f, 0.9f};
  return s;
}

// Spheres on a grid, tessellated finely enough to reach about `triangles`.
Scene procedural(std::size_t triangles) {
  if (triangles < 100 || triangles > 50'000'000)
    throw Error("procedural scene: triangle count must be 100 .. 50000000, got " + std::to_string(triangles));
  Scene s;
  s.name = "procedural";
  int floor = material(s, "floor", {0.6f, 0.6f, 0.6f}, 0, 32, 0.2f);
  int shiny = material(s, "shiny", {0.7f, 0.3f, 0.3f}, 0.5f, 50, 0.3f);
  add_quad(s, {-12, 0, -12}, {0, 0, 24}, {24, 0, 0}, floor);
  auto n = static_cast<int>(std::ceil(std::sqrt(triangles / 800.0)));
  // A sphere of s segments has about s * s triangles.
  int segments = std::max(6, static_cast<int>(std::lround(std::sqrt(static_cast<double>(triangles) / (n * n)))) / 2 * 2);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      float x = -10 + 20.0f * (i + 0.5f) / n, z = -10 + 20.0f * (j + 0.5f) / n;
      add_sphere(s, {x, 0.4f, z}, 8.0f / n, shiny, segments);
    }
  s.lights.push_back({{0, 20, 10}, {1, 1, 1}});
  s.camera = {{0, 14, 22}, {0, 0, 0}, {0, 1, 0}, 45};
  s.background = {0.3f, 0.3f, 0.35f};
  return s;
}

// The soft-shadow paper's scene: a sphere above a plane, lit by one or two
// 4 cm disk lights (units are metres).
Scene soft(int lights) {
  Scene s;
  s.name = lights == 1 ? "soft" : "soft2";
  int floor = material(s, "floor", {0.8f, 0.8f, 0.8f});
  int ball = material(s, "ball", {0.8f, 0.3f, 0.2f}, 0.4f, 40);
  add_quad(s, {-2, 0, -2}, {0, 0, 4}, {4, 0, 0}, floor);
  add_sphere(s, {0, 0.35f, 0}, 0.25f, ball, 48);
  s.disk_lights.push_back({{0.3f, 1.4f, 0.2f}, {0, -1, 0}, 0.02f, {0.9f, 0.9f, 0.85f}});
  if (lights == 2) s.disk_lights.push_back({{-0.5f, 1.2f, -0.1f}, {0, -1, 0}, 0.02f, {0.5f, 0.5f, 0.6f}});
  s.camera = {{0, 1.3f, 1.9f}, {0, 0.1f, 0}, {0, 1, 0}, 40};
  s.ambient = 0.08f;
  s.background = {0.2f, 0.2f, 0.25f};
  return s;
}

// The bidirectional seed's reflective scene: a tilted mirror beside a box
// in a corner of a diffuse room sends a patch of light onto the floor and
// the back wall.
Scene magg_mirror() {
  Scene s;
  s.name = "magg-mirror";
  int wall = material(s, "wall", {0.8f, 0.8f, 0.75f});
  int box = material(s, "box", {0.3f, 0.5f, 0.8f}, 0.3f, 30);
  int mirror = material(s, "mirror", {0, 0, 0}, 0.5f, 200, 1.0f);
  add_tiled_quad(s, {-2, 0, -2}, {0, 0, 4}, {4, 0, 0}, 24, wall);  // floor
  add_tiled_quad(s, {-2, 0, -2}, {4, 0, 0}, {0, 3, 0}, 24, wall);  // back wall
  // Leaning back from the vertical: the light above it lands before it.
  add_tiled_quad(s, {0.6f, 0.05f, -0.4f}, {0.6f, 1.4f, 0.25f}, {0, 0, 1.1f}, 16, mirror);
  add_box(s, {-1.3f, 0, -0.9f}, {-0.6f, 0.7f, -0.2f}, box);
  s.lights.push_back({{0.3f, 2.6f, 0.6f}, {1, 1, 1}});
  s.camera = {{0, 1.6f, 4.2f}, {0, 0.7f, 0}, {0, 1, 0}, 50};
  s.ambient = 0.05f;
  s.background = {0, 0, 0};
  return s;
}

// The bidirectional seed's transparent scene: a glass sphere floating
// above a finely tiled floor focuses the light under it (a ball lens of
// index 1.5 focuses 1.5 radii from its centre).
Scene magg_glass() {
  Scene s;
  s.name = "magg-glass";
  int floor = material(s, "floor", {0.8f, 0.8f, 0.8f});
  int back = material(s, "back", {0.7f, 0.4f, 0.3f});
  Material glass;
  glass.name = "glass";
  glass.diffuse = {0, 0, 0};
  glass.specular = 0.6f;
  glass.shininess = 120;
  glass.transparency = 1;
  glass.ior = 1.5f;
  s.materials.push_back(glass);
  int ball = static_cast<int>(s.materials.size() - 1);
  add_tiled_quad(s, {-2, 0, -2}, {0, 0, 4}, {4, 0, 0}, 40, floor);
  add_tiled_quad(s, {-2, 0, -2}, {4, 0, 0}, {0, 3, 0}, 8, back);
  add_sphere(s, {0, 0.8f, 0}, 0.5f, ball, 32);
  s.lights.push_back({{0.4f, 4.0f, 0.3f}, {1, 1, 1}});
  s.camera = {{0, 2.4f, 3.6f}, {0, 0.4f, 0}, {0, 1, 0}, 45};
  s.ambient = 0.05f;
  s.background = {0, 0, 0};
  return s;
}

}  // namespace

std::vector<std::string> builtin_scene_names() {
  return {"cornell", "spheres", "procedural", "soft", "soft2", "magg-mirror", "magg-glass"};
}

std::string builtin_scene_list() {
  std::string list;
  for (const std::string& name : builtin_scene_names()) list += (list.empty() ? "" : ", ") + name;
  return list;
}

Scene builtin_scene(const std::string& name, std::size_t triangles) {
  if (name == "cornell") return cornell();
  if (name == "spheres") return spheres();
  if (name == "procedural") return procedural(triangles);
  if (name == "soft") return soft(1);
  if (name == "soft2") return soft(2);
  if (name == "magg-mirror") return magg_mirror();
  if (name == "magg-glass") return magg_glass();
  throw Error("unknown built-in scene '" + name + "' (built in: " + builtin_scene_list() + ")");
}

}  // namespace sh::rt
