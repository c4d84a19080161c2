// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDPipelineKeys.h"

#include "vtkDemandDrivenPipeline.h"
#include "vtkFFDBuildLattice.h"
#include "vtkInformation.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkStructuredGrid.h"

#include <string>

// Each key is registered with vtkInformationKeyLookup by its constructor, which deletes it at exit, as VTK's own.
//------------------------------------------------------------------------------
vtkInformationIntegerVectorKey* vtkFFDPipelineKeys::DIVISIONS()
{
  static vtkInformationIntegerVectorKey* const key =
    new vtkFFDDownstreamIntegerVectorKey("DIVISIONS", "vtkFFDPipelineKeys", 3);
  return key;
}

//------------------------------------------------------------------------------
vtkInformationIntegerVectorKey* vtkFFDPipelineKeys::BASIS()
{
  static vtkInformationIntegerVectorKey* const key =
    new vtkFFDDownstreamIntegerVectorKey("BASIS", "vtkFFDPipelineKeys", 1);
  return key;
}

//------------------------------------------------------------------------------
void vtkFFDPipelineKeys::AnnounceLattice(vtkInformation* outInfo, int basis, const int divisions[3])
{
  outInfo->Set(DIVISIONS(), divisions, 3);
  outInfo->Set(BASIS(), &basis, 1);
  outInfo->Remove(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT());
  int points[3];
  std::string why; // an impossible lattice: its execution reports why
  if (vtkStructuredGrid::GetData(outInfo) &&
    vtkFFDBuildLattice::GetControlPointsPerAxis(basis, divisions, points, why, vtkFFDBuildLattice::DENSE))
  {
    const int extent[6] = { 0, points[0] - 1, 0, points[1] - 1, 0, points[2] - 1 };
    outInfo->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), extent, 6);
  }
}

//------------------------------------------------------------------------------
void vtkFFDPipelineKeys::Forget(vtkInformation* outInfo)
{
  outInfo->Remove(DIVISIONS());
  outInfo->Remove(BASIS());
  outInfo->Remove(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT());
}

//------------------------------------------------------------------------------
bool vtkFFDPipelineKeys::AnnouncedLattice(vtkInformation* inInfo, int& basis, int divisions[3])
{
  if (!inInfo || !inInfo->Has(DIVISIONS()) || !inInfo->Has(BASIS()))
  {
    return false;
  }
  inInfo->Get(DIVISIONS(), divisions);
  basis = inInfo->Get(BASIS(), 0);
  return true;
}

//------------------------------------------------------------------------------
void vtkFFDDownstreamIntegerVectorKey::CopyDefaultInformation(
  vtkInformation* request, vtkInformation* fromInfo, vtkInformation* toInfo)
{
  if (request->Has(vtkDemandDrivenPipeline::REQUEST_INFORMATION()))
  {
    this->ShallowCopy(fromInfo, toInfo);
  }
}
