// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDCellTable.h
 * @brief A local basis's cells in power form, for GridDeformation's WithCellTable evaluation.
 *
 * The CPU builds the table at every update where ffd::WorthCellTable() says it pays (FillCellTable(), cells in
 * parallel), the CUDA backend for the triquadratic and cubic bases on the device (a thread per cell and
 * component, detail::FillCellEntry()); GridDeformation (FFDGridDeformation.h) WithCellTable evaluates it by Horner's
 * rule (PowerForm(), declared there and defined here), so both backends evaluate the same table the same way.
 */
#ifndef FFDCellTable_h
#define FFDCellTable_h

#include "FFDGridDeformation.h"

#include <cstddef>

namespace ffd
{

/**
 * A local basis's displacement in each of its cells [cellBegin, cellEnd) (flat indices, as BindToGrid()
 * numbers them) in power form: at local coordinates (a, b, c) in [0, 1]^3 of the cell (in [-1, 1]^3, 2r - 1,
 * where the table is centred: CenteredCellTable()),
 * D = sum over i, j, k <= degree of C_ijk a^i b^j c^k, the C from the cell's (degree + 1)^3 control points by the
 * basis's change to monomials along each axis, in double. Horner's rule then takes (degree + 1)^3 - 1
 * multiply-adds a component, against about 1.3 times that and the weights for the weighted sum of the control
 * points (a half, and 14 against 7, for the trilinear basis). The rest lattice's coefficients are all 0, so it stays
 * exactly the identity. `displacements` as GridDeformation::Displacements on a grid of `dims`; `table` holds
 * CellTableStride(CellDegree(basis)) Reals per cell. For a sparse lattice, `cellVoxels` and `cellSupports` are
 * GridDeformation's (null for a dense one): its cells' entries are read through them, the same values in the same
 * order, so that its table is the dense lattice's, cell for cell.
 */
namespace detail
{
/// The change to monomials along an axis of a local basis: M[j][a], the coefficient of r^j (u^j for a centred
/// table, CenteredCellTable()) in the basis function of the cell's control point a.
template <GridBasis Basis>
struct ToMonomials
{
  static constexpr int N = CellDegree(Basis) + 1;
  double M[4][4] = {};

  FFD_HOST_DEVICE constexpr ToMonomials()
  {
    constexpr int d = N - 1;
    if constexpr (Basis == GridBasis::CubicBSpline)
    {
      const double m[4][4] = { { 1, 4, 1, 0 }, { -3, 0, 3, 0 }, { 3, -6, 3, 0 }, { -1, 3, -3, 1 } };
      for (int j = 0; j < 4; ++j)
      {
        for (int a = 0; a < 4; ++a)
        {
          this->M[j][a] = m[j][a] / 6.0;
        }
      }
    }
    else if constexpr (CenteredCellTable(Basis))
    {
      // Bernstein in u = 2r - 1: C(d, a) 2^-d (1 + u)^a (1 - u)^(d - a), the coefficient of u^j summed over the
      // ways to take p of the j powers from (1 + u)^a and j - p from (1 - u)^(d - a).
      for (int a = 0; a <= d; ++a)
      {
        for (int j = 0; j <= d; ++j)
        {
          double sum = 0.0;
          for (int p = 0; p <= j && p <= a; ++p)
          {
            const int q = j - p;
            sum += q <= d - a ? Choose(a, p) * Choose(d - a, q) * (q % 2 == 0 ? 1.0 : -1.0) : 0.0;
          }
          this->M[j][a] = Choose(d, a) * sum / double(1 << d);
        }
      }
    }
    else
    {
      // Bernstein: C(d, a) r^a (1 - r)^(d - a) = sum over j >= a of C(d, a) C(d - a, j - a) (-1)^(j - a) r^j.
      for (int a = 0; a <= d; ++a)
      {
        for (int j = a; j <= d; ++j)
        {
          this->M[j][a] = Choose(d, a) * Choose(d - a, j - a) * ((j - a) % 2 == 0 ? 1.0 : -1.0);
        }
      }
    }
  }

  FFD_HOST_DEVICE static constexpr double Choose(int m, int k)
  {
    double c = 1.0;
    for (int i = 1; i <= k; ++i)
    {
      c = c * (m - k + i) / i;
    }
    return c;
  }
};

/// One component of a cell's N^3 control points v (x fastest) with its axis of stride Stride (1, N or N^2) changed
/// to monomials by M (ToMonomials), a compile-time constant, so that its zeros and ones cost nothing.
template <int N, int Stride>
FFD_INLINE void ToMonomialsAlong(const double (&m)[4][4], double (&v)[N * N * N])
{
  FFD_UNROLL
  for (int outer = 0; outer < N * N * N; outer += N * Stride) // the axes above
  {
    FFD_UNROLL
    for (int inner = 0; inner < Stride; ++inner) // the axes below
    {
      double out[N];
      FFD_UNROLL
      for (int j = 0; j < N; ++j)
      {
        double sum = 0.0;
        FFD_UNROLL
        for (int a = 0; a < N; ++a)
        {
          sum += m[j][a] * v[outer + a * Stride + inner];
        }
        out[j] = sum;
      }
      FFD_UNROLL
      for (int j = 0; j < N; ++j)
      {
        v[outer + j * Stride + inner] = out[j];
      }
    }
  }
}

/**
 * Components [componentBegin, componentEnd) of `entry`, that of `cell` in the table of a local basis
 * (FillCellTable()), and its header (the cell's indices) with component 0: the control points of that component
 * (x fastest), changed to monomials along x, then y, then z, in double. The CPU fills a cell's three components in
 * one call, the CUDA backend each in a thread of its own.
 */
template <GridBasis Basis, typename Real>
FFD_INLINE void FillCellEntry(const Real* displacements, const int voxels[3], const int dims[3], const int* cellVoxels,
  const int* cellSupports, int cell, int componentBegin, int componentEnd, Real* entry)
{
  constexpr ToMonomials<Basis> toMonomials{};
  constexpr int N = ToMonomials<Basis>::N;
  int c[3] = { cell % voxels[0], cell / voxels[0] % voxels[1], cell / (voxels[0] * voxels[1]) };
  if (cellVoxels)
  {
    for (int a = 0; a < 3; ++a)
    {
      c[a] = cellVoxels[3 * std::size_t(cell) + a];
    }
  }
  int first[3], count;
  for (int a = 0; a < 3; ++a)
  {
    VoxelSupport(Basis, voxels[a], c[a], first[a], count);
  }
  if (componentBegin == 0)
  {
    for (int u = 0; u < 8; ++u)
    {
      entry[u] = Real(u < 3 ? c[u] : 0);
    }
  }
  const Real* corner = displacements + 3 * (first[0] + dims[0] * (first[1] + dims[1] * first[2]));
  const int* support = cellSupports ? cellSupports + std::size_t(cell) * (N * N * N) : nullptr;
  for (int k = componentBegin; k < componentEnd; ++k)
  {
    double v[N * N * N];
    FFD_UNROLL
    for (int local = 0; local < N * N * N; ++local)
    {
      const int x = local % N, y = local / N % N, z = local / (N * N);
      const Real* value =
        support ? displacements + 3 * std::size_t(support[local]) : corner + 3 * (x + dims[0] * (y + dims[1] * z));
      v[local] = double(value[k]);
    }
    ToMonomialsAlong<N, 1>(toMonomials.M, v);
    ToMonomialsAlong<N, N>(toMonomials.M, v);
    ToMonomialsAlong<N, N * N>(toMonomials.M, v);
    FFD_UNROLL
    for (int i = 0; i < N * N * N; ++i)
    {
      entry[8 + 3 * i + k] = Real(v[i]);
    }
  }
}

/// FillCellTable() for one local basis.
template <GridBasis Basis, typename Real>
FFD_INLINE void FillCellTableOf(const Real* displacements, const int voxels[3], const int dims[3],
  const int* cellVoxels, const int* cellSupports, Real* table, int cellBegin, int cellEnd)
{
  constexpr int stride = CellTableStride(CellDegree(Basis));
  for (int cell = cellBegin; cell < cellEnd; ++cell)
  {
    FillCellEntry<Basis>(
      displacements, voxels, dims, cellVoxels, cellSupports, cell, 0, 3, table + std::size_t(cell) * stride);
  }
}
} // namespace detail

template <typename Real>
FFD_INLINE void FillCellTable(GridBasis basis, const Real* displacements, const int voxels[3], const int dims[3],
  const int* cellVoxels, const int* cellSupports, Real* table, int cellBegin, int cellEnd)
{
  switch (basis)
  {
    case GridBasis::Trilinear:
      return detail::FillCellTableOf<GridBasis::Trilinear>(
        displacements, voxels, dims, cellVoxels, cellSupports, table, cellBegin, cellEnd);
    case GridBasis::TriquadraticBezier:
      return detail::FillCellTableOf<GridBasis::TriquadraticBezier>(
        displacements, voxels, dims, cellVoxels, cellSupports, table, cellBegin, cellEnd);
    case GridBasis::TricubicBezier:
      return detail::FillCellTableOf<GridBasis::TricubicBezier>(
        displacements, voxels, dims, cellVoxels, cellSupports, table, cellBegin, cellEnd);
    case GridBasis::CubicBSpline:
      return detail::FillCellTableOf<GridBasis::CubicBSpline>(
        displacements, voxels, dims, cellVoxels, cellSupports, table, cellBegin, cellEnd);
    case GridBasis::Bernstein: // one cell: no table
      break;
  }
}

/**
 * D of FillCellTable() (a basis of degree Degree) at local coordinates r[g] of the cell whose entry is `entry`, for
 * G lane groups g at once, by Horner's rule, into d[g], and, where dDdr is not null, its derivatives into dDdr[g]:
 * column a is dD/dr[a]. Each coefficient is read (broadcast to the lanes) once for all G groups: the broadcasts
 * are a large part of a cell's cost.
 */
template <int Degree, int G, typename Lane, typename Real>
FFD_INLINE void PowerForm(const Real* entry, const Lane (*r)[3], Vec3<Lane>* d, Mat3<Lane>* dDdr)
{
  constexpr int N = Degree + 1;
  const Real* c = entry + 8;
  Lane out[G][3];
  FFD_UNROLL
  for (int k = 0; k < 3; ++k)
  {
    // Along z, of polynomials along y, of polynomials along x; each with its derivative where asked.
    Lane z[G], zx[G], zy[G], zz[G];
    FFD_UNROLL
    for (int iz = Degree; iz >= 0; --iz)
    {
      Lane y[G], yx[G], yy[G];
      FFD_UNROLL
      for (int iy = Degree; iy >= 0; --iy)
      {
        const Real* row = c + 3 * N * (iy + N * iz) + k;
        Lane x[G], xx[G];
        const Lane top = Lane(row[3 * Degree]);
        FFD_UNROLL
        for (int g = 0; g < G; ++g)
        {
          x[g] = top;
          xx[g] = Lane(0);
        }
        FFD_UNROLL
        for (int ix = Degree - 1; ix >= 0; --ix)
        {
          const Lane coefficient = Lane(row[3 * ix]);
          FFD_UNROLL
          for (int g = 0; g < G; ++g)
          {
            if (dDdr)
            {
              xx[g] = x[g] + r[g][0] * xx[g];
            }
            x[g] = coefficient + r[g][0] * x[g];
          }
        }
        FFD_UNROLL
        for (int g = 0; g < G; ++g)
        {
          if (dDdr)
          {
            yy[g] = iy == Degree ? Lane(0) : y[g] + r[g][1] * yy[g];
            yx[g] = iy == Degree ? xx[g] : xx[g] + r[g][1] * yx[g];
          }
          y[g] = iy == Degree ? x[g] : x[g] + r[g][1] * y[g];
        }
      }
      FFD_UNROLL
      for (int g = 0; g < G; ++g)
      {
        if (dDdr)
        {
          zz[g] = iz == Degree ? Lane(0) : z[g] + r[g][2] * zz[g];
          zx[g] = iz == Degree ? yx[g] : yx[g] + r[g][2] * zx[g];
          zy[g] = iz == Degree ? yy[g] : yy[g] + r[g][2] * zy[g];
        }
        z[g] = iz == Degree ? y[g] : y[g] + r[g][2] * z[g];
      }
    }
    FFD_UNROLL
    for (int g = 0; g < G; ++g)
    {
      out[g][k] = z[g];
      if (dDdr)
      {
        dDdr[g].M[k][0] = zx[g];
        dDdr[g].M[k][1] = zy[g];
        dDdr[g].M[k][2] = zz[g];
      }
    }
  }
  FFD_UNROLL
  for (int g = 0; g < G; ++g)
  {
    d[g] = { out[g][0], out[g][1], out[g][2] };
  }
}

} // namespace ffd

#endif
