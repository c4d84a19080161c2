// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDCudaResidentPoints.h
 * @brief The CUDA backend's device residency, shared by the grid and the tetrahedral deformers.
 *
 * Plain C++ (no CUDA, VTK, OpenVDB or TBB header): vtkFFDDeform and the GPU tests include it alike, and only the
 * .cu files are compiled by nvcc.
 *
 * Residency: the points (and normals) are uploaded once and stay on the device with their binding (one int per
 * point); an update uploads only what describes the lattice's deformation (GridDeformer::Evaluate(),
 * TetrahedralDeformer::Evaluate()) and downloads the deformed points, through pinned staging buffers, straight
 * into the caller's arrays.
 *
 * Every method returns false on any CUDA failure (no device, out of memory, a launch error) with the reason in
 * GetLastError(); the object then holds no device state, and the caller falls back to the CPU. Nothing is
 * written to the caller's output arrays unless the whole evaluation succeeded on the device (the download is
 * the last step), but a failure during the download itself may leave them partly written: callers discard
 * their output when Download() returns false.
 */
#ifndef FFDCudaResidentPoints_h
#define FFDCudaResidentPoints_h

#include <cstdint>
#include <memory>
#include <string>

namespace ffd
{
namespace cuda
{

/// True when a CUDA device can be used; otherwise false, with the reason in `why` when given.
bool DeviceAvailable(std::string* why = nullptr);

/// What crossed the bus and what ran, so that tests can check the device residency.
struct Counters
{
  std::uint64_t PointUploads = 0;  ///< uploads of the input points
  std::uint64_t NormalUploads = 0; ///< uploads of the input normals
  std::uint64_t Bindings = 0;      ///< bindings computed on the device (grids) or uploaded to it (tetrahedra)
  std::uint64_t LatticeUploads = 0;
  std::uint64_t LatticeBytes = 0; ///< bytes of displacements uploaded, in all
  std::uint64_t Evaluations = 0;
  std::uint64_t AdjointPlans = 0; ///< plans of GridDeformer::Adjoint() made (one per binding)
  std::uint64_t CellTables = 0;   ///< evaluations of a grid's cells in power form (tables built on the device)
  std::uint64_t BytesDownloaded = 0;
  float LastKernelMilliseconds = 0; ///< device time of the last evaluation's (or adjoint's) kernels (CUDA events)
  /// Device time of the last update's work on the lattice before the points' kernel (the tetrahedra's maps, a
  /// grid's cell table; 0 where there was none).
  float LastLatticeKernelMilliseconds = 0;
};

/**
 * The points, normals and binding on the device, and the download of the results: what GridDeformer and
 * TetrahedralDeformer share. Each adds its own Bind() and Evaluate().
 */
class ResidentPoints
{
public:
  ResidentPoints(const ResidentPoints&) = delete;
  ResidentPoints& operator=(const ResidentPoints&) = delete;

  ///@{
  /// Uploads `count` points (x, y, z each) in their precision, which is also that of the evaluation and of the
  /// output. They stay on the device until replaced; the binding and the normals are dropped.
  bool SetPoints(const float* xyz, std::int64_t count);
  bool SetPoints(const double* xyz, std::int64_t count);
  ///@}

  ///@{
  /// Uploads unit normals (3 per point) to transform with the deformation, in the precision of the points (that
  /// of the evaluation: a float64 mesh's normals are transformed as accurately as on the CPU).
  bool SetNormals(const float* normals);
  bool SetNormals(const double* normals);
  ///@}

  ///@{
  /// Downloads the last evaluation: the deformed points (3 per point, the precision of SetPoints()) into
  /// outPoints, and the normals and determinants into the others when not null (they must have been evaluated).
  bool Download(float* outPoints, float* outNormals, float* outDeterminants);
  bool Download(double* outPoints, double* outNormals, double* outDeterminants);
  ///@}

  /// The bounds (xmin, xmax, ymin, ymax, zmin, zmax) of the last evaluation's points, reduced on the device
  /// (non-finite coordinates are skipped; no finite one: xmin > xmax): 6 values cross the bus, not the points.
  bool ComputeBounds(double bounds[6]);

  /// Frees every device and pinned buffer.
  void Release();

  const std::string& GetLastError() const;
  const Counters& GetCounters() const;

  /// The device state; defined for the .cu files only (FFDCudaDevice.cuh).
  struct State;

protected:
  friend class GLBuffers; // writes the last evaluation into OpenGL buffers (FFDCudaGLBuffers.h)

  explicit ResidentPoints(std::unique_ptr<State> state);
  ~ResidentPoints();

  std::unique_ptr<State> S;
};

} // namespace cuda
} // namespace ffd

#endif
