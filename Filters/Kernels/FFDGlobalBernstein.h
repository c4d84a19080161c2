// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDGlobalBernstein.h
 * @brief The global Sederberg-Parry FFD (paper equation 3) and its analytic Jacobian.
 *
 * A global lattice of degree (l, m, n) holds (l+1)(m+1)(n+1) control values in VTK structured order: value
 * (i, j, k) is at index i + (l+1) * (j + (m+1) * k), three Reals (x, y, z) each. Equation 3 is linear in those
 * values, so one function evaluates both the positions P_ijk and the displacements D_ijk = P_ijk - P_ijk^rest.
 *
 * The deformation is applied in displacement form, X_ffd = X + sum B_i B_j B_k D_ijk, which equals equation 3
 * because the Bernstein basis reproduces the rest lattice's affine map exactly (linear precision). It keeps
 * the rest lattice an exact identity and loses no precision to points far from the origin.
 */
#ifndef FFDGlobalBernstein_h
#define FFDGlobalBernstein_h

#include "FFDBernstein.h"
#include "FFDFrame.h"

namespace ffd
{

/// Equation 3: sum_ijk B_{i,l}(s) B_{j,m}(t) B_{k,n}(u) V_ijk, with dims = (l+1, m+1, n+1).
template <typename Real>
FFD_INLINE Vec3<Real> EvaluateBernstein(const Real* values, const int dims[3], const Vec3<Real>& stu)
{
  Real bs[MaxBernsteinDegree + 1], bt[MaxBernsteinDegree + 1], bu[MaxBernsteinDegree + 1];
  BernsteinBasis(dims[0] - 1, stu.x, bs);
  BernsteinBasis(dims[1] - 1, stu.y, bt);
  BernsteinBasis(dims[2] - 1, stu.z, bu);

  Vec3<Real> sum = { 0, 0, 0 };
  const Real* v = values;
  for (int k = 0; k < dims[2]; ++k)
  {
    Vec3<Real> sumJ = { 0, 0, 0 };
    for (int j = 0; j < dims[1]; ++j)
    {
      Vec3<Real> sumI = { 0, 0, 0 };
      for (int i = 0; i < dims[0]; ++i, v += 3)
      {
        sumI = sumI + bs[i] * Vec3<Real>{ v[0], v[1], v[2] };
      }
      sumJ = sumJ + bt[j] * sumI;
    }
    sum = sum + bu[k] * sumJ;
  }
  return sum;
}

/**
 * Equation 3 and its derivatives with respect to (s, t, u): returns the sum and sets gradient's columns to
 * d/ds, d/dt and d/du of it.
 */
template <typename Real>
FFD_INLINE Vec3<Real> EvaluateBernsteinWithGradient(
  const Real* values, const int dims[3], const Vec3<Real>& stu, Mat3<Real>& gradient)
{
  Real bs[MaxBernsteinDegree + 1], bt[MaxBernsteinDegree + 1], bu[MaxBernsteinDegree + 1];
  Real ds[MaxBernsteinDegree + 1], dt[MaxBernsteinDegree + 1], du[MaxBernsteinDegree + 1];
  BernsteinBasisAndDerivative(dims[0] - 1, stu.x, bs, ds);
  BernsteinBasisAndDerivative(dims[1] - 1, stu.y, bt, dt);
  BernsteinBasisAndDerivative(dims[2] - 1, stu.z, bu, du);

  const Vec3<Real> zero = { 0, 0, 0 };
  Vec3<Real> sum = zero, sumS = zero, sumT = zero, sumU = zero;
  const Real* v = values;
  for (int k = 0; k < dims[2]; ++k)
  {
    Vec3<Real> valJ = zero, valJS = zero, valJT = zero;
    for (int j = 0; j < dims[1]; ++j)
    {
      Vec3<Real> valI = zero, valIS = zero;
      for (int i = 0; i < dims[0]; ++i, v += 3)
      {
        const Vec3<Real> p = { v[0], v[1], v[2] };
        valI = valI + bs[i] * p;
        valIS = valIS + ds[i] * p;
      }
      valJ = valJ + bt[j] * valI;
      valJS = valJS + bt[j] * valIS;
      valJT = valJT + dt[j] * valI;
    }
    sum = sum + bu[k] * valJ;
    sumS = sumS + bu[k] * valJS;
    sumT = sumT + bu[k] * valJT;
    sumU = sumU + du[k] * valJ;
  }
  gradient = { { { sumS.x, sumT.x, sumU.x }, { sumS.y, sumT.y, sumU.y }, { sumS.z, sumT.z, sumU.z } } };
  return sum;
}

/**
 * dX_ffd/dX of the displacement form X_ffd = X + D(s(X), t(X), u(X)): I + dD/d(s,t,u) * d(s,t,u)/dX, where
 * displacementGradient comes from EvaluateBernsteinWithGradient() over the displacements.
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

} // namespace ffd

#endif
