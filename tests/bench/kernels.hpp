#pragma once
// The benchmark kernels, each written twice: as a DSL program and as the
// hand-written C++ it should match.  Shared by the backend benchmarks.
#include <cmath>
#include <cstdint>
#include <vector>

#include <sh/sh.hpp>

namespace bench {

inline constexpr int kMandelbrotIterations = 256;
inline constexpr int kTriangles = 32;

sh::Program saxpy_program(sh::Attrib1f& a);
void saxpy_cpp(float a, const float* x, const float* y, float* r, std::size_t begin, std::size_t end);

sh::Program mandelbrot_program();
void mandelbrot_cpp(const float* c, float* shade, std::size_t begin, std::size_t end);
std::vector<float> mandelbrot_coordinates(int size);

// Rays against a table of triangles (Möller–Trumbore), nearest hit.
struct TriangleScene {
  std::vector<float> vertices;  // 3 vertices x 3 floats per triangle
  std::vector<float> origins, directions;
};
TriangleScene triangle_scene(std::size_t rays);
sh::Program triangles_program(const sh::Table1D<sh::Attrib3f>& vertices);
void triangles_cpp(const TriangleScene& s, float* t, std::size_t begin, std::size_t end);

}  // namespace bench
