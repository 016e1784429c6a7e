#include <png.h>

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>

#include "sh/error.hpp"
#include "sh/raytracer/render.hpp"

namespace sh::rt {
namespace {

// Where an image is written before it takes its name: beside it (so the
// rename is atomic), under a name of this call's own, so that two writers
// of one path, or a file of the user's, never meet there.
std::string staging_name(const std::string& path) {
  static std::atomic<unsigned> calls{0};
  return path + "." + std::to_string(::getpid()) + "." + std::to_string(calls++) + ".tmp";
}

// Commits a file written under `tmp` to `path`, or removes it; `why` says
// why the writing failed (else the rename's reason is given).
void commit(const std::string& tmp, const std::string& path, bool written, std::string why) {
  if (written) {
    if (std::rename(tmp.c_str(), path.c_str()) == 0) return;
    why = std::strerror(errno);
  }
  std::remove(tmp.c_str());
  throw Error(path + ": cannot write the image" + (why.empty() ? "" : ": " + why));
}

// An image's values must be as many as its pixels ask for: a shorter
// buffer would be read past its end.
void check_values(const std::string& path, int width, int height, std::size_t values, int per_pixel) {
  if (width < 1 || height < 1 ||
      values != static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * per_pixel)
    throw Error(path + ": cannot write the image: " + std::to_string(values) + " values for " + std::to_string(width) +
                "x" + std::to_string(height) + " pixels of " + std::to_string(per_pixel));
}

}  // namespace

void write_png(const std::string& path, const Image& image) {
  check_values(path, image.width, image.height, image.rgb.size(), 3);
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
  std::string tmp = staging_name(path);
  bool ok = png_image_write_to_file(&png, tmp.c_str(), 0, bytes.data(), 0, nullptr) != 0;
  commit(tmp, path, ok, ok ? "" : png.message);
}

// PFM: "Pf" (one channel) header, bottom row first, little-endian floats.
void write_pfm(const std::string& path, int width, int height, const std::vector<float>& values) {
  check_values(path, width, height, values.size(), 1);
  std::string tmp = staging_name(path);
  {
    std::ofstream out(tmp, std::ios::binary);
    if (!out) commit(tmp, path, false, std::strerror(errno));
    out << "Pf\n" << width << " " << height << "\n-1.0\n";
    for (int y = height - 1; y >= 0; --y)
      out.write(reinterpret_cast<const char*>(values.data() + static_cast<std::size_t>(y) * width),
                static_cast<std::streamsize>(sizeof(float)) * width);
    commit(tmp, path, static_cast<bool>(out.flush()), "");
  }
}

}  // namespace sh::rt
