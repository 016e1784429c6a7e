// Scene files and models: what loads, and every bad input an error that
// names the file and the field or line, never a crash.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <random>

#include <sh/raytracer.hpp>

#include "helpers.hpp"

namespace {


class SceneFiles : public rt_test::FilesTest {
 protected:
  void expect_error(const std::string& path, std::initializer_list<const char*> fragments) {
    try {
      sh::rt::load_scene(path);
      FAIL() << "expected an error loading " << path;
    } catch (const sh::Error& e) {
      for (const char* f : fragments) EXPECT_NE(std::string(e.what()).find(f), std::string::npos) << e.what();
    }
  }
};

const char* kCube = R"(v -1 -1 -1
v 1 -1 -1
v 1 1 -1
v -1 1 -1
v -1 -1 1
v 1 -1 1
v 1 1 1
v -1 1 1
f 1 2 3 4
f 5 8 7 6
f 1 5 6 2
f 2 6 7 3
f 3 7 8 4
f 5 1 4 8
)";

TEST_F(SceneFiles, JsonSceneWithEveryKindOfObject) {
  write("cube.obj", kCube);
  std::string path = write("scene.json", R"({
    "camera": {"eye": [0, 2, 8], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov": 40},
    "background": [0.1, 0.2, 0.3],
    "ambient": 0.2,
    "lights": [{"type": "point", "position": [2, 5, 3], "color": [1, 1, 1]}],
    "materials": {"mirror": {"diffuse": [0.1, 0.1, 0.1], "reflectivity": 0.8, "specular": 0.5, "shininess": 80},
                  "red": {"diffuse": [0.8, 0.1, 0.1], "transparency": 0.5, "ior": 1.5}},
    "objects": [
      {"type": "mesh", "file": "cube.obj", "material": "red", "transform": {"translate": [2, 0, 0], "scale": 0.5, "rotate": [0, 45, 0]}},
      {"type": "sphere", "center": [-1, 0, 0], "radius": 0.7, "segments": 16, "material": "mirror"},
      {"type": "quad", "corner": [-5, -1, -5], "u": [0, 0, 10], "v": [10, 0, 0]},
      {"type": "box", "min": [0, -1, -3], "max": [1, 0, -2]}
    ]})");
  sh::rt::Scene s = sh::rt::load_scene(path);
  EXPECT_EQ(s.mesh.triangles(), 12u + 16u * 8u * 2u - 2u * 16u + 2u + 12u);
  EXPECT_EQ(s.materials.size(), 3u);
  EXPECT_TRUE(s.has_reflections());
  EXPECT_FLOAT_EQ(s.camera.fov_degrees, 40);
  EXPECT_FLOAT_EQ(s.materials[2].ior, 1.5f);
  // Polygons are fanned in file order: the first quad gives triangles 0, 1.
  EXPECT_FLOAT_EQ(s.mesh.positions[0].x, 2 + 0.5f * -std::cos(3.14159265f / 4) - 0.5f * std::sin(3.14159265f / 4));
  sh::rt::RenderSettings settings;
  settings.width = 32;
  settings.height = 24;
  sh::rt::Image img = sh::rt::Renderer(s, settings).render();
  EXPECT_EQ(img.rgb.size(), 32u * 24u * 3u);
}

TEST_F(SceneFiles, BareModelFileIsFramedByDefaultCameraAndLight) {
  std::string path = write("cube.obj", kCube);
  sh::rt::Scene s = sh::rt::load_scene(path);
  EXPECT_EQ(s.mesh.triangles(), 12u);
  EXPECT_EQ(s.lights.size(), 1u);
  sh::rt::RenderSettings settings;
  settings.width = 32;
  settings.height = 32;
  sh::rt::Image img = sh::rt::Renderer(s, settings).render();
  EXPECT_GE(img.triangle[16 * 32 + 16], 0) << "the model is in the middle of the picture";
}

TEST_F(SceneFiles, PlyModelLoads) {
  std::string path = write("tri.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                                      "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
                                      "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  EXPECT_EQ(sh::rt::load_scene(path).mesh.triangles(), 1u);
}

TEST_F(SceneFiles, MissingFile) { expect_error((dir_ / "nope.json").string(), {"nope.json", "cannot open"}); }

TEST_F(SceneFiles, MalformedJsonNamesLineAndColumn) {
  expect_error(write("bad.json", "{\n  \"camera\": {\n    \"eye\": [0, 1 2]\n  }\n}\n"), {"bad.json", "line 3", "not valid JSON"});
}

TEST_F(SceneFiles, UnknownFieldIsNamed) {
  expect_error(write("typo.json", R"({"objects": [{"type": "sphere", "center": [0,0,0], "radus": 1}]})"),
               {"typo.json", "objects[0].radus", "unknown field"});
  expect_error(write("typo2.json", R"({"camera": {"fov": 40, "eyes": [0,0,1]}, "objects": []})"), {"camera.eyes", "unknown field"});
}

TEST_F(SceneFiles, WrongTypesAndValuesAreNamed) {
  expect_error(write("t1.json", R"({"objects": [{"type": "sphere", "center": [0,0], "radius": 1}]})"),
               {"objects[0].center", "[x, y, z]"});
  expect_error(write("t2.json", R"({"objects": [{"type": "sphere", "center": [0,0,0], "radius": -1}]})"),
               {"objects[0].radius", "positive"});
  expect_error(write("t3.json", R"({"objects": [{"type": "cone"}]})"), {"objects[0].type", "unknown object type"});
  expect_error(write("t4.json", R"({"objects": [{"type": "sphere", "center": [0,0,0], "radius": 1, "material": "gold"}]})"),
               {"objects[0].material", "no material named 'gold'"});
  expect_error(write("t5.json", R"({"lights": [{"type": 5}], "objects": []})"), {"t5.json", "lights[0].type", "expected a string"});
  expect_error(write("t6.json", R"({"camera": {"eye": [0,0,10], "look_at": [0,0,0], "up": [0,0,1e-23]},
                                     "objects": [{"type": "sphere", "center": [0,0,0], "radius": 1}]})"),
               {"t6.json", "camera: up is parallel to the view direction, or too short"});
  // A scene too small for single precision to trace is refused by name; one
  // at the least span it allows loads.
  expect_error(write("t8.json", R"({"camera": {"eye": [0,0,4e-18], "look_at": [0,0,0]},
                                     "objects": [{"type": "sphere", "center": [0,0,0], "radius": 1e-18}]})"),
               {"t8.json", "the scene spans only 2e-18", "scale it up"});
  sh::rt::Scene small = sh::rt::load_scene(write("t9.json", R"({"camera": {"eye": [0,0,4e-16], "look_at": [0,0,0]},
                                     "objects": [{"type": "sphere", "center": [0,0,0], "radius": 1e-16}]})"));
  EXPECT_EQ(small.mesh.triangles() > 0, true);
  // A short up that is not parallel makes a frame (the camera's vectors
  // are normalised in double).
  sh::rt::Scene short_up = sh::rt::load_scene(write("t7.json", R"({"camera": {"eye": [0,0,10], "look_at": [0,0,0], "up": [0,1e-23,0]},
                                     "objects": [{"type": "sphere", "center": [0,0,0], "radius": 1}]})"));
  EXPECT_EQ(short_up.camera.up.y, 1e-23f);
}

TEST_F(SceneFiles, MeshThatFailsToLoad) {
  write("broken.obj", "this is not an obj file\nf 1 2 3 4 5\n");
  expect_error(write("m.json", R"({"objects": [{"type": "mesh", "file": "broken.obj"}]})"), {"m.json", "objects[0].file", "broken.obj"});
  expect_error(write("m2.json", R"({"objects": [{"type": "mesh", "file": "missing.obj"}]})"),
               {"objects[0].file", "missing.obj", "cannot open"});
}

TEST_F(SceneFiles, NanVertexIsRejected) {
  std::string path = write("nan.obj", "v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n");
  try {
    sh::rt::load_scene(path);
    FAIL() << "a NaN vertex must not load";
  } catch (const sh::Error& e) {
    std::string m = e.what();
    EXPECT_NE(m.find("nan.obj"), std::string::npos) << m;
  }
}

TEST_F(SceneFiles, ZeroAreaTrianglesWarn) {
  std::string path = write("flat.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nf 1 2 3\nf 1 2 4\n");
  sh::rt::Scene s = sh::rt::load_scene(path);
  EXPECT_EQ(s.mesh.triangles(), 1u);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("1 zero-area triangles left out"), std::string::npos) << s.warnings[0];
}

TEST_F(SceneFiles, EmptySceneIsAnError) {
  expect_error(write("empty.json", R"({"objects": []})"), {"empty.json", "objects", "nothing to trace"});
  expect_error(write("empty2.json", "{}"), {"empty2.json", "objects"});
}

TEST_F(SceneFiles, GarbledFilesAreErrorsNotCrashes) {
  const std::string good = R"({"camera": {"eye": [0, 1, 4], "fov": 40},
    "lights": [{"type": "point", "position": [1, 2, 3]}, {"type": "disk", "center": [0, 3, 0], "radius": 0.2}],
    "materials": {"m": {"diffuse": [0.5, 0.5, 0.5], "reflectivity": 0.3}},
    "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"},
                {"type": "quad", "corner": [-2, -1, -2], "u": [0, 0, 4], "v": [4, 0, 0]}]})";
  EXPECT_NO_THROW(sh::rt::load_scene(write("good.json", good)));
  std::mt19937 rng(7);
  const std::string alphabet = "{}[]\",:0123456789.-e truefalsn";
  int errors = 0;
  for (int trial = 0; trial < 300; ++trial) {
    std::string text = good;
    for (int k = 0; k < 2; ++k) text[rng() % text.size()] = alphabet[rng() % alphabet.size()];
    std::string path = write("garbled.json", text);
    try {
      sh::rt::load_scene(path);
    } catch (const sh::Error& e) {
      ++errors;
      EXPECT_NE(std::string(e.what()).find("garbled.json"), std::string::npos) << e.what();
    }
  }
  EXPECT_GT(errors, 100);
}

TEST(BuiltinScenes, UnknownNameAndBadTriangleCount) {
  EXPECT_THROW(sh::rt::builtin_scene("teapot"), sh::Error);
  EXPECT_THROW(sh::rt::builtin_scene("procedural", 10), sh::Error);
  sh::rt::Scene p = sh::rt::builtin_scene("procedural", 10000);
  EXPECT_GT(p.mesh.triangles(), 5000u);
  EXPECT_LT(p.mesh.triangles(), 20000u);
}

}  // namespace
