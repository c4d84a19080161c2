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
 * Bases (n voxels along an axis; every basis is a tensor product of one-dimensional bases, see FFDGridBasis.h):
 *
 * | basis               | control points per axis | support of voxel v (per axis)  | per voxel | continuity |
 * |---------------------|-------------------------|--------------------------------|-----------|------------|
 * | BERNSTEIN           | n + 1 (degree n)        | all n + 1 points               | all       | C-infinity |
 * | TRILINEAR           | n + 1                   | points v, v + 1                | 2x2x2     | C0         |
 * | TRIQUADRATIC_BEZIER | 2n + 1                  | points 2v .. 2v + 2            | 3x3x3     | C0         |
 * | TRICUBIC_BEZIER     | 3n + 1                  | points 3v .. 3v + 3            | 4x4x4     | C0         |
 * | CUBIC_BSPLINE       | n + 3                   | points v .. v + 3              | 4x4x4     | C2         |
 *
 * - BERNSTEIN is the global Sederberg-Parry FFD (paper equation 3): point i rests at parameter i/n; every
 *   control point influences every voxel, so all are active when any voxel is. Its degree is limited to
 *   ffd::MaxBernsteinDegree per axis.
 * - The Bezier sub-regions (paper Listings 1 and 2, equation 4) put degree p = 1, 2, 3 Bezier patches in the
 *   voxels; neighbouring voxels share their face control points, and point i rests at parameter i/(p n).
 * - CUBIC_BSPLINE is the uniform cubic B-spline: point i rests at parameter (i - 1)/n, so the lattice has one
 *   ring of control points beyond the frame on every side.
 *
 * The rest lattice is the identity map for every basis. Culling (paper section III.D): a control point is
 * active when it lies in the support of at least one active voxel; the cost is that of visiting the supports
 * of the active voxels, so large sparse grids are cheap.
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
#include "vtkWrappingHints.h" // For VTK_WRAPEXCLUDE

#include <string> // For GetControlPointsPerAxis

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

  /**
   * The control points per axis of a lattice of `basis` over `divisions` voxels: false, with the reason and its
   * remedy in `why`, for an unknown basis, a BERNSTEIN degree above the maximum, or more control points than the
   * deformation indexes (2^31 - 1). This filter and vtkFFDDeform check lattices by it.
   */
  VTK_WRAPEXCLUDE static bool GetControlPointsPerAxis(
    int basis, const int divisions[3], int points[3], std::string& why);

  /// Number of control points marked active by the last execution.
  vtkGetMacro(NumberOfActiveControlPoints, vtkIdType);

protected:
  vtkFFDBuildLattice();
  ~vtkFFDBuildLattice() override = default;

  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestUpdateExtent(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  /// An allocation that fails becomes an error and an empty output, never an exception out of Update().
  vtkTypeBool ProcessRequest(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  int Basis;
  vtkIdType NumberOfActiveControlPoints;

private:
  vtkFFDBuildLattice(const vtkFFDBuildLattice&) = delete;
  void operator=(const vtkFFDBuildLattice&) = delete;
};

#endif
