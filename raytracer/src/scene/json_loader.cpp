// JSON scene files.  Every error names the file and the field (as a path
// like objects[2].radius) or, for malformed JSON, the line and column.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "input_file.hpp"
#include "sh/error.hpp"
#include "sh/raytracer/scene.hpp"

namespace sh::rt {
namespace {

using nlohmann::json;

std::string text(double v) {
  char t[32];
  std::snprintf(t, sizeof t, "%g", v);
  return t;
}

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

  // Every number a scene holds is bounded by what the tracer supports (a
  // coordinate, a scale, a radius alike).
  float number(const json& j, const std::string& at) const {
    if (!j.is_number()) fail(at, "expected a number");
    double v = j.get<double>();
    if (!std::isfinite(v)) fail(at, "must be finite");
    // As the tracer holds it: 1e18 itself rounds to the bound.
    if (std::fabs(static_cast<float>(v)) > kMaxCoordinate)
      fail(at, text(v) + " is outside the range the tracer supports (|v| <= 1e18)");
    return static_cast<float>(v);
  }

  int integer(const json& j, const std::string& at, int lo, int hi) const {
    float v = number(j, at);
    if (v != std::floor(v)) fail(at, text(v) + " is not a whole number");
    if (!(v >= lo && v <= hi)) fail(at, "must be " + std::to_string(lo) + " .. " + std::to_string(hi));
    return static_cast<int>(v);
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
    if (std::string problem = material_problem(mat); !problem.empty()) r.fail(at, problem);
    ids[name] = static_cast<int>(s.materials.size());
    s.materials.push_back(mat);
  }
}

void read_lights(const Reader& r, const json& j, Scene& s) {
  if (!j.is_array()) r.fail("lights", "expected an array");
  for (std::size_t i = 0; i < j.size(); ++i) {
    std::string at = "lights[" + std::to_string(i) + "]";
    if (j[i].is_object() && j[i].contains("type") && !j[i]["type"].is_string()) r.fail(at + ".type", "expected a string");
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

// Shapes whose triangles are too small for single precision lose them: a
// warning counts them.
void zero_area(const Reader& r, const std::string& at, std::size_t dropped, Scene& s) {
  if (dropped > 0)
    s.warnings.push_back(r.file() + ": " + at + ": " + std::to_string(dropped) + " zero-area triangles left out");
}

// Shapes are made, and models' triangles gathered, in this process, where
// no loading child's limit holds: the scene may take as much memory as a
// model's load may (a position, a normal and a material a corner and a
// triangle, twice over while the vectors grow).
void within_memory(const Reader& r, const std::string& at, std::size_t triangles, std::size_t adding,
                   const LoadLimits& limits) {
  constexpr std::size_t kBytesPerTriangle = 2 * (3 * sizeof(Vec3) * 2 + sizeof(std::int32_t));
  std::size_t mib = (triangles + adding) * kBytesPerTriangle >> 20;
  if (mib > limits.memory_mib)
    r.fail(at, "makes " + std::to_string(adding) + " triangles, and the scene would take " + std::to_string(mib) +
                   " MiB, more than the load limit of " + std::to_string(limits.memory_mib) + " MiB (--load-memory)");
}

void read_object(const Reader& r, const json& o, const std::string& at, Scene& s,
                 const std::map<std::string, int>& materials, const LoadLimits& limits) {
  if (!o.is_object()) r.fail(at, "expected an object");
  if (!o.contains("type")) r.fail(at + ".type", "missing (mesh, sphere, quad or box)");
  if (!o["type"].is_string()) r.fail(at + ".type", "expected a string (mesh, sphere, quad or box)");
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
    std::size_t before = s.mesh.triangles();
    try {
      load_model(s, path, t, material, limits);
    } catch (const Error& e) {
      r.fail(at + ".file", e.what());
    }
    // Each load is held to the limit alone; what the loads add up to, here
    // (a load in this process has no limits).
    if (!limits.in_process) within_memory(r, at + ".file", before, s.mesh.triangles() - before, limits);
  } else if (type == "sphere") {
    r.only(o, at, {"type", "center", "radius", "segments", "material"});
    float radius = r.number(r.required(o, at, "radius"), at + ".radius");
    if (radius <= 0) r.fail(at + ".radius", "must be positive");
    // Fewer than 4 segments make one ring, all pole triangles: nothing.
    int segments = o.contains("segments") ? r.integer(o["segments"], at + ".segments", 4, 4096) : 32;
    within_memory(r, at + ".segments", s.mesh.triangles(),
                  static_cast<std::size_t>(segments) * static_cast<std::size_t>(segments - 2), limits);
    std::size_t before = s.mesh.triangles();
    std::size_t dropped = add_sphere(s, r.vec3(r.required(o, at, "center"), at + ".center"), radius, material, segments);
    if (s.mesh.triangles() == before)
      r.fail(at + ".radius", text(radius) + " is too small for the sphere's place: all " + std::to_string(dropped) +
                                 " of its triangles have zero area in single precision");
    zero_area(r, at, dropped, s);
  } else if (type == "quad") {
    r.only(o, at, {"type", "corner", "u", "v", "material"});
    std::size_t dropped = add_quad(s, r.vec3(r.required(o, at, "corner"), at + ".corner"),
                                   r.vec3(r.required(o, at, "u"), at + ".u"), r.vec3(r.required(o, at, "v"), at + ".v"), material);
    if (dropped == 2) r.fail(at, "u and v span no area (parallel, zero, or too small for the quad's place)");
  } else if (type == "box") {
    r.only(o, at, {"type", "min", "max", "material"});
    std::size_t dropped = add_box(s, r.vec3(r.required(o, at, "min"), at + ".min"), r.vec3(r.required(o, at, "max"), at + ".max"),
                                  material);
    if (dropped == 12) r.fail(at, "min and max span no area (equal, or too close for the box's place)");
    zero_area(r, at, dropped, s);
  } else {
    r.fail(at + ".type", "unknown object type '" + type + "' (known: mesh, sphere, quad, box)");
  }
}

Scene read_scene(const json& j, const std::string& path, const LoadLimits& limits);

// Follows the parser through the document, so that an error it finds (a
// number out of double range, nesting deeper than a scene has) names the
// field where it happened.
class FieldTracker {
 public:
  static constexpr int kMaxDepth = 64;

  bool operator()(int depth, json::parse_event_t event, json& parsed) {
    using E = json::parse_event_t;
    if (event == E::object_start || event == E::array_start) {
      if (depth > kMaxDepth) throw Error(at() + "nested deeper than " + std::to_string(kMaxDepth) + " levels");
      frames_.push_back({event == E::array_start, 0, "", {}});
    } else if (event == E::key && !frames_.empty()) {
      Frame& f = frames_.back();
      f.key = parsed.is_string() ? parsed.get<std::string>() : "?";
      // JSON keeps the last of a key given twice: the first would vanish.
      if (!f.keys.insert(f.key).second) throw Error(at() + "given twice in one object");
    } else if (event == E::object_end || event == E::array_end) {
      if (!frames_.empty()) frames_.pop_back();
      next();
    } else if (event == E::value) {
      next();
    }
    return true;
  }

  // "objects[2].radius: ", or "" at the top level.
  std::string at() const {
    std::string path;
    for (const Frame& f : frames_) {
      if (f.array) path += "[" + std::to_string(f.index) + "]";
      else if (!f.key.empty()) path += (path.empty() ? "" : ".") + f.key;
    }
    return path.empty() ? "" : path + ": ";
  }

 private:
  struct Frame {
    bool array;
    std::size_t index;
    std::string key;
    std::set<std::string> keys;  // an object's, so far
  };
  void next() {
    if (!frames_.empty() && frames_.back().array) ++frames_.back().index;
  }
  std::vector<Frame> frames_;
};

json parse(const std::string& text, const std::string& path) {
  FieldTracker tracker;
  try {
    return json::parse(text, std::ref(tracker));
  } catch (const json::parse_error& e) {
    throw Error(path + ": " + location(text, e.byte == 0 ? 0 : e.byte - 1) + ": " + tracker.at() + "not valid JSON (" +
                e.what() + ")");
  } catch (const json::exception& e) {
    throw Error(path + ": " + tracker.at() + "not valid JSON (" + e.what() + ")");
  } catch (const Error& e) {
    throw Error(path + ": " + e.what());
  }
}

}  // namespace

Scene load_scene_file(const std::string& path, const LoadLimits& limits) {
  check_input_file(path, "the scene file");
  std::ifstream in(path);
  if (!in) throw Error(path + ": cannot open the scene file");
  std::stringstream buffer;
  buffer << in.rdbuf();
  std::string text = buffer.str();
  json j = parse(text, path);
  try {
    return read_scene(j, path, limits);
  } catch (const json::exception& e) {
    // A value of the wrong JSON type where the reader did not check first.
    throw Error(path + ": " + e.what());
  }
}

namespace {

Scene read_scene(const json& j, const std::string& path, const LoadLimits& limits) {
  Reader r(path);
  r.only(j, "", {"camera", "lights", "materials", "objects", "background", "ambient"});
  Scene s;
  s.name = path;
  s.files.push_back(path);
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
  if (j.contains("objects") && !j["objects"].is_array()) r.fail("objects", "expected an array of objects");
  if (!j.contains("objects") || j["objects"].empty()) r.fail("objects", "missing or empty: the scene has nothing to trace");
  for (std::size_t i = 0; i < j["objects"].size(); ++i)
    read_object(r, j["objects"][i], "objects[" + std::to_string(i) + "]", s, materials, limits);
  validate(s, path);
  return s;
}

}  // namespace

}  // namespace sh::rt
