// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDInverse.h
 * @brief The rest position of a deformed point: Newton's method on the deformation itself, for every lattice
 * kind whose deformation gives its Jacobian.
 */
#ifndef FFDInverse_h
#define FFDInverse_h

#include "FFDVector.h"

namespace ffd
{

/// How the inversion of one point ended.
enum class InverseStatus : unsigned char
{
  Converged = 0,   ///< |F(x) - y| is within the tolerance
  Folded = 1,      ///< det J <= 0 at an iterate: the deformation folds there and Newton has no direction
  NotConverged = 2 ///< no step along Newton's direction lowered the residual, or the iterations ran out
};

/**
 * Finds x with F(x) = y, where F(x) = deformation.Deform(x, cell, J) for x's cell = bind(x) and F(x) = x (J = I)
 * where bind(x) is -1, by Newton's method with a backtracking line search: the step J^-1 (y - F(x)) is halved
 * until the residual |F(x) - y| decreases (vtkWarpTransform's inverse does the same). Each iterate is bound
 * again, so the search crosses cells. The first guess is y minus the displacement at y (exact for a translation).
 * `x` is the best point found and `jacobian` J there. Converged once the residual is at most `tolerance` where
 * det J > 0; Folded where det J <= 0 there or on the way (a folded region has several rest positions).
 */
template <typename Deformation, typename Bind>
FFD_INLINE InverseStatus InvertPoint(const Deformation& deformation, const Bind& bind, const Vec3<double>& y,
  double tolerance, int maxIterations, Vec3<double>& x, Mat3<double>& jacobian)
{
  using std::sqrt;
  const auto residual = [&](const Vec3<double>& p, Mat3<double>& j)
  {
    const int cell = bind(p);
    j = Mat3<double>::Identity();
    return (cell >= 0 ? deformation.Deform(p, cell, j) : p) - y;
  };
  x = y - residual(y, jacobian);
  Vec3<double> r = residual(x, jacobian);
  double error = sqrt(Dot(r, r));
  for (int iteration = 0;; ++iteration)
  {
    const double det = Determinant(jacobian);
    if (!(det > 0))
    {
      return InverseStatus::Folded;
    }
    if (error <= tolerance)
    {
      return InverseStatus::Converged;
    }
    if (iteration == maxIterations)
    {
      return InverseStatus::NotConverged;
    }
    // J^-1 = Cofactor(J)^T / det J.
    const Mat3<double> c = Cofactor(jacobian);
    const Vec3<double> step = (-1.0 / det) *
      Vec3<double>{ c.M[0][0] * r.x + c.M[1][0] * r.y + c.M[2][0] * r.z,
        c.M[0][1] * r.x + c.M[1][1] * r.y + c.M[2][1] * r.z, c.M[0][2] * r.x + c.M[1][2] * r.y + c.M[2][2] * r.z };
    bool lowered = false;
    double t = 1;
    for (int halving = 0; halving < 40 && !lowered; ++halving, t *= 0.5)
    {
      Mat3<double> j;
      const Vec3<double> candidate = x + t * step;
      const Vec3<double> rc = residual(candidate, j);
      const double e = sqrt(Dot(rc, rc));
      if (e < error)
      {
        x = candidate;
        r = rc;
        jacobian = j;
        error = e;
        lowered = true;
      }
    }
    if (!lowered)
    {
      return InverseStatus::NotConverged;
    }
  }
}

} // namespace ffd

#endif
