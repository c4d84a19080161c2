// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkFFDDeform
 * @brief   deforms a point set with a free-form deformation lattice
 *
 * The last stage of the voxel FFD pipeline. Input 0 is any vtkPointSet (the mesh); input 1 is a lattice from
 * vtkFFDBuildLattice, or any vtkStructuredGrid that keeps its data contract (vtkFFDDataContract). The output
 * is a copy of input 0 whose points are moved by the lattice's deformation, its points minus `RestPosition`:
 * X_ffd = X + sum_ijk B_ijk(s, t, u) (P_ijk - P_ijk^rest), which equals the paper's equation 3.
 *
 * Binding: each input point is bound once to the lattice's frame (its parameters s, t, u, equation 2), and the
 * binding is cached. It is recomputed only when the input's points change (another vtkPoints, a newer
 * modification time or another count) or when the lattice's rest frame, divisions or basis change; moving
 * lattice points only re-runs the evaluation. GetNumberOfBindings() counts the bindings computed so far.
 *
 * Points outside the frame keep their input position, as do non-finite points; points on a face or corner of
 * the frame are inside. Normals (the input's active point normals) are transformed by the cofactor of the
 * Jacobian (det J times its inverse transpose, the same direction where det J > 0) and renormalized.
 * With ComputeJacobianDeterminant on, the output gets a `JacobianDeterminant` point array (1 outside the frame)
 * in which folds show as values <= 0.
 *
 * The evaluation runs on the CPU with vtkSMPTools, in the precision of the output points (OutputPointsPrecision,
 * as in vtkWarpVector), using the VTK-free kernels of Filters/Kernels. Progress is reported between chunks of
 * points and the filter stops early when aborted.
 *
 * A lattice without the contract's arrays, with a flat or non-finite frame, an unsupported basis, or a point
 * count that does not match its divisions is an error; the output is then empty.
 *
 * @sa vtkFFDVoxelize vtkFFDBuildLattice vtkFFDDataContract vtkWarpVector
 */
#ifndef vtkFFDDeform_h
#define vtkFFDDeform_h

#include "vtkFFDFiltersModule.h" // For export macro
#include "vtkPointSetAlgorithm.h"

#include <memory> // For std::unique_ptr

class VTKFFDFILTERS_EXPORT vtkFFDDeform : public vtkPointSetAlgorithm
{
public:
  static vtkFFDDeform* New();
  vtkTypeMacro(vtkFFDDeform, vtkPointSetAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// The lattice, on input port 1.
  void SetLatticeConnection(vtkAlgorithmOutput* output) { this->SetInputConnection(1, output); }
  void SetLatticeData(vtkDataObject* lattice) { this->SetInputData(1, lattice); }
  ///@}

  ///@{
  /// Transform the input's point normals with the deformation (default on).
  vtkSetMacro(TransformNormals, bool);
  vtkGetMacro(TransformNormals, bool);
  vtkBooleanMacro(TransformNormals, bool);
  ///@}

  ///@{
  /// Add the `JacobianDeterminant` point array, det(dX_ffd/dX) (default off).
  vtkSetMacro(ComputeJacobianDeterminant, bool);
  vtkGetMacro(ComputeJacobianDeterminant, bool);
  vtkBooleanMacro(ComputeJacobianDeterminant, bool);
  static const char* JacobianDeterminantArrayName() { return "JacobianDeterminant"; }
  ///@}

  ///@{
  /// Precision of the output points (vtkAlgorithm::DesiredOutputPrecision); DEFAULT_PRECISION keeps the input's.
  vtkSetClampMacro(OutputPointsPrecision, int, SINGLE_PRECISION, DEFAULT_PRECISION);
  vtkGetMacro(OutputPointsPrecision, int);
  ///@}

  /// Number of times input points have been bound to a lattice (the binding cache's misses).
  vtkGetMacro(NumberOfBindings, vtkIdType);

protected:
  vtkFFDDeform();
  ~vtkFFDDeform() override;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  bool TransformNormals;
  bool ComputeJacobianDeterminant;
  int OutputPointsPrecision;
  vtkIdType NumberOfBindings;

private:
  vtkFFDDeform(const vtkFFDDeform&) = delete;
  void operator=(const vtkFFDDeform&) = delete;

  struct vtkInternals;
  std::unique_ptr<vtkInternals> Internals;
};

#endif
