// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkFFDBuildLattice
 * @brief   builds the control lattice of a basis over a voxel grid
 *
 * The second stage of the voxel FFD pipeline. The input is a voxel grid from vtkFFDVoxelize (a
 * vtkStructuredGrid with the `FFDFrame` and `FFDDivisions` field arrays and inactive voxels hidden); the output
 * is a vtkStructuredGrid of control points in their rest position, in VTK structured order (point (i, j, k)
 * is i + nI*(j + nJ*k)), double precision, with the data contract's arrays: `FFDFrame`, `FFDDivisions`,
 * `FFDBasis` (field data), `RestPosition` and `Active` (point data). Control points that influence no active
 * voxel under the basis are culled: `Active` is 0 and the ghost array marks them HIDDENPOINT.
 *
 * Bases:
 * - BERNSTEIN: the global Sederberg-Parry FFD (paper equation 3), degree = divisions per axis, so
 *   (nx+1)(ny+1)(nz+1) control points at X0 + (i/nx) S + (j/ny) T + (k/nz) U. Every control point influences
 *   every voxel: all are active when any voxel is.
 * - TRILINEAR, TRIQUADRATIC_BEZIER, TRICUBIC_BEZIER, CUBIC_BSPLINE: local bases (not implemented yet; asking
 *   for one is an error).
 *
 * Deform the lattice by moving its points (any filter, a script or a widget); its deformation is its points
 * minus `RestPosition`.
 *
 * @sa vtkFFDVoxelize vtkFFDDeform vtkFFDDataContract
 */
#ifndef vtkFFDBuildLattice_h
#define vtkFFDBuildLattice_h

#include "vtkFFDFiltersModule.h" // For export macro
#include "vtkStructuredGridAlgorithm.h"

class VTKFFDFILTERS_EXPORT vtkFFDBuildLattice : public vtkStructuredGridAlgorithm
{
public:
  static vtkFFDBuildLattice* New();
  vtkTypeMacro(vtkFFDBuildLattice, vtkStructuredGridAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  enum Bases
  {
    BERNSTEIN = 0,
    TRILINEAR = 1,
    TRIQUADRATIC_BEZIER = 2,
    TRICUBIC_BEZIER = 3,
    CUBIC_BSPLINE = 4
  };

  ///@{
  /// The basis of the lattice (default BERNSTEIN).
  vtkSetClampMacro(Basis, int, BERNSTEIN, CUBIC_BSPLINE);
  vtkGetMacro(Basis, int);
  void SetBasisToBernstein() { this->SetBasis(BERNSTEIN); }
  void SetBasisToTrilinear() { this->SetBasis(TRILINEAR); }
  void SetBasisToTriquadraticBezier() { this->SetBasis(TRIQUADRATIC_BEZIER); }
  void SetBasisToTricubicBezier() { this->SetBasis(TRICUBIC_BEZIER); }
  void SetBasisToCubicBSpline() { this->SetBasis(CUBIC_BSPLINE); }
  const char* GetBasisAsString() { return GetBasisAsString(this->Basis); }
  static const char* GetBasisAsString(int basis);
  ///@}

  /// Number of control points marked active by the last execution.
  vtkGetMacro(NumberOfActiveControlPoints, vtkIdType);

protected:
  vtkFFDBuildLattice();
  ~vtkFFDBuildLattice() override = default;

  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  int Basis;
  vtkIdType NumberOfActiveControlPoints;

private:
  vtkFFDBuildLattice(const vtkFFDBuildLattice&) = delete;
  void operator=(const vtkFFDBuildLattice&) = delete;
};

#endif
