// SPDX-License-Identifier: BSD-3-Clause
#include "FFDCudaDevice.cuh"

#include <algorithm>
#include <cstring>
#include <exception>
#include <thread>

namespace ffd
{
namespace cuda
{
using detail::Check;
using detail::CudaError;

namespace
{
// The smallest of `lows` and the largest of `highs` per axis (item i's value on axis c at [3 i + c]; the points
// themselves, or a previous pass's per-block results), non-finite values skipped, for the items of the grid's
// stride loop: block b writes its three lows at outLows + 3 b and highs at outHighs + 3 b. Two passes (the
// points, then the blocks' results in one block) give the bounds.
template <typename Real>
__global__ void __launch_bounds__(detail::ThreadsPerBlock) BoundsKernel(
  const Real* __restrict__ lows, const Real* __restrict__ highs, std::int64_t count, Real* outLows, Real* outHighs)
{
  constexpr int T = detail::ThreadsPerBlock;
  __shared__ Real low[3][T], high[3][T];
  Real l[3] = { INFINITY, INFINITY, INFINITY }, h[3] = { -INFINITY, -INFINITY, -INFINITY };
  for (std::int64_t i = blockIdx.x * std::int64_t(T) + threadIdx.x; i < count; i += std::int64_t(gridDim.x) * T)
  {
    for (int c = 0; c < 3; ++c)
    {
      const Real a = lows[3 * i + c], b = highs[3 * i + c];
      l[c] = isfinite(a) ? fmin(l[c], a) : l[c];
      h[c] = isfinite(b) ? fmax(h[c], b) : h[c];
    }
  }
  for (int c = 0; c < 3; ++c)
  {
    low[c][threadIdx.x] = l[c];
    high[c][threadIdx.x] = h[c];
  }
  for (int half = T / 2; half > 0; half /= 2)
  {
    __syncthreads();
    if (threadIdx.x < half)
    {
      for (int c = 0; c < 3; ++c)
      {
        low[c][threadIdx.x] = fmin(low[c][threadIdx.x], low[c][threadIdx.x + half]);
        high[c][threadIdx.x] = fmax(high[c][threadIdx.x], high[c][threadIdx.x + half]);
      }
    }
  }
  if (threadIdx.x < 3)
  {
    outLows[3 * blockIdx.x + threadIdx.x] = low[threadIdx.x][0];
    outHighs[3 * blockIdx.x + threadIdx.x] = high[threadIdx.x][0];
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
void ResidentPoints::State::EnsureStream()
{
  if (!this->Stream)
  {
    int device = 0;
    Check(cudaGetDevice(&device), "querying the device");
    Check(
      cudaDeviceGetAttribute(&this->Multiprocessors, cudaDevAttrMultiProcessorCount, device), "querying the device");
    Check(cudaStreamCreateWithFlags(&this->Stream, cudaStreamNonBlocking), "creating a stream");
    Check(cudaStreamCreateWithFlags(&this->Lanes[1].Stream, cudaStreamNonBlocking), "creating a stream");
    this->Lanes[0].Stream = this->Stream;
    for (DownloadLane& lane : this->Lanes)
    {
      for (cudaEvent_t& e : lane.ChunkDone)
      {
        Check(cudaEventCreateWithFlags(&e, cudaEventDisableTiming), "creating an event");
      }
    }
    Check(cudaEventCreateWithFlags(&this->DownloadReady, cudaEventDisableTiming), "creating an event");
    Check(cudaEventCreate(&this->KernelStart), "creating an event");
    Check(cudaEventCreate(&this->LatticeDone), "creating an event");
    Check(cudaEventCreate(&this->KernelStop), "creating an event");
  }
}

void ResidentPoints::State::Release()
{
  for (Buffer* b : { &this->Points, &this->Normals, &this->Cells, &this->Lattice, &this->OutPoints, &this->OutNormals,
         &this->OutDeterminants, &this->Reduction, &this->LatticeStaging })
  {
    b->Free();
  }
  for (DownloadLane& lane : this->Lanes)
  {
    for (int c = 0; c < 2; ++c)
    {
      lane.Staging[c].Free();
      if (lane.ChunkDone[c])
      {
        cudaEventDestroy(lane.ChunkDone[c]);
      }
      lane.ChunkDone[c] = nullptr;
    }
  }
  for (cudaEvent_t* e : { &this->DownloadReady, &this->KernelStart, &this->LatticeDone, &this->KernelStop })
  {
    if (*e)
    {
      cudaEventDestroy(*e);
    }
    *e = nullptr;
  }
  for (cudaStream_t* stream : { &this->Stream, &this->Lanes[1].Stream })
  {
    if (*stream)
    {
      cudaStreamDestroy(*stream);
    }
    *stream = nullptr;
  }
  this->Lanes[0].Stream = nullptr;
  this->Count = 0;
  this->HasNormals = false;
  this->Bound = false;
  this->Evaluated = false;
}

template <typename Real>
void ResidentPoints::State::Upload(const Real* xyz, std::int64_t count)
{
  this->Release();
  this->EnsureStream();
  const std::size_t bytes = std::size_t(count) * 3 * sizeof(Real);
  this->Points.Reserve(bytes, "allocating the points");
  Check(cudaMemcpyAsync(this->Points.Data, xyz, bytes, cudaMemcpyHostToDevice, this->Stream), "uploading the points");
  this->Count = count;
  this->IsDouble = sizeof(Real) == sizeof(double);
  ++this->Counts.PointUploads;
}

void* ResidentPoints::State::StageLattice(std::size_t bytes)
{
  this->LatticeStaging.Reserve(bytes, "allocating the lattice's staging buffer");
  return this->LatticeStaging.Data;
}

void ResidentPoints::State::UploadLattice(std::size_t bytes)
{
  this->Lattice.Reserve(bytes, "allocating the lattice");
  Check(cudaMemcpyAsync(this->Lattice.Data, this->LatticeStaging.Data, bytes, cudaMemcpyHostToDevice, this->Stream),
    "uploading the lattice");
  ++this->Counts.LatticeUploads;
  this->Counts.LatticeBytes += bytes;
}

void ResidentPoints::State::LatticeKernelsDone()
{
  Check(cudaGetLastError(), "launching the lattice's kernels");
  Check(cudaEventRecord(this->LatticeDone, this->Stream), "recording an event");
}

void ResidentPoints::State::FinishEvaluation(bool withNormals, bool withDeterminants, bool withLatticeKernels)
{
  Check(cudaGetLastError(), "launching the evaluation");
  Check(cudaEventRecord(this->KernelStop, this->Stream), "recording an event");
  Check(cudaStreamSynchronize(this->Stream), "evaluating");
  cudaEvent_t pointsStart = withLatticeKernels ? this->LatticeDone : this->KernelStart;
  Check(
    cudaEventElapsedTime(&this->Counts.LastKernelMilliseconds, pointsStart, this->KernelStop), "timing the evaluation");
  this->Counts.LastLatticeKernelMilliseconds = 0;
  if (withLatticeKernels)
  {
    Check(cudaEventElapsedTime(&this->Counts.LastLatticeKernelMilliseconds, this->KernelStart, this->LatticeDone),
      "timing the evaluation");
  }
  this->Evaluated = true;
  this->EvaluatedNormals = withNormals;
  this->EvaluatedDeterminants = withDeterminants;
  ++this->Counts.Evaluations;
}

void ResidentPoints::State::Download(const void* device, void* host, std::size_t bytes)
{
  if (bytes < 2 * detail::StagingBytes)
  {
    this->DownloadThrough(this->Lanes[0], device, host, bytes);
    this->Counts.BytesDownloaded += bytes;
    return;
  }
  Check(cudaEventRecord(this->DownloadReady, this->Stream), "recording an event");
  Check(cudaStreamWaitEvent(this->Lanes[1].Stream, this->DownloadReady, 0), "ordering the download");
  const std::size_t half = bytes / 2;
  int gpu = 0;
  Check(cudaGetDevice(&gpu), "querying the device");
  std::exception_ptr failure;
  std::thread second(
    [&]
    {
      try
      {
        Check(cudaSetDevice(gpu), "selecting the device"); // a new thread starts on device 0
        this->DownloadThrough(
          this->Lanes[1], static_cast<const char*>(device) + half, static_cast<char*>(host) + half, bytes - half);
      }
      catch (...)
      {
        failure = std::current_exception();
      }
    });
  try
  {
    this->DownloadThrough(this->Lanes[0], device, host, half);
  }
  catch (...)
  {
    second.join();
    throw;
  }
  second.join();
  if (failure)
  {
    std::rethrow_exception(failure);
  }
  this->Counts.BytesDownloaded += bytes;
}

void ResidentPoints::State::DownloadThrough(DownloadLane& lane, const void* device, void* host, std::size_t bytes)
{
  using detail::StagingBytes;
  lane.Staging[0].Reserve(StagingBytes, "allocating the staging buffers");
  lane.Staging[1].Reserve(StagingBytes, "allocating the staging buffers");
  const std::size_t chunks = (bytes + StagingBytes - 1) / StagingBytes;
  for (std::size_t c = 0; c <= chunks; ++c)
  {
    if (c < chunks)
    {
      const std::size_t offset = c * StagingBytes, size = std::min(StagingBytes, bytes - offset);
      Check(cudaMemcpyAsync(lane.Staging[c % 2].Data, static_cast<const char*>(device) + offset, size,
              cudaMemcpyDeviceToHost, lane.Stream),
        "downloading");
      Check(cudaEventRecord(lane.ChunkDone[c % 2], lane.Stream), "recording an event");
    }
    if (c > 0)
    {
      const std::size_t previous = c - 1, offset = previous * StagingBytes;
      const std::size_t size = std::min(StagingBytes, bytes - offset);
      Check(cudaEventSynchronize(lane.ChunkDone[previous % 2]), "downloading");
      std::memcpy(static_cast<char*>(host) + offset, lane.Staging[previous % 2].Data, size);
    }
  }
}

template <typename Real>
void ResidentPoints::State::SetNormals(const Real* normals)
{
  if (this->IsDouble != (sizeof(Real) == sizeof(double)))
  {
    throw CudaError{ cudaErrorInvalidValue, "uploading the normals: not in the precision of the points" };
  }
  const std::size_t bytes = std::size_t(this->Count) * 3 * sizeof(Real);
  this->Normals.Reserve(bytes, "allocating the normals");
  Check(
    cudaMemcpyAsync(this->Normals.Data, normals, bytes, cudaMemcpyHostToDevice, this->Stream), "uploading the normals");
  this->HasNormals = true;
  ++this->Counts.NormalUploads;
}

template <typename Real>
void ResidentPoints::State::RunDownload(Real* outPoints, Real* outNormals, Real* outDeterminants)
{
  if (!this->Evaluated || (this->IsDouble != (sizeof(Real) == sizeof(double))) ||
    (outNormals && !this->EvaluatedNormals) || (outDeterminants && !this->EvaluatedDeterminants))
  {
    throw CudaError{ cudaErrorInvalidValue, "downloading: nothing of that was evaluated" };
  }
  this->Download(this->OutPoints.Data, outPoints, std::size_t(this->Count) * 3 * sizeof(Real));
  if (outNormals)
  {
    this->Download(this->OutNormals.Data, outNormals, std::size_t(this->Count) * 3 * sizeof(Real));
  }
  if (outDeterminants)
  {
    this->Download(this->OutDeterminants.Data, outDeterminants, std::size_t(this->Count) * sizeof(Real));
  }
}

template <typename Real>
void ResidentPoints::State::RunComputeBounds(double bounds[6])
{
  if (!this->Evaluated || (this->IsDouble != (sizeof(Real) == sizeof(double))))
  {
    throw CudaError{ cudaErrorInvalidValue, "computing the bounds: nothing was evaluated" };
  }
  const unsigned blocks = std::max(1u, std::min(detail::BlocksFor(this->Count), 2u * unsigned(this->Multiprocessors)));
  this->Reduction.Reserve((6 * std::size_t(blocks) + 6) * sizeof(Real), "allocating the bounds' reduction");
  Real* partial = this->Reduction.As<Real>();
  Real* result = partial + 6 * std::size_t(blocks);
  const Real* points = this->OutPoints.As<Real>();
  BoundsKernel<Real><<<blocks, detail::ThreadsPerBlock, 0, this->Stream>>>(
    points, points, this->Count, partial, partial + 3 * std::size_t(blocks));
  BoundsKernel<Real><<<1, detail::ThreadsPerBlock, 0, this->Stream>>>(
    partial, partial + 3 * std::size_t(blocks), blocks, result, result + 3);
  Check(cudaGetLastError(), "launching the bounds' reduction");
  Real lowsHighs[6];
  Check(cudaMemcpyAsync(lowsHighs, result, sizeof lowsHighs, cudaMemcpyDeviceToHost, this->Stream),
    "downloading the bounds");
  Check(cudaStreamSynchronize(this->Stream), "computing the bounds");
  for (int c = 0; c < 3; ++c)
  {
    bounds[2 * c] = lowsHighs[c];
    bounds[2 * c + 1] = lowsHighs[3 + c];
  }
  this->Counts.BytesDownloaded += sizeof lowsHighs;
}

//------------------------------------------------------------------------------------------------------------
ResidentPoints::ResidentPoints(std::unique_ptr<State> state)
  : S(std::move(state))
{
}

ResidentPoints::~ResidentPoints()
{
  this->S->Release(); // here, where the state is still whole: its deformer's Release() frees its lattice too
}

bool ResidentPoints::SetPoints(const float* xyz, std::int64_t count)
{
  return this->S->Guard([&] { this->S->Upload(xyz, count); });
}

bool ResidentPoints::SetPoints(const double* xyz, std::int64_t count)
{
  return this->S->Guard([&] { this->S->Upload(xyz, count); });
}

bool ResidentPoints::SetNormals(const float* normals)
{
  return this->S->Guard([&] { this->S->SetNormals(normals); });
}

bool ResidentPoints::SetNormals(const double* normals)
{
  return this->S->Guard([&] { this->S->SetNormals(normals); });
}

bool ResidentPoints::Download(float* outPoints, float* outNormals, float* outDeterminants)
{
  return this->S->Guard([&] { this->S->RunDownload(outPoints, outNormals, outDeterminants); });
}

bool ResidentPoints::Download(double* outPoints, double* outNormals, double* outDeterminants)
{
  return this->S->Guard([&] { this->S->RunDownload(outPoints, outNormals, outDeterminants); });
}

bool ResidentPoints::ComputeBounds(double bounds[6])
{
  return this->S->Guard(
    [&]
    {
      if (this->S->IsDouble)
      {
        this->S->RunComputeBounds<double>(bounds);
      }
      else
      {
        this->S->RunComputeBounds<float>(bounds);
      }
    });
}

void ResidentPoints::Release()
{
  this->S->Release();
}

const std::string& ResidentPoints::GetLastError() const
{
  return this->S->LastError;
}

const Counters& ResidentPoints::GetCounters() const
{
  return this->S->Counts;
}

} // namespace cuda
} // namespace ffd
