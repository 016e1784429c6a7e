#pragma once
// The benchmark kernels, each written twice: as a DSL program and as the
// hand-written C++ it should match.  Shared by the backend benchmarks.
#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include <sh/sh.hpp>

namespace bench {

// A backend's compile of `p` from nothing: the passes and legalize (what a
// backend is always given), then its compile with the kernel cache off, so
// that no compile after the first loads the first's object.  (PoCL's own
// cache is set when PoCL starts: a benchmark turns it off in its main.)
std::unique_ptr<sh::Kernel> compile_cold(sh::Backend& backend, const sh::Program& p, const sh::Options& options);

inline constexpr int kMandelbrotIterations = 256;
inline constexpr int kTriangles = 32;

sh::Program saxpy_program(sh::Attrib1f& a);
void saxpy_cpp(float a, const float* x, const float* y, float* r, std::size_t begin, std::size_t end);
// The hand-vectorised forms of saxpy, Mandelbrot and the triangles, in
// the widest vectors the host has: AVX-512 or AVX2 (simd.hpp; the
// compiler's own form where the host has neither).
void saxpy_simd(float a, const float* x, const float* y, float* r, std::size_t begin, std::size_t end);

sh::Program mandelbrot_program();
void mandelbrot_cpp(const float* c, float* shade, std::size_t begin, std::size_t end);
void mandelbrot_simd(const float* c, float* shade, std::size_t begin, std::size_t end);
std::vector<float> mandelbrot_coordinates(int size);

// Rays against a table of triangles (Möller–Trumbore), nearest hit.
struct TriangleScene {
  std::vector<float> vertices;  // 3 vertices x 3 floats per triangle
  std::vector<float> origins, directions;
};
TriangleScene triangle_scene(std::size_t rays);
sh::Program triangles_program(const sh::Table1D<sh::Attrib3f>& vertices);
void triangles_cpp(const TriangleScene& s, float* t, std::size_t begin, std::size_t end);
void triangles_simd(const TriangleScene& s, float* t, std::size_t begin, std::size_t end);

// A 5 x 5 box blur of a W x H image, edges clamped: direct (25 taps), and
// separable (5 along rows into a W x H image, then 5 down its columns).
// The C++ forms cover rows [y0, y1): the plain loop (every tap clamped, as
// the DSL program reads), the same loop written for the auto-vectoriser (a
// clamp-free inner loop for the image's interior), and a hand-vectorised
// form.
// All add their taps in the same order, so every form gives the same bits.
inline constexpr int kBlurRadius = 2;
sh::Program blur_program(const sh::Table2D<sh::Attrib1f>& image);
sh::Program blur_rows_program(const sh::Table2D<sh::Attrib1f>& image);
sh::Program blur_columns_program(const sh::Table2D<sh::Attrib1f>& rows);
struct Image {
  const float* in;
  float* out;
  int w, h;
};
void blur_plain_cpp(const Image& im, int y0, int y1);
void blur_cpp(const Image& im, int y0, int y1);
void blur_simd(const Image& im, int y0, int y1);
void blur_rows_cpp(const Image& im, int y0, int y1);
void blur_columns_cpp(const Image& im, int y0, int y1);
// Both passes, fused in strips of rows that stay in the cache.
void blur_fused_cpp(const Image& im, int y0, int y1);
void blur_rows_simd(const Image& im, int y0, int y1);
void blur_columns_simd(const Image& im, int y0, int y1);
std::vector<float> blur_image(int w, int h);

}  // namespace bench
