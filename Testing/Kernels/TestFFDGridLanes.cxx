// SPDX-License-Identifier: BSD-3-Clause
// Deformation of many points at once in SIMD lanes (FFDGridLanes.h, FFDLanes.h), at every instruction-set level
// this CPU runs, for every basis, with lane groups in one cell and in many: against the float64 reference
// ffdref::DeformLocal; a point's result the same bit for bit whichever pass deforms it, whatever its neighbours
// and however the range is split; the list of gathered points.

#include "FFDGridPasses.h"
#include "FFDKernelTestUtilities.h"
#include "FFDLaneTestUtilities.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <memory>
#include <numeric>
#include <string>
#include <vector>

namespace
{
using ffdref::Basis;
using ffdref::Vec;
using ffdtest::DeformAll;
using ffdtest::GridLattice;
using ffdtest::LevelName;
using ffdtest::Levels;
using ffdtest::MaxCellsToTry;
using ffdtest::MeshLikePoints;
using ffdtest::PointSet;
using ffdtest::TestTile;

/// The points of `set` in a random order; order[p] is the point of `set` at p.
template <typename Real>
PointSet<Real> Shuffled(const PointSet<Real>& set, ffdtest::Rng& rng, std::vector<std::int64_t>& order)
{
  order.resize(std::size_t(set.Size()));
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), rng);
  PointSet<Real> shuffled;
  for (std::int64_t i : order)
  {
    shuffled.Values.insert(shuffled.Values.end(), &set.Values[3 * i], &set.Values[3 * i] + 3);
    shuffled.Cells.push_back(set.Cells[i]);
  }
  return shuffled;
}

/// Where ffdref::DeformLocal puts a point bound to a cell, clamped or not: X plus the reference's displacement
/// at the nearest point of the frame (X itself inside).
Vec ClampedReference(Basis b, const GridLattice& lat, const Vec& xd)
{
  Vec stu = ffdref::Parameters(lat.F, xd);
  for (double& p : stu)
  {
    p = std::min(1.0, std::max(0.0, p));
  }
  const Vec edge = ffdtest::ToWorld(lat.F, stu);
  const Vec moved = ffdref::DeformLocal(b, lat.F, lat.Divisions.data(), lat.Points, edge);
  return { xd[0] + moved[0] - edge[0], xd[1] + moved[1] - edge[1], xd[2] + moved[2] - edge[2] };
}

int CellCount(const GridLattice& lat)
{
  return lat.Basis == Basis::Bernstein ? 1 : lat.Divisions[0] * lat.Divisions[1] * lat.Divisions[2];
}

FFD_REAL_TYPED_TEST_SUITE(FFDGridLanesTest);

TYPED_TEST(FFDGridLanesTest, EveryLevelMatchesReference)
{
  // Every basis, level and in-place cell limit, random lattices, 1001 mesh-like points into a NaN-poisoned
  // output: every point is written, points outside keep their position exactly, the others match
  // ffdref::DeformLocal within ffdtest::PositionTolerance() (1e-12 in double, 1e-6 in float, relative to the
  // lattice's scale).
  using Real = TypeParam;
  ffdtest::Rng rng(601);
  ffdtest::WorstRatio worst("worst_error_over_tolerance");
  std::string levels;
  for (ffd::SimdLevel level : Levels())
  {
    levels += (levels.empty() ? "" : " ") + LevelName(level);
  }
  ::testing::Test::RecordProperty("simd_levels", levels);
  ffdtest::ForEachRandomLattice(rng, 6, 5,
    [&](const GridLattice& lat)
    {
      const double scale = ffdtest::LatticeScale(lat.Points);
      ffdtest::WithKernel<Real>(lat,
        [&](const auto& k)
        {
          const PointSet<Real> set = MeshLikePoints<Real>(rng, lat, k, 1001);
          for (int maxCells : MaxCellsToTry())
          {
            const ffd::GatheredPoints gathered =
              ffd::ListGatheredPoints(set.Cells.data(), set.Size(), CellCount(lat), maxCells, TestTile);
            for (ffd::SimdLevel level : Levels())
            {
              const std::vector<Real> out = DeformAll(level, k.D, set, gathered, maxCells);
              for (std::int64_t i = 0; i < set.Size(); ++i)
              {
                const ffd::Vec3<Real> x = ffd::Vec3<Real>::From(&set.Values[3 * i]);
                const ffd::Vec3<Real> y = ffd::Vec3<Real>::From(&out[3 * i]);
                const std::string where = lat.Name() + " level " + LevelName(level) + " in place up to " +
                  std::to_string(maxCells) + " cells, point " + std::to_string(i);
                if (set.Cells[i] < 0)
                {
                  ASSERT_TRUE(y.x == x.x && y.y == x.y && y.z == x.z) << where;
                  continue;
                }
                ffd::Mat3<Real> j;
                k.D.Deform(x, set.Cells[i], j);
                const Vec xd = ffdtest::ToRef(x);
                const Vec want = ClampedReference(lat.Basis, lat, xd);
                const double tol = ffdtest::PositionTolerance(scale, xd, lat.F, j);
                ASSERT_TRUE(ffdtest::MaxDiffWithin(ffdtest::ToRef(y), want, tol, &worst)) << where;
              }
            }
          }
        });
    });
}

TYPED_TEST(FFDGridLanesTest, ResultDependsOnlyOnThePoint)
{
  // At each level, a point's result is the same bit for bit: in its mesh order, split into random sub-ranges
  // (as threads split it), written by non-temporal stores, in a shuffled order (lane groups of many cells),
  // gathered in tiles of TestTile or GatherTile points, and whichever pass takes it, at every cell limit of
  // MaxCellsToTry() (every block gathered, up to every block in place).
  using Real = TypeParam;
  ffdtest::Rng rng(602);
  for (Basis b : ffdtest::AllBases)
  {
    GridLattice lat;
    do // enough cells that shuffled blocks span more than a few of them
    {
      lat = ffdtest::RandomGridLattice(rng, b, 5);
    } while (b != Basis::Bernstein && CellCount(lat) < 16);
    ffdtest::WithKernel<Real>(lat,
      [&](const auto& k)
      {
        const PointSet<Real> set = MeshLikePoints<Real>(rng, lat, k, 2003);
        std::vector<std::int64_t> order;
        const PointSet<Real> shuffled = Shuffled(set, rng, order);

        auto cuts = [&](std::int64_t n)
        {
          std::vector<std::int64_t> c;
          for (int m = 0; m < 7; ++m)
          {
            c.push_back(std::uniform_int_distribution<std::int64_t>(0, n)(rng));
          }
          std::sort(c.begin(), c.end());
          return c;
        };
        // The lists and the random cuts of each cell limit, drawn once for every level.
        struct Lists
        {
          ffd::GatheredPoints Gathered, ShuffledGathered, OneTile;
          std::vector<std::int64_t> BlockCuts, TileCuts;
        };
        std::vector<Lists> lists;
        for (int maxCells : MaxCellsToTry())
        {
          Lists l;
          l.Gathered = ffd::ListGatheredPoints(set.Cells.data(), set.Size(), CellCount(lat), maxCells, TestTile);
          l.ShuffledGathered =
            ffd::ListGatheredPoints(shuffled.Cells.data(), shuffled.Size(), CellCount(lat), maxCells, TestTile);
          l.OneTile = ffd::ListGatheredPoints(set.Cells.data(), set.Size(), CellCount(lat), maxCells);
          if (b != Basis::Bernstein && maxCells > 0 && maxCells < ffd::BlockSize) // in one cell, or outside
          {
            ASSERT_GT(l.ShuffledGathered.Order.size(), l.Gathered.Order.size()) << lat.Name();
          }
          l.BlockCuts = cuts((set.Size() + ffd::BlockSize - 1) / ffd::BlockSize);
          l.TileCuts = cuts(l.Gathered.TileCount());
          lists.push_back(std::move(l));
        }
        for (ffd::SimdLevel level : Levels())
        {
          std::vector<Real> first; // the result of the first cell limit, which the others must give
          for (std::size_t m = 0; m < lists.size(); ++m)
          {
            const int maxCells = MaxCellsToTry()[m];
            const ffd::GatheredPoints& gathered = lists[m].Gathered;
            const ffd::GatheredPoints& shuffledGathered = lists[m].ShuffledGathered;
            const ffd::GatheredPoints& oneTile = lists[m].OneTile;
            const std::vector<Real> whole = DeformAll(level, k.D, set, gathered, maxCells);
            const std::vector<Real> split =
              DeformAll(level, k.D, set, gathered, maxCells, lists[m].BlockCuts, lists[m].TileCuts);
            const std::vector<Real> tiled = DeformAll(level, k.D, set, oneTile, maxCells);
            const std::vector<Real> reordered = DeformAll(level, k.D, shuffled, shuffledGathered, maxCells);
            const std::vector<Real> streamed = DeformAll(level, k.D, set, gathered, maxCells, {}, {}, true);
            if (first.empty())
            {
              first = whole;
            }
            for (std::size_t p = 0; p < order.size(); ++p)
            {
              const std::size_t i = std::size_t(order[p]);
              const std::string where = lat.Name() + " " + LevelName(level) + " in place up to " +
                std::to_string(maxCells) + " cells, point " + std::to_string(i);
              for (int c = 0; c < 3; ++c)
              {
                ASSERT_EQ(whole[3 * i + c], first[3 * i + c]) << where;
                ASSERT_EQ(split[3 * i + c], whole[3 * i + c]) << where;
                ASSERT_EQ(tiled[3 * i + c], whole[3 * i + c]) << where << " (one tile of " << ffd::GatherTile << ")";
                ASSERT_EQ(streamed[3 * i + c], whole[3 * i + c]) << where << " (non-temporal stores)";
                ASSERT_EQ(reordered[3 * p + c], whole[3 * i + c]) << where;
              }
            }
          }
        }
      });
  }
}

TYPED_TEST(FFDGridLanesTest, JacobianAtEveryLevelMatchesReference)
{
  // DeformWithJacobian() at every level (None: one point at a time), every basis, random lattices, 1001
  // mesh-like points in their order and shuffled (lane groups in one cell and in many, points outside kept or
  // clamped), split into ranges at random multiples of BlockSize; the inputs (lattice, points, normals, cuts)
  // are drawn once, before the levels, so that every level of every CPU sees the same ones. Positions against
  // ffdref::DeformLocal (at the nearest point of the frame for points clamped to it) within PositionTolerance()
  // (points outside exactly kept); the determinant and the transformed normal against the same functions of
  // ffdref::JacobianLocal, within the bounds of JacobianErrorBound() carried through them (ffdtest::
  // DeterminantErrorBound(), ffdtest::NormalErrorBound(); points whose cof(J) n is under 0.1 long are skipped:
  // the normal is ill-defined there).
  using Real = TypeParam;
  ffdtest::Rng rng(604);
  ffdtest::WorstRatio worstPosition("worst_position_error_over_tolerance");
  ffdtest::WorstRatio worstDeterminant("worst_determinant_error_over_bound");
  ffdtest::WorstRatio worstNormal("worst_normal_error_over_bound");
  ffdtest::ForEachRandomLattice(rng, 4, 5,
    [&](const GridLattice& lat, int trial)
    {
      const double scale = ffdtest::LatticeScale(lat.Points);
      const std::vector<Vec> displacements = ffdtest::RoundLattice<Real>(lat.Displacements()); // as the kernel
      ffdtest::WithKernel<Real>(lat,
        [&](const auto& k)
        {
          PointSet<Real> set = MeshLikePoints<Real>(rng, lat, k, 1001);
          const bool clamp = trial >= 2; // the points outside lose the Jacobian's columns they are clamped along
          if (clamp)
          {
            for (std::int64_t i = 0; i < set.Size(); ++i)
            {
              set.Cells[i] = k.Bind(ffd::Vec3<Real>::From(&set.Values[3 * i]), true);
            }
          }
          if (trial % 2 == 1)
          {
            std::vector<std::int64_t> order;
            set = Shuffled(set, rng, order);
          }
          std::vector<Real> normals;
          for (std::int64_t i = 0; i < set.Size(); ++i)
          {
            const Vec n = ffdtest::RandomVec(rng, -1.0, 1.0);
            const double length = std::max(ffdtest::Norm(n), 1e-3);
            normals.insert(normals.end(), { Real(n[0] / length), Real(n[1] / length), Real(n[2] / length) });
          }
          std::vector<std::int64_t> cuts = { 0, set.Size() };
          for (int c = 0; c < 4; ++c)
          {
            cuts.push_back(
              ffd::BlockSize * std::uniform_int_distribution<std::int64_t>(0, set.Size() / ffd::BlockSize)(rng));
          }
          std::sort(cuts.begin(), cuts.end());
          const ffd::BlockCells listed = ffd::ListBlockCells(set.Cells.data(), set.Size(), ffd::BlockSize);
          for (ffd::SimdLevel level : Levels())
          {
            const Real nan = std::numeric_limits<Real>::quiet_NaN(); // poisoned outputs
            std::vector<Real> out(set.Values.size(), nan), outNormals(normals.size(), nan),
              determinants(std::size_t(set.Size()), nan);
            for (std::size_t c = 0; c + 1 < cuts.size(); ++c)
            {
              ffd::DeformWithJacobian(level, ffdtest::LatticeOf(k.D), set.Values.data(), set.Cells.data(), listed,
                normals.data(), out.data(), outNormals.data(), determinants.data(), cuts[c], cuts[c + 1]);
            }
            for (std::int64_t i = 0; i < set.Size(); ++i)
            {
              const std::string where =
                lat.Name() + (clamp ? " clamped" : "") + " level " + LevelName(level) + " point " + std::to_string(i);
              const ffd::Vec3<Real> x = ffd::Vec3<Real>::From(&set.Values[3 * i]);
              const ffd::Vec3<Real> y = ffd::Vec3<Real>::From(&out[3 * i]);
              const Vec xd = ffdtest::ToRef(x);
              const Vec n = ffdtest::ToRef(ffd::Vec3<Real>::From(&normals[3 * i]));
              const Vec gotNormal = ffdtest::ToRef(ffd::Vec3<Real>::From(&outNormals[3 * i]));
              if (set.Cells[i] < 0)
              {
                ASSERT_TRUE(y.x == x.x && y.y == x.y && y.z == x.z) << where;
                ASSERT_EQ(determinants[i], Real(1)) << where;
                ASSERT_TRUE(ffdtest::MaxDiffWithin(gotNormal, n, 4.0 * ffdtest::Eps<Real>()))
                  << where; // n renormalised
                continue;
              }
              const ffdtest::ReferenceJacobian ref =
                ffdtest::JacobianOfPoint<Real>(lat, displacements, xd, set.Cells[i]);
              const ffdtest::Mat bound =
                ffdtest::JacobianErrorBound<Real>(lat, displacements, xd, ref, k.D.CellTable != nullptr);
              ffd::Mat3<Real> j; // only for PositionTolerance()'s |J - I|
              k.D.Deform(x, set.Cells[i], j);
              const Vec want = ClampedReference(lat.Basis, lat, xd);
              const double tol = ffdtest::PositionTolerance(scale, xd, lat.F, j);
              ASSERT_TRUE(ffdtest::MaxDiffWithin(ffdtest::ToRef(y), want, tol, &worstPosition)) << where;

              const double detBound = ffdtest::DeterminantErrorBound<Real>(ref.J, bound);
              const double detError = std::fabs(double(determinants[i]) - ffdtest::Determinant(ref.J));
              worstDeterminant.Add(detError, detBound);
              ASSERT_LE(detError, detBound) << where;
              const Vec m = ffdtest::Product(ffdtest::Cofactor(ref.J), n);
              if (ffdtest::Norm(m) >= 0.1)
              {
                const Vec wantNormal = ffdtest::Scaled(m, 1.0 / ffdtest::Norm(m));
                const double normalBound = ffdtest::NormalErrorBound<Real>(ref.J, bound, n);
                ASSERT_TRUE(ffdtest::MaxDiffWithin(gotNormal, wantNormal, normalBound, &worstNormal)) << where;
              }
            }
          }
        });
    });
}

TEST(FFDGridLanes, GatherByCellListsTheBlocksNotDeformedInPlace)
{
  // 3 full blocks and a partial one, at most 8 cells a block in place: block 0 in cell 5 and block 2 in cells -1
  // and 3 are deformed in place; block 1 spans 10 cells (-1 included) and the partial tail are gathered: their
  // points, stably sorted by cell with -1 first. With a limit of BlockSize every full block is in place.
  const int maxCells = 8;
  const int cellCount = maxCells + 1; // cells 0 .. 8
  const int n = 3 * ffd::BlockSize + 5;
  std::vector<int> cells(n, 5);
  for (int i = ffd::BlockSize; i < 2 * ffd::BlockSize; ++i)
  {
    cells[i] = i % (maxCells + 2) - 1;
  }
  for (int i = 2 * ffd::BlockSize; i < 3 * ffd::BlockSize; ++i)
  {
    cells[i] = i % 2 == 0 ? -1 : 3;
  }
  const int tail[5] = { 7, 2, 7, -1, 0 };
  std::copy(tail, tail + 5, cells.begin() + 3 * ffd::BlockSize);

  std::vector<int> expected, expectedTail;
  for (int cell = -1; cell < cellCount; ++cell)
  {
    for (int i = 0; i < n; ++i)
    {
      const bool gathered = (i >= ffd::BlockSize && i < 2 * ffd::BlockSize) || i >= 3 * ffd::BlockSize;
      if (gathered && cells[i] == cell)
      {
        expected.push_back(i);
      }
      if (i >= 3 * ffd::BlockSize && cells[i] == cell)
      {
        expectedTail.push_back(i);
      }
    }
  }
  EXPECT_EQ(ffd::GatherByCell(cells.data(), n, cellCount, ffd::GatheredBlocks(cells.data(), n, maxCells)), expected);
  EXPECT_TRUE(ffd::BlockInPlace(cells.data(), n, 0, maxCells));
  EXPECT_FALSE(ffd::BlockInPlace(cells.data(), n, 1, maxCells));
  EXPECT_TRUE(ffd::BlockInPlace(cells.data(), n, 2, maxCells));
  EXPECT_FALSE(ffd::BlockInPlace(cells.data(), n, 3, maxCells));
  EXPECT_FALSE(ffd::BlockInPlace(cells.data(), n, 1, 9));
  EXPECT_TRUE(ffd::BlockInPlace(cells.data(), n, 1, 10));
  EXPECT_EQ(
    ffd::GatherByCell(cells.data(), n, cellCount, ffd::GatheredBlocks(cells.data(), n, ffd::BlockSize)), expectedTail);

  // What the gathered pass reads: that list, its last point repeated up to whole blocks, and their cells.
  const ffd::GatheredPoints gathered = ffd::ListGatheredPoints(cells.data(), n, cellCount, maxCells);
  ASSERT_EQ(gathered.Order.size(), 2u * ffd::BlockSize);
  EXPECT_EQ(gathered.TileBlocks.back(), 2);
  for (std::size_t g = 0; g < gathered.Order.size(); ++g)
  {
    EXPECT_EQ(gathered.Order[g], expected[std::min(g, expected.size() - 1)]) << g;
    EXPECT_EQ(gathered.Cells[g], cells[std::size_t(gathered.Order[g])]) << g;
  }
  EXPECT_EQ(gathered.Blocks.Entry.size(), 2u);
  // Where the results go: the gathered blocks 1 and 3 (partial), in the one tile, each point's rank its place
  // in the list.
  EXPECT_EQ(gathered.TileCount(), 1);
  EXPECT_EQ(gathered.TileBlocks, (std::vector<std::int64_t>{ 0, 2 }));
  EXPECT_EQ(gathered.Sources, (std::vector<std::int64_t>{ 1, 3 }));
  EXPECT_EQ(gathered.TileSources, (std::vector<std::int64_t>{ 0, 2 }));
  for (std::size_t k = 0; k < gathered.Sources.size(); ++k)
  {
    for (int l = 0; l < ffd::BlockSize && gathered.Sources[k] * ffd::BlockSize + l < n; ++l)
    {
      EXPECT_EQ(gathered.Order[gathered.Ranks[k * ffd::BlockSize + l]], gathered.Sources[k] * ffd::BlockSize + l);
    }
  }

  // In tiles of 2 blocks: block 1 in the first, sorted by cell; the tail in the second, padded by its last point.
  const ffd::GatheredPoints tiled = ffd::ListGatheredPoints(cells.data(), n, cellCount, maxCells, 2 * ffd::BlockSize);
  EXPECT_EQ(tiled.TileCount(), 2);
  EXPECT_EQ(tiled.TileBlocks, (std::vector<std::int64_t>{ 0, 1, 2 }));
  EXPECT_EQ(tiled.TileSources, (std::vector<std::int64_t>{ 0, 1, 2 }));
  std::vector<int> firstTile, secondTile;
  for (int i : expected)
  {
    (i < 2 * ffd::BlockSize ? firstTile : secondTile).push_back(i);
  }
  for (int g = 0; g < ffd::BlockSize; ++g)
  {
    EXPECT_EQ(tiled.Order[std::size_t(g)], firstTile[std::size_t(g)]) << g;
    EXPECT_EQ(tiled.Order[std::size_t(ffd::BlockSize + g)], secondTile[std::min(std::size_t(g), secondTile.size() - 1)])
      << g;
  }
  for (int l = 0; l < 5; ++l) // ranks are places within the tile's run
  {
    EXPECT_EQ(tiled.Order[std::size_t(ffd::BlockSize + tiled.Ranks[ffd::BlockSize + l])], 3 * ffd::BlockSize + l);
  }

  // The mean over the whole blocks, and the limits it gives: every block in place for a trilinear lattice at
  // a mean of 1.7 or less (2 with a cell table), for the other local bases at 1.2 or less, none above it (and
  // never for the global basis).
  EXPECT_EQ(ffd::CellsOfBlock(cells.data(), 1), maxCells + 2);
  EXPECT_DOUBLE_EQ(ffd::MeanCellsPerBlock(cells.data(), n), (1.0 + (maxCells + 2) + 2.0) / 3.0);
  EXPECT_EQ(ffd::MaxCellsInPlace(ffd::GridBasis::Trilinear, 1.5, false), ffd::BlockSize);
  EXPECT_EQ(ffd::MaxCellsInPlace(ffd::GridBasis::Trilinear, 1.9, false), 0);
  EXPECT_EQ(ffd::MaxCellsInPlace(ffd::GridBasis::Trilinear, 1.9, true), ffd::BlockSize);
  EXPECT_EQ(ffd::MaxCellsInPlace(ffd::GridBasis::Trilinear, 4.5, true), 0);
  EXPECT_EQ(ffd::MaxCellsInPlace(ffd::GridBasis::CubicBSpline, 1.5, false), 0);
  EXPECT_EQ(ffd::MaxCellsInPlace(ffd::GridBasis::TriquadraticBezier, 1.1, true), ffd::BlockSize);
  EXPECT_EQ(ffd::MaxCellsInPlace(ffd::GridBasis::TriquadraticBezier, 1.4, true), 0);
  EXPECT_EQ(ffd::MaxCellsInPlace(ffd::GridBasis::Bernstein, 16.0, false), ffd::BlockSize);

  // The same blocks listed: block 0 in one cell, block 1 in 9 cells and -1, block 2 in cell 3 (its odd points)
  // and -1; the partial tail is not listed. In place as BlockInPlace() says.
  const ffd::BlockCells listed = ffd::ListBlockCells(cells.data(), n, maxCells);
  ASSERT_EQ(listed.Entry.size(), 3u);
  EXPECT_EQ(listed.Entry[0], -1);
  ASSERT_GE(listed.Entry[1], 0);
  const int* second = listed.List.data() + listed.Entry[1];
  EXPECT_EQ(second[0], maxCells + 1);
  EXPECT_EQ(second[1], maxCells + 2);
  unsigned covered = 0;
  for (int k = 0; k < second[0]; ++k)
  {
    const int cell = second[2 + 2 * k];
    const unsigned bits = unsigned(second[3 + 2 * k]);
    EXPECT_GE(cell, 0);
    EXPECT_EQ(covered & bits, 0u) << "a point listed in two cells";
    covered |= bits;
    for (int l = 0; l < ffd::BlockSize; ++l)
    {
      EXPECT_EQ((bits >> l) & 1u, cells[ffd::BlockSize + l] == cell ? 1u : 0u) << "cell " << cell << " point " << l;
    }
  }
  const int* third = listed.List.data() + listed.Entry[2];
  EXPECT_EQ(third[0], 1);
  EXPECT_EQ(third[1], 2);
  EXPECT_EQ(third[2], 3);
  EXPECT_EQ(unsigned(third[3]), 0xAAAAu);
  for (int b = 0; b < 3; ++b)
  {
    EXPECT_EQ(listed.InPlace(b), ffd::BlockInPlace(cells.data(), n, b, maxCells)) << "block " << b;
  }
}

TEST(FFDGridLanes, CellSplitTakesTheFlatIndexApart)
{
  // The in-place pass takes a cell index apart by multiplications (ffd::CellSplit): the same indices as
  // GridDeformation::CellIndices()'s divisions, for small, prime and large divisors, at the ends of the range.
  ffdtest::Rng rng(603);
  for (int dx : { 1, 2, 3, 7, 9, 255, 1000, 46340 })
  {
    for (int dy : { 1, 5, 64, 46339 })
    {
      ffd::GridDeformation<4, double> d{};
      d.Basis = ffd::GridBasis::Trilinear;
      d.Voxels[0] = dx;
      d.Voxels[1] = dy;
      d.Voxels[2] = 1;
      const ffd::CellSplit split = ffd::CellSplit::For(d.Basis, d.Voxels);
      std::vector<int> cells = { 0, 1, dx - 1, dx, dx * dy - 1, std::numeric_limits<int>::max(),
        std::numeric_limits<int>::max() - 1 };
      for (int k = 0; k < 1000; ++k)
      {
        cells.push_back(std::uniform_int_distribution<int>(0, std::numeric_limits<int>::max())(rng));
      }
      for (int cell : cells)
      {
        int want[3], got[3];
        d.CellIndices(cell, want);
        split.Split(cell, got);
        ASSERT_TRUE(want[0] == got[0] && want[1] == got[1] && want[2] == got[2])
          << "cell " << cell << " divisors " << dx << " " << dy;
      }
    }
  }
}

} // namespace
