// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkFFDMeshInversion
 * @brief   the cells of a deformed volume mesh that turned inside out, and the scaled Jacobian of every cell
 *
 * vtkFFDDeform moves any vtkPointSet; a CFD user then asks whether the volume mesh is still valid. Input 0 is the
 * deformed mesh (vtkFFDDeform's output), input 1 the same mesh at rest (its input 0): the same points, in the same
 * number, and the same cells. Every cell must be a linear volume cell: VTK_TETRA, VTK_HEXAHEDRON, VTK_VOXEL,
 * VTK_WEDGE or VTK_PYRAMID (anything else, a triangle or a quadratic cell, is an error).
 *
 * A cell's Jacobians are its corner Jacobians and, for a hexahedron, the one at its centre (ffd::CellJacobians(),
 * Evaluation/Kernels/FFDCellJacobian.h). A cell is valid at rest when they all have one sign (positive, or all
 * negative: a mirrored node order), and inverted when one of them, after the deformation, no longer has that
 * sign (zero included: flattened there). The output is input 0 with two cell arrays:
 * - `Inverted` (unsigned char): 0 valid, 1 inverted, 2 invalid at rest (not counted as inverted);
 * - `ScaledJacobian` (double): the smallest scaled Jacobian of the deformed cell (1 for an ideal cell, <= 0 where
 *   inverted), times the rest orientation's sign, so that a mirrored cell reads as its unmirrored twin; for
 *   tetrahedra and hexahedra in positive order, vtkMeshQuality's TetScaledJacobian and HexScaledJacobian.
 * GetNumberOfInvertedCells(), GetNumberOfInvalidRestCells() and GetMinimumScaledJacobian() (over the cells valid at
 * rest) summarise it. The cells are measured in parallel (vtkSMPTools), with progress and abort between chunks.
 *
 * @sa vtkFFDDeform vtkFFDFoldCertificate vtkMeshQuality
 */
#ifndef vtkFFDMeshInversion_h
#define vtkFFDMeshInversion_h

#include "vtkFFDFiltersQualityModule.h" // For export macro
#include "vtkPointSetAlgorithm.h"

class VTKFFDFILTERSQUALITY_EXPORT vtkFFDMeshInversion : public vtkPointSetAlgorithm
{
public:
  static vtkFFDMeshInversion* New();
  vtkTypeMacro(vtkFFDMeshInversion, vtkPointSetAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// The values of the `Inverted` array.
  enum States
  {
    VALID = 0,
    INVERTED = 1,
    INVALID_AT_REST = 2
  };

  ///@{
  /// The mesh at rest, on input port 1.
  void SetRestMeshConnection(vtkAlgorithmOutput* output) { this->SetInputConnection(1, output); }
  void SetRestMeshData(vtkDataObject* mesh) { this->SetInputData(1, mesh); }
  ///@}

  ///@{
  /// The results of the last update.
  vtkGetMacro(NumberOfInvertedCells, vtkIdType);
  vtkGetMacro(NumberOfInvalidRestCells, vtkIdType);
  /// The smallest `ScaledJacobian` over the cells valid at rest (1 where there are none).
  vtkGetMacro(MinimumScaledJacobian, double);
  ///@}

protected:
  vtkFFDMeshInversion();
  ~vtkFFDMeshInversion() override = default;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  /// An allocation that fails becomes an error and an empty output, never an exception out of Update().
  vtkTypeBool ProcessRequest(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestDataObject(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  vtkIdType NumberOfInvertedCells = 0;
  vtkIdType NumberOfInvalidRestCells = 0;
  double MinimumScaledJacobian = 1.0;

private:
  vtkFFDMeshInversion(const vtkFFDMeshInversion&) = delete;
  void operator=(const vtkFFDMeshInversion&) = delete;
};

#endif
