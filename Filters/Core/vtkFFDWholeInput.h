// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file vtkFFDWholeInput.h
 * @brief The update request of the filters whose output depends on all of an input (private to the Filters
 * module): a lattice's every control point depends on the whole voxel grid, a refined or coarsened lattice on the
 * whole lattice and every point of the mesh.
 */
#ifndef vtkFFDWholeInput_h
#define vtkFFDWholeInput_h

#include "vtkInformation.h"
#include "vtkStreamingDemandDrivenPipeline.h"

/// Asks `inInfo`'s producer (if any) for one piece without ghost levels, and a structured input's whole extent.
inline void vtkFFDRequestWholeInput(vtkInformation* inInfo)
{
  if (!inInfo)
  {
    return;
  }
  inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER(), 0);
  inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES(), 1);
  inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_GHOST_LEVELS(), 0);
  if (inInfo->Has(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT()))
  {
    inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_EXTENT(),
      inInfo->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT()), 6);
  }
}

#endif
