// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDCpuTuning.h
 * @brief The CPU evaluation's tuning: block and tile sizes, and the thresholds that choose a pass (host only).
 *
 * Every constant and threshold that the CPU passes (FFDGridLanes.h, FFDPointBlocks.h) were tuned by is here, with
 * the reason for it; BENCHMARKS.md has the measurements. None of them changes a result: a point is deformed the
 * same whichever pass takes it. How many points a vtkSMPTools task takes is the VTK side's: vtkFFDGrain()
 * (Filters/Core/vtkFFDForInChunks.h).
 */
#ifndef FFDCpuTuning_h
#define FFDCpuTuning_h

#include "FFDGridDeformation.h"

#include <cstddef>
#include <cstdint>

namespace ffd
{

/// Consecutive points that the in-place pass takes together: a multiple of every SIMD level's lanes (16 floats).
constexpr int BlockSize = 16;

/// Blocks ahead whose points the in-place pass prefetches.
constexpr int PrefetchBlocks = 8;

/// Blocks over which the in-place pass defers the blocks in several cells to the end, while their points are
/// still in cache.
constexpr int InPlaceWindow = 64;

/**
 * Consecutive points among which the gathered pass sorts by cell (a multiple of BlockSize, at most 2^16: see
 * GatheredPoints::Ranks). The pass stages a tile's results (384 KB in float32, 768 KB in float64: a core's L2
 * cache) and reads them from there at random, instead of writing them at random across the output, whose lines
 * a write at random reads from memory first. Larger tiles leave fewer lane groups in two cells.
 */
constexpr int GatherTile = 32768;

/// Reals in a staging buffer of DeformGathered(): a tile's results, and one more that the write-out may read past
/// the last (detail::WriteTile()).
constexpr std::size_t GatherStaging = 3 * std::size_t(GatherTile) + 1;

/**
 * True when a deformation of `points` points over `cells` cells of a local basis is worth a cell table
 * (FillCellTable(), rebuilt at every update): when building the table costs less than it saves, with at least 8
 * points a cell for the trilinear basis, 64 for the triquadratic one and 256 for the cubic ones (a cell's table
 * costs about as much as deforming 6, 40 and 150 of its points). The tricubic Bezier basis's table is centred
 * (CenteredCellTable()), so that its power form keeps within the weighted sum's float32 error bound.
 */
inline bool WorthCellTable(GridBasis basis, std::int64_t cells, std::int64_t points)
{
  const int degree = CellDegree(basis);
  const std::int64_t pointsPerCell = degree == 1 ? 8 : (degree == 2 ? 64 : 256);
  return degree > 0 && cells * pointsPerCell <= points;
}

/**
 * True when the in-place pass should write an output of `bytes` bytes by non-temporal stores: when it is larger
 * than the last-level caches of most CPUs (64 MB), which it would leave anyway. Such stores write whole cache
 * lines without reading them first. A smaller output stays in the caches for whoever reads it next.
 */
inline bool StreamOutput(std::int64_t bytes)
{
  return bytes >= (std::int64_t(64) << 20);
}

/**
 * The most cells a block's points may lie in for the block to be deformed in place (BlockInPlace()), chosen for a
 * binding from its mean number of cells per block. In place reads and writes memory in order, but a lane group in
 * several cells evaluates each of its cells in all its lanes; the gathered pass reads a copy of its points in
 * order, sorted by cell within tiles, and writes each tile out in point order from its staging buffer. Below the
 * crossover every block is deformed in place (BlockSize), above it every block is gathered (0), those in one cell
 * too: the gathered pass reads them in order with the others, where the in-place pass would read them at random.
 * A mesh in random vertex order has several cells a block: gathered; one in a spatially coherent order has one or
 * two: in place for the cheap trilinear cells. The crossovers were measured on meshes reordered to means in
 * between; float64's are lower than float32's, and these lie between the two.
 */
inline int MaxCellsInPlace(GridBasis basis, double meanCellsPerBlock, bool cellTable)
{
  double crossover = 1.2; // the triquadratic and cubic bases: 27 or 64 control points a cell
  if (basis == GridBasis::Bernstein)
  {
    return BlockSize; // one cell
  }
  if (basis == GridBasis::Trilinear)
  {
    crossover = cellTable ? 2.0 : 1.7; // 7 multiply-adds a component, or 8 control points
  }
  return meanCellsPerBlock <= crossover ? BlockSize : 0;
}

} // namespace ffd

#endif
