// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDReference.h
 * @brief An independent float64 reference of the global FFD, written straight from the paper's equations 1-3.
 *
 * Test-only and deliberately naive: binomial coefficients times powers, Cramer's rule through the triple
 * products of equation 2, absolute control-point positions P_ijk. It shares no code with Filters/Kernels
 * (which uses the de Casteljau triangle, a dual basis and the displacement form), so agreement between the two
 * is evidence, not an identity.
 */
#ifndef FFDReference_h
#define FFDReference_h

#include <array>
#include <cmath>
#include <vector>

namespace ffdref
{
using Vec = std::array<double, 3>;

inline Vec Sub(const Vec& a, const Vec& b) { return { a[0] - b[0], a[1] - b[1], a[2] - b[2] }; }
inline double Dot(const Vec& a, const Vec& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
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
        p.push_back({ f.X0[0] + a * f.S[0] + b * f.T[0] + c * f.U[0],
          f.X0[1] + a * f.S[1] + b * f.T[1] + c * f.U[1], f.X0[2] + a * f.S[2] + b * f.T[2] + c * f.U[2] });
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
} // namespace ffdref

#endif
