// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDBernstein.h
 * @brief Bernstein polynomials of any degree up to MaxBernsteinDegree, and their derivatives.
 *
 * B_{k,n}(x) = C(n,k) x^k (1-x)^(n-k). They are computed with the de Casteljau triangle
 * B_{k,j} = (1-x) B_{k,j-1} + x B_{k-1,j-1}, which for x in [0, 1] only ever forms convex combinations of
 * non-negative numbers: no binomial coefficient overflows and no cancellation occurs, whatever the degree.
 * B'_{k,n}(x) = n (B_{k-1,n-1}(x) - B_{k,n-1}(x)) comes out of the same triangle one row early.
 */
#ifndef FFDBernstein_h
#define FFDBernstein_h

#include "FFDHostDevice.h"

namespace ffd
{

/// Highest degree per axis. Stack arrays of this size hold the basis on both CPU and GPU; a global lattice of
/// 33 control points per axis (35 937 in all) is already far past what a global FFD is useful for.
constexpr int MaxBernsteinDegree = 32;

namespace detail
{
/// Raises b[0..j-1], the basis of degree j-1, to degree j in place.
template <typename Real>
FFD_INLINE void BernsteinRaise(int j, Real x, Real* b)
{
  const Real y = Real(1) - x;
  Real carry = Real(0);
  FFD_UNROLL
  for (int k = 0; k < j; ++k)
  {
    const Real v = b[k];
    b[k] = carry + y * v;
    carry = x * v;
  }
  b[j] = carry;
}
} // namespace detail

/// b[k] = B_{k,n}(x) for k = 0..n.
template <typename Real>
FFD_INLINE void BernsteinBasis(int n, Real x, Real* b)
{
  b[0] = Real(1);
  for (int j = 1; j <= n; ++j)
  {
    detail::BernsteinRaise(j, x, b);
  }
}

/**
 * BernsteinBasis() for degrees n < MaxCount, with every loop bounded at compile time so that a GPU keeps the
 * MaxCount entries of b in registers.
 */
template <int MaxCount, typename Real>
FFD_INLINE void BernsteinBasisBounded(int n, Real x, Real* b)
{
  b[0] = Real(1);
  FFD_UNROLL
  for (int j = 1; j < MaxCount; ++j)
  {
    if (j > n)
    {
      break;
    }
    detail::BernsteinRaise(j, x, b);
  }
}

/// b[k] = B_{k,n}(x) and db[k] = d/dx B_{k,n}(x) for k = 0..n.
template <typename Real>
FFD_INLINE void BernsteinBasisAndDerivative(int n, Real x, Real* b, Real* db)
{
  if (n == 0)
  {
    b[0] = Real(1);
    db[0] = Real(0);
    return;
  }
  BernsteinBasis(n - 1, x, b);
  const Real rn = Real(n);
  db[0] = -rn * b[0];
  for (int k = 1; k < n; ++k)
  {
    db[k] = rn * (b[k - 1] - b[k]);
  }
  db[n] = rn * b[n - 1];
  detail::BernsteinRaise(n, x, b);
}

} // namespace ffd

#endif
