// SPDX-License-Identifier: BSD-3-Clause
// Tetrahedral FFD kernels (FFDTetrahedra.h, paper equation 5) against the float64 reference of
// FFDReference.h, which computes barycentric weights as ratios of signed volumes and deforms in the absolute
// form sum w P, sharing no code with the kernels' dual vectors and affine maps.

#include "FFDKernelTestUtilities.h"
#include "FFDTetrahedra.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>

namespace
{
using ffdref::Vec;
using ffdtest::DualNorm;
using ffdtest::Eps;
using ffdtest::MaxAbs;
using ffdtest::Norm;
using ffdtest::WorldScale;

FFD_REAL_TYPED_TEST_SUITE(FFDTetrahedraTest);

constexpr int NumberOfTetrahedra = 200;
constexpr int PointsPerTetrahedron = 50;

// A random well-shaped tetrahedron A, A + S, A + T, A + U of a random frame (relative volume >= 0.2), in a
// random order of its nodes so that half of them are inverted (negative orientation).
struct Tetrahedron
{
  ffdref::Frame Frame; // A, B - A, C - A, D - A of the ordered nodes
  std::array<Vec, 4> Nodes;
};

Tetrahedron RandomTetrahedron(ffdtest::Rng& rng)
{
  const ffdref::Frame f = ffdtest::RandomFrame(rng);
  std::array<Vec, 4> nodes = { f.X0, ffdtest::ToWorld(f, { 1, 0, 0 }), ffdtest::ToWorld(f, { 0, 1, 0 }),
    ffdtest::ToWorld(f, { 0, 0, 1 }) };
  if (rng() % 2)
  {
    std::swap(nodes[2], nodes[3]);
  }
  return { { nodes[0], ffdref::Sub(nodes[1], nodes[0]), ffdref::Sub(nodes[2], nodes[0]),
             ffdref::Sub(nodes[3], nodes[0]) },
    nodes };
}

ffd::Frame<double> KernelFrame(const Tetrahedron& t)
{
  EXPECT_EQ(ffd::CheckTetrahedron(t.Nodes[0].data(), t.Nodes[1].data(), t.Nodes[2].data(), t.Nodes[3].data()),
    ffd::FrameStatus::Valid);
  return ffd::TetrahedronFrame(t.Nodes[0].data(), t.Nodes[1].data(), t.Nodes[2].data(), t.Nodes[3].data());
}

// A point of weights (s, t, u) drawn from [-0.5, 1.5]: inside and outside the tetrahedron.
Vec RandomPoint(ffdtest::Rng& rng, const Tetrahedron& t)
{
  return ffdtest::ToWorld(t.Frame, ffdtest::RandomVec(rng, -0.5, 1.5));
}

TYPED_TEST(FFDTetrahedraTest, WeightsAreTheVolumeRatios)
{
  using Real = TypeParam;
  ffdtest::Rng rng(501);
  for (int trial = 0; trial < NumberOfTetrahedra; ++trial)
  {
    const Tetrahedron t = RandomTetrahedron(rng);
    const ffd::Frame<Real> frame = KernelFrame(t).template As<Real>();
    for (int i = 0; i < PointsPerTetrahedron; ++i)
    {
      const ffd::Vec3<Real> x = ffdtest::ToKernel<Real>(RandomPoint(rng, t));
      const Vec xd = ffdtest::ToRef(x);
      const std::array<double, 4> expected =
        ffdref::TetrahedronWeights(t.Nodes[0], t.Nodes[1], t.Nodes[2], t.Nodes[3], xd);
      const ffd::Vec3<Real> stu = frame.ToParametric(x);
      // Rounding of x - A and of the dual vectors, amplified by their norm.
      const double tol = 16.0 * Eps<Real>() * DualNorm(t.Frame) * WorldScale(t.Frame, xd);
      EXPECT_NEAR(stu.x, expected[1], tol);
      EXPECT_NEAR(stu.y, expected[2], tol);
      EXPECT_NEAR(stu.z, expected[3], tol);
      EXPECT_NEAR(1.0 - double(stu.x) - double(stu.y) - double(stu.z), expected[0], 3 * tol);
      const double margin = std::min({ expected[0], expected[1], expected[2], expected[3] });
      EXPECT_NEAR(ffd::InsideMargin(stu), margin, 4 * tol);
    }
  }
}

TYPED_TEST(FFDTetrahedraTest, MapIsTheWeightedSumOfNodes)
{
  using Real = TypeParam;
  ffdtest::Rng rng(502);
  for (int trial = 0; trial < NumberOfTetrahedra; ++trial)
  {
    const Tetrahedron t = RandomTetrahedron(rng);
    std::array<Vec, 4> moved;
    ffd::Vec3<double> d[4];
    double largest = 0.0;
    for (int n = 0; n < 4; ++n)
    {
      const Vec displacement = ffdtest::RandomVec(rng, -0.5, 0.5);
      moved[n] = { t.Nodes[n][0] + displacement[0], t.Nodes[n][1] + displacement[1], t.Nodes[n][2] + displacement[2] };
      d[n] = ffdtest::ToKernel<double>(displacement);
      largest = std::max(largest, MaxAbs(displacement));
    }
    const ffd::TetrahedronMap<Real> map =
      ffd::MakeTetrahedronMap(KernelFrame(t), d[0], d[1], d[2], d[3]).template As<Real>();
    for (int i = 0; i < PointsPerTetrahedron; ++i)
    {
      const ffd::Vec3<Real> x = ffdtest::ToKernel<Real>(RandomPoint(rng, t));
      const Vec xd = ffdtest::ToRef(x);
      const Vec expected = ffdref::DeformInTetrahedron(t.Nodes, moved, xd);
      // Weights as above times displacements of at most `largest`, and the rounding of x + D.
      const double tol = 64.0 * Eps<Real>() * WorldScale(t.Frame, xd) * (1.0 + DualNorm(t.Frame) * largest);
      const Vec y = ffdtest::ToRef(map.Deform(x));
      EXPECT_TRUE(ffdtest::VectorNear(y, expected, tol)) << "tetrahedron " << trial << " point " << i;
    }
  }
}

TYPED_TEST(FFDTetrahedraTest, RestLatticeIsTheExactIdentity)
{
  using Real = TypeParam;
  ffdtest::Rng rng(503);
  const ffd::Vec3<double> zero = { 0, 0, 0 };
  for (int trial = 0; trial < NumberOfTetrahedra; ++trial)
  {
    const Tetrahedron t = RandomTetrahedron(rng);
    const ffd::TetrahedronMap<Real> map =
      ffd::MakeTetrahedronMap(KernelFrame(t), zero, zero, zero, zero).template As<Real>();
    for (int i = 0; i < PointsPerTetrahedron; ++i)
    {
      const ffd::Vec3<Real> x = ffdtest::ToKernel<Real>(RandomPoint(rng, t));
      EXPECT_TRUE(ffdtest::VectorEqual(map.Deform(x), x)) << "tetrahedron " << trial << " point " << i;
    }
    EXPECT_TRUE(ffdtest::MatrixEqual(map.Jacobian(), ffd::Mat3<Real>::Identity())) << "tetrahedron " << trial;
  }
}

TYPED_TEST(FFDTetrahedraTest, AffineMotionOfTheNodesIsReproduced)
{
  using Real = TypeParam;
  ffdtest::Rng rng(504);
  for (int trial = 0; trial < NumberOfTetrahedra; ++trial)
  {
    const Tetrahedron t = RandomTetrahedron(rng);
    // y = M x + b with M = I + a random matrix of entries in [-0.3, 0.3].
    const ffdtest::Affine affine = ffdtest::RandomAffine(rng, 0.3);
    ffd::Vec3<double> d[4];
    for (int n = 0; n < 4; ++n)
    {
      d[n] = ffdtest::ToKernel<double>(ffdref::Sub(affine(t.Nodes[n]), t.Nodes[n]));
    }
    const ffd::TetrahedronMap<Real> map =
      ffd::MakeTetrahedronMap(KernelFrame(t), d[0], d[1], d[2], d[3]).template As<Real>();
    EXPECT_TRUE(ffdtest::MatrixNear(
      map.Jacobian(), affine.A, 64.0 * Eps<Real>() * DualNorm(t.Frame) * WorldScale(t.Frame, affine.B)))
      << "tetrahedron " << trial;
    for (int i = 0; i < PointsPerTetrahedron; ++i)
    {
      const ffd::Vec3<Real> x = ffdtest::ToKernel<Real>(RandomPoint(rng, t));
      const Vec xd = ffdtest::ToRef(x);
      const Vec expected = affine(xd);
      const double tol = 64.0 * Eps<Real>() * WorldScale(t.Frame, xd) * (1.0 + 2.0 * DualNorm(t.Frame));
      EXPECT_TRUE(ffdtest::VectorNear(ffdtest::ToRef(map.Deform(x)), expected, tol))
        << "tetrahedron " << trial << " point " << i;
    }
  }
}

TEST(FFDTetrahedra, CheckTetrahedronRejectsFlatAndNonFiniteAndAcceptsInverted)
{
  const double a[3] = { 0, 0, 0 }, b[3] = { 1, 0, 0 }, c[3] = { 0, 1, 0 }, d[3] = { 0, 0, 1 };
  EXPECT_EQ(ffd::CheckTetrahedron(a, b, c, d), ffd::FrameStatus::Valid);
  EXPECT_EQ(ffd::CheckTetrahedron(a, c, b, d), ffd::FrameStatus::Valid); // inverted
  const double onPlane[3] = { 0.3, 0.4, 0.0 }, nearPlane[3] = { 0.3, 0.4, 1e-14 };
  EXPECT_EQ(ffd::CheckTetrahedron(a, b, c, onPlane), ffd::FrameStatus::ZeroVolume);
  EXPECT_EQ(ffd::CheckTetrahedron(a, b, c, nearPlane), ffd::FrameStatus::ZeroVolume);
  EXPECT_EQ(ffd::CheckTetrahedron(a, b, b, d), ffd::FrameStatus::ZeroVolume); // two nodes at one place
  const double nan[3] = { std::numeric_limits<double>::quiet_NaN(), 0, 0 };
  EXPECT_EQ(ffd::CheckTetrahedron(a, b, c, nan), ffd::FrameStatus::NonFinite);
}

// The gradient of the nearest point of a tetrahedron's boundary feature: a projection onto the face's plane,
// onto the edge's line, or zero at a node; checked against the feature's own vectors.
TEST(FFDTetrahedra, ClosestPointGradientProjectsOntoTheFeature)
{
  ffdtest::Rng rng(505);
  for (int trial = 0; trial < NumberOfTetrahedra; ++trial)
  {
    const Tetrahedron t = RandomTetrahedron(rng);
    const ffd::Frame<double> frame = KernelFrame(t);
    const auto apply = [](const ffd::Mat3<double>& p, const Vec& v)
    { return ffdtest::ToRef(p * ffdtest::ToKernel<double>(v)); };
    const double tol = 1e-12 * (1.0 + DualNorm(t.Frame));
    // A point on face BCD (weight of A zero): tangents BC, BD are kept, the face normal is removed.
    const double s = ffdtest::Uniform(rng, 0.1, 0.5), u = ffdtest::Uniform(rng, 0.1, 0.4);
    const ffd::Mat3<double> face = ffd::ClosestPointGradient(frame, { s, 1.0 - s - u, u }, 1e-9);
    const Vec bc = ffdref::Sub(t.Nodes[2], t.Nodes[1]), bd = ffdref::Sub(t.Nodes[3], t.Nodes[1]);
    const Vec normal = ffdref::Cross(bc, bd);
    const Vec zero = { 0.0, 0.0, 0.0 };
    EXPECT_TRUE(ffdtest::VectorNear(apply(face, bc), bc, tol)) << "face, BC; tetrahedron " << trial;
    EXPECT_TRUE(ffdtest::VectorNear(apply(face, bd), bd, tol)) << "face, BD; tetrahedron " << trial;
    EXPECT_TRUE(ffdtest::VectorNear(apply(face, normal), zero, tol * Norm(normal)))
      << "face, normal; tetrahedron " << trial;
    // A point on edge AB: AB is kept, directions across it are removed.
    const ffd::Mat3<double> edge = ffd::ClosestPointGradient(frame, { 0.4, 0.0, 0.0 }, 1e-9);
    const Vec ab = ffdref::Sub(t.Nodes[1], t.Nodes[0]);
    const Vec across = ffdref::Cross(ab, bc);
    const Vec across2 = ffdref::Cross(ab, across);
    EXPECT_TRUE(ffdtest::VectorNear(apply(edge, ab), ab, tol)) << "edge, AB; tetrahedron " << trial;
    EXPECT_TRUE(ffdtest::VectorNear(apply(edge, across), zero, tol * Norm(across)))
      << "edge, across; tetrahedron " << trial;
    EXPECT_TRUE(ffdtest::VectorNear(apply(edge, across2), zero, tol * Norm(across2)))
      << "edge, across twice; tetrahedron " << trial;
    // At node C nothing moves the nearest point.
    const ffd::Mat3<double> node = ffd::ClosestPointGradient(frame, { 0.0, 1.0, 0.0 }, 1e-9);
    EXPECT_TRUE(ffdtest::MatrixEqual(node, ffd::Mat3<double>{})) << "node; tetrahedron " << trial;
  }
}
} // namespace
