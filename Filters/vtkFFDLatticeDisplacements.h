// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file vtkFFDLatticeDisplacements.h
 * @brief Reads a lattice's deformation, its points minus `RestPosition` (private to the Filters module).
 */
#ifndef vtkFFDLatticeDisplacements_h
#define vtkFFDLatticeDisplacements_h

#include "vtkArrayDispatch.h"
#include "vtkDataArray.h"
#include "vtkDataArrayRange.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkSMPTools.h"

#include <atomic>
#include <cmath>
#include <vector>

/**
 * The deformation of `lattice`, its points minus `rest` (3 components, a tuple per point), 3 doubles per point
 * into `displacements`, and the rest positions into `restValues` when not null. Returns the first point whose
 * position or rest position is not finite (the outputs then hold non-finite values), or -1.
 */
inline vtkIdType vtkFFDReadLatticeDisplacements(
  vtkPointSet* lattice, vtkDataArray* rest, std::vector<double>& displacements, std::vector<double>* restValues)
{
  const vtkIdType count = lattice->GetNumberOfPoints();
  displacements.resize(3 * count);
  if (restValues)
  {
    restValues->resize(3 * count);
  }
  if (count == 0)
  {
    return -1;
  }
  std::atomic<vtkIdType> firstNotFinite(count);
  // Read through the arrays' own types where they are float or double (vtkArrayDispatch): vtkDataArray's
  // virtual tuple access is a noticeable part of an update's fixed cost.
  auto read = [&](auto* points, auto* restPositions)
  {
    const auto x = vtk::DataArrayTupleRange<3>(points);
    const auto x0 = vtk::DataArrayTupleRange<3>(restPositions);
    // In parallel: a lattice of 100 k nodes, read serially, would hold up every update by a millisecond; in
    // tasks of at least 4096 nodes, so that a small lattice is read in one.
    vtkSMPTools::For(0, count, 4096,
      [&](vtkIdType begin, vtkIdType end)
      {
        for (vtkIdType p = begin; p < end; ++p)
        {
          for (int c = 0; c < 3; ++c)
          {
            const double rest0 = double(x0[p][c]);
            const double d = double(x[p][c]) - rest0;
            if (!std::isfinite(d))
            {
              vtkIdType first = firstNotFinite.load();
              while (p < first && !firstNotFinite.compare_exchange_weak(first, p))
              {
              }
            }
            displacements[3 * p + c] = d;
            if (restValues)
            {
              (*restValues)[3 * p + c] = rest0;
            }
          }
        }
      });
  };
  vtkDataArray* points = lattice->GetPoints()->GetData();
  if (!vtkArrayDispatch::Dispatch2ByValueType<vtkArrayDispatch::Reals, vtkArrayDispatch::Reals>::Execute(
        points, rest, read))
  {
    read(points, rest);
  }
  return firstNotFinite == count ? -1 : firstNotFinite.load();
}

#endif
