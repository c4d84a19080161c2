// SPDX-License-Identifier: BSD-3-Clause
#include "FFDCudaGridDeformer.h"

#include "FFDGridDeformation.h"

#include <cuda_runtime.h>

#include <algorithm>
#include <cstring>
#include <type_traits>
#include <vector>

namespace ffd
{
namespace cuda
{
namespace
{
constexpr int ThreadsPerBlock = 256;
// Size of each of the two pinned buffers that stage a download: large enough to run the bus at full speed,
// small enough that the host copy of one chunk overlaps the transfer of the next (8 MB chunks made an update
// of 1 M points 1.4-1.6 times the bare download, the host copy of the first chunk waiting alone).
constexpr std::size_t StagingBytes = std::size_t(2) << 20;

unsigned BlocksFor(std::int64_t n)
{
  return unsigned((n + ThreadsPerBlock - 1) / ThreadsPerBlock);
}

// A CUDA failure, turned into a message by Check().
struct CudaError
{
  cudaError_t Code;
  const char* What;
};

void Check(cudaError_t code, const char* what)
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
template <typename Real>
__global__ void BindKernel(const Real* points, std::int64_t count, ffd::Frame<double> frame, ffd::GridBasis basis,
  int voxelsS, int voxelsT, int voxelsU, bool clampOutside, int* cells)
{
  const std::int64_t i = blockIdx.x * std::int64_t(blockDim.x) + threadIdx.x;
  if (i >= count)
  {
    return;
  }
  const int voxels[3] = { voxelsS, voxelsT, voxelsU };
  const Real* p = points + 3 * i;
  cells[i] = ffd::BindToGrid(frame, basis, voxels, ffd::Vec3<double>{ double(p[0]), double(p[1]), double(p[2]) },
    clampOutside);
}

// With the Jacobian (normals, determinants) one point a thread; without, four points a thread, ThreadsPerBlock
// apart (consecutive threads, consecutive points), so that their independent lattice gathers overlap, and an
// instantiation that needs fewer registers. Launch bounds keep at least 4 (6) blocks of 256 threads on a
// multiprocessor: the gathers are dependent loads, and more threads in flight hide their latency. Trilinear on
// an H200: 58-62 % of the copy roofline with one point a thread, 64-70 % with four. (Reading each thread's four
// consecutive points as three 16-byte words gave the same; staging the points through shared memory was slower.)
template <typename Deformer, typename Real, bool WithJacobian>
__global__ void __launch_bounds__(ThreadsPerBlock, WithJacobian ? 4 : 6) DeformKernel(const Real* __restrict__ points,
  const int* __restrict__ cells, std::int64_t count, Deformer deformation,
  Real* __restrict__ outPoints, const float* __restrict__ normals, float* __restrict__ outNormals,
  Real* __restrict__ determinants)
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
    const Real* p = points + 3 * i;
    const ffd::Vec3<Real> x = { p[0], p[1], p[2] };
    const int cell = cells[i];
    ffd::Vec3<Real> y = x;
    ffd::Mat3<Real> jacobian = ffd::Mat3<Real>::Identity();
    if (cell >= 0)
    {
      y = WithJacobian ? deformation.Deform(x, cell, jacobian) : deformation.Deform(x, cell);
    }
    Real* out = outPoints + 3 * i;
    out[0] = y.x;
    out[1] = y.y;
    out[2] = y.z;
    if (!WithJacobian)
    {
      continue;
    }
    if (outNormals)
    {
      const ffd::Vec3<Real> n = ffd::TransformNormal(jacobian, ffd::Vec3<Real>::From(normals + 3 * i));
      outNormals[3 * i] = float(n.x);
      outNormals[3 * i + 1] = float(n.y);
      outNormals[3 * i + 2] = float(n.z);
    }
    if (determinants)
    {
      determinants[i] = ffd::Determinant(jacobian);
    }
  }
}

// The global basis without Jacobian, the case that dominates its cost: the lattice sits in shared memory as
// float4 (one 16-byte broadcast load per control point), each thread evaluates four points (each lattice value
// loaded serves all four, twelve FMAs; two points per thread ran at 3.1 G points/s, four at 3.6 for 11^3 on an
// H200), and the weights of the first axis stay in registers (MaxCount bounds the
// control points per axis at compile time). The same function as ffd::GridDeformation::Deform (the tests
// compare the two): x + sum_ijk B_i(s) B_j(t) B_k(u) D_ijk at the clamped parameters of a bound point.
template <int MaxCount>
__global__ void __launch_bounds__(ThreadsPerBlock) BernsteinKernel(const float* __restrict__ points,
  const int* __restrict__ cells, std::int64_t count, ffd::Frame<float> frame, int dimS, int dimT, int dimU,
  const float* __restrict__ displacements, float* __restrict__ outPoints)
{
  extern __shared__ float4 lattice[];
  const int total = dimS * dimT * dimU;
  for (int v = threadIdx.x; v < total; v += ThreadsPerBlock)
  {
    lattice[v] = make_float4(displacements[3 * v], displacements[3 * v + 1], displacements[3 * v + 2], 0.0f);
  }
  __syncthreads();

  constexpr int Points = 4;
  const std::int64_t first = blockIdx.x * std::int64_t(Points * ThreadsPerBlock) + threadIdx.x;
  float x[Points][3];
  bool bound[Points];
  float bs[Points][MaxCount], bt[Points][MaxCount], bu[Points][MaxCount];
  FFD_UNROLL
  for (int p = 0; p < Points; ++p)
  {
    const std::int64_t i = first + p * ThreadsPerBlock; // consecutive threads, consecutive points
    bound[p] = i < count && cells[i] >= 0;
    const std::int64_t at = i < count ? i : 0;
    x[p][0] = points[3 * at];
    x[p][1] = points[3 * at + 1];
    x[p][2] = points[3 * at + 2];
    const ffd::Vec3<float> stu = frame.ToParametric({ x[p][0], x[p][1], x[p][2] });
    auto clamp01 = [](float v) { return v < 0.0f ? 0.0f : (v > 1.0f ? 1.0f : v); };
    ffd::BernsteinBasisBounded<MaxCount>(dimS - 1, clamp01(stu.x), bs[p]);
    ffd::BernsteinBasisBounded<MaxCount>(dimT - 1, clamp01(stu.y), bt[p]);
    ffd::BernsteinBasisBounded<MaxCount>(dimU - 1, clamp01(stu.z), bu[p]);
  }

  float sum[Points][3] = {};
  for (int k = 0; k < dimU; ++k)
  {
    for (int j = 0; j < dimT; ++j)
    {
      const float4* row = lattice + dimS * (j + dimT * k);
      float partial[Points][3] = {};
      FFD_UNROLL
      for (int i = 0; i < MaxCount; ++i)
      {
        if (i >= dimS)
        {
          break;
        }
        const float4 d = row[i];
        FFD_UNROLL
        for (int p = 0; p < Points; ++p)
        {
          partial[p][0] += bs[p][i] * d.x;
          partial[p][1] += bs[p][i] * d.y;
          partial[p][2] += bs[p][i] * d.z;
        }
      }
      FFD_UNROLL
      for (int p = 0; p < Points; ++p)
      {
        const float w = bt[p][j] * bu[p][k];
        sum[p][0] += w * partial[p][0];
        sum[p][1] += w * partial[p][1];
        sum[p][2] += w * partial[p][2];
      }
    }
  }
  FFD_UNROLL
  for (int p = 0; p < Points; ++p)
  {
    const std::int64_t i = first + p * ThreadsPerBlock;
    if (i < count)
    {
      FFD_UNROLL
      for (int c = 0; c < 3; ++c)
      {
        outPoints[3 * i + c] = bound[p] ? x[p][c] + sum[p][c] : x[p][c];
      }
    }
  }
}
} // namespace

//------------------------------------------------------------------------------------------------------------
bool DeviceAvailable(std::string* why)
{
  int count = 0;
  const cudaError_t code = cudaGetDeviceCount(&count);
  if (code != cudaSuccess || count == 0)
  {
    if (why)
    {
      *why = code != cudaSuccess ? std::string("no CUDA device: ") + cudaGetErrorString(code)
                                 : std::string("no CUDA device");
    }
    cudaGetLastError(); // clear the sticky error of a failed query
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------------------------------------
struct GridDeformer::Impl
{
  std::int64_t Count = 0;
  bool IsDouble = false;
  bool HasNormals = false;
  bool Bound = false;
  bool Evaluated = false, EvaluatedNormals = false, EvaluatedDeterminants = false;
  ffd::GridBasis Basis = ffd::GridBasis::Bernstein;
  int Divisions[3] = { 0, 0, 0 };
  double Frame[12] = {};
  Buffer Points, Normals, Cells, Displacements, OutPoints, OutNormals, OutDeterminants;
  Buffer Staging[2] = { Buffer(true), Buffer(true) };
  Buffer LatticeStaging{ true };
  cudaStream_t Stream = nullptr;
  cudaEvent_t ChunkDone[2] = { nullptr, nullptr };
  cudaEvent_t KernelStart = nullptr, KernelStop = nullptr; // to time the evaluation kernel
  std::string LastError;
  Counters Counts;

  void EnsureStream()
  {
    if (!this->Stream)
    {
      Check(cudaStreamCreateWithFlags(&this->Stream, cudaStreamNonBlocking), "creating a stream");
      Check(cudaEventCreateWithFlags(&this->ChunkDone[0], cudaEventDisableTiming), "creating an event");
      Check(cudaEventCreateWithFlags(&this->ChunkDone[1], cudaEventDisableTiming), "creating an event");
      Check(cudaEventCreate(&this->KernelStart), "creating an event");
      Check(cudaEventCreate(&this->KernelStop), "creating an event");
    }
  }

  void Release()
  {
    for (Buffer* b : { &this->Points, &this->Normals, &this->Cells, &this->Displacements, &this->OutPoints,
           &this->OutNormals, &this->OutDeterminants })
    {
      b->Free();
    }
    this->Staging[0].Free();
    this->Staging[1].Free();
    this->LatticeStaging.Free();
    for (cudaEvent_t* e : { &this->ChunkDone[0], &this->ChunkDone[1], &this->KernelStart, &this->KernelStop })
    {
      if (*e)
      {
        cudaEventDestroy(*e);
      }
      *e = nullptr;
    }
    if (this->Stream)
    {
      cudaStreamDestroy(this->Stream);
    }
    this->Stream = nullptr;
    this->Count = 0;
    this->HasNormals = false;
    this->Bound = false;
    this->Evaluated = false;
  }

  // Runs `step`, turning a CUDA failure into false, a message and no device state.
  template <typename Step>
  bool Guard(Step&& step)
  {
    try
    {
      step();
      return true;
    }
    catch (const CudaError& e)
    {
      this->LastError = std::string("CUDA failed while ") + e.What + ": " + cudaGetErrorString(e.Code);
      cudaGetLastError(); // clear a non-sticky error so that later calls start clean
      this->Release();
      return false;
    }
  }

  template <typename Real>
  void Upload(const Real* xyz, std::int64_t count)
  {
    this->Release();
    this->EnsureStream();
    const std::size_t bytes = std::size_t(count) * 3 * sizeof(Real);
    this->Points.Reserve(bytes, "allocating the points");
    Check(cudaMemcpy(this->Points.Data, xyz, bytes, cudaMemcpyHostToDevice), "uploading the points");
    this->Count = count;
    this->IsDouble = sizeof(Real) == sizeof(double);
    ++this->Counts.PointUploads;
  }

  template <typename Real>
  void RunBind(const ffd::Frame<double>& frame, bool clampOutside)
  {
    BindKernel<Real><<<BlocksFor(this->Count), ThreadsPerBlock, 0, this->Stream>>>(this->Points.As<Real>(),
      this->Count, frame, this->Basis, this->Divisions[0], this->Divisions[1], this->Divisions[2], clampOutside,
      this->Cells.As<int>());
    Check(cudaGetLastError(), "launching the binding");
    Check(cudaStreamSynchronize(this->Stream), "binding the points");
  }

  // Copies `bytes` from the device to pageable host memory through the two pinned buffers, so that the host
  // copy of one chunk overlaps the transfer of the next.
  void Download(const void* device, void* host, std::size_t bytes)
  {
    const std::size_t chunks = (bytes + StagingBytes - 1) / StagingBytes;
    for (std::size_t c = 0; c <= chunks; ++c)
    {
      if (c < chunks)
      {
        const std::size_t offset = c * StagingBytes, size = std::min(StagingBytes, bytes - offset);
        Check(cudaMemcpyAsync(this->Staging[c % 2].Data, static_cast<const char*>(device) + offset, size,
                cudaMemcpyDeviceToHost, this->Stream),
          "downloading");
        Check(cudaEventRecord(this->ChunkDone[c % 2], this->Stream), "recording an event");
      }
      if (c > 0)
      {
        const std::size_t previous = c - 1, offset = previous * StagingBytes;
        const std::size_t size = std::min(StagingBytes, bytes - offset);
        Check(cudaEventSynchronize(this->ChunkDone[previous % 2]), "downloading");
        std::memcpy(static_cast<char*>(host) + offset, this->Staging[previous % 2].Data, size);
      }
    }
    this->Counts.BytesDownloaded += bytes;
  }

  template <typename Real>
  void RunEvaluate(const double* displacements, std::int64_t controlPoints, bool withNormals, bool withDeterminants)
  {
    if (!this->Bound || (this->IsDouble != (sizeof(Real) == sizeof(double))))
    {
      throw CudaError{ cudaErrorInvalidValue, "evaluating: no points bound in this precision" };
    }
    if (withNormals && !this->HasNormals)
    {
      throw CudaError{ cudaErrorInvalidValue, "evaluating: normals asked for but none uploaded" };
    }
    const int dims[3] = { ffd::ControlPointsAlongAxis(this->Basis, this->Divisions[0]),
      ffd::ControlPointsAlongAxis(this->Basis, this->Divisions[1]),
      ffd::ControlPointsAlongAxis(this->Basis, this->Divisions[2]) };
    if (controlPoints != std::int64_t(dims[0]) * dims[1] * dims[2])
    {
      throw CudaError{ cudaErrorInvalidValue, "evaluating: the lattice does not match the binding's basis" };
    }
    // The lattice: the only upload of an update.
    const std::size_t latticeBytes = std::size_t(controlPoints) * 3 * sizeof(Real);
    this->LatticeStaging.Reserve(latticeBytes, "allocating the lattice's staging buffer");
    Real* staged = static_cast<Real*>(this->LatticeStaging.Data);
    for (std::int64_t v = 0; v < 3 * controlPoints; ++v)
    {
      staged[v] = Real(displacements[v]);
    }
    this->Displacements.Reserve(latticeBytes, "allocating the lattice");
    Check(cudaMemcpyAsync(this->Displacements.Data, staged, latticeBytes, cudaMemcpyHostToDevice, this->Stream),
      "uploading the lattice");
    ++this->Counts.LatticeUploads;
    this->Counts.LatticeBytes += latticeBytes;

    this->OutPoints.Reserve(std::size_t(this->Count) * 3 * sizeof(Real), "allocating the deformed points");
    if (withNormals)
    {
      this->OutNormals.Reserve(std::size_t(this->Count) * 3 * sizeof(float), "allocating the normals");
    }
    if (withDeterminants)
    {
      this->OutDeterminants.Reserve(std::size_t(this->Count) * sizeof(Real), "allocating the determinants");
    }
    const ffd::Frame<Real> frame = ffd::Frame<Real>::FromArray(this->Frame);
    const Real* d = this->Displacements.As<Real>();
    float* normalsOut = withNormals ? this->OutNormals.As<float>() : nullptr;
    Real* determinantsOut = withDeterminants ? this->OutDeterminants.As<Real>() : nullptr;
    Check(cudaEventRecord(this->KernelStart, this->Stream), "recording an event");
    if (!this->LaunchBernstein(d, dims, withNormals || withDeterminants))
    {
      this->LaunchGeneric(frame, d, dims, normalsOut, determinantsOut);
    }
    Check(cudaGetLastError(), "launching the evaluation");
    Check(cudaEventRecord(this->KernelStop, this->Stream), "recording an event");
    Check(cudaStreamSynchronize(this->Stream), "evaluating");
    Check(cudaEventElapsedTime(&this->Counts.LastKernelMilliseconds, this->KernelStart, this->KernelStop),
      "timing the evaluation");
    this->Evaluated = true;
    this->EvaluatedNormals = withNormals;
    this->EvaluatedDeterminants = withDeterminants;
    ++this->Counts.Evaluations;
  }

  // Launches DeformKernel, one instantiation per basis (see ffd::GridDeformation's StaticBasis).
  template <typename Real>
  void LaunchGeneric(const ffd::Frame<Real>& frame, const Real* d, const int dims[3], float* normalsOut,
    Real* determinantsOut)
  {
    // One kernel per basis (see ffd::GridDeformation's StaticBasis). The global basis sums over every control
    // point of an axis, a local one over at most 4.
    auto launch = [&](auto maxCount, auto basis) {
      using Deformer = ffd::GridDeformation<decltype(maxCount)::value, Real, decltype(basis)::value>;
      const Deformer deformation{ this->Basis, { this->Divisions[0], this->Divisions[1], this->Divisions[2] },
        { dims[0], dims[1], dims[2] }, d, frame };
      if (normalsOut || determinantsOut)
      {
        DeformKernel<Deformer, Real, true><<<BlocksFor(this->Count), ThreadsPerBlock, 0, this->Stream>>>(
          this->Points.As<Real>(), this->Cells.As<int>(), this->Count, deformation, this->OutPoints.As<Real>(),
          this->Normals.As<float>(), normalsOut, determinantsOut);
      }
      else
      {
        DeformKernel<Deformer, Real, false><<<BlocksFor((this->Count + 3) / 4), ThreadsPerBlock, 0, this->Stream>>>(
          this->Points.As<Real>(), this->Cells.As<int>(), this->Count, deformation, this->OutPoints.As<Real>(),
          nullptr, nullptr, nullptr);
      }
    };
    using ffd::GridBasis;
    using Local = std::integral_constant<int, 4>;
    switch (this->Basis)
    {
      case GridBasis::Bernstein:
        launch(std::integral_constant<int, ffd::MaxBernsteinDegree + 1>(),
          std::integral_constant<int, int(GridBasis::Bernstein)>());
        break;
      case GridBasis::Trilinear:
        launch(Local(), std::integral_constant<int, int(GridBasis::Trilinear)>());
        break;
      case GridBasis::TriquadraticBezier:
        launch(Local(), std::integral_constant<int, int(GridBasis::TriquadraticBezier)>());
        break;
      case GridBasis::TricubicBezier:
        launch(Local(), std::integral_constant<int, int(GridBasis::TricubicBezier)>());
        break;
      case GridBasis::CubicBSpline:
        launch(Local(), std::integral_constant<int, int(GridBasis::CubicBSpline)>());
        break;
    }
  }

  // Launches BernsteinKernel when it applies: the global basis in float32, no Jacobian asked for, at most 16
  // control points per axis and a lattice that fits in 48 KB of shared memory. False otherwise.
  template <typename Real>
  bool LaunchBernstein(const Real* displacements, const int dims[3], bool withJacobian)
  {
    if constexpr (std::is_same<Real, float>::value)
    {
      const int largest = std::max(dims[0], std::max(dims[1], dims[2]));
      const std::size_t shared = std::size_t(dims[0]) * dims[1] * dims[2] * sizeof(float4);
      if (this->Basis != ffd::GridBasis::Bernstein || withJacobian || largest > 16 || shared > 48 * 1024)
      {
        return false;
      }
      const unsigned blocks = unsigned((this->Count + 4 * ThreadsPerBlock - 1) / (4 * ThreadsPerBlock));
      const ffd::Frame<float> frame = ffd::Frame<float>::FromArray(this->Frame);
      // The smaller instantiation that holds the lattice's axes. (A third one, for up to 12 control points per
      // axis, made 11^3 lattices slower: 3.4 instead of 3.6 G points/s on an H200.)
      auto launch = [&](auto maxCount) {
        BernsteinKernel<decltype(maxCount)::value><<<blocks, ThreadsPerBlock, shared, this->Stream>>>(
          this->Points.As<float>(), this->Cells.As<int>(), this->Count, frame, dims[0], dims[1], dims[2],
          displacements, this->OutPoints.As<float>());
      };
      if (largest <= 8)
      {
        launch(std::integral_constant<int, 8>());
      }
      else
      {
        launch(std::integral_constant<int, 16>());
      }
      return true;
    }
    return false;
  }

  template <typename Real>
  void RunDownload(Real* outPoints, float* outNormals, Real* outDeterminants)
  {
    if (!this->Evaluated || (this->IsDouble != (sizeof(Real) == sizeof(double))) ||
      (outNormals && !this->EvaluatedNormals) || (outDeterminants && !this->EvaluatedDeterminants))
    {
      throw CudaError{ cudaErrorInvalidValue, "downloading: nothing of that was evaluated" };
    }
    this->Staging[0].Reserve(StagingBytes, "allocating the staging buffers");
    this->Staging[1].Reserve(StagingBytes, "allocating the staging buffers");
    this->Download(this->OutPoints.Data, outPoints, std::size_t(this->Count) * 3 * sizeof(Real));
    if (outNormals)
    {
      this->Download(this->OutNormals.Data, outNormals, std::size_t(this->Count) * 3 * sizeof(float));
    }
    if (outDeterminants)
    {
      this->Download(this->OutDeterminants.Data, outDeterminants, std::size_t(this->Count) * sizeof(Real));
    }
  }
};

//------------------------------------------------------------------------------------------------------------
GridDeformer::GridDeformer()
  : P(new Impl)
{
}

GridDeformer::~GridDeformer()
{
  this->P->Release();
}

bool GridDeformer::SetPoints(const float* xyz, std::int64_t count)
{
  return this->P->Guard([&] { this->P->Upload(xyz, count); });
}

bool GridDeformer::SetPoints(const double* xyz, std::int64_t count)
{
  return this->P->Guard([&] { this->P->Upload(xyz, count); });
}

bool GridDeformer::SetNormals(const float* normals)
{
  return this->P->Guard([&] {
    const std::size_t bytes = std::size_t(this->P->Count) * 3 * sizeof(float);
    this->P->Normals.Reserve(bytes, "allocating the normals");
    Check(cudaMemcpy(this->P->Normals.Data, normals, bytes, cudaMemcpyHostToDevice), "uploading the normals");
    this->P->HasNormals = true;
    ++this->P->Counts.NormalUploads;
  });
}

bool GridDeformer::Bind(const double frame[12], int basis, const int divisions[3], bool clampOutside)
{
  return this->P->Guard([&] {
    Impl& p = *this->P;
    if (p.Count == 0 || !ffd::IsGridBasis(basis))
    {
      throw CudaError{ cudaErrorInvalidValue, "binding: no points, or an unknown basis" };
    }
    std::copy(frame, frame + 12, p.Frame);
    std::copy(divisions, divisions + 3, p.Divisions);
    p.Basis = static_cast<ffd::GridBasis>(basis);
    p.Cells.Reserve(std::size_t(p.Count) * sizeof(int), "allocating the binding");
    const ffd::Frame<double> f = ffd::Frame<double>::FromArray(frame);
    if (p.IsDouble)
    {
      p.RunBind<double>(f, clampOutside);
    }
    else
    {
      p.RunBind<float>(f, clampOutside);
    }
    p.Bound = true;
    p.Evaluated = false;
    ++p.Counts.Bindings;
  });
}

bool GridDeformer::Evaluate(const double* displacements, std::int64_t controlPoints, bool withNormals,
  bool withDeterminants)
{
  return this->P->Guard([&] {
    if (this->P->IsDouble)
    {
      this->P->RunEvaluate<double>(displacements, controlPoints, withNormals, withDeterminants);
    }
    else
    {
      this->P->RunEvaluate<float>(displacements, controlPoints, withNormals, withDeterminants);
    }
  });
}

bool GridDeformer::Download(float* outPoints, float* outNormals, float* outDeterminants)
{
  return this->P->Guard([&] { this->P->RunDownload(outPoints, outNormals, outDeterminants); });
}

bool GridDeformer::Download(double* outPoints, float* outNormals, double* outDeterminants)
{
  return this->P->Guard([&] { this->P->RunDownload(outPoints, outNormals, outDeterminants); });
}

void GridDeformer::Release()
{
  this->P->Release();
}

const std::string& GridDeformer::GetLastError() const
{
  return this->P->LastError;
}

const Counters& GridDeformer::GetCounters() const
{
  return this->P->Counts;
}

} // namespace cuda
} // namespace ffd
