// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDFoldCertificate.h
 * @brief Whether det J > 0 over a whole cell of a grid lattice: certified, folded, or undecided.
 *
 * Inside the frame the deformation is X(s,t,u) = sum_c w_c P_c (the rest lattice reproduces the frame's affine
 * map), so det J = det(X_s, X_t, X_u) / det(S, T, U): its sign is that of det(X_s, X_t, X_u) times the frame's
 * orientation. On a cell, X is a tensor-product polynomial; CellNet() writes it in Bezier form of order n_a (degree
 * n_a - 1) along axis a: a Bezier cell's control points as they are, a cubic B-spline cell through the 4x4 basis
 * change per axis, a voxel of the global Bernstein basis by de Casteljau restriction of the whole lattice.
 *
 * Why the certificate is sufficient: X_s = sum B_i(r) (n_0 - 1) (P_{i+1} - P_i) over the Bezier basis of one
 * degree less, whose weights are >= 0 and sum to 1; so X_s lies in the convex hull of the differences D_s, which
 * lies in the ball of centre c_s and radius r_s = max |D_s - c_s| (and likewise for t and u; the positive factors
 * n_a - 1 do not change a sign and are dropped). Writing X_a = c_a + e_a with |e_a| <= r_a and expanding the
 * trilinear det(X_s, X_t, X_u), every term but det(c_s, c_t, c_u) is bounded by Cauchy-Schwarz and Hadamard
 * (|e . (b x c)| <= |e| |b x c|, |det(a, b, c)| <= |a| |b| |c|):
 *   det >= det(c) - r_s |c_t x c_u| - r_t |c_u x c_s| - r_u |c_s x c_t| - r_s r_t |c_u| - r_t r_u |c_s| - r_u r_s |c_t|
 *          - r_s r_t r_u,
 * so a positive lower bound (times the orientation) certifies the whole cell. Rounding: the net is taken relative
 * to its first point, every radius is widened by Slack() (a bound on the rounding of the net's differences, of
 * the order of the coefficients' size times machine epsilon times the steps that made them), and the bound must
 * exceed BoundMargin() times its own terms' size. Where the bound fails, ExactCertifies() compares the exact
 * Bernstein coefficients of det J itself (degree 3n - 1 per axis; positive coefficients make a positive
 * polynomial): tighter, and dearer than a level of subdivision, so it is tried on subcells only (and on the cell
 * at depth 0). A cell neither decides is split at 1/2 along every axis (de Casteljau: the children's nets are
 * exact Bezier forms of the same polynomial) down to a depth; at every node's 8 corners the Bezier form interpolates,
 * so det there is the triple product of the corner differences, exact but for rounding: a value <= CornerMargin() times
 * its size (zero to float64 precision, or negative) makes the cell folded. A cell is certified when every leaf is,
 * folded when a corner is, undecided otherwise.
 *
 * Everything here is plain data and loops over caller-given storage (host and device alike).
 */
#ifndef FFDFoldCertificate_h
#define FFDFoldCertificate_h

#include "FFDGridBasis.h"
#include "FFDVector.h"

#include <cstdint>

namespace ffd
{

/// A cell's state; the values are those of the `FoldCertificate` cell array (NotChecked: not an active cell).
enum class FoldState : std::uint8_t
{
  Certified = 0,
  Folded = 1,
  Undecided = 2,
  NotChecked = 3,
};

/// The deepest subdivision CertifyNet() takes (8^8 leaves at most).
constexpr int MaxFoldDepth = 8;

/// Coefficients of a Bezier net of `order` coefficients per axis (i fastest).
FFD_INLINE int NetSize(const int order[3])
{
  return order[0] * order[1] * order[2];
}

namespace detail
{
/// The smaller and the larger of two numbers (not NaN): what fmin and fmax give, without their calls into libm.
FFD_INLINE double Min(double a, double b)
{
  return a < b ? a : b;
}
FFD_INLINE double Max(double a, double b)
{
  return a > b ? a : b;
}

/// Offset between neighbours along `axis` of a net of `order`.
FFD_INLINE int NetStride(const int order[3], int axis)
{
  return axis == 0 ? 1 : (axis == 1 ? order[0] : order[0] * order[1]);
}

/// Calls f(first) for the first coefficient of every row of the net along `axis`.
template <typename F>
FFD_INLINE void ForEachRow(const int order[3], int axis, F&& f)
{
  const int a1 = axis == 0 ? 1 : 0, a2 = axis == 2 ? 1 : 2;
  for (int j = 0; j < order[a2]; ++j)
  {
    for (int i = 0; i < order[a1]; ++i)
    {
      f(i * NetStride(order, a1) + j * NetStride(order, a2));
    }
  }
}
} // namespace detail

/**
 * De Casteljau at t on every row of the net along `axis`, in place: keeps the part over [0, t] (keepLeft) or over
 * [t, 1], each reparametrised to [0, 1].
 */
FFD_INLINE void SplitNet(Vec3<double>* net, const int order[3], int axis, double t, bool keepLeft)
{
  const int n = order[axis] - 1, stride = detail::NetStride(order, axis);
  detail::ForEachRow(order, axis,
    [&](int first)
    {
      Vec3<double>* p = net + first;
      for (int r = 1; r <= n; ++r)
      {
        if (keepLeft) // p_i <- b_{i-r}^r: at the end p_i = b_0^i
        {
          for (int i = n; i >= r; --i)
          {
            p[i * stride] = (1.0 - t) * p[(i - 1) * stride] + t * p[i * stride];
          }
        }
        else // p_i <- b_i^r: at the end p_i = b_i^{n-i}
        {
          for (int i = 0; i <= n - r; ++i)
          {
            p[i * stride] = (1.0 - t) * p[i * stride] + t * p[(i + 1) * stride];
          }
        }
      }
    });
}

/// The uniform cubic B-spline segment of 4 control points per axis in Bezier form, in place.
FFD_INLINE void BSplineToBezier(Vec3<double>* net, const int order[3])
{
  for (int axis = 0; axis < 3; ++axis)
  {
    const int s = detail::NetStride(order, axis);
    detail::ForEachRow(order, axis,
      [&](int first)
      {
        Vec3<double>* p = net + first;
        const Vec3<double> q0 = p[0], q1 = p[s], q2 = p[2 * s], q3 = p[3 * s];
        p[0] = (1.0 / 6.0) * (q0 + 4.0 * q1 + q2);
        p[s] = (1.0 / 3.0) * (2.0 * q1 + q2);
        p[2 * s] = (1.0 / 3.0) * (q1 + 2.0 * q2);
        p[3 * s] = (1.0 / 6.0) * (q1 + 4.0 * q2 + q3);
      });
  }
}

/**
 * The Bezier net of voxel `voxel` of a grid lattice of `basis` over `voxels` divisions, relative to its first
 * point, into `net` (at most SupportSize()^3 coefficients: (voxels + 1)^3 for the global basis); `order` receives
 * its coefficients per axis. pointOf(i, j, k) gives control point (i, j, k) of the voxel's support (VoxelSupport(),
 * counted from its First) as a Vec3<double>. Returns the largest |coordinate| of the net (for Slack()).
 */
template <typename PointOf>
FFD_INLINE double CellNet(
  GridBasis basis, const int voxels[3], const int voxel[3], PointOf&& pointOf, Vec3<double>* net, int order[3])
{
  for (int a = 0; a < 3; ++a)
  {
    order[a] = SupportSize(basis, voxels[a]);
  }
  const Vec3<double> origin = pointOf(0, 0, 0);
  double largest = 0.0; // of the coefficients before the conversions, whose rounding it bounds
  for (int k = 0, c = 0; k < order[2]; ++k)
  {
    for (int j = 0; j < order[1]; ++j)
    {
      for (int i = 0; i < order[0]; ++i, ++c)
      {
        net[c] = pointOf(i, j, k) - origin;
        largest = detail::Max(largest, detail::Max(fabs(net[c].x), detail::Max(fabs(net[c].y), fabs(net[c].z))));
      }
    }
  }
  if (basis == GridBasis::CubicBSpline)
  {
    BSplineToBezier(net, order);
  }
  else if (basis == GridBasis::Bernstein)
  {
    for (int a = 0; a < 3; ++a) // [v/n, (v+1)/n]: keep [0, b], then [a/b, 1] of it
    {
      const double lo = double(voxel[a]) / voxels[a], hi = double(voxel[a] + 1) / voxels[a];
      if (hi < 1.0)
      {
        SplitNet(net, order, a, hi, true);
      }
      if (lo > 0.0)
      {
        SplitNet(net, order, a, lo / hi, false);
      }
    }
  }
  return largest;
}

/// How far rounding may have moved the differences of neighbouring coefficients (the columns' nets) of a net of
/// `order` made by CellNet() and split `depth` times from those of the exact polynomial, with `largest` its largest
/// |coordinate|: each de Casteljau or basis-change step rounds a coefficient by at most a few units of the
/// coordinates' size; 16 eps per step, over every step, twice (a difference of two), with room to spare.
FFD_INLINE double Slack(const int order[3], int depth, double largest)
{
  const int steps = (order[0] + order[1] + order[2]) * (2 + depth) + 4;
  return 2.0 * 16.0 * 2.220446049250313e-16 * steps * largest * 1.7320508075688772; // |v| <= sqrt(3) max |v_i|
}

/// The relative margin by which the bound must exceed its terms' size: its 40-odd roundings, with room to spare.
FFD_INLINE constexpr double BoundMargin()
{
  return 256.0 * 2.220446049250313e-16;
}

/// The relative size under which a corner's triple product counts as zero.
FFD_INLINE constexpr double CornerMargin()
{
  return 64.0 * 2.220446049250313e-16;
}

namespace detail
{
FFD_INLINE double Length(const Vec3<double>& v)
{
  return sqrt(Dot(v, v));
}

/// Centre (of the bounding box) and radius of the differences of the net along `axis`.
FFD_INLINE void DifferenceBall(const Vec3<double>* net, const int order[3], int axis, Vec3<double>& centre, double& r)
{
  const int s = NetStride(order, axis);
  Vec3<double> lo = { 1e308, 1e308, 1e308 }, hi = { -1e308, -1e308, -1e308 };
  ForEachRow(order, axis,
    [&](int first)
    {
      for (int i = 0; i + 1 < order[axis]; ++i)
      {
        const Vec3<double> d = net[first + (i + 1) * s] - net[first + i * s];
        lo = { Min(lo.x, d.x), Min(lo.y, d.y), Min(lo.z, d.z) };
        hi = { Max(hi.x, d.x), Max(hi.y, d.y), Max(hi.z, d.z) };
      }
    });
  centre = 0.5 * (lo + hi);
  double r2 = 0.0;
  ForEachRow(order, axis,
    [&](int first)
    {
      for (int i = 0; i + 1 < order[axis]; ++i)
      {
        const Vec3<double> e = net[first + (i + 1) * s] - net[first + i * s] - centre;
        r2 = Max(r2, Dot(e, e));
      }
    });
  r = sqrt(r2);
}
} // namespace detail

/**
 * True when the lower bound of the file's comment, with every radius widened by `slack`, shows
 * orientation * det(X_s, X_t, X_u) > 0 over the whole net.
 */
FFD_INLINE bool BoundCertifies(const Vec3<double>* net, const int order[3], double orientation, double slack)
{
  Vec3<double> c[3];
  double r[3];
  for (int a = 0; a < 3; ++a)
  {
    detail::DifferenceBall(net, order, a, c[a], r[a]);
    r[a] += slack;
  }
  const double l[3] = { detail::Length(c[0]), detail::Length(c[1]), detail::Length(c[2]) };
  const double x[3] = { detail::Length(Cross(c[1], c[2])), detail::Length(Cross(c[2], c[0])),
    detail::Length(Cross(c[0], c[1])) };
  const double loss = r[0] * x[0] + r[1] * x[1] + r[2] * x[2] + r[0] * r[1] * l[2] + r[1] * r[2] * l[0] +
    r[2] * r[0] * l[1] + r[0] * r[1] * r[2];
  const double size = (l[0] + r[0]) * (l[1] + r[1]) * (l[2] + r[2]);
  return orientation * Dot(c[0], Cross(c[1], c[2])) - loss > BoundMargin() * size;
}

namespace detail
{
/// The largest order per axis ExactCertifies() takes (every local basis, the global one up to degree 3).
constexpr int MaxExactOrder = 4;

/// C(n, k) for 0 <= k <= n <= 3 (the degrees of the columns' nets).
FFD_INLINE double SmallBinomial(int n, int k)
{
  return (k == 0 || k == n) ? 1.0 : double(n); // C(2, 1) = 2, C(3, 1) = C(3, 2) = 3
}

/// A column's net (the differences along one axis) with each coefficient times its Bernstein binomials: products
/// of such nets are the scaled nets of the products. Norm and Wide feed the rounding bound of ExactCertifies().
struct ScaledColumn
{
  int Order[3];
  Vec3<double> C[MaxExactOrder * MaxExactOrder * MaxExactOrder];
  double Norm[MaxExactOrder * MaxExactOrder * MaxExactOrder]; // |C|
  double Wide[MaxExactOrder * MaxExactOrder * MaxExactOrder]; // |C| + its scale times the slack
};

FFD_INLINE void ScaledDifferences(
  const Vec3<double>* net, const int order[3], int axis, double slack, ScaledColumn& out)
{
  for (int a = 0; a < 3; ++a)
  {
    out.Order[a] = order[a] - (a == axis ? 1 : 0);
  }
  const int s = NetStride(order, axis);
  for (int k = 0, c = 0; k < out.Order[2]; ++k)
  {
    for (int j = 0; j < out.Order[1]; ++j)
    {
      for (int i = 0; i < out.Order[0]; ++i, ++c)
      {
        const int at = i + order[0] * (j + order[1] * k);
        const double scale =
          SmallBinomial(out.Order[0] - 1, i) * SmallBinomial(out.Order[1] - 1, j) * SmallBinomial(out.Order[2] - 1, k);
        out.C[c] = scale * (net[at + s] - net[at]);
        out.Norm[c] = sqrt(Dot(out.C[c], out.C[c]));
        out.Wide[c] = out.Norm[c] + scale * slack;
      }
    }
  }
}

/// Calls f(a, b, sum) for every coefficient a of a net of orders `oa` and b of `ob`, sum being the index of
/// a + b in the product's net (orders oa + ob - 1).
template <typename F>
FFD_INLINE void ForEachProductTerm(const int oa[3], const int ob[3], F&& f)
{
  const int o[3] = { oa[0] + ob[0] - 1, oa[1] + ob[1] - 1, oa[2] + ob[2] - 1 };
  for (int ak = 0, a = 0; ak < oa[2]; ++ak)
    for (int aj = 0; aj < oa[1]; ++aj)
      for (int ai = 0; ai < oa[0]; ++ai, ++a)
        for (int bk = 0, b = 0; bk < ob[2]; ++bk)
          for (int bj = 0; bj < ob[1]; ++bj)
            for (int bi = 0; bi < ob[0]; ++bi, ++b)
            {
              f(a, b, (ai + bi) + o[0] * ((aj + bj) + o[1] * (ak + bk)));
            }
}
} // namespace detail

/**
 * True when every Bernstein coefficient of orientation * det(X_s, X_t, X_u) on the net exceeds its rounding bound
 * (the polynomial then is positive: its Bernstein weights are >= 0 and sum to 1). The coefficients are exact
 * products of the columns' nets: with each net's coefficients scaled by their binomials, the product's scaled
 * coefficients are the discrete convolution of the factors', and positive binomials keep every sign, so the
 * scaled coefficients are compared, through Y = X_t x X_u then X_s . Y. Each bound is the convolution of the
 * factors' norms widened by `slack` (times their scales) less that of their norms, plus 4 T eps of it for the
 * sums' rounding (T terms at most in a sum). Nets of more than MaxExactOrder coefficients along an axis are
 * left to subdivision (false).
 */
FFD_INLINE bool ExactCertifies(const Vec3<double>* net, const int order[3], double orientation, double slack)
{
  using detail::MaxExactOrder;
  if (order[0] > MaxExactOrder || order[1] > MaxExactOrder || order[2] > MaxExactOrder)
  {
    return false;
  }
  detail::ScaledColumn x[3];
  for (int a = 0; a < 3; ++a)
  {
    detail::ScaledDifferences(net, order, a, slack, x[a]);
  }
  constexpr int YSize = (2 * MaxExactOrder - 1) * (2 * MaxExactOrder - 1) * (2 * MaxExactOrder - 1);
  constexpr int DSize = (3 * MaxExactOrder - 2) * (3 * MaxExactOrder - 2) * (3 * MaxExactOrder - 2);
  const int yOrder[3] = { x[1].Order[0] + x[2].Order[0] - 1, x[1].Order[1] + x[2].Order[1] - 1,
    x[1].Order[2] + x[2].Order[2] - 1 };
  const int dOrder[3] = { x[0].Order[0] + yOrder[0] - 1, x[0].Order[1] + yOrder[1] - 1, x[0].Order[2] + yOrder[2] - 1 };
  Vec3<double> y[YSize];
  double yNorm[YSize], yWide[YSize], det[DSize], dNorm[DSize], dWide[DSize];
  for (int c = 0; c < NetSize(yOrder); ++c)
  {
    y[c] = { 0, 0, 0 };
    yNorm[c] = yWide[c] = 0.0;
  }
  for (int c = 0; c < NetSize(dOrder); ++c)
  {
    det[c] = dNorm[c] = dWide[c] = 0.0;
  }
  detail::ForEachProductTerm(x[1].Order, x[2].Order,
    [&](int a, int b, int c)
    {
      y[c] = y[c] + Cross(x[1].C[a], x[2].C[b]);
      yNorm[c] += x[1].Norm[a] * x[2].Norm[b];
      yWide[c] += x[1].Wide[a] * x[2].Wide[b];
    });
  detail::ForEachProductTerm(x[0].Order, yOrder,
    [&](int a, int b, int c)
    {
      det[c] += Dot(x[0].C[a], y[b]);
      dNorm[c] += x[0].Norm[a] * yNorm[b];
      dWide[c] += x[0].Wide[a] * yWide[b];
    });
  const double terms = double(NetSize(x[0].Order)) * NetSize(x[1].Order);
  for (int c = 0; c < NetSize(dOrder); ++c)
  {
    if (!(orientation * det[c] > dWide[c] - dNorm[c] + 4.0 * terms * 2.220446049250313e-16 * dWide[c]))
    {
      return false;
    }
  }
  return true;
}

/// True when orientation * det(X_s, X_t, X_u) at one of the net's 8 corners is <= CornerMargin() times its size.
FFD_INLINE bool HasFoldedCorner(const Vec3<double>* net, const int order[3], double orientation)
{
  const int s[3] = { detail::NetStride(order, 0), detail::NetStride(order, 1), detail::NetStride(order, 2) };
  for (int corner = 0; corner < 8; ++corner)
  {
    int base = 0, step[3];
    for (int a = 0; a < 3; ++a)
    {
      const bool high = (corner >> a) & 1;
      base += high ? (order[a] - 1) * s[a] : 0;
      step[a] = high ? -s[a] : s[a];
    }
    Vec3<double> d[3];
    for (int a = 0; a < 3; ++a) // the difference at the corner, pointing inwards from the high side: flip it
    {
      const Vec3<double> inward = net[base + step[a]] - net[base];
      d[a] = step[a] > 0 ? inward : -1.0 * inward;
    }
    const double size = detail::Length(d[0]) * detail::Length(d[1]) * detail::Length(d[2]);
    if (orientation * Dot(d[0], Cross(d[1], d[2])) <= CornerMargin() * size)
    {
      return true;
    }
  }
  return false;
}

/**
 * The state of the net at the start of `scratch` (made by CellNet(), `order` coefficients per axis, largest
 * |coordinate| `largest`), splitting undecided nets down to `maxDepth` levels (0 to MaxFoldDepth). `scratch` holds
 * (maxDepth + 1) NetSize(order) coefficients: one net per level. orientation: the sign of det(S, T, U), +1 or -1.
 */
FFD_INLINE FoldState CertifyNet(
  Vec3<double>* scratch, const int order[3], double orientation, int maxDepth, double largest)
{
  const double slack = Slack(order, maxDepth, largest);
  if (BoundCertifies(scratch, order, orientation, slack))
  {
    return FoldState::Certified;
  }
  if (HasFoldedCorner(scratch, order, orientation))
  {
    return FoldState::Folded;
  }
  if (maxDepth == 0 && ExactCertifies(scratch, order, orientation, slack))
  {
    return FoldState::Certified;
  }
  const int size = NetSize(order);
  int child[MaxFoldDepth + 1] = {};
  bool undecided = maxDepth == 0;
  int level = 0; // the level whose children are being visited
  while (level >= 0 && maxDepth > 0)
  {
    if (child[level] == 8)
    {
      --level;
      continue;
    }
    const int which = child[level]++;
    const Vec3<double>* parent = scratch + level * size;
    Vec3<double>* net = scratch + (level + 1) * size;
    for (int c = 0; c < size; ++c)
    {
      net[c] = parent[c];
    }
    for (int a = 0; a < 3; ++a)
    {
      SplitNet(net, order, a, 0.5, ((which >> a) & 1) == 0);
    }
    if (BoundCertifies(net, order, orientation, slack))
    {
      continue;
    }
    if (HasFoldedCorner(net, order, orientation))
    {
      return FoldState::Folded;
    }
    if (ExactCertifies(net, order, orientation, slack))
    {
      continue;
    }
    if (level + 1 == maxDepth)
    {
      undecided = true;
      continue;
    }
    child[++level] = 0;
  }
  return undecided ? FoldState::Undecided : FoldState::Certified;
}

/// The orientation of a frame (X0, S, T, U as in `FFDFrame`): +1 where det(S, T, U) > 0, else -1.
FFD_INLINE double FrameOrientation(const double frame[12])
{
  const Vec3<double> s = { frame[3], frame[4], frame[5] }, t = { frame[6], frame[7], frame[8] },
                     u = { frame[9], frame[10], frame[11] };
  return Dot(s, Cross(t, u)) > 0.0 ? 1.0 : -1.0;
}

namespace detail
{
/// orientation of (b - a, c - a, d - a): +1, -1, or 0 where it is zero to float64 precision (CornerMargin()).
FFD_INLINE int TetrahedronSign(const Vec3<double> p[4])
{
  const Vec3<double> e[3] = { p[1] - p[0], p[2] - p[0], p[3] - p[0] };
  const double v = Dot(e[0], Cross(e[1], e[2]));
  const double size = Length(e[0]) * Length(e[1]) * Length(e[2]);
  return v > CornerMargin() * size ? 1 : (v < -CornerMargin() * size ? -1 : 0);
}
} // namespace detail

/**
 * A tetrahedron's state: its affine map's det J is its deformed volume over its rest volume, one number, so the
 * certificate is exact (but for rounding): certified when both volumes have one sign, folded when they differ or
 * the deformed one is zero to float64 precision; NotChecked for a flat rest tetrahedron (it has no map).
 */
FFD_INLINE FoldState TetrahedronState(const Vec3<double> rest[4], const Vec3<double> moved[4])
{
  const int before = detail::TetrahedronSign(rest);
  if (before == 0)
  {
    return FoldState::NotChecked;
  }
  return detail::TetrahedronSign(moved) == before ? FoldState::Certified : FoldState::Folded;
}

} // namespace ffd

#endif
