// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDGridLanes.h
 * @brief How the CPU passes deform points W at a time in SIMD lanes (host only; the FFDCpu library's own).
 *
 * GridDeformation's functions instantiated on Lanes<Real, W> (FFDLanes.h) deform W points at once. The points
 * are taken in blocks of BlockSize consecutive points, and a binding chooses how (MaxCellsInPlace(), from its
 * mean number of cells a block):
 * - In place (ffd::DeformBlocksInPlace(), FFDGridPasses.h), reading and writing memory in order. A lane group in one
 * cell reads each control point once for all lanes. A group in several cells (listed at binding, ListBlockCells())
 * computes each lane's weights once, then each cell's sum in all lanes, kept in that cell's lanes (DeformInLaneCells(),
 * FFDLaneCells.h).
 * - Gathered (DeformGathered()): the points of the blocks in more than MaxCellsInPlace() cells are listed once,
 *   at binding, tile by tile, each tile's sorted by cell (ListGatheredPoints()); the caller keeps a copy of
 *   their coordinates in that order (CopyGatheredPoints()). The pass deforms a tile's list in order into a
 *   staging buffer that stays in cache, then writes the tile's results out in point order, each read from its
 *   place in the buffer.
 * A mesh whose vertices come in a spatially coherent order has most of its groups in one cell and a few in two
 * or three: it is deformed in place. A mesh in random vertex order (several cells a block on average) would
 * evaluate several cells a group: all its blocks are gathered.
 * Every lane's result depends only on its own point and cell, so a point is deformed the same whichever pass
 * takes it and however the work is split among threads. The one-point code (SimdLevel::None) computes the same
 * function; it may differ in the last bit, where the wide code fuses a multiply and an add.
 *
 * Included only by the library's translation unit of each level, which defines that level's kernels
 * (FFD_DEFINE_GRID_KERNELS(), compiled for its instruction set: FFDSimdLevel.h) and instantiates its passes.
 */
#ifndef FFDGridLanes_h
#define FFDGridLanes_h

#include "FFDCellTable.h"
#include "FFDDeformPoint.h"
#include "FFDGridDeformation.h"
#include "FFDGridPassLevels.h"
#include "FFDLaneCells.h"
#include "FFDPointBlocks.h"
#include "FFDSimdLevel.h"

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <vector>

#if FFD_HAVE_LANES
namespace ffd
{
namespace detail
{
template <typename Lane>
inline typename Lane::IndexVector LaneCellsOf(const int* cells)
{
  typedef int CellVector __attribute__((vector_size(Lane::Width * sizeof(int))));
  CellVector narrow;
  std::memcpy(&narrow, cells, sizeof(narrow));
  return __builtin_convertvector(narrow, typename Lane::IndexVector);
}

/// Blocks of the in-place pass (of a local basis) whose points are not all in one cell.
template <typename Lane, bool Streaming, typename Deformation, typename Wide, typename Real>
inline void DeformInSeveralCells(const Deformation& deformation, const Wide& wide, const CellSplit& split,
  const BlockCells& blocks, const Real* in, Real* out, std::int64_t outFirst, const std::int64_t* several,
  int severalCount)
{
  for (int s = 0; s < severalCount; ++s)
  {
    const int* entry = blocks.List.data() + blocks.Entry[std::size_t(several[s])];
    for (int group = 0; group < BlockSize / Lane::Width; ++group)
    {
      const std::int64_t i = several[s] * BlockSize + group * Lane::Width;
      Vec3<Lane> x;
      Lane::Deinterleave3(in + 3 * i, x.x, x.y, x.z);
      const GroupCells<Lane> cells(deformation, split, entry, group);
      Vec3<Lane> y = x;
      if (cells.Count > 0)
      {
        const Vec3<Lane> yc = DeformInLaneCells(wide, x, cells);
        y = { Select(cells.Bound, yc.x, x.x), Select(cells.Bound, yc.y, x.y), Select(cells.Bound, yc.z, x.z) };
      }
      Lane::template Interleave3<Streaming>(y.x, y.y, y.z, out + 3 * (i - outFirst));
    }
  }
}

/// The in-place pass over blocks [blockBegin, blockEnd); point i's result goes to out + 3 (i - outFirst), by
/// non-temporal stores where Streaming (out + 3 (blockBegin BlockSize - outFirst) aligned to 64 bytes).
template <int W, bool Streaming, typename Deformation, typename Real>
inline void BlocksInPlaceInLanes(const Deformation& deformation, const Real* in, const int* cells, Real* out,
  const BlockCells& blocks, std::int64_t blockBegin, std::int64_t blockEnd, std::int64_t outFirst)
{
  static_assert(BlockSize % W == 0, "a block is a whole number of lane groups");
  using Lane = Lanes<Real, W>;
  using Mask = typename Lane::IndexVector;
  const auto wide = deformation.template WithLanes<Lane>();
  const bool global = deformation.BasisOf() == GridBasis::Bernstein;
  const CellSplit split = CellSplit::For(deformation.BasisOf(), deformation.Voxels);
  blockEnd = std::min(blockEnd, std::int64_t(blocks.Entry.size())); // the last, partial block is gathered
  // Blocks in several cells are deformed after the others of a window of blocks, still in cache: kept out of the
  // loop over the window, their code leaves that loop's registers to the common case.
  std::int64_t several[InPlaceWindow];
  for (std::int64_t window = blockBegin; window < blockEnd; window += InPlaceWindow)
  {
    int severalCount = 0;
    for (std::int64_t b = window; b < blockEnd && b < window + InPlaceWindow; ++b)
    {
      if (!blocks.InPlace(b))
      {
        continue;
      }
      if (b + PrefetchBlocks < blockEnd)
      {
        // The points a few blocks ahead: the hardware prefetcher does not fetch them in time on large meshes.
        const char* ahead = reinterpret_cast<const char*>(in + 3 * (b + PrefetchBlocks) * BlockSize);
        for (std::size_t line = 0; line < 3 * BlockSize * sizeof(Real); line += 64)
        {
          __builtin_prefetch(ahead + line);
        }
      }
      if (!global && blocks.Entry[std::size_t(b)] >= 0)
      {
        several[severalCount++] = b;
        continue;
      }
      const int first = cells[b * BlockSize];
      int c[3];
      if constexpr (!Deformation::UsesCellTable())
      {
        deformation.CellIndices(split, first < 0 ? 0 : first, c);
      }
      constexpr int Groups = BlockSize / W;
      const std::int64_t begin = b * BlockSize;
      Vec3<Lane> x[Groups], y[Groups];
      for (int g = 0; g < Groups; ++g)
      {
        Lane::Deinterleave3(in + 3 * (begin + g * W), x[g].x, x[g].y, x[g].z);
        y[g] = x[g]; // lanes of cell -1 keep their position
      }
      if (global)
      {
        // The global basis has one cell, 0.
        for (int g = 0; g < Groups; ++g)
        {
          const Mask bound = LaneCellsOf<Lane>(cells + begin + g * W) >= Mask{};
          const Vec3<Lane> yc = wide.Deform(x[g], 0);
          y[g] = { Select(bound, yc.x, x[g].x), Select(bound, yc.y, x[g].y), Select(bound, yc.z, x[g].z) };
        }
      }
      else if (first >= 0)
      {
        // One cell: each control point read once for all lanes of a group, or with a cell table each coefficient
        // once for all lanes of the block (GridDeformation::Deform() of Groups groups).
        if constexpr (Deformation::UsesCellTable())
        {
          wide.template Deform<Groups>(x, first, y);
        }
        else
        {
          for (int g = 0; g < Groups; ++g)
          {
            y[g] = wide.DeformInCell(x[g], first, c);
          }
        }
      }
      for (int g = 0; g < Groups; ++g)
      {
        Lane::template Interleave3<Streaming>(y[g].x, y[g].y, y[g].z, out + 3 * (begin + g * W - outFirst));
      }
    }
    DeformInSeveralCells<Lane, Streaming>(deformation, wide, split, blocks, in, out, outFirst, several, severalCount);
  }
}

/**
 * Point i deformed with its Jacobian (DeformOnePointWithJacobian()) in every lane of a group of its own: by the
 * lane code, not by scalar code, which the compiler may contract into multiply-adds differently in each of its
 * instantiations (that of a dense lattice and that of a sparse one would then differ in the last bit).
 */
template <typename Lane, typename Wide, typename Real>
inline void OnePointInLanes(const Wide& wide, const Real* in, const int* cells, const Real* inNormals, Real* out,
  Real* outNormals, Real* determinants, std::int64_t i)
{
  auto first = [](const Lane& lane)
  {
    Real v;
    std::memcpy(&v, &lane.V, sizeof(Real));
    return v;
  };
  const Vec3<Lane> x = { Lane(in[3 * i]), Lane(in[3 * i + 1]), Lane(in[3 * i + 2]) };
  Mat3<Lane> jacobian = Mat3<Lane>::Identity(); // cell -1 keeps its position
  const Vec3<Lane> y = cells[i] < 0 ? x : wide.Deform(x, cells[i], jacobian);
  out[3 * i] = first(y.x);
  out[3 * i + 1] = first(y.y);
  out[3 * i + 2] = first(y.z);
  if (outNormals)
  {
    const Vec3<Lane> n = { Lane(inNormals[3 * i]), Lane(inNormals[3 * i + 1]), Lane(inNormals[3 * i + 2]) };
    const Vec3<Lane> m = TransformNormal(jacobian, n);
    outNormals[3 * i] = first(m.x);
    outNormals[3 * i + 1] = first(m.y);
    outNormals[3 * i + 2] = first(m.z);
  }
  if (determinants)
  {
    determinants[i] = first(Determinant(jacobian));
  }
}

template <int W, typename Deformation, typename Real>
inline void WithJacobianInLanes(const Deformation& deformation, const Real* in, const int* cells,
  const BlockCells& blocks, const Real* inNormals, Real* out, Real* outNormals, Real* determinants, std::int64_t begin,
  std::int64_t end)
{
  using Lane = Lanes<Real, W>;
  using Mask = typename Lane::IndexVector;
  const auto wide = deformation.template WithLanes<Lane>();
  const bool global = deformation.BasisOf() == GridBasis::Bernstein;
  const CellSplit split = CellSplit::For(deformation.BasisOf(), deformation.Voxels);
  const Mat3<Lane> identity = Mat3<Lane>::Identity();
  // Whole blocks in lanes (begin is a block's first point), the last points one at a time (OnePointInLanes()).
  const std::int64_t whole = std::min(end, std::int64_t(blocks.Entry.size()) * BlockSize);
  std::int64_t i = begin;
  for (; i < whole; i += W)
  {
    Vec3<Lane> x;
    Lane::Deinterleave3(in + 3 * i, x.x, x.y, x.z);
    const int entry = blocks.Entry[std::size_t(i / BlockSize)];
    Vec3<Lane> yc = x;
    Mat3<Lane> jc = identity;
    Mask bound = {};
    if (global)
    {
      bound = LaneCellsOf<Lane>(cells + i) >= Mask{};
      yc = wide.Deform(x, 0, jc);
    }
    else if (entry < 0)
    {
      // One cell (or none) for the whole block.
      if (cells[i] >= 0)
      {
        bound = ~Mask{};
        yc = wide.Deform(x, cells[i], jc);
      }
    }
    else
    {
      // Every cell of the group: the weights and their derivatives once for all lanes, a sum per cell.
      const GroupCells<Lane> group(deformation, split, blocks.List.data() + entry, int(i % BlockSize) / W);
      bound = group.Bound;
      if (group.Count > 0)
      {
        yc = DeformInLaneCells(wide, x, group, jc);
      }
    }
    // Lanes of cell -1 keep their position, their Jacobian is the identity.
    const Vec3<Lane> y = { Select(bound, yc.x, x.x), Select(bound, yc.y, x.y), Select(bound, yc.z, x.z) };
    Mat3<Lane> jacobian;
    for (int r = 0; r < 3; ++r)
    {
      for (int c = 0; c < 3; ++c)
      {
        jacobian.M[r][c] = Select(bound, jc.M[r][c], identity.M[r][c]);
      }
    }
    Lane::Interleave3(y.x, y.y, y.z, out + 3 * i);
    if (outNormals)
    {
      Vec3<Lane> normal;
      Lane::Deinterleave3(inNormals + 3 * i, normal.x, normal.y, normal.z);
      const Vec3<Lane> m = TransformNormal(jacobian, normal);
      Lane::Interleave3(m.x, m.y, m.z, outNormals + 3 * i);
    }
    if (determinants)
    {
      const Lane det = Determinant(jacobian);
      std::memcpy(determinants + i, &det.V, sizeof(det.V));
    }
  }
  for (; i < end; ++i) // the points of the last, partial block
  {
    OnePointInLanes<Lane>(wide, in, cells, inNormals, out, outNormals, determinants, i);
  }
}

/// The kernels of one level: in its own translation unit (FFDGridPasses<Level>.cxx), compiled for its instruction
/// set. The gathered pass deforms a tile into staging by the level's in-place kernel, called (noinline: not a
/// third copy of it), then writes the tile out (WriteTile(), compiled for the same set: float64 points copied as
/// 4 Reals take one 32-byte move with AVX). The non-temporal stores stay a compile-time choice: as a run-time
/// flag they cost 4-7 % in float32 (BENCHMARKS.md, "What did not help").
#define FFD_DEFINE_GRID_KERNELS(Level, Target, Bytes)                                                                  \
  template <typename Deformation, typename Real>                                                                       \
  Target __attribute__((noinline)) void InPlaceIn(LevelTag<Level>, const Deformation& deformation, const Real* in,     \
    const int* cells, Real* out, const BlockCells& blocks, std::int64_t blockBegin, std::int64_t blockEnd,             \
    std::int64_t outFirst, bool stream)                                                                                \
  {                                                                                                                    \
    if (stream)                                                                                                        \
    {                                                                                                                  \
      BlocksInPlaceInLanes<Bytes / int(sizeof(Real)), true>(                                                           \
        deformation, in, cells, out, blocks, blockBegin, blockEnd, outFirst);                                          \
      _mm_sfence(); /* the non-temporal stores are seen by other threads after this */                                 \
      return;                                                                                                          \
    }                                                                                                                  \
    BlocksInPlaceInLanes<Bytes / int(sizeof(Real)), false>(                                                            \
      deformation, in, cells, out, blocks, blockBegin, blockEnd, outFirst);                                            \
  }                                                                                                                    \
  template <typename Deformation, typename Real>                                                                       \
  Target void WithJacobianIn(LevelTag<Level>, const Deformation& deformation, const Real* in, const int* cells,        \
    const BlockCells& blocks, const Real* inNormals, Real* out, Real* outNormals, Real* determinants,                  \
    std::int64_t begin, std::int64_t end)                                                                              \
  {                                                                                                                    \
    WithJacobianInLanes<Bytes / int(sizeof(Real))>(                                                                    \
      deformation, in, cells, blocks, inNormals, out, outNormals, determinants, begin, end);                           \
  }                                                                                                                    \
  template <typename Deformation, typename Real>                                                                       \
  Target void GatheredIn(LevelTag<Level>, const Deformation& deformation, const Real* listed,                          \
    const GatheredPoints& gathered, std::int64_t t, Real* staged, Real* out)                                           \
  {                                                                                                                    \
    const std::int64_t first = gathered.TileBlocks[std::size_t(t)];                                                    \
    InPlaceIn(LevelTag<Level>(), deformation, listed, gathered.Cells.data(), staged, gathered.Blocks, first,           \
      gathered.TileBlocks[std::size_t(t) + 1], first* BlockSize, false);                                               \
    WriteTile(gathered, t, staged, out);                                                                               \
  }

template <SimdLevel Level, typename Real>
void InPlaceAt(const GridLattice<Real>& lattice, const Real* in, const int* cells, Real* out, const BlockCells& blocks,
  std::int64_t blockBegin, std::int64_t blockEnd, bool stream)
{
  WithGridDeformation(lattice,
    [&](const auto& deformation)
    { InPlaceIn(LevelTag<Level>(), deformation, in, cells, out, blocks, blockBegin, blockEnd, 0, stream); });
}

template <SimdLevel Level, typename Real>
void WithJacobianAt(const GridLattice<Real>& lattice, const Real* in, const int* cells, const BlockCells& blocks,
  const Real* inNormals, Real* out, Real* outNormals, Real* determinants, std::int64_t begin, std::int64_t end)
{
  WithGridDeformation(lattice,
    [&](const auto& deformation)
    {
      WithJacobianIn(
        LevelTag<Level>(), deformation, in, cells, blocks, inNormals, out, outNormals, determinants, begin, end);
    });
}

template <SimdLevel Level, typename Real>
void GatheredAt(const GridLattice<Real>& lattice, const Real* listed, const GatheredPoints& gathered, std::int64_t t,
  Real* staged, Real* out)
{
  WithGridDeformation(lattice,
    [&](const auto& deformation) { GatheredIn(LevelTag<Level>(), deformation, listed, gathered, t, staged, out); });
}

} // namespace detail
} // namespace ffd
#endif

#endif
