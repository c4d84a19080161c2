// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDLanes.h
 * @brief A number of W lanes, so that the kernels deform W points at once on the CPU (host only).
 *
 * The kernels are templates on their number type. Lanes<T, W> is one more number type: the same functions
 * instantiated with it deform W points at once, one per lane, where those W points are bound to one cell, so
 * that every index the kernels compute and every control point they read is the same for all lanes (a control
 * point is read once and broadcast). The arithmetic is GCC/Clang vector extensions rather than intrinsics: a
 * function compiled for AVX-512 gets zmm instructions, one for AVX2 ymm, and a plain x86-64 build SSE2
 * (FFDGridLanes.h picks the widest at run time), from the same source. The exceptions, a broadcast, a square
 * root, a clamp to [0, 1], a mask to bits and a non-temporal store, are one intrinsic per width (detail::Splat(),
 * detail::Sqrt(), detail::Clamp01(), detail::LaneBits(), detail::Stream()).
 */
#ifndef FFDLanes_h
#define FFDLanes_h

#include "FFDVector.h"

#include <immintrin.h>

#include <cstdint>
#include <cstring>
#include <type_traits>
#include <utility>

namespace ffd
{

namespace detail
{
// What vector extensions do not give in one instruction, one overload per width: each is compiled for the
// instruction set of its width and inlined only into the functions of FFDGridLanes.h compiled for that set (the
// 16-byte ones are SSE2, which every x86-64 has). GCC 12 builds a splat of a scalar (`Vector{} + s`,
// `s - Vector{}`, an initializer list) with two to sixteen instructions, or through the stack where
// neighbouring scalars are splatted; the intrinsics give one broadcast.
typedef float Float32x16 __attribute__((vector_size(64)));
typedef double Float64x8 __attribute__((vector_size(64)));
typedef float Float32x8 __attribute__((vector_size(32)));
typedef double Float64x4 __attribute__((vector_size(32)));
typedef float Float32x4 __attribute__((vector_size(16)));
typedef double Float64x2 __attribute__((vector_size(16)));
typedef std::int32_t Int32x16 __attribute__((vector_size(64)));
typedef std::int64_t Int64x8 __attribute__((vector_size(64)));
typedef std::int32_t Int32x8 __attribute__((vector_size(32)));
typedef std::int64_t Int64x4 __attribute__((vector_size(32)));
typedef std::int32_t Int32x4 __attribute__((vector_size(16)));
typedef std::int64_t Int64x2 __attribute__((vector_size(16)));

/// v = s in every lane.
__attribute__((target("avx512f"))) inline void Splat(float s, Float32x16& v)
{
  v = reinterpret_cast<Float32x16>(_mm512_set1_ps(s));
}
__attribute__((target("avx512f"))) inline void Splat(double s, Float64x8& v)
{
  v = reinterpret_cast<Float64x8>(_mm512_set1_pd(s));
}
__attribute__((target("avx"))) inline void Splat(float s, Float32x8& v)
{
  v = reinterpret_cast<Float32x8>(_mm256_set1_ps(s));
}
__attribute__((target("avx"))) inline void Splat(double s, Float64x4& v)
{
  v = reinterpret_cast<Float64x4>(_mm256_set1_pd(s));
}
inline void Splat(float s, Float32x4& v)
{
  v = reinterpret_cast<Float32x4>(_mm_set1_ps(s));
}
inline void Splat(double s, Float64x2& v)
{
  v = reinterpret_cast<Float64x2>(_mm_set1_pd(s));
}

/// *p = v by a non-temporal store (p aligned to the vector's size): the cache line is written without being
/// read first, and not kept in the caches.
__attribute__((target("avx512f"))) inline void Stream(float* p, const Float32x16& v)
{
  _mm512_stream_ps(p, reinterpret_cast<__m512>(v));
}
__attribute__((target("avx512f"))) inline void Stream(double* p, const Float64x8& v)
{
  _mm512_stream_pd(p, reinterpret_cast<__m512d>(v));
}
__attribute__((target("avx"))) inline void Stream(float* p, const Float32x8& v)
{
  _mm256_stream_ps(p, reinterpret_cast<__m256>(v));
}
__attribute__((target("avx"))) inline void Stream(double* p, const Float64x4& v)
{
  _mm256_stream_pd(p, reinterpret_cast<__m256d>(v));
}
inline void Stream(float* p, const Float32x4& v)
{
  _mm_stream_ps(p, reinterpret_cast<__m128>(v));
}
inline void Stream(double* p, const Float64x2& v)
{
  _mm_stream_pd(p, reinterpret_cast<__m128d>(v));
}

/// r = the square root of v in every lane.
__attribute__((target("avx512f"))) inline void Sqrt(const Float32x16& v, Float32x16& r)
{
  r = reinterpret_cast<Float32x16>(_mm512_sqrt_ps(reinterpret_cast<__m512>(v)));
}
__attribute__((target("avx512f"))) inline void Sqrt(const Float64x8& v, Float64x8& r)
{
  r = reinterpret_cast<Float64x8>(_mm512_sqrt_pd(reinterpret_cast<__m512d>(v)));
}
__attribute__((target("avx"))) inline void Sqrt(const Float32x8& v, Float32x8& r)
{
  r = reinterpret_cast<Float32x8>(_mm256_sqrt_ps(reinterpret_cast<__m256>(v)));
}
__attribute__((target("avx"))) inline void Sqrt(const Float64x4& v, Float64x4& r)
{
  r = reinterpret_cast<Float64x4>(_mm256_sqrt_pd(reinterpret_cast<__m256d>(v)));
}
inline void Sqrt(const Float32x4& v, Float32x4& r)
{
  r = reinterpret_cast<Float32x4>(_mm_sqrt_ps(reinterpret_cast<__m128>(v)));
}
inline void Sqrt(const Float64x2& v, Float64x2& r)
{
  r = reinterpret_cast<Float64x2>(_mm_sqrt_pd(reinterpret_cast<__m128d>(v)));
}

/// r = v clamped to [0, 1] in every lane: max(0, v) then min(1, .), whose operand order keeps a NaN and -0 as the
/// comparisons v < 0 ? 0 : v and v > 1 ? 1 : v do (GCC 12 compiles those to a compare and a masked move each).
__attribute__((target("avx512f"))) inline void Clamp01(const Float32x16& v, Float32x16& r)
{
  r = reinterpret_cast<Float32x16>(
    _mm512_min_ps(_mm512_set1_ps(1.0f), _mm512_max_ps(_mm512_setzero_ps(), reinterpret_cast<__m512>(v))));
}
__attribute__((target("avx512f"))) inline void Clamp01(const Float64x8& v, Float64x8& r)
{
  r = reinterpret_cast<Float64x8>(
    _mm512_min_pd(_mm512_set1_pd(1.0), _mm512_max_pd(_mm512_setzero_pd(), reinterpret_cast<__m512d>(v))));
}
__attribute__((target("avx"))) inline void Clamp01(const Float32x8& v, Float32x8& r)
{
  r = reinterpret_cast<Float32x8>(
    _mm256_min_ps(_mm256_set1_ps(1.0f), _mm256_max_ps(_mm256_setzero_ps(), reinterpret_cast<__m256>(v))));
}
__attribute__((target("avx"))) inline void Clamp01(const Float64x4& v, Float64x4& r)
{
  r = reinterpret_cast<Float64x4>(
    _mm256_min_pd(_mm256_set1_pd(1.0), _mm256_max_pd(_mm256_setzero_pd(), reinterpret_cast<__m256d>(v))));
}
inline void Clamp01(const Float32x4& v, Float32x4& r)
{
  r = reinterpret_cast<Float32x4>(
    _mm_min_ps(_mm_set1_ps(1.0f), _mm_max_ps(_mm_setzero_ps(), reinterpret_cast<__m128>(v))));
}
inline void Clamp01(const Float64x2& v, Float64x2& r)
{
  r = reinterpret_cast<Float64x2>(
    _mm_min_pd(_mm_set1_pd(1.0), _mm_max_pd(_mm_setzero_pd(), reinterpret_cast<__m128d>(v))));
}

/// Bit l set where lane l of m is -1 (lanes are -1 or 0).
__attribute__((target("avx512f,avx512dq"))) inline unsigned LaneBits(const Int32x16& m)
{
  return _mm512_movepi32_mask(reinterpret_cast<__m512i>(m));
}
__attribute__((target("avx512f,avx512dq"))) inline unsigned LaneBits(const Int64x8& m)
{
  return _mm512_movepi64_mask(reinterpret_cast<__m512i>(m));
}
__attribute__((target("avx"))) inline unsigned LaneBits(const Int32x8& m)
{
  return unsigned(_mm256_movemask_ps(reinterpret_cast<__m256>(m)));
}
__attribute__((target("avx"))) inline unsigned LaneBits(const Int64x4& m)
{
  return unsigned(_mm256_movemask_pd(reinterpret_cast<__m256d>(m)));
}
inline unsigned LaneBits(const Int32x4& m)
{
  return unsigned(_mm_movemask_ps(reinterpret_cast<__m128>(m)));
}
inline unsigned LaneBits(const Int64x2& m)
{
  return unsigned(_mm_movemask_pd(reinterpret_cast<__m128d>(m)));
}
} // namespace detail

template <typename T, int W>
struct Lanes
{
  static_assert(std::is_floating_point<T>::value && W >= 2 && (W & (W - 1)) == 0, "W floating-point lanes");
  using Scalar = T;
  static constexpr int Width = W;
  typedef T Vector __attribute__((vector_size(W * sizeof(T))));
  using Index = std::conditional_t<sizeof(T) == 4, std::int32_t, std::int64_t>;
  typedef Index IndexVector __attribute__((vector_size(W * sizeof(T))));

  Vector V;

  Lanes() = default;
  /// Every lane s (also from ints and doubles, as the kernels' Real(1) and Real(cell) need).
  template <typename S, typename = std::enable_if_t<std::is_arithmetic<S>::value>>
  Lanes(S s)
  {
    detail::Splat(T(s), this->V);
  }
  explicit Lanes(const Vector& v)
    : V(v)
  {
  }

  friend Lanes operator+(const Lanes& a, const Lanes& b) { return Lanes(a.V + b.V); }
  friend Lanes operator-(const Lanes& a, const Lanes& b) { return Lanes(a.V - b.V); }
  friend Lanes operator*(const Lanes& a, const Lanes& b) { return Lanes(a.V * b.V); }
  friend Lanes operator/(const Lanes& a, const Lanes& b) { return Lanes(a.V / b.V); }
  friend Lanes operator-(const Lanes& a) { return Lanes(-a.V); }
  /// a in the lanes where mask is -1, b where it is 0. Written with bitwise operations: GCC 12 compiles
  /// `mask ? a : b` lane by lane, with branches, where the mask is not a comparison in the same expression.
  friend Lanes Select(const IndexVector& mask, const Lanes& a, const Lanes& b)
  {
    return Lanes(reinterpret_cast<Vector>(
      (reinterpret_cast<IndexVector>(a.V) & mask) | (reinterpret_cast<IndexVector>(b.V) & ~mask)));
  }

  Lanes& operator+=(const Lanes& a)
  {
    this->V += a.V;
    return *this;
  }

  // The conditions of the kernels (FFDVector.h), lane by lane.
  friend IndexVector InRange(const Lanes& v, const Lanes& lo, const Lanes& hi) { return (v.V >= lo.V) & (v.V <= hi.V); }
  friend Lanes KeepWhere(const IndexVector& keep, const Lanes& v)
  {
    return Lanes(reinterpret_cast<Vector>(reinterpret_cast<IndexVector>(v.V) & keep));
  }
  friend IndexVector IsPositive(const Lanes& v) { return v.V > Vector{}; }
  friend Lanes Choose(const IndexVector& condition, const Lanes& a, const Lanes& b) { return Select(condition, a, b); }
  friend Lanes sqrt(const Lanes& v)
  {
    Lanes r;
    detail::Sqrt(v.V, r.V);
    return r;
  }

  /// Bit l set where lane l of mask is -1 (mask lanes are -1 or 0).
  static unsigned Bits(const IndexVector& mask) { return detail::LaneBits(mask); }
  friend Lanes Clamp01(const Lanes& a)
  {
    Lanes r;
    detail::Clamp01(a.V, r.V);
    return r;
  }

  /// x, y, z of W points stored as x0 y0 z0 x1 y1 z1 ... (3 W values, no alignment needed).
  static void Deinterleave3(const T* p, Lanes& x, Lanes& y, Lanes& z)
  {
    Vector a, b, c;
    std::memcpy(&a, p, sizeof(Vector));
    std::memcpy(&b, p + W, sizeof(Vector));
    std::memcpy(&c, p + 2 * W, sizeof(Vector));
    x = Gather<0>(a, b, c, std::make_index_sequence<W>());
    y = Gather<1>(a, b, c, std::make_index_sequence<W>());
    z = Gather<2>(a, b, c, std::make_index_sequence<W>());
  }

  /// The inverse of Deinterleave3(). Streaming: by non-temporal stores (detail::Stream()), p aligned to the
  /// vector's size; the caller fences them (_mm_sfence()) before another thread reads them.
  template <bool Streaming = false>
  static void Interleave3(const Lanes& x, const Lanes& y, const Lanes& z, T* p)
  {
    Scatter<0, Streaming>(x.V, y.V, z.V, p, std::make_index_sequence<W>());
    Scatter<1, Streaming>(x.V, y.V, z.V, p + W, std::make_index_sequence<W>());
    Scatter<2, Streaming>(x.V, y.V, z.V, p + 2 * W, std::make_index_sequence<W>());
  }

private:
  // Lane l of component C is value 3 l + C of a|b|c: taken from a|b by a first shuffle, then kept or replaced
  // by one of c by a second (two-source shuffles with constant masks: vpermt2ps/pd on AVX-512).
  template <int C, std::size_t... L>
  static Lanes Gather(const Vector& a, const Vector& b, const Vector& c, std::index_sequence<L...>)
  {
    constexpr Index w = W;
    const IndexVector fromAB = { Index(3 * L + C < 2 * W ? 3 * L + C : 0)... };
    const IndexVector withC = { Index(3 * L + C < 2 * W ? Index(L) : w + Index(3 * L + C) - 2 * w)... };
    return Lanes(__builtin_shuffle(__builtin_shuffle(a, b, fromAB), c, withC));
  }

  // Value m = K W + j of the interleaved output is component m % 3 of lane m / 3. (Stored here rather than
  // returned: GCC warns of the ABI of a returned vector in code not compiled for its width.)
  template <int K, bool Streaming, std::size_t... J>
  static void Scatter(const Vector& x, const Vector& y, const Vector& z, T* p, std::index_sequence<J...>)
  {
    constexpr Index w = W;
    const IndexVector fromXY = { Index(
      ((K * W + J) % 3 == 1 ? w : 0) + ((K * W + J) % 3 == 2 ? 0 : (K * W + J) / 3))... };
    const IndexVector withZ = { Index((K * W + J) % 3 == 2 ? w + Index((K * W + J) / 3) : Index(J))... };
    const Vector v = __builtin_shuffle(__builtin_shuffle(x, y, fromXY), z, withZ);
    if constexpr (Streaming)
    {
      detail::Stream(p, v);
    }
    else
    {
      std::memcpy(p, &v, sizeof(Vector));
    }
  }
};

template <typename T, int W>
struct ScalarOf<Lanes<T, W>>
{
  using Type = T;
};

} // namespace ffd

#endif
