// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkFFDCudaBackend
 * @brief   vtkFFDDeform's glue to the CUDA backend (Evaluation/CUDA): residency, precision, array layout
 *
 * Private to the Filters module (not wrapped). It keeps one ffd::cuda::GridDeformer and one
 * ffd::cuda::TetrahedralDeformer per vtkFFDDeform, uploads the input's points and normals only when they change.
 * A grid lattice's points are re-bound on the device only when they or the lattice's rest frame, shape or the
 * outside policy change (the same key as the CPU binding, vtkFFDBindingKey); a tetrahedral lattice's binding is
 * the host's (vtkFFDTetrahedralDeformer: it needs VTK's cell locator), uploaded once per binding, and so is a
 * sparse grid lattice's (vtkFFDGridDeformer: it needs the lookup of its voxels' cells). An update
 * uploads only the lattice's displacements (of control points or of nodes) and downloads straight into the
 * output arrays, or, for a renderer that draws from the device (GPU–GL interop), keeps the results there and
 * hands out a vtkFFDDeviceOutput.
 *
 * In a build without CUDA every call answers "not available", so vtkFFDDeform needs no conditional code.
 */
#ifndef vtkFFDCudaBackend_h
#define vtkFFDCudaBackend_h

#include "vtkFFDBindingKey.h"
#include "vtkSmartPointer.h"
#include "vtkType.h"

#include <memory>
#include <string>

class vtkDataArray;
class vtkFFDDeviceOutput;
class vtkFFDGridDeformer;
class vtkFFDTetrahedralDeformer;
class vtkPoints;

class vtkFFDCudaBackend
{
public:
  vtkFFDCudaBackend();
  ~vtkFFDCudaBackend();
  vtkFFDCudaBackend(const vtkFFDCudaBackend&) = delete;
  vtkFFDCudaBackend& operator=(const vtkFFDCudaBackend&) = delete;

  /// True when this build has the CUDA backend and a device can be used; otherwise false and why not.
  static bool IsAvailable(std::string& why);

  /**
   * Deforms on the device: the input's points (and normals, 3 components, may be null) bound per `key` to the
   * grid lattice of `grid` (its last SetLattice()), displaced by its displacements. A dense lattice's points are
   * bound on the device; a sparse lattice's binding is the host's (`grid`'s Bind() must have run for these
   * points: finding a voxel's cell needs its lookup), uploaded with its cells when the key changes. The results
   * go to outPoints (a float or double AOS array with the points' count of tuples: the evaluation's precision),
   * outNormals and outDeterminants (of outPoints' type) when not null. `bound` tells whether the device's binding
   * was (re)made. With `keptOnDevice` not null nothing is downloaded (outPoints and outNormals only give the
   * precision and whether normals are evaluated): *keptOnDevice gets the handle of the results on the device.
   * On any failure: false, the reason in `why`, the outputs to be discarded, and no device state kept.
   */
  bool DeformGrid(const vtkFFDGridDeformer& grid, const vtkFFDBindingKey& key, vtkPoints* points, vtkDataArray* normals,
    vtkDataArray* outPoints, vtkDataArray* outNormals, vtkDataArray* outDeterminants,
    vtkSmartPointer<vtkFFDDeviceOutput>* keptOnDevice, bool& bound, std::string& why);

  /**
   * W^T g on the device (ffd::cuda::GridDeformer::Adjoint()): the gradient g (3 doubles per point) of an objective
   * at the points deformed by the grid lattice of `grid`, taken to its control points (`sums`, 3 doubles each).
   * The device's binding is used where it is for `key` (DeformGrid()'s, in its precision), else made as
   * DeformGrid() makes it with the points uploaded in `precision` (VTK_FLOAT or VTK_DOUBLE). Failures as
   * DeformGrid().
   */
  bool AdjointGrid(const vtkFFDGridDeformer& grid, const vtkFFDBindingKey& key, vtkPoints* points, int precision,
    const double* gradient, double* sums, bool& bound, std::string& why);

  /**
   * Deforms on the device the input's points bound by `tetrahedra` (whose Bind() ran for them; its binding is
   * uploaded when the device does not hold it) by the nodes' displacements of its last SetLattice(), then moves
   * the points clamped to the control mesh on the host with its ApplyClampedPoints(), as the CPU does. Outputs
   * and failures as DeformGrid(); `keptOnDevice` only where no point is clamped (they are moved on the host).
   */
  bool DeformTetrahedra(const vtkFFDTetrahedralDeformer& tetrahedra, vtkPoints* points, vtkDataArray* normals,
    vtkDataArray* outPoints, vtkDataArray* outNormals, vtkDataArray* outDeterminants,
    vtkSmartPointer<vtkFFDDeviceOutput>* keptOnDevice, std::string& why);

  /**
   * W^T g on the device for the tetrahedral lattice of `tetrahedra` (whose Bind() ran for these points, with no
   * point clamped to the control mesh: those are the host's): its binding uploaded, with the points in `precision`
   * where the device holds other points (else in theirs), then ffd::cuda::TetrahedralDeformer::Adjoint(). Failures
   * as DeformGrid().
   */
  bool AdjointTetrahedra(const vtkFFDTetrahedralDeformer& tetrahedra, vtkPoints* points, int precision,
    const double* gradient, double* sums, std::string& why);

  ///@{
  /// What crossed the bus, in all (both lattice kinds): the lattices' displacements uploaded, and the bytes
  /// downloaded (deformed points, normals, determinants, bounds).
  vtkTypeUInt64 GetLatticeBytesUploaded() const;
  vtkTypeUInt64 GetBytesDownloaded() const;
  ///@}

private:
  struct vtkState;
  std::shared_ptr<vtkState> State; // shared with the vtkFFDDeviceOutput handles of results kept on the device
};

#endif
