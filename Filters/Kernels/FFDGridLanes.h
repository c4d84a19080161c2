// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDGridLanes.h
 * @brief Deforms points W at a time on the CPU, with the widest SIMD the CPU has (host only).
 *
 * GridDeformation::Deform() instantiated on Lanes<Real, W> (FFDLanes.h) deforms W points bound to one cell at
 * once, each control point read once for all of them. The points are taken in blocks of BlockSize
 * consecutive points: a mesh whose vertices come in a spatially coherent order has most of its blocks in one
 * cell or a few (always one, for the global basis), and DeformBlocksInPlace() deforms those in place, once
 * per cell, each lane keeping the result of its own cell. The points of the other blocks are listed once, at
 * binding, sorted by cell (GatherByCell()), and DeformGathered() deforms them W at a time from that list: a
 * mesh in random vertex order costs a gather and a scatter per point, not one evaluation per cell of a block.
 * Every lane's result depends only on its own point and cell, so a point is deformed the same whichever pass
 * takes it and however the work is split among threads. The one-point code (SimdLevel::None) computes the same function; it may differ in the last
 * bit, where the wide code fuses a multiply and an add.
 *
 * The default build must run on any x86-64, so the wide variants are compiled with GCC's target attribute
 * (AVX-512: 16 floats or 8 doubles a lane group; AVX2 and FMA: 8 or 4) and chosen at run time by
 * SimdLevelOfCpu(); `flatten` inlines every kernel function into them, so that no out-of-line copy compiled for
 * one instruction set is shared with code compiled for another. SSE2 (any x86-64) takes 4 floats or 2 doubles.
 */
#ifndef FFDGridLanes_h
#define FFDGridLanes_h

#include "FFDGridDeformation.h"

#include <cstdint>
#include <vector>

#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__)) && !defined(__CUDACC__)
#define FFD_HAVE_LANES 1
#include "FFDLanes.h"
#define FFD_TARGET_AVX512 __attribute__((target("avx512f,avx512dq,avx512vl,avx512bw,avx2,fma,bmi2"), flatten))
#define FFD_TARGET_AVX2 __attribute__((target("avx2,fma,bmi2"), flatten))
#define FFD_TARGET_SSE2 __attribute__((flatten))
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

/// Consecutive points that DeformBlocksInPlace() takes together: a multiple of every level's lanes (16 floats).
constexpr int BlockSize = 16;

/// Blocks whose points lie in at most this many cells (-1 counts as one) are deformed in place, once per
/// cell, with each lane taking its own cell's result; the points of the others are gathered by cell. In place
/// reads and writes memory in order; a gather and a scatter per point cost less than more evaluations only
/// when a block's points are scattered over many cells, as in a mesh in random vertex order (with 4, the
/// 6.7 M-point armadillo of BENCHMARKS.md ran 2 times slower, its memory accessed at random).
constexpr int MaxCellsInPlace = 8;

/// True when block b (of n points) is deformed in place: it is whole and its points lie in at most
/// MaxCellsInPlace cells.
inline bool BlockInPlace(const int* cells, std::int64_t n, std::int64_t b)
{
  const std::int64_t first = b * BlockSize;
  if (first + BlockSize > n)
  {
    return false; // the last, partial block goes to the gathered points
  }
  int seen[MaxCellsInPlace];
  int count = 0;
  for (int l = 0; l < BlockSize; ++l)
  {
    const int cell = cells[first + l];
    bool known = false;
    for (int k = 0; k < count; ++k)
    {
      known |= seen[k] == cell;
    }
    if (!known)
    {
      if (count == MaxCellsInPlace)
      {
        return false;
      }
      seen[count++] = cell;
    }
  }
  return true;
}

/**
 * The points of the blocks not deformed in place (BlockInPlace()), sorted by cell (a stable counting sort:
 * cell -1 first, then by cell, each cell's points in input order), for DeformGathered(). `cellCount` is the
 * number of cells of the binding.
 */
inline std::vector<int> GatherByCell(const int* cells, std::int64_t n, int cellCount)
{
  std::vector<std::int64_t> offsets(std::size_t(cellCount) + 2, 0);
  const std::int64_t blocks = (n + BlockSize - 1) / BlockSize;
  for (std::int64_t b = 0; b < blocks; ++b)
  {
    if (!BlockInPlace(cells, n, b))
    {
      for (std::int64_t i = b * BlockSize; i < n && i < (b + 1) * BlockSize; ++i)
      {
        ++offsets[std::size_t(cells[i] + 2)];
      }
    }
  }
  for (std::size_t c = 1; c < offsets.size(); ++c)
  {
    offsets[c] += offsets[c - 1];
  }
  std::vector<int> gathered(std::size_t(offsets.back()));
  for (std::int64_t b = 0; b < blocks; ++b)
  {
    if (!BlockInPlace(cells, n, b))
    {
      for (std::int64_t i = b * BlockSize; i < n && i < (b + 1) * BlockSize; ++i)
      {
        gathered[std::size_t(offsets[std::size_t(cells[i] + 1)]++)] = int(i);
      }
    }
  }
  return gathered;
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

#if FFD_HAVE_LANES
template <int W, typename Deformation, typename Real>
inline void BlocksInPlaceInLanes(const Deformation& deformation, const Real* in, const int* cells, Real* out,
  std::int64_t n, std::int64_t blockBegin, std::int64_t blockEnd)
{
  static_assert(BlockSize % W == 0, "a block is a whole number of lane groups");
  using Lane = Lanes<Real, W>;
  using Mask = typename Lane::IndexVector;
  const auto wide = deformation.template WithLanes<Lane>();
  for (std::int64_t b = blockBegin; b < blockEnd; ++b)
  {
    if (!BlockInPlace(cells, n, b))
    {
      continue;
    }
    for (std::int64_t i = b * BlockSize; i < (b + 1) * BlockSize; i += W)
    {
      Vec3<Lane> x;
      Lane::Deinterleave3(in + 3 * i, x.x, x.y, x.z);
      bool one = cells[i] >= 0; // the common case first: the W points in one cell
      for (int l = 1; l < W; ++l)
      {
        one &= cells[i + l] == cells[i];
      }
      if (one)
      {
        const Vec3<Lane> y = wide.Deform(x, int(cells[i]));
        Lane::Interleave3(y.x, y.y, y.z, out + 3 * i);
        continue;
      }
      Vec3<Lane> y = x; // lanes of cell -1 keep their position
      bool done[W] = {};
      for (int first = 0; first < W; ++first)
      {
        const int cell = cells[i + first];
        if (done[first] || cell < 0)
        {
          continue;
        }
        Mask mine;
        for (int l = 0; l < W; ++l)
        {
          const bool same = cells[i + l] == cell;
          mine[l] = same ? -1 : 0;
          done[l] = done[l] || same;
        }
        const Vec3<Lane> yc = wide.Deform(x, cell);
        y = { Select(mine, yc.x, y.x), Select(mine, yc.y, y.y), Select(mine, yc.z, y.z) };
      }
      Lane::Interleave3(y.x, y.y, y.z, out + 3 * i);
    }
  }
}

template <int W, typename Deformation, typename Real>
inline void GatheredInLanes(const Deformation& deformation, const Real* in, const int* cells, const int* gathered,
  Real* out, std::int64_t begin, std::int64_t end)
{
  using Lane = Lanes<Real, W>;
  const auto wide = deformation.template WithLanes<Lane>();
  Real staged[3 * W] = {};
  std::int64_t g = begin;
  while (g < end)
  {
    // Up to W listed points of one cell; unused lanes repeat the first point and are not written back.
    const int cell = cells[gathered[g]];
    int count = 1;
    while (count < W && g + count < end && cells[gathered[g + count]] == cell)
    {
      ++count;
    }
    for (int l = 0; l < W; ++l)
    {
      const std::int64_t i = gathered[g + (l < count ? l : 0)];
      staged[3 * l] = in[3 * i];
      staged[3 * l + 1] = in[3 * i + 1];
      staged[3 * l + 2] = in[3 * i + 2];
    }
    if (cell >= 0)
    {
      Vec3<Lane> x;
      Lane::Deinterleave3(staged, x.x, x.y, x.z);
      const Vec3<Lane> y = wide.Deform(x, cell);
      Lane::Interleave3(y.x, y.y, y.z, staged);
    }
    for (int l = 0; l < count; ++l)
    {
      const std::int64_t i = gathered[g + l];
      out[3 * i] = staged[3 * l];
      out[3 * i + 1] = staged[3 * l + 1];
      out[3 * i + 2] = staged[3 * l + 2];
    }
    g += count;
  }
}

// The wide variants of both passes, one function per instruction set (see the file's documentation).
#define FFD_LANE_VARIANTS(Suffix, Target, Bytes)                                                              \
  template <typename Deformation, typename Real>                                                              \
  Target void BlocksInPlace##Suffix(const Deformation& deformation, const Real* in, const int* cells, Real* out, \
    std::int64_t n, std::int64_t blockBegin, std::int64_t blockEnd)                                           \
  {                                                                                                           \
    BlocksInPlaceInLanes<Bytes / sizeof(Real)>(deformation, in, cells, out, n, blockBegin, blockEnd);         \
  }                                                                                                           \
  template <typename Deformation, typename Real>                                                              \
  Target void Gathered##Suffix(const Deformation& deformation, const Real* in, const int* cells,              \
    const int* gathered, Real* out, std::int64_t begin, std::int64_t end)                                     \
  {                                                                                                           \
    GatheredInLanes<Bytes / sizeof(Real)>(deformation, in, cells, gathered, out, begin, end);                \
  }
FFD_LANE_VARIANTS(AVX512, FFD_TARGET_AVX512, 64)
FFD_LANE_VARIANTS(AVX2, FFD_TARGET_AVX2, 32)
FFD_LANE_VARIANTS(SSE2, FFD_TARGET_SSE2, 16)
#undef FFD_LANE_VARIANTS
#endif
} // namespace detail

/**
 * First pass: out = the deformation of in for the points of blocks [blockBegin, blockEnd) that are deformed in
 * place (BlockInPlace()); the others are left to DeformGathered(). 3 values per point
 * (x y z), n points, cells[i] from BindToGrid() (-1: the point keeps its position). `level` at most
 * SimdLevelOfCpu().
 */
template <typename Deformation, typename Real>
inline void DeformBlocksInPlace(SimdLevel level, const Deformation& deformation, const Real* in, const int* cells,
  Real* out, std::int64_t n, std::int64_t blockBegin, std::int64_t blockEnd)
{
#if FFD_HAVE_LANES
  switch (level)
  {
    case SimdLevel::AVX512:
      return detail::BlocksInPlaceAVX512(deformation, in, cells, out, n, blockBegin, blockEnd);
    case SimdLevel::AVX2:
      return detail::BlocksInPlaceAVX2(deformation, in, cells, out, n, blockBegin, blockEnd);
    case SimdLevel::SSE2:
      return detail::BlocksInPlaceSSE2(deformation, in, cells, out, n, blockBegin, blockEnd);
    case SimdLevel::None:
      break;
  }
#endif
  for (std::int64_t b = blockBegin; b < blockEnd; ++b)
  {
    if (BlockInPlace(cells, n, b))
    {
      for (std::int64_t i = b * BlockSize; i < (b + 1) * BlockSize; ++i)
      {
        detail::DeformOnePoint(deformation, in, cells, out, i);
      }
    }
  }
}

/// Second pass: the points gathered[begin, end) of GatherByCell()'s list.
template <typename Deformation, typename Real>
inline void DeformGathered(SimdLevel level, const Deformation& deformation, const Real* in, const int* cells,
  const int* gathered, Real* out, std::int64_t begin, std::int64_t end)
{
#if FFD_HAVE_LANES
  switch (level)
  {
    case SimdLevel::AVX512:
      return detail::GatheredAVX512(deformation, in, cells, gathered, out, begin, end);
    case SimdLevel::AVX2:
      return detail::GatheredAVX2(deformation, in, cells, gathered, out, begin, end);
    case SimdLevel::SSE2:
      return detail::GatheredSSE2(deformation, in, cells, gathered, out, begin, end);
    case SimdLevel::None:
      break;
  }
#endif
  for (std::int64_t g = begin; g < end; ++g)
  {
    detail::DeformOnePoint(deformation, in, cells, out, gathered[g]);
  }
}

} // namespace ffd

#endif
