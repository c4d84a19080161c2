// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file vtkFFDPipelineKeys.h
 * @brief Information keys that the filters set in RequestInformation (private to the Filters module).
 *
 * A dense lattice is a vtkStructuredGrid, whose consumers (vtkDataSetSurfaceFilter, vtkExtractEdges, ParaView's
 * representations) ask for pieces of its WHOLE_EXTENT: without one announced before execution, the executive
 * gives them an empty output. The lattice's extent follows the divisions of the voxel grid, which
 * vtkFFDVoxelize knows before it executes: it announces them with DIVISIONS(), which travels downstream through
 * any filter (ParaView puts one after every filter), and vtkFFDBuildLattice turns them into the WHOLE_EXTENT of
 * its dense output.
 */
#ifndef vtkFFDPipelineKeys_h
#define vtkFFDPipelineKeys_h

#include "vtkInformationIntegerVectorKey.h"

class vtkFFDPipelineKeys
{
public:
  /// The voxels per axis (3 ints) of the voxel grid that this output information describes.
  static vtkInformationIntegerVectorKey* DIVISIONS();
};

/// An integer-vector key that every executive copies from a filter's first input to its outputs, as
/// vtkInformationDataObjectMetaDataKey does with data objects.
class vtkFFDDownstreamIntegerVectorKey : public vtkInformationIntegerVectorKey
{
public:
  vtkTypeMacro(vtkFFDDownstreamIntegerVectorKey, vtkInformationIntegerVectorKey);
  vtkFFDDownstreamIntegerVectorKey(const char* name, const char* location, int length)
    : vtkInformationIntegerVectorKey(name, location, length)
  {
  }
  void CopyDefaultInformation(vtkInformation* request, vtkInformation* fromInfo, vtkInformation* toInfo) override;
};

#endif
