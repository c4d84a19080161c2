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
 * A sparse lattice (docs/pipeline-and-data-contract.md, "Data contract") binds the same way, then numbers its cells
 * from 0 in increasing order of that flat index (a point in a voxel without a cell keeps its position): the order of
 * the cells, and so every grouping of points by cell, is the dense lattice's, and a sparse lattice deforms its points
 * bit for bit as the dense one does.
 *
 * Outside policy: a point outside the frame keeps its position, or, with clamping, takes the displacement of
 * the frame point of its parameters clamped to [0, 1] (the nearest point of a box frame), and the Jacobian
 * loses the columns of the clamped directions.
 */
#ifndef FFDGridDeformation_h
#define FFDGridDeformation_h

#include "FFDGridBasis.h"

#include <cmath>
#include <cstddef>
#include <type_traits>

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
 * The cell of a point along each axis of a grid of `cells` cells per axis, or false where it keeps its position:
 * non-finite points, and points outside the frame (beyond ParametricTolerance()) unless clampOutside.
 */
template <typename Real>
FFD_INLINE bool BindToCells(
  const Frame<Real>& frame, const int cells[3], const Vec3<Real>& x, bool clampOutside, int c[3])
{
  const Vec3<Real> stu = frame.ToParametric(x);
  const Real p[3] = { stu.x, stu.y, stu.z };
  const Real lo = -ParametricTolerance<Real>(), hi = Real(1) + ParametricTolerance<Real>();
  for (int a = 0; a < 3; ++a)
  {
    if (!detail::IsFinite(p[a]) || (!clampOutside && !(p[a] >= lo && p[a] <= hi)))
    {
      return false;
    }
    c[a] = CellOf(p[a] < Real(0) ? Real(0) : (p[a] > Real(1) ? Real(1) : p[a]), cells[a]);
  }
  return true;
}

/// The cell a point is bound to (BindToCells()) as the flat index ci + cx (cj + cy ck), or -1 when it keeps its
/// position. `voxels` are the lattice's divisions.
template <typename Real>
FFD_INLINE int BindToGrid(
  const Frame<Real>& frame, GridBasis basis, const int voxels[3], const Vec3<Real>& x, bool clampOutside)
{
  const int cells[3] = { BindingCells(basis, voxels[0]), BindingCells(basis, voxels[1]),
    BindingCells(basis, voxels[2]) };
  int c[3];
  return BindToCells(frame, cells, x, clampOutside, c) ? c[0] + cells[0] * (c[1] + cells[1] * c[2]) : -1;
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

/// The degree of a local basis's polynomial in each cell along each axis: 1 (trilinear), 2 (triquadratic), 3
/// (tricubic Bezier and cubic B-spline); 0 for the global basis, which has no cell table.
FFD_INLINE constexpr int CellDegree(GridBasis basis)
{
  return basis == GridBasis::CubicBSpline ? 3 : BezierDegree(basis);
}

/**
 * True where a basis's cell table is a polynomial in the centred local coordinate u = 2r - 1 in [-1, 1] rather
 * than in r in [0, 1]: the tricubic Bezier basis. Its monomial coefficients in r reach 8 times its control points
 * along an axis (27 times in sum over the powers), and Horner's rule in float32 then lost more than the weighted
 * sum's error bound allows; in u they reach 1.5 times (5 in sum), below the cubic B-spline's 5.3 in r.
 */
FFD_INLINE constexpr bool CenteredCellTable(GridBasis basis)
{
  return basis == GridBasis::TricubicBezier;
}

/// Reals per cell in a cell table of a basis of that degree (FillCellTable()): the cell's indices along the
/// three axes, 5 unused, then the (degree + 1)^3 coefficients x y z each, rounded up to 32 bytes of floats.
FFD_INLINE constexpr int CellTableStride(int degree)
{
  return (8 + 3 * (degree + 1) * (degree + 1) * (degree + 1) + 7) / 8 * 8;
}

/// D of a cell table's entry at local coordinates r[g] of G lane groups, by Horner's rule, with its derivatives
/// where dDdr is not null: defined with the table (FFDCellTable.h).
template <int Degree, int G, typename Lane, typename Real>
FFD_INLINE void PowerForm(const Real* entry, const Lane (*r)[3], Vec3<Lane>* d, Mat3<Lane>* dDdr);

/// The control points of a sparse lattice's cell, for SumTensorProduct(): its support's indices into the
/// lattice's values, i fastest.
template <typename Value>
struct SupportValues
{
  const Value* Values;
  const int* Support;
};

template <typename Value>
struct LatticeValues<SupportValues<Value>>
{
  template <typename Real>
  FFD_INLINE static Vec3<Real> Get(const SupportValues<Value>* values, int index)
  {
    return LatticeValues<Value>::template Get<Real>(values->Values, values->Support[index]);
  }
};

/// Which lattices a GridDeformation evaluates: dense ones, sparse ones (CellSupports), or either, told apart at
/// run time by CellSupports (one instantiation for both, where the branch costs less than a second one: the CPU).
enum class GridStorage
{
  Either,
  Dense,
  Sparse
};

/**
 * A grid lattice's deformation, as plain data that host and device code evaluate alike. MaxCount bounds the
 * control points per axis that influence a point: 4 covers every local basis (and global ones up to degree 3),
 * MaxBernsteinDegree + 1 every global one; callers pick it from the basis (vtkFFDDeform, the CUDA backend).
 * StaticBasis, when not -1, is the basis known at compile time (it must equal Basis): the compiler then drops
 * the other bases' branches and unrolls the fixed-size sums (WithStaticBasis() instantiates one per basis).
 * Real is the displacements' type; Lane, the arithmetic's, is Real too, or on the host a Lanes type
 * (Evaluation/CPU/FFDLanes.h) that deforms several points of one cell at once through these same functions
 * (WithLanes()); Evaluation/CPU/FFDLaneCells.h deforms lanes in several cells from the same building blocks.
 * A deformation of a local basis WithCellTable evaluates each cell in power form from CellTable (FillCellTable()
 * of its displacements): the same function, rounded differently. That is a compile-time choice, so that no
 * code path holds both evaluations, whose common subexpressions the compiler would otherwise share and round
 * differently (a multiply no longer fused into its add) from one caller to another.
 * A sparse lattice (CellSupports not null, a local basis) holds only its cells' control points: Displacements
 * then has one entry per control point of the sparse lattice, and cells are numbered as the binding of a sparse
 * lattice numbers them (CellVoxels, CellSupports). Storage says which lattices an instantiation takes: the GPU's
 * kernels are instantiated for each (the run-time test slowed the dense trilinear kernel by 8 %).
 */
template <int MaxCount, typename Real, int StaticBasis = -1, typename Lane = Real, bool WithCellTable = false,
  GridStorage Storage = GridStorage::Either>
struct GridDeformation
{
  static_assert(!WithCellTable || StaticBasis != int(GridBasis::Bernstein), "a cell table is for a local basis");

  using Value = Real;                         ///< the displacements' type
  static constexpr int MaxWeights = MaxCount; ///< the size of its AxisWeights

  GridBasis Basis;
  int Voxels[3];             ///< the lattice's divisions
  int Dims[3];               ///< control points per axis
  const Real* Displacements; ///< 3 per control point, VTK order: the lattice's points minus RestPosition
  ffd::Frame<Lane> Frame;
  const Real* CellTable = nullptr; ///< WithCellTable: FillCellTable() of Displacements
  /// Sparse lattices only (null for dense ones): per cell, its voxel's index along each axis (3 ints), and the
  /// index in Displacements of each control point of its support (SupportCount()^3 ints, i fastest).
  const int* CellVoxels = nullptr;
  const int* CellSupports = nullptr;

  /// This deformation evaluated in lanes of type OtherLane (its frame converted once, host only).
  template <typename OtherLane>
  GridDeformation<MaxCount, Real, StaticBasis, OtherLane, WithCellTable, Storage> WithLanes() const
  {
    return { this->Basis, { this->Voxels[0], this->Voxels[1], this->Voxels[2] },
      { this->Dims[0], this->Dims[1], this->Dims[2] }, this->Displacements, this->Frame.template As<OtherLane>(),
      this->CellTable, this->CellVoxels, this->CellSupports };
  }

  /// True where cells are evaluated from CellTable (a compile-time constant).
  static constexpr bool UsesCellTable() { return WithCellTable; }

  /// True for a sparse lattice (never for the global basis), a compile-time constant unless Storage is Either.
  FFD_INLINE bool IsSparse() const
  {
    if constexpr (StaticBasis == int(GridBasis::Bernstein) || Storage == GridStorage::Dense)
    {
      return false;
    }
    else if constexpr (Storage == GridStorage::Sparse)
    {
      return true;
    }
    else
    {
      return this->CellSupports != nullptr;
    }
  }

  /// Control points along each axis of a cell's support (a local basis).
  FFD_INLINE int SupportCount() const { return CellDegree(this->BasisOf()) + 1; }

  /// The basis: StaticBasis where it is known at compile time (constant-folded), else Basis.
  FFD_INLINE GridBasis BasisOf() const { return StaticBasis >= 0 ? static_cast<GridBasis>(StaticBasis) : this->Basis; }

  /// X + D(s, t, u) for a point bound to `cell` (not -1); with lanes, every lane is bound to `cell`.
  FFD_INLINE Vec3<Lane> Deform(const Vec3<Lane>& x, int cell) const
  {
    Vec3<Lane> y;
    this->Deform<1>(&x, cell, &y);
    return y;
  }

  /// Deform() of G lane groups x[g] (or points) all bound to `cell`, into y[g]: with a CellTable, each of the
  /// cell's coefficients is read once for all groups (PowerForm()).
  template <int G>
  FFD_INLINE void Deform(const Vec3<Lane>* x, int cell, Vec3<Lane>* y) const
  {
    if constexpr (WithCellTable)
    {
      const Real* entry = this->CellEntry(cell);
      const Vec3<Lane> index = { Lane(entry[0]), Lane(entry[1]), Lane(entry[2]) };
      Lane r[G][3];
      FFD_UNROLL
      for (int g = 0; g < G; ++g)
      {
        this->TableCoordinates(this->Frame.ToParametric(x[g]), index, r[g]);
      }
      this->CellPowerForm<G>(entry, r, y, nullptr);
      FFD_UNROLL
      for (int g = 0; g < G; ++g)
      {
        y[g] = x[g] + y[g];
      }
      return;
    }
    int c[3];
    this->CellIndices(cell, c);
    FFD_UNROLL
    for (int g = 0; g < G; ++g)
    {
      y[g] = this->DeformInCell(x[g], cell, c);
    }
  }

  /// Deform() for a cell given also by its index along each axis (CellIndices()), for callers that take the flat
  /// index apart faster themselves (the CUDA backend multiplies by reciprocals instead of dividing).
  FFD_INLINE Vec3<Lane> DeformInCell(const Vec3<Lane>& x, int cell, const int indices[3]) const
  {
    AxisWeights<MaxCount, Lane> axes[3];
    this->Weights(this->Frame.ToParametric(x), indices, false, axes);
    if (this->IsSparse())
    {
      const SupportValues<Real> values = this->CellValues(cell, axes);
      return x + SumTensorProduct(&values, this->CellDims().D, axes);
    }
    return x + SumTensorProduct(this->Displacements, this->Dims, axes);
  }

  /// DeformInCell() of G points of one cell at once: each control point read once for all of them
  /// (SumTensorProducts()), the same results as G calls.
  template <int G>
  FFD_INLINE void DeformInCell(const Vec3<Lane>* x, int cell, const int indices[3], Vec3<Lane>* y) const
  {
    AxisWeights<MaxCount, Lane> axes[G][3];
    FFD_UNROLL
    for (int g = 0; g < G; ++g)
    {
      this->Weights(this->Frame.ToParametric(x[g]), indices, false, axes[g]);
    }
    Vec3<Lane> sums[G];
    if (this->IsSparse())
    {
      SupportValues<Real> values{};
      FFD_UNROLL
      for (int g = 0; g < G; ++g)
      {
        values = this->CellValues(cell, axes[g]);
      }
      SumTensorProducts<G>(&values, this->CellDims().D, axes, sums);
    }
    else
    {
      SumTensorProducts<G>(this->Displacements, this->Dims, axes, sums);
    }
    FFD_UNROLL
    for (int g = 0; g < G; ++g)
    {
      y[g] = x[g] + sums[g];
    }
  }

  /// The index along each axis of a bound cell: BindToGrid()'s flat index ci + cx (cj + cy ck) taken apart, or
  /// a sparse lattice's CellVoxels.
  FFD_INLINE void CellIndices(int cell, int c[3]) const
  {
    if (this->IsSparse())
    {
      this->SparseCellIndices(cell, c);
      return;
    }
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

  /// CellIndices() with the flat index taken apart by `split` (CellSplit::For() of this deformation).
  FFD_INLINE void CellIndices(const CellSplit& split, int cell, int c[3]) const
  {
    if (this->IsSparse())
    {
      this->SparseCellIndices(cell, c);
      return;
    }
    split.Split(cell, c);
  }

  /// Deform() and the Jacobian dX_ffd/dX there.
  FFD_INLINE Vec3<Lane> Deform(const Vec3<Lane>& x, int cell, Mat3<Lane>& jacobian) const
  {
    const Vec3<Lane> stu = this->Frame.ToParametric(x);
    if constexpr (WithCellTable)
    {
      const Real* entry = this->CellEntry(cell);
      Lane r[3];
      this->TableCoordinates(stu, { Lane(entry[0]), Lane(entry[1]), Lane(entry[2]) }, r);
      Mat3<Lane> gradient;
      Vec3<Lane> d;
      this->CellPowerForm<1>(entry, &r, &d, &gradient);
      jacobian = this->JacobianAt(stu, this->TableGradient(gradient));
      return x + d;
    }
    int c[3];
    this->CellIndices(cell, c);
    AxisWeights<MaxCount, Lane> axes[3];
    this->Weights(stu, c, true, axes);
    Mat3<Lane> gradient;
    Vec3<Lane> d;
    if (this->IsSparse())
    {
      const SupportValues<Real> values = this->CellValues(cell, axes);
      d = SumTensorProductWithGradient(&values, this->CellDims().D, axes, gradient);
    }
    else
    {
      d = SumTensorProductWithGradient(this->Displacements, this->Dims, axes, gradient);
    }
    jacobian = this->JacobianAt(stu, gradient);
    return x + d;
  }

  /// Calls f(index, weight) for each control point that moves a point x bound to `cell` (not -1): its index
  /// into Displacements and its weight in Deform(), the weights summing to 1. Host code with scalar lanes (the
  /// control points' masses in vtkFFDLatticeDynamics).
  template <typename F>
  void ForEachWeight(const Vec3<Lane>& x, int cell, F&& f) const
  {
    AxisWeights<MaxCount, Lane> axes[3];
    this->WeightsAt(x, cell, axes);
    for (int k = 0; k < axes[2].Count; ++k)
    {
      for (int j = 0; j < axes[1].Count; ++j)
      {
        for (int i = 0; i < axes[0].Count; ++i)
        {
          f(this->ControlPointOf(cell, axes, i, j, k), axes[0].W[i] * axes[1].W[j] * axes[2].W[k]);
        }
      }
    }
  }

  /// The weights along each axis of a point x bound to `cell` (not -1), as Deform() takes them: the weight of the
  /// support's control point (i, j, k) is axes[0].W[i] * axes[1].W[j] * axes[2].W[k] (ForEachWeight()).
  FFD_INLINE void WeightsAt(const Vec3<Lane>& x, int cell, AxisWeights<MaxCount, Lane>* axes) const
  {
    int c[3];
    this->CellIndices(cell, c);
    this->WeightsInCell(x, c, axes);
  }

  /// WeightsAt() for a point of the cell of indices `indices` along each axis (CellIndices()), for callers that
  /// take many points of one cell.
  FFD_INLINE void WeightsInCell(const Vec3<Lane>& x, const int indices[3], AxisWeights<MaxCount, Lane>* axes) const
  {
    this->Weights(this->Frame.ToParametric(x), indices, false, axes);
  }

  /// The index into Displacements of the control point (i, j, k) of the support of `cell`, whose WeightsAt() gave
  /// `axes` (their First: the same for every point of the cell).
  FFD_INLINE int ControlPointOf(int cell, const AxisWeights<MaxCount, Lane>* axes, int i, int j, int k) const
  {
    if (this->IsSparse())
    {
      const int n = this->SupportCount();
      return this->CellSupports[std::size_t(cell) * std::size_t(n * n * n) + std::size_t(i + n * (j + n * k))];
    }
    return axes[0].First + i + this->Dims[0] * (axes[1].First + j + this->Dims[1] * (axes[2].First + k));
  }

  // The building blocks of Deform(), public for the CPU's lanes in several cells (Evaluation/CPU/FFDLaneCells.h).

  /// The grid on which SumTensorProduct() finds a sparse lattice's cell's control points: its support's.
  struct Extent
  {
    int D[3];
  };
  FFD_INLINE Extent CellDims() const
  {
    const int n = this->SupportCount();
    return { { n, n, n } };
  }

  /// A sparse lattice's cell's control points, with `axes` (of that cell) made relative to its support.
  FFD_INLINE SupportValues<Real> CellValues(int cell, AxisWeights<MaxCount, Lane>* axes) const
  {
    const int n = this->SupportCount();
    FFD_UNROLL
    for (int a = 0; a < 3; ++a)
    {
      axes[a].First = 0;
    }
    return { this->Displacements, this->CellSupports + std::size_t(cell) * std::size_t(n * n * n) };
  }

  /// The CellTable entry of a bound cell.
  FFD_INLINE const Real* CellEntry(int cell) const
  {
    return this->CellTable + std::size_t(cell) * CellTableStride(CellDegree(this->BasisOf()));
  }

  /// PowerForm() of this deformation's basis.
  template <int G>
  FFD_INLINE void CellPowerForm(const Real* entry, const Lane (*r)[3], Vec3<Lane>* d, Mat3<Lane>* dDdr) const
  {
    switch (CellDegree(this->BasisOf()))
    {
      case 1:
        return PowerForm<1, G>(entry, r, d, dDdr);
      case 2:
        return PowerForm<2, G>(entry, r, d, dDdr);
      default:
        return PowerForm<3, G>(entry, r, d, dDdr);
    }
  }

  /// The local coordinates in the cells of indices `cell` (as numbers) of points at parameters stu, as
  /// ComputeAxisWeights() computes them, centred (2r - 1) where the table is (CenteredCellTable()).
  FFD_INLINE void TableCoordinates(const Vec3<Lane>& stu, const Vec3<Lane>& cell, Lane r[3]) const
  {
    const bool centered = CenteredCellTable(this->BasisOf());
    FFD_UNROLL
    for (int a = 0; a < 3; ++a)
    {
      const Lane n = Lane(this->Voxels[a]);
      r[a] = Clamp01(stu[a] * n - cell[a]);
      if (centered)
      {
        r[a] = Lane(2) * r[a] - Lane(1);
      }
    }
  }

  /// dD/d(s, t, u) from the dD/dr of PowerForm(): r = s n - c along each axis (2 (s n - c) - 1 centred).
  FFD_INLINE Mat3<Lane> TableGradient(Mat3<Lane> dDdr) const
  {
    const bool centered = CenteredCellTable(this->BasisOf());
    FFD_UNROLL
    for (int a = 0; a < 3; ++a)
    {
      const Lane n = Lane(centered ? 2 * this->Voxels[a] : this->Voxels[a]);
      for (int row = 0; row < 3; ++row)
      {
        dDdr.M[row][a] = dDdr.M[row][a] * n;
      }
    }
    return dDdr;
  }

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

private:
  FFD_INLINE void SparseCellIndices(int cell, int c[3]) const
  {
    const int* voxel = this->CellVoxels + 3 * std::size_t(cell);
    c[0] = voxel[0];
    c[1] = voxel[1];
    c[2] = voxel[2];
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

/**
 * Calls f(MaxCount, StaticBasis) with the GridDeformation template arguments of `basis` as
 * std::integral_constant values: the global basis sums over at most MaxBernsteinDegree + 1 control points an
 * axis, a local one over at most 4. One instantiation per basis, for the CPU and the CUDA backend alike.
 */
template <typename F>
inline void WithStaticBasis(GridBasis basis, F&& f)
{
  using Local = std::integral_constant<int, 4>;
  switch (basis)
  {
    case GridBasis::Bernstein:
      f(std::integral_constant<int, MaxBernsteinDegree + 1>(),
        std::integral_constant<int, int(GridBasis::Bernstein)>());
      break;
    case GridBasis::Trilinear:
      f(Local(), std::integral_constant<int, int(GridBasis::Trilinear)>());
      break;
    case GridBasis::TriquadraticBezier:
      f(Local(), std::integral_constant<int, int(GridBasis::TriquadraticBezier)>());
      break;
    case GridBasis::TricubicBezier:
      f(Local(), std::integral_constant<int, int(GridBasis::TricubicBezier)>());
      break;
    case GridBasis::CubicBSpline:
      f(Local(), std::integral_constant<int, int(GridBasis::CubicBSpline)>());
      break;
  }
}

} // namespace ffd

#endif
