// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkFFDDeform
 * @brief   deforms a point set with a free-form deformation lattice
 *
 * The last stage of the voxel FFD pipeline. Input 0 is any vtkPointSet (the mesh); input 1 is a lattice from
 * vtkFFDBuildLattice, or any vtkPointSet that keeps its data contract (vtkFFDDataContract). The output is a copy
 * of input 0 whose points are moved by the lattice's deformation, its points minus `RestPosition`:
 * X_ffd = X + sum_ijk B_i(s) B_j(t) B_k(u) (P_ijk - P_ijk^rest), which equals the paper's equation 3 for the
 * global Bernstein basis and its local counterparts for the others (trilinear, triquadratic and tricubic
 * Bezier sub-regions, uniform cubic B-spline; see vtkFFDBuildLattice).
 *
 * Binding: each input point is bound once to the lattice: the index of the cell it lies in (4 bytes per
 * point; its local coordinates are recomputed from the point at evaluation, exactly, in the point's
 * precision). The binding is cached and recomputed only when the input's points change (another vtkPoints, a
 * newer modification time or another count), when the lattice's rest frame, divisions or basis change, or
 * when the outside policy changes; moving lattice points only re-runs the evaluation, which for a local basis
 * touches only the 8, 27 or 64 control points of the point's voxel. GetNumberOfBindings() counts the bindings.
 * An input whose vertex order is spatially random keeps more with its binding: a copy of its points in the
 * order they are evaluated in, about 23 bytes a point in float32 (35 in float64), and a few hundred KB a
 * thread (docs/pipeline-and-data-contract.md, "What the filters do", says how it is used).
 *
 * Points outside the frame keep their input position (KEEP_POSITION, the default) or take the displacement at
 * the frame point of their parameters clamped to [0, 1] (CLAMP_TO_EDGE; the nearest point of a box frame; not
 * vtkBSplineTransform's Edge mode, which repeats edge coefficients and so differs outside: see
 * docs/pipeline-and-data-contract.md); non-finite points always keep theirs. Points on a face or corner of the frame
 * are inside. Normals (the input's active point normals) are transformed by the cofactor of the Jacobian (det J times
 * its inverse transpose, the same direction where det J > 0) and renormalized; cell normals, which a non-affine
 * deformation invalidates, are dropped. With ComputeJacobianDeterminant on, the output gets a
 * `JacobianDeterminant` point array (1 where points keep their position) in which folds show as values <= 0.
 *
 * Backends: the evaluation runs on the CPU with vtkSMPTools, or on a CUDA device (a build with CUDA), in the
 * precision of the output points (OutputPointsPrecision, as in vtkWarpVector); both call the same VTK-free
 * kernels of Evaluation/Kernels, so they compute the same function. AUTOMATIC (the default) uses CUDA when a device
 * is present, else the CPU; CUDA asked for where it cannot run, or any CUDA failure (no device, out of memory, a
 * launch error), falls back to the CPU with a warning, never to a wrong or partial output.
 * GetLastBackendUsed() tells which ran. On the device the points, normals and binding stay resident across
 * updates; an update uploads only the lattice and downloads the deformed points into the output array.
 *
 * GPU–GL interop: a renderer that draws from the device (vtkFFDInteropPolyDataMapper) sets the request key
 * KEEP_OUTPUT_ON_DEVICE() around its updates; when the CUDA backend deforms, the deformed points (and normals)
 * then stay on the device, where the renderer writes them into its vertex buffers, and nothing is downloaded.
 * Such an output carries a handle under DEVICE_OUTPUT() in its information, and its points and normals are
 * the input's (copies made once per input, so that nothing else draws them): not the deformed ones. Any update
 * without the key (another consumer's, or Update() called by the caller) executes the filter again and
 * downloads them (vtkFFDDeformExecutive), so that the pipeline never hands out undeformed points as deformed
 * ones. The output is downloaded as usual where ComputeJacobianDeterminant is on, where the CPU deforms, and
 * where tetrahedral points are clamped (they are moved on the host).
 * Progress is reported between chunks of points on the CPU, and the filter stops early when aborted.
 * The output announces the times of both inputs (the union of their ranges; of their time steps where both have
 * steps), so that a lattice that varies in time, such as vtkFFDSimulateLattice's, re-executes the deformation at
 * each time.
 *
 * Tetrahedral lattices (paper section III.E): input 1 may instead be a vtkUnstructuredGrid of tetrahedra with a
 * `RestPosition` point array and no `FFDFrame` (from vtkFFDBuildTetrahedralLattice, or built by the user). Each
 * point is bound to the tetrahedron that holds it, located with vtkStaticCellLocator and checked with the
 * barycentric weights of equation 5 (4 bytes per point, cached as above, keyed on the lattice's RestPosition
 * and cell arrays and their modification times); it moves by the weighted displacements of the tetrahedron's
 * four nodes, an affine map per tetrahedron, so normals follow that map. Tetrahedra without volume are
 * reported (a warning at binding) and skipped. Points outside every tetrahedron keep their position, take the
 * displacement of the nearest point of the control mesh (CLAMP_TO_EDGE), or follow the affine map of the
 * nearest tetrahedron (EXTRAPOLATE, tetrahedral lattices only). The binding runs on the CPU (it needs VTK's
 * locator); the evaluation on either backend, as for grids.
 *
 * A lattice without the contract's arrays, with a flat or non-finite frame, an unknown basis, non-finite
 * points, or a point count that does not match its divisions and basis is an error, as is a tetrahedral
 * lattice with cells other than tetrahedra or without a RestPosition of one 3-vector per point; the output is
 * then empty.
 *
 * @sa vtkFFDVoxelize vtkFFDBuildLattice vtkFFDDataContract vtkWarpVector
 */
#ifndef vtkFFDDeform_h
#define vtkFFDDeform_h

#include "vtkFFDFiltersCoreModule.h" // For export macro
#include "vtkPointSetAlgorithm.h"

#include <functional> // For std::function
#include <memory>     // For std::unique_ptr
#include <string>     // For std::string

class vtkDataArray;
class vtkFFDCudaBackend;
class vtkFFDGridDeformer;
class vtkFFDTetrahedralDeformer;
class vtkInformationIntegerKey;
class vtkInformationObjectBaseKey;
class vtkPoints;

class VTKFFDFILTERSCORE_EXPORT vtkFFDDeform : public vtkPointSetAlgorithm
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

  enum OutsidePolicies
  {
    KEEP_POSITION = 0,
    CLAMP_TO_EDGE = 1,
    EXTRAPOLATE = 2
  };

  ///@{
  /**
   * What points outside the lattice do (default KEEP_POSITION): keep their position; take the displacement of
   * the nearest point of the lattice (CLAMP_TO_EDGE); or, for tetrahedral lattices only, follow the affine map
   * of the nearest tetrahedron (EXTRAPOLATE).
   */
  vtkSetClampMacro(OutsidePolicy, int, KEEP_POSITION, EXTRAPOLATE);
  vtkGetMacro(OutsidePolicy, int);
  void SetOutsidePolicyToKeepPosition() { this->SetOutsidePolicy(KEEP_POSITION); }
  void SetOutsidePolicyToClampToEdge() { this->SetOutsidePolicy(CLAMP_TO_EDGE); }
  void SetOutsidePolicyToExtrapolate() { this->SetOutsidePolicy(EXTRAPOLATE); }
  const char* GetOutsidePolicyAsString();
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

  enum Backends
  {
    AUTOMATIC = 0,
    CPU = 1,
    CUDA = 2
  };

  ///@{
  /// Where the evaluation runs (default AUTOMATIC: CUDA when a device is present, else the CPU).
  vtkSetClampMacro(Backend, int, AUTOMATIC, CUDA);
  vtkGetMacro(Backend, int);
  void SetBackendToAutomatic() { this->SetBackend(AUTOMATIC); }
  void SetBackendToCPU() { this->SetBackend(CPU); }
  void SetBackendToCUDA() { this->SetBackend(CUDA); }
  ///@}

  /// The backend that computed the last output: "CPU" or "CUDA" ("None" before the first execution).
  const char* GetLastBackendUsed() const { return this->LastBackendUsed; }

  /// Number of times input points have been bound to a lattice (the binding cache's misses), on either backend.
  vtkGetMacro(NumberOfBindings, vtkIdType);

  ///@{
  /// What crossed the bus to and from the CUDA device since this filter was made: the lattices' displacements
  /// uploaded, and the bytes downloaded (deformed points, normals, determinants; an output kept on the device
  /// downloads its bounds only, 24 or 48 bytes). 0 where CUDA never ran.
  vtkTypeUInt64 GetLatticeBytesUploaded() const;
  vtkTypeUInt64 GetBytesDownloaded() const;
  ///@}

  /// Request key (on this filter's output information, set by a consumer around its update): keep the output
  /// on the CUDA device when CUDA deforms it (see the class description).
  static vtkInformationIntegerKey* KEEP_OUTPUT_ON_DEVICE();

  /// Key of the output data object's information: the vtkFFDDeviceOutput handle of the deformed points kept on
  /// the device; absent when the output's points are the deformed ones.
  static vtkInformationObjectBaseKey* DEVICE_OUTPUT();

protected:
  vtkFFDDeform();
  ~vtkFFDDeform() override;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  /// vtkFFDDeformExecutive: re-executes for host points when the output was kept on the device.
  vtkExecutive* CreateDefaultExecutive() override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  /// An allocation that fails becomes an error and an empty output, never an exception out of Update().
  vtkTypeBool ProcessRequest(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  /// Gives the output the input's structure and data, the deformed points and the transformed normals and det J
  /// (or, kept on the device, the input's copies and the device's handle).
  void FillOutput(vtkPointSet* input, vtkPointSet* output);

  int OutsidePolicy;
  int Backend;
  const char* LastBackendUsed;
  bool TransformNormals;
  bool ComputeJacobianDeterminant;
  int OutputPointsPrecision;
  vtkIdType NumberOfBindings;

private:
  vtkFFDDeform(const vtkFFDDeform&) = delete;
  void operator=(const vtkFFDDeform&) = delete;

  /// What holds this filter's binding, on the host and on the device: vtkFFDSensitivity runs the adjoint on it, so
  /// that a mesh deformed and differentiated by the same lattice is bound once.
  friend class vtkFFDSensitivity;
  struct vtkBinding
  {
    vtkFFDGridDeformer& Grid;
    vtkFFDTetrahedralDeformer& Tetrahedra;
    vtkFFDCudaBackend& Cuda;
  };
  vtkBinding GetBinding();

  // The steps of RequestData().
  vtkDataArray* GetNormalsToTransform(vtkPointSet* input);
  /// The arrays to deform into; `onDevice`: the input's copies, for an output kept on the device.
  void MakeOutputArrays(vtkPoints* points, vtkDataArray* normals, bool onDevice);
  bool DeformByGrid(vtkPoints* points, vtkDataArray* normals);
  bool DeformByTetrahedra(vtkPoints* points, vtkDataArray* normals);
  /// True when `deform` deformed on the GPU, where the Backend setting and a device allow it; false when the
  /// CPU must, with a warning where CUDA was asked for and cannot run, or failed.
  bool DeformedOnCuda(const std::function<bool(std::string& why)>& deform);

  struct vtkInternals;
  std::unique_ptr<vtkInternals> Internals;
};

#endif
