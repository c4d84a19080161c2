// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkFFDDirectManipulation
 * @brief   moves a lattice's control points so that chosen mesh points go where they are asked to
 *
 * Direct manipulation of free-form deformations (Hsu, Hughes and Kaufman 1992, the paper's reference [8]): input 0
 * is a lattice (grid, dense or sparse, any basis; or tetrahedral), input 1 the mesh at rest that it deforms. Given
 * mesh point ids (`TargetPointIds`) and where each should be once deformed (`TargetPositions`, world
 * coordinates), the output is a copy of the lattice whose control points moved by the smallest displacement that
 * takes every target there: the deformed point is linear in the control points, F(x_p) = x_p + sum_i w_i(x_p)
 * (P_i - R_i), so the change dP solves W dP = T - F(x) for the targets' weights W, and the filter takes
 * dP = W^+ (T - F(x)) (Eigen's complete orthogonal decomposition: the minimum-norm solution where the targets can
 * be met, the minimum-norm least-squares one where they cannot, e.g. one point asked to two places). With
 * `Regularization` lambda > 0 it takes W^T (W W^T + lambda I)^-1 (T - F(x)) instead (lambda relative to the mean
 * of diag W W^T): regularised least squares, which meets the targets less closely and moves less.
 *
 * Only control points whose support holds a target move (the columns of W); the others keep their coordinates
 * bit for bit. A target whose mesh point lies outside the lattice cannot be moved (a warning says how many;
 * where none is inside, the output is the lattice as it is). An id that names no mesh point, a mesh point or a
 * target position that is not finite, and a Regularization that is not a finite number >= 0 are errors that
 * leave the output empty.
 * GetMaximumTargetDistance() is the largest distance between a target and its deformed point afterwards (0 up to
 * rounding where the targets can be met).
 *
 * @sa vtkFFDDeform vtkFFDLatticeWidget
 */
#ifndef vtkFFDDirectManipulation_h
#define vtkFFDDirectManipulation_h

#include "vtkFFDFiltersManipulationModule.h" // For export macro
#include "vtkPointSetAlgorithm.h"
#include "vtkSmartPointer.h" // For the targets

class vtkIdTypeArray;
class vtkPoints;

class VTKFFDFILTERSMANIPULATION_EXPORT vtkFFDDirectManipulation : public vtkPointSetAlgorithm
{
public:
  static vtkFFDDirectManipulation* New();
  vtkTypeMacro(vtkFFDDirectManipulation, vtkPointSetAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// The mesh at rest that the lattice deforms (input 1; required where there are targets).
  void SetMeshConnection(vtkAlgorithmOutput* output) { this->SetInputConnection(1, output); }
  void SetMeshData(vtkDataObject* mesh) { this->SetInputData(1, mesh); }

  ///@{
  /// The mesh points to move (ids into input 1's points) and where each should go, in the same order.
  void SetTargetPointIds(vtkIdTypeArray* ids);
  vtkIdTypeArray* GetTargetPointIds();
  void SetTargetPositions(vtkPoints* positions);
  vtkPoints* GetTargetPositions();
  ///@}

  ///@{
  /// lambda of the regularised solution, relative to the mean of diag W W^T (default 0: the pseudo-inverse).
  vtkSetClampMacro(Regularization, double, 0.0, VTK_DOUBLE_MAX);
  vtkGetMacro(Regularization, double);
  ///@}

  ///@{
  /// The last update: how many control points moved, and the largest distance from a target to its point.
  vtkGetMacro(NumberOfMovedControlPoints, vtkIdType);
  vtkGetMacro(MaximumTargetDistance, double);
  ///@}

  /// Includes the targets' modification times.
  vtkMTimeType GetMTime() override;

protected:
  vtkFFDDirectManipulation();
  ~vtkFFDDirectManipulation() override;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  /// Checks the inputs first: one clear error where one is missing or of the wrong type.
  int RequestDataObject(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  vtkTypeBool ProcessRequest(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  vtkSmartPointer<vtkIdTypeArray> TargetPointIds;
  vtkSmartPointer<vtkPoints> TargetPositions;
  double Regularization;
  vtkIdType NumberOfMovedControlPoints;
  double MaximumTargetDistance;

private:
  vtkFFDDirectManipulation(const vtkFFDDirectManipulation&) = delete;
  void operator=(const vtkFFDDirectManipulation&) = delete;
};

#endif
