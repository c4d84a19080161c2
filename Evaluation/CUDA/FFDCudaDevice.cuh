// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDCudaDevice.cuh
 * @brief What the CUDA deformers share, for their .cu files only: device buffers, error handling, the resident
 * points' state (ResidentPoints::State) and the per-point evaluation kernels.
 *
 * The kernels take a deformation object with the interface of ffd::GridDeformation (Deform(x, cell) and
 * Deform(x, cell, jacobian)): a grid's, or a tetrahedral lattice's maps (FFDCudaTetrahedralDeformer.cu), so both
 * lattices run the same kernels around their own Evaluation/Kernels functions.
 */
#ifndef FFDCudaDevice_cuh
#define FFDCudaDevice_cuh

#include "FFDCudaResidentPoints.h"

#include "FFDDeformPoint.h"

#include <cuda_runtime.h>

#include <cstddef>
#include <cstdint>
#include <string>

namespace ffd
{
namespace cuda
{
namespace detail
{
constexpr int ThreadsPerBlock = 256;
// Size of each of the two pinned buffers that stage a download: large enough to run the bus at full speed,
// small enough that the host copy of one chunk overlaps the transfer of the next (8 MB chunks made an update
// of 1 M points 1.4-1.6 times the bare download, the host copy of the first chunk waiting alone).
constexpr std::size_t StagingBytes = std::size_t(2) << 20;

inline unsigned BlocksFor(std::int64_t n)
{
  return unsigned((n + ThreadsPerBlock - 1) / ThreadsPerBlock);
}

// A CUDA failure, turned into a message by State::Guard().
struct CudaError
{
  cudaError_t Code;
  const char* What;
};

inline void Check(cudaError_t code, const char* what)
{
  if (code != cudaSuccess)
  {
    throw CudaError{ code, what };
  }
}

// Device memory (cudaMalloc), or pinned host memory (cudaMallocHost) for the staging of transfers.
struct Buffer
{
  const bool Pinned;
  void* Data = nullptr;
  std::size_t Bytes = 0;

  explicit Buffer(bool pinned = false)
    : Pinned(pinned)
  {
  }
  ~Buffer() { this->Free(); }

  void Reserve(std::size_t bytes, const char* what)
  {
    if (bytes <= this->Bytes)
    {
      return;
    }
    this->Free();
    Check(this->Pinned ? cudaMallocHost(&this->Data, bytes) : cudaMalloc(&this->Data, bytes), what);
    this->Bytes = bytes;
  }
  void Free()
  {
    if (this->Data)
    {
      this->Pinned ? cudaFreeHost(this->Data) : cudaFree(this->Data);
    }
    this->Data = nullptr;
    this->Bytes = 0;
  }
  template <typename T>
  T* As() const
  {
    return static_cast<T*>(this->Data);
  }
};

//------------------------------------------------------------------------------------------------------------
// Points one at a time through ffd::DeformBoundPoint, the CPU's per-point function. With the Jacobian
// (normals, determinants) one point a thread; without, four points a thread, ThreadsPerBlock apart (consecutive
// threads, consecutive points), so that their independent lattice gathers overlap. Launch bounds keep at least
// 4 (6) blocks of 256 threads on a multiprocessor: the gathers are dependent loads, and more threads in flight
// hide their latency. Without the Jacobian DeformPointsKernel is the faster choice for float32 points and for cell
// tables in either precision (BENCHMARKS.md); this kernel takes the rest: float64 weighted sums, and every
// evaluation with the Jacobian.
template <typename Deformation, typename Real, bool WithJacobian>
__global__ void __launch_bounds__(ThreadsPerBlock, WithJacobian ? 4 : 6) DeformKernel(const Real* __restrict__ points,
  const int* __restrict__ cells, std::int64_t count, Deformation deformation, Real* __restrict__ outPoints,
  const Real* __restrict__ normals, Real* __restrict__ outNormals, Real* __restrict__ determinants)
{
  constexpr int PointsPerThread = WithJacobian ? 1 : 4;
  FFD_UNROLL
  for (int r = 0; r < PointsPerThread; ++r)
  {
    const std::int64_t i =
      blockIdx.x * std::int64_t(PointsPerThread * ThreadsPerBlock) + r * ThreadsPerBlock + threadIdx.x;
    if (i >= count)
    {
      return;
    }
    ffd::DeformBoundPoint<WithJacobian>(deformation, ffd::Vec3<Real>::From(points + 3 * i), cells[i], outPoints + 3 * i,
      outNormals ? normals + 3 * i : nullptr, outNormals ? outNormals + 3 * i : nullptr,
      determinants ? determinants + i : nullptr);
  }
}

// Four consecutive points (12 numbers from 16-byte-aligned storage) read and written as 16-byte words with
// streaming hints: they are touched once.
__device__ __forceinline__ void LoadFour(const float* points, std::int64_t group, ffd::Vec3<float>* x)
{
  const float4* in = reinterpret_cast<const float4*>(points) + 3 * group;
  const float4 a = __ldcs(in), b = __ldcs(in + 1), c = __ldcs(in + 2);
  x[0] = { a.x, a.y, a.z };
  x[1] = { a.w, b.x, b.y };
  x[2] = { b.z, b.w, c.x };
  x[3] = { c.y, c.z, c.w };
}

__device__ __forceinline__ void LoadFour(const double* points, std::int64_t group, ffd::Vec3<double>* x)
{
  const double2* in = reinterpret_cast<const double2*>(points) + 6 * group;
  double v[12];
  FFD_UNROLL
  for (int w = 0; w < 6; ++w)
  {
    const double2 d = __ldcs(in + w);
    v[2 * w] = d.x;
    v[2 * w + 1] = d.y;
  }
  FFD_UNROLL
  for (int g = 0; g < 4; ++g)
  {
    x[g] = { v[3 * g], v[3 * g + 1], v[3 * g + 2] };
  }
}

__device__ __forceinline__ void StoreFour(float* points, std::int64_t group, const ffd::Vec3<float>* x)
{
  float4* out = reinterpret_cast<float4*>(points) + 3 * group;
  __stcs(out, make_float4(x[0].x, x[0].y, x[0].z, x[1].x));
  __stcs(out + 1, make_float4(x[1].y, x[1].z, x[2].x, x[2].y));
  __stcs(out + 2, make_float4(x[2].z, x[3].x, x[3].y, x[3].z));
}

__device__ __forceinline__ void StoreFour(double* points, std::int64_t group, const ffd::Vec3<double>* x)
{
  double2* out = reinterpret_cast<double2*>(points) + 6 * group;
  const double v[12] = { x[0].x, x[0].y, x[0].z, x[1].x, x[1].y, x[1].z, x[2].x, x[2].y, x[2].z, x[3].x, x[3].y,
    x[3].z };
  FFD_UNROLL
  for (int w = 0; w < 6; ++w)
  {
    __stcs(out + w, make_double2(v[2 * w], v[2 * w + 1]));
  }
}

// Points without the Jacobian (the common update): each thread deforms four consecutive points, read with their
// cells as 16-byte words (LoadFour()) and written alike. Launch bounds keep MinBlocks blocks of 256 threads on a
// multiprocessor: 4 (64 registers, so that all four points' loads are issued before the first lattice gather)
// one point at a time. Grouped: where the four share their cell (points in mesh order mostly do),
// deformation.DeformGroup() deforms them together, each control point (or cell table coefficient) read once for the
// four (the same results); a weighted sum then takes up to 128 registers (2 blocks), a float32 power form 80 (3).
template <typename Deformation, typename Real, bool Grouped, int MinBlocks>
__global__ void __launch_bounds__(ThreadsPerBlock, MinBlocks) DeformPointsKernel(const Real* __restrict__ points,
  const int* __restrict__ cells, std::int64_t count, Deformation deformation, Real* __restrict__ outPoints)
{
  auto deform = [&](ffd::Vec3<Real>& x, int cell)
  {
    if (cell >= 0)
    {
      x = deformation.Deform(x, cell);
    }
  };
  const std::int64_t group = blockIdx.x * std::int64_t(ThreadsPerBlock) + threadIdx.x;
  const std::int64_t first = 4 * group;
  if (first + 4 <= count)
  {
    ffd::Vec3<Real> x[4];
    LoadFour(points, group, x);
    const int4 cell = __ldcs(reinterpret_cast<const int4*>(cells) + group);
    bool together = false;
    if constexpr (Grouped)
    {
      together = cell.x >= 0 && cell.x == cell.y && cell.x == cell.z && cell.x == cell.w;
      if (together)
      {
        deformation.DeformGroup(x, cell.x);
      }
    }
    if (!together)
    {
      deform(x[0], cell.x);
      deform(x[1], cell.y);
      deform(x[2], cell.z);
      deform(x[3], cell.w);
    }
    StoreFour(outPoints, group, x);
    return;
  }
  for (std::int64_t i = first; i < count; ++i) // the last one to three points
  {
    ffd::Vec3<Real> x = { points[3 * i], points[3 * i + 1], points[3 * i + 2] };
    deform(x, cells[i]);
    outPoints[3 * i] = x.x;
    outPoints[3 * i + 1] = x.y;
    outPoints[3 * i + 2] = x.z;
  }
}

// Launches DeformKernel over `count` points on `stream`: with the Jacobian where normals or determinants are asked
// for.
template <typename Deformation, typename Real>
void LaunchDeform(const Deformation& deformation, const Real* points, const int* cells, std::int64_t count,
  Real* outPoints, const Real* normals, Real* outNormals, Real* determinants, cudaStream_t stream)
{
  if (outNormals || determinants)
  {
    DeformKernel<Deformation, Real, true><<<BlocksFor(count), ThreadsPerBlock, 0, stream>>>(
      points, cells, count, deformation, outPoints, normals, outNormals, determinants);
  }
  else
  {
    DeformKernel<Deformation, Real, false><<<BlocksFor((count + 3) / 4), ThreadsPerBlock, 0, stream>>>(
      points, cells, count, deformation, outPoints, nullptr, nullptr, nullptr);
  }
}

// Launches DeformPointsKernel over `count` points on `stream`.
template <bool Grouped = false, int MinBlocks = Grouped ? 2 : 4, typename Deformation, typename Real>
void LaunchDeformPoints(const Deformation& deformation, const Real* points, const int* cells, std::int64_t count,
  Real* outPoints, cudaStream_t stream)
{
  DeformPointsKernel<Deformation, Real, Grouped, MinBlocks>
    <<<BlocksFor((count + 3) / 4), ThreadsPerBlock, 0, stream>>>(points, cells, count, deformation, outPoints);
}
} // namespace detail

//------------------------------------------------------------------------------------------------------------
// The resident points, normals and binding, the last evaluation's results and their staged download, the
// lattice's upload, the stream, the counters. Each deformer's Impl derives from it and adds its lattice.
struct ResidentPoints::State
{
  using Buffer = detail::Buffer;

  std::int64_t Count = 0;
  bool IsDouble = false;
  bool HasNormals = false;
  bool Bound = false;
  bool Evaluated = false, EvaluatedNormals = false, EvaluatedDeterminants = false;
  Buffer Points, Normals, Cells, Lattice, OutPoints, OutNormals, OutDeterminants, Reduction;
  Buffer LatticeStaging{ true };
  cudaStream_t Stream = nullptr;
  // A download goes through two lanes at once, each a stream with two pinned buffers and their events, its half
  // copied out of pinned memory by a host thread of its own: that host copy, not the bus, bounds a download into
  // pageable memory. Lane 0 runs on Stream.
  struct DownloadLane
  {
    cudaStream_t Stream = nullptr;
    Buffer Staging[2] = { Buffer(true), Buffer(true) };
    cudaEvent_t ChunkDone[2] = { nullptr, nullptr };
  };
  DownloadLane Lanes[2];
  cudaEvent_t DownloadReady = nullptr; // recorded on Stream: what lane 1 waits for
  // Around an evaluation: its start, the end of the lattice's own kernels (if any), the end of the points'.
  cudaEvent_t KernelStart = nullptr, LatticeDone = nullptr, KernelStop = nullptr;
  int Multiprocessors = 0; // of the current device, for persistent grids
  std::string LastError;
  Counters Counts;

  virtual ~State() = default;

  /// Frees every buffer and forgets the points; a deformer that holds more frees that too.
  virtual void Release();

  void EnsureStream();

  /// Runs `step`, turning a CUDA failure into false, a message and no device state.
  template <typename Step>
  bool Guard(Step&& step)
  {
    try
    {
      step();
      return true;
    }
    catch (const detail::CudaError& e)
    {
      this->LastError = std::string("CUDA failed while ") + e.What + ": " + cudaGetErrorString(e.Code);
      cudaGetLastError(); // clear a non-sticky error so that later calls start clean
      this->Release();
      return false;
    }
  }

  /// Guard() of `deformer`'s RunEvaluate() (a State of its own) in the points' precision.
  template <typename Deformer, typename... Args>
  static bool EvaluateInPrecision(Deformer& deformer, const Args&... args)
  {
    return deformer.Guard(
      [&]
      {
        if (deformer.IsDouble)
        {
          deformer.template RunEvaluate<double>(args...);
        }
        else
        {
          deformer.template RunEvaluate<float>(args...);
        }
      });
  }

  template <typename Real>
  void Upload(const Real* xyz, std::int64_t count);

  /// Throws unless points are bound in the precision Real, with normals where they are asked for.
  template <typename Real>
  void RequireBound(bool withNormals) const
  {
    if (!this->Bound || (this->IsDouble != (sizeof(Real) == sizeof(double))))
    {
      throw detail::CudaError{ cudaErrorInvalidValue, "evaluating: no points bound in this precision" };
    }
    if (withNormals && !this->HasNormals)
    {
      throw detail::CudaError{ cudaErrorInvalidValue, "evaluating: normals asked for but none uploaded" };
    }
  }

  /// The lattice's update: `bytes` that the caller writes into the returned pinned buffer, then UploadLattice()
  /// sends to `Lattice` (the only upload of an update).
  void* StageLattice(std::size_t bytes);
  void UploadLattice(std::size_t bytes);

  /// Allocates the outputs of an evaluation (the points, in their precision Real) and records its start.
  template <typename Real>
  void BeginEvaluation(bool withNormals, bool withDeterminants)
  {
    this->OutPoints.Reserve(std::size_t(this->Count) * 3 * sizeof(Real), "allocating the deformed points");
    if (withNormals)
    {
      this->OutNormals.Reserve(std::size_t(this->Count) * 3 * sizeof(Real), "allocating the normals");
    }
    if (withDeterminants)
    {
      this->OutDeterminants.Reserve(std::size_t(this->Count) * sizeof(Real), "allocating the determinants");
    }
    detail::Check(cudaEventRecord(this->KernelStart, this->Stream), "recording an event");
  }

  /// Between the lattice's kernels and the points' kernel of an evaluation.
  void LatticeKernelsDone();

  /// After the points' kernel: checks its launch, waits for it, reads the times and marks what was evaluated.
  void FinishEvaluation(bool withNormals, bool withDeterminants, bool withLatticeKernels);

  template <typename Real>
  void SetNormals(const Real* normals);

  template <typename Real>
  void RunDownload(Real* outPoints, Real* outNormals, Real* outDeterminants);

  template <typename Real>
  void RunComputeBounds(double bounds[6]);

  /// Copies `bytes` from the device (what Stream wrote) to pageable host memory: from two staging buffers' worth
  /// on, half through each lane (DownloadLane), the second in a thread of its own.
  void Download(const void* device, void* host, std::size_t bytes);

  /// Copies `bytes` through `lane`'s two pinned buffers, so that the host copy of one chunk overlaps the transfer of
  /// the next.
  void DownloadThrough(DownloadLane& lane, const void* device, void* host, std::size_t bytes);
};

} // namespace cuda
} // namespace ffd

#endif
