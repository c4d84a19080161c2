// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDPipelineKeys.h"

#include "vtkDemandDrivenPipeline.h"
#include "vtkFFDBuildLattice.h"
#include "vtkInformation.h"
#include "vtkInformationIntegerVectorKey.h"
#include "vtkInformationVector.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkStructuredGrid.h"

#include <algorithm>
#include <string>
#include <vector>

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

//------------------------------------------------------------------------------
int vtkFFDPipelineKeys::AnnounceTimes(
  int done, vtkInformation* request, vtkInformationVector** inputs, int ports, vtkInformationVector* outputs)
{
  if (!done || !request->Has(vtkDemandDrivenPipeline::REQUEST_INFORMATION()))
  {
    return done;
  }
  vtkInformation* outInfo = outputs->GetInformationObject(0);
  using SDDP = vtkStreamingDemandDrivenPipeline;
  std::vector<double> steps;
  double range[2] = { 0, 0 };
  bool timed = false, stepped = true;
  for (int port = 0; port < ports; ++port)
  {
    for (int c = 0; inputs[port] && c < inputs[port]->GetNumberOfInformationObjects(); ++c)
    {
      vtkInformation* inInfo = inputs[port]->GetInformationObject(c);
      const double* own = inInfo->Get(SDDP::TIME_STEPS());
      const int count = own ? inInfo->Length(SDDP::TIME_STEPS()) : 0;
      double first = count ? own[0] : 0, last = count ? own[count - 1] : 0;
      if (inInfo->Length(SDDP::TIME_RANGE()) == 2)
      {
        first = inInfo->Get(SDDP::TIME_RANGE())[0];
        last = inInfo->Get(SDDP::TIME_RANGE())[1];
      }
      else if (count == 0)
      {
        continue; // no time
      }
      range[0] = timed ? std::min(range[0], first) : first;
      range[1] = timed ? std::max(range[1], last) : last;
      timed = true;
      stepped = stepped && count > 0;
      steps.insert(steps.end(), own, own + count);
    }
  }
  outInfo->Remove(SDDP::TIME_STEPS());
  outInfo->Remove(SDDP::TIME_RANGE());
  if (!timed)
  {
    return done;
  }
  if (stepped)
  {
    std::sort(steps.begin(), steps.end());
    steps.erase(std::unique(steps.begin(), steps.end()), steps.end());
    outInfo->Set(SDDP::TIME_STEPS(), steps.data(), static_cast<int>(steps.size()));
  }
  outInfo->Set(SDDP::TIME_RANGE(), range, 2);
  return done;
}
