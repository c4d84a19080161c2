// SPDX-License-Identifier: BSD-3-Clause
// The one-dimensional refinement of FFDRefinement.h against the float64 reference's bases (ffdref::AxisWeights:
// binomials times powers, Cox-de Boor): for every basis and random coarse control values, the function of the
// refined control values equals the coarse function at random parameters; every local row lies in its parent
// voxel's support.
//
// Tolerance: both sides sum at most 2n + 1 products of weights in [0, 1] (partition of unity) and values of
// magnitude <= 1, each refined value itself a convex combination rounded once per term, so each side is within
// (4n + 4) eps of the exact value: the bound below, with n the coarse voxels.

#include "FFDReference.h"
#include "FFDRefinement.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace
{
using ffdref::Basis;

double Evaluate(Basis basis, int voxels, const std::vector<double>& c, double s)
{
  const std::vector<double> w = ffdref::AxisWeights(basis, voxels, s);
  double sum = 0;
  for (std::size_t i = 0; i < c.size(); ++i)
  {
    sum += w[i] * c[i];
  }
  return sum;
}

const Basis Bases[] = { Basis::Bernstein, Basis::Trilinear, Basis::TriquadraticBezier, Basis::TricubicBezier,
  Basis::CubicBSpline };
} // namespace

TEST(FFDRefinement, RefinedControlPointsGiveTheSameFunction)
{
  std::mt19937 rng(20261126);
  std::uniform_real_distribution<double> value(-1, 1), parameter(0, 1);
  for (Basis basis : Bases)
  {
    for (int voxels : { 1, 2, 3, 5, 8 })
    {
      const ffd::GridBasis grid = ffd::GridBasis(int(basis));
      std::vector<double> coarse(ffdref::PointsAlongAxis(basis, voxels));
      for (double& c : coarse)
      {
        c = value(rng);
      }
      std::vector<double> fine(ffdref::PointsAlongAxis(basis, 2 * voxels));
      ASSERT_EQ(int(fine.size()), ffd::ControlPointsAlongAxis(grid, 2 * voxels));
      for (int j = 0; j < int(fine.size()); ++j)
      {
        const ffd::RefinementRow row = ffd::RefineRow(grid, voxels, j);
        ASSERT_GE(row.First, 0);
        ASSERT_LE(row.First + row.Count, int(coarse.size()));
        for (int t = 0; t < row.Count; ++t)
        {
          fine[j] += row.W[t] * coarse[row.First + t];
        }
      }
      const double tolerance = (4 * voxels + 4) * std::numeric_limits<double>::epsilon();
      for (int sample = 0; sample < 200; ++sample)
      {
        const double s = sample < 2 ? double(sample) : parameter(rng);
        EXPECT_NEAR(Evaluate(basis, 2 * voxels, fine, s), Evaluate(basis, voxels, coarse, s), tolerance)
          << "basis " << int(basis) << ", " << voxels << " voxels, s = " << s;
      }
    }
  }
}

TEST(FFDRefinement, AFineVoxelsControlPointsFollowFromItsParentsSupport)
{
  for (Basis basis : Bases)
  {
    if (basis == Basis::Bernstein)
    {
      continue; // one voxel: every row lies in the whole lattice (checked above)
    }
    const ffd::GridBasis grid = ffd::GridBasis(int(basis));
    for (int voxels : { 1, 2, 3, 7 })
    {
      for (int fineVoxel = 0; fineVoxel < 2 * voxels; ++fineVoxel)
      {
        int first = 0, count = 0;
        ffd::VoxelSupport(grid, 2 * voxels, fineVoxel, first, count);
        for (int j = first; j < first + count; ++j)
        {
          ffd::RefinementRow row;
          EXPECT_TRUE(ffd::LocalRefinementRow(grid, voxels, fineVoxel, j, row))
            << "basis " << int(basis) << ", fine voxel " << fineVoxel << ", point " << j;
        }
      }
    }
  }
}
