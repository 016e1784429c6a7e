// Images: every backend agrees with the interpreter on every built-in
// scene; kernels specialised to a scene are smaller and give the image the
// general kernel gives with those features switched off.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

#include <sh/raytracer.hpp>
#include <sh/sh.hpp>

#include "helpers.hpp"

namespace {

sh::rt::Image render(const sh::rt::Scene& s, const std::string& backend, int w, int h, bool specialise = true,
                     sh::Precision precision = sh::Precision::F32) {
  sh::rt::RenderSettings settings;
  settings.width = w;
  settings.height = h;
  settings.backend = backend;
  settings.specialise = specialise;
  settings.options.precision = precision;
  return sh::rt::Renderer(s, settings).render();
}

class EveryBackend : public testing::TestWithParam<std::string> {};

TEST_P(EveryBackend, AgreesWithInterpOnEveryBuiltinScene) {
  for (const std::string& name : sh::rt::builtin_scene_names()) {
    sh::rt::Scene s = sh::rt::builtin_scene(name, 3000);
    sh::rt::Image reference = render(s, "interp", 64, 48);
    sh::rt::Image image = render(s, GetParam(), 64, 48);
    double share = sh::rt::share_within(reference, image, 1.0f / 255);
    // Backends differ in the last bits of t; where a hit falls on the edge
    // between two walls (cornell's corners: 7 of its 3072 pixels) the ray
    // leaving it starts on the other wall, and shadowed or lit turns on
    // those bits.
    EXPECT_GE(share, 0.997) << name << " on " << GetParam() << ": " << share * 100 << "% of pixels within 1/255";
    EXPECT_EQ(reference.triangle, image.triangle) << name << " on " << GetParam();
  }
}

INSTANTIATE_TEST_SUITE_P(Backends, EveryBackend, testing::ValuesIn(rt_test::backends_beside_interp()),
                         [](const testing::TestParamInfo<std::string>& i) { return i.param; });

std::size_t statements(const sh::Program& p) {
  std::string text = sh::print_optimized(p);
  return static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n'));
}

TEST(Specialisation, SceneWithoutLightsOrMirrorsGetsASmallerKernelAndTheSameImage) {
  sh::rt::Scene s = sh::rt::builtin_scene("cornell");
  s.lights.clear();
  for (sh::rt::Material& m : s.materials) m.reflectivity = 0;
  sh::rt::RenderSettings settings;
  settings.width = 48;
  settings.height = 36;
  settings.backend = "cpu";
  sh::rt::Renderer special(s, settings);
  settings.specialise = false;
  sh::rt::Renderer general(s, settings);
  EXPECT_EQ(special.features().left_out(),
            "shadow rays to point lights (none), soft shadows (no disk lights), reflection loop (no reflective material, "
            "or depth 0), vertex colours (none in the scene), refraction (no transparent material, or depth 0)");
  EXPECT_EQ(general.features().left_out(), "nothing");
  std::size_t small = statements(special.program()), big = statements(general.program());
  EXPECT_LT(small * 3, big * 2) << "specialised " << small << " vs general " << big << " IR lines";
  // The general kernel with no lights (light_count 0) and no reflective
  // material computes the same picture.
  sh::rt::Image a = special.render(), b = general.render();
  EXPECT_EQ(sh::rt::share_within(a, b, 0.0f), 1.0);
}

TEST(Specialisation, ReflectionDepthIsAUniform) {
  sh::rt::Scene s = sh::rt::builtin_scene("spheres");
  sh::rt::RenderSettings settings;
  settings.width = 32;
  settings.height = 24;
  settings.backend = "cpu";
  settings.reflections = 1;
  sh::rt::Renderer one(s, settings);
  settings.reflections = 4;
  sh::rt::Renderer four(s, settings);
  EXPECT_EQ(one.program().hash(), four.program().hash()) << "a new depth must not need a new kernel";
  EXPECT_LT(sh::rt::share_within(one.render(), four.render(), 0.0f), 1.0);
}

// NaN pixels, written black, are counted, and the first is found.
TEST(Images, NanPixelsAreCountedAndTheFirstFound) {
  sh::rt::Image img;
  img.width = 4;
  img.height = 2;
  img.rgb.assign(3 * 8, 0.5f);
  EXPECT_EQ(sh::rt::nan_pixels(img).count, 0u);
  EXPECT_EQ(sh::rt::nan_pixels(img).first, -1);
  img.rgb[3 * 5 + 2] = std::numeric_limits<float>::quiet_NaN();
  img.rgb[3 * 6] = std::numeric_limits<float>::quiet_NaN();
  img.rgb[3 * 6 + 1] = std::numeric_limits<float>::quiet_NaN();
  sh::rt::NanPixels nan = sh::rt::nan_pixels(img);
  EXPECT_EQ(nan.count, 2u);
  EXPECT_EQ(nan.first, 5);
}

// The largest difference and the PSNR compare the colours a PNG holds
// (clamped to [0, 1]); a NaN is an infinite difference, where the largest
// of the others would hide it.
TEST(Images, DifferencesAreOfTheClampedColoursAndANanIsInfinite) {
  sh::rt::Image a;
  a.width = 2;
  a.height = 1;
  a.rgb.assign(6, 0.5f);
  sh::rt::Image b = a;
  EXPECT_EQ(sh::rt::max_difference(a, b), 0.0f);
  EXPECT_EQ(sh::rt::psnr(a, b), INFINITY);
  b.rgb[0] = 0.75f;
  b.rgb[1] = 7.0f;  // 1 once clamped
  EXPECT_FLOAT_EQ(sh::rt::max_difference(a, b), 0.5f);
  b.rgb[4] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(sh::rt::max_difference(a, b), INFINITY);
  EXPECT_EQ(sh::rt::max_difference(b, a), INFINITY);
}

// Written under a name of their own, then renamed: a file of the user's
// beside the image is left alone, and a failure says why.
TEST(Images, PngAndPfmAreWrittenWhole) {
  sh::rt::Image img = render(sh::rt::builtin_scene("cornell"), "cpu", 20, 10);
  std::string dir = testing::TempDir() + "images_" + std::to_string(::getpid());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  std::ofstream(dir + "/out.png.tmp") << "the user's";
  sh::rt::write_png(dir + "/out.png", img);
  sh::rt::write_pfm(dir + "/out.pfm", img.width, img.height, img.distance);
  std::ifstream png(dir + "/out.png", std::ios::binary);
  char magic[8];
  png.read(magic, 8);
  EXPECT_EQ(std::string(magic + 1, 3), "PNG");
  EXPECT_EQ(std::filesystem::file_size(dir + "/out.pfm"), std::string("Pf\n20 10\n-1.0\n").size() + 200 * 4);
  std::string kept;
  std::getline(std::ifstream(dir + "/out.png.tmp"), kept);
  EXPECT_EQ(kept, "the user's");
  for (const auto& entry : std::filesystem::directory_iterator(dir))
    EXPECT_EQ(entry.path().extension() == ".tmp", entry.path().filename() == "out.png.tmp") << entry.path();
  EXPECT_THROW(sh::rt::write_png("/nonexistent-dir/x.png", img), sh::Error);
  std::filesystem::create_directories(dir + "/a-directory.png");
  for (bool pfm : {false, true})
    try {
      if (pfm)
        sh::rt::write_pfm(dir + "/a-directory.png", img.width, img.height, img.distance);
      else
        sh::rt::write_png(dir + "/a-directory.png", img);
      ADD_FAILURE() << "an image written over a directory";
    } catch (const sh::Error& e) {
      EXPECT_NE(std::string(e.what()).find("cannot write the image: Is a directory"), std::string::npos) << e.what();
    }
  std::filesystem::remove_all(dir);
}

}  // namespace
