// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDPointBlocks.h
 * @brief The lists a CPU binding makes of its points: blocks deformed in place with their cells, and the points
 * gathered by cell, tile by tile (host only).
 *
 * FFDGridLanes.h says how the passes use them; FFDCpuTuning.h holds the sizes and thresholds.
 */
#ifndef FFDPointBlocks_h
#define FFDPointBlocks_h

#include "FFDCpuTuning.h"

#include <algorithm>
#include <cstdint>
#include <vector>

namespace ffd
{

/// The number of cells (-1 counts as one) that the points of block b (a whole one) lie in.
inline int CellsOfBlock(const int* cells, std::int64_t b)
{
  const int* block = cells + b * BlockSize;
  int count = 0;
  for (int l = 0; l < BlockSize; ++l)
  {
    bool seen = false;
    for (int k = 0; k < l; ++k)
    {
      seen |= block[k] == block[l];
    }
    count += seen ? 0 : 1;
  }
  return count;
}

/// The mean of CellsOfBlock() over the whole blocks of n points (1 where there is none).
inline double MeanCellsPerBlock(const int* cells, std::int64_t n)
{
  const std::int64_t blocks = n / BlockSize;
  std::int64_t sum = 0;
  for (std::int64_t b = 0; b < blocks; ++b)
  {
    sum += CellsOfBlock(cells, b);
  }
  return blocks > 0 ? double(sum) / double(blocks) : 1.0;
}

/// True when block b (of n points) is deformed in place: it is whole and its points lie in at most maxCells
/// cells (MaxCellsInPlace()).
inline bool BlockInPlace(const int* cells, std::int64_t n, std::int64_t b, int maxCells)
{
  const std::int64_t first = b * BlockSize;
  if (first + BlockSize > n)
  {
    return false; // the last, partial block goes to the gathered points
  }
  if (maxCells >= BlockSize)
  {
    return true;
  }
  if (maxCells <= 0)
  {
    return false;
  }
  if (maxCells == 1)
  {
    bool one = true;
    for (int l = 1; l < BlockSize; ++l)
    {
      one &= cells[first + l] == cells[first];
    }
    return one;
  }
  return CellsOfBlock(cells, b) <= maxCells;
}

/**
 * The cells of a binding's whole blocks, listed once per binding so that deforming a block in several cells does
 * not search them again (a chain of dependent compares per cell, which cost more than the cell's sum): Entry[b]
 * is -1 for block b when its points all lie in the cell of its first point (-1 included), else the offset in
 * List of: the number of its cells other than -1, its CellsOfBlock(), then each cell other than -1 and the bits
 * of the block's points in it (bit l for point b BlockSize + l). Blocks in more than MaxCells cells are left to
 * the gathered pass.
 */
struct BlockCells
{
  int MaxCells = BlockSize;
  std::vector<int> Entry;
  std::vector<int> List;

  /// True when whole block b is deformed in place (BlockInPlace()). The limits MaxCellsInPlace() gives, 0 and
  /// BlockSize, need no look at the block.
  bool InPlace(std::int64_t b) const
  {
    if (this->MaxCells <= 0 || this->MaxCells >= BlockSize)
    {
      return this->MaxCells > 0;
    }
    const int entry = this->Entry[std::size_t(b)];
    return entry < 0 || this->List[std::size_t(entry) + 1] <= this->MaxCells; // a listed block: 2 cells or more
  }
};

/// The BlockCells of n points bound to `cells`, with blocks in more than maxCells cells gathered.
inline BlockCells ListBlockCells(const int* cells, std::int64_t n, int maxCells)
{
  BlockCells blocks;
  blocks.MaxCells = maxCells;
  blocks.Entry.resize(std::size_t(n / BlockSize));
  for (std::size_t b = 0; b < blocks.Entry.size(); ++b)
  {
    const int* block = cells + b * BlockSize;
    unsigned others = 0;
    for (int l = 0; l < BlockSize; ++l)
    {
      others |= block[l] != block[0] ? 1u << l : 0u;
    }
    if (others == 0)
    {
      blocks.Entry[b] = -1;
      continue;
    }
    const std::size_t entry = blocks.List.size();
    blocks.Entry[b] = int(entry);
    blocks.List.push_back(0);
    blocks.List.push_back(0);
    unsigned bound = 0; // the points in a listed cell
    for (int l = 0; l < BlockSize; ++l)
    {
      bool seen = block[l] < 0;
      for (int k = 0; k < l; ++k)
      {
        seen |= block[k] == block[l];
      }
      if (!seen)
      {
        unsigned bits = 0;
        for (int m = l; m < BlockSize; ++m)
        {
          bits |= block[m] == block[l] ? 1u << m : 0u;
        }
        blocks.List.push_back(block[l]);
        blocks.List.push_back(int(bits));
        ++blocks.List[entry];
        bound |= bits;
      }
    }
    // CellsOfBlock(): the listed cells, and -1 where some point is in none.
    blocks.List[entry + 1] = blocks.List[entry] + (bound != (1u << BlockSize) - 1 ? 1 : 0);
  }
  return blocks;
}

/// The blocks of n points bound to `cells` that are not deformed in place (BlockInPlace() with maxCells), in
/// order.
inline std::vector<std::int64_t> GatheredBlocks(const int* cells, std::int64_t n, int maxCells)
{
  std::vector<std::int64_t> gathered;
  for (std::int64_t b = 0; b < (n + BlockSize - 1) / BlockSize; ++b)
  {
    if (!BlockInPlace(cells, n, b, maxCells))
    {
      gathered.push_back(b);
    }
  }
  return gathered;
}

/**
 * The points of the blocks `sources` (GatheredBlocks(): those not deformed in place), tile by tile (of `tile`
 * points, GatherTile but in tests), each tile's sorted by cell: cell -1 first, then by cell, each cell's points
 * in input order (two stable counting sorts: by cell, then by tile). For DeformGathered(); `cellCount` is the
 * number of cells of the binding.
 */
inline std::vector<int> GatherByCell(
  const int* cells, std::int64_t n, int cellCount, const std::vector<std::int64_t>& sources, int tile = GatherTile)
{
  std::vector<std::int64_t> offsets(std::size_t(cellCount) + 2, 0);
  for (std::int64_t b : sources)
  {
    for (std::int64_t i = b * BlockSize; i < n && i < (b + 1) * BlockSize; ++i)
    {
      ++offsets[std::size_t(cells[i] + 2)];
    }
  }
  for (std::size_t c = 1; c < offsets.size(); ++c)
  {
    offsets[c] += offsets[c - 1];
  }
  std::vector<int> byCell(std::size_t(offsets.back()));
  for (std::int64_t b : sources)
  {
    for (std::int64_t i = b * BlockSize; i < n && i < (b + 1) * BlockSize; ++i)
    {
      byCell[std::size_t(offsets[std::size_t(cells[i] + 1)]++)] = int(i);
    }
  }
  std::vector<std::int64_t> tiles(std::size_t((n + tile - 1) / tile) + 1, 0);
  for (int i : byCell)
  {
    ++tiles[std::size_t(i / tile) + 1];
  }
  for (std::size_t t = 1; t < tiles.size(); ++t)
  {
    tiles[t] += tiles[t - 1];
  }
  std::vector<int> gathered(byCell.size());
  for (int i : byCell)
  {
    gathered[std::size_t(tiles[std::size_t(i / tile)]++)] = i;
  }
  return gathered;
}

/**
 * The points that the gathered pass deforms (DeformGathered()), listed once per binding, with where each result goes.
 * The list, Order, is GatherByCell()'s, each tile's run of it padded to whole blocks by repeating its last point (so
 * that every listed point is deformed in lanes, as bit for bit as the in-place pass); Cells, their cells in that order;
 * Blocks, the BlockCells of that order (every block in place); TileBlocks, the blocks of each tile's run: tile t's are
 * [TileBlocks[t], TileBlocks[t + 1]). The pass reads the points' coordinates in that order from a copy
 * (CopyGatheredPoints()), so that it reads memory in order and deforms whole lane groups of one cell. For the writing:
 * Sources, GatheredBlocks(), in point order, tile t's being [TileSources[t], TileSources[t + 1]); Ranks, for point l of
 * the k-th of them, at k BlockSize + l, its place in its tile's run.
 */
struct GatheredPoints
{
  std::int64_t Points = 0; ///< the binding's points
  std::vector<int> Order;
  std::vector<int> Cells;
  BlockCells Blocks;
  std::vector<std::int64_t> TileBlocks;
  std::vector<std::int64_t> Sources;
  std::vector<std::int64_t> TileSources;
  std::vector<std::uint16_t> Ranks;

  /// The tiles of the binding's points (some may list no point).
  std::int64_t TileCount() const { return std::int64_t(this->TileBlocks.size()) - 1; }
};

/// The GatheredPoints of n points bound to `cells` (a binding of cellCount cells) with blocks in more than
/// maxCells cells gathered, in tiles of `tile` points (GatherTile but in tests: a multiple of BlockSize, at most
/// GatherTile, the points a staging buffer of DeformGathered() holds).
inline GatheredPoints ListGatheredPoints(
  const int* cells, std::int64_t n, int cellCount, int maxCells, int tile = GatherTile)
{
  static_assert(GatherTile % BlockSize == 0 && GatherTile <= 65536, "tiles of whole blocks, ranks of 16 bits");
  tile = std::max(BlockSize, std::min(GatherTile, tile / BlockSize * BlockSize));
  GatheredPoints gathered;
  gathered.Points = n;
  gathered.Sources = GatheredBlocks(cells, n, maxCells);
  const std::vector<int> byCell = GatherByCell(cells, n, cellCount, gathered.Sources, tile);
  const std::int64_t tiles = (n + tile - 1) / tile;
  const std::int64_t blocks = (n + BlockSize - 1) / BlockSize;
  gathered.TileSources.assign(std::size_t(tiles) + 1, 0);
  for (std::int64_t b : gathered.Sources)
  {
    ++gathered.TileSources[std::size_t(b * BlockSize / tile) + 1];
  }
  for (std::size_t t = 1; t < gathered.TileSources.size(); ++t)
  {
    gathered.TileSources[t] += gathered.TileSources[t - 1];
  }
  // Each point's place in its tile's run, found through its block's place among Sources.
  std::vector<std::int64_t> sourceOfBlock(std::size_t(blocks), -1);
  for (std::size_t k = 0; k < gathered.Sources.size(); ++k)
  {
    sourceOfBlock[std::size_t(gathered.Sources[k])] = std::int64_t(k);
  }
  gathered.Ranks.assign(gathered.Sources.size() * BlockSize, 0);
  gathered.TileBlocks.assign(std::size_t(tiles) + 1, 0);
  std::size_t next = 0;
  for (std::int64_t t = 0; t < tiles; ++t)
  {
    const std::size_t runFirst = gathered.Order.size();
    for (; next < byCell.size() && byCell[next] / tile == t; ++next)
    {
      const int i = byCell[next];
      gathered.Ranks[std::size_t(sourceOfBlock[std::size_t(i / BlockSize)] * BlockSize + i % BlockSize)] =
        std::uint16_t(gathered.Order.size() - runFirst);
      gathered.Order.push_back(i);
    }
    while ((gathered.Order.size() - runFirst) % BlockSize != 0)
    {
      gathered.Order.push_back(gathered.Order.back());
    }
    gathered.TileBlocks[std::size_t(t) + 1] = std::int64_t(gathered.Order.size()) / BlockSize;
  }
  gathered.Cells.reserve(gathered.Order.size());
  for (int i : gathered.Order)
  {
    gathered.Cells.push_back(cells[i]);
  }
  gathered.Blocks = ListBlockCells(gathered.Cells.data(), std::int64_t(gathered.Cells.size()), BlockSize);
  return gathered;
}

/// copy = in[Order[g]] (3 values each) for the listed points g in [begin, end): what DeformGathered() reads.
template <typename Real>
inline void CopyGatheredPoints(
  const Real* in, const GatheredPoints& gathered, std::int64_t begin, std::int64_t end, Real* copy)
{
  for (std::int64_t g = begin; g < end; ++g)
  {
    const std::int64_t i = gathered.Order[std::size_t(g)];
    copy[3 * g] = in[3 * i];
    copy[3 * g + 1] = in[3 * i + 1];
    copy[3 * g + 2] = in[3 * i + 2];
  }
}

} // namespace ffd

#endif
