// SPDX-License-Identifier: BSD-3-Clause
// Binding and evaluation of grid lattices (FFDGridDeformation.h) for every basis against the float64 reference
// ffdref::DeformLocal (equation 2 by Cramer's rule, the voxel found by the reference itself, absolute control
// points summed over the whole lattice): cells of points inside, on faces and corners, outside and non-finite;
// the displacement form and its Jacobian; the clamping outside policy; locality of one moved control point.
//
// Normalisation of errors, as in TestFFDGlobalBernstein.cxx: the lattice's scale max_ijk ||P_ijk||_inf, plus
// |X| for the displacement form (X + D rounds at the size of X).

#include "FFDGridDeformation.h"
#include "FFDKernelTestUtilities.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace
{
using ffdref::Basis;
using ffdref::Vec;
using ffdtest::Eps;
using ffdtest::EvaluationTolerance;
using ffdtest::GradientTolerance;
using ffdtest::GridLattice;
using ffdtest::MaxAbs;
using ffdtest::PositionTolerance;
using ffdtest::WithKernel;
using ffdtest::WorstRatio;

/// Cells per axis seen by the binding, from the data contract: the voxels, one cell for the global basis.
int Cells(const GridLattice& lat, int a)
{
  return lat.Basis == Basis::Bernstein ? 1 : lat.Divisions[a];
}

/// The flat cell index ci + cx (cj + cy ck) of per-axis cells.
int FlatCell(const GridLattice& lat, const int c[3])
{
  return c[0] + Cells(lat, 0) * (c[1] + Cells(lat, 1) * c[2]);
}

/// A world point at parameters stu, rounded to Real, with its parameters recomputed in double from the rounded
/// point (the reference's equation 2).
template <typename Real>
std::pair<ffd::Vec3<Real>, Vec> PointAt(const GridLattice& lat, const Vec& stu)
{
  const ffd::Vec3<Real> x = ffdtest::ToKernel<Real>(ffdtest::ToWorld(lat.F, stu));
  return { x, ffdref::Parameters(lat.F, ffdtest::ToRef(x)) };
}

/// Random parameters whose local coordinate lies in [margin, 1 - margin] of a random cell on every axis.
Vec InteriorParameters(ffdtest::Rng& rng, const GridLattice& lat, double margin)
{
  Vec stu;
  for (int a = 0; a < 3; ++a)
  {
    const int c = std::uniform_int_distribution<int>(0, Cells(lat, a) - 1)(rng);
    stu[a] = (c + ffdtest::Uniform(rng, margin, 1.0 - margin)) / Cells(lat, a);
  }
  return stu;
}

/// The deformed position of x under the clamping policy, from the reference: x plus the displacement at the
/// frame point of clamped parameters.
Vec ClampedReference(const GridLattice& lat, const Vec& x)
{
  Vec stu = ffdref::Parameters(lat.F, x);
  for (double& v : stu)
  {
    v = std::min(std::max(v, 0.0), 1.0);
  }
  const Vec xc = ffdtest::ToWorld(lat.F, stu);
  const Vec d = ffdref::Sub(ffdref::DeformLocal(lat.Basis, lat.F, lat.Divisions.data(), lat.Points, xc), xc);
  return { x[0] + d[0], x[1] + d[1], x[2] + d[2] };
}

FFD_REAL_TYPED_TEST_SUITE(FFDGridDeformationTest);

TYPED_TEST(FFDGridDeformationTest, DeformMatchesReference)
{
  // Every basis, random lattices and points of the frame: BindToGrid then Deform (both overloads) against
  // ffdref::DeformLocal over the exact lattice and frame. Tolerance: PositionTolerance(), which covers the
  // rounding of frame, displacements and point to Real.
  using Real = TypeParam;
  ffdtest::Rng rng(501);
  WorstRatio worst("worst_error_over_tolerance");
  ffdtest::ForEachRandomLattice(rng, 30, 6,
    [&](const GridLattice& lat)
    {
      const double scale = ffdtest::LatticeScale(lat.Points);
      WithKernel<Real>(lat,
        [&](const auto& k)
        {
          for (int p = 0; p < 30; ++p)
          {
            const ffd::Vec3<Real> x = PointAt<Real>(lat, ffdtest::RandomVec(rng, 0.0, 1.0)).first;
            const Vec xd = ffdtest::ToRef(x);
            const int cell = k.Bind(x, false);
            ASSERT_GE(cell, 0) << lat.Name() << " point " << p;
            ffd::Mat3<Real> j;
            const Vec got = ffdtest::ToRef(k.D.Deform(x, cell));
            const Vec gotJ = ffdtest::ToRef(k.D.Deform(x, cell, j));
            const Vec want = ffdref::DeformLocal(lat.Basis, lat.F, lat.Divisions.data(), lat.Points, xd);
            const double tol = PositionTolerance(scale, xd, lat.F, j);
            ASSERT_TRUE(ffdtest::MaxDiffWithin(got, want, tol, &worst)) << lat.Name() << " point " << p;
            ASSERT_TRUE(ffdtest::MaxDiffWithin(gotJ, want, tol)) << lat.Name() << " point " << p << " (with Jacobian)";
          }
        });
    });
}

TYPED_TEST(FFDGridDeformationTest, AffineMotionIsReproduced)
{
  // Every control point moved by x -> A x + b: the displacement form gives A X + b at every point of the frame,
  // and its Jacobian is A. Tolerances: EvaluationTolerance() times (mapped scale + |X|) on positions; on the
  // Jacobian 100 EvaluationTolerance() times max(1, |A|): its entries sum n-scaled weights (n <= 6) times
  // displacements of the mapped scale, times the dual vectors (|dual| <= 10 for these frames).
  using Real = TypeParam;
  ffdtest::Rng rng(502);
  WorstRatio worst("worst_error_over_tolerance");
  ffdtest::ForEachRandomLattice(rng, 20, 6,
    [&](GridLattice& lat)
    {
      const ffdtest::Affine map = ffdtest::RandomAffine(rng, 0.5);
      const double mmax = ffdtest::MaxAbsEntry(map.A, 1.0);
      for (size_t i = 0; i < lat.Rest.size(); ++i)
      {
        lat.Points[i] = map(lat.Rest[i]);
      }
      const double scale = ffdtest::LatticeScale(lat.Points);
      WithKernel<Real>(lat,
        [&](const auto& k)
        {
          for (int p = 0; p < 30; ++p)
          {
            const ffd::Vec3<Real> x = PointAt<Real>(lat, ffdtest::RandomVec(rng, 0.0, 1.0)).first;
            const Vec xd = ffdtest::ToRef(x);
            const int cell = k.Bind(x, false);
            ASSERT_GE(cell, 0);
            ffd::Mat3<Real> j;
            const Vec got = ffdtest::ToRef(k.D.Deform(x, cell, j));
            const double tol = EvaluationTolerance<Real>() * (scale + MaxAbs(xd));
            ASSERT_TRUE(ffdtest::MaxDiffWithin(got, map(xd), tol, &worst)) << lat.Name() << " point " << p;
            const double tolJ = 100.0 * EvaluationTolerance<Real>() * mmax;
            ASSERT_TRUE(ffdtest::MatrixNear(j, map.A, tolJ, "J", &worst)) << lat.Name() << " point " << p;
          }
        });
    });
}

/// Central differences, h = 1e-6, of a map of world points: fd[r][c] = d f_r / d x_c.
template <typename F>
ffdtest::Mat CentralDifferences(const Vec& x, F&& f)
{
  return ffdtest::CentralDifferences(x, 1e-6, std::forward<F>(f));
}

/// The reference's Jacobian of the lattice's deformation at x: CentralDifferences() of ffdref::DeformLocal.
ffdtest::Mat ReferenceJacobianAt(const GridLattice& lat, const Vec& x)
{
  return CentralDifferences(
    x, [&](const Vec& y) { return ffdref::DeformLocal(lat.Basis, lat.F, lat.Divisions.data(), lat.Points, y); });
}

TYPED_TEST(FFDGridDeformationTest, JacobianMatchesCentralDifferences)
{
  // Deform's Jacobian against central differences of ffdref::DeformLocal in world coordinates, at points at
  // least 0.01 (local coordinate) from their cell's faces: a world step of 1e-6 moves the parameters by at most
  // 1e-5 (|dual| <= 10), so the differences stay in one polynomial piece. Tolerance: GradientTolerance() times
  // max(1, |dX_ffd/dX|_max) per entry.
  using Real = TypeParam;
  ffdtest::Rng rng(503);
  WorstRatio worst("worst_error_over_tolerance");
  ffdtest::ForEachRandomLattice(rng, 20, 6,
    [&](const GridLattice& lat)
    {
      WithKernel<Real>(lat,
        [&](const auto& k)
        {
          for (int p = 0; p < 10; ++p)
          {
            const ffd::Vec3<Real> x = PointAt<Real>(lat, InteriorParameters(rng, lat, 0.01)).first;
            const int cell = k.Bind(x, false);
            ASSERT_GE(cell, 0);
            ffd::Mat3<Real> j;
            k.D.Deform(x, cell, j);
            const ffdtest::Mat fd = ReferenceJacobianAt(lat, ffdtest::ToRef(x));
            const double tol = GradientTolerance<Real>() * ffdtest::MaxAbsEntry(fd, 1.0);
            ASSERT_TRUE(ffdtest::MatrixNear(j, fd, tol, "J", &worst)) << lat.Name() << " point " << p;
          }
        });
    });
}

TYPED_TEST(FFDGridDeformationTest, TransformNormalMatchesDeformedTangents)
{
  // A unit normal n = t1 x t2 / |t1 x t2| of a surface through X is carried to the normal of the deformed
  // surface, (J t1) x (J t2) normalised, with J from central differences of ffdref::DeformLocal (as in
  // JacobianMatchesCentralDifferences); folded points (det J < 0) included, where the cross product of the
  // deformed tangents, not J^-T n, is the deformed surface's orientation. Tolerance per component:
  // 10 GradientTolerance() |J|max^2 / |(J t1) x (J t2)| (the cross product's error relative to its length);
  // points where that length is under 0.1 are skipped (the normal is ill-defined there).
  using Real = TypeParam;
  ffdtest::Rng rng(508);
  WorstRatio worst("worst_error_over_tolerance");
  int folded = 0;
  ffdtest::ForEachRandomLattice(rng, 20, 4,
    [&](const GridLattice& lat)
    {
      WithKernel<Real>(lat,
        [&](const auto& k)
        {
          for (int p = 0; p < 10; ++p)
          {
            const ffd::Vec3<Real> x = PointAt<Real>(lat, InteriorParameters(rng, lat, 0.01)).first;
            const int cell = k.Bind(x, false);
            ASSERT_GE(cell, 0);
            ffd::Mat3<Real> j;
            k.D.Deform(x, cell, j);
            const ffdtest::Mat fd = ReferenceJacobianAt(lat, ffdtest::ToRef(x));
            const double jmax = ffdtest::MaxAbsEntry(fd, 1.0);
            const Vec t1 = ffdtest::RandomVec(rng, -1.0, 1.0), t2 = ffdtest::RandomVec(rng, -1.0, 1.0);
            const Vec n = ffdref::Cross(t1, t2);
            const double nn = ffdtest::Norm(n);
            if (nn < 0.1)
            {
              continue;
            }
            const Vec m = ffdref::Cross(ffdtest::Product(fd, t1), ffdtest::Product(fd, t2));
            const double mm = ffdtest::Norm(m);
            if (mm < 0.1 * nn)
            {
              continue;
            }
            folded += ffd::Determinant(j) < Real(0) ? 1 : 0;
            const ffd::Vec3<Real> unit = ffdtest::ToKernel<Real>({ n[0] / nn, n[1] / nn, n[2] / nn });
            const Vec got = ffdtest::ToRef(ffd::TransformNormal(j, unit));
            const Vec want = { m[0] / mm, m[1] / mm, m[2] / mm };
            const double tol = 10.0 * GradientTolerance<Real>() * jmax * jmax * nn / mm;
            ASSERT_TRUE(ffdtest::MaxDiffWithin(got, want, tol, &worst)) << lat.Name() << " point " << p;
          }
        });
    });
  ::testing::Test::RecordProperty("folded_points", folded);
}

TYPED_TEST(FFDGridDeformationTest, BindToGridFindsCells)
{
  // Expected cells from the test's own arithmetic, floor(s cells) per axis on the parameters of the rounded point
  // in double, flattened as ci + cx (cj + cy ck):
  //  - points inside (skipped within 1e-3 of a cell face, where Real's rounding may pick either cell);
  //  - the 27 combinations of s in {0, interior, 1} per axis (corners, edges, faces of the frame): s = 0 goes to
  //    cell 0, s = 1 to the last cell, with either policy, and these points deform like the reference (points
  //    on the frame's faces are not left behind; tolerance PositionTolerance());
  //  - interior voxel faces s = c/n: cell c - 1 or c.
  using Real = TypeParam;
  ffdtest::Rng rng(504);
  ffdtest::ForEachRandomLattice(rng, 20, 6,
    [&](const GridLattice& lat)
    {
      const double scale = ffdtest::LatticeScale(lat.Points);
      WithKernel<Real>(lat,
        [&](const auto& k)
        {
          for (int p = 0; p < 100; ++p)
          {
            const auto [x, stu] = PointAt<Real>(lat, ffdtest::RandomVec(rng, 0.0, 1.0));
            int c[3];
            bool nearFace = false;
            for (int a = 0; a < 3; ++a)
            {
              const double v = stu[a] * Cells(lat, a);
              c[a] = std::min(int(std::floor(v)), Cells(lat, a) - 1);
              nearFace = nearFace || std::fabs(v - std::round(v)) < 1e-3;
            }
            if (!nearFace)
            {
              ASSERT_EQ(k.Bind(x, false), FlatCell(lat, c)) << lat.Name() << " point " << p;
              ASSERT_EQ(k.Bind(x, true), FlatCell(lat, c)) << lat.Name() << " point " << p;
            }
          }
          for (int combo = 0; combo < 27; ++combo)
          {
            const int kind[3] = { combo % 3, (combo / 3) % 3, combo / 9 }; // 0: s = 0, 1: interior, 2: s = 1
            Vec stu;
            int c[3];
            for (int a = 0; a < 3; ++a)
            {
              const int cells = Cells(lat, a);
              const int random = std::uniform_int_distribution<int>(0, cells - 1)(rng);
              c[a] = kind[a] == 0 ? 0 : (kind[a] == 2 ? cells - 1 : random);
              stu[a] = kind[a] == 0 ? 0.0 : (kind[a] == 2 ? 1.0 : (c[a] + ffdtest::Uniform(rng, 0.01, 0.99)) / cells);
            }
            const ffd::Vec3<Real> x = PointAt<Real>(lat, stu).first;
            const Vec xd = ffdtest::ToRef(x);
            const int cell = k.Bind(x, false);
            ASSERT_EQ(cell, FlatCell(lat, c)) << lat.Name() << " kinds " << kind[0] << kind[1] << kind[2];
            ASSERT_EQ(k.Bind(x, true), cell) << lat.Name() << " kinds " << kind[0] << kind[1] << kind[2];
            const Vec want = ffdref::DeformLocal(lat.Basis, lat.F, lat.Divisions.data(), lat.Points, xd);
            ffd::Mat3<Real> j;
            const Vec got = ffdtest::ToRef(k.D.Deform(x, cell, j));
            ASSERT_TRUE(ffdtest::MaxDiffWithin(got, want, PositionTolerance(scale, xd, lat.F, j)))
              << lat.Name() << " kinds " << kind[0] << kind[1] << kind[2];
          }
          for (int a = 0; a < 3; ++a)
          {
            for (int face = 1; face < Cells(lat, a); ++face)
            {
              Vec stu = InteriorParameters(rng, lat, 0.01); // the other axes away from their cells' faces
              int lo[3], hi[3];
              for (int q = 0; q < 3; ++q)
              {
                lo[q] = hi[q] = int(std::floor(stu[q] * Cells(lat, q)));
              }
              stu[a] = double(face) / Cells(lat, a);
              lo[a] = face - 1;
              hi[a] = face;
              const int cell = k.Bind(PointAt<Real>(lat, stu).first, false);
              ASSERT_TRUE(cell == FlatCell(lat, lo) || cell == FlatCell(lat, hi))
                << lat.Name() << " face " << face << " of axis " << a << ": cell " << cell;
            }
          }
        });
    });
}

TYPED_TEST(FFDGridDeformationTest, BindToGridOutsideAndNonFinite)
{
  // Points just outside the frame on a random axis: within ParametricTolerance() they are inside (edge cell);
  // beyond 2 ParametricTolerance() they get -1 without clamping and the edge cell with clamping (the band between
  // is left alone: there Real's rounding of the point decides). Far outside (s in [-2, -0.01] or [1.01, 3]):
  // -1, or the clamped cell. NaN or an infinity in any coordinate: -1 with either policy.
  using Real = TypeParam;
  ffdtest::Rng rng(505);
  const double band = double(ffd::ParametricTolerance<Real>());
  ffdtest::ForEachRandomLattice(rng, 10, 6,
    [&](const GridLattice& lat)
    {
      WithKernel<Real>(lat,
        [&](const auto& k)
        {
          for (int p = 0; p < 200; ++p)
          {
            const int axis = std::uniform_int_distribution<int>(0, 2)(rng);
            const bool high = rng() % 2 == 1;
            const bool far = p % 2 == 0;
            Vec stu = InteriorParameters(rng, lat, 0.01);
            const double out = far ? ffdtest::Uniform(rng, 0.01, 2.0) : ffdtest::Uniform(rng, -3.0 * band, 3.0 * band);
            stu[axis] = high ? 1.0 + out : -out;
            const auto [x, seen] = PointAt<Real>(lat, stu);
            const double beyond = high ? seen[axis] - 1.0 : -seen[axis];
            int c[3];
            for (int a = 0; a < 3; ++a)
            {
              c[a] = std::min(std::max(int(std::floor(seen[a] * Cells(lat, a))), 0), Cells(lat, a) - 1);
            }
            if (beyond <= 0.5 * band)
            {
              ASSERT_EQ(k.Bind(x, false), FlatCell(lat, c)) << lat.Name() << " " << beyond << " outside";
              ASSERT_EQ(k.Bind(x, true), FlatCell(lat, c)) << lat.Name() << " " << beyond << " outside";
            }
            else if (beyond >= 2.0 * band)
            {
              ASSERT_EQ(k.Bind(x, false), -1) << lat.Name() << " " << beyond << " outside";
              ASSERT_EQ(k.Bind(x, true), FlatCell(lat, c)) << lat.Name() << " " << beyond << " outside";
            }
          }
          const Real bad[3] = { std::numeric_limits<Real>::quiet_NaN(), std::numeric_limits<Real>::infinity(),
            -std::numeric_limits<Real>::infinity() };
          for (int a = 0; a < 3; ++a)
          {
            for (Real v : bad)
            {
              ffd::Vec3<Real> x = PointAt<Real>(lat, { 0.5, 0.5, 0.5 }).first;
              (a == 0 ? x.x : (a == 1 ? x.y : x.z)) = v;
              ASSERT_EQ(k.Bind(x, false), -1) << lat.Name() << " coordinate " << a << " = " << v;
              ASSERT_EQ(k.Bind(x, true), -1) << lat.Name() << " coordinate " << a << " = " << v;
            }
          }
        });
    });
}

TYPED_TEST(FFDGridDeformationTest, ClampingGivesEdgeDisplacement)
{
  // The clamping policy: a point outside takes the displacement of the frame point of
  // clamped parameters, X + D(clamp(s, t, u)), checked against the reference at that frame point (tolerance
  // PositionTolerance()). Its Jacobian drops the clamped directions: against central
  // differences of the reference's clamped map (GradientTolerance() times max(1, |J|)), and exactly along the
  // frame edge of a clamped axis, (J - I) E_a = 0 (tolerance 100 eps(Real) |J| |E_a|: rounding of the dual
  // basis, whose product with E_a is the unit vector e_a). Parameters are 0.01 or more outside (or inside, away
  // from cell faces), so the differences do not cross a face.
  using Real = TypeParam;
  ffdtest::Rng rng(506);
  WorstRatio worst("worst_error_over_tolerance");
  ffdtest::ForEachRandomLattice(rng, 20, 6,
    [&](const GridLattice& lat)
    {
      const double scale = ffdtest::LatticeScale(lat.Points);
      const Vec edges[3] = { lat.F.S, lat.F.T, lat.F.U };
      WithKernel<Real>(lat,
        [&](const auto& k)
        {
          for (int p = 0; p < 20; ++p)
          {
            Vec stu = InteriorParameters(rng, lat, 0.01);
            bool clamped[3] = { false, false, false };
            for (int a = 0; a < 3; ++a)
            {
              if (rng() % 2 == 0 || (a == 2 && !clamped[0] && !clamped[1]))
              {
                clamped[a] = true;
                const double out = ffdtest::Uniform(rng, 0.01, 0.5);
                stu[a] = rng() % 2 == 0 ? -out : 1.0 + out;
              }
            }
            const ffd::Vec3<Real> x = PointAt<Real>(lat, stu).first;
            const Vec xd = ffdtest::ToRef(x);
            ASSERT_EQ(k.Bind(x, false), -1) << lat.Name();
            const int cell = k.Bind(x, true);
            ASSERT_GE(cell, 0) << lat.Name();
            ffd::Mat3<Real> j;
            const Vec got = ffdtest::ToRef(k.D.Deform(x, cell, j));
            const Vec gotPlain = ffdtest::ToRef(k.D.Deform(x, cell));
            const Vec want = ClampedReference(lat, xd);
            const double tol = PositionTolerance(scale, xd, lat.F, j);
            ASSERT_TRUE(ffdtest::MaxDiffWithin(got, want, tol, &worst)) << lat.Name() << " point " << p;
            ASSERT_TRUE(ffdtest::MaxDiffWithin(gotPlain, want, tol)) << lat.Name() << " point " << p;

            const ffdtest::Mat fd = CentralDifferences(xd, [&](const Vec& y) { return ClampedReference(lat, y); });
            const double jmax = std::max(ffdtest::MaxAbsEntry(fd, 1.0), ffdtest::MaxAbsEntry(j, 1.0));
            const double tolJ = GradientTolerance<Real>() * jmax;
            ASSERT_TRUE(ffdtest::MatrixNear(j, fd, tolJ, "J", &worst)) << lat.Name() << " point " << p;
            for (int a = 0; a < 3; ++a)
            {
              if (!clamped[a])
              {
                continue;
              }
              const Vec& e = edges[a];
              Vec je;
              for (int r = 0; r < 3; ++r)
              {
                je[r] = double(j.M[r][0]) * e[0] + double(j.M[r][1]) * e[1] + double(j.M[r][2]) * e[2];
              }
              ASSERT_TRUE(ffdtest::VectorNear(je, e, 100.0 * Eps<Real>() * jmax * ffdtest::Norm(e)))
                << lat.Name() << " (J - I) E along clamped axis " << a;
            }
          }
        });
    });
}

/**
 * The voxels [lo, hi] along an axis of n voxels that control point i influences, from the bases' definitions:
 * Bezier voxel c of degree d owns the points d c .. d c + d (a shared face point belongs to both neighbours),
 * B-spline voxel c is influenced by the points c .. c + 3, the global basis couples every point to every voxel.
 */
std::pair<int, int> SupportVoxels(Basis b, int n, int i)
{
  if (b == Basis::Bernstein)
  {
    return { 0, n - 1 };
  }
  if (b == Basis::CubicBSpline)
  {
    return { std::max(i - 3, 0), std::min(i, n - 1) };
  }
  const int d = int(b);
  return { std::max((i + d - 1) / d - 1, 0), std::min(i / d, n - 1) };
}

TYPED_TEST(FFDGridDeformationTest, MovingOneControlPointIsLocal)
{
  // One random control point moved by up to 0.5: points of voxels outside its support (SupportVoxels, computed
  // here) keep their deformed position bit for bit, and points inside change by what the reference says
  // (tolerance: the sum of both evaluations' PositionTolerance()). Local lattices have 4..6 voxels per axis, and
  // half of the points are drawn in the support's voxels, so that both kinds of points occur. Also:
  // ffd::VoxelSupport (used for culling) lists exactly the control points whose SupportVoxels hold the voxel.
  using Real = TypeParam;
  ffdtest::Rng rng(507);
  WorstRatio worst("worst_error_over_tolerance");
  for (Basis b : ffdtest::AllBases)
  {
    for (int trial = 0; trial < 20; ++trial)
    {
      GridLattice lat;
      do
      {
        lat = ffdtest::RandomGridLattice(rng, b, b == Basis::Bernstein ? 4 : 6);
      } while (b != Basis::Bernstein && std::min({ lat.Divisions[0], lat.Divisions[1], lat.Divisions[2] }) < 4);
      const std::array<int, 3> dims = lat.Dims();
      int moved[3];
      for (int a = 0; a < 3; ++a)
      {
        moved[a] = std::uniform_int_distribution<int>(0, dims[a] - 1)(rng);
        for (int c = 0; c < lat.Divisions[a]; ++c)
        {
          int first = 0, count = 0;
          ffd::VoxelSupport(ffd::GridBasis(int(b)), lat.Divisions[a], c, first, count);
          for (int i = 0; i < dims[a]; ++i)
          {
            const std::pair<int, int> support = SupportVoxels(b, lat.Divisions[a], i);
            ASSERT_EQ(i >= first && i < first + count, c >= support.first && c <= support.second)
              << lat.Name() << " voxel " << c << " point " << i;
          }
        }
      }
      GridLattice after = lat;
      Vec& p = after.Points[moved[0] + dims[0] * (moved[1] + dims[1] * moved[2])];
      const Vec delta = ffdtest::RandomVec(rng, -0.5, 0.5);
      p = { p[0] + delta[0], p[1] + delta[1], p[2] + delta[2] };
      const double scale = std::max(ffdtest::LatticeScale(lat.Points), ffdtest::LatticeScale(after.Points));

      int inside = 0, outside = 0;
      WithKernel<Real>(lat,
        [&](const auto& k0)
        {
          WithKernel<Real>(after,
            [&](const auto& k1)
            {
              if ((k0.D.CellTable == nullptr) != (k1.D.CellTable == nullptr))
              {
                return; // compare like with like: a cell table rounds differently
              }
              for (int q = 0; q < 200; ++q)
              {
                Vec drawn = ffdtest::RandomVec(rng, 0.0, 1.0);
                for (int a = 0; a < 3 && q % 2 == 0; ++a)
                {
                  const std::pair<int, int> support = SupportVoxels(b, lat.Divisions[a], moved[a]);
                  const int c = std::uniform_int_distribution<int>(support.first, support.second)(rng);
                  drawn[a] = (c + ffdtest::Uniform(rng, 0.0, 1.0)) / lat.Divisions[a];
                }
                const auto [x, stu] = PointAt<Real>(lat, drawn);
                const Vec xd = ffdtest::ToRef(x);
                bool inSupport = true, nearFace = false;
                for (int a = 0; a < 3; ++a)
                {
                  const double v = stu[a] * lat.Divisions[a];
                  const int c = std::min(int(std::floor(v)), lat.Divisions[a] - 1);
                  const std::pair<int, int> support = SupportVoxels(b, lat.Divisions[a], moved[a]);
                  inSupport = inSupport && c >= support.first && c <= support.second;
                  nearFace = nearFace || std::fabs(v - std::round(v)) < 1e-3;
                }
                if (nearFace) // Real's rounding may bind it to the neighbouring voxel
                {
                  continue;
                }
                const int cell = k0.Bind(x, false);
                ASSERT_GE(cell, 0);
                ffd::Mat3<Real> j0, j1;
                const ffd::Vec3<Real> y0 = k0.D.Deform(x, cell, j0);
                const ffd::Vec3<Real> y1 = k1.D.Deform(x, cell, j1);
                if (!inSupport)
                {
                  ++outside;
                  ASSERT_TRUE(y0.x == y1.x && y0.y == y1.y && y0.z == y1.z) << lat.Name() << " point " << q;
                  continue;
                }
                ++inside;
                const Vec want = ffdref::Sub(ffdref::DeformLocal(b, after.F, after.Divisions.data(), after.Points, xd),
                  ffdref::DeformLocal(b, lat.F, lat.Divisions.data(), lat.Points, xd));
                const Vec got = ffdref::Sub(ffdtest::ToRef(y1), ffdtest::ToRef(y0));
                const double tol = PositionTolerance(scale, xd, lat.F, j0) + PositionTolerance(scale, xd, lat.F, j1);
                ASSERT_TRUE(ffdtest::MaxDiffWithin(got, want, tol, &worst)) << lat.Name() << " point " << q;
              }
            });
        });
      ASSERT_GT(inside, 0) << lat.Name();
      if (b != Basis::Bernstein)
      {
        ASSERT_GT(outside, 0) << lat.Name();
      }
    }
  }
}

} // namespace
