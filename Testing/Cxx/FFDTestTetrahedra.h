// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDTestTetrahedra.h
 * @brief Tetrahedral lattices built by hand, for the tests and the benchmark of the tetrahedral FFD: the Kuhn
 * triangulation of a box (a user-supplied lattice, as vtkFFDDeform accepts any vtkUnstructuredGrid of
 * tetrahedra with RestPosition).
 */
#ifndef FFDTestTetrahedra_h
#define FFDTestTetrahedra_h

#include "vtkCellArray.h"
#include "vtkCellType.h"
#include "vtkDoubleArray.h"
#include "vtkFFDDataContract.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkSmartPointer.h"
#include "vtkUnstructuredGrid.h"

#include <random>
#include <utility>

namespace ffdtest
{
/**
 * The Kuhn triangulation of the box `bounds` (xmin, xmax, ymin, ymax, zmin, zmax) split into n^3 cells: six
 * tetrahedra around each cell's main diagonal, conforming across cells (6 n^3 tetrahedra, (n + 1)^3 nodes).
 * The interior nodes are jittered by up to `jitter` of a cell (irregular tetrahedra), and every third
 * tetrahedron is inverted (two nodes swapped) when `invertSome`. Points and RestPosition are doubles.
 */
inline vtkSmartPointer<vtkUnstructuredGrid> KuhnBoxLattice(
  int n, const double bounds[6], double jitter = 0.0, bool invertSome = false, unsigned seed = 1)
{
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  double h[3];
  for (int a = 0; a < 3; ++a)
  {
    h[a] = (bounds[2 * a + 1] - bounds[2 * a]) / n;
  }
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  const auto id = [n](int i, int j, int k) { return vtkIdType(i + (n + 1) * (j + (n + 1) * k)); };
  for (int k = 0; k <= n; ++k)
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i)
      {
        const bool interior = i > 0 && i < n && j > 0 && j < n && k > 0 && k < n;
        const double e = interior ? jitter : 0.0;
        points->InsertNextPoint(bounds[0] + (i + e * unit(rng)) * h[0], bounds[2] + (j + e * unit(rng)) * h[1],
          bounds[4] + (k + e * unit(rng)) * h[2]);
      }
  vtkNew<vtkCellArray> cells;
  cells->AllocateExact(6 * vtkIdType(n) * n * n, 24 * vtkIdType(n) * n * n);
  const int orders[6][3] = { { 0, 1, 2 }, { 0, 2, 1 }, { 1, 0, 2 }, { 1, 2, 0 }, { 2, 0, 1 }, { 2, 1, 0 } };
  vtkIdType count = 0;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        for (const auto& order : orders)
        {
          int c[3] = { i, j, k };
          vtkIdType t[4];
          t[0] = id(c[0], c[1], c[2]);
          for (int s = 0; s < 3; ++s)
          {
            ++c[order[s]];
            t[s + 1] = id(c[0], c[1], c[2]);
          }
          if (invertSome && count % 3 == 0)
          {
            std::swap(t[1], t[2]);
          }
          cells->InsertNextCell(4, t);
          ++count;
        }
  auto lattice = vtkSmartPointer<vtkUnstructuredGrid>::New();
  lattice->SetPoints(points);
  lattice->SetCells(VTK_TETRA, cells);
  vtkNew<vtkDoubleArray> rest;
  rest->DeepCopy(points->GetData());
  rest->SetName(vtkFFDDataContract::RestPositionArrayName());
  lattice->GetPointData()->AddArray(rest);
  return lattice;
}
} // namespace ffdtest

#endif
