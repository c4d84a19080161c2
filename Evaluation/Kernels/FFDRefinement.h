// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDRefinement.h
 * @brief Exact refinement of the grid bases: the control points of n voxels per axis as those of 2n.
 *
 * Every grid basis of n voxels along an axis spans a space of functions that the same basis of 2n voxels also
 * spans (the paper: "any deformation produced with a grid of density n can be exactly produced on a grid of
 * density 2n"), so each control point of the fine lattice is a fixed combination of a few coarse ones. Along one
 * axis, fine control point j is sum_i R_ji c_i over the coarse points [First, First + Count):
 *
 * | basis             | fine points | R                                                                      |
 * |-------------------|-------------|------------------------------------------------------------------------|
 * | Bezier, degree d  | 2dn + 1     | de Casteljau at r = 1/2 in each voxel: left k: C(k,i) / 2^k on dV + i; |
 * | (trilinear d = 1) |             | right k: C(d-k,i) / 2^(d-k) on dV + k + i                              |
 * | cubic B-spline    | 2n + 3      | knot insertion at every voxel's middle: (c_{i-1} + 6 c_i + c_{i+1}) / 8 |
 * |                   |             | at fine 2i - 1, (c_i + c_{i+1}) / 2 at fine 2i                          |
 * | Bernstein, deg. n | 2n + 1      | degree elevation by n: C(n,i) C(n,j-i) / C(2n,j)                        |
 *
 * The fine lattice of a tensor-product basis is the tensor product of the axes' refinements. Each fine point's row
 * depends only on j, so a fine point computed from any coarse voxel that holds it is computed the same way. The
 * coefficients of the local bases are dyadic (exact in binary); degree elevation's are rounded once each. For a
 * local basis, the row of every fine point in the support of fine voxel f lies in the support of coarse voxel
 * f / 2 (LocalRefinementRow() checks it): a fine voxel's control points follow from its parent's alone.
 */
#ifndef FFDRefinement_h
#define FFDRefinement_h

#include "FFDBernstein.h"
#include "FFDGridBasis.h"

namespace ffd
{

/// Fine control point j's combination of coarse control points [First, First + Count) along one axis.
struct RefinementRow
{
  int First = 0;
  int Count = 0;
  double W[MaxBernsteinDegree / 2 + 1] = {};
};

namespace detail
{
/// C(n, k) as a double, exact for every n <= MaxBernsteinDegree (below 2^53).
inline double Binomial(int n, int k)
{
  double c = 1;
  for (int i = 1; i <= k; ++i)
  {
    c = c * double(n - k + i) / double(i);
  }
  return c;
}
} // namespace detail

/**
 * The row of fine control point j (0 <= j < ControlPointsAlongAxis(basis, 2 voxels)) of an axis of `voxels` coarse
 * voxels (1 <= voxels, and 2 voxels <= MaxBernsteinDegree for the global basis).
 */
inline RefinementRow RefineRow(GridBasis basis, int voxels, int j)
{
  RefinementRow row;
  if (basis == GridBasis::Bernstein)
  {
    const int n = voxels;
    row.First = j > n ? j - n : 0;
    row.Count = (j < n ? j : n) - row.First + 1;
    for (int t = 0; t < row.Count; ++t)
    {
      const int i = row.First + t;
      row.W[t] = detail::Binomial(n, i) * detail::Binomial(n, j - i) / detail::Binomial(2 * n, j);
    }
  }
  else if (basis == GridBasis::CubicBSpline)
  {
    if (j % 2 == 1)
    {
      row.First = (j + 1) / 2 - 1;
      row.Count = 3;
      row.W[0] = 0.125;
      row.W[1] = 0.75;
      row.W[2] = 0.125;
    }
    else
    {
      row.First = j / 2;
      row.Count = 2;
      row.W[0] = 0.5;
      row.W[1] = 0.5;
    }
  }
  else
  {
    const int d = BezierDegree(basis);
    const int fineVoxel = j / d < 2 * voxels ? j / d : 2 * voxels - 1;
    const int k = j - d * fineVoxel; // 0..d within the fine voxel
    const int parent = fineVoxel / 2;
    const bool left = fineVoxel % 2 == 0;
    const int order = left ? k : d - k; // the de Casteljau point is an average of order + 1 coarse points
    row.First = d * parent + (left ? 0 : k);
    row.Count = order + 1;
    for (int i = 0; i <= order; ++i)
    {
      row.W[i] = detail::Binomial(order, i) / double(1 << order);
    }
  }
  return row;
}

/**
 * RefineRow() for fine control point j in the support of fine voxel `fineVoxel`, with First made relative to the
 * support of the parent coarse voxel fineVoxel / 2 (VoxelSupport()); false if the row reached outside it, which
 * the bases' definitions rule out (the tests check every case).
 */
inline bool LocalRefinementRow(GridBasis basis, int voxels, int fineVoxel, int j, RefinementRow& row)
{
  row = RefineRow(basis, voxels, j);
  int first = 0, count = 0;
  VoxelSupport(basis, voxels, basis == GridBasis::Bernstein ? 0 : fineVoxel / 2, first, count);
  row.First -= first;
  return row.First >= 0 && row.First + row.Count <= count;
}

} // namespace ffd

#endif
