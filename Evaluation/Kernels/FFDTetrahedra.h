// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDTetrahedra.h
 * @brief Tetrahedral FFD (paper section III.E): barycentric weights and the affine map of a tetrahedron,
 * shared by the CPU and CUDA paths.
 *
 * A tetrahedron ABCD is the frame X0 = A, S = B - A, T = C - A, U = D - A, so equation 5, its weights (s, t, u),
 * is equation 2 of that frame (Frame::ToParametric) and a point's fourth weight is 1 - s - t - u. Moving the
 * nodes by dA, dB, dC, dD moves the point by
 *   D(X) = (1 - s - t - u) dA + s dB + t dC + u dD = dA + [dB - dA, dC - dA, dD - dA] d(s,t,u)/dX (X - A),
 * an affine map of X. Evaluation uses that form, TetrahedronMap: the weights are not stored per point but
 * folded, once per update and per tetrahedron, into a gradient G and an offset, so a point costs one 3x3
 * product and the binding one int (the tetrahedron). Its Jacobian I + G is constant in the tetrahedron, so
 * normals follow each tetrahedron's affine map.
 *
 * Displacement form: the rest lattice (all d = 0) gives G = 0 and an exact identity; X - A is taken in the
 * point's precision before the product, so points far from the origin keep their digits.
 */
#ifndef FFDTetrahedra_h
#define FFDTetrahedra_h

#include "FFDFrame.h"

namespace ffd
{

/// The 12 numbers of a tetrahedron's frame, X0 = A, S = B - A, T = C - A, U = D - A (corners of 3 doubles).
inline void TetrahedronFrameArray(
  const double a[3], const double b[3], const double c[3], const double d[3], double frame[12])
{
  for (int i = 0; i < 3; ++i)
  {
    frame[i] = a[i];
    frame[3 + i] = b[i] - a[i];
    frame[6 + i] = c[i] - a[i];
    frame[9 + i] = d[i] - a[i];
  }
}

/// Whether a tetrahedron (rest corners A, B, C, D) has a volume: CheckFrame() of its frame.
inline FrameStatus CheckTetrahedron(const double a[3], const double b[3], const double c[3], const double d[3])
{
  double frame[12];
  TetrahedronFrameArray(a, b, c, d, frame);
  return CheckFrame(frame);
}

/// The frame of a tetrahedron, whose parameters are its weights (equation 5). The caller has checked it with
/// CheckTetrahedron().
inline Frame<double> TetrahedronFrame(const double a[3], const double b[3], const double c[3], const double d[3])
{
  double frame[12];
  TetrahedronFrameArray(a, b, c, d, frame);
  return Frame<double>::FromArray(frame);
}

/**
 * How far inside its tetrahedron a point with weights (s, t, u) lies: the smallest of its four weights. It is
 * >= 0 inside and on the faces, and negative outside, by how much in weight units; a point on a face shared by
 * two tetrahedra has the margin 0 in both (up to rounding), so the binding keeps the larger one.
 */
template <typename Real>
FFD_INLINE Real InsideMargin(const Vec3<Real>& stu)
{
  const Real r = Real(1) - stu.x - stu.y - stu.z;
  const Real a = stu.x < stu.y ? stu.x : stu.y;
  const Real b = stu.z < r ? stu.z : r;
  return a < b ? a : b;
}

/// The displacement of the points of one tetrahedron, D(X) = Offset + Gradient (X - Corner).
template <typename Real>
struct alignas(16 * sizeof(Real)) TetrahedronMap
{
  Vec3<Real> Corner;   ///< rest position of node A
  Vec3<Real> Offset;   ///< displacement of node A
  Mat3<Real> Gradient; ///< dD/dX, constant in the tetrahedron

  FFD_INLINE Vec3<Real> Displacement(const Vec3<Real>& x) const { return Offset + Gradient * (x - Corner); }

  /// X + D(X): the deformed position of a point bound to this tetrahedron (or extrapolated from it).
  FFD_INLINE Vec3<Real> Deform(const Vec3<Real>& x) const { return x + Displacement(x); }

  /// dX_ffd/dX = I + Gradient.
  FFD_INLINE Mat3<Real> Jacobian() const
  {
    Mat3<Real> j = Gradient;
    j.M[0][0] += Real(1);
    j.M[1][1] += Real(1);
    j.M[2][2] += Real(1);
    return j;
  }

  /// The same map rounded to another precision.
  template <typename Other>
  FFD_INLINE TetrahedronMap<Other> As() const
  {
    TetrahedronMap<Other> m;
    m.Corner = { Other(Corner.x), Other(Corner.y), Other(Corner.z) };
    m.Offset = { Other(Offset.x), Other(Offset.y), Other(Offset.z) };
    for (int r = 0; r < 3; ++r)
    {
      for (int c = 0; c < 3; ++c)
      {
        m.Gradient.M[r][c] = Other(Gradient.M[r][c]);
      }
    }
    return m;
  }
};

/**
 * The map of a tetrahedron with rest frame `rest` (TetrahedronFrame()) whose nodes A, B, C, D moved by
 * dA, dB, dC, dD: Gradient = [dB - dA, dC - dA, dD - dA] d(s,t,u)/dX, in double precision.
 */
FFD_INLINE TetrahedronMap<double> MakeTetrahedronMap(const Frame<double>& rest, const Vec3<double>& dA,
  const Vec3<double>& dB, const Vec3<double>& dC, const Vec3<double>& dD)
{
  const Vec3<double> e[3] = { dB - dA, dC - dA, dD - dA };
  const Vec3<double> dual[3] = { rest.DualS, rest.DualT, rest.DualU };
  TetrahedronMap<double> m;
  m.Corner = rest.Origin;
  m.Offset = dA;
  for (int r = 0; r < 3; ++r)
  {
    for (int c = 0; c < 3; ++c)
    {
      m.Gradient.M[r][c] = e[0][r] * dual[0][c] + e[1][r] * dual[1][c] + e[2][r] * dual[2][c];
    }
  }
  return m;
}

/// The deformation of points bound to tetrahedra (the cell is the tetrahedron): a point moves by its
/// tetrahedron's map. It has GridDeformation's interface, so that DeformBoundPoint() and the CUDA kernels serve
/// both lattice kinds.
template <typename Real>
struct TetrahedralDeformation
{
  const TetrahedronMap<Real>* Maps;

  FFD_INLINE Vec3<Real> Deform(const Vec3<Real>& x, int cell) const { return this->Maps[cell].Deform(x); }

  FFD_INLINE Vec3<Real> Deform(const Vec3<Real>& x, int cell, Mat3<Real>& jacobian) const
  {
    const TetrahedronMap<Real>& map = this->Maps[cell];
    jacobian = map.Jacobian();
    return map.Deform(x);
  }
};

/**
 * d(closest point)/dX for a point outside the lattice whose nearest point of the control mesh has weights
 * `stu` in tetrahedron `rest`, and lies on the boundary feature where `tolerance` or fewer of its four weights
 * vanish: on a face the projection onto that face's plane, on an edge onto the edge's line, at a node zero.
 * The Jacobian of a point clamped to the control mesh is I + Gradient times this (CLAMP_TO_EDGE).
 */
inline Mat3<double> ClosestPointGradient(const Frame<double>& rest, const Vec3<double>& stu, double tolerance)
{
  // The nodes whose weight does not vanish span the feature; its directions are their differences.
  const double w[4] = { 1.0 - stu.x - stu.y - stu.z, stu.x, stu.y, stu.z };
  const Vec3<double> nodes[4] = { rest.Origin, rest.Origin + rest.S, rest.Origin + rest.T, rest.Origin + rest.U };
  int kept[4], count = 0;
  for (int i = 0; i < 4; ++i)
  {
    if (w[i] > tolerance)
    {
      kept[count++] = i;
    }
  }
  Mat3<double> p = { { { 0, 0, 0 }, { 0, 0, 0 }, { 0, 0, 0 } } };
  if (count == 2) // an edge: e e^T / |e|^2
  {
    const Vec3<double> e = nodes[kept[1]] - nodes[kept[0]];
    const double ee = Dot(e, e);
    for (int r = 0; r < 3; ++r)
    {
      for (int c = 0; c < 3; ++c)
      {
        p.M[r][c] = e[r] * e[c] / ee;
      }
    }
  }
  else if (count >= 3) // a face (or, by rounding, the inside): I - n n^T / |n|^2
  {
    const Vec3<double> n = Cross(nodes[kept[1]] - nodes[kept[0]], nodes[kept[2]] - nodes[kept[0]]);
    const double nn = Dot(n, n);
    p = Mat3<double>::Identity();
    for (int r = 0; r < 3; ++r)
    {
      for (int c = 0; c < 3; ++c)
      {
        p.M[r][c] -= n[r] * n[c] / nn;
      }
    }
  }
  return p;
}

} // namespace ffd

#endif
