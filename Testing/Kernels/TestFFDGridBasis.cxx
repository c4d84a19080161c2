// SPDX-License-Identifier: BSD-3-Clause
// The grid bases of FFDGridBasis.h (global Bernstein, trilinear, triquadratic and tricubic Bezier sub-regions,
// uniform cubic B-spline) against the float64 reference ffdref:: (binomials times powers in the voxel's local
// coordinate, Cox-de Boor recursion, sums over the whole lattice): partition of unity, linear precision,
// random lattices, the one-voxel Bezier = global Bernstein identities, continuity across voxel faces and knots,
// and derivatives.
//
// Normalisation of errors, as in TestFFDGlobalBernstein.cxx: an evaluation error is divided by the lattice's
// scale max_ijk ||P_ijk||_inf (the frames sit near the origin, so this is the lattice's extent to within a small
// factor, and it is the size of the numbers every basis combines).

#include "FFDGridBasis.h"
#include "FFDKernelTestUtilities.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

namespace
{
using ffdref::Basis;
using ffdref::Vec;
using ffdtest::Eps;
using ffdtest::EvaluationTolerance;
using ffdtest::GradientTolerance;
using ffdtest::GridLattice;
using ffdtest::MaxDiff;
using ffdtest::WorstRatio;

/// Weight arrays large enough for every basis, the global one included.
constexpr int MaxCount = ffd::MaxBernsteinDegree + 1;
template <typename Real>
using Axes = ffd::AxisWeights<MaxCount, Real>;

ffd::GridBasis KernelBasis(Basis b)
{
  return ffd::GridBasis(int(b));
}

/// Kernel weights along the three axes at parameters stu; axis a bound to cells[a], or, when cells is null, to
/// the cell ffd::CellOf gives.
template <typename Real>
void KernelAxes(const GridLattice& lat, const Vec& stu, const int* cells, bool withDerivative, Axes<Real>* axes)
{
  const ffd::GridBasis basis = KernelBasis(lat.Basis);
  for (int a = 0; a < 3; ++a)
  {
    const Real s = Real(stu[a]);
    const int c = cells ? cells[a] : ffd::CellOf(s, ffd::BindingCells(basis, lat.Divisions[a]));
    ffd::ComputeAxisWeights(basis, lat.Divisions[a], c, s, withDerivative, axes[a]);
  }
}

/// ffd::SumTensorProduct of `values` (a lattice of lat's shape, rounded to Real) at stu.
template <typename Real>
Vec Evaluate(const GridLattice& lat, const std::vector<Real>& values, const Vec& stu, const int* cells = nullptr)
{
  Axes<Real> axes[3];
  KernelAxes(lat, stu, cells, false, axes);
  return ffdtest::ToRef(ffd::SumTensorProduct(values.data(), lat.Dims().data(), axes));
}

/// ffd::SumTensorProductWithGradient: the value, and gradient[r][c] = d x_r / d stu_c.
template <typename Real>
Vec EvaluateWithGradient(const GridLattice& lat, const std::vector<Real>& values, const Vec& stu, double gradient[3][3],
  const int* cells = nullptr)
{
  Axes<Real> axes[3];
  KernelAxes(lat, stu, cells, true, axes);
  ffd::Mat3<Real> g;
  const Vec x = ffdtest::ToRef(ffd::SumTensorProductWithGradient(values.data(), lat.Dims().data(), axes, g));
  for (int r = 0; r < 3; ++r)
  {
    for (int c = 0; c < 3; ++c)
    {
      gradient[r][c] = double(g.M[r][c]);
    }
  }
  return x;
}

/// Random parameters in [0, 1] rounded to Real (so the reference sees exactly what the kernel sees).
template <typename Real>
Vec RandomParameters(ffdtest::Rng& rng)
{
  return ffdtest::ToRef(ffdtest::ToKernel<Real>(ffdtest::RandomVec(rng, 0.0, 1.0)));
}

/**
 * Random parameters whose local coordinate in their voxel lies in [margin, 1 - margin] on every axis, rounded
 * to Real: central differences of the reference around them stay inside one polynomial piece.
 */
template <typename Real>
Vec InteriorParameters(ffdtest::Rng& rng, const GridLattice& lat, double margin)
{
  Vec stu;
  for (int a = 0; a < 3; ++a)
  {
    const int cells = lat.Basis == Basis::Bernstein ? 1 : lat.Divisions[a];
    const int c = std::uniform_int_distribution<int>(0, cells - 1)(rng);
    stu[a] = double(Real((c + ffdtest::Uniform(rng, margin, 1.0 - margin)) / cells));
  }
  return stu;
}

FFD_REAL_TYPED_TEST_SUITE(FFDGridBasisTest);

TEST(FFDGridBasisLayout, MatchesDataContractAndReference)
{
  // Enum values, lattice sizes, rest parameters and voxel supports of the kernels against the reference and the
  // data contract (ARCHITECTURE.md): exact, except the rest parameters, which both compute as one quotient.
  for (Basis b : ffdtest::AllBases)
  {
    const ffd::GridBasis k = KernelBasis(b);
    ASSERT_TRUE(ffd::IsGridBasis(int(b)));
    for (int n = 1; n <= 8; ++n)
    {
      const int points = ffdref::PointsAlongAxis(b, n);
      ASSERT_EQ(ffd::ControlPointsAlongAxis(k, n), points) << ffdtest::BasisName(b) << " n=" << n;
      for (int i = 0; i < points; ++i)
      {
        ASSERT_NEAR(ffd::RestParameter(k, n, i), ffdref::RestParameter(b, n, i), 1e-15)
          << ffdtest::BasisName(b) << " n=" << n << " i=" << i;
      }
      // The control points influencing voxel c are those with a non-zero reference weight at its centre
      // (every basis function is positive inside its support).
      for (int c = 0; c < n; ++c)
      {
        const double s = (b == Basis::Bernstein ? 0.5 : (c + 0.5) / n);
        const std::vector<double> w = ffdref::AxisWeights(b, n, s);
        int first = 0, count = 0;
        ffd::VoxelSupport(k, n, c, first, count);
        ASSERT_LE(count, ffd::SupportSize(k, n));
        for (int i = 0; i < points; ++i)
        {
          ASSERT_EQ(w[i] != 0.0, i >= first && i < first + count)
            << ffdtest::BasisName(b) << " n=" << n << " voxel " << c << " point " << i;
        }
      }
    }
  }
  EXPECT_FALSE(ffd::IsGridBasis(-1));
  EXPECT_FALSE(ffd::IsGridBasis(5));
  EXPECT_EQ(ffd::BezierDegree(ffd::GridBasis::Trilinear), 1);
  EXPECT_EQ(ffd::BezierDegree(ffd::GridBasis::TriquadraticBezier), 2);
  EXPECT_EQ(ffd::BezierDegree(ffd::GridBasis::TricubicBezier), 3);
}

TYPED_TEST(FFDGridBasisTest, AxisWeightsMatchReferenceAndSumToOne)
{
  // Per axis, for every basis, n = 1..8 voxels, random s (and s = 0, 1 and every voxel face): the kernel's
  // weights equal the reference's on [First, First + Count), the reference's are exactly 0 elsewhere, the
  // weights sum to 1 and their derivatives to 0. Tolerance: 16 (Count + 1) eps(Real) absolute on weights
  // (numbers in [0, 1] from a few multiplications each, or the de Casteljau triangle whose error grows with the
  // degree) and the same times n on the derivatives (which carry the factor n of d/ds = n d/dr).
  using Real = TypeParam;
  ffdtest::Rng rng(401);
  WorstRatio worst("worst_error_over_tolerance");
  for (Basis b : ffdtest::AllBases)
  {
    for (int n = 1; n <= 8; ++n)
    {
      std::vector<double> params = { 0.0, 1.0 };
      for (int c = 1; c < n; ++c)
      {
        params.push_back(double(c) / n);
      }
      for (int p = 0; p < 100; ++p)
      {
        params.push_back(ffdtest::Uniform(rng, 0.0, 1.0));
      }
      for (double sd : params)
      {
        const Real s = Real(sd);
        Axes<Real> a;
        const int cell = ffd::CellOf(s, ffd::BindingCells(KernelBasis(b), n));
        ffd::ComputeAxisWeights(KernelBasis(b), n, cell, s, true, a);
        const std::vector<double> w = ffdref::AxisWeights(b, n, double(s));
        const double tol = 16.0 * (a.Count + 1) * Eps<Real>();
        double sum = 0.0, dsum = 0.0;
        for (int i = 0; i < int(w.size()); ++i)
        {
          const bool inSupport = i >= a.First && i < a.First + a.Count;
          const double got = inSupport ? double(a.W[i - a.First]) : 0.0;
          worst.Add(std::fabs(got - w[i]), tol);
          ASSERT_NEAR(got, w[i], tol) << ffdtest::BasisName(b) << " n=" << n << " s=" << s << " i=" << i;
          if (inSupport)
          {
            sum += double(a.W[i - a.First]);
            dsum += double(a.D[i - a.First]);
          }
        }
        ASSERT_NEAR(sum, 1.0, tol) << ffdtest::BasisName(b) << " n=" << n << " s=" << s;
        ASSERT_NEAR(dsum, 0.0, n * tol) << ffdtest::BasisName(b) << " n=" << n << " s=" << s;
      }
    }
  }
}

TYPED_TEST(FFDGridBasisTest, RestLatticeIsIdentity)
{
  // Linear precision: with the reference's rest positions (trilinear i/n, quadratic i/(2n), cubic i/(3n),
  // B-spline (i-1)/n, global i/n) as values, SumTensorProduct gives X0 + sS + tT + uU, at random parameters and
  // at the rest parameters of the nodes inside the frame. Tolerance: EvaluationTolerance() times the lattice
  // scale.
  using Real = TypeParam;
  ffdtest::Rng rng(402);
  WorstRatio worst("worst_error_over_tolerance");
  ffdtest::ForEachRandomLattice(rng, 20, 6,
    [&](const GridLattice& lat)
    {
      const std::vector<Real> values = ffdtest::Flatten<Real>(lat.Rest);
      const double tol = EvaluationTolerance<Real>() * ffdtest::LatticeScale(lat.Rest);
      std::vector<Vec> params;
      for (int p = 0; p < 50; ++p)
      {
        params.push_back(RandomParameters<Real>(rng));
      }
      for (int p = 0; p < 50; ++p)
      {
        Vec stu;
        for (int a = 0; a < 3; ++a)
        {
          const int n = lat.Divisions[a];
          const int i = std::uniform_int_distribution<int>(0, lat.Dims()[a] - 1)(rng);
          stu[a] = double(Real(std::min(std::max(ffdref::RestParameter(lat.Basis, n, i), 0.0), 1.0)));
        }
        params.push_back(stu);
      }
      for (const Vec& stu : params)
      {
        const Vec got = Evaluate(lat, values, stu);
        const Vec want = ffdtest::ToWorld(lat.F, stu);
        ASSERT_TRUE(ffdtest::MaxDiffWithin(got, want, tol, &worst))
          << lat.Name() << " at (" << stu[0] << "," << stu[1] << "," << stu[2] << ")";
      }
    });
}

TYPED_TEST(FFDGridBasisTest, AffineMotionIsReproduced)
{
  // Every control point moved by one affine map x -> A x + b: SumTensorProduct at (s, t, u) is the map of
  // X0 + sS + tT + uU. Tolerance: EvaluationTolerance() times the mapped lattice's scale.
  using Real = TypeParam;
  ffdtest::Rng rng(403);
  WorstRatio worst("worst_error_over_tolerance");
  ffdtest::ForEachRandomLattice(rng, 20, 6,
    [&](const GridLattice& lat)
    {
      const ffdtest::Affine map = ffdtest::RandomAffine(rng, 0.5);
      std::vector<Vec> mapped;
      for (const Vec& p : lat.Rest)
      {
        mapped.push_back(map(p));
      }
      const std::vector<Real> values = ffdtest::Flatten<Real>(mapped);
      const double tol = EvaluationTolerance<Real>() * ffdtest::LatticeScale(mapped);
      for (int p = 0; p < 50; ++p)
      {
        const Vec stu = RandomParameters<Real>(rng);
        const Vec got = Evaluate(lat, values, stu);
        const Vec want = map(ffdtest::ToWorld(lat.F, stu));
        ASSERT_TRUE(ffdtest::MaxDiffWithin(got, want, tol, &worst)) << lat.Name() << " point " << p;
      }
    });
}

TYPED_TEST(FFDGridBasisTest, RandomLatticesMatchReference)
{
  // Random absolute control points, SumTensorProduct against ffdref::EvaluateLocal (which finds the voxel itself
  // and sums over the whole lattice), both fed the same Real-rounded lattice and parameters. Tolerance:
  // EvaluationTolerance() times the lattice scale.
  using Real = TypeParam;
  ffdtest::Rng rng(404);
  WorstRatio worst("worst_error_over_tolerance");
  ffdtest::ForEachRandomLattice(rng, 40, 6,
    [&](const GridLattice& lat)
    {
      const std::vector<Real> values = ffdtest::Flatten<Real>(lat.Points);
      const std::vector<Vec> seen = ffdtest::RoundLattice<Real>(lat.Points);
      const double tol = EvaluationTolerance<Real>() * ffdtest::LatticeScale(seen);
      for (int p = 0; p < 30; ++p)
      {
        const Vec stu = RandomParameters<Real>(rng);
        const Vec got = Evaluate(lat, values, stu);
        const Vec want = ffdref::EvaluateLocal(lat.Basis, lat.Divisions.data(), seen, stu);
        ASSERT_TRUE(ffdtest::MaxDiffWithin(got, want, tol, &worst)) << lat.Name() << " point " << p;
      }
    });
}

TYPED_TEST(FFDGridBasisTest, OneBezierVoxelEqualsGlobalBernstein)
{
  // One voxel of a Bezier basis of degree d (trilinear: 2x2x2, triquadratic: 3x3x3, tricubic: 4x4x4 points) is
  // the global Bernstein basis of degree d over the same frame: same lattice size, same rest positions, same
  // values and derivatives (kernel against kernel), and the same values as the foundation's reference
  // ffdref::Evaluate of equation 3. Tolerance: EvaluationTolerance() times the lattice scale on values, and
  // GradientTolerance() times it on derivatives (both sides compute them analytically; the derivative of degree
  // d is at most 2d times the scale).
  using Real = TypeParam;
  ffdtest::Rng rng(405);
  WorstRatio worst("worst_error_over_tolerance");
  const auto bases = { Basis::Trilinear, Basis::TriquadraticBezier, Basis::TricubicBezier };
  ffdtest::ForEachRandomLattice(rng, bases, 20, 1,
    [&](const GridLattice& bezier)
    {
      const int d = int(bezier.Basis);
      GridLattice global = bezier;
      global.Basis = Basis::Bernstein;
      global.Divisions = { d, d, d };
      ASSERT_EQ(bezier.Dims(), global.Dims());
      ASSERT_EQ(ffdref::RestLattice(Basis::Bernstein, global.F, global.Divisions.data()), bezier.Rest);
      for (int i = 0; i <= d; ++i)
      {
        ASSERT_EQ(
          ffd::RestParameter(KernelBasis(bezier.Basis), 1, i), ffd::RestParameter(ffd::GridBasis::Bernstein, d, i));
      }
      const std::vector<Real> values = ffdtest::Flatten<Real>(bezier.Points);
      const std::vector<Vec> seen = ffdtest::RoundLattice<Real>(bezier.Points);
      const double scale = ffdtest::LatticeScale(seen);
      const double tol = EvaluationTolerance<Real>() * scale;
      for (int p = 0; p < 50; ++p)
      {
        const Vec stu = RandomParameters<Real>(rng);
        double gb[3][3], gg[3][3];
        const Vec xb = EvaluateWithGradient(bezier, values, stu, gb);
        const Vec xg = EvaluateWithGradient(global, values, stu, gg);
        const Vec want = ffdref::Evaluate(seen, d, d, d, stu);
        ASSERT_TRUE(ffdtest::MaxDiffWithin(xb, xg, tol, &worst)) << bezier.Name() << " point " << p;
        ASSERT_TRUE(ffdtest::MaxDiffWithin(xb, want, tol, &worst)) << bezier.Name() << " point " << p;
        ASSERT_TRUE(ffdtest::MatrixNear(gb, gg, GradientTolerance<Real>() * scale, "dx/dstu"))
          << bezier.Name() << " point " << p;
      }
    });
}

/// One side of a voxel face or knot along axis `a`: the value, the analytic gradient, and the derivative of the
/// gradient along a, with the point bound to the cell on that side.
struct Side
{
  Vec Value;
  double Gradient[3][3];
  double Second[3][3]; ///< d/ds_a of Gradient
};

/**
 * Evaluates at stu with axis a bound to cells[a] and differentiates the analytic gradient along a at s with the
 * one-sided four-point formula on the abscissae s + q dir h, q = 0..3, rounded to Real. The formula uses the
 * rounded abscissae and is exact for cubics: along a, a piece's gradient is a quadratic (d/ds_a) or a cubic
 * (the other columns), so only rounding remains.
 */
template <typename Real>
Side EvaluateSide(
  const GridLattice& lat, const std::vector<Real>& values, const Vec& stu, const int cells[3], int a, int dir, double h)
{
  constexpr int Nodes = 4;
  Side side;
  side.Value = EvaluateWithGradient(lat, values, stu, side.Gradient, cells);
  double x[Nodes] = { stu[a] };
  double g[Nodes][3][3];
  for (int q = 1; q < Nodes; ++q)
  {
    Vec p = stu;
    p[a] = double(Real(stu[a] + q * dir * h));
    x[q] = p[a];
    EvaluateWithGradient(lat, values, p, g[q], cells);
  }
  // Derivatives at x0 of the Lagrange polynomials through the nodes: L_0'(x0) = sum_m 1 / (x0 - x_m), and for
  // q > 0, L_q'(x0) = prod_{m != 0, q} (x0 - x_m) / prod_{m != q} (x_q - x_m).
  double weight[Nodes] = { 0.0 };
  for (int m = 1; m < Nodes; ++m)
  {
    weight[0] += 1.0 / (x[0] - x[m]);
  }
  for (int q = 1; q < Nodes; ++q)
  {
    double num = 1.0, den = 1.0;
    for (int m = 0; m < Nodes; ++m)
    {
      if (m != q)
      {
        num *= m != 0 ? x[0] - x[m] : 1.0;
        den *= x[q] - x[m];
      }
    }
    weight[q] = num / den;
  }
  for (int r = 0; r < 3; ++r)
  {
    for (int c = 0; c < 3; ++c)
    {
      side.Second[r][c] = weight[0] * side.Gradient[r][c];
      for (int q = 1; q < Nodes; ++q)
      {
        side.Second[r][c] += weight[q] * g[q][r][c];
      }
    }
  }
  return side;
}

/// Largest jumps across the interior faces of a lattice, each divided by its natural size: value / scale,
/// gradient / (n scale), second derivative / (n^2 scale), where n is the voxels along the face's normal axis.
struct Jumps
{
  double Value = 0.0, Gradient = 0.0, Second = 0.0;
  int Faces = 0;
};

/**
 * Jumps at every interior face c/n of every axis, at `samples` random positions on the face, with the point
 * bound to the voxels c - 1 and c. The face parameter is c/n rounded to Real: both sides are evaluated there (the
 * left voxel's local coordinate is clamped to 1 if the rounding puts it past), so the value jump also holds
 * |gradient| times the rounding of c/n, which the caller's tolerance allows for.
 */
template <typename Real>
Jumps FaceJumps(ffdtest::Rng& rng, const GridLattice& lat, const std::vector<Real>& values, int samples)
{
  Jumps jumps;
  const double scale = ffdtest::LatticeScale(ffdtest::RoundLattice<Real>(lat.Points));
  for (int a = 0; a < 3; ++a)
  {
    const int n = lat.Divisions[a];
    for (int c = 1; c < n; ++c)
    {
      for (int sample = 0; sample < samples; ++sample)
      {
        Vec stu = RandomParameters<Real>(rng);
        stu[a] = double(Real(double(c) / n));
        int cells[3];
        for (int q = 0; q < 3; ++q)
        {
          cells[q] = ffd::CellOf(Real(stu[q]), lat.Divisions[q]);
        }
        const double h = 0.1 / n; // three steps stay inside the voxel on each side
        cells[a] = c - 1;
        const Side left = EvaluateSide(lat, values, stu, cells, a, -1, h);
        cells[a] = c;
        const Side right = EvaluateSide(lat, values, stu, cells, a, +1, h);
        jumps.Value = std::max(jumps.Value, MaxDiff(left.Value, right.Value) / scale);
        for (int r = 0; r < 3; ++r)
        {
          for (int k = 0; k < 3; ++k)
          {
            const double gradientJump = std::fabs(left.Gradient[r][k] - right.Gradient[r][k]);
            const double secondJump = std::fabs(left.Second[r][k] - right.Second[r][k]);
            jumps.Gradient = std::max(jumps.Gradient, gradientJump / (n * scale));
            jumps.Second = std::max(jumps.Second, secondJump / (n * n * scale));
          }
        }
        ++jumps.Faces;
      }
    }
  }
  return jumps;
}

/// Lattices of the basis with 2..5 voxels on every axis (so that every axis has interior faces).
GridLattice LatticeWithFaces(ffdtest::Rng& rng, Basis b)
{
  GridLattice lat;
  do
  {
    lat = ffdtest::RandomGridLattice(rng, b, 5);
  } while (std::min({ lat.Divisions[0], lat.Divisions[1], lat.Divisions[2] }) < 2);
  return lat;
}

/**
 * Tolerances of the relative jumps of FaceJumps (each relative to its natural size):
 *  - value: EvaluationTolerance() plus 8 eps(Real) n (the face parameter c/n rounded to Real moves the point by
 *    eps, the value by |d/ds| eps <= 8 n scale eps for displacements of 0.3 on lattices of scale >= 0.5);
 *  - gradient: 8 n EvaluationTolerance() (the d/ds weights are n times larger and the rounding of c/n moves the
 *    gradient by |d2/ds2| eps ~ n^2 scale eps);
 *  - second derivative: 100 EvaluationTolerance() (the four-point formula's weights are ~(11/6)/h with
 *    h = 0.1/n: gradient rounding errors grow by ~20 n relative to n^2 scale).
 */
template <typename Real>
Jumps JumpTolerance(int n)
{
  Jumps tol;
  tol.Value = EvaluationTolerance<Real>() + 8.0 * n * Eps<Real>();
  tol.Gradient = 8.0 * n * EvaluationTolerance<Real>();
  tol.Second = 100.0 * EvaluationTolerance<Real>();
  return tol;
}

TYPED_TEST(FFDGridBasisTest, BezierSubRegionsAreC0AcrossFaces)
{
  // C0 of every local basis across every interior voxel face: the value with the point bound to the voxel on
  // either side, at the same (rounded) face parameter. A wrong First (face control points not shared) or a
  // wrong local coordinate jumps by a fraction of the scale. Tolerance: JumpTolerance(). Also at s = c/n -+ 1e-9
  // (double only; float cannot resolve it), each side carried to the face by its analytic derivative: tolerance
  // EvaluationTolerance() times the scale.
  using Real = TypeParam;
  ffdtest::Rng rng(406);
  WorstRatio worst("worst_error_over_tolerance");
  for (Basis b : { Basis::Trilinear, Basis::TriquadraticBezier, Basis::TricubicBezier, Basis::CubicBSpline })
  {
    for (int trial = 0; trial < 10; ++trial)
    {
      const GridLattice lat = LatticeWithFaces(rng, b);
      const std::vector<Real> values = ffdtest::Flatten<Real>(lat.Points);
      const int nmax = std::max({ lat.Divisions[0], lat.Divisions[1], lat.Divisions[2] });
      const Jumps jumps = FaceJumps(rng, lat, values, 10);
      const Jumps tol = JumpTolerance<Real>(nmax);
      ASSERT_GT(jumps.Faces, 0);
      worst.Add(jumps.Value, tol.Value);
      ASSERT_LE(jumps.Value, tol.Value) << lat.Name();
      if (sizeof(Real) < sizeof(double))
      {
        continue;
      }
      const double scale = ffdtest::LatticeScale(lat.Points);
      const double delta = 1e-9;
      for (int a = 0; a < 3; ++a)
      {
        const int n = lat.Divisions[a];
        for (int c = 1; c < n; ++c)
        {
          Vec stu = RandomParameters<Real>(rng);
          int cells[3];
          for (int q = 0; q < 3; ++q)
          {
            cells[q] = ffd::CellOf(Real(stu[q]), lat.Divisions[q]);
          }
          double gl[3][3], gr[3][3];
          stu[a] = double(c) / n - delta;
          cells[a] = c - 1;
          const Vec left = EvaluateWithGradient(lat, values, stu, gl, cells);
          stu[a] = double(c) / n + delta;
          cells[a] = c;
          const Vec right = EvaluateWithGradient(lat, values, stu, gr, cells);
          // Each side's value carried to the face by its own first-order Taylor term; what remains is the jump,
          // rounding, and delta^2 |d2/ds2| / 2 < 1e-16 n^2 scale.
          Vec leftFace, rightFace;
          for (int r = 0; r < 3; ++r)
          {
            leftFace[r] = left[r] + delta * gl[r][a];
            rightFace[r] = right[r] - delta * gr[r][a];
          }
          const double tolDelta = EvaluationTolerance<Real>() * scale;
          ASSERT_TRUE(ffdtest::MaxDiffWithin(leftFace, rightFace, tolDelta, &worst))
            << lat.Name() << " face " << c << " of axis " << a;
        }
      }
    }
  }
}

TYPED_TEST(FFDGridBasisTest, CubicBSplineIsC2AcrossKnots)
{
  // C2 of the uniform cubic B-spline across every interior knot: value, analytic gradient (all three columns)
  // and the derivative along the knot's axis of that gradient (the second derivatives d2/ds_a ds_k, by the
  // one-sided four-point formula on each side) agree. Tolerances: JumpTolerance().
  using Real = TypeParam;
  ffdtest::Rng rng(407);
  WorstRatio worst("worst_error_over_tolerance");
  for (int trial = 0; trial < 20; ++trial)
  {
    const GridLattice lat = LatticeWithFaces(rng, Basis::CubicBSpline);
    const std::vector<Real> values = ffdtest::Flatten<Real>(lat.Points);
    const Jumps jumps = FaceJumps(rng, lat, values, 10);
    const Jumps tol = JumpTolerance<Real>(std::max({ lat.Divisions[0], lat.Divisions[1], lat.Divisions[2] }));
    worst.Add(jumps.Value, tol.Value);
    worst.Add(jumps.Gradient, tol.Gradient);
    worst.Add(jumps.Second, tol.Second);
    ASSERT_LE(jumps.Value, tol.Value) << lat.Name();
    ASSERT_LE(jumps.Gradient, tol.Gradient) << lat.Name();
    ASSERT_LE(jumps.Second, tol.Second) << lat.Name();
  }
}

TYPED_TEST(FFDGridBasisTest, BezierSubRegionsAreNotC1)
{
  // The check of CubicBSplineIsC2AcrossKnots can fail: on random lattices, the Bezier bases' gradient jumps
  // across faces by far more than the C1 tolerance (their face control points are shared, not constrained to
  // be collinear with their neighbours). Required: a jump above 1000 times the tolerance on every lattice.
  using Real = TypeParam;
  ffdtest::Rng rng(408);
  for (Basis b : { Basis::Trilinear, Basis::TriquadraticBezier, Basis::TricubicBezier })
  {
    for (int trial = 0; trial < 10; ++trial)
    {
      const GridLattice lat = LatticeWithFaces(rng, b);
      const std::vector<Real> values = ffdtest::Flatten<Real>(lat.Points);
      const Jumps jumps = FaceJumps(rng, lat, values, 5);
      const Jumps tol = JumpTolerance<Real>(std::max({ lat.Divisions[0], lat.Divisions[1], lat.Divisions[2] }));
      ASSERT_GT(jumps.Gradient, 1000.0 * tol.Gradient) << lat.Name();
    }
  }
}

TYPED_TEST(FFDGridBasisTest, GradientMatchesCentralDifferences)
{
  // SumTensorProductWithGradient for every basis: its value against ffdref::EvaluateLocal (EvaluationTolerance()
  // times the scale) and its columns d/ds, d/dt, d/du against central differences of ffdref::EvaluateLocal,
  // h = 1e-6, at points at least 0.01 (local coordinate) from their voxel's faces so that the differences stay in
  // one polynomial piece. Tolerance: GradientTolerance() times max(scale, |derivative|).
  using Real = TypeParam;
  ffdtest::Rng rng(409);
  WorstRatio worst("worst_error_over_tolerance");
  ffdtest::ForEachRandomLattice(rng, 20, 6,
    [&](const GridLattice& lat)
    {
      const std::vector<Real> values = ffdtest::Flatten<Real>(lat.Points);
      const std::vector<Vec> seen = ffdtest::RoundLattice<Real>(lat.Points);
      const double scale = ffdtest::LatticeScale(seen);
      for (int p = 0; p < 10; ++p)
      {
        const Vec stu = InteriorParameters<Real>(rng, lat, 0.01);
        double g[3][3];
        const Vec got = EvaluateWithGradient(lat, values, stu, g);
        const Vec want = ffdref::EvaluateLocal(lat.Basis, lat.Divisions.data(), seen, stu);
        ASSERT_TRUE(ffdtest::MaxDiffWithin(got, want, EvaluationTolerance<Real>() * scale)) << lat.Name();
        const ffdtest::Mat fd = ffdtest::CentralDifferences(
          stu, 1e-6, [&](const Vec& y) { return ffdref::EvaluateLocal(lat.Basis, lat.Divisions.data(), seen, y); });
        const auto tol = [&](int r, int c) { return GradientTolerance<Real>() * std::max(scale, std::fabs(fd[r][c])); };
        ASSERT_TRUE(ffdtest::MatrixNear(g, fd, tol, "dx/dstu", &worst)) << lat.Name() << " point " << p;
      }
    });
}

} // namespace
