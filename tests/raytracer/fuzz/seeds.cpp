#include "seeds.hpp"

#include <cstdint>
#include <cstring>

namespace sh::fuzz {
namespace {

struct Tetra {
  float p[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  int faces[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
};

std::vector<std::size_t> range(std::size_t first, std::size_t count) {
  std::vector<std::size_t> r;
  for (std::size_t i = 0; i < count; ++i) r.push_back(first + i);
  return r;
}

template <typename T>
void append(std::string& out, T value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));  // little endian, as the formats are
  out.append(bytes, sizeof(T));
}

Seed obj() {
  Seed s{"obj", "obj", "", range(1, 8), "v ", {}, range(11, 6)};
  s.bytes =
      "# a cube, half its vertices coloured\n"
      "v -1 -1 -1 1 0 0\nv 1 -1 -1 0 1 0\nv 1 1 -1 0 0 1\nv -1 1 -1 1 1 0\n"
      "v -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n"
      "vn 0 0 -1\nvn 0 0 1\n"
      "f 1//1 4//1 3//1 2//1\nf 5//2 6//2 7//2 8//2\nf 1 5 8 4\nf 2 3 7 6\nf 3 4 8 7\nf 1 2 6 5\n";
  return s;
}

const char* kPlyProperties =
    "property float x\nproperty float y\nproperty float z\n"
    "property float nx\nproperty float ny\nproperty float nz\n"
    "property uchar red\nproperty uchar green\nproperty uchar blue\n"
    "element face 4\nproperty list uchar int vertex_indices\nend_header\n";

Seed ply_ascii() {
  Tetra t;
  Seed s{"ply", "ply", "", range(16, 4), "", {}, range(20, 4)};
  s.bytes = std::string("ply\nformat ascii 1.0\ncomment a tetrahedron\nelement vertex 4\n") + kPlyProperties;
  for (auto& p : t.p)
    s.bytes += std::to_string(p[0]) + " " + std::to_string(p[1]) + " " + std::to_string(p[2]) + " 0 0 1 200 100 50\n";
  for (auto& f : t.faces) s.bytes += "3 " + std::to_string(f[0]) + " " + std::to_string(f[1]) + " " + std::to_string(f[2]) + "\n";
  return s;
}

Seed ply_binary() {
  Tetra t;
  Seed s{"ply-binary", "ply", "", {}, "", {}, {}};
  s.bytes = std::string("ply\nformat binary_little_endian 1.0\nelement vertex 4\n") + kPlyProperties;
  for (auto& p : t.p) {
    for (float c : p) {
      s.float_offsets.push_back(s.bytes.size());
      append(s.bytes, c);
    }
    for (float n : {0.f, 0.f, 1.f}) append(s.bytes, n);
    for (std::uint8_t c : {200, 100, 50}) append(s.bytes, c);
  }
  for (auto& f : t.faces) {
    append(s.bytes, std::uint8_t{3});
    for (int i : f) append(s.bytes, std::int32_t{i});
  }
  return s;
}

Seed stl_ascii() {
  Tetra t;
  Seed s{"stl", "stl", "solid tetra\n", {}, "vertex ", {}, {}};
  std::size_t line = 1;
  for (auto& f : t.faces) {
    s.bytes += "facet normal 0 0 0\n outer loop\n";
    line += 2;
    for (int i : f) {
      s.bytes += "  vertex " + std::to_string(t.p[i][0]) + " " + std::to_string(t.p[i][1]) + " " + std::to_string(t.p[i][2]) + "\n";
      s.vertex_lines.push_back(line++);
    }
    s.bytes += " endloop\nendfacet\n";
    line += 2;
  }
  s.bytes += "endsolid tetra\n";
  return s;
}

Seed stl_binary() {
  Tetra t;
  Seed s{"stl-binary", "stl", std::string(80, ' '), {}, "", {}, {}};
  s.bytes.replace(0, 15, "binary tetra   ");  // not "solid": a binary STL
  append(s.bytes, std::uint32_t{4});
  for (auto& f : t.faces) {
    for (int k = 0; k < 3; ++k) append(s.bytes, 0.f);  // normal: computed
    for (int i : f)
      for (float c : t.p[i]) {
        s.float_offsets.push_back(s.bytes.size());
        append(s.bytes, c);
      }
    append(s.bytes, std::uint16_t{0});
  }
  return s;
}

Seed off() {
  Tetra t;
  Seed s{"off", "off", "OFF\n4 4 6\n", range(2, 4), "", {}, range(6, 4)};
  for (auto& p : t.p) s.bytes += std::to_string(p[0]) + " " + std::to_string(p[1]) + " " + std::to_string(p[2]) + "\n";
  for (auto& f : t.faces) s.bytes += "3 " + std::to_string(f[0]) + " " + std::to_string(f[1]) + " " + std::to_string(f[2]) + "\n";
  return s;
}

std::string base64(const std::string& bytes) {
  const char* digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    std::uint32_t group = 0;
    int n = static_cast<int>(std::min<std::size_t>(3, bytes.size() - i));
    for (int k = 0; k < 3; ++k) group = group << 8 | (k < n ? static_cast<std::uint8_t>(bytes[i + k]) : 0);
    for (int k = 0; k < 4; ++k) out += k <= n ? digits[(group >> (18 - 6 * k)) & 63] : '=';
  }
  return out;
}

// One triangle, its buffer embedded as a data URI.
Seed gltf() {
  std::string buffer;
  for (float c : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) append(buffer, c);
  for (std::uint16_t i : {0, 1, 2}) append(buffer, i);
  Seed s{"gltf", "gltf", "", {}, "", {}, {}};
  s.bytes = R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
"meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
"buffers": [{"byteLength": 42, "uri": "data:application/octet-stream;base64,)" + base64(buffer) + R"("}],
"bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 6}],
"accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
              {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}]}
)";
  return s;
}

Seed scene() {
  Seed s{"json", "json", "", {}, "", {}, {}};
  s.bytes = std::string(R"({"camera": {"eye": [0, 1.5, 6], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov": 45},
"background": [0.1, 0.1, 0.2], "ambient": 0.1,
"lights": [{"type": "point", "position": [2, 4, 3], "color": [1, 1, 1]},
           {"type": "disk", "center": [0, 3, 0], "normal": [0, -1, 0], "radius": 0.2}],
"materials": {"shiny": {"diffuse": [0.8, 0.2, 0.2], "reflectivity": 0.3, "specular": 0.5, "shininess": 40},
              "glass": {"type": "glass"}},
"objects": [{"type": "sphere", "center": [-1, 0, 0], "radius": 0.6, "segments": 12, "material": "shiny"},
            {"type": "quad", "corner": [-3, -1, -3], "u": [0, 0, 6], "v": [6, 0, 0]},
            {"type": "box", "min": [0.5, -1, -0.5], "max": [1.5, 0, 0.5], "material": "glass"},
            {"type": "mesh", "file": ")") + kSceneMeshName + R"(", "transform": {"translate": [0, 1, -1], "scale": 0.5, "rotate": [0, 30, 0]}}]}
)";
  return s;
}

}  // namespace

std::string scene_mesh() { return "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n"; }

std::vector<Seed> seeds() { return {obj(), ply_ascii(), ply_binary(), stl_ascii(), stl_binary(), off(), gltf(), scene()}; }

}  // namespace sh::fuzz
