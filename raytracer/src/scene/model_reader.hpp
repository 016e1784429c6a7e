#pragma once
// Reading model files, inside the library: the checked walk over what
// assimp returns, the read itself, and the read in a child process.
#include <string>

#include "sh/raytracer/scene.hpp"

struct aiScene;

namespace sh::rt {

// The model's triangles (material 0) and warnings, in a scene of their own.
// Every pointer, index and coordinate assimp hands over is checked; a bad
// one throws sh::Error naming the file, the mesh and the face or vertex.
Scene triangles_of(const aiScene& model, const std::string& path, const Transform& t);

// Reads the file with assimp in this process.
Scene read_model_file(const std::string& path, const Transform& t);

// read_model_file in a child process under the limits (isolated_load.cpp).
Scene read_model_isolated(const std::string& path, const Transform& t, const LoadLimits& limits);

}  // namespace sh::rt
