// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDLaneTestUtilities.h
 * @brief What the tests of the SIMD passes (FFDGridLanes.h) share: the levels this CPU runs, mesh-like point sets,
 * and both passes over a whole set.
 */
#ifndef FFDLaneTestUtilities_h
#define FFDLaneTestUtilities_h

#include "FFDGridPasses.h"
#include "FFDKernelTestUtilities.h"

#include <algorithm>
#include <cstdlib>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace ffdtest
{
/// The levels this CPU runs, one point at a time (None) included.
inline std::vector<ffd::SimdLevel> Levels()
{
  std::vector<ffd::SimdLevel> levels;
  for (int l = 0; l <= int(ffd::SimdLevelOfCpu()); ++l)
  {
    levels.push_back(ffd::SimdLevel(l));
  }
  return levels;
}

inline std::string LevelName(ffd::SimdLevel level)
{
  const char* names[] = { "None", "SSE2", "AVX2", "AVX512" };
  return names[int(level)];
}

/// Points as the filter holds them: 3 Real values each, and their cells from the kernel's binding.
template <typename Real>
struct PointSet
{
  std::vector<Real> Values;
  std::vector<int> Cells;
  std::int64_t Size() const { return std::int64_t(this->Cells.size()); }
};

/**
 * A mesh-like point set of lattice `lat`: runs of 1 to 40 points in one random cell (the coherent order of a
 * mesh: blocks of one cell, of a few, of many), random points of the frame, points outside the frame (cell -1), and a
 * count that is not a multiple of any lane width.
 */
template <typename Real, typename K>
PointSet<Real> MeshLikePoints(Rng& rng, const GridLattice& lat, const K& k, int count)
{
  PointSet<Real> set;
  auto add = [&](const ffdref::Vec& stu)
  {
    const ffd::Vec3<Real> x = ffdtest::ToKernel<Real>(ffdtest::ToWorld(lat.F, stu));
    set.Values.insert(set.Values.end(), { x.x, x.y, x.z });
    set.Cells.push_back(k.Bind(x, false));
  };
  while (int(set.Cells.size()) < count)
  {
    const double kind = ffdtest::Uniform(rng, 0.0, 1.0);
    if (kind < 0.6) // a run in one cell
    {
      ffdref::Vec lo;
      for (int a = 0; a < 3; ++a)
      {
        const int cells = lat.Basis == ffdref::Basis::Bernstein ? 1 : lat.Divisions[a];
        lo[a] = double(std::uniform_int_distribution<int>(0, cells - 1)(rng)) / cells;
      }
      const int run = std::uniform_int_distribution<int>(1, 40)(rng);
      for (int p = 0; p < run; ++p)
      {
        ffdref::Vec stu;
        for (int a = 0; a < 3; ++a)
        {
          const int cells = lat.Basis == ffdref::Basis::Bernstein ? 1 : lat.Divisions[a];
          stu[a] = lo[a] + ffdtest::Uniform(rng, 0.01, 0.99) / cells;
        }
        add(stu);
      }
    }
    else if (kind < 0.95)
    {
      add(ffdtest::RandomVec(rng, 0.0, 1.0));
    }
    else
    {
      add(ffdtest::RandomVec(rng, 1.1, 1.5)); // outside: keeps its position
    }
  }
  set.Values.resize(3 * std::size_t(count));
  set.Cells.resize(std::size_t(count));
  return set;
}

/// The lattice of a deformation as the passes of the FFDCpu library take it (its cell table where it has one).
template <typename D>
ffd::GridLattice<typename D::Value> LatticeOf(const D& d)
{
  return { d.Basis, { d.Voxels[0], d.Voxels[1], d.Voxels[2] }, { d.Dims[0], d.Dims[1], d.Dims[2] }, d.Displacements,
    d.Frame, D::UsesCellTable() ? d.CellTable : nullptr, d.CellVoxels, d.CellSupports };
}

/// Both passes over the whole set with blocks in at most maxCells cells in place (`gathered` listed for that
/// limit), the in-place pass's range of blocks and the gathered pass's range of tiles cut where given (sorted,
/// within the ranges); with `stream`, into memory aligned to 64 bytes, the in-place pass by non-temporal stores.
template <typename D, typename Real>
std::vector<Real> DeformAll(ffd::SimdLevel level, const D& d, const PointSet<Real>& set,
  const ffd::GatheredPoints& gathered, int maxCells, const std::vector<std::int64_t>& blockCuts = {},
  const std::vector<std::int64_t>& gatheredCuts = {}, bool stream = false)
{
  const std::size_t bytes = (set.Values.size() * sizeof(Real) + 63) / 64 * 64;
  const std::unique_ptr<Real, decltype(&std::free)> aligned(
    static_cast<Real*>(std::aligned_alloc(64, std::max<std::size_t>(bytes, 64))), &std::free);
  Real* out = aligned.get();
  std::fill(out, out + set.Values.size(), std::numeric_limits<Real>::quiet_NaN()); // poisoned
  const std::int64_t blocks = (set.Size() + ffd::BlockSize - 1) / ffd::BlockSize;
  const ffd::BlockCells listed = ffd::ListBlockCells(set.Cells.data(), set.Size(), maxCells);
  std::int64_t begin = 0;
  for (std::int64_t cut : blockCuts)
  {
    ffd::DeformBlocksInPlace(level, LatticeOf(d), set.Values.data(), set.Cells.data(), out, listed, begin, cut, stream);
    begin = cut;
  }
  ffd::DeformBlocksInPlace(
    level, LatticeOf(d), set.Values.data(), set.Cells.data(), out, listed, begin, blocks, stream);
  std::vector<Real> copy(3 * gathered.Order.size());
  ffd::CopyGatheredPoints(set.Values.data(), gathered, 0, std::int64_t(gathered.Order.size()), copy.data());
  std::vector<Real> staging(ffd::GatherStaging, std::numeric_limits<Real>::quiet_NaN());
  begin = 0;
  for (std::int64_t cut : gatheredCuts)
  {
    ffd::DeformGathered(level, LatticeOf(d), copy.data(), gathered, out, begin, cut, staging.data());
    begin = cut;
  }
  ffd::DeformGathered(level, LatticeOf(d), copy.data(), gathered, out, begin, gathered.TileCount(), staging.data());
  return std::vector<Real>(out, out + set.Values.size());
}

/// The cell limits of the in-place pass that the tests try: every block gathered (what the filter chooses for a
/// mesh in random order), every block gathered but those in one cell, at most 4 cells, and every block in place
/// (lane groups of up to W cells: what the filter chooses for a mesh in a coherent order).
inline std::vector<int> MaxCellsToTry()
{
  return { 0, 1, 4, ffd::BlockSize };
}

/// Points a tile of the gathered pass in the tests: several tiles in sets of 1001 and 2003 points, a last one
/// partial (the filter's, ffd::GatherTile, holds 32768).
constexpr int TestTile = 256;

} // namespace ffdtest

#endif
