// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file vtkFFDLatticeDisplacements.h
 * @brief Reads a lattice's deformation, its points minus `RestPosition` (private to the Filters module).
 */
#ifndef vtkFFDLatticeDisplacements_h
#define vtkFFDLatticeDisplacements_h

#include "vtkDataArray.h"
#include "vtkPointSet.h"
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
  // In parallel: a lattice of 100 k nodes, read serially, would hold up every update by a millisecond; in tasks
  // of at least 4096 nodes, so that a small lattice is read in one.
  std::atomic<vtkIdType> firstNotFinite(count);
  vtkSMPTools::For(0, count, 4096, [&](vtkIdType begin, vtkIdType end) {
    for (vtkIdType p = begin; p < end; ++p)
    {
      double x[3], x0[3];
      lattice->GetPoint(p, x);
      rest->GetTuple(p, x0);
      for (int c = 0; c < 3; ++c)
      {
        const double d = x[c] - x0[c];
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
          (*restValues)[3 * p + c] = x0[c];
        }
      }
    }
  });
  return firstNotFinite == count ? -1 : firstNotFinite.load();
}

#endif
