// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file vtkFFDForInChunks.h
 * @brief vtkSMPTools::For in a few chunks, with progress and abort between them (private to the Filters module).
 */
#ifndef vtkFFDForInChunks_h
#define vtkFFDForInChunks_h

#include "vtkAlgorithm.h"
#include "vtkSMPTools.h"

#include <algorithm>
#include <cmath>

/**
 * The grain of a parallel loop over n items of about `cost` units of work each (control points read per point,
 * say): tasks of at least 2^15 units, so that scheduling stays a small part of a task (left to itself, TBB cut
 * an evaluation of 26 k points into tasks whose scheduling cost as much as the points), four tasks per thread
 * where that is more, and at most 16384 items, so that large inputs are still shared out evenly. A constant
 * grain of 16384 points left a mesh of 13.8 k points on one thread whatever the lattice.
 */
inline vtkIdType vtkFFDGrain(vtkIdType n, double cost)
{
  const vtkIdType least = static_cast<vtkIdType>(std::ceil(32768.0 / std::max(cost, 1.0)));
  const vtkIdType even = n / (4 * std::max(1, vtkSMPTools::GetEstimatedNumberOfThreads()));
  return std::max<vtkIdType>(1, std::min<vtkIdType>(16384, std::max(least, even)));
}

/**
 * Runs functor(begin, end) over [0, n) as a few vtkSMPTools::For calls, so that progress is reported and abort
 * honoured between them (never from inside an SMP body). `self` may be null. Returns false when aborted. A
 * chunk is at least 2^20 items (points, or blocks of 16): each call starts and joins the threads, which cost a
 * tenth of an evaluation of 0.4 M points split into 6 calls. Each call's tasks take at least `grain` items: left
 * to itself, TBB cut an evaluation of 26 k points into tasks whose scheduling cost as much as the points.
 */
template <typename Functor>
bool vtkFFDForInChunks(
  vtkAlgorithm* self, vtkIdType n, vtkIdType grain, Functor& functor, double progressBegin, double progressEnd)
{
  const vtkIdType chunks = std::max<vtkIdType>(1, std::min<vtkIdType>(10, n >> 20));
  for (vtkIdType c = 0; c < chunks; ++c)
  {
    if (self && self->GetAbortExecute())
    {
      return false;
    }
    vtkSMPTools::For(n * c / chunks, n * (c + 1) / chunks, grain, functor);
    if (self)
    {
      self->UpdateProgress(progressBegin + (progressEnd - progressBegin) * double(c + 1) / double(chunks));
    }
  }
  return true;
}

#endif
