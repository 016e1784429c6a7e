#pragma once
// Valid model and scene files, one per format the fuzzer mutates.
#include <string>
#include <vector>

namespace sh::fuzz {

// Where in a seed the vertex coordinates are, so that a mutation can poison
// one: text seeds list them on lines (0-based) [first_line, first_line +
// count); binary seeds hold float32 at byte offsets in `float_offsets`.
struct Seed {
  std::string format;     // obj, ply, ply-binary, stl, stl-binary, off, gltf, json
  std::string extension;  // of the file written
  std::string bytes;
  std::vector<std::size_t> vertex_lines;   // text seeds: lines holding a vertex (every vertex is used)
  std::string vertex_prefix;               // ... whose coordinates follow this prefix ("v ", "vertex ", "")
  std::vector<std::size_t> float_offsets;  // binary seeds: vertex coordinates
  std::vector<std::size_t> face_lines;     // text seeds: lines holding a face's indices
};

std::vector<Seed> seeds();

// The model a JSON seed refers to, written beside every case.
inline constexpr const char* kSceneMeshName = "seed_mesh.obj";
std::string scene_mesh();

}  // namespace sh::fuzz
