// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDGridLanes.h
 * @brief Deforms a range of points W at a time on the CPU, with the widest SIMD the CPU has (host only).
 *
 * A mesh's consecutive vertices mostly lie in one cell of the lattice (always, for the global basis's single
 * cell). DeformPoints() walks the points in blocks of W: a block whose points are all bound to one cell is
 * deformed at once by GridDeformation::Deform() instantiated on Lanes<Real, W> (FFDLanes.h), each control point
 * read once for the W points; any other block, and the tail, point by point by the same function on Real.
 * Both compute the same function; they may differ in the last bit, where the wide code fuses a multiply and
 * an add that the one-point code, compiled for any x86-64, does not.
 *
 * The default build must run on any x86-64, so the wide variants are compiled with GCC's target attribute
 * (AVX-512: 16 floats or 8 doubles a block; AVX2 and FMA: 8 or 4) and chosen at run time by SimdLevelOfCpu();
 * `flatten` inlines every kernel function into them, so no out-of-line copy compiled for one instruction set
 * can be shared with code compiled for another. Compilers without these extensions use the one-point loop.
 */
#ifndef FFDGridLanes_h
#define FFDGridLanes_h

#include "FFDGridDeformation.h"

#include <cstdint>

#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__)) && !defined(__CUDACC__)
#define FFD_HAVE_LANES 1
#include "FFDLanes.h"
#define FFD_TARGET_AVX512 __attribute__((target("avx512f,avx512dq,avx512vl,avx512bw,avx2,fma,bmi2"), flatten))
#define FFD_TARGET_AVX2 __attribute__((target("avx2,fma,bmi2"), flatten))
#else
#define FFD_HAVE_LANES 0
#endif

namespace ffd
{

/// Instruction sets of the blocks: SSE2 (any x86-64: 4 floats, 2 doubles), AVX2 with FMA, AVX-512.
enum class SimdLevel
{
  None = 0, ///< one point at a time
  SSE2 = 1,
  AVX2 = 2,
  AVX512 = 3,
};

/// The widest level this CPU runs (None where lanes are not compiled in).
inline SimdLevel SimdLevelOfCpu()
{
#if FFD_HAVE_LANES
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
    __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512bw"))
  {
    return SimdLevel::AVX512;
  }
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") && __builtin_cpu_supports("bmi2"))
  {
    return SimdLevel::AVX2;
  }
  return SimdLevel::SSE2;
#else
  return SimdLevel::None;
#endif
}

namespace detail
{
/// Point i deformed alone: cell -1 keeps its position.
template <typename Deformation, typename Real>
inline void DeformOnePoint(const Deformation& deformation, const Real* in, const int* cells, Real* out, std::int64_t i)
{
  const Vec3<Real> x = { in[3 * i], in[3 * i + 1], in[3 * i + 2] };
  const Vec3<Real> y = cells[i] >= 0 ? deformation.Deform(x, cells[i]) : x;
  out[3 * i] = y.x;
  out[3 * i + 1] = y.y;
  out[3 * i + 2] = y.z;
}

template <typename Deformation, typename Real>
inline void DeformOneByOne(
  const Deformation& deformation, const Real* in, const int* cells, Real* out, std::int64_t begin, std::int64_t end)
{
  for (std::int64_t i = begin; i < end; ++i)
  {
    DeformOnePoint(deformation, in, cells, out, i);
  }
}

#if FFD_HAVE_LANES
// Points [begin, begin + count), count <= W, deformed in lanes. Each lane's result depends only on its own point
// and cell, whatever the other lanes hold: a block is evaluated once for each cell its points are bound to, and
// every lane takes the evaluation of its own cell (most blocks of a mesh have one; -1 keeps the position).
// So a point's result does not depend on its neighbours nor on how the range was split among threads.
template <int W, typename Wide, typename Real>
inline void DeformBlock(const Wide& wide, const Real* in, const int* cells, Real* out, int count)
{
  using Lane = Lanes<Real, W>;
  using Mask = typename Lane::IndexVector;
  bool shared = count == W && cells[0] >= 0; // the common case, first: one cell for the whole block
  for (int l = 1; l < count; ++l)
  {
    shared &= cells[l] == cells[0];
  }
  if (shared)
  {
    Vec3<Lane> x;
    Lane::Deinterleave3(in, x.x, x.y, x.z);
    const Vec3<Lane> y = wide.Deform(x, cells[0]);
    Lane::Interleave3(y.x, y.y, y.z, out);
    return;
  }

  Real padded[3 * W] = {};
  int cell[W];
  const Real* source = in;
  for (int l = 0; l < W; ++l)
  {
    cell[l] = l < count ? cells[l] : -1;
  }
  if (count < W)
  {
    for (int v = 0; v < 3 * count; ++v)
    {
      padded[v] = in[v];
    }
    source = padded;
  }
  Vec3<Lane> x;
  Lane::Deinterleave3(source, x.x, x.y, x.z);

  Vec3<Lane> y = x;
  bool done[W] = {};
  for (int first = 0; first < W; ++first)
  {
    if (done[first] || cell[first] < 0)
    {
      continue;
    }
    const int c = cell[first];
    Mask mine;
    for (int l = 0; l < W; ++l)
    {
      const bool same = cell[l] == c;
      mine[l] = same ? -1 : 0;
      done[l] = done[l] || same;
    }
    const Vec3<Lane> yc = wide.Deform(x, c);
    y = { Select(mine, yc.x, y.x), Select(mine, yc.y, y.y), Select(mine, yc.z, y.z) };
  }

  if (count == W)
  {
    Lane::Interleave3(y.x, y.y, y.z, out);
    return;
  }
  Lane::Interleave3(y.x, y.y, y.z, padded);
  for (int v = 0; v < 3 * count; ++v)
  {
    out[v] = padded[v];
  }
}

template <int W, typename Deformation, typename Real>
inline void DeformInBlocks(
  const Deformation& deformation, const Real* in, const int* cells, Real* out, std::int64_t begin, std::int64_t end)
{
  const auto wide = deformation.template WithLanes<Lanes<Real, W>>();
  for (std::int64_t i = begin; i < end; i += W)
  {
    const int count = int(end - i < W ? end - i : W);
    DeformBlock<W>(wide, in + 3 * i, cells + i, out + 3 * i, count);
  }
}

template <typename Deformation, typename Real>
FFD_TARGET_AVX512 void DeformInBlocksAVX512(
  const Deformation& deformation, const Real* in, const int* cells, Real* out, std::int64_t begin, std::int64_t end)
{
  DeformInBlocks<64 / sizeof(Real)>(deformation, in, cells, out, begin, end);
}

template <typename Deformation, typename Real>
FFD_TARGET_AVX2 void DeformInBlocksAVX2(
  const Deformation& deformation, const Real* in, const int* cells, Real* out, std::int64_t begin, std::int64_t end)
{
  DeformInBlocks<32 / sizeof(Real)>(deformation, in, cells, out, begin, end);
}
#endif
} // namespace detail

/**
 * out = the deformation of in for points [begin, end): 3 values per point (x y z), cells[i] from BindToGrid()
 * (-1: the point keeps its position). `level` at most SimdLevelOfCpu(); None deforms one point at a time.
 */
template <typename Deformation, typename Real>
inline void DeformPoints(SimdLevel level, const Deformation& deformation, const Real* in, const int* cells, Real* out,
  std::int64_t begin, std::int64_t end)
{
#if FFD_HAVE_LANES
  switch (level)
  {
    case SimdLevel::AVX512:
      detail::DeformInBlocksAVX512(deformation, in, cells, out, begin, end);
      return;
    case SimdLevel::AVX2:
      detail::DeformInBlocksAVX2(deformation, in, cells, out, begin, end);
      return;
    case SimdLevel::SSE2:
      detail::DeformInBlocks<16 / sizeof(Real)>(deformation, in, cells, out, begin, end);
      return;
    case SimdLevel::None:
      break;
  }
#else
  (void)level;
#endif
  detail::DeformOneByOne(deformation, in, cells, out, begin, end);
}

} // namespace ffd

#endif
