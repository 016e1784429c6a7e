#include <cmath>
#include <numbers>

#include "sh/raytracer/scene.hpp"

namespace sh::rt {

std::size_t add_sphere(Scene& s, Vec3 centre, float radius, int material, int segments) {
  MeshBuilder b(s, material);
  int rings = segments / 2;
  // The seam and the poles are one vertex each, not the rounding of
  // sin(pi) and cos(2 pi): a closed mesh has no cracks to slip through.
  auto point = [&](int ring, int seg) {
    if (ring == 0 || ring == rings) return Vec3{0, ring == 0 ? 1.0f : -1.0f, 0};
    float theta = std::numbers::pi_v<float> * ring / rings;
    float phi = 2 * std::numbers::pi_v<float> * (seg % segments) / segments;
    return Vec3{std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi)};
  };
  for (int r = 0; r < rings; ++r)
    for (int g = 0; g < segments; ++g) {
      Vec3 n00 = point(r, g), n01 = point(r, g + 1), n10 = point(r + 1, g), n11 = point(r + 1, g + 1);
      auto at = [&](Vec3 n) { return centre + n * radius; };
      // Pole rows have one zero-area triangle per quad: leave it out.
      if (r > 0) b.triangle(at(n00), at(n01), at(n11), n00, n01, n11);
      if (r < rings - 1) b.triangle(at(n00), at(n11), at(n10), n00, n11, n10);
    }
  return b.degenerate();
}

std::size_t add_quad(Scene& s, Vec3 corner, Vec3 edge_u, Vec3 edge_v, int material) {
  MeshBuilder b(s, material);
  Vec3 a = corner, c = corner + edge_u + edge_v;
  b.triangle(a, corner + edge_u, c);
  b.triangle(a, c, corner + edge_v);
  return b.degenerate();
}

std::size_t add_tiled_quad(Scene& s, Vec3 corner, Vec3 edge_u, Vec3 edge_v, int tiles, int material) {
  std::size_t degenerate = 0;
  for (int i = 0; i < tiles; ++i)
    for (int j = 0; j < tiles; ++j)
      degenerate += add_quad(s, corner + edge_u * (static_cast<float>(i) / tiles) + edge_v * (static_cast<float>(j) / tiles),
               edge_u * (1.0f / tiles), edge_v * (1.0f / tiles), material);
  return degenerate;
}

std::size_t add_box(Scene& s, Vec3 lo, Vec3 hi, int material) {
  Vec3 d = hi - lo;
  Vec3 x{d.x, 0, 0}, y{0, d.y, 0}, z{0, 0, d.z};
  return add_quad(s, lo, y, x, material)        // z = lo
         + add_quad(s, lo + z, x, y, material)  // z = hi
         + add_quad(s, lo, z, y, material)      // x = lo
         + add_quad(s, lo + x, y, z, material)  // x = hi
         + add_quad(s, lo, x, z, material)      // y = lo
         + add_quad(s, lo + y, z, x, material);  // y = hi
}

}  // namespace sh::rt
