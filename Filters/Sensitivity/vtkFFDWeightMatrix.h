// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkFFDWeightMatrix
 * @brief   the weights of vtkFFDDeform as a sparse matrix W (points x control points) in CSR form
 *
 * vtkFFDDeform moves each point x_i of a mesh to X_i = x_i + sum_c W_ic (P_c - P_c^rest): W holds the weight of
 * every control point c at every point i, the same numbers the evaluation sums and vtkFFDSensitivity's W^T g is made
 * of. Compute() binds the mesh at rest to the lattice (every grid basis, dense and sparse, and tetrahedral lattices,
 * under OutsidePolicy as vtkFFDDeform defines it) and fills W in compressed sparse row form: row i's column ids
 * (lattice point ids) and values are ColumnIds and Values from RowOffsets[i] to RowOffsets[i + 1] - 1, the column
 * ids of a row increasing. Python's vtkffd.sparse.weight_matrix() makes a scipy.sparse.csr_matrix of them.
 *
 * A row holds every control point of the point's support, a weight of 0 included (the support's size: 2^3 for the
 * trilinear basis, 4^3 for the cubic ones, (n+1)(m+1)(l+1) for a Bernstein lattice of degree (n, m, l); 4 for a
 * tetrahedron), so that the structure depends on the binding alone. A point kept outside (KEEP_POSITION), or not
 * finite, has an empty row; a clamped point (CLAMP_TO_EDGE) has the weights of its clamped parameters (grids) or of
 * its nearest point of the control mesh (tetrahedra); an extrapolated one (EXTRAPOLATE, tetrahedral lattices only)
 * its nearest tetrahedron's barycentric weights, which may be negative. The weights of a non-empty row sum to 1 up
 * to rounding.
 *
 * The rows are counted, offset (a prefix sum) and filled in parallel with vtkSMPTools, each row by one thread: the
 * same arrays for any number of threads. Each Compute() makes new arrays, so that arrays handed out earlier (to
 * numpy, say) stay as they were. The binding is kept while the mesh's points, the lattice's rest state and the
 * policy stay the same.
 *
 * @sa vtkFFDDeform vtkFFDSensitivity
 */
#ifndef vtkFFDWeightMatrix_h
#define vtkFFDWeightMatrix_h

#include "vtkFFDDeform.h"                   // For the outside policies
#include "vtkFFDFiltersSensitivityModule.h" // For export macro
#include "vtkObject.h"
#include "vtkSmartPointer.h" // For vtkSmartPointer

#include <memory> // For std::unique_ptr
#include <vector> // For std::vector

class vtkDoubleArray;
class vtkIdTypeArray;
class vtkPointSet;

class VTKFFDFILTERSSENSITIVITY_EXPORT vtkFFDWeightMatrix : public vtkObject
{
public:
  static vtkFFDWeightMatrix* New();
  vtkTypeMacro(vtkFFDWeightMatrix, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// What points outside the lattice do: vtkFFDDeform's OutsidePolicy, with its values (default
  /// vtkFFDDeform::KEEP_POSITION; EXTRAPOLATE for tetrahedral lattices only).
  vtkSetClampMacro(OutsidePolicy, int, vtkFFDDeform::KEEP_POSITION, vtkFFDDeform::EXTRAPOLATE);
  vtkGetMacro(OutsidePolicy, int);
  ///@}

  /**
   * Computes W for `mesh` (any vtkPointSet, at rest: vtkFFDDeform's input 0) and `lattice` (vtkFFDDeform's input
   * 1). Returns 1, or 0 after an error (reported with vtkErrorMacro: a missing or malformed input, EXTRAPOLATE
   * with a grid lattice, too little memory), the matrix then empty (no rows, no columns).
   */
  int Compute(vtkPointSet* mesh, vtkPointSet* lattice);

  ///@{
  /// The matrix of the last Compute(): its rows (the mesh's points) and columns (the lattice's points).
  vtkGetMacro(NumberOfRows, vtkIdType);
  vtkGetMacro(NumberOfColumns, vtkIdType);
  ///@}

  ///@{
  /// The CSR arrays of the last Compute(): NumberOfRows + 1 offsets, and as many column ids and values as the
  /// last offset says.
  vtkIdTypeArray* GetRowOffsets();
  vtkIdTypeArray* GetColumnIds();
  vtkDoubleArray* GetValues();
  ///@}

protected:
  vtkFFDWeightMatrix();
  ~vtkFFDWeightMatrix() override;

  int OutsidePolicy;
  vtkIdType NumberOfRows;
  vtkIdType NumberOfColumns;
  vtkSmartPointer<vtkIdTypeArray> RowOffsets;
  vtkSmartPointer<vtkIdTypeArray> ColumnIds;
  vtkSmartPointer<vtkDoubleArray> Values;

private:
  vtkFFDWeightMatrix(const vtkFFDWeightMatrix&) = delete;
  void operator=(const vtkFFDWeightMatrix&) = delete;

  // The steps of Compute(), on new arrays: false after an error (reported).
  bool FillGrid(vtkPointSet* mesh, vtkPointSet* lattice);
  bool FillTetrahedral(vtkPointSet* mesh, vtkPointSet* lattice);
  // The offsets of rows of `perRow` entries for the points bound to a cell (cellOf[p] >= 0), empty for the others,
  // and room for the entries: false, reported, where memory lacks.
  bool AllocateRows(const std::vector<int>& cellOf, int perRow);

  struct vtkInternals;
  std::unique_ptr<vtkInternals> Internals;
};

#endif
