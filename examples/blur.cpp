// A box blur written as stencils (docs/stencils.md): each pixel reads its
// neighbours in a table at offsets from position(), edges clamped.  Once
// directly, (2r+1)^2 taps; once separably, 2r+1 taps along the rows into an
// image whose memory the columns' table reads in place; and once more
// separably with the two passes fused in strips of rows (run_fused).
// Writes the image and its blur side by side as a PNG.
//   blur [output.png] [size] [radius]
#include <png.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <sh/sh.hpp>

using namespace sh;

// Writes an 8-bit grey PNG through a temporary file, so a failed write
// never leaves a half-written image under the real name.
bool write_png(const std::string& path, int w, int h, const std::vector<unsigned char>& grey) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  image.width = static_cast<png_uint_32>(w);
  image.height = static_cast<png_uint_32>(h);
  image.format = PNG_FORMAT_GRAY;
  std::string tmp = path + ".tmp";
  if (!png_image_write_to_file(&image, tmp.c_str(), 0, grey.data(), 0, nullptr)) {
    std::fprintf(stderr, "blur: cannot write %s: %s\n", tmp.c_str(), image.message);
    return false;
  }
  return std::rename(tmp.c_str(), path.c_str()) == 0;
}

// The taps are unrolled here, on the host: each is a read at a constant
// offset, which the cpu backend loads as a vector of neighbours.
Program box(const Table2D<Attrib1f>& image, int radius) {
  return SH_BEGIN_PROGRAM("box") {
    OutputAttrib1f out;
    Attrib2i at = position<2>();
    Attrib1f sum = 0.0f;
    for (int dy = -radius; dy <= radius; ++dy)
      for (int dx = -radius; dx <= radius; ++dx) sum += image[at + ConstAttrib2i(dx, dy)];
    out = sum / static_cast<float>((2 * radius + 1) * (2 * radius + 1));
  } SH_END;
}

// One pass of the separable form: 2r+1 taps along `step`.
Program line(const Table2D<Attrib1f>& image, int radius, int step_x, int step_y) {
  return SH_BEGIN_PROGRAM("line") {
    OutputAttrib1f out;
    Attrib2i at = position<2>();
    Attrib1f sum = 0.0f;
    for (int k = -radius; k <= radius; ++k) sum += image[at + ConstAttrib2i(k * step_x, k * step_y)];
    out = sum / static_cast<float>(2 * radius + 1);
  } SH_END;
}

int main(int argc, char** argv) {
  if (argc > 1 && argv[1][0] == '-') {  // --help, or an option this example does not have
    std::printf("usage: blur [OUT.png [SIZE [RADIUS]]]  (defaults: blur.png, 512, 4; backend: SH_BACKEND)\n");
    return argv[1] == std::string("--help") || argv[1] == std::string("-h") ? 0 : 2;
  }
  std::string out = argc > 1 ? argv[1] : "blur.png";
  int size = argc > 2 ? std::atoi(argv[2]) : 512;
  int radius = argc > 3 ? std::atoi(argv[3]) : 4;
  if (size < 1 || size > 8192 || radius < 0 || radius > 32) {
    std::fprintf(stderr, "blur: size must be 1..8192 and radius 0..32, got %s and %s\n", argc > 2 ? argv[2] : "512",
                 argc > 3 ? argv[3] : "4");
    return 2;
  }

  // Stripes and a disc: edges to blur.
  std::vector<float> pixels;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      float dx = x - size / 2.0f, dy = y - size / 2.0f;
      bool disc = dx * dx + dy * dy < size * size / 9.0f;
      pixels.push_back(disc ? 1.0f : ((x / 16 + y / 16) % 2) * 0.5f);
    }
  Table2D<Attrib1f> image(size, size);
  image.assign(pixels);

  Channel<Attrib1f> direct;
  direct.shape(static_cast<std::size_t>(size), static_cast<std::size_t>(size));
  RunStats d = run(box(image, radius), {}, {direct});

  // The rows' output is the columns' table: one memory, no copy.
  Channel<Attrib1f> rows, separable;
  rows.shape(static_cast<std::size_t>(size), static_cast<std::size_t>(size));
  separable.shape(static_cast<std::size_t>(size), static_cast<std::size_t>(size));
  Table2D<Attrib1f> rows_table(size, size);
  rows_table.memory(rows.memory());
  RunStats r = run(line(image, radius, 1, 0), {}, {rows});
  RunStats c = run(line(rows_table, radius, 0, 1), {}, {separable});

  // The same two passes in strips: the rows a strip's columns read stay in
  // the cache, and `rows_between` is only the link between the programs.
  Channel<Attrib1f> fused;
  fused.shape(static_cast<std::size_t>(size), static_cast<std::size_t>(size));
  Table2D<Attrib1f> rows_between(size, size);
  RunStats f = run_fused(line(image, radius, 1, 0), rows_between, line(rows_between, radius, 0, 1), {fused});
  if (fused.values() != separable.values()) {
    std::fprintf(stderr, "blur: the fused passes differ from the separable ones\n");
    return 1;
  }

  float largest = 0;  // the direct and separable forms add in different orders
  for (std::size_t p = 0; p < direct.size(); ++p) largest = std::max(largest, std::fabs(direct[p] - separable[p]));
  std::vector<unsigned char> grey(static_cast<std::size_t>(size) * size * 2);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      std::size_t p = static_cast<std::size_t>(y) * size + x, row = static_cast<std::size_t>(y) * size * 2;
      grey[row + x] = static_cast<unsigned char>(255 * pixels[p]);
      grey[row + size + x] = static_cast<unsigned char>(255 * direct[p]);
    }
  if (!write_png(out, 2 * size, size, grey)) return 1;
  std::printf("blur: %dx%d, radius %d, on %s: direct %.2f ms, separable %.2f + %.2f ms, fused %.2f ms (%zu strips); "
              "largest difference %.2g; image: %s\n",
              size, size, radius, d.backend.c_str(), d.run_ms, r.run_ms, c.run_ms, f.run_ms, f.strips, largest, out.c_str());
  return largest <= 1e-5f ? 0 : 1;
}
