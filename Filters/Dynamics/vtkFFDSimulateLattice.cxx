// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDSimulateLattice.h"

#include "vtkFFDInputChecks.h"
#include "vtkFFDLatticeDynamics.h"
#include "vtkFFDStatistics.h"

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
  , MaximumNumberOfSteps(100000)
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
int vtkFFDSimulateLattice::RequestDataObject(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  if (!(vtkFFDCheckInput(this, inputVector[0], 0, "vtkPointSet", "the lattice",
          "SetInputConnection() to the lattice to simulate, the output of vtkFFDBuildLattice or "
          "vtkFFDBuildTetrahedralLattice.") &&
        vtkFFDCheckInput(this, inputVector[1], 1, "vtkPointSet", "the mesh",
          "SetMeshConnection() to the mesh that the lattice deforms, whose points give the masses, or to nothing.",
          true)))
  {
    return vtkFFDEmptyOutputs(outputVector); // an earlier output would show what the inputs no longer give
  }
  return this->Superclass::RequestDataObject(request, inputVector, outputVector);
}

//------------------------------------------------------------------------------------------------------------
int vtkFFDSimulateLattice::ExecuteInformation(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkInformation* info = outputVector->GetInformationObject(0);
  info->Remove(vtkStreamingDemandDrivenPipeline::TIME_STEPS());
  info->Remove(vtkStreamingDemandDrivenPipeline::TIME_RANGE());
  if (std::isfinite(this->EndTime) && this->EndTime >= 0) // else RequestData() says what is wrong
  {
    const double range[2] = { 0.0, this->EndTime };
    info->Set(vtkStreamingDemandDrivenPipeline::TIME_RANGE(), range, 2);
  }
  return 1;
}

//------------------------------------------------------------------------------------------------------------
bool vtkFFDSimulateLattice::RequestedStep(vtkInformation* outInfo, double& time, double& step)
{
  if (!this->Dynamics)
  {
    vtkErrorMacro("No Dynamics object: SetDynamics() to a vtkFFDLatticeDynamics.");
    return false;
  }
  if (!(std::isfinite(this->EndTime) && this->EndTime >= 0))
  {
    vtkErrorMacro(<< "SetEndTime(" << this->EndTime << "): the end time (s) must be a finite number >= 0.");
    return false;
  }
  if (this->MaximumNumberOfSteps < 1)
  {
    vtkErrorMacro(<< "SetMaximumNumberOfSteps(" << this->MaximumNumberOfSteps << "): it must be at least 1.");
    return false;
  }
  if (!this->Dynamics->CheckSettings()) // the Dynamics object reports which
  {
    return false;
  }
  time = outInfo->Has(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP())
    ? outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP())
    : 0.0;
  if (std::isnan(time))
  {
    vtkErrorMacro("The pipeline asks for the lattice at time NaN: ask for a time in [0, EndTime].");
    return false;
  }
  time = std::min(std::max(time, 0.0), this->EndTime);
  step = std::floor(time / this->Dynamics->GetTimeStep() + 0.5);
  return true;
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
    vtkErrorMacro("Input 0 (the lattice) must be a vtkPointSet.");
    return 0;
  }
  const vtkFFDStatisticsOnReturn statistics(output,
    [this](vtkDataObject* out)
    {
      vtkFFDLatticeDynamics* dynamics = this->GetDynamics();
      if (!dynamics)
      {
        return; // SetDynamics(nullptr): an error, and no statistics
      }
      vtkFFDRecordValue(out, "Time", dynamics->GetTime());
      vtkFFDRecordCount(out, "NumberOfSimulatedPoints", dynamics->GetNumberOfSimulatedPoints());
      vtkFFDRecordCount(out, "NumberOfSprings", dynamics->GetNumberOfSprings());
      vtkFFDRecordValue(out, "KineticEnergy", dynamics->GetKineticEnergy());
      vtkFFDRecordValue(out, "PotentialEnergy", dynamics->GetPotentialEnergy());
    });
  double t = 0, step = 0;
  if (!this->RequestedStep(outInfo, t, step))
  {
    return 0;
  }

  // Continue the last simulation when nothing changed and the time is not earlier; else start again.
  vtkMTimeType sources = std::max(this->GetMTime(), input->GetMTime());
  if (mesh)
  {
    sources = std::max(sources, mesh->GetMTime());
  }
  const bool restart = !this->Working || sources > this->WorkingTime || step < double(this->WorkingStep) ||
    this->Dynamics->GetLattice() != this->Working || this->Dynamics->GetMesh() != mesh;
  const double from = restart ? 0.0 : double(this->WorkingStep);
  if (!(step - from <= double(this->MaximumNumberOfSteps)))
  {
    vtkErrorMacro(<< "Time " << t << " s is " << step - from << " time steps of " << this->Dynamics->GetTimeStep()
                  << " s from the last simulated time (" << from * this->Dynamics->GetTimeStep()
                  << " s): more than the " << this->MaximumNumberOfSteps
                  << " an update may run. Raise SetMaximumNumberOfSteps(), lengthen the Dynamics' SetTimeStep(), "
                     "or ask for earlier times first (a later time continues from the last one).");
    return 0;
  }
  if ((restart && !this->Restart(input, mesh, sources)) || !this->Simulate(static_cast<vtkIdType>(step)))
  {
    return 0;
  }
  if (!this->Working)
  {
    return 1; // aborted: the output stays empty
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
bool vtkFFDSimulateLattice::Restart(vtkPointSet* input, vtkPointSet* mesh, vtkMTimeType sources)
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
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------------------------------------
bool vtkFFDSimulateLattice::Simulate(vtkIdType target)
{
  // Progress every 1 % of the steps; the simulation can be aborted between them.
  const vtkIdType first = this->WorkingStep;
  const vtkIdType chunk = std::min<vtkIdType>(VTK_INT_MAX, std::max<vtkIdType>(1, (target - first) / 100));
  while (this->WorkingStep < target && !this->GetAbortExecute())
  {
    const int now = static_cast<int>(std::min(chunk, target - this->WorkingStep));
    if (!this->Dynamics->Step(now))
    {
      this->Working->Delete();
      this->Working = nullptr;
      return false;
    }
    this->WorkingStep += now;
    this->UpdateProgress(double(this->WorkingStep - first) / double(target - first));
  }
  if (this->WorkingStep < target) // aborted: the next request starts again
  {
    this->Working->Delete();
    this->Working = nullptr;
  }
  return true;
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDSimulateLattice::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "EndTime: " << this->EndTime << "\n";
  os << indent << "MaximumNumberOfSteps: " << this->MaximumNumberOfSteps << "\n";
  os << indent << "Dynamics: " << this->Dynamics << "\n";
  if (this->Dynamics)
  {
    this->Dynamics->PrintSelf(os, indent.GetNextIndent());
  }
}
