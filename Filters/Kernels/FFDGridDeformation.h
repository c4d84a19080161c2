// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDGridDeformation.h
 * @brief Binding and per-point evaluation of a grid lattice's deformation, shared by the CPU and CUDA paths.
 *
 * Binding stores one int per point: the flat index ci + cx (cj + cy ck) of the cell the point lies in
 * (BindingCells() per axis), or -1 for a point that keeps its position. The local coordinates are not stored:
 * evaluation recomputes them from the point, which it reads anyway for the displacement form, in the point's
 * own precision, so the binding costs 4 bytes per point and loses no digit of a double-precision point.
 *
 * Outside policy: a point outside the frame keeps its position, or, with clamping, takes the displacement of
 * the nearest point of the frame (VTK's Edge border mode, Blender's lattice): the parameters are clamped to
 * [0, 1], and the Jacobian loses the columns of the clamped directions.
 */
#ifndef FFDGridDeformation_h
#define FFDGridDeformation_h

#include "FFDGridBasis.h"

#include <cmath>

namespace ffd
{

namespace detail
{
template <typename Real>
FFD_INLINE bool IsFinite(Real v)
{
  Real largest;
  if constexpr (sizeof(Real) >= sizeof(double))
  {
    largest = Real(1.7976931348623157e308);
  }
  else
  {
    largest = Real(3.40282347e38f);
  }
  return v >= -largest && v <= largest; // false for NaN and infinities
}
} // namespace detail

/**
 * The cell a point is bound to, or -1 when it keeps its position: non-finite points, and points outside the
 * frame (beyond ParametricTolerance()) unless clampOutside. `voxels` are the lattice's divisions.
 */
template <typename Real>
FFD_INLINE int BindToGrid(
  const Frame<Real>& frame, GridBasis basis, const int voxels[3], const Vec3<Real>& x, bool clampOutside)
{
  const Vec3<Real> stu = frame.ToParametric(x);
  const Real p[3] = { stu.x, stu.y, stu.z };
  const Real lo = -ParametricTolerance<Real>(), hi = Real(1) + ParametricTolerance<Real>();
  int cell = 0;
  for (int a = 2; a >= 0; --a)
  {
    if (!detail::IsFinite(p[a]) || (!clampOutside && !(p[a] >= lo && p[a] <= hi)))
    {
      return -1;
    }
    const int cells = BindingCells(basis, voxels[a]);
    cell = cell * cells + CellOf(p[a] < Real(0) ? Real(0) : (p[a] > Real(1) ? Real(1) : p[a]), cells);
  }
  return cell;
}

/**
 * dX_ffd/dX of the displacement form X_ffd = X + D(s(X), t(X), u(X)): I + dD/d(s,t,u) * d(s,t,u)/dX, where
 * displacementGradient's columns are dD/ds, dD/dt and dD/du.
 */
template <typename Real>
FFD_INLINE Mat3<Real> DeformationJacobian(const Mat3<Real>& displacementGradient, const Frame<Real>& frame)
{
  Mat3<Real> j = displacementGradient * frame.ParametricGradient();
  j.M[0][0] += Real(1);
  j.M[1][1] += Real(1);
  j.M[2][2] += Real(1);
  return j;
}

/**
 * A grid lattice's deformation, as plain data that host and device code evaluate alike. MaxCount bounds the
 * control points per axis that influence a point: 4 covers every local basis (and global ones up to degree 3),
 * MaxBernsteinDegree + 1 every global one; callers pick it from the basis (vtkFFDDeform, the CUDA backend).
 * StaticBasis, when not -1, is the basis known at compile time (it must equal Basis): the compiler then drops
 * the other bases' branches and unrolls the fixed-size sums, which made the local bases 2-3 times faster.
 * Real is the displacements' type; Lane, the arithmetic's, is Real too, or on the host a Lanes type
 * (FFDLanes.h) that deforms several points of one cell at once through these same functions (WithLanes()).
 */
template <int MaxCount, typename Real, int StaticBasis = -1, typename Lane = Real>
struct GridDeformation
{
  using Value = Real; ///< the displacements' type

  GridBasis Basis;
  int Voxels[3];             ///< the lattice's divisions
  int Dims[3];               ///< control points per axis
  const Real* Displacements; ///< 3 per control point, VTK order: the lattice's points minus RestPosition
  ffd::Frame<Lane> Frame;

  /// This deformation evaluated in lanes of type OtherLane (its frame converted once, host only).
  template <typename OtherLane>
  GridDeformation<MaxCount, Real, StaticBasis, OtherLane> WithLanes() const
  {
    return { this->Basis, { this->Voxels[0], this->Voxels[1], this->Voxels[2] },
      { this->Dims[0], this->Dims[1], this->Dims[2] }, this->Displacements,
      this->Frame.template As<OtherLane>() };
  }

  /// The basis: StaticBasis where it is known at compile time (constant-folded), else Basis.
  FFD_INLINE GridBasis BasisOf() const
  {
    return StaticBasis >= 0 ? static_cast<GridBasis>(StaticBasis) : this->Basis;
  }

  /// X + D(s, t, u) for a point bound to `cell` (not -1); with lanes, every lane is bound to `cell`.
  FFD_INLINE Vec3<Lane> Deform(const Vec3<Lane>& x, int cell) const
  {
    int c[3];
    this->CellIndices(cell, c);
    return this->DeformInCell(x, c);
  }

  /// Deform() for a cell given by its index along each axis (CellIndices()), for callers that take the flat
  /// index apart faster themselves (the CUDA backend multiplies by reciprocals instead of dividing).
  FFD_INLINE Vec3<Lane> DeformInCell(const Vec3<Lane>& x, const int cell[3]) const
  {
    AxisWeights<MaxCount, Lane> axes[3];
    this->Weights(this->Frame.ToParametric(x), cell, false, axes);
    return x + SumTensorProduct(this->Displacements, this->Dims, axes);
  }

  /**
   * Deform() for lanes bound to different cells of a local basis (host only, Lane a Lanes type): `cell` holds
   * each lane's cell index along each axis (CellIndices(), as numbers), and `values` reads each lane's control
   * points as LatticeValues<Values>: for a control point given relative to its cell's first one
   * (i + Dims[0] (j + Dims[1] k)), its value in every lane (FFDGridLanes.h). The same weights and sum as
   * Deform(), so a lane's result is bit for bit the one it gets when all lanes share its cell.
   */
  template <typename Values>
  Vec3<Lane> DeformInLaneCells(const Vec3<Lane>& x, const Vec3<Lane>& cell, const Values* values) const
  {
    AxisWeights<MaxCount, Lane> axes[3];
    this->LaneCellWeights(this->Frame.ToParametric(x), cell, false, axes);
    return x + SumTensorProduct(values, this->Dims, axes);
  }

  /// The index along each axis of a bound cell: BindToGrid()'s flat index ci + cx (cj + cy ck) taken apart.
  FFD_INLINE void CellIndices(int cell, int c[3]) const
  {
    const GridBasis basis = this->BasisOf();
    FFD_UNROLL
    for (int a = 0; a < 2; ++a)
    {
      const int cells = BindingCells(basis, this->Voxels[a]);
      c[a] = cell % cells;
      cell /= cells;
    }
    c[2] = cell; // the last axis takes what is left: no division
  }

  /// Deform() and the Jacobian dX_ffd/dX there.
  FFD_INLINE Vec3<Lane> Deform(const Vec3<Lane>& x, int cell, Mat3<Lane>& jacobian) const
  {
    const Vec3<Lane> stu = this->Frame.ToParametric(x);
    int c[3];
    this->CellIndices(cell, c);
    AxisWeights<MaxCount, Lane> axes[3];
    this->Weights(stu, c, true, axes);
    Mat3<Lane> gradient;
    const Vec3<Lane> d = SumTensorProductWithGradient(this->Displacements, this->Dims, axes, gradient);
    jacobian = this->JacobianAt(stu, gradient);
    return x + d;
  }

  /// DeformInLaneCells() and the Jacobian dX_ffd/dX there.
  template <typename Values>
  Vec3<Lane> DeformInLaneCells(
    const Vec3<Lane>& x, const Vec3<Lane>& cell, const Values* values, Mat3<Lane>& jacobian) const
  {
    const Vec3<Lane> stu = this->Frame.ToParametric(x);
    AxisWeights<MaxCount, Lane> axes[3];
    this->LaneCellWeights(stu, cell, true, axes);
    Mat3<Lane> gradient;
    const Vec3<Lane> d = SumTensorProductWithGradient(values, this->Dims, axes, gradient);
    jacobian = this->JacobianAt(stu, gradient);
    return x + d;
  }

private:
  /// The Jacobian from the displacement's gradient at parameters stu: a clamped direction (outside the frame)
  /// loses its column, the displacement not changing along it.
  FFD_INLINE Mat3<Lane> JacobianAt(const Vec3<Lane>& stu, Mat3<Lane> gradient) const
  {
    using Scalar = typename ScalarOf<Lane>::Type;
    const Lane lo = -ParametricTolerance<Scalar>(), hi = Lane(1) + ParametricTolerance<Scalar>();
    for (int a = 0; a < 3; ++a)
    {
      const auto inside = InRange(stu[a], lo, hi);
      for (int r = 0; r < 3; ++r)
      {
        gradient.M[r][a] = KeepWhere(inside, gradient.M[r][a]);
      }
    }
    return DeformationJacobian(gradient, this->Frame);
  }

  /// The weights along each axis at parameters stu of lanes in the cells of indices `cell` (DeformInLaneCells()),
  /// as ComputeAxisWeights() computes them for one cell.
  void LaneCellWeights(
    const Vec3<Lane>& stu, const Vec3<Lane>& cell, bool withDerivative, AxisWeights<MaxCount, Lane>* axes) const
  {
    const Lane p[3] = { stu.x, stu.y, stu.z };
    const Lane c[3] = { cell.x, cell.y, cell.z };
    for (int a = 0; a < 3; ++a)
    {
      const Lane n = Lane(this->Voxels[a]);
      axes[a].First = 0;
      ComputeLocalAxisWeights(this->BasisOf(), n, Clamp01(p[a] * n - c[a]), withDerivative, axes[a]);
    }
  }

  /// The weights along each axis at parameters stu (ComputeAxisWeights() clamps them to the frame) of a point
  /// in cell (ci, cj, ck).
  FFD_INLINE void Weights(
    const Vec3<Lane>& stu, const int cell[3], bool withDerivative, AxisWeights<MaxCount, Lane>* axes) const
  {
    const Lane p[3] = { stu.x, stu.y, stu.z };
    const GridBasis basis = this->BasisOf();
    FFD_UNROLL
    for (int a = 0; a < 3; ++a)
    {
      ComputeAxisWeights(basis, this->Voxels[a], cell[a], p[a], withDerivative, axes[a]);
    }
  }
};

} // namespace ffd

#endif
