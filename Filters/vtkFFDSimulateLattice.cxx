// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDSimulateLattice.h"

#include "vtkFFDLatticeDynamics.h"

#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include <algorithm>
#include <cmath>

vtkStandardNewMacro(vtkFFDSimulateLattice);
vtkCxxSetObjectMacro(vtkFFDSimulateLattice, Dynamics, vtkFFDLatticeDynamics);

//------------------------------------------------------------------------------------------------------------
vtkFFDSimulateLattice::vtkFFDSimulateLattice()
  : Dynamics(vtkFFDLatticeDynamics::New())
  , EndTime(10.0)
  , Working(nullptr)
  , WorkingStep(0)
  , WorkingTime(0)
{
  this->SetNumberOfInputPorts(2);
}

vtkFFDSimulateLattice::~vtkFFDSimulateLattice()
{
  this->SetDynamics(nullptr);
  if (this->Working)
  {
    this->Working->Delete();
  }
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDSimulateLattice::SetMeshData(vtkPointSet* mesh)
{
  this->SetInputData(1, mesh);
}

//------------------------------------------------------------------------------------------------------------
vtkMTimeType vtkFFDSimulateLattice::GetMTime()
{
  const vtkMTimeType time = this->Superclass::GetMTime();
  return this->Dynamics ? std::max(time, this->Dynamics->GetMTime()) : time;
}

//------------------------------------------------------------------------------------------------------------
int vtkFFDSimulateLattice::FillInputPortInformation(int port, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkPointSet");
  if (port == 1)
  {
    info->Set(vtkAlgorithm::INPUT_IS_OPTIONAL(), 1);
  }
  return 1;
}

//------------------------------------------------------------------------------------------------------------
int vtkFFDSimulateLattice::ExecuteInformation(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkInformation* info = outputVector->GetInformationObject(0);
  info->Remove(vtkStreamingDemandDrivenPipeline::TIME_STEPS());
  const double range[2] = { 0.0, this->EndTime };
  info->Set(vtkStreamingDemandDrivenPipeline::TIME_RANGE(), range, 2);
  return 1;
}

//------------------------------------------------------------------------------------------------------------
int vtkFFDSimulateLattice::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkPointSet* input = vtkPointSet::GetData(inputVector[0]);
  vtkPointSet* mesh = vtkPointSet::GetData(inputVector[1]);
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  vtkPointSet* output = vtkPointSet::GetData(outInfo);
  if (!input || !output)
  {
    vtkErrorMacro("Expected a lattice (a vtkPointSet) on input 0.");
    return 0;
  }
  if (!this->Dynamics)
  {
    vtkErrorMacro("No Dynamics object: SetDynamics() to a vtkFFDLatticeDynamics.");
    return 0;
  }
  const double t = outInfo->Has(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP())
    ? outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP())
    : 0.0;
  const double steps = std::floor(std::max(t, 0.0) / this->Dynamics->GetTimeStep() + 0.5);
  if (!(steps < double(VTK_INT_MAX)))
  {
    vtkErrorMacro(<< "Time " << t << " is " << steps << " time steps of " << this->Dynamics->GetTimeStep()
                  << " s away: too many.");
    return 0;
  }
  const vtkIdType target = static_cast<vtkIdType>(steps);

  // Continue the last simulation when nothing changed and the time is not earlier; else start again.
  vtkMTimeType sources = std::max(this->GetMTime(), input->GetMTime());
  if (mesh)
  {
    sources = std::max(sources, mesh->GetMTime());
  }
  if (!this->Working || sources > this->WorkingTime || target < this->WorkingStep ||
    this->Dynamics->GetLattice() != this->Working || this->Dynamics->GetMesh() != mesh)
  {
    // The same working lattice when it can be: the Dynamics object then keeps its MTime.
    if (this->Working && !this->Working->IsA(input->GetClassName()))
    {
      this->Working->Delete();
      this->Working = nullptr;
    }
    if (!this->Working)
    {
      this->Working = input->NewInstance();
    }
    this->Working->DeepCopy(input);
    this->Dynamics->SetLattice(this->Working);
    this->Dynamics->SetMesh(mesh);
    this->WorkingStep = 0;
    this->WorkingTime = std::max(this->GetMTime(), sources);
    if (!this->Dynamics->Initialize())
    {
      this->Working->Delete();
      this->Working = nullptr;
      return 0;
    }
  }
  // Progress every few steps; the simulation can be aborted between them.
  const vtkIdType first = this->WorkingStep;
  const vtkIdType chunk = std::max<vtkIdType>(1, (target - first) / 20);
  while (this->WorkingStep < target && !this->GetAbortExecute())
  {
    const int now = static_cast<int>(std::min(chunk, target - this->WorkingStep));
    if (!this->Dynamics->Step(now))
    {
      this->Working->Delete();
      this->Working = nullptr;
      return 0;
    }
    this->WorkingStep += now;
    this->UpdateProgress(double(this->WorkingStep - first) / double(target - first));
  }
  if (this->WorkingStep < target) // aborted: the next request starts again
  {
    this->Working->Delete();
    this->Working = nullptr;
    return 1;
  }
  output->ShallowCopy(input);
  vtkNew<vtkPoints> points;
  points->SetDataType(this->Working->GetPoints()->GetDataType()); // DeepCopy() keeps the receiver's type
  points->DeepCopy(this->Working->GetPoints());
  output->SetPoints(points);
  output->GetInformation()->Set(vtkDataObject::DATA_TIME_STEP(), t);
  return 1;
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDSimulateLattice::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "EndTime: " << this->EndTime << "\n";
  os << indent << "Dynamics: " << this->Dynamics << "\n";
  if (this->Dynamics)
  {
    this->Dynamics->PrintSelf(os, indent.GetNextIndent());
  }
}
