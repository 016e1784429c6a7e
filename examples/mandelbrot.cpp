// The Mandelbrot set: a data-dependent loop per pixel, written as a PNG.
//   mandelbrot [output.png] [size]
#include <png.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <sh/sh.hpp>

using namespace sh;

Attrib1f max_iterations = 256.0f;

// Writes an 8-bit RGB PNG through a temporary file, so a failed write never
// leaves a half-written image under the real name.
bool write_png(const std::string& path, int w, int h, const std::vector<unsigned char>& rgb) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  image.width = static_cast<png_uint_32>(w);
  image.height = static_cast<png_uint_32>(h);
  image.format = PNG_FORMAT_RGB;
  std::string tmp = path + ".tmp";
  if (!png_image_write_to_file(&image, tmp.c_str(), 0, rgb.data(), 0, nullptr)) {
    std::fprintf(stderr, "mandelbrot: cannot write %s: %s\n", tmp.c_str(), image.message);
    return false;
  }
  return std::rename(tmp.c_str(), path.c_str()) == 0;
}

int main(int argc, char** argv) {
  if (argc > 1 && argv[1][0] == '-') {  // --help, or an option this example does not have
    std::printf("usage: mandelbrot [OUT.png [SIZE]]  (defaults: mandelbrot.png, 512; backend: SH_BACKEND)\n");
    return argv[1] == std::string("--help") || argv[1] == std::string("-h") ? 0 : 2;
  }
  std::string out = argc > 1 ? argv[1] : "mandelbrot.png";
  int size = argc > 2 ? std::atoi(argv[2]) : 512;
  if (size < 1 || size > 16384) {
    std::fprintf(stderr, "mandelbrot: size must be 1..16384, got %s\n", argc > 2 ? argv[2] : "?");
    return 2;
  }

  Program mandel = SH_BEGIN_PROGRAM("mandelbrot") {
    InputAttrib2f c;
    OutputAttrib1f shade;
    Attrib2f z = ConstAttrib2f(0.0f, 0.0f);
    Attrib1f i = 0.0f;
    SH_WHILE(i < max_iterations && dot(z, z) < 4.0f) {
      z = join(z(0) * z(0) - z(1) * z(1), 2.0f * z(0) * z(1)) + c;
      i += 1.0f;
    } SH_ENDWHILE;
    shade = i / max_iterations;
  } SH_END;

  std::vector<float> coords;
  coords.reserve(static_cast<std::size_t>(size) * size * 2);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      coords.push_back(-2.2f + 3.0f * (x + 0.5f) / size);
      coords.push_back(-1.5f + 3.0f * (y + 0.5f) / size);
    }
  Channel<Attrib2f> c(coords);
  Channel<Attrib1f> shade;
  RunStats s = run(mandel, {c}, {shade});

  std::vector<unsigned char> rgb(static_cast<std::size_t>(size) * size * 3);
  for (std::size_t p = 0; p < shade.size(); ++p) {
    float t = shade[p];
    rgb[3 * p] = static_cast<unsigned char>(255 * t);
    rgb[3 * p + 1] = static_cast<unsigned char>(255 * t * t);
    rgb[3 * p + 2] = static_cast<unsigned char>(t < 1 ? 255 * (1 - t) * t * 4 > 255 ? 255 : 255 * (1 - t) * t * 4 : 0);
  }
  if (!write_png(out, size, size, rgb)) return 1;
  std::printf("mandelbrot: %dx%d on %s in %.1f ms (compile %.1f ms); image: %s\n", size, size, s.backend.c_str(),
              s.run_ms, s.compile_ms, out.c_str());
  return 0;
}
