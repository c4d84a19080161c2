// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkFFDRefineLattice
 * @brief   the same deformation on a lattice of twice the divisions: exact refinement of a grid lattice
 *
 * The input is a grid lattice of vtkFFDBuildLattice (dense or sparse, at rest or deformed); the output is the
 * lattice of the same frame and basis over 2n voxels per axis (each voxel split into eight), repeated `Levels`
 * times, whose deformation is the input's, for every basis (docs/level-of-detail.md): trilinear by midpoints,
 * the Bezier sub-regions by de Casteljau at each voxel's middle, the cubic B-spline by knot insertion, the global
 * Bernstein basis by degree elevation (ffd::RefineRow, Evaluation/Kernels/FFDRefinement.h). Only the displacements
 * (points minus `RestPosition`) are refined: the output's rest positions are those vtkFFDBuildLattice gives, so
 * a refined lattice at rest is the finer lattice at rest, bit for bit.
 *
 * The output keeps the input's form. A sparse lattice's cells each become the eight voxels they split into, so
 * the refined lattice covers exactly the input's active region. A dense lattice's active region is the voxels
 * whose whole support is `Active` (all voxels without that array); the output marks `Active` the control points
 * of their halves and leaves the others at rest.
 *
 * @sa vtkFFDBuildLattice vtkFFDCoarsenLattice vtkFFDBuildDetailLattice
 */
#ifndef vtkFFDRefineLattice_h
#define vtkFFDRefineLattice_h

#include "vtkFFDFiltersLevelOfDetailModule.h" // For export macro
#include "vtkPointSetAlgorithm.h"
#include "vtkSmartPointer.h" // For RefineOnce

class VTKFFDFILTERSLEVELOFDETAIL_EXPORT vtkFFDRefineLattice : public vtkPointSetAlgorithm
{
public:
  static vtkFFDRefineLattice* New();
  vtkTypeMacro(vtkFFDRefineLattice, vtkPointSetAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// How many times the divisions double (default 1: n -> 2n; 0 passes the lattice through).
  vtkSetClampMacro(Levels, int, 0, 16);
  vtkGetMacro(Levels, int);
  ///@}

protected:
  vtkFFDRefineLattice();
  ~vtkFFDRefineLattice() override = default;

  /// The output's extent is the refined lattice's, known in RequestData only.
  int ExecuteInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int ComputeInputUpdateExtent(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  /// Checks the inputs first: one clear error where one is missing or of the wrong type.
  int RequestDataObject(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  vtkTypeBool ProcessRequest(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  int Levels;

private:
  vtkFFDRefineLattice(const vtkFFDRefineLattice&) = delete;
  void operator=(const vtkFFDRefineLattice&) = delete;

  /// False, after reporting the size and the Levels that fit, where the last level needs more memory than the
  /// system has: checked before the first level is refined.
  bool CheckLastLevelFits(vtkPointSet* input);

  /// `lattice` refined once, or null after reporting an error.
  vtkSmartPointer<vtkPointSet> RefineOnce(vtkPointSet* lattice);
};

#endif
