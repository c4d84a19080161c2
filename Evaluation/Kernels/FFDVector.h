// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDVector.h
 * @brief Minimal 3-vector and 3x3 matrix types for the FFD kernels (host and device).
 */
#ifndef FFDVector_h
#define FFDVector_h

#include "FFDHostDevice.h"

#include <cmath>

namespace ffd
{

/// v clamped to [0, 1]; NaN stays NaN. Number types of several lanes (FFDLanes.h) overload it.
template <typename Real>
FFD_INLINE Real Clamp01(Real v)
{
  return v < Real(0) ? Real(0) : (v > Real(1) ? Real(1) : v);
}

/// True where lo <= v <= hi (false for NaN). Number types of several lanes overload it with a lane mask, and
/// KeepWhere() and Choose() with it, so that the kernels branch on such conditions the same way in every lane.
template <typename Real>
FFD_INLINE bool InRange(Real v, Real lo, Real hi)
{
  return v >= lo && v <= hi;
}

/// v where `keep`, else 0.
template <typename Real>
FFD_INLINE Real KeepWhere(bool keep, Real v)
{
  return keep ? v : Real(0);
}

/// True where v > 0.
template <typename Real>
FFD_INLINE bool IsPositive(Real v)
{
  return v > Real(0);
}

/// a where `condition`, else b.
template <typename Real>
FFD_INLINE Real Choose(bool condition, Real a, Real b)
{
  return condition ? a : b;
}

/// The number type of one lane of Real (Real itself, but for the Lanes types of FFDLanes.h).
template <typename Real>
struct ScalarOf
{
  using Type = Real;
};

template <typename Real>
struct Vec3
{
  Real x, y, z;

  FFD_INLINE Real operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  template <typename Other>
  FFD_INLINE static Vec3 From(const Other* p)
  {
    return { static_cast<Real>(p[0]), static_cast<Real>(p[1]), static_cast<Real>(p[2]) };
  }
};

template <typename Real>
FFD_INLINE Vec3<Real> operator+(const Vec3<Real>& a, const Vec3<Real>& b)
{
  return { a.x + b.x, a.y + b.y, a.z + b.z };
}

template <typename Real>
FFD_INLINE Vec3<Real> operator-(const Vec3<Real>& a, const Vec3<Real>& b)
{
  return { a.x - b.x, a.y - b.y, a.z - b.z };
}

template <typename Real>
FFD_INLINE Vec3<Real> operator*(Real s, const Vec3<Real>& a)
{
  return { s * a.x, s * a.y, s * a.z };
}

template <typename Real>
FFD_INLINE Real Dot(const Vec3<Real>& a, const Vec3<Real>& b)
{
  return a.x * b.x + a.y * b.y + a.z * b.z;
}

template <typename Real>
FFD_INLINE Vec3<Real> Cross(const Vec3<Real>& a, const Vec3<Real>& b)
{
  return { a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x };
}

/// Row-major 3x3 matrix: M[r][c].
template <typename Real>
struct Mat3
{
  Real M[3][3];

  FFD_INLINE static Mat3 Identity() { return { { { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 } } }; }
  FFD_INLINE static Mat3 FromRows(const Vec3<Real>& r0, const Vec3<Real>& r1, const Vec3<Real>& r2)
  {
    return { { { r0.x, r0.y, r0.z }, { r1.x, r1.y, r1.z }, { r2.x, r2.y, r2.z } } };
  }
};

template <typename Real>
FFD_INLINE Vec3<Real> operator*(const Mat3<Real>& a, const Vec3<Real>& v)
{
  return { a.M[0][0] * v.x + a.M[0][1] * v.y + a.M[0][2] * v.z, a.M[1][0] * v.x + a.M[1][1] * v.y + a.M[1][2] * v.z,
    a.M[2][0] * v.x + a.M[2][1] * v.y + a.M[2][2] * v.z };
}

template <typename Real>
FFD_INLINE Mat3<Real> operator*(const Mat3<Real>& a, const Mat3<Real>& b)
{
  Mat3<Real> c{};
  for (int r = 0; r < 3; ++r)
  {
    for (int k = 0; k < 3; ++k)
    {
      c.M[r][k] = a.M[r][0] * b.M[0][k] + a.M[r][1] * b.M[1][k] + a.M[r][2] * b.M[2][k];
    }
  }
  return c;
}

template <typename Real>
FFD_INLINE Real Determinant(const Mat3<Real>& a)
{
  return a.M[0][0] * (a.M[1][1] * a.M[2][2] - a.M[1][2] * a.M[2][1]) -
    a.M[0][1] * (a.M[1][0] * a.M[2][2] - a.M[1][2] * a.M[2][0]) +
    a.M[0][2] * (a.M[1][0] * a.M[2][1] - a.M[1][1] * a.M[2][0]);
}

/**
 * Cofactor matrix, det(A) * A^-T. Normals are transformed by it rather than by A^-T: both give the same
 * direction where det(A) > 0, the cofactor also exists where A is singular, and it is what the cross product of
 * two deformed tangents gives, so transformed normals agree with normals recomputed from the deformed surface
 * even where the deformation folds (det(A) < 0).
 */
template <typename Real>
FFD_INLINE Mat3<Real> Cofactor(const Mat3<Real>& a)
{
  Mat3<Real> c;
  c.M[0][0] = a.M[1][1] * a.M[2][2] - a.M[1][2] * a.M[2][1];
  c.M[0][1] = a.M[1][2] * a.M[2][0] - a.M[1][0] * a.M[2][2];
  c.M[0][2] = a.M[1][0] * a.M[2][1] - a.M[1][1] * a.M[2][0];
  c.M[1][0] = a.M[0][2] * a.M[2][1] - a.M[0][1] * a.M[2][2];
  c.M[1][1] = a.M[0][0] * a.M[2][2] - a.M[0][2] * a.M[2][0];
  c.M[1][2] = a.M[0][1] * a.M[2][0] - a.M[0][0] * a.M[2][1];
  c.M[2][0] = a.M[0][1] * a.M[1][2] - a.M[0][2] * a.M[1][1];
  c.M[2][1] = a.M[0][2] * a.M[1][0] - a.M[0][0] * a.M[1][2];
  c.M[2][2] = a.M[0][0] * a.M[1][1] - a.M[0][1] * a.M[1][0];
  return c;
}

/**
 * A unit normal carried by the deformation: the cofactor of the Jacobian times it (see Cofactor()),
 * renormalized; unchanged where that product vanishes.
 */
template <typename Real>
FFD_INLINE Vec3<Real> TransformNormal(const Mat3<Real>& jacobian, const Vec3<Real>& normal)
{
  using std::sqrt; // or the Lanes overload
  const Vec3<Real> m = Cofactor(jacobian) * normal;
  const Real length = sqrt(Dot(m, m));
  const auto positive = IsPositive(length);
  const Real scale = Real(1) / length;
  return { Choose(positive, scale * m.x, normal.x), Choose(positive, scale * m.y, normal.y),
    Choose(positive, scale * m.z, normal.z) };
}

} // namespace ffd

#endif
