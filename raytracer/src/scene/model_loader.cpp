// Model files through assimp: OBJ, PLY, STL, glTF, OFF, NFF and more.
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <assimp/Importer.hpp>
#include <cmath>
#include <fstream>
#include <numbers>

#include "sh/error.hpp"
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

void load_model(Scene& scene, const std::string& path, const Transform& t, int material) {
  if (!std::ifstream(path)) throw Error(path + ": cannot open the model file");
  Assimp::Importer importer;
  // Triangulate fans each polygon from its first vertex, in file order.
  const aiScene* model = importer.ReadFile(path, aiProcess_Triangulate | aiProcess_PreTransformVertices);
  if (!model || !model->mRootNode || (model->mFlags & AI_SCENE_FLAGS_INCOMPLETE))
    throw Error(path + ": cannot load the model: " + importer.GetErrorString());
  MeshBuilder b(scene, material);
  std::size_t before = scene.mesh.triangles();
  for (unsigned m = 0; m < model->mNumMeshes; ++m) {
    const aiMesh* mesh = model->mMeshes[m];
    auto vertex = [&](unsigned i) {
      const aiVector3D& v = mesh->mVertices[i];
      return t.apply({v.x, v.y, v.z});
    };
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines
      const unsigned* i = face.mIndices;
      Vec3 n[3] = {};
      if (mesh->HasNormals())
        for (int k = 0; k < 3; ++k) {
          const aiVector3D& v = mesh->mNormals[i[k]];
          n[k] = t.apply_normal({v.x, v.y, v.z});
        }
      if (mesh->HasVertexColors(0)) {
        auto color = [&](unsigned k) {
          const aiColor4D& c = mesh->mColors[0][k];
          return Vec3{c.r, c.g, c.b};
        };
        b.colored(vertex(i[0]), vertex(i[1]), vertex(i[2]), n[0], n[1], n[2], color(i[0]), color(i[1]), color(i[2]));
      } else {
        b.triangle(vertex(i[0]), vertex(i[1]), vertex(i[2]), n[0], n[1], n[2]);
      }
    }
  }
  if (b.degenerate() > 0)
    scene.warnings.push_back(path + ": " + std::to_string(b.degenerate()) + " zero-area triangles left out");
  if (scene.mesh.triangles() == before) throw Error(path + ": the model has no triangles");
}

Scene load_model_as_scene(const std::string& path) {
  Scene s;
  s.name = path;
  Material m;
  m.name = "default";
  m.specular = 0.3f;
  s.materials.push_back(m);
  load_model(s, path, Transform{}, 0);
  // Frame the model: look at its centre from the front, a light above.
  Vec3 lo = s.bounds_min(), hi = s.bounds_max(), centre = (lo + hi) * 0.5f;
  float radius = std::max(length(hi - lo) * 0.5f, 1e-6f);
  s.camera = {centre + Vec3{0, radius * 0.5f, radius * 2.6f}, centre, {0, 1, 0}, 45};
  s.lights.push_back({centre + Vec3{radius * 2, radius * 3, radius * 2}, {1, 1, 1}});
  validate(s, path);
  return s;
}

Scene load_scene(const std::string& what) {
  for (const std::string& name : builtin_scene_names())
    if (what == name) return builtin_scene(name);
  auto dot = what.find_last_of('.');
  std::string ext = dot == std::string::npos ? "" : what.substr(dot + 1);
  if (ext == "json") return load_scene_file(what);
  if (!std::ifstream(what))
    throw Error(what + ": no such file, and not a built-in scene (built in: cornell, spheres, procedural)");
  return load_model_as_scene(what);
}

}  // namespace sh::rt
