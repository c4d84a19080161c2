// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDKernelTestUtilities.h
 * @brief Random inputs shared by the kernel tests: frames, points, grid lattices of every basis, conversions
 * between the reference's double arrays (ffdref::) and the kernels' types (ffd::), the tolerances the tests
 * share, the loop over random lattices of every basis, random affine maps and central differences; the
 * comparisons themselves are FFDTestComparisons.h's. No VTK, plain C++17 (also built by nvcc).
 */
#ifndef FFDKernelTestUtilities_h
#define FFDKernelTestUtilities_h

#include "FFDCellTable.h"
#include "FFDFrame.h"
#include "FFDGridDeformation.h"
#include "FFDReference.h"
#include "FFDTestComparisons.h"
#include "FFDVector.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <initializer_list>
#include <iomanip>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <type_traits>
#include <utility>
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

/// Largest norm of the dual vectors (rows of d(s,t,u)/dX): how much a world error grows in parameters.
inline double DualNorm(const ffdref::Frame& f)
{
  const ffdref::Vec tu = ffdref::Cross(f.T, f.U), su = ffdref::Cross(f.S, f.U), st = ffdref::Cross(f.S, f.T);
  return std::max({ Norm(tu) / std::fabs(ffdref::Dot(tu, f.S)), Norm(su) / std::fabs(ffdref::Dot(su, f.T)),
    Norm(st) / std::fabs(ffdref::Dot(st, f.U)) });
}

/// Size of the numbers a frame computation rounds: |x|, |X0| and the edges.
inline double WorldScale(const ffdref::Frame& f, const ffdref::Vec& x)
{
  return MaxAbs(x) + MaxAbs(f.X0) + Norm(f.S) + Norm(f.T) + Norm(f.U);
}

/**
 * A random non-orthogonal parallelepiped near the origin: X0 in [-1, 1]^3, edges of random direction and
 * length in [0.5, 2], rejected until its relative volume is at least 0.2 (so its parameter map is well
 * conditioned and the tolerances below need no condition number). Edges are never orthogonal in practice.
 */
inline ffdref::Frame RandomFrame(Rng& rng)
{
  const auto edge = [&rng]()
  {
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

/// max_c |a_c - b_c|
inline double MaxDiff(const ffdref::Vec& a, const ffdref::Vec& b)
{
  return MaxAbs(ffdref::Sub(a, b));
}

/**
 * MaxDiff(got, want) <= tol, as ASSERT_LE compares (a NaN fails); records MaxDiff / tol in `worst`, if given. The
 * message gives the difference, the tolerance and both vectors.
 */
inline ::testing::AssertionResult MaxDiffWithin(
  const ffdref::Vec& got, const ffdref::Vec& want, double tol, WorstRatio* worst = nullptr)
{
  const double diff = MaxDiff(got, want);
  if (worst)
  {
    worst->Add(diff, tol);
  }
  if (diff <= tol)
  {
    return ::testing::AssertionSuccess();
  }
  std::ostringstream s;
  s << std::setprecision(17) << "max |got - want| = " << diff << " > " << tol << ", got (" << got[0] << ", " << got[1]
    << ", " << got[2] << "), expected (" << want[0] << ", " << want[1] << ", " << want[2] << ")";
  return ::testing::AssertionFailure() << s.str();
}

/// Evaluation tolerance relative to the lattice scale: 1e-12 in double, 1e-6 in float (the issues' targets).
/// Every basis is a convex combination of the control points with weights from a stable recurrence or a cubic
/// of a number in [0, 1], so its rounding error is a few eps(Real) times the scale.
template <typename Real>
constexpr double EvaluationTolerance()
{
  return sizeof(Real) >= sizeof(double) ? 1e-12 : 1e-6;
}

/// Gradient tolerance relative to max(lattice scale, largest derivative): 1e-6 in double (central
/// differences with h = 1e-6 of a polynomial: truncation h^2 |f'''| / 6 and rounding eps/h, both far below),
/// 1e-4 in float (the kernel's derivative sums n (B_{k-1} - B_k) P_k lose ~n^2 eps_float ~ 1e-5 at the
/// global basis's highest degree).
template <typename Real>
constexpr double GradientTolerance()
{
  return sizeof(Real) >= sizeof(double) ? 1e-6 : 1e-4;
}

/// The kernels' frame (dual basis from ffd::Frame::FromArray) of a reference frame.
template <typename Real>
ffd::Frame<Real> KernelFrame(const ffdref::Frame& f)
{
  double a[12];
  FrameToArray(f, a);
  return ffd::Frame<Real>::FromArray(a);
}

/// Every grid basis, in the order of the data contract.
constexpr ffdref::Basis AllBases[] = { ffdref::Basis::Bernstein, ffdref::Basis::Trilinear,
  ffdref::Basis::TriquadraticBezier, ffdref::Basis::TricubicBezier, ffdref::Basis::CubicBSpline };

inline std::string BasisName(ffdref::Basis b)
{
  const char* names[] = { "Bernstein", "Trilinear", "TriquadraticBezier", "TricubicBezier", "CubicBSpline" };
  return names[int(b)];
}

/// A lattice of one grid basis over a frame: its rest positions (from the reference) and its moved points.
struct GridLattice
{
  ffdref::Basis Basis;
  ffdref::Frame F;
  std::array<int, 3> Divisions; ///< voxels per axis (the degree per axis for the global basis)
  std::vector<ffdref::Vec> Rest, Points;

  std::array<int, 3> Dims() const
  {
    return { ffdref::PointsAlongAxis(Basis, Divisions[0]), ffdref::PointsAlongAxis(Basis, Divisions[1]),
      ffdref::PointsAlongAxis(Basis, Divisions[2]) };
  }
  /// Points minus rest: what the deformation evaluates.
  std::vector<ffdref::Vec> Displacements() const
  {
    std::vector<ffdref::Vec> d;
    for (size_t i = 0; i < Points.size(); ++i)
    {
      d.push_back(ffdref::Sub(Points[i], Rest[i]));
    }
    return d;
  }
  std::string Name() const
  {
    return BasisName(Basis) + " divisions (" + std::to_string(Divisions[0]) + "," + std::to_string(Divisions[1]) + "," +
      std::to_string(Divisions[2]) + ")";
  }
};

/// A random frame, random divisions in 1..maxDivisions per axis, control points displaced from rest by up to
/// maxDisplacement in each coordinate (the frames' edges are 0.5..2 long).
inline GridLattice RandomGridLattice(Rng& rng, ffdref::Basis basis, int maxDivisions, double maxDisplacement = 0.3)
{
  GridLattice lat;
  lat.Basis = basis;
  lat.F = RandomFrame(rng);
  std::uniform_int_distribution<int> divisions(1, maxDivisions);
  lat.Divisions = { divisions(rng), divisions(rng), divisions(rng) };
  lat.Rest = ffdref::RestLattice(basis, lat.F, lat.Divisions.data());
  for (const ffdref::Vec& p : lat.Rest)
  {
    const ffdref::Vec d = RandomVec(rng, -maxDisplacement, maxDisplacement);
    lat.Points.push_back({ p[0] + d[0], p[1] + d[1], p[2] + d[2] });
  }
  return lat;
}

/**
 * The loop the grid tests share: for each basis of `bases` (every grid basis by default), `trials` lattices of
 * RandomGridLattice(rng, basis, maxDivisions), each passed to f as a GridLattice& that f may change (and the trial,
 * 0..trials - 1, where f takes it too). Stops at the first fatal failure, as an ASSERT_* in the loop's body would.
 */
template <typename F>
void ForEachRandomLattice(Rng& rng, std::initializer_list<ffdref::Basis> bases, int trials, int maxDivisions, F&& f)
{
  for (ffdref::Basis b : bases)
  {
    for (int trial = 0; trial < trials; ++trial)
    {
      GridLattice lat = RandomGridLattice(rng, b, maxDivisions);
      if constexpr (std::is_invocable_v<F&, GridLattice&, int>)
      {
        f(lat, trial);
      }
      else
      {
        f(lat);
      }
      if (::testing::Test::HasFatalFailure())
      {
        return;
      }
    }
  }
}

template <typename F>
void ForEachRandomLattice(Rng& rng, int trials, int maxDivisions, F&& f)
{
  ForEachRandomLattice(rng,
    { ffdref::Basis::Bernstein, ffdref::Basis::Trilinear, ffdref::Basis::TriquadraticBezier,
      ffdref::Basis::TricubicBezier, ffdref::Basis::CubicBSpline },
    trials, maxDivisions, std::forward<F>(f));
}

/**
 * A lattice's deformation as the filters hold it: displacements rounded to Real and an ffd::GridDeformation over
 * them, for a local basis with CellTable its ffd::FillCellTable() too. MaxCount is 4, what the local
 * bases need, and MaxBernsteinDegree + 1 for the global basis.
 */
template <typename Real, int MaxCount, bool CellTable = false>
class Kernel
{
public:
  explicit Kernel(const GridLattice& lat)
    : Values(Flatten<Real>(lat.Displacements()))
  {
    this->D.Basis = ffd::GridBasis(int(lat.Basis));
    const std::array<int, 3> dims = lat.Dims();
    for (int a = 0; a < 3; ++a)
    {
      this->D.Voxels[a] = lat.Divisions[a];
      this->D.Dims[a] = dims[a];
    }
    this->D.Displacements = this->Values.data();
    this->D.Frame = KernelFrame<Real>(lat.F);
    if (CellTable)
    {
      const int cells = lat.Divisions[0] * lat.Divisions[1] * lat.Divisions[2];
      this->Table.resize(std::size_t(cells) * ffd::CellTableStride(ffd::CellDegree(this->D.Basis)));
      ffd::FillCellTable(this->D.Basis, this->Values.data(), this->D.Voxels, this->D.Dims, nullptr, nullptr,
        this->Table.data(), 0, cells);
      this->D.CellTable = this->Table.data();
    }
  }
  Kernel(const Kernel&) = delete; // D points into Values
  Kernel& operator=(const Kernel&) = delete;

  int Bind(const ffd::Vec3<Real>& x, bool clamp) const
  {
    return ffd::BindToGrid(this->D.Frame, this->D.Basis, this->D.Voxels, x, clamp);
  }

  const std::vector<Real> Values;
  std::vector<Real> Table;
  ffd::GridDeformation<MaxCount, Real, -1, Real, CellTable> D;
};

/// Calls f(kernel) with the Kernels of lat that the filters may build: MaxCount 4 for the local bases and for
/// the global basis of degree <= 3 (one cubic voxel), MaxBernsteinDegree + 1 for the global basis, and for a
/// local basis one with a cell table too.
template <typename Real, typename F>
void WithKernel(const GridLattice& lat, F&& f)
{
  if (lat.Basis == ffdref::Basis::Bernstein)
  {
    const Kernel<Real, ffd::MaxBernsteinDegree + 1> k(lat);
    f(k);
  }
  if (lat.Basis != ffdref::Basis::Bernstein || std::max({ lat.Divisions[0], lat.Divisions[1], lat.Divisions[2] }) <= 3)
  {
    const Kernel<Real, 4> k(lat);
    f(k);
  }
  if (lat.Basis != ffdref::Basis::Bernstein) // ffd::WorthCellTable()
  {
    const Kernel<Real, 4, true> k(lat);
    f(k);
  }
}

/**
 * Tolerance of a deformed position X + D against the reference: EvaluationTolerance() times (scale + |X|) (the
 * issues' target; X + D rounds at the size of X), plus the rounding of equation 2 amplified by the
 * displacement's gradient: computing (s, t, u) in Real errs as a world error of ~8 eps(Real) (|X| + |X0|) would,
 * which moves D by |J - I| times that. In double the second term is below 1e-13 here; in float it matters on
 * rough lattices (|J - I| reaches ~20 with displacements of 0.3 over control points 1/18 of an edge apart).
 */
template <typename Real>
double PositionTolerance(double scale, const ffdref::Vec& x, const ffdref::Frame& f, const ffd::Mat3<Real>& j)
{
  double gradient = 0.0;
  for (int r = 0; r < 3; ++r)
  {
    for (int c = 0; c < 3; ++c)
    {
      gradient = std::max(gradient, std::fabs(double(j.M[r][c]) - (r == c ? 1.0 : 0.0)));
    }
  }
  return EvaluationTolerance<Real>() * (scale + MaxAbs(x)) + 8.0 * Eps<Real>() * gradient * (MaxAbs(x) + MaxAbs(f.X0));
}

/// A 3x3 matrix of the reference, by rows.
using Mat = std::array<ffdref::Vec, 3>;

inline ffdref::Vec Scaled(const ffdref::Vec& a, double s)
{
  return { s * a[0], s * a[1], s * a[2] };
}

inline ffdref::Vec Product(const Mat& a, const ffdref::Vec& v)
{
  return { ffdref::Dot(a[0], v), ffdref::Dot(a[1], v), ffdref::Dot(a[2], v) };
}

inline double Determinant(const Mat& a)
{
  return ffdref::Dot(a[0], ffdref::Cross(a[1], a[2]));
}

/// det(A) A^-T, entry (i, k) = a[i+1][k+1] a[i+2][k+2] - a[i+1][k+2] a[i+2][k+1] (indices mod 3).
inline Mat Cofactor(const Mat& a)
{
  Mat c;
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k)
    {
      const int i1 = (i + 1) % 3, i2 = (i + 2) % 3, k1 = (k + 1) % 3, k2 = (k + 2) % 3;
      c[i][k] = a[i1][k1] * a[i2][k2] - a[i1][k2] * a[i2][k1];
    }
  return c;
}

/// An affine map x -> A x + b.
struct Affine
{
  Mat A;
  ffdref::Vec B;

  ffdref::Vec operator()(const ffdref::Vec& x) const
  {
    ffdref::Vec y;
    for (int r = 0; r < 3; ++r)
    {
      y[r] = A[r][0] * x[0] + A[r][1] * x[1] + A[r][2] * x[2] + B[r];
    }
    return y;
  }
};

/// A random affine map: A = I plus entries uniform in [-amplitude, amplitude] (drawn row by row), then b in
/// [-1, 1]^3.
inline Affine RandomAffine(Rng& rng, double amplitude)
{
  Affine m;
  for (int r = 0; r < 3; ++r)
  {
    for (int c = 0; c < 3; ++c)
    {
      m.A[r][c] = (r == c ? 1.0 : 0.0) + Uniform(rng, -amplitude, amplitude);
    }
  }
  m.B = RandomVec(rng, -1.0, 1.0);
  return m;
}

/// Central differences of a map f of 3-vectors at x with step h: d[r][c] = (f(x + h e_c) - f(x - h e_c))_r / 2h.
template <typename F>
Mat CentralDifferences(const ffdref::Vec& x, double h, F&& f)
{
  Mat d;
  for (int c = 0; c < 3; ++c)
  {
    ffdref::Vec plus = x, minus = x;
    plus[c] += h;
    minus[c] -= h;
    const ffdref::Vec diff = ffdref::Sub(f(plus), f(minus));
    for (int r = 0; r < 3; ++r)
    {
      d[r][c] = diff[r] / (2.0 * h);
    }
  }
  return d;
}

/// The float64 Jacobian of a point bound to a grid lattice, and where ffdref::JacobianLocal evaluated it.
struct ReferenceJacobian
{
  Mat J;
  ffdref::Vec Stu;          ///< the point's parameters, clamped to the frame
  std::array<int, 3> Voxel; ///< the voxel along each axis of the cell the kernel bound the point to
  std::array<bool, 3> Free; ///< false along the axes the point is clamped along
};

/**
 * ffdref::JacobianLocal of the point xd bound to `cell` (BindToGrid()'s flat index) over the displacements the
 * kernel reads (rounded to Real): in the polynomial of that cell, with the columns of the axes along which the
 * point lies outside the frame (beyond ParametricTolerance(), as the kernel decides) dropped.
 */
template <typename Real>
ReferenceJacobian JacobianOfPoint(
  const GridLattice& lat, const std::vector<ffdref::Vec>& displacements, const ffdref::Vec& xd, int cell)
{
  ReferenceJacobian ref;
  ref.Stu = ffdref::Parameters(lat.F, xd);
  const double tolerance = double(ffd::ParametricTolerance<Real>());
  for (int a = 0; a < 3; ++a)
  {
    ref.Free[a] = ref.Stu[a] >= -tolerance && ref.Stu[a] <= 1.0 + tolerance;
    ref.Stu[a] = std::min(1.0, std::max(0.0, ref.Stu[a]));
    const int cells = lat.Basis == ffdref::Basis::Bernstein ? 1 : lat.Divisions[a];
    ref.Voxel[a] = cell % cells;
    cell /= cells;
  }
  ref.J = ffdref::JacobianLocal(lat.Basis, lat.F, lat.Divisions.data(), displacements, ref.Stu, ref.Voxel, ref.Free);
  return ref;
}

/**
 * A bound on each entry's error of a Jacobian that a kernel computes in Real at the point of `ref`, from a
 * running error analysis. Its two sources:
 * - the evaluation: dD/d(stu_a) is a sum of products of derivative weights and displacements, each weight from
 *   a recurrence of at most 3 roundings per degree, the tensor product and its nested sums 3 (d + 2) more,
 *   then times the dual vectors (3), plus the identity (1). In all at most m = 6 (d + 2) roundings, each of
 *   relative size eps, on terms whose absolute sum is ffdref::EvaluateLocalDerivative(..., absolute) (the
 *   derivative's recurrences with their differences made sums: cancellation is not credited). A local basis
 *   with a cell table evaluates the power form: its coefficients are the cell's control values mixed by the
 *   change to monomials, whose absolute column sums reach 2^d times a Bernstein weight's maximum (C(d, i)
 *   2^(d-i) for B_{i,d}), so the bound is taken 2^d times larger there.
 * - the parameters: (s, t, u) computed in Real from X err as a world error of 8 eps (|X| + |X0|) would
 *   (PositionTolerance()), which moves the Jacobian by its derivative along them, the second derivatives'
 *   absolute sums times the dual vectors.
 * First order in eps; d is the largest degree along an axis (the divisions for the global basis).
 */
template <typename Real>
Mat JacobianErrorBound(const GridLattice& lat, const std::vector<ffdref::Vec>& displacements, const ffdref::Vec& xd,
  const ReferenceJacobian& ref, bool powerForm)
{
  const double eps = Eps<Real>();
  int degree = 0;
  for (int a = 0; a < 3; ++a)
  {
    degree = std::max(degree, ffdref::Degree(lat.Basis, lat.Divisions[a]));
  }
  const double rounding = 6.0 * (degree + 2) * eps * (powerForm ? std::pow(2.0, degree) : 1.0);
  const std::array<ffdref::Vec, 3> dual = ffdref::DualVectors(lat.F);
  const double worldError = 8.0 * eps * (MaxAbs(xd) + MaxAbs(lat.F.X0));
  Mat bound{};
  for (int a = 0; a < 3; ++a)
  {
    if (!ref.Free[a])
    {
      continue;
    }
    std::array<int, 3> order = { 0, 0, 0 };
    ++order[a];
    const ffdref::Vec first =
      ffdref::EvaluateLocalDerivative(lat.Basis, lat.Divisions.data(), displacements, ref.Stu, order, ref.Voxel, true);
    ffdref::Vec moved = { 0, 0, 0 }; // |d(dD/d stu_a)| from the parameters' errors
    for (int b = 0; b < 3; ++b)
    {
      if (!ref.Free[b])
      {
        continue;
      }
      std::array<int, 3> second = order;
      ++second[b];
      const ffdref::Vec h = ffdref::EvaluateLocalDerivative(
        lat.Basis, lat.Divisions.data(), displacements, ref.Stu, second, ref.Voxel, true);
      const double stuError = worldError * (std::fabs(dual[b][0]) + std::fabs(dual[b][1]) + std::fabs(dual[b][2]));
      for (int r = 0; r < 3; ++r)
      {
        moved[r] += h[r] * stuError;
      }
    }
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c)
      {
        bound[r][c] += (rounding * first[r] + moved[r]) * std::fabs(dual[a][c]);
      }
  }
  for (int r = 0; r < 3; ++r)
  {
    bound[r][r] += rounding;
  }
  return bound;
}

/**
 * A bound on the error of det(J) computed in Real from a Jacobian within `bound` of j (first order): the
 * inputs' errors times |d det / dJ| = |cof(J)|, plus the rounding of the three-term expansion (5 roundings on
 * each of its six triple products).
 */
template <typename Real>
double DeterminantErrorBound(const Mat& j, const Mat& bound)
{
  const Mat cof = Cofactor(j);
  double e = 0.0, products = 0.0;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
    {
      e += std::fabs(cof[r][c]) * bound[r][c];
    }
  const int perms[6][3] = { { 0, 1, 2 }, { 0, 2, 1 }, { 1, 0, 2 }, { 1, 2, 0 }, { 2, 0, 1 }, { 2, 1, 0 } };
  for (const auto& p : perms)
  {
    products += std::fabs(j[0][p[0]] * j[1][p[1]] * j[2][p[2]]);
  }
  return e + 5.0 * Eps<Real>() * products;
}

/**
 * A bound on the max-norm error of the unit normal cof(J) n / |cof(J) n| computed in Real from a Jacobian within
 * `bound` of j (first order; n exact): each cofactor entry, a difference of two products, errs by the inputs'
 * errors times the other factors plus 2 eps times the products; m = cof(J) n adds 3 eps |cof| |n| a component;
 * normalising turns an error e of m into at most 2 |e| / |m|, and rounds 5 more times (dot, sqrt, division,
 * product).
 */
template <typename Real>
double NormalErrorBound(const Mat& j, const Mat& bound, const ffdref::Vec& n)
{
  const double eps = Eps<Real>();
  ffdref::Vec e = { 0, 0, 0 };
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k)
    {
      const int i1 = (i + 1) % 3, i2 = (i + 2) % 3, k1 = (k + 1) % 3, k2 = (k + 2) % 3;
      const double p = std::fabs(j[i1][k1] * j[i2][k2]), q = std::fabs(j[i1][k2] * j[i2][k1]);
      const double cofError = std::fabs(j[i1][k1]) * bound[i2][k2] + bound[i1][k1] * std::fabs(j[i2][k2]) +
        std::fabs(j[i1][k2]) * bound[i2][k1] + bound[i1][k2] * std::fabs(j[i2][k1]) + 2.0 * eps * (p + q);
      e[i] += (cofError + 3.0 * eps * (p + q)) * std::fabs(n[k]);
    }
  const double m = Norm(Product(Cofactor(j), n));
  return 2.0 * Norm(e) / m + 5.0 * eps;
}

} // namespace ffdtest

#endif
