// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkFFDBuildDetailLattice
 * @brief   adaptive refinement: a finer lattice of detail over selected voxels, added to the lattice it refines
 *
 * Hierarchical B-splines (Forsey and Bartels 1988) for every local basis. The input is a grid lattice (dense or
 * sparse, of a local basis); the output is a sparse lattice at rest of the same frame and basis over twice the
 * divisions, covering only the selected voxels of the input: `SelectedVoxels` (their (i, j, k) in the input's
 * divisions), and with `SecondDerivativeThreshold` above 0 also every covered voxel whose deformation bends more
 * than it (the largest second difference of its control points' displacements, pure or mixed, along the lattice's
 * axes, over the product of the control-point spacings: a length over a length squared).
 *
 * vtkFFDDeformBlocks with SetCompositionToAdd() adds the detail lattice's deformation to the input's. At rest it
 * adds nothing, so the pair deforms as the input alone; moving a detail control point changes the deformation
 * only near it. Its movable control points (`Active` 1) are those of the selected voxels' halves; its cells are
 * every fine voxel they influence, so the detail's deformation is a whole spline of the basis, continuous as the
 * basis is (C0 for the Bezier sub-regions and trilinear, C2 for the B-spline) and zero outside its cells. The
 * other points of the cells' supports, the ring that closes the region, have `Active` 0 and are hidden: left at
 * rest they keep the deformation continuous across the region's boundary, which moving them would break.
 *
 * @sa vtkFFDRefineLattice vtkFFDDeformBlocks
 */
#ifndef vtkFFDBuildDetailLattice_h
#define vtkFFDBuildDetailLattice_h

#include "vtkFFDFiltersLevelOfDetailModule.h" // For export macro
#include "vtkSmartPointer.h"                  // For SelectedVoxels
#include "vtkUnstructuredGridAlgorithm.h"

class vtkIntArray;

class VTKFFDFILTERSLEVELOFDETAIL_EXPORT vtkFFDBuildDetailLattice : public vtkUnstructuredGridAlgorithm
{
public:
  static vtkFFDBuildDetailLattice* New();
  vtkTypeMacro(vtkFFDBuildDetailLattice, vtkUnstructuredGridAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// Voxels of the input to refine: 3 ints (i, j, k) a tuple, within its divisions (none by default).
  void SetSelectedVoxels(vtkIntArray* voxels);
  vtkIntArray* GetSelectedVoxels();
  ///@}

  ///@{
  /// Refine also every covered voxel whose second difference per unit length squared exceeds this (0: off).
  vtkSetClampMacro(SecondDerivativeThreshold, double, 0.0, VTK_DOUBLE_MAX);
  vtkGetMacro(SecondDerivativeThreshold, double);
  ///@}

  /// The input voxels the last update refined (selected and over the threshold, each once).
  vtkGetMacro(NumberOfRefinedVoxels, vtkIdType);

  /// Includes SelectedVoxels' modification time: changing its values re-executes the filter.
  vtkMTimeType GetMTime() override;

protected:
  vtkFFDBuildDetailLattice();
  ~vtkFFDBuildDetailLattice() override;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  vtkTypeBool ProcessRequest(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  vtkSmartPointer<vtkIntArray> SelectedVoxels;
  double SecondDerivativeThreshold;
  vtkIdType NumberOfRefinedVoxels;

private:
  vtkFFDBuildDetailLattice(const vtkFFDBuildDetailLattice&) = delete;
  void operator=(const vtkFFDBuildDetailLattice&) = delete;
};

#endif
