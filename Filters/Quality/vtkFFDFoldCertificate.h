// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkFFDFoldCertificate
 * @brief   whether a lattice's deformation keeps det J > 0 over each whole active cell: certified, folded, undecided
 *
 * Sampling det J (vtkFFDDeform's `JacobianDeterminant`) finds folds only where it samples; this filter decides
 * each active voxel of a grid lattice as a whole (every basis vtkFFDDeform takes, dense and sparse): certified
 * when det J > 0 at every point of the voxel, folded when a point with det J <= 0 was found, undecided when
 * neither was shown within MaxSubdivisionDepth subdivisions (Evaluation/Kernels/FFDFoldCertificate.h proves the
 * bound it certifies with). For a tetrahedral lattice each tetrahedron's det J is one number, its deformed volume
 * over its rest volume: certified or folded, exactly (but for float64 rounding).
 *
 * Input: a lattice (vtkFFDBuildLattice's or vtkFFDBuildTetrahedralLattice's output with its points moved, or any
 * lattice that keeps the data contract). Output: the lattice with a cell array `FoldCertificate` (unsigned char,
 * ffd::FoldState): 0 certified, 1 folded, 2 undecided, 3 not checked. How the cells map to voxels:
 * - a sparse lattice's cells are its active voxels: each cell has its voxel's state;
 * - a dense lattice (vtkStructuredGrid) has a cell between each 2x2x2 neighbouring control points: each has the
 *   state of the voxel that holds it at rest (a Bezier voxel of degree d holds d^3 of them, the global basis's
 *   and the trilinear voxels one each; the B-spline's outer ring of cells lies outside the frame and is not
 *   checked), 3 where that voxel is not active (its support is not all `Active`);
 * - a tetrahedral lattice's cells are its tetrahedra: 3 for a tetrahedron flat at rest.
 * The counts (GetNumberOfCertifiedCells() and the like) are of active voxels (tetrahedra), not of the array's cells.
 * vtkFFDLatticeActor colours the cells this array marks (ColorByFoldCertificate).
 *
 * The cells are decided in parallel with vtkSMPTools, with progress and abort between chunks. Bad input (a
 * lattice that breaks the data contract) is an error that fails the update; an allocation failure is reported as
 * an error and leaves an empty output.
 *
 * @sa vtkFFDDeform vtkFFDBuildLattice vtkFFDLatticeActor
 */
#ifndef vtkFFDFoldCertificate_h
#define vtkFFDFoldCertificate_h

#include "vtkFFDFiltersQualityModule.h" // For export macro
#include "vtkPointSetAlgorithm.h"

#include <memory> // For std::unique_ptr

class vtkPointSet;
class vtkUnsignedCharArray;
class vtkUnstructuredGrid;

class VTKFFDFILTERSQUALITY_EXPORT vtkFFDFoldCertificate : public vtkPointSetAlgorithm
{
public:
  static vtkFFDFoldCertificate* New();
  vtkTypeMacro(vtkFFDFoldCertificate, vtkPointSetAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// The states, the values of the `FoldCertificate` array (those of ffd::FoldState).
  enum States
  {
    CERTIFIED = 0,
    FOLDED = 1,
    UNDECIDED = 2,
    NOT_CHECKED = 3
  };

  /// The name of the output's cell array, "FoldCertificate".
  static const char* GetFoldCertificateArrayName() { return "FoldCertificate"; }

  ///@{
  /**
   * How many times a cell the bound does not decide is split in 8 (0 to 8, default 3): each level costs up to 8
   * times the last for undecided cells only, and decides cells whose det J comes closer to 0.
   */
  vtkSetClampMacro(MaxSubdivisionDepth, int, 0, 8);
  vtkGetMacro(MaxSubdivisionDepth, int);
  ///@}

  ///@{
  /// The states' counts over the active voxels (tetrahedra) of the last update.
  vtkGetMacro(NumberOfCertifiedCells, vtkIdType);
  vtkGetMacro(NumberOfFoldedCells, vtkIdType);
  vtkGetMacro(NumberOfUndecidedCells, vtkIdType);
  ///@}

protected:
  vtkFFDFoldCertificate();
  ~vtkFFDFoldCertificate() override;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  /// An allocation that fails becomes an error and an empty output, never an exception out of Update().
  vtkTypeBool ProcessRequest(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestDataObject(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  int MaxSubdivisionDepth = 3;
  vtkIdType NumberOfCertifiedCells = 0;
  vtkIdType NumberOfFoldedCells = 0;
  vtkIdType NumberOfUndecidedCells = 0;

private:
  vtkFFDFoldCertificate(const vtkFFDFoldCertificate&) = delete;
  void operator=(const vtkFFDFoldCertificate&) = delete;

  // The states of the lattice's cells into `states` (one per cell): false on an error (reported) or abort.
  bool CertifyGrid(vtkPointSet* lattice, vtkUnsignedCharArray* states);
  bool CertifyTetrahedra(vtkUnstructuredGrid* lattice, vtkUnsignedCharArray* states);

  // The lattice readers, kept between updates: a lattice whose points alone moved is not checked again in full.
  struct vtkInternals;
  std::unique_ptr<vtkInternals> Internals;
};

#endif
