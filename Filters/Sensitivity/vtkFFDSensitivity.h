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
 * Deterministic: the same bits for any number of threads and on every run, on the CPU and on the device. No
 * floating-point atomics: for a grid lattice, once per binding, the bound points are grouped by cell (in
 * increasing id) and cut into chunks of one cell (their size set by the point count and the support, not by the
 * threads); each update sums every chunk's points into a float64 partial per control point of its cell's support
 * (chunks in parallel), then adds each control point's partials in one fixed order (FFDAdjoint.h). A tetrahedral
 * lattice sums each tetrahedron's points, then each node's tetrahedra in increasing order. All sums are in
 * float64.
 *
 * Binding: SetDeform() names the vtkFFDDeform that deforms the same mesh by the same lattice; its binding (on the
 * host, or on the CUDA device) is then the one used, and so are its OutsidePolicy, Backend and precision: the mesh
 * is bound once for both. Without it the filter keeps a binding of its own (OutsidePolicy, Backend here).
 *
 * Backends: the sums run on the CPU with vtkSMPTools or, for grid lattices, on a CUDA device (Backend, as
 * vtkFFDDeform's: AUTOMATIC takes CUDA where a device is present; any CUDA failure falls back to the CPU with a
 * warning). The device computes the weights in the precision of the points it holds (vtkFFDDeform's output
 * precision; the mesh's points' without SetDeform()) and sums in float64 without atomics: each cell's points in
 * chunks, then each control point's chunks, in an order set by the binding alone, so the same bits at every run;
 * in float64 it agrees with the CPU to the rounding of the sums. Tetrahedral lattices, bound on the host, are
 * summed on the device too, but where points are clamped to the control mesh (CLAMP_TO_EDGE: their nearest
 * points are the host's), on the CPU. GetLastBackendUsed() tells which ran.
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
class vtkPoints;
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

  ///@{
  /// Where the sums run (vtkFFDDeform's values; default AUTOMATIC). Ignored where SetDeform() names a filter: its
  /// Backend applies.
  vtkSetClampMacro(Backend, int, vtkFFDDeform::AUTOMATIC, vtkFFDDeform::CUDA);
  vtkGetMacro(Backend, int);
  void SetBackendToAutomatic() { this->SetBackend(vtkFFDDeform::AUTOMATIC); }
  void SetBackendToCPU() { this->SetBackend(vtkFFDDeform::CPU); }
  void SetBackendToCUDA() { this->SetBackend(vtkFFDDeform::CUDA); }
  ///@}

  /// The backend that computed the last output: "CPU" or "CUDA" ("None" before the first execution).
  const char* GetLastBackendUsed() const { return this->LastBackendUsed; }

  ///@{
  /// The vtkFFDDeform that deforms input 0 by input 1, whose binding, OutsidePolicy, Backend and precision the sums
  /// then use (default none: a binding of this filter's own).
  virtual void SetDeform(vtkFFDDeform* deform);
  vtkGetObjectMacro(Deform, vtkFFDDeform);
  ///@}

  /// Number of times this filter bound the input points to a lattice, on the host or the device (none while the
  /// binding it uses, its own or the Deform's, is for these points, the lattice's rest state and the policy).
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
  int Backend;
  const char* LastBackendUsed;
  char* SensitivityArrayName;
  vtkFFDDeform* Deform;
  vtkIdType NumberOfBindings;

private:
  vtkFFDSensitivity(const vtkFFDSensitivity&) = delete;
  void operator=(const vtkFFDSensitivity&) = delete;

  // The steps of RequestData(): W^T g into `sums` (3 per control point); false on an error (reported) or abort.
  bool SumGrid(vtkPointSet* mesh, vtkPointSet* lattice, vtkDataArray* gradient, std::vector<double>& sums);
  bool SumTetrahedral(
    vtkPointSet* mesh, vtkUnstructuredGrid* lattice, vtkDataArray* gradient, std::vector<double>& sums);
  /// SumGrid() on the device, where the backend allows it; false where the CPU must sum (with a warning where
  /// CUDA was asked for or failed).
  bool SumGridOnCuda(vtkPoints* points, const double* g, std::vector<double>& sums);
  /// Whether the sums may run on the device (the Backend, a device); a warning where CUDA was asked for and cannot.
  bool CudaAllowed();
  /// VTK_FLOAT or VTK_DOUBLE: the precision of the points where the device binds them (the Deform's output's).
  int DevicePrecision(vtkPoints* points) const;

  // Whose binding and settings the sums use: the Deform's, else this filter's own.
  vtkFFDDeform* Engine();
  int EngineOutsidePolicy() const;

  struct vtkInternals;
  std::unique_ptr<vtkInternals> Internals;
};

#endif
