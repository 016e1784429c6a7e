#include <png.h>

#include <cmath>
#include <cstdio>
#include <fstream>

#include "sh/error.hpp"
#include "sh/raytracer/render.hpp"

namespace sh::rt {
namespace {

// Commits a file written under `tmp` to `path`, or removes it.
void commit(const std::string& tmp, const std::string& path, bool ok, const std::string& why) {
  if (!ok || std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    throw Error(path + ": cannot write the image" + (why.empty() ? "" : ": " + why));
  }
}

}  // namespace

void write_png(const std::string& path, const Image& image) {
  std::vector<unsigned char> bytes(image.rgb.size());
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    float v = std::isnan(image.rgb[i]) ? 0.f : std::clamp(image.rgb[i], 0.f, 1.f);
    bytes[i] = static_cast<unsigned char>(std::lround(v * 255));
  }
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  png.width = static_cast<png_uint_32>(image.width);
  png.height = static_cast<png_uint_32>(image.height);
  png.format = PNG_FORMAT_RGB;
  std::string tmp = path + ".tmp";
  bool ok = png_image_write_to_file(&png, tmp.c_str(), 0, bytes.data(), 0, nullptr) != 0;
  commit(tmp, path, ok, ok ? "" : png.message);
}

// PFM: "Pf" (one channel) header, bottom row first, little-endian floats.
void write_pfm(const std::string& path, int width, int height, const std::vector<float>& values) {
  std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary);
    out << "Pf\n" << width << " " << height << "\n-1.0\n";
    for (int y = height - 1; y >= 0; --y)
      out.write(reinterpret_cast<const char*>(values.data() + static_cast<std::size_t>(y) * width),
                static_cast<std::streamsize>(sizeof(float)) * width);
    commit(tmp, path, static_cast<bool>(out.flush()), "");
  }
}

}  // namespace sh::rt
