#include "kernels.hpp"

#include "simd.hpp"

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <random>
#include <string>
#include <type_traits>
#include <utility>

namespace bench {

using namespace sh;

namespace {

// $SH_CACHE_DIR is "off" while one lives, and as it was after.
class KernelCacheOff {
 public:
  KernelCacheOff() : was_set_(std::getenv("SH_CACHE_DIR") != nullptr), was_(was_set_ ? std::getenv("SH_CACHE_DIR") : "") {
    ::setenv("SH_CACHE_DIR", "off", 1);
  }
  KernelCacheOff(const KernelCacheOff&) = delete;
  KernelCacheOff& operator=(const KernelCacheOff&) = delete;
  ~KernelCacheOff() { was_set_ ? ::setenv("SH_CACHE_DIR", was_.c_str(), 1) : ::unsetenv("SH_CACHE_DIR"); }

 private:
  bool was_set_;
  std::string was_;
};

}  // namespace

std::unique_ptr<Kernel> compile_cold(Backend& backend, const Program& p, const Options& options) {
  KernelCacheOff off;
  return backend.compile(passes::legalize(optimize(p.ir())), options);
}

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
  // The thread's strip, kept for its next call as the DSL's strips keep
  // theirs: neither allocates nor clears one in the timed calls.
  thread_local std::vector<float> strip;
  strip.resize(static_cast<std::size_t>(kFusedRows + 2 * kBlurRadius) * im.w);
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

// The widest vectors the host has (simd.hpp), a vector of pixels per step.
// The direct blur reads each row's taps in the host's faster way
// (simd::row_taps: lane shifts of two loads on AMD, a load a tap on
// Intel and with AVX2), takes two output rows a trip with AVX-512 (six
// input rows read, not ten), and reads a vector's taps that reach past
// the row's ends from a clamped copy, as the backend's edge batches do.
// The passes load each tap; their edges and a row's last partial step are
// the C++ form's; the rows' pass writes its rows into the cache, where the
// columns' pass reads them next (streamed past it, the two passes took
// 3.22 ms on an Intel host with a large L3, cached 2.35).
#if defined(BENCH_HAND_SIMD)
namespace {

using simd::F;
using simd::kLanes;

// Where the steps start: the first x on a vector's boundary at or after
// `from` (the image's rows start on one).
int on_a_vector(int from) { return (from + kLanes - 1) / kLanes * kLanes; }

// The taps of `row` for the vector of pixels at x; `Inside`: every value
// row_taps reads, row[x - kBlurRadius .. + 2 * kLanes), lies in the row.
template <simd::Taps How, bool Inside>
void taps_at(const float* row, int x, int w, F (&taps)[kTaps]) {
  if constexpr (Inside) {
    simd::row_taps<How>(row + x - kBlurRadius, taps);
  } else {
    // The row's values from x - kBlurRadius on, its end values repeated
    // past its ends: what a clamped read finds there.
    alignas(64) float copy[2 * kLanes];
    int from = x - kBlurRadius, lo = std::clamp(-from, 0, 2 * kLanes), hi = std::clamp(w - from, lo, 2 * kLanes);
    std::fill(copy, copy + lo, row[0]);
    std::copy(row + from + lo, row + from + hi, copy + lo);
    std::fill(copy + hi, copy + 2 * kLanes, row[w - 1]);
    simd::row_taps<How>(copy, taps);
  }
}

// Rows output rows of the direct blur at x, from the input rows
// r[0 .. Rows + kTaps - 1): each input row's taps are read once and added
// to every output row that reads it, each output row adding its rows and
// taps in the program's order.
template <int Rows, simd::Taps How, bool Inside>
void blur_step(const float* const* r, float* const* out, int x, int w) {
  F sum[Rows];
  for (F& s : sum) s = simd::zero();
  // Input row K's taps, added tap by tap to each output row that reads
  // it; K a constant, so that every loop here unrolls and the output
  // rows' adds interleave.
  auto add_input_row = [&]<int K>(std::integral_constant<int, K>) {
    F taps[kTaps];
    taps_at<How, Inside>(r[K], x, w, taps);
    for (const F& tap : taps)
      for (int j = 0; j < Rows; ++j)
        if (K >= j && K < j + kTaps) sum[j] = simd::add(sum[j], tap);
  };
  [&]<int... K>(std::integer_sequence<int, K...>) {
    (add_input_row(std::integral_constant<int, K>{}), ...);
  }(std::make_integer_sequence<int, Rows + kTaps - 1>{});
  for (int j = 0; j < Rows; ++j) simd::store_out(out[j] + x, simd::mul(sum[j], simd::splat(kBoxWeight)));
}

template <int Rows, simd::Taps How>
void direct_blur_rows(const Image& im, int y) {
  const float* r[Rows + kTaps - 1];
  float* out[Rows];
  for (int k = 0; k < Rows + kTaps - 1; ++k) r[k] = row_at(im, y + k - kBlurRadius);
  for (int j = 0; j < Rows; ++j) out[j] = im.out + static_cast<std::size_t>(y + j) * im.w;
  // The vectors before the row's inside, inside it (a loop of its own),
  // and after it.
  auto inside = [&](int x) { return x >= kBlurRadius && x - kBlurRadius + 2 * kLanes <= im.w; };
  int x = 0;
  for (; x + kLanes <= im.w && !inside(x); x += kLanes) blur_step<Rows, How, false>(r, out, x, im.w);
  for (; x + kLanes <= im.w && inside(x); x += kLanes) blur_step<Rows, How, true>(r, out, x, im.w);
  for (; x + kLanes <= im.w; x += kLanes) blur_step<Rows, How, false>(r, out, x, im.w);
  for (int j = 0; j < Rows; ++j)
    for (int xs = x; xs < im.w; ++xs) out[j][xs] = box_at(im, y + j, xs);
}

template <simd::Taps How>
void direct_blur(const Image& im, int y0, int y1) {
  int y = y0;
  for (; y + simd::kStencilRows <= y1; y += simd::kStencilRows) direct_blur_rows<simd::kStencilRows, How>(im, y);
  for (; y < y1; ++y) direct_blur_rows<1, How>(im, y);
}

}  // namespace

void blur_simd(const Image& im, int y0, int y1) {
  simd::with_host_taps([&](auto how) { direct_blur<how.value>(im, y0, y1); });
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
    for (; x < std::min(on_a_vector(interior_lo(im)), im.w); ++x) out[x] = at(x);
    for (; x + kLanes <= interior_hi(im); x += kLanes) {
      F sum = simd::zero();
      for (int dx = -kBlurRadius; dx <= kBlurRadius; ++dx) sum = simd::add(sum, simd::load(r + x + dx));
      simd::store(out + x, simd::mul(sum, simd::splat(kLineWeight)));
    }
    for (; x < im.w; ++x) out[x] = at(x);
  });
}

void blur_columns_simd(const Image& im, int y0, int y1) {
  each_row(im, y0, y1, [&](int y, float* out) {
    const float* r[kTaps];
    for (int k = 0; k < kTaps; ++k) r[k] = row_at(im, y + k - kBlurRadius);
    int x = 0;
    for (; x + kLanes <= im.w; x += kLanes) {
      F sum = simd::zero();
      for (int k = 0; k < kTaps; ++k) sum = simd::add(sum, simd::load(r[k] + x));
      simd::store_out(out + x, simd::mul(sum, simd::splat(kLineWeight)));
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
// Without AVX2 the hand form is the compiler's.
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

#if defined(BENCH_HAND_SIMD)
void saxpy_simd(float a, const float* x, const float* y, float* r, std::size_t begin, std::size_t end) {
  F av = simd::splat(a);
  std::size_t i =
      std::min(end, begin + (sizeof(F) - reinterpret_cast<std::uintptr_t>(r + begin) % sizeof(F)) % sizeof(F) / sizeof(float));
  saxpy_cpp(a, x, y, r, begin, i);
  for (; i + kLanes <= end; i += kLanes)
    simd::store_out(r + i, simd::add(simd::mul(av, simd::load(x + i)), simd::load(y + i)));
  _mm_sfence();
  saxpy_cpp(a, x, y, r, i, end);
}

// A vector of pixels iterates together while any is inside; each counts
// only while it is.
void mandelbrot_simd(const float* c, float* shade, std::size_t begin, std::size_t end) {
  const F four = simd::splat(4.0f), two = simd::splat(2.0f), one = simd::splat(1.0f);
  const F limit = simd::splat(static_cast<float>(kMandelbrotIterations));
  std::size_t p = begin;
  for (; p + kLanes <= end; p += kLanes) {
    F cx, cy;
    simd::split_pairs(c + 2 * p, cx, cy);
    F zx = simd::zero(), zy = simd::zero(), i = simd::zero();
    for (;;) {
      F r2 = simd::add(simd::mul(zx, zx), simd::mul(zy, zy));
      simd::Mask inside = simd::both(simd::compare<_CMP_LT_OQ>(i, limit), simd::compare<_CMP_LT_OQ>(r2, four));
      if (simd::none(inside)) break;
      F nx = simd::add(simd::sub(simd::mul(zx, zx), simd::mul(zy, zy)), cx);
      F ny = simd::add(simd::mul(simd::mul(two, zx), zy), cy);
      zx = simd::choose(inside, nx, zx);
      zy = simd::choose(inside, ny, zy);
      i = simd::choose(inside, simd::add(i, one), i);
    }
    simd::store(shade + p, i);
  }
  mandelbrot_cpp(c, shade, p, end);
}

// A vector of rays against each triangle, the rays' coordinates gathered
// from their 3-float records, the triangle's broadcast.
void triangles_simd(const TriangleScene& s, float* out, std::size_t begin, std::size_t end) {
  const float* V = s.vertices.data();
  using simd::mul;
  using simd::sub;
  auto dot = [&](const F* a, const F* b) { return simd::add(simd::add(mul(a[0], b[0]), mul(a[1], b[1])), mul(a[2], b[2])); };
  auto cross = [&](const F* a, const F* b, F* r) {
    r[0] = sub(mul(a[1], b[2]), mul(a[2], b[1]));
    r[1] = sub(mul(a[2], b[0]), mul(a[0], b[2]));
    r[2] = sub(mul(a[0], b[1]), mul(a[1], b[0]));
  };
  std::size_t r = begin;
  for (; r + kLanes <= end; r += kLanes) {
    F o[3], d[3];
    for (int k = 0; k < 3; ++k) {
      o[k] = simd::every_third(&s.origins[3 * r + k]);
      d[k] = simd::every_third(&s.directions[3 * r + k]);
    }
    F nearest = simd::splat(1e30f);
    for (int t = 0; t < kTriangles; ++t) {
      const float* v = V + 9 * t;
      F v0[3], e1[3], e2[3], p[3], sv[3], q[3];
      for (int k = 0; k < 3; ++k) {
        v0[k] = simd::splat(v[k]);
        e1[k] = simd::splat(v[3 + k] - v[k]);
        e2[k] = simd::splat(v[6 + k] - v[k]);
        sv[k] = sub(o[k], v0[k]);
      }
      cross(d, e2, p);
      F det = dot(e1, p);
      F inv = simd::div(simd::splat(1.0f), det);
      F u = mul(dot(sv, p), inv);
      cross(sv, e1, q);
      F vv = mul(dot(d, q), inv);
      F tt = mul(dot(e2, q), inv);
      simd::Mask hit = simd::compare<_CMP_GT_OQ>(simd::abs(det), simd::splat(1e-8f));
      hit = simd::both(hit, simd::compare<_CMP_GE_OQ>(u, simd::zero()));
      hit = simd::both(hit, simd::compare<_CMP_GE_OQ>(vv, simd::zero()));
      hit = simd::both(hit, simd::compare<_CMP_LE_OQ>(simd::add(u, vv), simd::splat(1.0f)));
      hit = simd::both(hit, simd::compare<_CMP_GT_OQ>(tt, simd::splat(1e-6f)));
      hit = simd::both(hit, simd::compare<_CMP_LT_OQ>(tt, nearest));
      nearest = simd::choose(hit, tt, nearest);
    }
    simd::store(out + r, nearest);
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
