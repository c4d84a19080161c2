// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkFFDSimulateLattice
 * @brief   the lattice at the time the pipeline asks for, simulated by vtkFFDLatticeDynamics
 *
 * The pipeline form of vtkFFDLatticeDynamics, for animations and ParaView-style scripts: input 0 is a lattice at
 * rest (or at its starting shape), input 1 (optional) the mesh that gives the masses. The filter reports the
 * time range [0, EndTime] and, asked for time t (vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP(), or 0),
 * outputs a copy of the lattice whose points are those of the simulation after round(t / TimeStep) steps of the
 * Dynamics object's settings, forces and pins, from the input's points at rest. The output is the same whether
 * t is reached at once or through earlier requests: a later time continues the last simulation, an earlier one
 * or any change of the inputs or the settings starts again from the input.
 *
 * @sa vtkFFDLatticeDynamics vtkFFDMagneticSphere vtkFFDDeform
 */
#ifndef vtkFFDSimulateLattice_h
#define vtkFFDSimulateLattice_h

#include "vtkFFDFiltersModule.h" // For export macro
#include "vtkPointSetAlgorithm.h"

class vtkFFDLatticeDynamics;
class vtkPointSet;

class VTKFFDFILTERS_EXPORT vtkFFDSimulateLattice : public vtkPointSetAlgorithm
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
  /// The end of the time range the filter reports, in seconds (default 10).
  vtkSetClampMacro(EndTime, double, 0.0, VTK_DOUBLE_MAX);
  vtkGetMacro(EndTime, double);
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
  int ExecuteInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  vtkFFDLatticeDynamics* Dynamics;
  double EndTime;

private:
  vtkFFDSimulateLattice(const vtkFFDSimulateLattice&) = delete;
  void operator=(const vtkFFDSimulateLattice&) = delete;

  // The running simulation: the lattice it moves, the step it is at, and what it started from.
  vtkPointSet* Working;
  vtkIdType WorkingStep;
  vtkMTimeType WorkingTime; // the filter's MTime and its inputs' when the simulation started
};

#endif
