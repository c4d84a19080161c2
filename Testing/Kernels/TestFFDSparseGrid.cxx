// SPDX-License-Identifier: BSD-3-Clause
// A sparse lattice (GridDeformation with CellVoxels and CellSupports) deforms its points bit for bit as the dense
// lattice does, at every instruction-set level, with and without cell tables and the Jacobian: built here from
// the dense lattice by keeping a random subset of its cells, independently of the filters' reader.

#include "FFDCellTable.h"
#include "FFDGridPasses.h"
#include "FFDKernelTestUtilities.h"
#include "FFDLaneTestUtilities.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

namespace
{
using ffdref::Basis;
using ffdtest::GridLattice;

/// Bitwise equality of two arrays of Reals (NaN included).
template <typename Real>
bool SameBits(const std::vector<Real>& a, const std::vector<Real>& b)
{
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(Real)) == 0;
}

/**
 * The sparse form of a dense kernel's lattice over the cells that `keep` marks: the control points of their
 * supports in increasing dense order, the cells in increasing dense order with their voxels and supports (i
 * fastest), and the table of those cells where the dense kernel has one. `Sparse` evaluates it.
 */
template <typename K>
struct SparseLattice
{
  using Deformation = typename std::remove_const<decltype(K::D)>::type;
  using Real = typename Deformation::Value;

  std::vector<int> SparseCellOfDense; // -1 for a cell not kept
  std::vector<Real> Values;
  std::vector<int> Voxels, Supports;
  std::vector<Real> Table;
  Deformation Sparse;

  SparseLattice(const K& k, const std::vector<bool>& keep)
    : Sparse(k.D)
  {
    const Deformation& d = k.D;
    const int n = d.SupportCount();
    std::vector<int> compact(std::size_t(d.Dims[0]) * d.Dims[1] * d.Dims[2], -1);
    int cells = 0;
    for (std::size_t c = 0; c < keep.size(); ++c)
    {
      SparseCellOfDense.push_back(keep[c] ? cells++ : -1);
    }
    // The kept control points, then the cells' supports through them.
    auto forSupport = [&](int cell, auto&& f)
    {
      const int v[3] = { cell % d.Voxels[0], cell / d.Voxels[0] % d.Voxels[1], cell / (d.Voxels[0] * d.Voxels[1]) };
      int first[3], count;
      for (int a = 0; a < 3; ++a)
      {
        ffd::VoxelSupport(d.Basis, d.Voxels[a], v[a], first[a], count);
      }
      for (int z = 0; z < n; ++z)
        for (int y = 0; y < n; ++y)
          for (int x = 0; x < n; ++x)
            f(v, (first[0] + x) + d.Dims[0] * ((first[1] + y) + d.Dims[1] * (first[2] + z)));
    };
    for (std::size_t c = 0; c < keep.size(); ++c)
    {
      if (keep[c])
      {
        forSupport(int(c), [&](const int*, int point) { compact[point] = 0; });
      }
    }
    int points = 0;
    for (std::size_t p = 0; p < compact.size(); ++p)
    {
      if (compact[p] == 0)
      {
        compact[p] = points++;
        Values.insert(Values.end(), d.Displacements + 3 * p, d.Displacements + 3 * p + 3);
      }
    }
    for (std::size_t c = 0; c < keep.size(); ++c)
    {
      if (!keep[c])
      {
        continue;
      }
      bool first = true;
      forSupport(int(c),
        [&](const int* v, int point)
        {
          if (first)
          {
            Voxels.insert(Voxels.end(), v, v + 3);
            first = false;
          }
          Supports.push_back(compact[point]);
        });
    }
    Sparse.Displacements = Values.data();
    Sparse.CellVoxels = Voxels.data();
    Sparse.CellSupports = Supports.data();
    if (Deformation::UsesCellTable())
    {
      Table.resize(std::size_t(cells) * ffd::CellTableStride(ffd::CellDegree(d.Basis)));
      ffd::FillCellTable(
        d.Basis, Values.data(), d.Voxels, d.Dims, Voxels.data(), Supports.data(), Table.data(), 0, cells);
      Sparse.CellTable = Table.data();
    }
  }
  SparseLattice(const SparseLattice&) = delete; // Sparse points into the vectors
};

FFD_REAL_TYPED_TEST_SUITE(FFDSparseGridTest);

TYPED_TEST(FFDSparseGridTest, DeformsAsTheDenseLatticeBitForBit)
{
  // Every local basis, random lattices of up to 5 voxels an axis, a random half of the cells kept (and a lattice
  // of one cell), 1001 mesh-like points, clamped or not: points of the cells not kept are bound to no cell in
  // both forms; both passes at every level and in-place cell limit, and DeformWithJacobian() (positions, normals,
  // determinants), give the same bits for the sparse lattice as for the dense one.
  using Real = TypeParam;
  ffdtest::Rng rng(1701);
  int compared = 0;
  ffdtest::ForEachRandomLattice(rng,
    { Basis::Trilinear, Basis::TriquadraticBezier, Basis::TricubicBezier, Basis::CubicBSpline }, 4, 5,
    [&](const GridLattice& lat, int trial)
    {
      ffdtest::WithKernel<Real>(lat,
        [&](const auto& k)
        {
          const int cellCount = lat.Divisions[0] * lat.Divisions[1] * lat.Divisions[2];
          std::vector<bool> keep(std::size_t(cellCount), false);
          if (trial == 0)
          {
            keep[std::uniform_int_distribution<int>(0, cellCount - 1)(rng)] = true;
          }
          else
          {
            for (std::size_t c = 0; c < keep.size(); ++c)
            {
              keep[c] = ffdtest::Uniform(rng, 0.0, 1.0) < 0.5;
            }
          }
          const SparseLattice<std::decay_t<decltype(k)>> sparse(k, keep);
          ffdtest::PointSet<Real> dense = ffdtest::MeshLikePoints<Real>(rng, lat, k, 1001);
          const bool clamp = trial % 2 == 1;
          ffdtest::PointSet<Real> onSparse = dense;
          for (std::int64_t i = 0; i < dense.Size(); ++i)
          {
            const int cell = k.Bind(ffd::Vec3<Real>::From(&dense.Values[3 * i]), clamp);
            onSparse.Cells[i] = cell < 0 ? -1 : sparse.SparseCellOfDense[std::size_t(cell)];
            dense.Cells[i] = onSparse.Cells[i] < 0 ? -1 : cell;
          }
          const int sparseCells = int(sparse.Voxels.size() / 3);
          for (int maxCells : ffdtest::MaxCellsToTry())
          {
            const ffd::GatheredPoints gatheredDense =
              ffd::ListGatheredPoints(dense.Cells.data(), dense.Size(), cellCount, maxCells, ffdtest::TestTile);
            const ffd::GatheredPoints gatheredSparse =
              ffd::ListGatheredPoints(onSparse.Cells.data(), onSparse.Size(), sparseCells, maxCells, ffdtest::TestTile);
            for (ffd::SimdLevel level : ffdtest::Levels())
            {
              const std::string where = lat.Name() + " level " + ffdtest::LevelName(level) + " in place up to " +
                std::to_string(maxCells) + " cells";
              ASSERT_TRUE(SameBits(ffdtest::DeformAll(level, k.D, dense, gatheredDense, maxCells),
                ffdtest::DeformAll(level, sparse.Sparse, onSparse, gatheredSparse, maxCells)))
                << where;
              ++compared;
            }
          }
          std::vector<Real> normals;
          for (std::int64_t i = 0; i < dense.Size(); ++i)
          {
            const ffdref::Vec n = ffdtest::RandomVec(rng, -1.0, 1.0);
            normals.insert(normals.end(), { Real(n[0]), Real(n[1]), Real(n[2]) });
          }
          const ffd::BlockCells listedDense = ffd::ListBlockCells(dense.Cells.data(), dense.Size(), ffd::BlockSize);
          const ffd::BlockCells listedSparse =
            ffd::ListBlockCells(onSparse.Cells.data(), onSparse.Size(), ffd::BlockSize);
          for (ffd::SimdLevel level : ffdtest::Levels())
          {
            auto run = [&](const auto& d, const ffdtest::PointSet<Real>& set, const ffd::BlockCells& listed)
            {
              const Real nan = std::numeric_limits<Real>::quiet_NaN();
              std::vector<Real> out(set.Values.size(), nan), outNormals(normals.size(), nan),
                determinants(std::size_t(set.Size()), nan);
              ffd::DeformWithJacobian(level, ffdtest::LatticeOf(d), set.Values.data(), set.Cells.data(), listed,
                normals.data(), out.data(), outNormals.data(), determinants.data(), 0, set.Size());
              out.insert(out.end(), outNormals.begin(), outNormals.end());
              out.insert(out.end(), determinants.begin(), determinants.end());
              return out;
            };
            ASSERT_TRUE(SameBits(run(k.D, dense, listedDense), run(sparse.Sparse, onSparse, listedSparse)))
              << lat.Name() << " with the Jacobian, level " << ffdtest::LevelName(level);
          }
        });
    });
  ::testing::Test::RecordProperty("compared_evaluations", compared);
  EXPECT_GT(compared, 0);
}

} // namespace
