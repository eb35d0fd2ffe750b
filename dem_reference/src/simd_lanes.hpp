// Lane types of the contact kernel: one double (the scalar kernel), two (SSE2, NEON or
// plain C++) and four (AVX2, when the build enables it), with the same small set of
// operations, so that the kernel is written once (as Box2D v3 writes its solver over
// b2FloatW).
//
// Why this gives the same bits in every width: each operation is one correctly rounded
// IEEE operation per lane (+, −, ×, ÷, √, negation, comparison, select), the kernel
// applies them in one written order, and no back end contracts a×b+c into a fused
// multiply-add. x86-64 without -march has no FMA instruction (SSE2, and AVX2 without
// -mfma). A build whose target has FMA (aarch64, -march=native, -mfma) must compile
// with -ffp-contract=off, or the compiler may fuse the scalar and the lane
// instantiations differently (and the pinned hashes of tests/dem_reference no longer
// hold).
#pragma once

#include <cmath>

#if defined(__SSE2__)
#include <emmintrin.h>
#define PDAMP_LANES_SSE2 1
#elif defined(__ARM_NEON) && defined(__aarch64__)
#include <arm_neon.h>
#define PDAMP_LANES_NEON 1
#endif
#if defined(__AVX2__)
#include <immintrin.h>
#define PDAMP_LANES_AVX2 1
#endif
#if defined(__AVX512F__) && defined(__AVX512DQ__)
#define PDAMP_LANES_AVX512 1
#endif

#define PDAMP_LANE_INLINE [[gnu::always_inline]] inline

namespace pdamp::dem_reference::detail::simd {

// Every lane type W provides:
//   W::kWidth, W::Mask (a lane mask: all bits set where true),
//   W::splat(x), W::gather(f): lane l = f(l), lane(v, l), scatter(v, f): f(l) = lane l
//   (f returns a double&), + − × ÷, unary −, sqrt, < > (to a Mask), select(m, yes, no),
//   and for masks & | andnot(a, b) = ¬a ∧ b, any(m), all(m), lane(m, l).

// ---- one lane: the scalar kernel ----------------------------------------------------
struct Lanes1 {
  static constexpr int kWidth = 1;
  struct Mask {
    bool m;
  };
  double v;
  PDAMP_LANE_INLINE static Lanes1 splat(double x) { return {x}; }
  template <class F>
  PDAMP_LANE_INLINE static Lanes1 gather(F&& f) {
    return {f(0)};
  }
};
PDAMP_LANE_INLINE Lanes1 operator+(Lanes1 a, Lanes1 b) { return {a.v + b.v}; }
PDAMP_LANE_INLINE Lanes1 operator-(Lanes1 a, Lanes1 b) { return {a.v - b.v}; }
PDAMP_LANE_INLINE Lanes1 operator*(Lanes1 a, Lanes1 b) { return {a.v * b.v}; }
PDAMP_LANE_INLINE Lanes1 operator/(Lanes1 a, Lanes1 b) { return {a.v / b.v}; }
PDAMP_LANE_INLINE Lanes1 operator-(Lanes1 a) { return {-a.v}; }
PDAMP_LANE_INLINE Lanes1 sqrt(Lanes1 a) { return {std::sqrt(a.v)}; }
PDAMP_LANE_INLINE Lanes1::Mask operator<(Lanes1 a, Lanes1 b) { return {a.v < b.v}; }
PDAMP_LANE_INLINE Lanes1::Mask operator>(Lanes1 a, Lanes1 b) { return {a.v > b.v}; }
PDAMP_LANE_INLINE Lanes1::Mask operator&(Lanes1::Mask a, Lanes1::Mask b) { return {a.m && b.m}; }
PDAMP_LANE_INLINE Lanes1::Mask operator|(Lanes1::Mask a, Lanes1::Mask b) { return {a.m || b.m}; }
PDAMP_LANE_INLINE Lanes1::Mask andnot(Lanes1::Mask a, Lanes1::Mask b) { return {!a.m && b.m}; }
PDAMP_LANE_INLINE bool any(Lanes1::Mask a) { return a.m; }
PDAMP_LANE_INLINE bool all(Lanes1::Mask a) { return a.m; }
PDAMP_LANE_INLINE bool lane(Lanes1::Mask a, int) { return a.m; }
PDAMP_LANE_INLINE Lanes1 select(Lanes1::Mask m, Lanes1 yes, Lanes1 no) { return m.m ? yes : no; }
PDAMP_LANE_INLINE double lane(Lanes1 a, int) { return a.v; }
template <class F>
PDAMP_LANE_INLINE void scatter(Lanes1 a, F&& f) {
  f(0) = a.v;
}

// ---- two lanes in plain C++: the portable fallback ----------------------------------
// Two independent dependency chains still overlap in an out-of-order core where the
// compiler does not vectorise them.
struct LanesPortable2 {
  static constexpr int kWidth = 2;
  struct Mask {
    bool m[2];
  };
  double v[2];
  PDAMP_LANE_INLINE static LanesPortable2 splat(double x) { return {{x, x}}; }
  template <class F>
  PDAMP_LANE_INLINE static LanesPortable2 gather(F&& f) {
    return {{f(0), f(1)}};
  }
};
using P2 = LanesPortable2;
PDAMP_LANE_INLINE P2 operator+(P2 a, P2 b) { return {{a.v[0] + b.v[0], a.v[1] + b.v[1]}}; }
PDAMP_LANE_INLINE P2 operator-(P2 a, P2 b) { return {{a.v[0] - b.v[0], a.v[1] - b.v[1]}}; }
PDAMP_LANE_INLINE P2 operator*(P2 a, P2 b) { return {{a.v[0] * b.v[0], a.v[1] * b.v[1]}}; }
PDAMP_LANE_INLINE P2 operator/(P2 a, P2 b) { return {{a.v[0] / b.v[0], a.v[1] / b.v[1]}}; }
PDAMP_LANE_INLINE P2 operator-(P2 a) { return {{-a.v[0], -a.v[1]}}; }
PDAMP_LANE_INLINE P2 sqrt(P2 a) { return {{std::sqrt(a.v[0]), std::sqrt(a.v[1])}}; }
PDAMP_LANE_INLINE P2::Mask operator<(P2 a, P2 b) { return {{a.v[0] < b.v[0], a.v[1] < b.v[1]}}; }
PDAMP_LANE_INLINE P2::Mask operator>(P2 a, P2 b) { return {{a.v[0] > b.v[0], a.v[1] > b.v[1]}}; }
PDAMP_LANE_INLINE P2::Mask operator&(P2::Mask a, P2::Mask b) { return {{a.m[0] && b.m[0], a.m[1] && b.m[1]}}; }
PDAMP_LANE_INLINE P2::Mask operator|(P2::Mask a, P2::Mask b) { return {{a.m[0] || b.m[0], a.m[1] || b.m[1]}}; }
PDAMP_LANE_INLINE P2::Mask andnot(P2::Mask a, P2::Mask b) { return {{!a.m[0] && b.m[0], !a.m[1] && b.m[1]}}; }
PDAMP_LANE_INLINE bool any(P2::Mask a) { return a.m[0] || a.m[1]; }
PDAMP_LANE_INLINE bool all(P2::Mask a) { return a.m[0] && a.m[1]; }
PDAMP_LANE_INLINE bool lane(P2::Mask a, int l) { return a.m[l]; }
PDAMP_LANE_INLINE P2 select(P2::Mask m, P2 yes, P2 no) {
  return {{m.m[0] ? yes.v[0] : no.v[0], m.m[1] ? yes.v[1] : no.v[1]}};
}
PDAMP_LANE_INLINE double lane(P2 a, int l) { return a.v[l]; }
template <class F>
PDAMP_LANE_INLINE void scatter(P2 a, F&& f) {
  f(0) = a.v[0];
  f(1) = a.v[1];
}

#if defined(PDAMP_LANES_SSE2)
// ---- two lanes of an SSE2 register (part of x86-64 itself: no -march needed) --------
struct LanesSse2 {
  static constexpr int kWidth = 2;
  struct Mask {
    __m128d m;
  };
  __m128d v;
  PDAMP_LANE_INLINE static LanesSse2 splat(double x) { return {_mm_set1_pd(x)}; }
  template <class F>
  PDAMP_LANE_INLINE static LanesSse2 gather(F&& f) {
    return {_mm_set_pd(f(1), f(0))};  // lane 0 = f(0)
  }
};
using S2 = LanesSse2;
PDAMP_LANE_INLINE S2 operator+(S2 a, S2 b) { return {_mm_add_pd(a.v, b.v)}; }
PDAMP_LANE_INLINE S2 operator-(S2 a, S2 b) { return {_mm_sub_pd(a.v, b.v)}; }
PDAMP_LANE_INLINE S2 operator*(S2 a, S2 b) { return {_mm_mul_pd(a.v, b.v)}; }
PDAMP_LANE_INLINE S2 operator/(S2 a, S2 b) { return {_mm_div_pd(a.v, b.v)}; }
PDAMP_LANE_INLINE S2 operator-(S2 a) { return {_mm_xor_pd(a.v, _mm_set1_pd(-0.0))}; }
PDAMP_LANE_INLINE S2 sqrt(S2 a) { return {_mm_sqrt_pd(a.v)}; }
PDAMP_LANE_INLINE S2::Mask operator<(S2 a, S2 b) { return {_mm_cmplt_pd(a.v, b.v)}; }
PDAMP_LANE_INLINE S2::Mask operator>(S2 a, S2 b) { return {_mm_cmpgt_pd(a.v, b.v)}; }
PDAMP_LANE_INLINE S2::Mask operator&(S2::Mask a, S2::Mask b) { return {_mm_and_pd(a.m, b.m)}; }
PDAMP_LANE_INLINE S2::Mask operator|(S2::Mask a, S2::Mask b) { return {_mm_or_pd(a.m, b.m)}; }
PDAMP_LANE_INLINE S2::Mask andnot(S2::Mask a, S2::Mask b) { return {_mm_andnot_pd(a.m, b.m)}; }
PDAMP_LANE_INLINE bool any(S2::Mask a) { return _mm_movemask_pd(a.m) != 0; }
PDAMP_LANE_INLINE bool all(S2::Mask a) { return _mm_movemask_pd(a.m) == 3; }
PDAMP_LANE_INLINE bool lane(S2::Mask a, int l) { return ((_mm_movemask_pd(a.m) >> l) & 1) != 0; }
PDAMP_LANE_INLINE S2 select(S2::Mask m, S2 yes, S2 no) {
  return {_mm_or_pd(_mm_and_pd(m.m, yes.v), _mm_andnot_pd(m.m, no.v))};
}
PDAMP_LANE_INLINE double lane(S2 a, int l) {
  return l == 0 ? _mm_cvtsd_f64(a.v) : _mm_cvtsd_f64(_mm_unpackhi_pd(a.v, a.v));
}
template <class F>
PDAMP_LANE_INLINE void scatter(S2 a, F&& f) {
  _mm_storel_pd(&f(0), a.v);
  _mm_storeh_pd(&f(1), a.v);
}
#endif

#if defined(PDAMP_LANES_NEON)
// ---- two lanes of a NEON register (aarch64) -----------------------------------------
struct LanesNeon {
  static constexpr int kWidth = 2;
  struct Mask {
    uint64x2_t m;
  };
  float64x2_t v;
  PDAMP_LANE_INLINE static LanesNeon splat(double x) { return {vdupq_n_f64(x)}; }
  template <class F>
  PDAMP_LANE_INLINE static LanesNeon gather(F&& f) {
    return {vsetq_lane_f64(f(1), vdupq_n_f64(f(0)), 1)};
  }
};
using N2 = LanesNeon;
PDAMP_LANE_INLINE N2 operator+(N2 a, N2 b) { return {vaddq_f64(a.v, b.v)}; }
PDAMP_LANE_INLINE N2 operator-(N2 a, N2 b) { return {vsubq_f64(a.v, b.v)}; }
PDAMP_LANE_INLINE N2 operator*(N2 a, N2 b) { return {vmulq_f64(a.v, b.v)}; }
PDAMP_LANE_INLINE N2 operator/(N2 a, N2 b) { return {vdivq_f64(a.v, b.v)}; }
PDAMP_LANE_INLINE N2 operator-(N2 a) { return {vnegq_f64(a.v)}; }
PDAMP_LANE_INLINE N2 sqrt(N2 a) { return {vsqrtq_f64(a.v)}; }
PDAMP_LANE_INLINE N2::Mask operator<(N2 a, N2 b) { return {vcltq_f64(a.v, b.v)}; }
PDAMP_LANE_INLINE N2::Mask operator>(N2 a, N2 b) { return {vcgtq_f64(a.v, b.v)}; }
PDAMP_LANE_INLINE N2::Mask operator&(N2::Mask a, N2::Mask b) { return {vandq_u64(a.m, b.m)}; }
PDAMP_LANE_INLINE N2::Mask operator|(N2::Mask a, N2::Mask b) { return {vorrq_u64(a.m, b.m)}; }
PDAMP_LANE_INLINE N2::Mask andnot(N2::Mask a, N2::Mask b) { return {vbicq_u64(b.m, a.m)}; }
PDAMP_LANE_INLINE bool any(N2::Mask a) { return (vgetq_lane_u64(a.m, 0) | vgetq_lane_u64(a.m, 1)) != 0; }
PDAMP_LANE_INLINE bool all(N2::Mask a) { return (vgetq_lane_u64(a.m, 0) & vgetq_lane_u64(a.m, 1)) != 0; }
PDAMP_LANE_INLINE bool lane(N2::Mask a, int l) {
  return (l == 0 ? vgetq_lane_u64(a.m, 0) : vgetq_lane_u64(a.m, 1)) != 0;
}
PDAMP_LANE_INLINE N2 select(N2::Mask m, N2 yes, N2 no) { return {vbslq_f64(m.m, yes.v, no.v)}; }
PDAMP_LANE_INLINE double lane(N2 a, int l) { return l == 0 ? vgetq_lane_f64(a.v, 0) : vgetq_lane_f64(a.v, 1); }
template <class F>
PDAMP_LANE_INLINE void scatter(N2 a, F&& f) {
  f(0) = vgetq_lane_f64(a.v, 0);
  f(1) = vgetq_lane_f64(a.v, 1);
}
#endif

#if defined(PDAMP_LANES_AVX2)
// ---- four lanes of an AVX2 register (a build with -mavx2 and without FMA contraction) -
struct LanesAvx2 {
  static constexpr int kWidth = 4;
  struct Mask {
    __m256d m;
  };
  __m256d v;
  PDAMP_LANE_INLINE static LanesAvx2 splat(double x) { return {_mm256_set1_pd(x)}; }
  template <class F>
  PDAMP_LANE_INLINE static LanesAvx2 gather(F&& f) {
    return {_mm256_set_pd(f(3), f(2), f(1), f(0))};  // lane 0 = f(0)
  }
};
using A4 = LanesAvx2;
PDAMP_LANE_INLINE A4 operator+(A4 a, A4 b) { return {_mm256_add_pd(a.v, b.v)}; }
PDAMP_LANE_INLINE A4 operator-(A4 a, A4 b) { return {_mm256_sub_pd(a.v, b.v)}; }
PDAMP_LANE_INLINE A4 operator*(A4 a, A4 b) { return {_mm256_mul_pd(a.v, b.v)}; }
PDAMP_LANE_INLINE A4 operator/(A4 a, A4 b) { return {_mm256_div_pd(a.v, b.v)}; }
PDAMP_LANE_INLINE A4 operator-(A4 a) { return {_mm256_xor_pd(a.v, _mm256_set1_pd(-0.0))}; }
PDAMP_LANE_INLINE A4 sqrt(A4 a) { return {_mm256_sqrt_pd(a.v)}; }
PDAMP_LANE_INLINE A4::Mask operator<(A4 a, A4 b) { return {_mm256_cmp_pd(a.v, b.v, _CMP_LT_OQ)}; }
PDAMP_LANE_INLINE A4::Mask operator>(A4 a, A4 b) { return {_mm256_cmp_pd(a.v, b.v, _CMP_GT_OQ)}; }
PDAMP_LANE_INLINE A4::Mask operator&(A4::Mask a, A4::Mask b) { return {_mm256_and_pd(a.m, b.m)}; }
PDAMP_LANE_INLINE A4::Mask operator|(A4::Mask a, A4::Mask b) { return {_mm256_or_pd(a.m, b.m)}; }
PDAMP_LANE_INLINE A4::Mask andnot(A4::Mask a, A4::Mask b) { return {_mm256_andnot_pd(a.m, b.m)}; }
PDAMP_LANE_INLINE bool any(A4::Mask a) { return _mm256_movemask_pd(a.m) != 0; }
PDAMP_LANE_INLINE bool all(A4::Mask a) { return _mm256_movemask_pd(a.m) == 15; }
PDAMP_LANE_INLINE bool lane(A4::Mask a, int l) { return ((_mm256_movemask_pd(a.m) >> l) & 1) != 0; }
PDAMP_LANE_INLINE A4 select(A4::Mask m, A4 yes, A4 no) { return {_mm256_blendv_pd(no.v, yes.v, m.m)}; }
PDAMP_LANE_INLINE double lane(A4 a, int l) {
  const __m128d half = l < 2 ? _mm256_castpd256_pd128(a.v) : _mm256_extractf128_pd(a.v, 1);
  return (l & 1) == 0 ? _mm_cvtsd_f64(half) : _mm_cvtsd_f64(_mm_unpackhi_pd(half, half));
}
template <class F>
PDAMP_LANE_INLINE void scatter(A4 a, F&& f) {
  const __m128d low = _mm256_castpd256_pd128(a.v);
  const __m128d high = _mm256_extractf128_pd(a.v, 1);
  _mm_storel_pd(&f(0), low);
  _mm_storeh_pd(&f(1), low);
  _mm_storel_pd(&f(2), high);
  _mm_storeh_pd(&f(3), high);
}
#endif

#if defined(PDAMP_LANES_AVX512)
// ---- eight lanes of an AVX-512 register (a build with -mavx512f -mavx512dq) ---------
struct LanesAvx512 {
  static constexpr int kWidth = 8;
  struct Mask {
    __mmask8 m;
  };
  __m512d v;
  PDAMP_LANE_INLINE static LanesAvx512 splat(double x) { return {_mm512_set1_pd(x)}; }
  template <class F>
  PDAMP_LANE_INLINE static LanesAvx512 gather(F&& f) {
    return {_mm512_set_pd(f(7), f(6), f(5), f(4), f(3), f(2), f(1), f(0))};  // lane 0 = f(0)
  }
};
using A8 = LanesAvx512;
PDAMP_LANE_INLINE A8 operator+(A8 a, A8 b) { return {_mm512_add_pd(a.v, b.v)}; }
PDAMP_LANE_INLINE A8 operator-(A8 a, A8 b) { return {_mm512_sub_pd(a.v, b.v)}; }
PDAMP_LANE_INLINE A8 operator*(A8 a, A8 b) { return {_mm512_mul_pd(a.v, b.v)}; }
PDAMP_LANE_INLINE A8 operator/(A8 a, A8 b) { return {_mm512_div_pd(a.v, b.v)}; }
PDAMP_LANE_INLINE A8 operator-(A8 a) { return {_mm512_xor_pd(a.v, _mm512_set1_pd(-0.0))}; }
PDAMP_LANE_INLINE A8 sqrt(A8 a) { return {_mm512_sqrt_pd(a.v)}; }
PDAMP_LANE_INLINE A8::Mask operator<(A8 a, A8 b) { return {_mm512_cmp_pd_mask(a.v, b.v, _CMP_LT_OQ)}; }
PDAMP_LANE_INLINE A8::Mask operator>(A8 a, A8 b) { return {_mm512_cmp_pd_mask(a.v, b.v, _CMP_GT_OQ)}; }
PDAMP_LANE_INLINE A8::Mask operator&(A8::Mask a, A8::Mask b) { return {static_cast<__mmask8>(a.m & b.m)}; }
PDAMP_LANE_INLINE A8::Mask operator|(A8::Mask a, A8::Mask b) { return {static_cast<__mmask8>(a.m | b.m)}; }
PDAMP_LANE_INLINE A8::Mask andnot(A8::Mask a, A8::Mask b) { return {static_cast<__mmask8>(~a.m & b.m)}; }
PDAMP_LANE_INLINE bool any(A8::Mask a) { return a.m != 0; }
PDAMP_LANE_INLINE bool all(A8::Mask a) { return a.m == 0xff; }
PDAMP_LANE_INLINE bool lane(A8::Mask a, int l) { return ((a.m >> l) & 1) != 0; }
PDAMP_LANE_INLINE A8 select(A8::Mask m, A8 yes, A8 no) { return {_mm512_mask_blend_pd(m.m, no.v, yes.v)}; }
PDAMP_LANE_INLINE double lane(A8 a, int l) {
  alignas(64) double t[8];
  _mm512_store_pd(t, a.v);
  return t[l];
}
template <class F>
PDAMP_LANE_INLINE void scatter(A8 a, F&& f) {
  alignas(64) double t[8];
  _mm512_store_pd(t, a.v);
  for (int l = 0; l < 8; ++l) f(l) = t[l];
}
#endif

/// The best two-lane type of the build.
#if defined(PDAMP_LANES_SSE2)
using Lanes2 = LanesSse2;
#elif defined(PDAMP_LANES_NEON)
using Lanes2 = LanesNeon;
#else
using Lanes2 = LanesPortable2;
#endif

/// The lane type the force sweep evaluates touching contacts in: two lanes, the widest
/// every x86-64 has. Wider lanes pay little, and only where the build may assume them:
/// on a 2-core Xeon four AVX2 lanes were within the run-to-run spread (bench_dem, 1000
/// spheres 51.5 against 53.0 M particle-steps/s, 10,000 spheres 34.6 against 34.3); on a
/// 2-core AMD EPYC (Zen 5) whole runs of the 6 x 6 bench layer, paired against two SSE2
/// lanes, took 0.929 of the time with four AVX2 lanes and 0.881 with eight AVX-512 lanes
/// (docs/dem.md, Performance design). Gathering a contact's operands and adding its
/// forces stay one lane at a time whatever the width, and the rest of a block runs in
/// fewer lanes. PDAMP_DEM_LANES=1, 2, 4 or 8 forces a width (for measurements; 4 needs
/// -mavx2, 8 -mavx512f -mavx512dq, and Eigen then wants -mfma).
#if defined(PDAMP_DEM_LANES) && PDAMP_DEM_LANES == 1
using SweepLanes = Lanes1;
#elif defined(PDAMP_DEM_LANES) && PDAMP_DEM_LANES == 4 && defined(PDAMP_LANES_AVX2)
using SweepLanes = LanesAvx2;
#elif defined(PDAMP_DEM_LANES) && PDAMP_DEM_LANES == 8 && defined(PDAMP_LANES_AVX512)
using SweepLanes = LanesAvx512;
#else
using SweepLanes = Lanes2;
#endif

}  // namespace pdamp::dem_reference::detail::simd
