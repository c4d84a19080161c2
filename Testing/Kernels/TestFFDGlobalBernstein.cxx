// SPDX-License-Identifier: BSD-3-Clause
// The global FFD (the Bernstein case of FFDGridBasis.h and FFDGridDeformation.h, paper equation 3) and its
// Jacobian against the float64 reference ffdref:: (binomials times powers, absolute control points, equation 2
// by Cramer's rule).
//
// Normalisation of errors: an evaluation error is divided by the lattice's scale, max_ijk ||P_ijk||_inf (the
// half-size of the smallest origin-centred cube holding the lattice). The random frames sit near the origin
// (X0 in [-1, 1]^3, edges 0.5..2), so this is the lattice's extent to within a small factor, and it is the
// size of the numbers the evaluation rounds: equation 3 is a convex combination of the P_ijk.

#include "FFDGridDeformation.h"
#include "FFDKernelTestUtilities.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

namespace
{
using ffdref::Vec;
using ffdtest::Eps;
using ffdtest::EvaluationTolerance;
using ffdtest::GradientTolerance;
using ffdtest::MaxAbs;
using ffdtest::WorstRatio;

// Equation 3 through the kernels: the global basis is one cell of degree dims - 1 per axis.
template <typename Real>
void GlobalWeights(const int dims[3], const ffd::Vec3<Real>& stu, bool withDerivative,
  ffd::AxisWeights<ffd::MaxBernsteinDegree + 1, Real>* axes)
{
  const Real p[3] = { stu.x, stu.y, stu.z };
  for (int a = 0; a < 3; ++a)
  {
    ffd::ComputeAxisWeights(ffd::GridBasis::Bernstein, dims[a] - 1, 0, p[a], withDerivative, axes[a]);
  }
}

template <typename Real>
ffd::Vec3<Real> EvaluateBernstein(const Real* values, const int dims[3], const ffd::Vec3<Real>& stu)
{
  ffd::AxisWeights<ffd::MaxBernsteinDegree + 1, Real> axes[3];
  GlobalWeights(dims, stu, false, axes);
  return ffd::SumTensorProduct(values, dims, axes);
}

template <typename Real>
ffd::Vec3<Real> EvaluateBernsteinWithGradient(
  const Real* values, const int dims[3], const ffd::Vec3<Real>& stu, ffd::Mat3<Real>& gradient)
{
  ffd::AxisWeights<ffd::MaxBernsteinDegree + 1, Real> axes[3];
  GlobalWeights(dims, stu, true, axes);
  return ffd::SumTensorProductWithGradient(values, dims, axes, gradient);
}

FFD_REAL_TYPED_TEST_SUITE(FFDGlobalBernsteinTest);

/// A lattice of degree (l, m, n) over a frame: its rest positions and its (moved) control points.
struct Lattice
{
  ffdref::Frame F;
  int L, M, N;
  std::vector<Vec> Rest, Points;
  std::array<int, 3> Dims() const { return { L + 1, M + 1, N + 1 }; }
  std::string Name() const
  {
    return "degree (" + std::to_string(L) + "," + std::to_string(M) + "," + std::to_string(N) + ")";
  }
};

/**
 * Random degree per axis in 1..6 for the first cases, then some larger ones (up to the kernels' maximum);
 * control points displaced from rest by up to 0.3 in each coordinate (the frames' edges are 0.5..2 long).
 */
std::vector<Lattice> RandomLattices(ffdtest::Rng& rng, int count)
{
  const std::vector<std::array<int, 3>> larger = { { 12, 1, 3 }, { 9, 9, 9 }, { 20, 2, 5 },
    { ffd::MaxBernsteinDegree, 3, 1 } };
  std::vector<Lattice> lattices;
  for (int c = 0; c < count + int(larger.size()); ++c)
  {
    Lattice lat;
    lat.F = ffdtest::RandomFrame(rng);
    std::uniform_int_distribution<int> degree(1, 6);
    const std::array<int, 3> d =
      c < count ? std::array<int, 3>{ degree(rng), degree(rng), degree(rng) } : larger[c - count];
    lat.L = d[0];
    lat.M = d[1];
    lat.N = d[2];
    lat.Rest = ffdref::RestLattice(lat.F, lat.L, lat.M, lat.N);
    for (const Vec& p : lat.Rest)
    {
      const Vec d3 = ffdtest::RandomVec(rng, -0.3, 0.3);
      lat.Points.push_back({ p[0] + d3[0], p[1] + d3[1], p[2] + d3[2] });
    }
    lattices.push_back(std::move(lat));
  }
  return lattices;
}

/// P - rest: the displacements the filter evaluates, in double (rounded to Real by ffdtest::Flatten).
std::vector<Vec> Displacements(const Lattice& lat)
{
  std::vector<Vec> d;
  for (size_t i = 0; i < lat.Points.size(); ++i)
  {
    d.push_back(ffdref::Sub(lat.Points[i], lat.Rest[i]));
  }
  return d;
}

TYPED_TEST(FFDGlobalBernsteinTest, RestLatticeReproducesFrame)
{
  // Partition of unity and linear precision: with the rest lattice's absolute positions as values,
  // equation 3 is X0 + sS + tT + uU. Tolerance: EvaluationTolerance() times the lattice scale.
  using Real = TypeParam;
  ffdtest::Rng rng(301);
  WorstRatio worst("worst_error_over_tolerance");
  for (const Lattice& lat : RandomLattices(rng, 40))
  {
    const std::vector<Real> values = ffdtest::Flatten<Real>(lat.Rest);
    const double tol = EvaluationTolerance<Real>() * ffdtest::LatticeScale(lat.Rest);
    for (int p = 0; p < 50; ++p)
    {
      const ffd::Vec3<Real> stu = ffdtest::ToKernel<Real>(ffdtest::RandomVec(rng, 0.0, 1.0));
      const Vec got = ffdtest::ToRef(EvaluateBernstein(values.data(), lat.Dims().data(), stu));
      const Vec want = ffdtest::ToWorld(lat.F, ffdtest::ToRef(stu));
      ASSERT_TRUE(ffdtest::MaxDiffWithin(got, want, tol, &worst)) << lat.Name() << " point " << p;
    }
  }
}

TYPED_TEST(FFDGlobalBernsteinTest, AffineMapIsReproduced)
{
  // A lattice moved by an affine map x -> A x + b deforms every point by that map, in both forms: equation 3
  // over absolute positions at the lattice nodes' parameters and at random ones, and the displacement form
  // X + sum B D at random points X of the frame. Tolerance: EvaluationTolerance() times the scale of the
  // mapped lattice (max |A P + b|), plus |X| in that scale for the displacement form (X + D rounds at that
  // size; the same target covers the frame's rounding to Real, see DisplacementFormMatchesDeform).
  using Real = TypeParam;
  ffdtest::Rng rng(302);
  WorstRatio worst("worst_error_over_tolerance");
  for (const Lattice& lat : RandomLattices(rng, 30))
  {
    const ffdtest::Affine map = ffdtest::RandomAffine(rng, 0.5);
    std::vector<Vec> mapped, displacement;
    for (const Vec& p : lat.Rest)
    {
      mapped.push_back(map(p));
      displacement.push_back(ffdref::Sub(mapped.back(), p));
    }
    const std::vector<Real> values = ffdtest::Flatten<Real>(mapped);
    const std::vector<Real> dvalues = ffdtest::Flatten<Real>(displacement);
    const double scale = ffdtest::LatticeScale(mapped);
    const double tol = EvaluationTolerance<Real>() * scale;

    // Absolute form, at every node's parameters (i/l, j/m, k/n) and at random parameters.
    std::vector<Vec> params;
    for (int k = 0; k <= lat.N; ++k)
      for (int j = 0; j <= lat.M; ++j)
        for (int i = 0; i <= lat.L; ++i)
          params.push_back({ double(i) / lat.L, double(j) / lat.M, double(k) / lat.N });
    for (int p = 0; p < 50; ++p)
    {
      params.push_back(ffdtest::RandomVec(rng, 0.0, 1.0));
    }
    for (const Vec& stu : params)
    {
      const ffd::Vec3<Real> s = ffdtest::ToKernel<Real>(stu);
      const Vec got = ffdtest::ToRef(EvaluateBernstein(values.data(), lat.Dims().data(), s));
      const Vec want = map(ffdtest::ToWorld(lat.F, ffdtest::ToRef(s)));
      ASSERT_TRUE(ffdtest::MaxDiffWithin(got, want, tol, &worst))
        << lat.Name() << " at (" << stu[0] << "," << stu[1] << "," << stu[2] << ")";
    }

    // Displacement form at random points of the frame.
    double fa[12];
    ffdtest::FrameToArray(lat.F, fa);
    const ffd::Frame<Real> frame = ffd::Frame<Real>::FromArray(fa);
    for (int p = 0; p < 50; ++p)
    {
      const ffd::Vec3<Real> x = ffdtest::ToKernel<Real>(ffdtest::ToWorld(lat.F, ffdtest::RandomVec(rng, 0, 1)));
      ffd::Vec3<Real> stu;
      ASSERT_TRUE(frame.Bind(x, stu));
      const Vec got = ffdtest::ToRef(x + EvaluateBernstein(dvalues.data(), lat.Dims().data(), stu));
      const Vec want = map(ffdtest::ToRef(x));
      const double tolD = EvaluationTolerance<Real>() * (scale + MaxAbs(ffdtest::ToRef(x)));
      ASSERT_TRUE(ffdtest::MaxDiffWithin(got, want, tolD, &worst)) << lat.Name() << " displacement form, point " << p;
    }
  }
}

TYPED_TEST(FFDGlobalBernsteinTest, RandomLatticesMatchReference)
{
  // Equation 3 over random absolute control points against ffdref::Evaluate, both fed the same Real-rounded
  // lattice and parameters. Tolerance: EvaluationTolerance() times the lattice scale.
  using Real = TypeParam;
  ffdtest::Rng rng(303);
  WorstRatio worst("worst_error_over_tolerance");
  for (const Lattice& lat : RandomLattices(rng, 60))
  {
    const std::vector<Real> values = ffdtest::Flatten<Real>(lat.Points);
    const std::vector<Vec> seen = ffdtest::RoundLattice<Real>(lat.Points);
    const double tol = EvaluationTolerance<Real>() * ffdtest::LatticeScale(seen);
    for (int p = 0; p < 20; ++p)
    {
      const ffd::Vec3<Real> stu = ffdtest::ToKernel<Real>(ffdtest::RandomVec(rng, 0.0, 1.0));
      const Vec got = ffdtest::ToRef(EvaluateBernstein(values.data(), lat.Dims().data(), stu));
      const Vec want = ffdref::Evaluate(seen, lat.L, lat.M, lat.N, ffdtest::ToRef(stu));
      ASSERT_TRUE(ffdtest::MaxDiffWithin(got, want, tol, &worst)) << lat.Name() << " point " << p;
    }
  }
}

TYPED_TEST(FFDGlobalBernsteinTest, DisplacementFormMatchesDeform)
{
  // The filter's path, X + EvaluateBernstein(P - rest) at the parameters Frame::Bind gives, against
  // ffdref::Deform (equation 2 then equation 3 over absolute points). Unlike RandomLatticesMatchReference the
  // reference sees the exact lattice and frame, so the whole path is held to the targets: tolerance
  // EvaluationTolerance() times (|P| + |X|) (X + D rounds at the size of X), covering the rounding of the
  // frame, the displacements and the point to Real and the parameter map's own arithmetic.
  using Real = TypeParam;
  ffdtest::Rng rng(304);
  WorstRatio worst("worst_error_over_tolerance");
  for (const Lattice& lat : RandomLattices(rng, 40))
  {
    const std::vector<Real> dvalues = ffdtest::Flatten<Real>(Displacements(lat));
    double fa[12];
    ffdtest::FrameToArray(lat.F, fa);
    const ffd::Frame<Real> frame = ffd::Frame<Real>::FromArray(fa);
    const double scale = ffdtest::LatticeScale(lat.Points);
    for (int p = 0; p < 20; ++p)
    {
      const ffd::Vec3<Real> x = ffdtest::ToKernel<Real>(ffdtest::ToWorld(lat.F, ffdtest::RandomVec(rng, 0, 1)));
      const Vec xd = ffdtest::ToRef(x);
      ffd::Vec3<Real> stu;
      ASSERT_TRUE(frame.Bind(x, stu)) << lat.Name() << " point " << p;
      const Vec got = ffdtest::ToRef(x + EvaluateBernstein(dvalues.data(), lat.Dims().data(), stu));
      const Vec want = ffdref::Deform(lat.F, lat.Points, lat.L, lat.M, lat.N, xd);
      const double tol = EvaluationTolerance<Real>() * (scale + MaxAbs(xd));
      ASSERT_TRUE(ffdtest::MaxDiffWithin(got, want, tol, &worst)) << lat.Name() << " point " << p;
    }
  }
}

/// Raises the degree along `axis` by one: P'_i = (i/(L+1)) P_{i-1} + (1 - i/(L+1)) P_i, i = 0..L+1, where L
/// is the degree along that axis (the terms P_{-1} and P_{L+1} have weight 0).
Lattice Elevate(const Lattice& lat, int axis)
{
  const std::array<int, 3> dims = lat.Dims();
  std::array<int, 3> out = dims;
  out[axis] += 1;
  const int degree = dims[axis] - 1;
  Lattice e = lat;
  (axis == 0 ? e.L : axis == 1 ? e.M : e.N) += 1;
  e.Points.assign(size_t(out[0]) * out[1] * out[2], Vec{ 0, 0, 0 });
  e.Rest.clear();
  for (int k = 0; k < out[2]; ++k)
    for (int j = 0; j < out[1]; ++j)
      for (int i = 0; i < out[0]; ++i)
      {
        const std::array<int, 3> ijk = { i, j, k };
        const int q = ijk[axis];
        const double w = double(q) / (degree + 1);
        Vec& target = e.Points[i + out[0] * (j + out[1] * k)];
        const auto add = [&](int index, double weight)
        {
          if (weight == 0.0)
          {
            return;
          }
          std::array<int, 3> src = ijk;
          src[axis] = index;
          const Vec& p = lat.Points[src[0] + dims[0] * (src[1] + dims[1] * src[2])];
          for (int c = 0; c < 3; ++c)
          {
            target[c] += weight * p[c];
          }
        };
        add(q - 1, w);
        add(q, 1.0 - w);
      }
  return e;
}

TYPED_TEST(FFDGlobalBernsteinTest, DegreeElevationLeavesDeformationUnchanged)
{
  // The kernel over an elevated lattice (along each axis, then along all three) against the reference over
  // the original lattice. Tolerance: EvaluationTolerance() times the lattice scale (elevation forms convex
  // combinations, so the elevated lattice has no larger scale).
  using Real = TypeParam;
  ffdtest::Rng rng(305);
  WorstRatio worst("worst_error_over_tolerance");
  for (const Lattice& lat : RandomLattices(rng, 30))
  {
    if (std::max({ lat.L, lat.M, lat.N }) >= ffd::MaxBernsteinDegree)
    {
      continue; // cannot be raised further
    }
    const std::vector<Lattice> elevated = { Elevate(lat, 0), Elevate(lat, 1), Elevate(lat, 2),
      Elevate(Elevate(Elevate(lat, 0), 1), 2) };
    const double tol = EvaluationTolerance<Real>() * ffdtest::LatticeScale(lat.Points);
    for (const Lattice& e : elevated)
    {
      ASSERT_EQ(int(e.Points.size()), (e.L + 1) * (e.M + 1) * (e.N + 1));
      const std::vector<Real> values = ffdtest::Flatten<Real>(e.Points);
      for (int p = 0; p < 20; ++p)
      {
        const ffd::Vec3<Real> stu = ffdtest::ToKernel<Real>(ffdtest::RandomVec(rng, 0.0, 1.0));
        const Vec got = ffdtest::ToRef(EvaluateBernstein(values.data(), e.Dims().data(), stu));
        const Vec want = ffdref::Evaluate(lat.Points, lat.L, lat.M, lat.N, ffdtest::ToRef(stu));
        ASSERT_TRUE(ffdtest::MaxDiffWithin(got, want, tol, &worst))
          << lat.Name() << " elevated to " << e.Name() << ", point " << p;
      }
    }
  }
}

TYPED_TEST(FFDGlobalBernsteinTest, GradientMatchesCentralDifferences)
{
  // EvaluateBernsteinWithGradient: its value against ffdref::Evaluate (EvaluationTolerance() times the
  // scale), its columns d/ds, d/dt, d/du against central differences of ffdref::Evaluate, h = 1e-6.
  using Real = TypeParam;
  ffdtest::Rng rng(306);
  WorstRatio worst("worst_error_over_tolerance");
  for (const Lattice& lat : RandomLattices(rng, 30))
  {
    const std::vector<Real> values = ffdtest::Flatten<Real>(lat.Points);
    const std::vector<Vec> seen = ffdtest::RoundLattice<Real>(lat.Points);
    const double scale = ffdtest::LatticeScale(seen);
    for (int p = 0; p < 10; ++p)
    {
      const ffd::Vec3<Real> stu = ffdtest::ToKernel<Real>(ffdtest::RandomVec(rng, 0.001, 0.999));
      const Vec s = ffdtest::ToRef(stu);
      ffd::Mat3<Real> g;
      const Vec got = ffdtest::ToRef(EvaluateBernsteinWithGradient(values.data(), lat.Dims().data(), stu, g));
      const Vec want = ffdref::Evaluate(seen, lat.L, lat.M, lat.N, s);
      ASSERT_TRUE(ffdtest::MaxDiffWithin(got, want, EvaluationTolerance<Real>() * scale)) << lat.Name();
      const ffdtest::Mat fd = ffdtest::CentralDifferences(
        s, 1e-6, [&](const Vec& y) { return ffdref::Evaluate(seen, lat.L, lat.M, lat.N, y); });
      const auto tol = [&](int r, int c) { return GradientTolerance<Real>() * std::max(scale, std::fabs(fd[r][c])); };
      ASSERT_TRUE(ffdtest::MatrixNear(g, fd, tol, "dx/dstu", &worst)) << lat.Name() << " point " << p;
    }
  }
}

TYPED_TEST(FFDGlobalBernsteinTest, DeformationJacobianMatchesCentralDifferences)
{
  // ffd::DeformationJacobian of the displacement form against central differences of ffdref::Deform in world
  // coordinates, h = 1e-6. Tolerance: GradientTolerance() times max(1, |dX_ffd/dX|_max) per entry (the
  // Jacobian is dimensionless; the identity part is 1).
  using Real = TypeParam;
  ffdtest::Rng rng(307);
  WorstRatio worst("worst_error_over_tolerance");
  for (const Lattice& lat : RandomLattices(rng, 30))
  {
    const std::vector<Real> dvalues = ffdtest::Flatten<Real>(Displacements(lat));
    double fa[12];
    ffdtest::FrameToArray(lat.F, fa);
    const ffd::Frame<Real> frame = ffd::Frame<Real>::FromArray(fa);
    for (int p = 0; p < 10; ++p)
    {
      const ffd::Vec3<Real> x = ffdtest::ToKernel<Real>(ffdtest::ToWorld(lat.F, ffdtest::RandomVec(rng, 0.01, 0.99)));
      const Vec xd = ffdtest::ToRef(x);
      ffd::Vec3<Real> stu;
      ASSERT_TRUE(frame.Bind(x, stu));
      ffd::Mat3<Real> g;
      EvaluateBernsteinWithGradient(dvalues.data(), lat.Dims().data(), stu, g);
      const ffd::Mat3<Real> j = ffd::DeformationJacobian(g, frame);
      const ffdtest::Mat fd = ffdtest::CentralDifferences(
        xd, 1e-6, [&](const Vec& y) { return ffdref::Deform(lat.F, lat.Points, lat.L, lat.M, lat.N, y); });
      const double tol = GradientTolerance<Real>() * ffdtest::MaxAbsEntry(fd, 1.0);
      ASSERT_TRUE(ffdtest::MatrixNear(j, fd, tol, "J", &worst)) << lat.Name() << " point " << p;
    }
  }
}

/// Inverse and determinant of a 3x3 matrix by Gauss-Jordan elimination with partial pivoting, in double:
/// an independent route to det(A) A^-T.
double InvertReference(const double a[3][3], double inv[3][3])
{
  double m[3][6];
  for (int r = 0; r < 3; ++r)
  {
    for (int c = 0; c < 3; ++c)
    {
      m[r][c] = a[r][c];
      m[r][3 + c] = r == c ? 1.0 : 0.0;
    }
  }
  double det = 1.0;
  for (int col = 0; col < 3; ++col)
  {
    int pivot = col;
    for (int r = col + 1; r < 3; ++r)
    {
      pivot = std::fabs(m[r][col]) > std::fabs(m[pivot][col]) ? r : pivot;
    }
    if (pivot != col)
    {
      std::swap(m[pivot], m[col]);
      det = -det;
    }
    det *= m[col][col];
    const double d = m[col][col];
    for (int c = 0; c < 6; ++c)
    {
      m[col][c] /= d;
    }
    for (int r = 0; r < 3; ++r)
    {
      if (r != col)
      {
        const double f = m[r][col];
        for (int c = 0; c < 6; ++c)
        {
          m[r][c] -= f * m[col][c];
        }
      }
    }
  }
  for (int r = 0; r < 3; ++r)
  {
    for (int c = 0; c < 3; ++c)
    {
      inv[r][c] = m[r][3 + c];
    }
  }
  return det;
}

TYPED_TEST(FFDGlobalBernsteinTest, CofactorIsDeterminantTimesInverseTranspose)
{
  // Random well-conditioned matrices A = 2 I + [-1, 1]^(3x3) (entries <= 3, condition number small).
  // Tolerance: absolute, 64 eps(Real) max|A|^2 on the cofactor (its entries are 2x2 minors, products of two
  // entries) and 64 eps(Real) max|A|^3 on the determinant. Also on singular matrices (third row a combination
  // of the first two), where A^-1 does not exist: cofactor rows are the cross products of the other rows.
  using Real = TypeParam;
  ffdtest::Rng rng(308);
  for (int trial = 0; trial < 1000; ++trial)
  {
    double a[3][3];
    ffd::Mat3<Real> ak;
    double amax = 0.0;
    for (int r = 0; r < 3; ++r)
    {
      for (int c = 0; c < 3; ++c)
      {
        ak.M[r][c] = Real((r == c ? 2.0 : 0.0) + ffdtest::Uniform(rng, -1.0, 1.0));
        a[r][c] = double(ak.M[r][c]);
        amax = std::max(amax, std::fabs(a[r][c]));
      }
    }
    double inv[3][3];
    const double det = InvertReference(a, inv);
    EXPECT_NEAR(double(ffd::Determinant(ak)), det, 64.0 * Eps<Real>() * amax * amax * amax);
    ffdtest::Mat want; // det(A) A^-T
    for (int r = 0; r < 3; ++r)
    {
      for (int c = 0; c < 3; ++c)
      {
        want[r][c] = det * inv[c][r];
      }
    }
    ASSERT_TRUE(ffdtest::MatrixNear(ffd::Cofactor(ak), want, 64.0 * Eps<Real>() * amax * amax, "cofactor"))
      << "trial " << trial;

    // Singular: row 2 = alpha row 0 + beta row 1.
    const double alpha = ffdtest::Uniform(rng, -1, 1), beta = ffdtest::Uniform(rng, -1, 1);
    for (int c = 0; c < 3; ++c)
    {
      ak.M[2][c] = Real(alpha * a[0][c] + beta * a[1][c]);
      a[2][c] = double(ak.M[2][c]);
      amax = std::max(amax, std::fabs(a[2][c]));
    }
    const Vec rows[3] = { { a[0][0], a[0][1], a[0][2] }, { a[1][0], a[1][1], a[1][2] }, { a[2][0], a[2][1], a[2][2] } };
    ffdtest::Mat crosses; // row r: the cross product of the other two rows
    for (int r = 0; r < 3; ++r)
    {
      crosses[r] = ffdref::Cross(rows[(r + 1) % 3], rows[(r + 2) % 3]);
    }
    ASSERT_TRUE(ffdtest::MatrixNear(ffd::Cofactor(ak), crosses, 64.0 * Eps<Real>() * amax * amax, "cofactor"))
      << "singular, trial " << trial;
  }
}

} // namespace
