// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkFFDSimulateLattice
 * @brief   the lattice at the time the pipeline asks for, simulated by vtkFFDLatticeDynamics
 *
 * The pipeline form of vtkFFDLatticeDynamics, for animations and ParaView-style scripts: input 0 is a lattice at
 * rest (or at its starting shape), input 1 (optional) the mesh that gives the masses. The filter reports the
 * time range [0, EndTime] and, asked for time t (vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP(), or 0),
 * outputs a copy of the lattice whose points are those of the simulation after round(t / TimeStep) steps of the
 * Dynamics object's settings, forces and pins, from the input's points at rest. A time outside [0, EndTime] is
 * clamped to it, as a reader gives its last time step (the output's DATA_TIME_STEP says which time it is). The
 * output is the same whether t is reached at once or through earlier requests: a later time continues the last
 * simulation, an earlier one or any change of the inputs or the settings starts again from the input. An update
 * runs at most MaximumNumberOfSteps steps (an error beyond), reports its progress and stops when aborted.
 *
 * @sa vtkFFDLatticeDynamics vtkFFDMagneticSphere vtkFFDDeform
 */
#ifndef vtkFFDSimulateLattice_h
#define vtkFFDSimulateLattice_h

#include "vtkFFDFiltersDynamicsModule.h" // For export macro
#include "vtkPointSetAlgorithm.h"

class vtkFFDLatticeDynamics;
class vtkPointSet;

class VTKFFDFILTERSDYNAMICS_EXPORT vtkFFDSimulateLattice : public vtkPointSetAlgorithm
{
public:
  static vtkFFDSimulateLattice* New();
  vtkTypeMacro(vtkFFDSimulateLattice, vtkPointSetAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * The simulation's settings, forces and pins (a default one at first). Its lattice and mesh are the filter's:
   * the filter sets them to a copy of input 0 and to input 1.
   */
  void SetDynamics(vtkFFDLatticeDynamics* dynamics);
  vtkGetObjectMacro(Dynamics, vtkFFDLatticeDynamics);
  ///@}

  ///@{
  /// The end of the time range the filter reports, in seconds: finite, >= 0 (default 10).
  vtkSetMacro(EndTime, double);
  vtkGetMacro(EndTime, double);
  ///@}

  ///@{
  /**
   * The most time steps one update may run, >= 1 (default 100,000): a time farther than that from the last one
   * simulated is an error, which says how far it is, instead of a run of hours.
   */
  vtkSetMacro(MaximumNumberOfSteps, vtkIdType);
  vtkGetMacro(MaximumNumberOfSteps, vtkIdType);
  ///@}

  /// The mesh whose points give the masses (input 1, optional).
  void SetMeshConnection(vtkAlgorithmOutput* output) { this->SetInputConnection(1, output); }
  void SetMeshData(vtkPointSet* mesh);

  /// Includes the Dynamics object's modification time.
  vtkMTimeType GetMTime() override;

protected:
  vtkFFDSimulateLattice();
  ~vtkFFDSimulateLattice() override;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  /// Checks the inputs first: one clear error where one is missing or of the wrong type.
  int RequestDataObject(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int ExecuteInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  vtkFFDLatticeDynamics* Dynamics;
  double EndTime;
  vtkIdType MaximumNumberOfSteps;

private:
  vtkFFDSimulateLattice(const vtkFFDSimulateLattice&) = delete;
  void operator=(const vtkFFDSimulateLattice&) = delete;

  // The steps of RequestData(). The time asked for, clamped to [0, EndTime], and its step (false after an error).
  bool RequestedStep(vtkInformation* outInfo, double& time, double& step);
  // A new simulation from the input (false after an error); `sources`: the inputs' latest MTime.
  bool Restart(vtkPointSet* input, vtkPointSet* mesh, vtkMTimeType sources);
  // Runs to `target` (false after an error); Working is null where it was aborted.
  bool Simulate(vtkIdType target);

  // The running simulation: the lattice it moves, the step it is at, and what it started from.
  vtkPointSet* Working;
  vtkIdType WorkingStep;
  vtkMTimeType WorkingTime; // the filter's MTime and its inputs' when the simulation started
};

#endif
