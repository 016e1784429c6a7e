#pragma once
// The widest vectors the host has, for the benchmark's hand-written forms:
// AVX-512 (sixteen floats) or AVX2 (eight).  Each form is written once over
// these few operations, so that it is the best C++ on either kind of host;
// without AVX2 the hand forms are the compiler's (kernels.cpp).
#include <immintrin.h>

#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <utility>

#if defined(__AVX512F__) || defined(__AVX2__)
#define BENCH_HAND_SIMD 1

namespace bench::simd {

// How a stencil reads a row of taps (row_taps).
enum class Taps { Shifted, Loaded };

#if defined(__AVX512F__)
using F = __m512;
using Mask = __mmask16;
inline constexpr int kLanes = 16;

inline F load(const float* p) { return _mm512_loadu_ps(p); }
inline void store(float* p, F v) { _mm512_storeu_ps(p, v); }
inline void stream(float* p, F v) { _mm512_stream_ps(p, v); }
inline F splat(float v) { return _mm512_set1_ps(v); }
inline F add(F a, F b) { return _mm512_add_ps(a, b); }
inline F sub(F a, F b) { return _mm512_sub_ps(a, b); }
inline F mul(F a, F b) { return _mm512_mul_ps(a, b); }
inline F div(F a, F b) { return _mm512_div_ps(a, b); }
inline F abs(F a) { return _mm512_abs_ps(a); }
template <int Cmp>
Mask compare(F a, F b) {
  return _mm512_cmp_ps_mask(a, b, Cmp);
}
inline Mask both(Mask a, Mask b) { return a & b; }
inline bool none(Mask m) { return m == 0; }
// Where m holds, if_true; elsewhere otherwise.
inline F choose(Mask m, F if_true, F otherwise) { return _mm512_mask_mov_ps(otherwise, m, if_true); }

// Output rows the direct blur takes a trip: with 32 registers two rows
// share the loads and shifts of the input rows both read.
inline constexpr int kStencilRows = 2;

namespace detail {
// Lanes K .. K + 15 of first:next.
template <int K>
F lanes_from(F first, F next) {
  if constexpr (K == 0)
    return first;
  else
    // The masked form: GCC 12's unmasked one reads an undefined vector.
    return _mm512_castsi512_ps(_mm512_mask_alignr_epi32(_mm512_castps_si512(first), 0xFFFF, _mm512_castps_si512(next),
                                                        _mm512_castps_si512(first), K));
}
template <std::size_t... K>
void row_taps(F first, F next, F* taps, std::index_sequence<K...>) {
  ((taps[K] = lanes_from<static_cast<int>(K)>(first, next)), ...);
}
}  // namespace detail

// The vectors at from + 0, from + 1, ... from + Taps - 1, read as How
// says: Shifted, two loads and a lane shift (`valignd`) a tap, as the cpu
// backend reads a row of taps with AVX-512; Loaded, a load a tap.  Reads
// from[0 .. 2 * kLanes).
template <Taps How, int N>
void row_taps(const float* from, F (&taps)[N]) {
  static_assert(N <= kLanes, "a row's taps lie in two vectors");
  if constexpr (How == Taps::Shifted)
    detail::row_taps(load(from), load(from + kLanes), taps, std::make_index_sequence<N>{});
  else
    for (int k = 0; k < N; ++k) taps[k] = load(from + k);
}

// The faster way on this host: on a Zen 4 host the shifts freed the load
// port, whose loads across cache lines bound the direct blur (22 % faster);
// on an Intel host, with one port for shifts and two for loads, a load a
// tap is 6 % faster (BENCHMARKS.md, issue 25).
// fn(std::integral_constant<Taps, the host's way>{}).
template <class Fn>
void with_host_taps(Fn fn) {
  static const bool shifted = __builtin_cpu_is("amd");
  if (shifted)
    fn(std::integral_constant<Taps, Taps::Shifted>{});
  else
    fn(std::integral_constant<Taps, Taps::Loaded>{});
}

// p[0], p[3], p[6], ...: one coordinate of kLanes 3-float records.
inline F every_third(const float* p) {
  const __m512i at = _mm512_mullo_epi32(_mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15),
                                        _mm512_set1_epi32(3));
  // The masked form: GCC 12's unmasked one reads an undefined vector.
  return _mm512_mask_i32gather_ps(_mm512_setzero_ps(), 0xFFFF, at, p, 4);
}

// The even and odd floats of p[0 .. 2 * kLanes).
inline void split_pairs(const float* p, F& even, F& odd) {
  const __m512i evens = _mm512_setr_epi32(0, 2, 4, 6, 8, 10, 12, 14, 16, 18, 20, 22, 24, 26, 28, 30);
  const __m512i odds = _mm512_add_epi32(evens, _mm512_set1_epi32(1));
  F lo = load(p), hi = load(p + kLanes);
  even = _mm512_permutex2var_ps(lo, evens, hi);
  odd = _mm512_permutex2var_ps(lo, odds, hi);
}
#else
using F = __m256;
using Mask = __m256;  // all ones where true
inline constexpr int kLanes = 8;

inline F load(const float* p) { return _mm256_loadu_ps(p); }
inline void store(float* p, F v) { _mm256_storeu_ps(p, v); }
inline void stream(float* p, F v) { _mm256_stream_ps(p, v); }
inline F splat(float v) { return _mm256_set1_ps(v); }
inline F add(F a, F b) { return _mm256_add_ps(a, b); }
inline F sub(F a, F b) { return _mm256_sub_ps(a, b); }
inline F mul(F a, F b) { return _mm256_mul_ps(a, b); }
inline F div(F a, F b) { return _mm256_div_ps(a, b); }
inline F abs(F a) { return _mm256_andnot_ps(_mm256_set1_ps(-0.0f), a); }
template <int Cmp>
Mask compare(F a, F b) {
  return _mm256_cmp_ps(a, b, Cmp);
}
inline Mask both(Mask a, Mask b) { return _mm256_and_ps(a, b); }
inline bool none(Mask m) { return _mm256_movemask_ps(m) == 0; }
inline F choose(Mask m, F if_true, F otherwise) { return _mm256_blendv_ps(otherwise, if_true, m); }

// One output row a trip: with 16 registers the loads two rows would
// share are folded into their adds again (the cpu backend's reasoning too).
inline constexpr int kStencilRows = 1;

// A load a tap: without AVX-512 a lane shift across a vector's halves is
// two instructions, slower than the load.  Reads from[0 .. 2 * kLanes).
template <Taps How, int N>
void row_taps(const float* from, F (&taps)[N]) {
  static_assert(How == Taps::Loaded, "a lane shift across halves is not worth its two instructions");
  for (int k = 0; k < N; ++k) taps[k] = load(from + k);
}

template <class Fn>
void with_host_taps(Fn fn) {
  fn(std::integral_constant<Taps, Taps::Loaded>{});
}

inline F every_third(const float* p) {
  return _mm256_i32gather_ps(p, _mm256_setr_epi32(0, 3, 6, 9, 12, 15, 18, 21), 4);
}

inline void split_pairs(const float* p, F& even, F& odd) {
  F lo = load(p), hi = load(p + kLanes);
  // Within each half: lo's pairs then hi's; the quarters then put in order.
  even = _mm256_castpd_ps(_mm256_permute4x64_pd(_mm256_castps_pd(_mm256_shuffle_ps(lo, hi, 0x88)), 0xD8));
  odd = _mm256_castpd_ps(_mm256_permute4x64_pd(_mm256_castps_pd(_mm256_shuffle_ps(lo, hi, 0xDD)), 0xD8));
}
#endif

inline F zero() { return splat(0.0f); }

// kLanes results that nothing reads again at `to`: past the cache where
// they start a vector, as the cpu backend writes an output of half its
// last-level cache or more, so that a line is not read before it is
// written.  On an Intel host whose cache holds the outputs, where the
// backend stores them plainly, streaming is still the faster for the
// hand forms (the direct blur 1.75-1.80 ms against 1.92-2.05).  A pass
// ends with a fence that orders them, as the kernel does.
inline void store_out(float* to, F v) {
  if (reinterpret_cast<std::uintptr_t>(to) % sizeof(F) == 0)
    stream(to, v);
  else
    store(to, v);
}

}  // namespace bench::simd
#endif
