// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDCudaGridDeformer.h
 * @brief The CUDA backend: device-resident binding and evaluation of a grid lattice's deformation.
 *
 * Plain C++ (no CUDA, VTK, OpenVDB or TBB header): vtkFFDDeform and the GPU tests include it alike, and only
 * FFDCudaGridDeformer.cu is compiled by nvcc. The device code calls the same Filters/Kernels functions as the
 * CPU path (ffd::BindToGrid, ffd::GridDeformation), so both compute one function.
 *
 * Residency: the points (and normals) are uploaded once and stay on the device with their binding (one int per
 * point); an update uploads only the lattice's displacements and downloads the deformed points, through pinned
 * staging buffers, straight into the caller's arrays.
 *
 * Every method returns false on any CUDA failure (no device, out of memory, a launch error) with the reason in
 * GetLastError(); the object then holds no device state, and the caller falls back to the CPU. Nothing is
 * written to the caller's output arrays unless the whole evaluation succeeded on the device (the download is
 * the last step), but a failure during the download itself may leave them partly written: callers discard
 * their output when Deform() returns false.
 */
#ifndef FFDCudaGridDeformer_h
#define FFDCudaGridDeformer_h

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
  std::uint64_t Bindings = 0;      ///< binding kernels run
  std::uint64_t LatticeUploads = 0;
  std::uint64_t LatticeBytes = 0; ///< bytes of displacements uploaded, in all
  std::uint64_t Evaluations = 0;
  std::uint64_t BytesDownloaded = 0;
  float LastKernelMilliseconds = 0; ///< device time of the last evaluation kernel (CUDA events)
};

class GridDeformer
{
public:
  GridDeformer();
  ~GridDeformer();
  GridDeformer(const GridDeformer&) = delete;
  GridDeformer& operator=(const GridDeformer&) = delete;

  ///@{
  /// Uploads `count` points (x, y, z each) in their precision, which is also that of the evaluation and of the
  /// output. They stay on the device until replaced; the binding and the normals are dropped.
  bool SetPoints(const float* xyz, std::int64_t count);
  bool SetPoints(const double* xyz, std::int64_t count);
  ///@}

  /// Uploads unit normals (3 floats per point) to transform with the deformation.
  bool SetNormals(const float* normals);

  /// Binds the points to a lattice (ffd::BindToGrid): frame X0, S, T, U; basis (ffd::GridBasis value);
  /// divisions (voxels per axis). The binding stays on the device.
  bool Bind(const double frame[12], int basis, const int divisions[3], bool clampOutside);

  /// Uploads the displacements (3 doubles per control point, VTK order, `controlPoints` of them, as many as the
  /// basis and divisions of Bind() give) and evaluates every point on the device, with the transformed normals
  /// (needs SetNormals()) and det(J) when asked for. The results stay on the device until Download().
  bool Evaluate(const double* displacements, std::int64_t controlPoints, bool withNormals, bool withDeterminants);

  ///@{
  /// Downloads the last evaluation: the deformed points (3 per point, the precision of SetPoints()) into
  /// outPoints, and the normals and determinants into the others when not null (they must have been evaluated).
  bool Download(float* outPoints, float* outNormals, float* outDeterminants);
  bool Download(double* outPoints, float* outNormals, double* outDeterminants);
  ///@}

  /// Frees every device and pinned buffer.
  void Release();

  const std::string& GetLastError() const;
  const Counters& GetCounters() const;

private:
  struct Impl;
  std::unique_ptr<Impl> P;
};

} // namespace cuda
} // namespace ffd

#endif
