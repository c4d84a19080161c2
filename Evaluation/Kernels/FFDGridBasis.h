// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDGridBasis.h
 * @brief Tensor-product bases over a grid of voxels: global Bernstein, Bezier sub-regions, cubic B-spline.
 *
 * Every grid basis of VoxelFFD is a tensor product of one-dimensional bases, one per axis of the frame. Along an
 * axis of n voxels, the parameter s in [0, 1] falls in voxel c = min(floor(s n), n - 1) at local coordinate
 * r = s n - c, and a few consecutive control points [First, First + Count) carry the weights:
 *
 * | basis                | points per axis | First     | Count | weights                      | continuity |
 * |----------------------|-----------------|-----------|-------|------------------------------|------------|
 * | Bernstein (global)   | n + 1           | 0         | n + 1 | B_{i,n}(s), degree n = voxels| C-infinity |
 * | Trilinear            | n + 1           | c         | 2     | 1 - r, r (paper Listing 1)   | C0         |
 * | TriquadraticBezier   | 2n + 1          | 2c        | 3     | B_{i,2}(r)                   | C0         |
 * | TricubicBezier       | 3n + 1          | 3c        | 4     | B_{i,3}(r) (Listing 2, eq. 4)| C0         |
 * | CubicBSpline         | n + 3           | c         | 4     | uniform cubic B-spline of r  | C2         |
 *
 * Neighbouring Bezier voxels share their face control points. The B-spline lattice has one ring of control
 * points beyond the frame on every side. Rest positions (RestParameter) are the Greville abscissae, so every
 * basis reproduces affine maps (linear precision) and the rest lattice is the identity.
 *
 * The global Bernstein basis is the case of one voxel of degree n; the binding (GridBinding) therefore sees
 * one cell per axis for it.
 */
#ifndef FFDGridBasis_h
#define FFDGridBasis_h

#include "FFDBernstein.h"
#include "FFDFrame.h"

#include <cstdint>

namespace ffd
{

/// The grid bases; the values are those of vtkFFDBuildLattice::Bases and of the `FFDBasis` field array.
enum class GridBasis : int
{
  Bernstein = 0,
  Trilinear = 1,
  TriquadraticBezier = 2,
  TricubicBezier = 3,
  CubicBSpline = 4,
};

/// True for the values of GridBasis.
FFD_INLINE bool IsGridBasis(int basis)
{
  return basis >= int(GridBasis::Bernstein) && basis <= int(GridBasis::CubicBSpline);
}

/// Polynomial degree of a Bezier basis in each voxel (1, 2, 3), 0 for the others.
FFD_INLINE constexpr int BezierDegree(GridBasis basis)
{
  return basis == GridBasis::Trilinear       ? 1
    : basis == GridBasis::TriquadraticBezier ? 2
    : basis == GridBasis::TricubicBezier     ? 3
                                             : 0;
}

/// Control points along an axis of `voxels` voxels.
FFD_INLINE int ControlPointsAlongAxis(GridBasis basis, int voxels)
{
  switch (basis)
  {
    case GridBasis::Bernstein:
      return voxels + 1;
    case GridBasis::CubicBSpline:
      return voxels + 3;
    default:
      return BezierDegree(basis) * voxels + 1;
  }
}

/// Most control points along an axis that influence one point (the size of the per-axis weight arrays).
FFD_INLINE int SupportSize(GridBasis basis, int voxels)
{
  return basis == GridBasis::Bernstein ? voxels + 1 : (basis == GridBasis::CubicBSpline ? 4 : BezierDegree(basis) + 1);
}

/// Parameter of control point i's rest position along an axis of `voxels` voxels (outside [0, 1] for the
/// B-spline's outer ring).
FFD_INLINE double RestParameter(GridBasis basis, int voxels, int i)
{
  switch (basis)
  {
    case GridBasis::Bernstein:
      return double(i) / voxels;
    case GridBasis::CubicBSpline:
      return double(i - 1) / voxels;
    default:
      return double(i) / (BezierDegree(basis) * voxels);
  }
}

/// The control points [first, first + count) along an axis that influence voxel `voxel` of that axis.
FFD_INLINE void VoxelSupport(GridBasis basis, int voxels, int voxel, int& first, int& count)
{
  count = SupportSize(basis, voxels);
  first = basis == GridBasis::Bernstein ? 0 : (basis == GridBasis::CubicBSpline ? voxel : BezierDegree(basis) * voxel);
}

/// Cells per axis seen by the binding: the voxels, except for the global basis (one cell).
FFD_INLINE int BindingCells(GridBasis basis, int voxels)
{
  return basis == GridBasis::Bernstein ? 1 : voxels;
}

/**
 * BindToGrid()'s flat cell index ci + cx (cj + cy ck) taken apart by multiplications: the same indices as
 * GridDeformation::CellIndices(), whose two integer divisions by run-time divisors cost as much as the rest of a
 * point's set-up in the CPU's lane groups and the GPU's float32 kernel. n / d is (n M) >> S with
 * S = 31 + ceil(log2 d) and M = ceil(2^S / d) < 2^32, exact for every 0 <= n < 2^31 (Granlund and Montgomery,
 * "Division by invariant integers using multiplication", 1994: M d - 2^S < d <= 2^(S - 31)).
 */
struct CellSplit
{
  std::uint32_t M[2];
  int S[2];
  int D[2];

  /// The split for a lattice of `voxels` divisions of that basis.
  FFD_INLINE static CellSplit For(GridBasis basis, const int voxels[3])
  {
    CellSplit split{};
    for (int a = 0; a < 2; ++a)
    {
      const int d = BindingCells(basis, voxels[a]);
      int log2 = 0;
      while ((std::uint64_t(1) << log2) < std::uint64_t(d))
      {
        ++log2;
      }
      split.S[a] = 31 + log2;
      split.M[a] = std::uint32_t(((std::uint64_t(1) << split.S[a]) + std::uint64_t(d) - 1) / std::uint64_t(d));
      split.D[a] = d;
    }
    return split;
  }

  /// The indices along the three axes of a cell (0 <= cell < 2^31).
  FFD_INLINE void Split(int cell, int c[3]) const
  {
    FFD_UNROLL
    for (int a = 0; a < 2; ++a)
    {
      const int q = int(std::uint64_t(std::uint32_t(cell)) * this->M[a] >> this->S[a]);
      c[a] = cell - q * this->D[a];
      cell = q;
    }
    c[2] = cell;
  }
};

/// The cell of parameter s in [0, 1] along an axis of `cells` cells; s = 1 belongs to the last cell.
template <typename Real>
FFD_INLINE int CellOf(Real s, int cells)
{
  const int c = int(s * Real(cells));
  return c < 0 ? 0 : (c >= cells ? cells - 1 : c);
}

/// Weights of the control points along one axis that influence a point, and their derivatives with respect
/// to the frame parameter s (not the local coordinate).
template <int MaxCount, typename Real>
struct AxisWeights
{
  int First;
  int Count;
  Real W[MaxCount];
  Real D[MaxCount];
};

namespace detail
{
/// Bernstein weights of degree 1 to 3 at r, and their derivatives times `scale` (d/ds = scale d/dr), written
/// out so that every array index is a constant (on a GPU a run-time index would put the arrays in local memory).
template <int MaxCount, typename Real>
FFD_INLINE void LowDegreeBernstein(int degree, Real r, Real scale, bool withDerivative, AxisWeights<MaxCount, Real>& a)
{
  const Real q = Real(1) - r;
  if (degree == 1)
  {
    a.W[0] = q;
    a.W[1] = r;
  }
  else if (degree == 2)
  {
    a.W[0] = q * q;
    a.W[1] = Real(2) * q * r;
    a.W[2] = r * r;
  }
  else
  {
    a.W[0] = q * q * q;
    a.W[1] = Real(3) * q * q * r;
    a.W[2] = Real(3) * q * r * r;
    a.W[3] = r * r * r;
  }
  if (withDerivative)
  {
    if (degree == 1)
    {
      a.D[0] = -scale;
      a.D[1] = scale;
    }
    else if (degree == 2)
    {
      a.D[0] = Real(-2) * q * scale;
      a.D[1] = Real(2) * (q - r) * scale;
      a.D[2] = Real(2) * r * scale;
    }
    else
    {
      a.D[0] = Real(-3) * q * q * scale;
      a.D[1] = Real(3) * q * (q - Real(2) * r) * scale;
      a.D[2] = Real(3) * r * (Real(2) * q - r) * scale;
      a.D[3] = Real(3) * r * r * scale;
    }
  }
}
} // namespace detail

/**
 * Count, W (and D when withDerivative) of a local basis at local coordinate r in [0, 1] of a voxel along an
 * axis of n voxels; First is the caller's. The derivatives are with respect to the frame parameter s (n d/dr).
 * Real may be a Lanes type whose lanes lie in different voxels (FFDGridLanes.h): r and n are per lane.
 */
template <int MaxCount, typename Real>
FFD_INLINE void ComputeLocalAxisWeights(
  GridBasis basis, Real n, Real r, bool withDerivative, AxisWeights<MaxCount, Real>& a)
{
  static_assert(MaxCount >= 4, "a local basis has up to 4 weights per axis");
  if (basis == GridBasis::CubicBSpline)
  {
    // Uniform cubic B-spline: (1-r)^3/6, (3r^3 - 6r^2 + 4)/6, (-3r^3 + 3r^2 + 3r + 1)/6, r^3/6.
    const Real q = Real(1) - r, r2 = r * r, r3 = r2 * r, sixth = Real(1) / Real(6);
    a.Count = 4;
    a.W[0] = q * q * q * sixth;
    a.W[1] = (Real(3) * r3 - Real(6) * r2 + Real(4)) * sixth;
    a.W[2] = (Real(-3) * r3 + Real(3) * r2 + Real(3) * r + Real(1)) * sixth;
    a.W[3] = r3 * sixth;
    if (withDerivative)
    {
      const Real h = n * Real(0.5); // d/ds = n d/dr
      a.D[0] = -q * q * h;
      a.D[1] = (Real(3) * r2 - Real(4) * r) * h;
      a.D[2] = (Real(-3) * r2 + Real(2) * r + Real(1)) * h;
      a.D[3] = r2 * h;
    }
    return;
  }
  // A Bezier voxel: Bernstein polynomials of degree 1, 2 or 3 in r.
  const int degree = BezierDegree(basis);
  a.Count = degree + 1;
  detail::LowDegreeBernstein(degree, r, n, withDerivative, a);
}

/**
 * Fills `a` for the parameter s of a point bound to `cell` along an axis of `voxels` voxels; s outside [0, 1]
 * (a point clamped to the frame) counts as the nearest face. The local coordinate is clamped to [0, 1], so a
 * point evaluated in a precision lower than that of its binding stays in its cell. Derivatives are computed
 * only when withDerivative is true. With MaxCount <= 4 (every local basis) the global basis is limited to
 * degree 3 (one cubic voxel).
 */
template <int MaxCount, typename Real>
FFD_INLINE void ComputeAxisWeights(
  GridBasis basis, int voxels, int cell, Real s, bool withDerivative, AxisWeights<MaxCount, Real>& a)
{
  static_assert(MaxCount >= 4, "a local basis has up to 4 weights per axis");
  if (basis != GridBasis::Bernstein)
  {
    // The bound cell is the clamped parameter's, so clamping r alone gives what clamping s first would.
    const Real n = Real(voxels);
    a.First = basis == GridBasis::CubicBSpline ? cell : BezierDegree(basis) * cell;
    ComputeLocalAxisWeights(basis, n, Clamp01(s * n - Real(cell)), withDerivative, a);
    return;
  }
  // The global basis: Bernstein polynomials of degree `voxels` in s.
  const Real r = Clamp01(s);
  a.First = 0;
  a.Count = voxels + 1;
  if constexpr (MaxCount > 4)
  {
    if (voxels > 3) // the de Casteljau triangle for any degree
    {
      if (withDerivative)
      {
        BernsteinBasisAndDerivative(voxels, r, a.W, a.D);
      }
      else
      {
        BernsteinBasis(voxels, r, a.W);
      }
      return;
    }
  }
  detail::LowDegreeBernstein(voxels, r, Real(1), withDerivative, a);
}

namespace detail
{
/// Loop bound over one axis's weights: the compile-time MaxCount for the local bases (at most 4), so that
/// compilers unroll the loops and keep the weights in registers, the run-time count for the global basis.
template <int MaxCount, typename Real>
FFD_INLINE constexpr int LoopCount(const AxisWeights<MaxCount, Real>& a)
{
  return MaxCount <= 4 ? MaxCount : a.Count;
}
} // namespace detail

/**
 * How SumTensorProduct() reads control point `index` of a lattice of Values: three Values per control point,
 * in VTK order. A lattice stored otherwise specializes it: the CUDA backend's float4 lattice (one 16-byte load
 * per control point instead of three 4-byte ones).
 */
template <typename Value>
struct LatticeValues
{
  template <typename Real>
  FFD_INLINE static Vec3<Real> Get(const Value* values, int index)
  {
    const Value* v = values + 3 * index;
    return { Real(v[0]), Real(v[1]), Real(v[2]) };
  }
};

/**
 * sum_ijk W0_i W1_j W2_k V_ijk over the supports in `axes`, for values in VTK order on a grid of `dims`
 * (read through LatticeValues<Value>).
 * Value is the values' type, Real the weights' and the sum's: the same, or a Lanes type (FFDLanes.h) whose
 * lanes are points of one cell, each value then read once for all of them.
 */
template <int MaxCount, typename Real, typename Value>
FFD_INLINE Vec3<Real> SumTensorProduct(const Value* values, const int dims[3], const AxisWeights<MaxCount, Real>* axes)
{
  Vec3<Real> sum = { 0, 0, 0 };
  FFD_UNROLL
  for (int k = 0; k < detail::LoopCount(axes[2]); ++k)
  {
    if (k >= axes[2].Count)
    {
      break;
    }
    Vec3<Real> sumJ = { 0, 0, 0 };
    FFD_UNROLL
    for (int j = 0; j < detail::LoopCount(axes[1]); ++j)
    {
      if (j >= axes[1].Count)
      {
        break;
      }
      const int row = axes[0].First + dims[0] * ((axes[1].First + j) + dims[1] * (axes[2].First + k));
      Vec3<Real> sumI = { 0, 0, 0 };
      FFD_UNROLL
      for (int i = 0; i < detail::LoopCount(axes[0]); ++i)
      {
        if (i >= axes[0].Count)
        {
          break;
        }
        sumI = sumI + axes[0].W[i] * LatticeValues<Value>::template Get<Real>(values, row + i);
      }
      sumJ = sumJ + axes[1].W[j] * sumI;
    }
    sum = sum + axes[2].W[k] * sumJ;
  }
  return sum;
}

/**
 * SumTensorProduct() of G points of one cell (their supports the same: axes[g] of point g): each value is read
 * once for the G points, and each point's sum is made by the same operations in the same order as
 * SumTensorProduct()'s, so the results are the same bits.
 */
template <int G, int MaxCount, typename Real, typename Value>
FFD_INLINE void SumTensorProducts(
  const Value* values, const int dims[3], const AxisWeights<MaxCount, Real> (*axes)[3], Vec3<Real>* sums)
{
  const AxisWeights<MaxCount, Real>* first = axes[0];
  FFD_UNROLL
  for (int g = 0; g < G; ++g)
  {
    sums[g] = { 0, 0, 0 };
  }
  FFD_UNROLL
  for (int k = 0; k < detail::LoopCount(first[2]); ++k)
  {
    if (k >= first[2].Count)
    {
      break;
    }
    Vec3<Real> sumJ[G];
    FFD_UNROLL
    for (int g = 0; g < G; ++g)
    {
      sumJ[g] = { 0, 0, 0 };
    }
    FFD_UNROLL
    for (int j = 0; j < detail::LoopCount(first[1]); ++j)
    {
      if (j >= first[1].Count)
      {
        break;
      }
      const int row = first[0].First + dims[0] * ((first[1].First + j) + dims[1] * (first[2].First + k));
      Vec3<Real> sumI[G];
      FFD_UNROLL
      for (int g = 0; g < G; ++g)
      {
        sumI[g] = { 0, 0, 0 };
      }
      FFD_UNROLL
      for (int i = 0; i < detail::LoopCount(first[0]); ++i)
      {
        if (i >= first[0].Count)
        {
          break;
        }
        const Vec3<Real> v = LatticeValues<Value>::template Get<Real>(values, row + i);
        FFD_UNROLL
        for (int g = 0; g < G; ++g)
        {
          sumI[g] = sumI[g] + axes[g][0].W[i] * v;
        }
      }
      FFD_UNROLL
      for (int g = 0; g < G; ++g)
      {
        sumJ[g] = sumJ[g] + axes[g][1].W[j] * sumI[g];
      }
    }
    FFD_UNROLL
    for (int g = 0; g < G; ++g)
    {
      sums[g] = sums[g] + axes[g][2].W[k] * sumJ[g];
    }
  }
}

/// SumTensorProduct() and its derivatives with respect to (s, t, u): gradient's columns are d/ds, d/dt, d/du.
template <int MaxCount, typename Real, typename Value>
FFD_INLINE Vec3<Real> SumTensorProductWithGradient(
  const Value* values, const int dims[3], const AxisWeights<MaxCount, Real>* axes, Mat3<Real>& gradient)
{
  const Vec3<Real> zero = { 0, 0, 0 };
  Vec3<Real> sum = zero, sumS = zero, sumT = zero, sumU = zero;
  FFD_UNROLL
  for (int k = 0; k < detail::LoopCount(axes[2]); ++k)
  {
    if (k >= axes[2].Count)
    {
      break;
    }
    Vec3<Real> valJ = zero, valJS = zero, valJT = zero;
    FFD_UNROLL
    for (int j = 0; j < detail::LoopCount(axes[1]); ++j)
    {
      if (j >= axes[1].Count)
      {
        break;
      }
      const int row = axes[0].First + dims[0] * ((axes[1].First + j) + dims[1] * (axes[2].First + k));
      Vec3<Real> valI = zero, valIS = zero;
      FFD_UNROLL
      for (int i = 0; i < detail::LoopCount(axes[0]); ++i)
      {
        if (i >= axes[0].Count)
        {
          break;
        }
        const Vec3<Real> p = LatticeValues<Value>::template Get<Real>(values, row + i);
        valI = valI + axes[0].W[i] * p;
        valIS = valIS + axes[0].D[i] * p;
      }
      valJ = valJ + axes[1].W[j] * valI;
      valJS = valJS + axes[1].W[j] * valIS;
      valJT = valJT + axes[1].D[j] * valI;
    }
    sum = sum + axes[2].W[k] * valJ;
    sumS = sumS + axes[2].W[k] * valJS;
    sumT = sumT + axes[2].W[k] * valJT;
    sumU = sumU + axes[2].D[k] * valJ;
  }
  gradient = { { { sumS.x, sumT.x, sumU.x }, { sumS.y, sumT.y, sumU.y }, { sumS.z, sumT.z, sumU.z } } };
  return sum;
}

} // namespace ffd

#endif
