// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkFFDBuildLattice
 * @brief   builds the control lattice of a basis over a voxel grid
 *
 * The second stage of the voxel FFD pipeline. The input is a voxel grid (vtkFFDVoxelize's output, or any
 * vtkDataSet with the `FFDFrame` and `FFDDivisions` field arrays and a `VoxelIndex` cell array of 3 ints giving
 * the (i, j, k) of each active voxel, each voxel once). The output is the control lattice of a basis in its rest
 * position, double precision, with the data contract's arrays (docs/pipeline-and-data-contract.md, "Data contract"), in
 * one of two forms (LatticeForm):
 * - DENSE: a vtkStructuredGrid of every control point, point (i, j, k) being i + nI*(j + nJ*k) (VTK structured
 *   order, `points.reshape(nK, nJ, nI, 3)` in numpy), with `FFDFrame`, `FFDDivisions`, `FFDBasis` (field data),
 *   `RestPosition` and `Active` (point data). Control points that influence no active voxel under the basis are
 *   culled: `Active` is 0 and the ghost array marks them HIDDENPOINT. Its memory follows nI*nJ*nK: 50 bytes a
 *   control point.
 * - SPARSE (local bases only): a vtkUnstructuredGrid of the active control points alone, in increasing lattice
 *   order i + nI*(j + nJ*k), with the same arrays (`Active` is 1 for all) and `LatticeIndex` (point data, the
 *   (i, j, k) of each point); one cell per active voxel, in the voxel grid's order, with its `VoxelIndex`, listing
 *   the control points of the voxel's support: VTK_HEXAHEDRON (TRILINEAR), VTK_BEZIER_HEXAHEDRON of 27 or 64
 *   points in VTK's order (the Bezier sub-regions, which VTK and ParaView draw as the sub-regions themselves) and
 *   VTK_POLY_VERTEX of 64 points, i fastest (CUBIC_BSPLINE, which has no VTK cell type). Its memory and time
 *   follow the active voxels and control points (61 bytes a control point and 4 bytes a cell's point, 8 where ids
 *   pass 2^31), never nI*nJ*nK, so lattices over 1024^3 voxels and beyond are cheap over a small mesh: the union
 *   of the supports is found in parallel with OpenVDB and the cells' point ids by binary search in it (the same
 *   output whatever the number of threads).
 * - AUTOMATIC (the default): SPARSE for the local bases, whose memory then follows the mesh rather than the
 *   divisions, and DENSE for BERNSTEIN, whose every control point influences every voxel. A user who indexes the
 *   lattice as a grid (numpy's reshape(nK, nJ, nI, 3), i + nI*(j + nJ*k)) asks for SetLatticeFormToDense().
 * Both forms compute each rest position by the same formula: the sparse lattice's points are the dense lattice's
 * active points, bit for bit. The memory a lattice needs is checked against what the system can give before it is
 * allocated.
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
 * of the active voxels.
 *
 * The dense form's extent is known only once the input's `FFDDivisions` is read, at RequestData: the output's
 * WHOLE_EXTENT is left empty before, and the lattice asks its input for the whole voxel grid.
 *
 * Deform the lattice by moving its points (any filter, a script or a widget); its deformation is its points
 * minus `RestPosition`.
 *
 * @sa vtkFFDVoxelize vtkFFDDeform vtkFFDDataContract
 */
#ifndef vtkFFDBuildLattice_h
#define vtkFFDBuildLattice_h

#include "vtkFFDFiltersCoreModule.h" // For export macro
#include "vtkPointSetAlgorithm.h"
#include "vtkWrappingHints.h" // For VTK_WRAPEXCLUDE

#include <string> // For GetControlPointsPerAxis

class vtkDataSet;
class vtkIntArray;
class vtkStructuredGrid;
class vtkUnstructuredGrid;

class VTKFFDFILTERSCORE_EXPORT vtkFFDBuildLattice : public vtkPointSetAlgorithm
{
public:
  static vtkFFDBuildLattice* New();
  vtkTypeMacro(vtkFFDBuildLattice, vtkPointSetAlgorithm);
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

  enum LatticeForms
  {
    AUTOMATIC = 0,
    DENSE = 1,
    SPARSE = 2
  };

  ///@{
  /// The form of the output (default AUTOMATIC: SPARSE for the local bases, DENSE for BERNSTEIN). SPARSE with
  /// BERNSTEIN is an error.
  vtkSetClampMacro(LatticeForm, int, AUTOMATIC, SPARSE);
  vtkGetMacro(LatticeForm, int);
  void SetLatticeFormToAutomatic() { this->SetLatticeForm(AUTOMATIC); }
  void SetLatticeFormToDense() { this->SetLatticeForm(DENSE); }
  void SetLatticeFormToSparse() { this->SetLatticeForm(SPARSE); }
  const char* GetLatticeFormAsString();
  ///@}

  /**
   * The control points per axis of a lattice of `basis` over `divisions` voxels in `form` (DENSE or SPARSE): false,
   * with the reason and its remedy in `why`, for an unknown basis, a BERNSTEIN degree above the maximum, more
   * control points along an axis than an int counts, or, for a DENSE lattice, more control points than the
   * deformation indexes (2^31 - 1); a SPARSE lattice's linear indices i + nI*(j + nJ*k) need only fit 64 bits. This
   * filter and vtkFFDDeform check lattices by it.
   */
  VTK_WRAPEXCLUDE static bool GetControlPointsPerAxis(
    int basis, const int divisions[3], int points[3], std::string& why, int form = DENSE);

  /// Number of control points marked active by the last execution (the points of a sparse lattice).
  vtkGetMacro(NumberOfActiveControlPoints, vtkIdType);

protected:
  vtkFFDBuildLattice();
  ~vtkFFDBuildLattice() override = default;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  /// A vtkStructuredGrid for the dense form, a vtkUnstructuredGrid for the sparse one.
  int RequestDataObject(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  /// vtkPointSetAlgorithm's RequestInformation.
  int ExecuteInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  /// vtkPointSetAlgorithm's RequestUpdateExtent.
  int ComputeInputUpdateExtent(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  /// An allocation that fails becomes an error and an empty output, never an exception out of Update().
  vtkTypeBool ProcessRequest(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  int Basis;
  int LatticeForm;
  vtkIdType NumberOfActiveControlPoints;

private:
  ///@{
  /// Checks of RequestData(), each false (or null) after reporting an error: the input's frame and divisions;
  /// the lattice form against the basis, giving the control points per axis; the input's VoxelIndex cell array
  /// (each index within the divisions, each once), which is returned.
  bool ReadFrameAndDivisions(vtkDataSet* input, double frame[12], int divisions[3]);
  bool CheckForm(bool sparse, const int divisions[3], int pointsPerAxis[3]);
  vtkIntArray* GetActiveVoxels(vtkDataSet* input, const int divisions[3]);
  ///@}
  /// The forms of RequestData(), after the input's checks: 1 on success, 0 on failure, with the error reported.
  int BuildDense(const double frame[12], const int divisions[3], const int pointsPerAxis[3], vtkIntArray* voxels,
    vtkStructuredGrid* output);
  int BuildSparse(const double frame[12], const int divisions[3], vtkIntArray* voxels, vtkUnstructuredGrid* output);

  vtkFFDBuildLattice(const vtkFFDBuildLattice&) = delete;
  void operator=(const vtkFFDBuildLattice&) = delete;
};

#endif
