// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDPipelineKeys.h"

#include "vtkDemandDrivenPipeline.h"
#include "vtkFFDBuildLattice.h"
#include "vtkInformation.h"
#include "vtkInformationIntegerVectorKey.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkStructuredGrid.h"

#include <string>

namespace
{
/// An integer-vector key that every executive copies from a filter's first input to its outputs at
/// REQUEST_INFORMATION, as vtkInformationDataObjectMetaDataKey does with data objects.
class DownstreamIntegerVectorKey : public vtkInformationIntegerVectorKey
{
public:
  DownstreamIntegerVectorKey(const char* name, int length)
    : vtkInformationIntegerVectorKey(name, "vtkFFDPipelineKeys", length)
  {
  }
  void CopyDefaultInformation(vtkInformation* request, vtkInformation* fromInfo, vtkInformation* toInfo) override
  {
    if (request->Has(vtkDemandDrivenPipeline::REQUEST_INFORMATION()))
    {
      this->ShallowCopy(fromInfo, toInfo);
    }
  }
};
} // namespace

// Each key is registered with vtkInformationKeyLookup by its constructor, which deletes it at exit, as VTK's own.
//------------------------------------------------------------------------------
vtkInformationIntegerVectorKey* vtkFFDPipelineKeys::DIVISIONS()
{
  static vtkInformationIntegerVectorKey* const key = new DownstreamIntegerVectorKey("DIVISIONS", 3);
  return key;
}

//------------------------------------------------------------------------------
vtkInformationIntegerVectorKey* vtkFFDPipelineKeys::BASIS()
{
  static vtkInformationIntegerVectorKey* const key = new DownstreamIntegerVectorKey("BASIS", 1);
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
