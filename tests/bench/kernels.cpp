#include "kernels.hpp"

#include <random>

namespace bench {

using namespace sh;

Program saxpy_program(Attrib1f& a) {
  return SH_BEGIN_PROGRAM("saxpy") {
    InputAttrib1f x;
    InputAttrib1f y;
    OutputAttrib1f r;
    r = a * x + y;
  } SH_END;
}

void saxpy_cpp(float a, const float* x, const float* y, float* r, std::size_t begin, std::size_t end) {
  for (std::size_t i = begin; i < end; ++i) r[i] = a * x[i] + y[i];
}

Program mandelbrot_program() {
  return SH_BEGIN_PROGRAM("mandelbrot") {
    InputAttrib2f c;
    OutputAttrib1f shade;
    Attrib2f z = ConstAttrib2f(0.0f, 0.0f);
    Attrib1f i = 0.0f;
    SH_WHILE(i < static_cast<float>(kMandelbrotIterations) && dot(z, z) < 4.0f) {
      z = join(z(0) * z(0) - z(1) * z(1), 2.0f * z(0) * z(1)) + c;
      i += 1.0f;
    } SH_ENDWHILE;
    shade = i;
  } SH_END;
}

void mandelbrot_cpp(const float* c, float* shade, std::size_t begin, std::size_t end) {
  for (std::size_t p = begin; p < end; ++p) {
    float cx = c[2 * p], cy = c[2 * p + 1], zx = 0, zy = 0, i = 0;
    while (i < static_cast<float>(kMandelbrotIterations) && zx * zx + zy * zy < 4.0f) {
      float nx = zx * zx - zy * zy + cx;
      zy = 2.0f * zx * zy + cy;
      zx = nx;
      i += 1.0f;
    }
    shade[p] = i;
  }
}

std::vector<float> mandelbrot_coordinates(int size) {
  std::vector<float> c;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      c.push_back(-2.2f + 3.0f * (x + 0.5f) / size);
      c.push_back(-1.5f + 3.0f * (y + 0.5f) / size);
    }
  return c;
}

TriangleScene triangle_scene(std::size_t rays) {
  TriangleScene s;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (int t = 0; t < kTriangles; ++t) {
    float cx = u(rng) * 4, cy = u(rng) * 4, cz = 5 + u(rng);
    for (int v = 0; v < 3; ++v) {
      s.vertices.push_back(cx + u(rng));
      s.vertices.push_back(cy + u(rng));
      s.vertices.push_back(cz + 0.3f * u(rng));
    }
  }
  for (std::size_t r = 0; r < rays; ++r) {
    s.origins.insert(s.origins.end(), {u(rng) * 0.1f, u(rng) * 0.1f, 0.0f});
    float dx = u(rng) * 0.7f, dy = u(rng) * 0.7f, dz = 1.0f;
    float len = std::sqrt(dx * dx + dy * dy + dz * dz);
    s.directions.insert(s.directions.end(), {dx / len, dy / len, dz / len});
  }
  return s;
}

Program triangles_program(const Table1D<Attrib3f>& vertices) {
  return SH_BEGIN_PROGRAM("triangles") {
    InputPoint3f o;
    InputVector3f d;
    OutputAttrib1f nearest;
    nearest = 1e30f;
    SH_FOR(Attrib1i i = 0, i < kTriangles, i += 1) {
      Attrib3f v0 = vertices[3 * i], v1 = vertices[3 * i + 1], v2 = vertices[3 * i + 2];
      Attrib3f e1 = v1 - v0, e2 = v2 - v0;
      Attrib3f p = cross(d, e2);
      Attrib1f det = dot(e1, p);
      Attrib1f inv = 1.0f / det;
      Attrib3f s = o - v0;
      Attrib1f u = dot(s, p) * inv;
      Attrib3f q = cross(s, e1);
      Attrib1f v = dot(d, q) * inv;
      Attrib1f t = dot(e2, q) * inv;
      Attrib1f hit = abs(det) > 1e-8f && u >= 0.0f && v >= 0.0f && u + v <= 1.0f && t > 1e-6f && t < nearest;
      nearest = cond(hit, t, nearest);
    } SH_ENDFOR;
  } SH_END;
}

void triangles_cpp(const TriangleScene& s, float* out, std::size_t begin, std::size_t end) {
  const float* V = s.vertices.data();
  for (std::size_t r = begin; r < end; ++r) {
    const float* o = &s.origins[3 * r];
    const float* d = &s.directions[3 * r];
    float nearest = 1e30f;
    for (int i = 0; i < kTriangles; ++i) {
      const float *v0 = V + 9 * i, *v1 = v0 + 3, *v2 = v0 + 6;
      float e1[3] = {v1[0] - v0[0], v1[1] - v0[1], v1[2] - v0[2]};
      float e2[3] = {v2[0] - v0[0], v2[1] - v0[1], v2[2] - v0[2]};
      float p[3] = {d[1] * e2[2] - d[2] * e2[1], d[2] * e2[0] - d[0] * e2[2], d[0] * e2[1] - d[1] * e2[0]};
      float det = e1[0] * p[0] + e1[1] * p[1] + e1[2] * p[2];
      float inv = 1.0f / det;
      float sv[3] = {o[0] - v0[0], o[1] - v0[1], o[2] - v0[2]};
      float u = (sv[0] * p[0] + sv[1] * p[1] + sv[2] * p[2]) * inv;
      float q[3] = {sv[1] * e1[2] - sv[2] * e1[1], sv[2] * e1[0] - sv[0] * e1[2], sv[0] * e1[1] - sv[1] * e1[0]};
      float v = (d[0] * q[0] + d[1] * q[1] + d[2] * q[2]) * inv;
      float t = (e2[0] * q[0] + e2[1] * q[1] + e2[2] * q[2]) * inv;
      bool hit = std::fabs(det) > 1e-8f && u >= 0 && v >= 0 && u + v <= 1 && t > 1e-6f && t < nearest;
      nearest = hit ? t : nearest;
    }
    out[r] = nearest;
  }
}

}  // namespace bench
