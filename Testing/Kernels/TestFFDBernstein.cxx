// SPDX-License-Identifier: BSD-3-Clause
// Bernstein bases (FFDBernstein.h) against the naive float64 reference ffdref::Bernstein, C(n,k) x^k (1-x)^(n-k).

#include "FFDBernstein.h"
#include "FFDKernelTestUtilities.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

namespace
{
using ffdtest::Eps;

FFD_REAL_TYPED_TEST_SUITE(FFDBernsteinTest);

constexpr int MaxDegree = ffd::MaxBernsteinDegree;
constexpr int SamplesPerDegree = 200;

/// Reference derivative from the analytic formula d/dx B_{k,n} = n (B_{k-1,n-1} - B_{k,n-1}).
double ReferenceDerivative(int n, int k, double x)
{
  if (n == 0)
  {
    return 0.0;
  }
  const double left = k > 0 ? ffdref::Bernstein(n - 1, k - 1, x) : 0.0;
  const double right = k < n ? ffdref::Bernstein(n - 1, k, x) : 0.0;
  return n * (left - right);
}

TYPED_TEST(FFDBernsteinTest, ValuesMatchReference)
{
  using Real = TypeParam;
  ffdtest::Rng rng(101);
  // Tolerance: every value relative to itself, 4 (n+1) eps. The de Casteljau triangle forms n convex
  // combinations of non-negative numbers (relative error <= ~2n eps) and the reference's binomial times powers
  // has a relative error of a few n eps in double. Values under a floor (1e6 times the smallest normal number)
  // are compared absolutely: there Real's gradual underflow, not the algorithm, sets the error.
  const double floor = 1e6 * double(std::numeric_limits<Real>::min());
  Real b[MaxDegree + 1];
  for (int n = 0; n <= MaxDegree; ++n)
  {
    const double relTol = 4.0 * (n + 1) * Eps<Real>();
    for (int sample = 0; sample < SamplesPerDegree; ++sample)
    {
      const Real x = Real(ffdtest::Uniform(rng, 0.0, 1.0));
      ffd::BernsteinBasis(n, x, b);
      for (int k = 0; k <= n; ++k)
      {
        const double ref = ffdref::Bernstein(n, k, double(x));
        ASSERT_LE(std::fabs(double(b[k]) - ref), relTol * ref + floor)
          << "n=" << n << " k=" << k << " x=" << x << " got " << b[k] << " want " << ref;
      }
    }
  }
}

TYPED_TEST(FFDBernsteinTest, PartitionOfUnity)
{
  using Real = TypeParam;
  ffdtest::Rng rng(102);
  // Tolerance: |1 - sum_k B_{k,n}(x)| <= 2 (n+1) eps (each value within ~2n eps relative, all positive).
  Real b[MaxDegree + 1];
  for (int n = 0; n <= MaxDegree; ++n)
  {
    for (int sample = 0; sample < SamplesPerDegree; ++sample)
    {
      const Real x = Real(ffdtest::Uniform(rng, 0.0, 1.0));
      ffd::BernsteinBasis(n, x, b);
      double sum = 0.0;
      for (int k = 0; k <= n; ++k)
      {
        ASSERT_GE(b[k], Real(0)) << "n=" << n << " k=" << k << " x=" << x;
        sum += double(b[k]);
      }
      ASSERT_NEAR(sum, 1.0, 2.0 * (n + 1) * Eps<Real>()) << "n=" << n << " x=" << x;
    }
  }
}

TYPED_TEST(FFDBernsteinTest, DerivativeMatchesAnalyticFormula)
{
  using Real = TypeParam;
  ffdtest::Rng rng(103);
  // Tolerance: absolute, 8 n (n+1) eps. The derivative is n times a difference of two degree n-1 values, each
  // within ~2n eps of the reference (values <= 1), so its error is at most ~4 n^2 eps.
  Real b[MaxDegree + 1], db[MaxDegree + 1], bOnly[MaxDegree + 1];
  for (int n = 0; n <= MaxDegree; ++n)
  {
    const double tol = 8.0 * n * (n + 1) * Eps<Real>();
    for (int sample = 0; sample < SamplesPerDegree; ++sample)
    {
      const Real x = Real(ffdtest::Uniform(rng, 0.0, 1.0));
      ffd::BernsteinBasisAndDerivative(n, x, b, db);
      ffd::BernsteinBasis(n, x, bOnly);
      for (int k = 0; k <= n; ++k)
      {
        ASSERT_NEAR(double(db[k]), ReferenceDerivative(n, k, double(x)), tol) << "n=" << n << " k=" << k << " x=" << x;
        // The values that come with the derivative are the basis itself, to the last bit of their reference.
        ASSERT_LE(std::fabs(double(b[k]) - ffdref::Bernstein(n, k, double(x))),
          4.0 * (n + 1) * Eps<Real>() * ffdref::Bernstein(n, k, double(x)) +
            1e6 * double(std::numeric_limits<Real>::min()))
          << "n=" << n << " k=" << k << " x=" << x;
        ASSERT_EQ(b[k], bOnly[k]) << "n=" << n << " k=" << k << " x=" << x;
      }
    }
  }
}

TYPED_TEST(FFDBernsteinTest, DerivativeMatchesCentralDifferences)
{
  using Real = TypeParam;
  ffdtest::Rng rng(104);
  // Central differences of the double reference with h = 1e-6: truncation h^2/6 |B'''| <= 1e-12 n^3 / 6 and
  // rounding eps_double / h ~ 1e-10, both under 1e-7 for n <= 32. Tolerance: absolute,
  // 1e-7 (n+1) + 8 n (n+1) eps(Real) (the second term is the kernel's own rounding, as above).
  const double h = 1e-6;
  Real b[MaxDegree + 1], db[MaxDegree + 1];
  for (int n = 0; n <= MaxDegree; ++n)
  {
    const double tol = 1e-7 * (n + 1) + 8.0 * n * (n + 1) * Eps<Real>();
    for (int sample = 0; sample < SamplesPerDegree / 4; ++sample)
    {
      const Real x = Real(ffdtest::Uniform(rng, h, 1.0 - h));
      ffd::BernsteinBasisAndDerivative(n, x, b, db);
      for (int k = 0; k <= n; ++k)
      {
        const double xd = double(x);
        const double fd = (ffdref::Bernstein(n, k, xd + h) - ffdref::Bernstein(n, k, xd - h)) / (2.0 * h);
        ASSERT_NEAR(double(db[k]), fd, tol) << "n=" << n << " k=" << k << " x=" << x;
      }
    }
  }
}

TYPED_TEST(FFDBernsteinTest, HighDegreeStaysFiniteAndExactAtEnds)
{
  using Real = TypeParam;
  // At the highest degree, in the corners of [0, 1] where naive C(n,k) x^k (1-x)^(n-k) underflows or loses
  // digits: every value and derivative is finite, values lie in [0, 1], and they still sum to one
  // (tolerance 2 (n+1) eps as in PartitionOfUnity). At the ends the basis is exactly the unit vector.
  const int n = MaxDegree;
  const std::vector<Real> xs = { Real(0), Real(1), Real(0.5), std::numeric_limits<Real>::denorm_min(),
    std::numeric_limits<Real>::min(), Real(1e-30), std::numeric_limits<Real>::epsilon(),
    Real(1) - std::numeric_limits<Real>::epsilon(), Real(0.999) };
  Real b[MaxDegree + 1], db[MaxDegree + 1];
  for (Real x : xs)
  {
    ffd::BernsteinBasisAndDerivative(n, x, b, db);
    double sum = 0.0;
    for (int k = 0; k <= n; ++k)
    {
      ASSERT_TRUE(std::isfinite(b[k]) && std::isfinite(db[k])) << "k=" << k << " x=" << x;
      ASSERT_GE(b[k], Real(0)) << "k=" << k << " x=" << x;
      ASSERT_LE(b[k], Real(1)) << "k=" << k << " x=" << x;
      ASSERT_LE(std::fabs(db[k]), Real(n)) << "k=" << k << " x=" << x; // |B'| <= n (B_{k-1} + B_k) <= n
      sum += double(b[k]);
    }
    ASSERT_NEAR(sum, 1.0, 2.0 * (n + 1) * Eps<Real>()) << "x=" << x;
  }
  ffd::BernsteinBasisAndDerivative(n, Real(0), b, db);
  EXPECT_EQ(b[0], Real(1));
  EXPECT_EQ(db[0], Real(-n));
  EXPECT_EQ(db[1], Real(n));
  ffd::BernsteinBasisAndDerivative(n, Real(1), b, db);
  EXPECT_EQ(b[n], Real(1));
  EXPECT_EQ(db[n], Real(n));
  EXPECT_EQ(db[n - 1], Real(-n));
  for (int k = 1; k < n; ++k)
  {
    EXPECT_EQ(b[k], Real(0)) << "k=" << k;
  }
}

} // namespace
