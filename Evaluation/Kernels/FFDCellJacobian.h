// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDCellJacobian.h
 * @brief The corner Jacobians of linear volume cells (tetrahedra, hexahedra, wedges, pyramids), raw and scaled.
 *
 * A linear cell's map from its reference cell has, at each corner, the Jacobian whose columns are the corner's
 * three edges (in VTK's node order, oriented so that a valid cell has det > 0 at every corner); a hexahedron's
 * trilinear map also has its Jacobian at the centre, the principal axes (sums of the four edges along each
 * direction). The scaled Jacobian is the smallest such det over the cell, each divided by the product of its
 * columns' lengths and times a factor that makes the ideal cell 1: sqrt(2) for a tetrahedron (whose det is one
 * number: VTK's vtkMeshQuality::TetScaledJacobian), 1 for a hexahedron (vtkMeshQuality::HexScaledJacobian, with
 * the centre), 2 / sqrt(3) for a wedge (a right prism on an equilateral triangle), sqrt(2) for a pyramid (over its
 * base corners; equilateral faces). A zero-length column gives 0. Plain data, host and device alike.
 */
#ifndef FFDCellJacobian_h
#define FFDCellJacobian_h

#include "FFDVector.h"

namespace ffd
{

/// The linear volume cells, each with VTK's node order (a VTK_VOXEL is a hexahedron once its nodes are reordered).
enum class VolumeCell
{
  Tetrahedron,
  Hexahedron,
  Wedge,
  Pyramid,
};

/// The most Jacobians a cell has: a hexahedron's 8 corners and its centre.
constexpr int MaxCellJacobians = 9;

namespace detail
{
/// The corners of a cell of that type: corner c's columns are nodes[c][1..3] minus nodes[c][0]. Returns their
/// number. (Tables filled here rather than static ones, which device code cannot hold.)
FFD_INLINE int CornerNodes(VolumeCell type, int nodes[8][4])
{
  const int tetrahedron[1][4] = { { 0, 1, 2, 3 } };
  const int hexahedron[8][4] = { { 0, 1, 3, 4 }, { 1, 2, 0, 5 }, { 2, 3, 1, 6 }, { 3, 0, 2, 7 }, { 4, 7, 5, 0 },
    { 5, 4, 6, 1 }, { 6, 5, 7, 2 }, { 7, 6, 4, 3 } };
  // VTK's wedge: the base (0, 1, 2) faces away from the top (3, 4, 5) by the right-hand rule.
  const int wedge[6][4] = { { 0, 2, 1, 3 }, { 1, 0, 2, 4 }, { 2, 1, 0, 5 }, { 3, 4, 5, 0 }, { 4, 5, 3, 1 },
    { 5, 3, 4, 2 } };
  // VTK's pyramid: the base (0, 1, 2, 3) faces the apex 4 by the right-hand rule; the apex, with 4 edges, is left
  // out.
  const int pyramid[4][4] = { { 0, 1, 3, 4 }, { 1, 2, 0, 4 }, { 2, 3, 1, 4 }, { 3, 0, 2, 4 } };
  const int(*table)[4] = type == VolumeCell::Tetrahedron ? tetrahedron
    : type == VolumeCell::Hexahedron                     ? hexahedron
    : type == VolumeCell::Wedge                          ? wedge
                                                         : pyramid;
  const int count = type == VolumeCell::Tetrahedron ? 1
    : type == VolumeCell::Hexahedron                ? 8
    : type == VolumeCell::Wedge                     ? 6
                                                    : 4;
  for (int c = 0; c < count; ++c)
  {
    for (int i = 0; i < 4; ++i)
    {
      nodes[c][i] = table[c][i];
    }
  }
  return count;
}

FFD_INLINE double Norm(const Vec3<double>& v)
{
  return sqrt(Dot(v, v));
}
} // namespace detail

/// Nodes of a cell of that type.
FFD_INLINE int NodesOf(VolumeCell type)
{
  return type == VolumeCell::Tetrahedron ? 4
                                         : (type == VolumeCell::Hexahedron ? 8 : (type == VolumeCell::Wedge ? 6 : 5));
}

/**
 * The cell's Jacobian determinants (`det`) and their scaled values (`scaled`, see the file's comment) at each
 * corner, and a hexahedron's at its centre; returns their number. `p` holds the cell's nodes in VTK order.
 */
FFD_INLINE int CellJacobians(VolumeCell type, const Vec3<double>* p, double* det, double* scaled)
{
  int nodes[8][4];
  const int corners = detail::CornerNodes(type, nodes);
  double product[MaxCellJacobians];
  int count = 0;
  for (int c = 0; c < corners; ++c, ++count)
  {
    const int* n = nodes[c];
    const Vec3<double> a = p[n[1]] - p[n[0]], b = p[n[2]] - p[n[0]], e = p[n[3]] - p[n[0]];
    det[count] = Dot(a, Cross(b, e));
    product[count] = detail::Norm(a) * detail::Norm(b) * detail::Norm(e);
  }
  if (type == VolumeCell::Tetrahedron) // one det: divided by the largest product over the 4 corners
  {
    for (int c = 1; c < 4; ++c)
    {
      const Vec3<double> a = p[(c + 1) % 4] - p[c], b = p[(c + 2) % 4] - p[c], e = p[(c + 3) % 4] - p[c];
      const double other = detail::Norm(a) * detail::Norm(b) * detail::Norm(e);
      product[0] = other > product[0] ? other : product[0];
    }
  }
  if (type == VolumeCell::Hexahedron) // the principal axes at the centre
  {
    const Vec3<double> xi = (p[1] - p[0]) + (p[2] - p[3]) + (p[5] - p[4]) + (p[6] - p[7]);
    const Vec3<double> eta = (p[3] - p[0]) + (p[2] - p[1]) + (p[7] - p[4]) + (p[6] - p[5]);
    const Vec3<double> zeta = (p[4] - p[0]) + (p[5] - p[1]) + (p[6] - p[2]) + (p[7] - p[3]);
    det[count] = Dot(xi, Cross(eta, zeta));
    product[count++] = detail::Norm(xi) * detail::Norm(eta) * detail::Norm(zeta);
  }
  const double factor = type == VolumeCell::Hexahedron ? 1.0
    : type == VolumeCell::Wedge                        ? 1.1547005383792515 // 2 / sqrt(3)
                                                       : 1.4142135623730951;                       // sqrt(2)
  for (int c = 0; c < count; ++c)
  {
    scaled[c] = product[c] > 0.0 ? factor * det[c] / product[c] : 0.0;
  }
  return count;
}

} // namespace ffd

#endif
