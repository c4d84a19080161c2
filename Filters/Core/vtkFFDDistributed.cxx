// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDDistributed.h"

#include "vtkCommunicator.h"
#include "vtkDataSetAttributes.h"
#include "vtkDoubleArray.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkMultiProcessController.h"
#include "vtkNew.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkTypeInt64Array.h"
#include "vtkUnsignedCharArray.h"

#include <algorithm>

namespace
{
// AllGatherV of `values` into every process's concatenation, in process order.
template <typename T, typename ArrayT>
std::vector<T> GatherAll(vtkMultiProcessController* controller, const std::vector<T>& values)
{
  vtkNew<ArrayT> send;
  send->SetNumberOfValues(static_cast<vtkIdType>(values.size()));
  std::copy(values.begin(), values.end(), send->GetPointer(0));
  vtkNew<ArrayT> received;
  controller->AllGatherV(send, received);
  return std::vector<T>(received->GetPointer(0), received->GetPointer(0) + received->GetNumberOfValues());
}
} // namespace

//------------------------------------------------------------------------------
bool vtkFFDRequestOwnPiece(vtkMultiProcessController* controller, vtkInformationVector** inputVector)
{
  if (!vtkFFDIsDistributed(controller))
  {
    return false;
  }
  if (vtkInformation* inInfo = inputVector[0]->GetInformationObject(0))
  {
    inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER(), controller->GetLocalProcessId());
    inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES(), controller->GetNumberOfProcesses());
    inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_GHOST_LEVELS(), 0);
  }
  return true;
}

//------------------------------------------------------------------------------
vtkSmartPointer<vtkDataArray> vtkFFDOwnedPoints(vtkPointSet* input)
{
  if (!input->GetPoints()) // an empty piece
  {
    auto none = vtkSmartPointer<vtkDoubleArray>::New();
    none->SetNumberOfComponents(3);
    return none;
  }
  vtkDataArray* points = input->GetPoints()->GetData();
  vtkUnsignedCharArray* ghostArray = input->GetPointGhostArray();
  const unsigned char* ghosts = ghostArray ? ghostArray->GetPointer(0) : nullptr;
  auto isOwned = [ghosts](vtkIdType id) { return !ghosts || !(ghosts[id] & vtkDataSetAttributes::DUPLICATEPOINT); };
  const vtkIdType count = points->GetNumberOfTuples();
  vtkIdType owned = 0;
  for (vtkIdType id = 0; id < count; ++id)
  {
    owned += isOwned(id) ? 1 : 0;
  }
  if (owned == count)
  {
    return points;
  }
  auto copy = vtkSmartPointer<vtkDataArray>::Take(points->NewInstance());
  copy->SetNumberOfComponents(3);
  copy->SetNumberOfTuples(owned);
  for (vtkIdType id = 0, next = 0; id < count; ++id)
  {
    if (isOwned(id))
    {
      copy->SetTuple(next++, id, points);
    }
  }
  return copy;
}

//------------------------------------------------------------------------------------------------------------
bool vtkFFDIsDistributed(vtkMultiProcessController* controller)
{
  return controller && controller->GetNumberOfProcesses() > 1;
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDSumOverProcesses(vtkMultiProcessController* controller, std::vector<ffd::ExactSum>& sums)
{
  if (!vtkFFDIsDistributed(controller))
  {
    return;
  }
  // Each sum's partials, preceded by their count.
  std::vector<double> mine;
  for (const ffd::ExactSum& sum : sums)
  {
    mine.push_back(static_cast<double>(sum.GetPartials().size()));
    mine.insert(mine.end(), sum.GetPartials().begin(), sum.GetPartials().end());
  }
  const std::vector<double> all = GatherAll<double, vtkDoubleArray>(controller, mine);
  std::vector<ffd::ExactSum> total(sums.size());
  for (std::size_t at = 0; at < all.size();)
  {
    for (ffd::ExactSum& sum : total)
    {
      const std::size_t count = static_cast<std::size_t>(all[at++]);
      for (std::size_t p = 0; p < count; ++p)
      {
        sum.Add(all[at++]);
      }
    }
  }
  sums = total;
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDBoundsOverProcesses(vtkMultiProcessController* controller, vtkIdType& count, double low[3], double high[3])
{
  if (!vtkFFDIsDistributed(controller))
  {
    return;
  }
  const vtkIdType mine = count;
  controller->AllReduce(&mine, &count, 1, vtkCommunicator::SUM_OP);
  const double myLow[3] = { low[0], low[1], low[2] }, myHigh[3] = { high[0], high[1], high[2] };
  controller->AllReduce(myLow, low, 3, vtkCommunicator::MIN_OP);
  controller->AllReduce(myHigh, high, 3, vtkCommunicator::MAX_OP);
}

//------------------------------------------------------------------------------------------------------------
std::vector<vtkTypeInt64> vtkFFDUnionOverProcesses(
  vtkMultiProcessController* controller, const std::vector<vtkTypeInt64>& values)
{
  if (!vtkFFDIsDistributed(controller))
  {
    return values;
  }
  std::vector<vtkTypeInt64> all = GatherAll<vtkTypeInt64, vtkTypeInt64Array>(controller, values);
  std::sort(all.begin(), all.end());
  all.erase(std::unique(all.begin(), all.end()), all.end());
  return all;
}

//------------------------------------------------------------------------------------------------------------
std::vector<double> vtkFFDGatherOverProcesses(vtkMultiProcessController* controller, const std::vector<double>& values)
{
  return vtkFFDIsDistributed(controller) ? GatherAll<double, vtkDoubleArray>(controller, values) : values;
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDAnyOverProcesses(vtkMultiProcessController* controller, unsigned char* flags, vtkIdType count)
{
  if (!vtkFFDIsDistributed(controller))
  {
    return;
  }
  const std::vector<unsigned char> mine(flags, flags + count);
  controller->AllReduce(mine.data(), flags, count, vtkCommunicator::MAX_OP);
}
