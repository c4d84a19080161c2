// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkFFDDataContract
 * @brief   names and accessors of the arrays that voxel grids and lattices carry
 *
 * vtkFFDVoxelize, vtkFFDBuildLattice and vtkFFDDeform agree on a small data contract
 * (docs/pipeline-and-data-contract.md, "Data contract"):
 *
 * | name           | where                 | what                                                         |
 * |----------------|-----------------------|--------------------------------------------------------------|
 * | `FFDFrame`     | field data, 12 doubles| X0, S, T, U: the parallelepiped X0 + sS + tT + uU            |
 * | `FFDDivisions` | field data, 3 ints    | voxels per axis                                              |
 * | `FFDBasis`     | field data, 1 int     | basis (vtkFFDBuildLattice::Basis), lattices only             |
 * | `RestPosition` | point data, 3 doubles | control point position before any deformation                |
 * | `Active`       | point data, uint8     | 1 where the control point influences some input point        |
 * | `VoxelIndex`   | cell data, 3 ints     | (i, j, k) of a sparse voxel grid's or lattice's voxel        |
 * | `LatticeIndex` | point data, 3 ints    | (i, j, k) of a sparse lattice's control point                |
 *
 * Voxel grids are vtkUnstructuredGrids of the active voxels; lattices are dense (vtkStructuredGrid) or sparse
 * (vtkUnstructuredGrid of the active control points and one cell per active voxel): docs/pipeline-and-data-contract.md,
 * "Data contract".
 *
 * This class gathers those names and the checked reads and writes of the field arrays, so that every filter
 * (and a Python script) reads them the same way. The Get methods return false, leaving the output untouched,
 * when an array is missing, has the wrong type or size, or holds non-finite or out-of-range values.
 *
 * @sa vtkFFDVoxelize vtkFFDBuildLattice vtkFFDDeform
 */
#ifndef vtkFFDDataContract_h
#define vtkFFDDataContract_h

#include "vtkFFDFiltersCoreModule.h" // For export macro
#include "vtkObject.h"

class vtkDataObject;

class VTKFFDFILTERSCORE_EXPORT vtkFFDDataContract : public vtkObject
{
public:
  static vtkFFDDataContract* New();
  vtkTypeMacro(vtkFFDDataContract, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// Array names of the data contract.
  static const char* FrameArrayName() { return "FFDFrame"; }
  static const char* DivisionsArrayName() { return "FFDDivisions"; }
  static const char* BasisArrayName() { return "FFDBasis"; }
  static const char* RestPositionArrayName() { return "RestPosition"; }
  static const char* ActiveArrayName() { return "Active"; }
  static const char* VoxelIndexArrayName() { return "VoxelIndex"; }
  static const char* LatticeIndexArrayName() { return "LatticeIndex"; }
  ///@}

  ///@{
  /**
   * Frame of a voxel grid or lattice: X0, S, T, U as 12 doubles. GetFrame() succeeds only for 12 finite
   * numbers; whether the frame has a volume is the caller's check (ffd::CheckFrame).
   */
  static bool GetFrame(vtkDataObject* data, double frame[12]);
  static void SetFrame(vtkDataObject* data, const double frame[12]);
  ///@}

  ///@{
  /// Voxels per axis; GetDivisions() succeeds only for three values >= 1.
  static bool GetDivisions(vtkDataObject* data, int divisions[3]);
  static void SetDivisions(vtkDataObject* data, const int divisions[3]);
  ///@}

  ///@{
  /// Basis enum value of a lattice (see vtkFFDBuildLattice); GetBasis() does not check the range.
  static bool GetBasis(vtkDataObject* data, int& basis);
  static void SetBasis(vtkDataObject* data, int basis);
  ///@}

protected:
  vtkFFDDataContract() = default;
  ~vtkFFDDataContract() override = default;

private:
  vtkFFDDataContract(const vtkFFDDataContract&) = delete;
  void operator=(const vtkFFDDataContract&) = delete;
};

#endif
