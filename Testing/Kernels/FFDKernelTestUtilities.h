// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDKernelTestUtilities.h
 * @brief Random inputs shared by the kernel tests: frames, points and conversions between the reference's
 * double arrays (ffdref::) and the kernels' types (ffd::). No VTK, plain C++17 (also built by nvcc).
 */
#ifndef FFDKernelTestUtilities_h
#define FFDKernelTestUtilities_h

#include "FFDReference.h"
#include "FFDVector.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace ffdtest
{
using Rng = std::mt19937;

/// Machine epsilon of Real, as a double.
template <typename Real>
constexpr double Eps()
{
  return static_cast<double>(std::numeric_limits<Real>::epsilon());
}

inline double Uniform(Rng& rng, double lo, double hi)
{
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}

inline ffdref::Vec RandomVec(Rng& rng, double lo, double hi)
{
  return { Uniform(rng, lo, hi), Uniform(rng, lo, hi), Uniform(rng, lo, hi) };
}

inline double Norm(const ffdref::Vec& a)
{
  return std::sqrt(ffdref::Dot(a, a));
}

inline double MaxAbs(const ffdref::Vec& a)
{
  return std::max({ std::fabs(a[0]), std::fabs(a[1]), std::fabs(a[2]) });
}

/// |det(S,T,U)| / (|S||T||U|): 1 for a box, 0 for a flat frame.
inline double RelativeVolume(const ffdref::Frame& f)
{
  return std::fabs(ffdref::Dot(ffdref::Cross(f.S, f.T), f.U)) / (Norm(f.S) * Norm(f.T) * Norm(f.U));
}

/**
 * A random non-orthogonal parallelepiped near the origin: X0 in [-1, 1]^3, edges of random direction and
 * length in [0.5, 2], rejected until its relative volume is at least 0.2 (so its parameter map is well
 * conditioned and the tolerances below need no condition number). Edges are never orthogonal in practice.
 */
inline ffdref::Frame RandomFrame(Rng& rng)
{
  const auto edge = [&rng]() {
    ffdref::Vec d;
    do
    {
      d = RandomVec(rng, -1.0, 1.0);
    } while (Norm(d) < 0.1);
    const double scale = Uniform(rng, 0.5, 2.0) / Norm(d);
    return ffdref::Vec{ scale * d[0], scale * d[1], scale * d[2] };
  };
  ffdref::Frame f;
  do
  {
    f = { RandomVec(rng, -1.0, 1.0), edge(), edge(), edge() };
  } while (RelativeVolume(f) < 0.2);
  return f;
}

/// The frame's 12 numbers in the data contract's order: X0, S, T, U.
inline void FrameToArray(const ffdref::Frame& f, double a[12])
{
  for (int c = 0; c < 3; ++c)
  {
    a[c] = f.X0[c];
    a[3 + c] = f.S[c];
    a[6 + c] = f.T[c];
    a[9 + c] = f.U[c];
  }
}

/// X0 + sS + tT + uU, in double.
inline ffdref::Vec ToWorld(const ffdref::Frame& f, const ffdref::Vec& stu)
{
  ffdref::Vec x;
  for (int c = 0; c < 3; ++c)
  {
    x[c] = f.X0[c] + stu[0] * f.S[c] + stu[1] * f.T[c] + stu[2] * f.U[c];
  }
  return x;
}

/// Rounds a double vector to Real, as a caller holding Real data would pass it.
template <typename Real>
ffd::Vec3<Real> ToKernel(const ffdref::Vec& v)
{
  return ffd::Vec3<Real>::From(v.data());
}

template <typename Real>
ffdref::Vec ToRef(const ffd::Vec3<Real>& v)
{
  return { double(v.x), double(v.y), double(v.z) };
}

/// The values the kernels read (x, y, z per control point, VTK order), rounded to Real.
template <typename Real>
std::vector<Real> Flatten(const std::vector<ffdref::Vec>& points)
{
  std::vector<Real> values;
  values.reserve(3 * points.size());
  for (const ffdref::Vec& p : points)
  {
    values.insert(values.end(), { Real(p[0]), Real(p[1]), Real(p[2]) });
  }
  return values;
}

/// The lattice the kernel actually sees: each coordinate rounded to Real, back in double for the reference.
template <typename Real>
std::vector<ffdref::Vec> RoundLattice(const std::vector<ffdref::Vec>& points)
{
  std::vector<ffdref::Vec> rounded;
  rounded.reserve(points.size());
  for (const ffdref::Vec& p : points)
  {
    rounded.push_back({ double(Real(p[0])), double(Real(p[1])), double(Real(p[2])) });
  }
  return rounded;
}

/// max_ijk ||P_ijk||_inf: the normalisation of the evaluation tests' errors.
inline double LatticeScale(const std::vector<ffdref::Vec>& points)
{
  double scale = 0.0;
  for (const ffdref::Vec& p : points)
  {
    scale = std::max(scale, MaxAbs(p));
  }
  return scale;
}

} // namespace ffdtest

#endif
