// SPDX-License-Identifier: BSD-3-Clause
// The frame and its parameter map (FFDFrame.h, paper equations 1 and 2) against the float64 reference
// ffdref::Parameters (Cramer's rule through triple products).

#include "FFDFrame.h"
#include "FFDKernelTestUtilities.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace
{
using ffdref::Vec;
using ffdtest::DualNorm;
using ffdtest::Eps;
using ffdtest::Norm;
using ffdtest::WorldScale;

FFD_REAL_TYPED_TEST_SUITE(FFDFrameTest);

constexpr int NumberOfFrames = 200;
constexpr int PointsPerFrame = 50;

template <typename Real>
ffd::Frame<Real> KernelFrame(const ffdref::Frame& f)
{
  double a[12];
  ffdtest::FrameToArray(f, a);
  EXPECT_EQ(ffd::CheckFrame(a), ffd::FrameStatus::Valid);
  return ffd::Frame<Real>::FromArray(a);
}

TYPED_TEST(FFDFrameTest, ToParametricMatchesReference)
{
  using Real = TypeParam;
  ffdtest::Rng rng(201);
  for (int trial = 0; trial < NumberOfFrames; ++trial)
  {
    const ffdref::Frame f = ffdtest::RandomFrame(rng);
    const ffd::Frame<Real> frame = KernelFrame<Real>(f);
    for (int p = 0; p < PointsPerFrame; ++p)
    {
      // Points inside and around the frame; the reference sees the point as rounded to Real.
      const ffd::Vec3<Real> x = ffdtest::ToKernel<Real>(ffdtest::ToWorld(f, ffdtest::RandomVec(rng, -0.5, 1.5)));
      const Vec xd = ffdtest::ToRef(x);
      const Vec ref = ffdref::Parameters(f, xd);
      const Vec got = ffdtest::ToRef(frame.ToParametric(x));
      // Tolerance (absolute, in parameter units): 16 eps |dual| (|x| + |X0| + |S| + |T| + |U|): the frame's
      // numbers are rounded to Real and X - X0 and the dot products round at that scale, and the dual vectors
      // turn world errors into parameter errors.
      const double tol = 16.0 * Eps<Real>() * DualNorm(f) * WorldScale(f, xd);
      ASSERT_TRUE(ffdtest::VectorNear(got, ref, tol, "axis")) << "frame " << trial << " point " << p;
    }
  }
}

TYPED_TEST(FFDFrameTest, ToWorldInvertsToParametric)
{
  using Real = TypeParam;
  ffdtest::Rng rng(202);
  for (int trial = 0; trial < NumberOfFrames; ++trial)
  {
    const ffdref::Frame f = ffdtest::RandomFrame(rng);
    const ffd::Frame<Real> frame = KernelFrame<Real>(f);
    const double edges = Norm(f.S) + Norm(f.T) + Norm(f.U);
    for (int p = 0; p < PointsPerFrame; ++p)
    {
      const ffd::Vec3<Real> x = ffdtest::ToKernel<Real>(ffdtest::ToWorld(f, ffdtest::RandomVec(rng, -0.5, 1.5)));
      const Vec back = ffdtest::ToRef(frame.ToWorld(frame.ToParametric(x)));
      const Vec xd = ffdtest::ToRef(x);
      // Tolerance (absolute, world units): the parameter error above times the edges, plus the rounding of
      // the sum X0 + sS + tT + uU: 16 eps (1 + |dual| (|S| + |T| + |U|)) (|x| + |X0| + |S| + |T| + |U|).
      const double tol = 16.0 * Eps<Real>() * (1.0 + DualNorm(f) * edges) * WorldScale(f, xd);
      ASSERT_TRUE(ffdtest::VectorNear(back, xd, tol, "axis")) << "frame " << trial << " point " << p;
    }
  }
}

TYPED_TEST(FFDFrameTest, BindKeepsCornersFacesAndInterior)
{
  using Real = TypeParam;
  using V = ffd::Vec3<Real>;
  ffdtest::Rng rng(203);
  for (int trial = 0; trial < NumberOfFrames; ++trial)
  {
    const ffdref::Frame f = ffdtest::RandomFrame(rng);
    const ffd::Frame<Real> frame = KernelFrame<Real>(f);
    // Bound parameters are clamped to [0, 1] and, inside, equal the reference's to the tolerance of
    // ToParametricMatchesReference.
    const auto expectBound = [&](const V& x, const Vec& stu, const char* what)
    {
      V got;
      ASSERT_TRUE(frame.Bind(x, got)) << what << ", frame " << trial;
      const Vec g = ffdtest::ToRef(got);
      const double tol = 16.0 * Eps<Real>() * DualNorm(f) * WorldScale(f, ffdtest::ToRef(x));
      for (int c = 0; c < 3; ++c)
      {
        ASSERT_GE(g[c], 0.0) << what;
        ASSERT_LE(g[c], 1.0) << what;
      }
      ASSERT_TRUE(ffdtest::VectorNear(g, stu, tol, "axis")) << what << ", frame " << trial;
    };
    // The 8 corners, built exactly as X0, X0 + S, X0 + S + T, ... in Real from the frame's own vectors.
    for (int corner = 0; corner < 8; ++corner)
    {
      V x = frame.Origin;
      x = (corner & 1) ? x + frame.S : x;
      x = (corner & 2) ? x + frame.T : x;
      x = (corner & 4) ? x + frame.U : x;
      expectBound(x, { double(corner & 1), double((corner >> 1) & 1), double((corner >> 2) & 1) }, "corner");
    }
    // Points on each of the 6 faces: X0 + aS + bT (+ U), and the same for the other axes.
    for (int axis = 0; axis < 3; ++axis)
    {
      const V* edges[3] = { &frame.S, &frame.T, &frame.U };
      for (int side = 0; side < 2; ++side)
      {
        const Real a = Real(ffdtest::Uniform(rng, 0.0, 1.0)), b = Real(ffdtest::Uniform(rng, 0.0, 1.0));
        V x = frame.Origin + a * *edges[(axis + 1) % 3] + b * *edges[(axis + 2) % 3];
        x = side ? x + *edges[axis] : x;
        Vec stu;
        stu[axis] = side;
        stu[(axis + 1) % 3] = a;
        stu[(axis + 2) % 3] = b;
        expectBound(x, stu, "face");
      }
    }
    // Interior points.
    for (int p = 0; p < 10; ++p)
    {
      const Vec stu = ffdtest::RandomVec(rng, 0.0, 1.0);
      expectBound(ffdtest::ToKernel<Real>(ffdtest::ToWorld(f, stu)), stu, "interior");
    }
  }
}

TYPED_TEST(FFDFrameTest, BindRejectsOutsideAndNonFinitePoints)
{
  using Real = TypeParam;
  using V = ffd::Vec3<Real>;
  ffdtest::Rng rng(204);
  // "Slightly outside": 1e-3 (float) or 1e-8 (double) beyond a face, in parameter units. Far above the
  // rounding error of the parameters (ToParametricMatchesReference: at most 16 eps |dual| scale, ~8e-5 in
  // float and ~1e-13 in double for these frames), so these points are outside whatever the rounding; a
  // binding band wider than that would let them in.
  const double delta = sizeof(Real) >= sizeof(double) ? 1e-8 : 1e-3;
  for (int trial = 0; trial < NumberOfFrames; ++trial)
  {
    const ffdref::Frame f = ffdtest::RandomFrame(rng);
    const ffd::Frame<Real> frame = KernelFrame<Real>(f);
    V stu;
    for (int axis = 0; axis < 3; ++axis)
    {
      for (int side = 0; side < 2; ++side)
      {
        Vec p = ffdtest::RandomVec(rng, 0.0, 1.0);
        p[axis] = side ? 1.0 + delta : -delta;
        EXPECT_FALSE(frame.Bind(ffdtest::ToKernel<Real>(ffdtest::ToWorld(f, p)), stu))
          << "frame " << trial << " axis " << axis << " side " << side;
        p[axis] = side ? ffdtest::Uniform(rng, 1.01, 3.0) : ffdtest::Uniform(rng, -3.0, -0.01);
        EXPECT_FALSE(frame.Bind(ffdtest::ToKernel<Real>(ffdtest::ToWorld(f, p)), stu))
          << "frame " << trial << " axis " << axis << " side " << side;
      }
    }
    const Real bad[3] = { std::numeric_limits<Real>::quiet_NaN(), std::numeric_limits<Real>::infinity(),
      -std::numeric_limits<Real>::infinity() };
    for (Real value : bad)
    {
      for (int c = 0; c < 3; ++c)
      {
        // A point at the frame's centre with one coordinate replaced by NaN or +-Inf.
        const Vec centre = ffdtest::ToWorld(f, { 0.5, 0.5, 0.5 });
        Real xyz[3] = { Real(centre[0]), Real(centre[1]), Real(centre[2]) };
        xyz[c] = value;
        EXPECT_FALSE(frame.Bind(V::From(xyz), stu)) << "coordinate " << c << " = " << value;
      }
    }
  }
}

TEST(FFDCheckFrame, ValidFrames)
{
  ffdtest::Rng rng(205);
  for (int trial = 0; trial < NumberOfFrames; ++trial)
  {
    ffdref::Frame f = ffdtest::RandomFrame(rng);
    double a[12];
    ffdtest::FrameToArray(f, a);
    EXPECT_EQ(ffd::CheckFrame(a), ffd::FrameStatus::Valid);
    // The flatness test is relative: the same shape at any reasonable size is valid.
    for (double scale : { 1e-20, 1e20 })
    {
      double scaled[12];
      for (int c = 0; c < 12; ++c)
      {
        scaled[c] = scale * a[c];
      }
      EXPECT_EQ(ffd::CheckFrame(scaled), ffd::FrameStatus::Valid) << "scale " << scale;
    }
  }
}

TEST(FFDCheckFrame, NonFinite)
{
  ffdtest::Rng rng(206);
  double a[12];
  ffdtest::FrameToArray(ffdtest::RandomFrame(rng), a);
  for (int c = 0; c < 12; ++c)
  {
    for (double bad : { std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
           -std::numeric_limits<double>::infinity() })
    {
      double b[12];
      std::copy(a, a + 12, b);
      b[c] = bad;
      EXPECT_EQ(ffd::CheckFrame(b), ffd::FrameStatus::NonFinite) << "component " << c << " = " << bad;
    }
  }
}

TEST(FFDCheckFrame, OutOfRange)
{
  // Finite edges whose volume or dual basis is not a finite, nonzero double: the parameter map cannot be built.
  ffdtest::Rng rng(208);
  for (int trial = 0; trial < NumberOfFrames; ++trial)
  {
    double a[12];
    ffdtest::FrameToArray(ffdtest::RandomFrame(rng), a);
    for (double scale : { 1e250, 1e-250 })
    {
      double scaled[12];
      for (int c = 0; c < 12; ++c)
      {
        scaled[c] = scale * a[c];
      }
      EXPECT_EQ(ffd::CheckFrame(scaled), ffd::FrameStatus::OutOfRange) << "scale " << scale;
    }
  }
  const double huge[12] = { 0, 0, 0, 1e308, 0, 0, 0, 1e308, 0, 0, 0, 1e308 };
  EXPECT_EQ(ffd::CheckFrame(huge), ffd::FrameStatus::OutOfRange);
}

TEST(FFDCheckFrame, ZeroVolume)
{
  ffdtest::Rng rng(207);
  for (int trial = 0; trial < NumberOfFrames; ++trial)
  {
    ffdref::Frame f = ffdtest::RandomFrame(rng);
    double a[12];
    // Flat: U in the plane of S and T.
    const double alpha = ffdtest::Uniform(rng, -1.0, 1.0), beta = ffdtest::Uniform(rng, -1.0, 1.0);
    ffdref::Frame flat = f;
    for (int c = 0; c < 3; ++c)
    {
      flat.U[c] = alpha * f.S[c] + beta * f.T[c];
    }
    ffdtest::FrameToArray(flat, a);
    EXPECT_EQ(ffd::CheckFrame(a), ffd::FrameStatus::ZeroVolume) << "flat, frame " << trial;
    // A zero edge, on each axis in turn.
    for (int edge = 0; edge < 3; ++edge)
    {
      ffdtest::FrameToArray(f, a);
      a[3 + 3 * edge] = a[4 + 3 * edge] = a[5 + 3 * edge] = 0.0;
      EXPECT_EQ(ffd::CheckFrame(a), ffd::FrameStatus::ZeroVolume) << "zero edge " << edge;
    }
    // Two equal edges.
    ffdref::Frame twin = f;
    twin.T = f.S;
    ffdtest::FrameToArray(twin, a);
    EXPECT_EQ(ffd::CheckFrame(a), ffd::FrameStatus::ZeroVolume) << "equal edges, frame " << trial;
  }
  double zero[12] = {};
  EXPECT_EQ(ffd::CheckFrame(zero), ffd::FrameStatus::ZeroVolume);
}

} // namespace
