// JSON scene files.  Every error names the file and the field (as a path
// like objects[2].radius) or, for malformed JSON, the line and column.
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "sh/error.hpp"
#include "sh/raytracer/scene.hpp"

namespace sh::rt {
namespace {

using nlohmann::json;

class Reader {
 public:
  explicit Reader(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const std::string& field, const std::string& what) const {
    throw Error(file_ + ": " + field + ": " + what);
  }

  // Rejects fields the format does not know (a typo must not pass silently).
  void only(const json& j, const std::string& at, std::initializer_list<const char*> known) const {
    if (!j.is_object()) fail(at, "expected an object");
    std::set<std::string> names(known.begin(), known.end());
    for (const auto& [key, value] : j.items())
      if (!names.count(key)) fail(at.empty() ? key : at + "." + key, "unknown field");
  }

  float number(const json& j, const std::string& at) const {
    if (!j.is_number()) fail(at, "expected a number");
    double v = j.get<double>();
    if (!std::isfinite(v)) fail(at, "must be finite");
    return static_cast<float>(v);
  }

  float number(const json& parent, const std::string& at, const char* key, float fallback) const {
    return parent.contains(key) ? number(parent[key], at + "." + key) : fallback;
  }

  Vec3 vec3(const json& j, const std::string& at) const {
    if (j.is_number()) {
      float v = number(j, at);
      return {v, v, v};
    }
    if (!j.is_array() || j.size() != 3) fail(at, "expected [x, y, z]");
    return {number(j[0], at + "[0]"), number(j[1], at + "[1]"), number(j[2], at + "[2]")};
  }

  Vec3 vec3(const json& parent, const std::string& at, const char* key, Vec3 fallback) const {
    return parent.contains(key) ? vec3(parent[key], at + "." + key) : fallback;
  }

  const json& required(const json& parent, const std::string& at, const char* key) const {
    if (!parent.contains(key)) fail(at + "." + key, "missing");
    return parent[key];
  }

  const std::string& file() const { return file_; }

 private:
  std::string file_;
};

std::string location(const std::string& text, std::size_t byte) {
  std::size_t line = 1, column = 1;
  for (std::size_t i = 0; i < byte && i < text.size(); ++i) {
    if (text[i] == '\n') {
      ++line;
      column = 1;
    } else {
      ++column;
    }
  }
  return "line " + std::to_string(line) + ", column " + std::to_string(column);
}

std::string directory_of(const std::string& path) {
  auto slash = path.find_last_of('/');
  return slash == std::string::npos ? "" : path.substr(0, slash + 1);
}

Camera read_camera(const Reader& r, const json& j) {
  r.only(j, "camera", {"eye", "look_at", "up", "fov"});
  Camera c;
  c.eye = r.vec3(j, "camera", "eye", c.eye);
  c.look_at = r.vec3(j, "camera", "look_at", c.look_at);
  c.up = r.vec3(j, "camera", "up", c.up);
  c.fov_degrees = r.number(j, "camera", "fov", c.fov_degrees);
  return c;
}

void read_materials(const Reader& r, const json& j, Scene& s, std::map<std::string, int>& ids) {
  if (!j.is_object()) r.fail("materials", "expected an object of named materials");
  for (const auto& [name, m] : j.items()) {
    std::string at = "materials." + name;
    r.only(m, at, {"type", "diffuse", "specular", "shininess", "reflectivity", "transparency", "ior"});
    Material mat;
    mat.name = name;
    // A type sets what its name promises; the numbers given refine it.
    if (m.contains("type") && !m["type"].is_string()) r.fail(at + ".type", "expected a string");
    std::string type = m.value("type", "diffuse");
    if (type == "mirror") {
      mat.reflectivity = 1;
      mat.diffuse = {0, 0, 0};
    } else if (type == "glass") {
      mat.transparency = 1;
      mat.ior = 1.5f;
      mat.diffuse = {0, 0, 0};
      mat.specular = 0.5f;
    } else if (type != "diffuse") {
      r.fail(at + ".type", "must be diffuse, mirror or glass, not '" + type + "'");
    }
    mat.diffuse = r.vec3(m, at, "diffuse", mat.diffuse);
    mat.specular = r.number(m, at, "specular", mat.specular);
    mat.shininess = r.number(m, at, "shininess", mat.shininess);
    mat.reflectivity = r.number(m, at, "reflectivity", mat.reflectivity);
    mat.transparency = r.number(m, at, "transparency", mat.transparency);
    mat.ior = r.number(m, at, "ior", mat.ior);
    if (mat.reflectivity < 0 || mat.reflectivity > 1) r.fail(at + ".reflectivity", "must be in [0, 1]");
    if (mat.transparency < 0 || mat.transparency > 1) r.fail(at + ".transparency", "must be in [0, 1]");
    if (mat.reflectivity + mat.transparency > 1) r.fail(at, "reflectivity + transparency must not exceed 1");
    if (!(mat.ior >= 1 && mat.ior <= 4)) r.fail(at + ".ior", "must be in [1, 4]");
    if (mat.shininess < 0) r.fail(at + ".shininess", "must not be negative");
    ids[name] = static_cast<int>(s.materials.size());
    s.materials.push_back(mat);
  }
}

void read_lights(const Reader& r, const json& j, Scene& s) {
  if (!j.is_array()) r.fail("lights", "expected an array");
  for (std::size_t i = 0; i < j.size(); ++i) {
    std::string at = "lights[" + std::to_string(i) + "]";
    std::string type = j[i].is_object() ? j[i].value("type", "point") : "point";
    if (type == "disk") {
      r.only(j[i], at, {"type", "center", "normal", "radius", "color"});
      DiskLight d;
      d.centre = r.vec3(r.required(j[i], at, "center"), at + ".center");
      d.normal = r.vec3(j[i], at, "normal", d.normal);
      d.radius = r.number(j[i], at, "radius", d.radius);
      d.color = r.vec3(j[i], at, "color", d.color);
      if (d.radius < 0) r.fail(at + ".radius", "must not be negative");
      if (length(d.normal) == 0) r.fail(at + ".normal", "must not be zero");
      s.disk_lights.push_back(d);
      continue;
    }
    r.only(j[i], at, {"type", "position", "color", "intensity"});
    if (type != "point") r.fail(at + ".type", "unknown light type '" + type + "' (known: point, disk)");
    s.lights.push_back({r.vec3(r.required(j[i], at, "position"), at + ".position"), r.vec3(j[i], at, "color", {1, 1, 1}),
                        r.number(j[i], at, "intensity", 0)});
    if (s.lights.back().intensity < 0) r.fail(at + ".intensity", "must not be negative");
  }
}

Transform read_transform(const Reader& r, const json& j, const std::string& at) {
  r.only(j, at, {"translate", "scale", "rotate"});
  Transform t;
  t.translate = r.vec3(j, at, "translate", t.translate);
  t.scale = r.vec3(j, at, "scale", t.scale);
  t.rotate_degrees = r.vec3(j, at, "rotate", t.rotate_degrees);
  return t;
}

void read_object(const Reader& r, const json& o, const std::string& at, Scene& s,
                 const std::map<std::string, int>& materials) {
  if (!o.is_object()) r.fail(at, "expected an object");
  if (!o.contains("type") || !o["type"].is_string()) r.fail(at + ".type", "missing (mesh, sphere, quad or box)");
  std::string type = o["type"];
  int material = 0;
  if (o.contains("material")) {
    if (!o["material"].is_string()) r.fail(at + ".material", "expected a material name");
    auto it = materials.find(o["material"].get<std::string>());
    if (it == materials.end()) r.fail(at + ".material", "no material named '" + o["material"].get<std::string>() + "'");
    material = it->second;
  }
  if (type == "mesh") {
    r.only(o, at, {"type", "file", "material", "transform"});
    const json& file = r.required(o, at, "file");
    if (!file.is_string()) r.fail(at + ".file", "expected a path");
    std::string path = file.get<std::string>();
    if (!path.empty() && path[0] != '/') path = directory_of(r.file()) + path;
    Transform t = o.contains("transform") ? read_transform(r, o["transform"], at + ".transform") : Transform{};
    try {
      load_model(s, path, t, material);
    } catch (const Error& e) {
      r.fail(at + ".file", e.what());
    }
  } else if (type == "sphere") {
    r.only(o, at, {"type", "center", "radius", "segments", "material"});
    float radius = r.number(r.required(o, at, "radius"), at + ".radius");
    if (radius <= 0) r.fail(at + ".radius", "must be positive");
    int segments = o.contains("segments") ? static_cast<int>(r.number(o["segments"], at + ".segments")) : 32;
    if (segments < 3 || segments > 4096) r.fail(at + ".segments", "must be 3 .. 4096");
    add_sphere(s, r.vec3(r.required(o, at, "center"), at + ".center"), radius, material, segments);
  } else if (type == "quad") {
    r.only(o, at, {"type", "corner", "u", "v", "material"});
    add_quad(s, r.vec3(r.required(o, at, "corner"), at + ".corner"), r.vec3(r.required(o, at, "u"), at + ".u"),
             r.vec3(r.required(o, at, "v"), at + ".v"), material);
  } else if (type == "box") {
    r.only(o, at, {"type", "min", "max", "material"});
    add_box(s, r.vec3(r.required(o, at, "min"), at + ".min"), r.vec3(r.required(o, at, "max"), at + ".max"), material);
  } else {
    r.fail(at + ".type", "unknown object type '" + type + "' (known: mesh, sphere, quad, box)");
  }
}

Scene read_scene(const json& j, const std::string& path);

}  // namespace

Scene load_scene_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error(path + ": cannot open the scene file");
  std::stringstream buffer;
  buffer << in.rdbuf();
  std::string text = buffer.str();
  json j;
  try {
    j = json::parse(text);
  } catch (const json::parse_error& e) {
    throw Error(path + ": " + location(text, e.byte == 0 ? 0 : e.byte - 1) + ": not valid JSON (" + e.what() + ")");
  }
  try {
    return read_scene(j, path);
  } catch (const json::exception& e) {
    // A value of the wrong JSON type where the reader did not check first.
    throw Error(path + ": " + e.what());
  }
}

namespace {

Scene read_scene(const json& j, const std::string& path) {
  Reader r(path);
  r.only(j, "", {"camera", "lights", "materials", "objects", "background", "ambient"});
  Scene s;
  s.name = path;
  std::map<std::string, int> materials;
  Material fallback;
  fallback.name = "default";
  s.materials.push_back(fallback);
  materials["default"] = 0;
  if (j.contains("camera")) s.camera = read_camera(r, j["camera"]);
  if (j.contains("materials")) read_materials(r, j["materials"], s, materials);
  if (j.contains("lights")) read_lights(r, j["lights"], s);
  s.background = r.vec3(j, "", "background", s.background);
  s.ambient = r.number(j, "", "ambient", s.ambient);
  if (!j.contains("objects") || !j["objects"].is_array() || j["objects"].empty())
    r.fail("objects", "missing or empty: the scene has nothing to trace");
  for (std::size_t i = 0; i < j["objects"].size(); ++i) {
    std::size_t before = s.mesh.triangles();
    read_object(r, j["objects"][i], "objects[" + std::to_string(i) + "]", s, materials);
    if (s.mesh.triangles() == before)
      s.warnings.push_back(path + ": objects[" + std::to_string(i) + "] has no triangles of non-zero area");
  }
  validate(s, path);
  return s;
}

}  // namespace

}  // namespace sh::rt
