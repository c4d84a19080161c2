// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDFrame.h
 * @brief The lattice frame (X0, S, T, U) and its parameter map (paper equations 1 and 2).
 *
 * A frame is the parallelepiped X = X0 + sS + tT + uU, s, t, u in [0, 1]. Its parameter map inverts that
 * relation with the dual basis of equation 2:
 *   s = (T x U).(X - X0) / ((T x U).S),  t = (S x U).(X - X0) / ((S x U).T),  u = (S x T).(X - X0) / ((S x T).U).
 * The dual vectors are the rows of d(s,t,u)/dX, which the Jacobian of a deformation needs.
 * The 12 numbers of a frame are stored as in the data contract's `FFDFrame` field array: X0, S, T, U.
 */
#ifndef FFDFrame_h
#define FFDFrame_h

#include "FFDVector.h"

#include <cmath>

namespace ffd
{

/// Why a frame cannot be used.
enum class FrameStatus
{
  Valid,
  NonFinite,  ///< a component is NaN or infinite
  ZeroVolume, ///< S, T, U are (nearly) linearly dependent: no inverse parameter map
  OutOfRange, ///< S, T, U are so long or so short that their volume or dual basis is not a finite double
};

/// Relative volume |det(S,T,U)| / (|S||T||U|) under which a frame counts as flat.
constexpr double MinimumRelativeFrameVolume = 1e-12;

/// The dual basis of edges S, T, U (equation 2): the rows of d(s,t,u)/dX, in double precision.
inline void DualBasis(const Vec3<double>& s, const Vec3<double>& t, const Vec3<double>& u, Vec3<double> dual[3])
{
  const Vec3<double> tu = Cross(t, u);
  const Vec3<double> su = Cross(s, u);
  const Vec3<double> st = Cross(s, t);
  dual[0] = (1.0 / Dot(tu, s)) * tu;
  dual[1] = (1.0 / Dot(su, t)) * su;
  dual[2] = (1.0 / Dot(st, u)) * st;
}

/// Checks the 12 numbers X0, S, T, U of a frame. Host only: it runs once per update, not per point.
inline FrameStatus CheckFrame(const double frame[12])
{
  for (int c = 0; c < 12; ++c)
  {
    if (!std::isfinite(frame[c]))
    {
      return FrameStatus::NonFinite;
    }
  }
  const Vec3<double> edges[3] = { Vec3<double>::From(frame + 3), Vec3<double>::From(frame + 6),
    Vec3<double>::From(frame + 9) };
  // Flatness is relative, |det(S,T,U)| / (|S||T||U|): computed on the edges divided by their largest component,
  // so that no product overflows or underflows whatever the frame's size.
  Vec3<double> unit[3];
  for (int e = 0; e < 3; ++e)
  {
    const double largest = std::fmax(std::fabs(edges[e].x), std::fmax(std::fabs(edges[e].y), std::fabs(edges[e].z)));
    if (!(largest > 0.0))
    {
      return FrameStatus::ZeroVolume;
    }
    const Vec3<double> scaled = { edges[e].x / largest, edges[e].y / largest, edges[e].z / largest };
    unit[e] = (1.0 / std::sqrt(Dot(scaled, scaled))) * scaled;
  }
  if (!(std::fabs(Dot(Cross(unit[0], unit[1]), unit[2])) > MinimumRelativeFrameVolume))
  {
    return FrameStatus::ZeroVolume;
  }
  // The parameter map divides by the volume itself: it and the dual basis must be finite doubles.
  Vec3<double> dual[3];
  DualBasis(edges[0], edges[1], edges[2], dual);
  for (const Vec3<double>& d : dual)
  {
    if (!std::isfinite(d.x) || !std::isfinite(d.y) || !std::isfinite(d.z) || (d.x == 0.0 && d.y == 0.0 && d.z == 0.0))
    {
      return FrameStatus::OutOfRange;
    }
  }
  return FrameStatus::Valid;
}

/// What is wrong with a frame of that status, for error messages ("The frame " + ...).
inline const char* DescribeFrameStatus(FrameStatus status)
{
  switch (status)
  {
    case FrameStatus::NonFinite:
      return "has a NaN or infinite component";
    case FrameStatus::ZeroVolume:
      return "has (nearly) zero volume: its edge vectors S, T, U are (nearly) linearly dependent";
    case FrameStatus::OutOfRange:
      return "has edge vectors so long or so short that its volume overflows or underflows double precision: "
             "scale the data towards unit size";
    case FrameStatus::Valid:
      break;
  }
  return "is valid";
}

/// Half-width, in parameter units, of the band around the frame's faces that still counts as inside.
template <typename Real>
FFD_INLINE Real ParametricTolerance()
{
  return sizeof(Real) >= sizeof(double) ? Real(1e-10) : Real(1e-5);
}

template <typename Real>
struct Frame
{
  Vec3<Real> Origin, S, T, U;     ///< X = Origin + s S + t T + u U
  Vec3<Real> DualS, DualT, DualU; ///< rows of d(s,t,u)/dX (equation 2)

  /// Builds the frame and its dual basis in double precision, then rounds to Real.
  /// The caller has checked the numbers with CheckFrame().
  static Frame FromArray(const double f[12])
  {
    Vec3<double> dual[3];
    DualBasis(Vec3<double>::From(f + 3), Vec3<double>::From(f + 6), Vec3<double>::From(f + 9), dual);
    return { Vec3<Real>::From(f), Vec3<Real>::From(f + 3), Vec3<Real>::From(f + 6), Vec3<Real>::From(f + 9),
      Vec3<Real>::From(&dual[0].x), Vec3<Real>::From(&dual[1].x), Vec3<Real>::From(&dual[2].x) };
  }

  /// Equation 2: (s, t, u) of a point.
  FFD_INLINE Vec3<Real> ToParametric(const Vec3<Real>& x) const
  {
    const Vec3<Real> d = x - Origin;
    return { Dot(DualS, d), Dot(DualT, d), Dot(DualU, d) };
  }

  /// The lattice space X(s, t, u) = X0 + sS + tT + uU.
  FFD_INLINE Vec3<Real> ToWorld(const Vec3<Real>& p) const { return Origin + p.x * S + p.y * T + p.z * U; }

  /// d(s,t,u)/dX as a matrix whose rows are the dual vectors.
  FFD_INLINE Mat3<Real> ParametricGradient() const { return Mat3<Real>::FromRows(DualS, DualT, DualU); }

  /**
   * Binds a point to the frame: its parameters, clamped to [0, 1], and true when it lies inside the frame or
   * within ParametricTolerance() of it. Points on a face or corner are inside even where rounding puts them a
   * hair outside. False for points outside and for non-finite points (every comparison with NaN fails).
   */
  FFD_INLINE bool Bind(const Vec3<Real>& x, Vec3<Real>& stu) const
  {
    stu = ToParametric(x);
    const Real lo = -ParametricTolerance<Real>();
    const Real hi = Real(1) + ParametricTolerance<Real>();
    if (!(stu.x >= lo && stu.x <= hi && stu.y >= lo && stu.y <= hi && stu.z >= lo && stu.z <= hi))
    {
      return false;
    }
    stu = { Clamp01(stu.x), Clamp01(stu.y), Clamp01(stu.z) };
    return true;
  }

  /// The same frame in another number type: a Lanes type (FFDLanes.h), to evaluate several points at once.
  template <typename Other>
  Frame<Other> As() const
  {
    return { Convert<Other>(Origin), Convert<Other>(S), Convert<Other>(T), Convert<Other>(U), Convert<Other>(DualS),
      Convert<Other>(DualT), Convert<Other>(DualU) };
  }

private:
  template <typename Other>
  static Vec3<Other> Convert(const Vec3<Real>& v)
  {
    return { Other(v.x), Other(v.y), Other(v.z) };
  }
};

} // namespace ffd

#endif
