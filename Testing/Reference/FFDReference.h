// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDReference.h
 * @brief An independent float64 reference of the global FFD, written straight from the paper's equations 1-3.
 *
 * Test-only and deliberately naive: binomial coefficients times powers, Cramer's rule through the triple
 * products of equation 2, absolute control-point positions P_ijk. It shares no code with Evaluation/Kernels
 * (which uses the de Casteljau triangle, a dual basis and the displacement form), so agreement between the two
 * is evidence, not an identity.
 *
 * The local bases (issue 3) follow the same rule: Bezier sub-regions are binomials times powers of the voxel's
 * local coordinate, the uniform cubic B-spline is the Cox-de Boor recursion on integer knots (the kernels use
 * closed-form polynomials), and DeformLocal finds the voxel itself and sums over every control point of the
 * lattice (the kernels sum over the voxel's support only), in the absolute form sum w P.
 */
#ifndef FFDReference_h
#define FFDReference_h

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

namespace ffdref
{
using Vec = std::array<double, 3>;

inline Vec Sub(const Vec& a, const Vec& b)
{
  return { a[0] - b[0], a[1] - b[1], a[2] - b[2] };
}
inline double Dot(const Vec& a, const Vec& b)
{
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
inline Vec Cross(const Vec& a, const Vec& b)
{
  return { a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0] };
}

/// The frame: X0, S, T, U.
struct Frame
{
  Vec X0, S, T, U;
};

/// Equation 2.
inline Vec Parameters(const Frame& f, const Vec& x)
{
  const Vec d = Sub(x, f.X0);
  const Vec tu = Cross(f.T, f.U), su = Cross(f.S, f.U), st = Cross(f.S, f.T);
  return { Dot(tu, d) / Dot(tu, f.S), Dot(su, d) / Dot(su, f.T), Dot(st, d) / Dot(st, f.U) };
}

/// Equation 1: P_ijk = X0 + i/l S + j/m T + k/n U, for a lattice of degree (l, m, n), in VTK order.
inline std::vector<Vec> RestLattice(const Frame& f, int l, int m, int n)
{
  std::vector<Vec> p;
  for (int k = 0; k <= n; ++k)
    for (int j = 0; j <= m; ++j)
      for (int i = 0; i <= l; ++i)
      {
        const double a = double(i) / l, b = double(j) / m, c = double(k) / n;
        p.push_back({ f.X0[0] + a * f.S[0] + b * f.T[0] + c * f.U[0], f.X0[1] + a * f.S[1] + b * f.T[1] + c * f.U[1],
          f.X0[2] + a * f.S[2] + b * f.T[2] + c * f.U[2] });
      }
  return p;
}

inline double Binomial(int n, int k)
{
  double c = 1.0;
  for (int q = 1; q <= k; ++q)
  {
    c = c * (n - k + q) / q;
  }
  return c;
}

/// The Bernstein polynomial C(n,k) x^k (1-x)^(n-k).
inline double Bernstein(int n, int k, double x)
{
  return Binomial(n, k) * std::pow(x, k) * std::pow(1.0 - x, n - k);
}

/// Equation 3 at parameters (s, t, u) for absolute control points P (VTK order), degree (l, m, n).
inline Vec Evaluate(const std::vector<Vec>& p, int l, int m, int n, const Vec& stu)
{
  Vec x = { 0, 0, 0 };
  for (int i = 0; i <= l; ++i)
    for (int j = 0; j <= m; ++j)
      for (int k = 0; k <= n; ++k)
      {
        const double w = Bernstein(l, i, stu[0]) * Bernstein(m, j, stu[1]) * Bernstein(n, k, stu[2]);
        const Vec& q = p[i + (l + 1) * (j + (m + 1) * k)];
        for (int c = 0; c < 3; ++c)
        {
          x[c] += w * q[c];
        }
      }
  return x;
}

/// The deformed position of a world point: equation 2, then equation 3.
inline Vec Deform(const Frame& f, const std::vector<Vec>& p, int l, int m, int n, const Vec& x)
{
  return Evaluate(p, l, m, n, Parameters(f, x));
}

/// The grid bases, numbered as the data contract's `FFDBasis` field array.
enum class Basis : int
{
  Bernstein = 0,          ///< global, degree = voxels along the axis
  Trilinear = 1,          ///< Bezier sub-regions of degree 1 (paper Listing 1)
  TriquadraticBezier = 2, ///< Bezier sub-regions of degree 2
  TricubicBezier = 3,     ///< Bezier sub-regions of degree 3 (paper Listing 2, equation 4)
  CubicBSpline = 4,       ///< uniform cubic B-spline, one ring of control points beyond the frame
};

/// Degree of a basis's polynomials along an axis of n voxels.
inline int Degree(Basis b, int n)
{
  return b == Basis::Bernstein ? n : (b == Basis::CubicBSpline ? 3 : int(b));
}

/// Control points along an axis of n voxels: neighbouring Bezier voxels share their face points, the B-spline
/// has one extra point on each side.
inline int PointsAlongAxis(Basis b, int n)
{
  return b == Basis::CubicBSpline ? n + 3 : Degree(b, n) * (b == Basis::Bernstein ? 1 : n) + 1;
}

/// Rest parameter of control point i: i/n (global), i/(d n) (Bezier of degree d), (i-1)/n (B-spline).
inline double RestParameter(Basis b, int n, int i)
{
  if (b == Basis::CubicBSpline)
  {
    return double(i - 1) / n;
  }
  return double(i) / (PointsAlongAxis(b, n) - 1);
}

/// Cox-de Boor recursion on the integer knots t_j = j: the B-spline of degree p supported on [i, i+p+1].
inline double UniformBSpline(int i, int p, double x)
{
  if (p == 0)
  {
    return (x >= i && x < i + 1) ? 1.0 : 0.0;
  }
  return (x - i) / p * UniformBSpline(i, p - 1, x) + (i + p + 1 - x) / p * UniformBSpline(i + 1, p - 1, x);
}

/**
 * The order-th derivative in x of Bernstein(n, k, x), by d/dx B(n, k) = n (B(n-1, k-1) - B(n-1, k)), 0 for k outside
 * [0, n]. With `absolute`, the same recursion with each difference made a sum (and |B| at order 0): what a
 * computation of the derivative adds up before its terms cancel, the size that its rounding errors scale with.
 */
inline double BernsteinDerivative(int n, int k, double x, int order, bool absolute = false)
{
  if (k < 0 || k > n)
  {
    return 0.0;
  }
  if (order == 0)
  {
    return absolute ? std::fabs(Bernstein(n, k, x)) : Bernstein(n, k, x);
  }
  const double sign = absolute ? 1.0 : -1.0;
  return n *
    (BernsteinDerivative(n - 1, k - 1, x, order - 1, absolute) +
      sign * BernsteinDerivative(n - 1, k, x, order - 1, absolute));
}

/// The order-th derivative of UniformBSpline(i, p, x), by d/dx N(i, p) = N(i, p-1) - N(i+1, p-1) on unit knots;
/// `absolute` as in BernsteinDerivative().
inline double UniformBSplineDerivative(int i, int p, double x, int order, bool absolute = false)
{
  if (order == 0)
  {
    return UniformBSpline(i, p, x);
  }
  if (p == 0)
  {
    return 0.0;
  }
  const double sign = absolute ? 1.0 : -1.0;
  return UniformBSplineDerivative(i, p - 1, x, order - 1, absolute) +
    sign * UniformBSplineDerivative(i + 1, p - 1, x, order - 1, absolute);
}

/**
 * The order-th derivative in s of each of AxisWeights()'s weights (`absolute` as in BernsteinDerivative()).
 * Bezier bases take the polynomial of voxel `voxel` (-1: the voxel holding s), so that a derivative is that of
 * the voxel a point was bound to even where rounding puts s a hair into the next one (the derivative jumps there).
 */
inline std::vector<double> AxisWeightDerivatives(
  Basis b, int n, double s, int order, int voxel = -1, bool absolute = false)
{
  const int count = PointsAlongAxis(b, n);
  std::vector<double> w(count, 0.0);
  const double chain = std::pow(double(n), order); // d(s n)/ds = n per order
  if (b == Basis::Bernstein)
  {
    for (int i = 0; i < count; ++i)
    {
      w[i] = BernsteinDerivative(n, i, s, order, absolute);
    }
  }
  else if (b == Basis::CubicBSpline)
  {
    for (int i = 0; i < count; ++i)
    {
      w[i] = chain * UniformBSplineDerivative(i - 3, 3, s * n, order, absolute);
    }
  }
  else
  {
    const int d = Degree(b, n);
    const int c = voxel >= 0 ? voxel : std::min(int(std::floor(s * n)), n - 1);
    for (int i = 0; i <= d; ++i)
    {
      w[d * c + i] = chain * BernsteinDerivative(d, i, s * n - c, order, absolute);
    }
  }
  return w;
}

/**
 * Weights of all PointsAlongAxis() control points along an axis of n voxels at the parameter s in [0, 1].
 * Bezier: voxel c = floor(s n) (n - 1 at s = 1), local coordinate r = s n - c, weight C(d,i) r^i (1-r)^(d-i)
 * on control point d c + i. B-spline: in voxel units x = s n the knots are the integers, control point i's
 * cubic spans the knots i-3 .. i+1 (centred on its rest parameter (i-1)/n), so its weight is N(i-3, 3, x).
 */
inline std::vector<double> AxisWeights(Basis b, int n, double s)
{
  return AxisWeightDerivatives(b, n, s, 0);
}

/// Rest positions X0 + RestParameter(i) S + RestParameter(j) T + RestParameter(k) U, VTK order.
inline std::vector<Vec> RestLattice(Basis b, const Frame& f, const int divisions[3])
{
  std::vector<Vec> p;
  for (int k = 0; k < PointsAlongAxis(b, divisions[2]); ++k)
    for (int j = 0; j < PointsAlongAxis(b, divisions[1]); ++j)
      for (int i = 0; i < PointsAlongAxis(b, divisions[0]); ++i)
      {
        const double a = RestParameter(b, divisions[0], i), e = RestParameter(b, divisions[1], j),
                     c = RestParameter(b, divisions[2], k);
        p.push_back({ f.X0[0] + a * f.S[0] + e * f.T[0] + c * f.U[0], f.X0[1] + a * f.S[1] + e * f.T[1] + c * f.U[1],
          f.X0[2] + a * f.S[2] + e * f.T[2] + c * f.U[2] });
      }
  return p;
}

/**
 * The derivative of EvaluateLocal()'s sum of orders `order` in (s, t, u) at `stu`, over values v (VTK order), in
 * the voxels `voxel` (AxisWeightDerivatives()); with `absolute`, the absolute weights times |v| per component.
 */
inline Vec EvaluateLocalDerivative(Basis b, const int divisions[3], const std::vector<Vec>& v, const Vec& stu,
  const std::array<int, 3>& order, const std::array<int, 3>& voxel, bool absolute = false)
{
  const std::vector<double> ws = AxisWeightDerivatives(b, divisions[0], stu[0], order[0], voxel[0], absolute);
  const std::vector<double> wt = AxisWeightDerivatives(b, divisions[1], stu[1], order[1], voxel[1], absolute);
  const std::vector<double> wu = AxisWeightDerivatives(b, divisions[2], stu[2], order[2], voxel[2], absolute);
  const int ni = int(ws.size()), nj = int(wt.size());
  Vec x = { 0, 0, 0 };
  for (int k = 0; k < int(wu.size()); ++k)
    for (int j = 0; j < nj; ++j)
      for (int i = 0; i < ni; ++i)
      {
        const double w = ws[i] * wt[j] * wu[k];
        const Vec& q = v[i + ni * (j + nj * k)];
        for (int c = 0; c < 3; ++c)
        {
          x[c] += w * (absolute ? std::fabs(q[c]) : q[c]);
        }
      }
  return x;
}

/// sum_ijk w_i(s) w_j(t) w_k(u) P_ijk over the whole lattice (absolute control points, VTK order), for
/// parameters in [0, 1].
inline Vec EvaluateLocal(Basis b, const int divisions[3], const std::vector<Vec>& p, const Vec& stu)
{
  return EvaluateLocalDerivative(b, divisions, p, stu, { 0, 0, 0 }, { -1, -1, -1 });
}

/// The rows of d(s, t, u)/dX (equation 2's dual vectors): (T x U)/(S . T x U), (S x U)/(T . S x U), (S x T)/(U . S x
/// T).
inline std::array<Vec, 3> DualVectors(const Frame& f)
{
  const Vec tu = Cross(f.T, f.U), su = Cross(f.S, f.U), st = Cross(f.S, f.T);
  const double a = Dot(tu, f.S), b = Dot(su, f.T), c = Dot(st, f.U);
  return { Vec{ tu[0] / a, tu[1] / a, tu[2] / a }, Vec{ su[0] / b, su[1] / b, su[2] / b },
    Vec{ st[0] / c, st[1] / c, st[2] / c } };
}

/**
 * The Jacobian dY/dX of the displacement form Y = X + D(stu(X)), D = sum w (P - R) over displacements d (VTK
 * order), at stu in the voxels `voxel`: I + sum over the axes a that are `free` of dD/d(stu_a) (dual vector a)^T.
 * An axis along which a point is clamped to the frame is not free (D does not change along it). Rows of the
 * result are rows of the Jacobian.
 */
inline std::array<Vec, 3> JacobianLocal(Basis b, const Frame& f, const int divisions[3], const std::vector<Vec>& d,
  const Vec& stu, const std::array<int, 3>& voxel, const std::array<bool, 3>& free)
{
  const std::array<Vec, 3> dual = DualVectors(f);
  std::array<Vec, 3> j = { Vec{ 1, 0, 0 }, Vec{ 0, 1, 0 }, Vec{ 0, 0, 1 } };
  for (int a = 0; a < 3; ++a)
  {
    if (!free[a])
    {
      continue;
    }
    std::array<int, 3> order = { 0, 0, 0 };
    order[a] = 1;
    const Vec g = EvaluateLocalDerivative(b, divisions, d, stu, order, voxel);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c)
      {
        j[r][c] += g[r] * dual[a][c];
      }
  }
  return j;
}

/// The deformed position of a world point inside the frame: equation 2, then EvaluateLocal. Parameters a
/// rounding error outside [0, 1] (points on a face) are clamped to it.
inline Vec DeformLocal(Basis b, const Frame& f, const int divisions[3], const std::vector<Vec>& p, const Vec& x)
{
  Vec stu = Parameters(f, x);
  for (double& v : stu)
  {
    v = std::min(std::max(v, 0.0), 1.0);
  }
  return EvaluateLocal(b, divisions, p, stu);
}
/**
 * Tetrahedral FFD (paper section III.E), written independently of equation 5's dual vectors: the barycentric
 * weights of x in tetrahedron (a, b, c, d) are ratios of signed volumes, w_a = vol(x, b, c, d) / vol(a, b, c, d)
 * and so on, so that x = w_a a + w_b b + w_c c + w_d d with weights summing to 1.
 */
inline double SignedVolume(const Vec& a, const Vec& b, const Vec& c, const Vec& d)
{
  return Dot(Cross(Sub(b, a), Sub(c, a)), Sub(d, a)) / 6.0;
}

inline std::array<double, 4> TetrahedronWeights(const Vec& a, const Vec& b, const Vec& c, const Vec& d, const Vec& x)
{
  const double v = SignedVolume(a, b, c, d);
  return { SignedVolume(x, b, c, d) / v, SignedVolume(a, x, c, d) / v, SignedVolume(a, b, x, d) / v,
    SignedVolume(a, b, c, x) / v };
}

/// The absolute form of the tetrahedral FFD: sum over the four nodes of weight times the node's position.
inline Vec DeformInTetrahedron(const std::array<Vec, 4>& rest, const std::array<Vec, 4>& moved, const Vec& x)
{
  const std::array<double, 4> w = TetrahedronWeights(rest[0], rest[1], rest[2], rest[3], x);
  Vec y = { 0.0, 0.0, 0.0 };
  for (int i = 0; i < 4; ++i)
  {
    for (int c = 0; c < 3; ++c)
    {
      y[c] += w[i] * moved[i][c];
    }
  }
  return y;
}
} // namespace ffdref

#endif
