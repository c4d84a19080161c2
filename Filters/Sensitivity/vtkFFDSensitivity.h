// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkFFDSensitivity
 * @brief   the adjoint of vtkFFDDeform: an objective's gradient at the control points, dJ/dP = W^T g
 *
 * vtkFFDDeform moves each point x to X(x) = x + sum_c w_c(x) (P_c - P_c^rest), linear in the control points P: with
 * W the matrix of the weights w_c(x_i) (points x control points), X = x + W (P - P^rest). Given the gradient
 * g_i = dJ/dX_i of an objective J at every deformed point, the gradient at the control points is therefore
 * dJ/dP = W^T g, exactly, for every lattice (the chain rule, no finite difference). Input 0 is the mesh at rest
 * (vtkFFDDeform's input 0) with g as a 3-component point array, chosen with SetInputArrayToProcess(0, 0, 0,
 * vtkDataObject::FIELD_ASSOCIATION_POINTS, name); input 1 the lattice (any lattice vtkFFDDeform takes: every grid
 * basis, dense and sparse, and tetrahedral lattices, whose points move by their tetrahedron's barycentric
 * weights). The output is the lattice with a point array `Sensitivity` (SensitivityArrayName):
 * dJ/dP, 3 float64 components per control point, 0 for control points that move no point. Points follow the
 * outside policy as vtkFFDDeform's (OutsidePolicy, the same values): a point kept outside has no weights, a
 * clamped one those of its clamped parameters (grids) or of its nearest point of the control mesh (tetrahedra),
 * an extrapolated one its nearest tetrahedron's.
 *
 * Forward mode (the Jacobian-vector product) needs no filter: the points' motion under a control-point direction
 * dP is W dP, which is vtkFFDDeform's displacement of the mesh by a lattice whose points are RestPosition + dP.
 *
 * Deterministic: the same bits for any number of threads and on every run. No floating-point atomics: the
 * points are grouped by their cell, in increasing id, and the cells are coloured so that cells of one colour share
 * no control point (2^3 colours for the Bezier bases, 4^3 for the cubic B-spline); colours are summed one after
 * the other, the cells of a colour in parallel, so each control point receives its terms in one fixed order. The
 * global Bernstein basis, one cell, sums fixed chunks of points (their number set by the point count, not by the
 * threads) into partial gradients, then adds the partials in chunk order. A tetrahedral lattice sums each
 * tetrahedron's points, then each node's tetrahedra in increasing order. All sums are in float64.
 *
 * The sums run on the CPU with vtkSMPTools; the CUDA backend does not compute them yet.
 *
 * @sa vtkFFDDeform
 */
#ifndef vtkFFDSensitivity_h
#define vtkFFDSensitivity_h

#include "vtkFFDDeform.h"                   // For the outside policies
#include "vtkFFDFiltersSensitivityModule.h" // For export macro
#include "vtkPointSetAlgorithm.h"

#include <memory> // For std::unique_ptr
#include <vector> // For std::vector

class vtkDataArray;
class vtkUnstructuredGrid;

class VTKFFDFILTERSSENSITIVITY_EXPORT vtkFFDSensitivity : public vtkPointSetAlgorithm
{
public:
  static vtkFFDSensitivity* New();
  vtkTypeMacro(vtkFFDSensitivity, vtkPointSetAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// The lattice, on input port 1.
  void SetLatticeConnection(vtkAlgorithmOutput* output) { this->SetInputConnection(1, output); }
  void SetLatticeData(vtkDataObject* lattice) { this->SetInputData(1, lattice); }
  ///@}

  ///@{
  /// What points outside the lattice do: vtkFFDDeform's OutsidePolicy, with its values (default
  /// vtkFFDDeform::KEEP_POSITION; EXTRAPOLATE for tetrahedral lattices only).
  vtkSetClampMacro(OutsidePolicy, int, vtkFFDDeform::KEEP_POSITION, vtkFFDDeform::EXTRAPOLATE);
  vtkGetMacro(OutsidePolicy, int);
  ///@}

  ///@{
  /// The name of the output's point array of dJ/dP (default "Sensitivity").
  vtkSetStringMacro(SensitivityArrayName);
  vtkGetStringMacro(SensitivityArrayName);
  ///@}

  /// Number of times the input points have been bound to a lattice (the binding is kept while they, the lattice's
  /// rest state and the policy stay the same).
  vtkGetMacro(NumberOfBindings, vtkIdType);

protected:
  vtkFFDSensitivity();
  ~vtkFFDSensitivity() override;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  /// An allocation that fails becomes an error and an empty output, never an exception out of Update().
  vtkTypeBool ProcessRequest(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestDataObject(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  int OutsidePolicy;
  char* SensitivityArrayName;
  vtkIdType NumberOfBindings;

private:
  vtkFFDSensitivity(const vtkFFDSensitivity&) = delete;
  void operator=(const vtkFFDSensitivity&) = delete;

  // The steps of RequestData(): W^T g into `sums` (3 per control point); false on an error (reported) or abort.
  bool SumGrid(vtkPointSet* mesh, vtkPointSet* lattice, vtkDataArray* gradient, std::vector<double>& sums);
  bool SumTetrahedral(
    vtkPointSet* mesh, vtkUnstructuredGrid* lattice, vtkDataArray* gradient, std::vector<double>& sums);

  struct vtkInternals;
  std::unique_ptr<vtkInternals> Internals;
};

#endif
