// Model files through assimp: OBJ, PLY, STL, glTF, OFF, NFF and more.
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <assimp/DefaultLogger.hpp>
#include <assimp/Importer.hpp>
#include <assimp/LogStream.hpp>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numbers>

#include "sh/error.hpp"
#include "input_file.hpp"
#include "model_reader.hpp"
#include "ply_header.hpp"
#include "sh/raytracer/scene.hpp"

namespace sh::rt {
namespace {

Vec3 rotate(Vec3 p, Vec3 degrees) {
  auto rad = [](float d) { return d * std::numbers::pi_v<float> / 180; };
  float cx = std::cos(rad(degrees.x)), sx = std::sin(rad(degrees.x));
  float cy = std::cos(rad(degrees.y)), sy = std::sin(rad(degrees.y));
  float cz = std::cos(rad(degrees.z)), sz = std::sin(rad(degrees.z));
  p = {p.x, cx * p.y - sx * p.z, sx * p.y + cx * p.z};
  p = {cy * p.x + sy * p.z, p.y, -sy * p.x + cy * p.z};
  return {cz * p.x - sz * p.y, sz * p.x + cz * p.y, p.z};
}

}  // namespace

Vec3 Transform::apply(Vec3 p) const {
  return rotate({p.x * scale.x, p.y * scale.y, p.z * scale.z}, rotate_degrees) + translate;
}

Vec3 Transform::apply_normal(Vec3 n) const {
  // Inverse transpose of a rotation times a diagonal scale.
  return normalize(rotate({n.x / scale.x, n.y / scale.y, n.z / scale.z}, rotate_degrees));
}

namespace {

std::string mesh_name(const aiMesh& mesh, unsigned m) {
  std::string name = "mesh " + std::to_string(m);
  return mesh.mName.length > 0 ? name + " '" + mesh.mName.C_Str() + "'" : name;
}

// Checks what assimp promises but a broken importer may not keep: arrays
// present for what the mesh claims, indices within its vertices.
void check_mesh(const aiMesh* mesh, unsigned m, const std::string& path) {
  if (!mesh) throw Error(path + ": mesh " + std::to_string(m) + " is missing");
  std::string where = path + ": " + mesh_name(*mesh, m);
  if (mesh->mNumVertices > 0 && !mesh->mVertices) throw Error(where + ": " + std::to_string(mesh->mNumVertices) + " vertices without positions");
  if (mesh->mNumFaces > 0 && !mesh->mFaces) throw Error(where + ": " + std::to_string(mesh->mNumFaces) + " faces without indices");
  for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
    const aiFace& face = mesh->mFaces[f];
    if (face.mNumIndices > 0 && !face.mIndices) throw Error(where + ", face " + std::to_string(f) + ": no vertex indices");
    for (unsigned k = 0; k < face.mNumIndices; ++k)
      if (face.mIndices[k] >= mesh->mNumVertices)
        throw Error(where + ", face " + std::to_string(f) + ": vertex index " + std::to_string(face.mIndices[k]) +
                    " is past the mesh's " + std::to_string(mesh->mNumVertices) + " vertices");
  }
}

// The transformed position of vertex i, checked against what the tracer supports.
Vec3 position(const aiMesh& mesh, unsigned m, unsigned i, const Transform& t, const std::string& path) {
  const aiVector3D& v = mesh.mVertices[i];
  Vec3 p = t.apply({v.x, v.y, v.z});
  std::string problem = coordinate_problem(p);
  if (problem.empty()) return p;
  bool moved = t.scale.x != 1 || t.scale.y != 1 || t.scale.z != 1 || length(t.translate) != 0;
  throw Error(path + ": " + mesh_name(mesh, m) + ", vertex " + std::to_string(i) + ": " + problem +
              (moved ? " (after the transform)" : ""));
}

Vec3 color(const aiMesh& mesh, unsigned m, unsigned i, const std::string& path) {
  const aiColor4D& c = mesh.mColors[0][i];
  Vec3 rgb{c.r, c.g, c.b};
  if (!finite(rgb)) throw Error(path + ": " + mesh_name(mesh, m) + ", vertex " + std::to_string(i) + ": colour is not a finite number");
  return rgb;
}

void add_mesh(const aiMesh& mesh, unsigned m, const Transform& t, const std::string& path, MeshBuilder& b) {
  for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
    const aiFace& face = mesh.mFaces[f];
    if (face.mNumIndices != 3) continue;  // points and lines
    const unsigned* i = face.mIndices;
    Vec3 p[3], n[3] = {};
    for (int k = 0; k < 3; ++k) p[k] = position(mesh, m, i[k], t, path);
    if (mesh.HasNormals())
      for (int k = 0; k < 3; ++k) {
        const aiVector3D& v = mesh.mNormals[i[k]];
        n[k] = t.apply_normal({v.x, v.y, v.z});  // a zero or NaN normal: the face's (MeshBuilder)
      }
    if (mesh.HasVertexColors(0))
      b.colored(p[0], p[1], p[2], n[0], n[1], n[2], color(mesh, m, i[0], path), color(mesh, m, i[1], path),
                color(mesh, m, i[2], path));
    else
      b.triangle(p[0], p[1], p[2], n[0], n[1], n[2]);
  }
}

// Collects what assimp reports as errors while it reads a file: an importer
// that repairs a file (OFF: an index past the vertices becomes the last
// vertex) says so only there, and the tracer passes it on as a warning.
// assimp's logger is global: loads in this process must not overlap (the
// child process of isolated_load.cpp loads one file).
class LibraryErrors {
 public:
  LibraryErrors() {
    Assimp::DefaultLogger::create("", Assimp::Logger::NORMAL, 0);
    Assimp::DefaultLogger::get()->attachStream(new Stream(messages_), Assimp::Logger::Err);
  }
  ~LibraryErrors() { Assimp::DefaultLogger::kill(); }
  LibraryErrors(const LibraryErrors&) = delete;
  LibraryErrors& operator=(const LibraryErrors&) = delete;

  void add_warnings(const std::string& path, std::vector<std::string>& warnings) const {
    for (const std::string& m : messages_) warnings.push_back(path + ": the model library reports: " + m);
  }

 private:
  static constexpr std::size_t kMostMessages = 5;

  // Materials, textures and texture coordinates of a model are not used
  // (the scene gives the material): what goes wrong with them is no news.
  static bool about_what_the_tracer_ignores(const std::string& m) {
    for (const char* word : {"material", "Material", "texture", "Texture", "uvcoords"})
      if (m.find(word) != std::string::npos) return true;
    return false;
  }

  class Stream : public Assimp::LogStream {
   public:
    explicit Stream(std::vector<std::string>& to) : to_(to) {}
    void write(const char* message) override {
      std::string m = message;
      if (auto colon = m.find(": "); m.rfind("Error", 0) == 0 && colon != std::string::npos) m.erase(0, colon + 2);
      while (!m.empty() && (m.back() == '\n' || m.back() == '\r')) m.pop_back();
      if (about_what_the_tracer_ignores(m)) return;
      if (to_.size() < kMostMessages && std::find(to_.begin(), to_.end(), m) == to_.end()) to_.push_back(m);
    }

   private:
    std::vector<std::string>& to_;
  };

  std::vector<std::string> messages_;
};

}  // namespace

Scene triangles_of(const aiScene& model, const std::string& path, const Transform& t) {
  Scene s;
  MeshBuilder b(s, 0);
  if (model.mNumMeshes > 0 && !model.mMeshes) throw Error(path + ": " + std::to_string(model.mNumMeshes) + " meshes missing");
  for (unsigned m = 0; m < model.mNumMeshes; ++m) {
    check_mesh(model.mMeshes[m], m, path);
    add_mesh(*model.mMeshes[m], m, t, path, b);
  }
  if (s.mesh.triangles() == 0)
    throw Error(path + ": the model has no triangles" +
                (b.degenerate() > 0 ? " of non-zero area (" + std::to_string(b.degenerate()) +
                                          " have zero area in single precision: is the model too small for its place?)"
                                    : ""));
  if (b.degenerate() > 0)
    s.warnings.push_back(path + ": " + std::to_string(b.degenerate()) + " zero-area triangles left out");
  return s;
}

Scene read_model_file(const std::string& path, const Transform& t) {
  check_input_file(path, "the model file");
  check_ply_header(path);
  LibraryErrors errors;
  Assimp::Importer importer;
  // Triangulate fans each polygon from its first vertex, in file order.
  // ValidateDataStructure rejects indices and counts that do not add up;
  // FindInvalidData drops normals and texture coordinates that are NaN or
  // all alike.
  unsigned flags = aiProcess_Triangulate | aiProcess_PreTransformVertices | aiProcess_ValidateDataStructure |
                   aiProcess_FindInvalidData;
  const aiScene* model = importer.ReadFile(path, flags);
  if (!model || !model->mRootNode || (model->mFlags & AI_SCENE_FLAGS_INCOMPLETE))
    throw Error(path + ": cannot load the model: " + importer.GetErrorString());
  Scene s = triangles_of(*model, path, t);
  errors.add_warnings(path, s.warnings);
  return s;
}

void load_model(Scene& scene, const std::string& path, const Transform& t, int material, const LoadLimits& limits) {
  Scene model = limits.in_process ? read_model_file(path, t) : read_model_isolated(path, t, limits);
  scene.mesh.append(model.mesh, material);
  scene.files.push_back(path);
  scene.warnings.insert(scene.warnings.end(), model.warnings.begin(), model.warnings.end());
}

Scene load_model_as_scene(const std::string& path, const LoadLimits& limits) {
  Scene s;
  s.name = path;
  Material m;
  m.name = "default";
  m.specular = 0.3f;
  s.materials.push_back(m);
  load_model(s, path, Transform{}, 0, limits);
  // Frame the model: look at its centre from the front, a light above.
  Vec3 lo = s.bounds_min(), hi = s.bounds_max(), centre = (lo + hi) * 0.5f;
  float radius = std::max(length(hi - lo) * 0.5f, 1e-6f);
  s.camera = {centre + Vec3{0, radius * 0.5f, radius * 2.6f}, centre, {0, 1, 0}, 45};
  s.lights.push_back({centre + Vec3{radius * 2, radius * 3, radius * 2}, {1, 1, 1}});
  validate(s, path);
  return s;
}

Scene load_scene(const std::string& what, const LoadLimits& limits) {
  for (const std::string& name : builtin_scene_names())
    if (what == name) return builtin_scene(name);
  auto dot = what.find_last_of('.');
  std::string ext = dot == std::string::npos ? "" : what.substr(dot + 1);
  if (ext == "json") return load_scene_file(what, limits);
  std::error_code missing;
  if (!std::filesystem::exists(what, missing))
    throw Error(what + ": no such file, and not a built-in scene (built in: " + builtin_scene_list() + ")");
  return load_model_as_scene(what, limits);
}

}  // namespace sh::rt
