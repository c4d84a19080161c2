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
