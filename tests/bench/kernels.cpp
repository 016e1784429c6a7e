#include "kernels.hpp"

#include <immintrin.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <utility>

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

namespace bench {
namespace {

constexpr int kTaps = 2 * kBlurRadius + 1;
constexpr float kBoxWeight = 1.0f / (kTaps * kTaps);
constexpr float kLineWeight = 1.0f / kTaps;

int clamped(int v, int n) { return v < 0 ? 0 : v >= n ? n - 1 : v; }

// Runs row(y, its output) for the rows [y0, y1).
template <class Row>
void each_row(const Image& im, int y0, int y1, Row row) {
  for (int y = y0; y < y1; ++y) row(y, im.out + static_cast<std::size_t>(y) * im.w);
}

const float* row_at(const Image& im, int y) { return im.in + static_cast<std::size_t>(clamped(y, im.h)) * im.w; }

// The blur's one pixel at x, clamping x: the form for the image's edges.
float box_at(const Image& im, int y, int x) {
  float sum = 0;
  for (int dy = -kBlurRadius; dy <= kBlurRadius; ++dy)
    for (int dx = -kBlurRadius; dx <= kBlurRadius; ++dx) sum += row_at(im, y + dy)[clamped(x + dx, im.w)];
  return sum * kBoxWeight;
}

// The pixels whose taps all lie inside the row: [lo, hi).
int interior_lo(const Image&) { return kBlurRadius; }
int interior_hi(const Image& im) { return im.w - kBlurRadius; }

}  // namespace

Program blur_program(const Table2D<Attrib1f>& image) {
  return SH_BEGIN_PROGRAM("blur") {
    OutputAttrib1f out;
    Attrib2i at = position<2>();
    Attrib1f sum = 0.0f;
    for (int dy = -kBlurRadius; dy <= kBlurRadius; ++dy)
      for (int dx = -kBlurRadius; dx <= kBlurRadius; ++dx) sum += image[at + ConstAttrib2i(dx, dy)];
    out = sum * kBoxWeight;
  } SH_END;
}

Program blur_rows_program(const Table2D<Attrib1f>& image) {
  return SH_BEGIN_PROGRAM("blur_rows") {
    OutputAttrib1f out;
    Attrib2i at = position<2>();
    Attrib1f sum = 0.0f;
    for (int dx = -kBlurRadius; dx <= kBlurRadius; ++dx) sum += image[at + ConstAttrib2i(dx, 0)];
    out = sum * kLineWeight;
  } SH_END;
}

Program blur_columns_program(const Table2D<Attrib1f>& rows) {
  return SH_BEGIN_PROGRAM("blur_columns") {
    OutputAttrib1f out;
    Attrib2i at = position<2>();
    Attrib1f sum = 0.0f;
    for (int dy = -kBlurRadius; dy <= kBlurRadius; ++dy) sum += rows[at + ConstAttrib2i(0, dy)];
    out = sum * kLineWeight;
  } SH_END;
}

void blur_plain_cpp(const Image& im, int y0, int y1) {
  each_row(im, y0, y1, [&](int y, float* out) {
    for (int x = 0; x < im.w; ++x) out[x] = box_at(im, y, x);
  });
}

void blur_cpp(const Image& im, int y0, int y1) {
  each_row(im, y0, y1, [&](int y, float* out) {
    const float* r[kTaps];
    for (int k = 0; k < kTaps; ++k) r[k] = row_at(im, y + k - kBlurRadius);
    for (int x = 0; x < std::min(interior_lo(im), im.w); ++x) out[x] = box_at(im, y, x);
    for (int x = interior_lo(im); x < interior_hi(im); ++x) {
      float sum = 0;
      for (int k = 0; k < kTaps; ++k)
        for (int dx = -kBlurRadius; dx <= kBlurRadius; ++dx) sum += r[k][x + dx];
      out[x] = sum * kBoxWeight;
    }
    for (int x = std::max(interior_hi(im), interior_lo(im)); x < im.w; ++x) out[x] = box_at(im, y, x);
  });
}

namespace {

// Row y of the rows' pass into `out`.
void row_pass(const Image& im, int y, float* out) {
  const float* r = row_at(im, y);
  auto at = [&](int x) {
    float sum = 0;
    for (int dx = -kBlurRadius; dx <= kBlurRadius; ++dx) sum += r[clamped(x + dx, im.w)];
    return sum * kLineWeight;
  };
  for (int x = 0; x < std::min(interior_lo(im), im.w); ++x) out[x] = at(x);
  for (int x = interior_lo(im); x < interior_hi(im); ++x) {
    float sum = 0;
    for (int dx = -kBlurRadius; dx <= kBlurRadius; ++dx) sum += r[x + dx];
    out[x] = sum * kLineWeight;
  }
  for (int x = std::max(interior_hi(im), interior_lo(im)); x < im.w; ++x) out[x] = at(x);
}

// A row of the columns' pass from the kTaps rows it reads.
void column_pass(const float* const* r, int w, float* out) {
  for (int x = 0; x < w; ++x) {
    float sum = 0;
    for (int k = 0; k < kTaps; ++k) sum += r[k][x];
    out[x] = sum * kLineWeight;
  }
}

// Output rows of a fused strip: a strip's rows pass stays in the cache.
constexpr int kFusedRows = 64;

}  // namespace

void blur_rows_cpp(const Image& im, int y0, int y1) {
  each_row(im, y0, y1, [&](int y, float* out) { row_pass(im, y, out); });
}

void blur_columns_cpp(const Image& im, int y0, int y1) {
  each_row(im, y0, y1, [&](int y, float* out) {
    const float* r[kTaps];
    for (int k = 0; k < kTaps; ++k) r[k] = row_at(im, y + k - kBlurRadius);
    column_pass(r, im.w, out);
  });
}

void blur_fused_cpp(const Image& im, int y0, int y1) {
  std::vector<float> strip(static_cast<std::size_t>(kFusedRows + 2 * kBlurRadius) * im.w);
  for (int first = y0; first < y1; first += kFusedRows) {
    int end = std::min(y1, first + kFusedRows);
    int low = clamped(first - kBlurRadius, im.h), high = clamped(end - 1 + kBlurRadius, im.h) + 1;
    for (int y = low; y < high; ++y) row_pass(im, y, strip.data() + static_cast<std::size_t>(y - low) * im.w);
    auto strip_row = [&](int y) { return strip.data() + static_cast<std::size_t>(clamped(y, im.h) - low) * im.w; };
    for (int y = first; y < end; ++y) {
      const float* r[kTaps];
      for (int k = 0; k < kTaps; ++k) r[k] = strip_row(y + k - kBlurRadius);
      column_pass(r, im.w, im.out + static_cast<std::size_t>(y) * im.w);
    }
  }
}

// AVX-512: sixteen pixels per step.  The direct blur reads each row's
// taps from two unaligned loads, of the sixteen elements from its first
// tap and the sixteen after them, each tap a lane shift of the two
// (`valignd`), as the cpu backend shares a row's loads too: five loads a
// row, four of them across a cache line, left the load port the
// bottleneck.  The passes load
// each tap.  The edges and the row's last partial step as the C++ form.
#if defined(__AVX512F__)
namespace {

// Lanes K .. K + 15 of first:next.
template <int K>
__m512 lanes_from(__m512 first, __m512 next) {
  if constexpr (K == 0)
    return first;
  else
    // The masked form: GCC 12's unmasked one reads an undefined vector.
    return _mm512_castsi512_ps(_mm512_mask_alignr_epi32(_mm512_castps_si512(first), 0xFFFF, _mm512_castps_si512(next),
                                                        _mm512_castps_si512(first), K));
}

// Sixteen results at `to`: past the cache where they start a line, as the
// cpu backend writes an output too large for it (the benchmark's all are),
// so that a line is not read before it is written.  A pass ends with a
// fence that orders them, as the kernel does.
void store_out(float* to, __m512 v) {
  if (reinterpret_cast<std::uintptr_t>(to) % 64 == 0)
    _mm512_stream_ps(to, v);
  else
    _mm512_storeu_ps(to, v);
}

// Where the steps of sixteen start: the first x on a line at or after
// `from` (the image's rows start on one).
int on_a_line(int from) { return (from + 15) / 16 * 16; }

// The row's taps added to `sum` in order, left to right.
static_assert(kTaps <= 16, "a row's taps lie in two vectors");
template <std::size_t... K>
__m512 add_row(__m512 sum, __m512 first, __m512 next, std::index_sequence<K...>) {
  ((sum = _mm512_add_ps(sum, lanes_from<static_cast<int>(K)>(first, next))), ...);
  return sum;
}

}  // namespace

void blur_simd(const Image& im, int y0, int y1) {
  each_row(im, y0, y1, [&](int y, float* out) {
    const float* r[kTaps];
    for (int k = 0; k < kTaps; ++k) r[k] = row_at(im, y + k - kBlurRadius);
    int x = 0;
    for (; x < std::min(on_a_line(interior_lo(im)), im.w); ++x) out[x] = box_at(im, y, x);
    for (; x + 16 <= interior_hi(im); x += 16) {
      __m512 sum = _mm512_setzero_ps();
      for (int k = 0; k < kTaps; ++k) {
        const float* from = r[k] + x - kBlurRadius;
        sum = add_row(sum, _mm512_loadu_ps(from), _mm512_loadu_ps(from + 16), std::make_index_sequence<kTaps>{});
      }
      store_out(out + x, _mm512_mul_ps(sum, _mm512_set1_ps(kBoxWeight)));
    }
    for (; x < im.w; ++x) out[x] = box_at(im, y, x);
  });
  _mm_sfence();
}

void blur_rows_simd(const Image& im, int y0, int y1) {
  each_row(im, y0, y1, [&](int y, float* out) {
    const float* r = row_at(im, y);
    auto at = [&](int x) {
      float sum = 0;
      for (int dx = -kBlurRadius; dx <= kBlurRadius; ++dx) sum += r[clamped(x + dx, im.w)];
      return sum * kLineWeight;
    };
    int x = 0;
    for (; x < std::min(on_a_line(interior_lo(im)), im.w); ++x) out[x] = at(x);
    for (; x + 16 <= interior_hi(im); x += 16) {
      __m512 sum = _mm512_setzero_ps();
      for (int dx = -kBlurRadius; dx <= kBlurRadius; ++dx) sum = _mm512_add_ps(sum, _mm512_loadu_ps(r + x + dx));
      store_out(out + x, _mm512_mul_ps(sum, _mm512_set1_ps(kLineWeight)));
    }
    for (; x < im.w; ++x) out[x] = at(x);
  });
  _mm_sfence();
}

void blur_columns_simd(const Image& im, int y0, int y1) {
  each_row(im, y0, y1, [&](int y, float* out) {
    const float* r[kTaps];
    for (int k = 0; k < kTaps; ++k) r[k] = row_at(im, y + k - kBlurRadius);
    int x = 0;
    for (; x + 16 <= im.w; x += 16) {
      __m512 sum = _mm512_setzero_ps();
      for (int k = 0; k < kTaps; ++k) sum = _mm512_add_ps(sum, _mm512_loadu_ps(r[k] + x));
      store_out(out + x, _mm512_mul_ps(sum, _mm512_set1_ps(kLineWeight)));
    }
    for (; x < im.w; ++x) {
      float sum = 0;
      for (int k = 0; k < kTaps; ++k) sum += r[k][x];
      out[x] = sum * kLineWeight;
    }
  });
  _mm_sfence();
}
#else
// Without AVX-512 the hand form is the compiler's.
void blur_simd(const Image& im, int y0, int y1) { blur_cpp(im, y0, y1); }
void blur_rows_simd(const Image& im, int y0, int y1) { blur_rows_cpp(im, y0, y1); }
void blur_columns_simd(const Image& im, int y0, int y1) { blur_columns_cpp(im, y0, y1); }
#endif

std::vector<float> blur_image(int w, int h) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> value(0.0f, 1.0f);
  std::vector<float> image(static_cast<std::size_t>(w) * h);
  for (float& v : image) v = value(rng);
  return image;
}

}  // namespace bench

namespace bench {

#if defined(__AVX512F__)
void saxpy_simd(float a, const float* x, const float* y, float* r, std::size_t begin, std::size_t end) {
  __m512 av = _mm512_set1_ps(a);
  std::size_t i = std::min(end, begin + (64 - reinterpret_cast<std::uintptr_t>(r + begin) % 64) % 64 / sizeof(float));
  saxpy_cpp(a, x, y, r, begin, i);
  for (; i + 16 <= end; i += 16)
    store_out(r + i, _mm512_add_ps(_mm512_mul_ps(av, _mm512_loadu_ps(x + i)), _mm512_loadu_ps(y + i)));
  _mm_sfence();
  saxpy_cpp(a, x, y, r, i, end);
}

// Sixteen pixels iterate together while any is inside; each counts only
// while it is.
void mandelbrot_simd(const float* c, float* shade, std::size_t begin, std::size_t end) {
  const __m512i even = _mm512_setr_epi32(0, 2, 4, 6, 8, 10, 12, 14, 16, 18, 20, 22, 24, 26, 28, 30);
  const __m512i odd = _mm512_add_epi32(even, _mm512_set1_epi32(1));
  std::size_t p = begin;
  for (; p + 16 <= end; p += 16) {
    __m512 lo = _mm512_loadu_ps(c + 2 * p), hi = _mm512_loadu_ps(c + 2 * p + 16);
    __m512 cx = _mm512_permutex2var_ps(lo, even, hi), cy = _mm512_permutex2var_ps(lo, odd, hi);
    __m512 zx = _mm512_setzero_ps(), zy = _mm512_setzero_ps(), i = _mm512_setzero_ps();
    const __m512 four = _mm512_set1_ps(4.0f), two = _mm512_set1_ps(2.0f), one = _mm512_set1_ps(1.0f);
    const __m512 limit = _mm512_set1_ps(static_cast<float>(kMandelbrotIterations));
    for (;;) {
      __m512 r2 = _mm512_add_ps(_mm512_mul_ps(zx, zx), _mm512_mul_ps(zy, zy));
      __mmask16 inside = _mm512_cmp_ps_mask(i, limit, _CMP_LT_OQ) & _mm512_cmp_ps_mask(r2, four, _CMP_LT_OQ);
      if (!inside) break;
      __m512 nx = _mm512_add_ps(_mm512_sub_ps(_mm512_mul_ps(zx, zx), _mm512_mul_ps(zy, zy)), cx);
      __m512 ny = _mm512_add_ps(_mm512_mul_ps(_mm512_mul_ps(two, zx), zy), cy);
      zx = _mm512_mask_mov_ps(zx, inside, nx);
      zy = _mm512_mask_mov_ps(zy, inside, ny);
      i = _mm512_mask_add_ps(i, inside, i, one);
    }
    _mm512_storeu_ps(shade + p, i);
  }
  mandelbrot_cpp(c, shade, p, end);
}

// Sixteen rays against each triangle, the rays' coordinates gathered from
// their 3-float records, the triangle's broadcast.
void triangles_simd(const TriangleScene& s, float* out, std::size_t begin, std::size_t end) {
  const float* V = s.vertices.data();
  const __m512i stride = _mm512_mullo_epi32(_mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15),
                                            _mm512_set1_epi32(3));
  auto sub = [](__m512 a, __m512 b) { return _mm512_sub_ps(a, b); };
  auto mul = [](__m512 a, __m512 b) { return _mm512_mul_ps(a, b); };
  auto dot = [&](const __m512* a, const __m512* b) {
    return _mm512_add_ps(_mm512_add_ps(mul(a[0], b[0]), mul(a[1], b[1])), mul(a[2], b[2]));
  };
  auto cross = [&](const __m512* a, const __m512* b, __m512* r) {
    r[0] = sub(mul(a[1], b[2]), mul(a[2], b[1]));
    r[1] = sub(mul(a[2], b[0]), mul(a[0], b[2]));
    r[2] = sub(mul(a[0], b[1]), mul(a[1], b[0]));
  };
  std::size_t r = begin;
  for (; r + 16 <= end; r += 16) {
    __m512 o[3], d[3];
    for (int k = 0; k < 3; ++k) {
      o[k] = _mm512_mask_i32gather_ps(_mm512_setzero_ps(), 0xffff, stride, &s.origins[3 * r + k], 4);
      d[k] = _mm512_mask_i32gather_ps(_mm512_setzero_ps(), 0xffff, stride, &s.directions[3 * r + k], 4);
    }
    __m512 nearest = _mm512_set1_ps(1e30f);
    for (int t = 0; t < kTriangles; ++t) {
      const float* v = V + 9 * t;
      __m512 v0[3], e1[3], e2[3], p[3], sv[3], q[3];
      for (int k = 0; k < 3; ++k) {
        v0[k] = _mm512_set1_ps(v[k]);
        e1[k] = _mm512_set1_ps(v[3 + k] - v[k]);
        e2[k] = _mm512_set1_ps(v[6 + k] - v[k]);
        sv[k] = sub(o[k], v0[k]);
      }
      cross(d, e2, p);
      __m512 det = dot(e1, p);
      __m512 inv = _mm512_div_ps(_mm512_set1_ps(1.0f), det);
      __m512 u = mul(dot(sv, p), inv);
      cross(sv, e1, q);
      __m512 vv = mul(dot(d, q), inv);
      __m512 tt = mul(dot(e2, q), inv);
      __mmask16 hit = _mm512_cmp_ps_mask(_mm512_abs_ps(det), _mm512_set1_ps(1e-8f), _CMP_GT_OQ) &
                      _mm512_cmp_ps_mask(u, _mm512_setzero_ps(), _CMP_GE_OQ) &
                      _mm512_cmp_ps_mask(vv, _mm512_setzero_ps(), _CMP_GE_OQ) &
                      _mm512_cmp_ps_mask(_mm512_add_ps(u, vv), _mm512_set1_ps(1.0f), _CMP_LE_OQ) &
                      _mm512_cmp_ps_mask(tt, _mm512_set1_ps(1e-6f), _CMP_GT_OQ) & _mm512_cmp_ps_mask(tt, nearest, _CMP_LT_OQ);
      nearest = _mm512_mask_mov_ps(nearest, hit, tt);
    }
    _mm512_storeu_ps(out + r, nearest);
  }
  triangles_cpp(s, out, r, end);
}
#else
void saxpy_simd(float a, const float* x, const float* y, float* r, std::size_t begin, std::size_t end) {
  saxpy_cpp(a, x, y, r, begin, end);
}
void mandelbrot_simd(const float* c, float* shade, std::size_t begin, std::size_t end) { mandelbrot_cpp(c, shade, begin, end); }
void triangles_simd(const TriangleScene& s, float* out, std::size_t begin, std::size_t end) { triangles_cpp(s, out, begin, end); }
#endif

}  // namespace bench
