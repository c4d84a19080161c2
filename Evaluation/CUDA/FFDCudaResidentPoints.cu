// SPDX-License-Identifier: BSD-3-Clause
#include "FFDCudaDevice.cuh"

#include <algorithm>
#include <cstring>

namespace ffd
{
namespace cuda
{
using detail::Check;
using detail::CudaError;

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
    Check(cudaEventCreateWithFlags(&this->ChunkDone[0], cudaEventDisableTiming), "creating an event");
    Check(cudaEventCreateWithFlags(&this->ChunkDone[1], cudaEventDisableTiming), "creating an event");
    Check(cudaEventCreate(&this->KernelStart), "creating an event");
    Check(cudaEventCreate(&this->LatticeDone), "creating an event");
    Check(cudaEventCreate(&this->KernelStop), "creating an event");
  }
}

void ResidentPoints::State::Release()
{
  for (Buffer* b : { &this->Points, &this->Normals, &this->Cells, &this->Lattice, &this->OutPoints, &this->OutNormals,
         &this->OutDeterminants, &this->Staging[0], &this->Staging[1], &this->LatticeStaging })
  {
    b->Free();
  }
  for (cudaEvent_t* e :
    { &this->ChunkDone[0], &this->ChunkDone[1], &this->KernelStart, &this->LatticeDone, &this->KernelStop })
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

template <typename Real>
void ResidentPoints::State::Upload(const Real* xyz, std::int64_t count)
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
  using detail::StagingBytes;
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
void ResidentPoints::State::SetNormals(const Real* normals)
{
  if (this->IsDouble != (sizeof(Real) == sizeof(double)))
  {
    throw CudaError{ cudaErrorInvalidValue, "uploading the normals: not in the precision of the points" };
  }
  const std::size_t bytes = std::size_t(this->Count) * 3 * sizeof(Real);
  this->Normals.Reserve(bytes, "allocating the normals");
  Check(cudaMemcpy(this->Normals.Data, normals, bytes, cudaMemcpyHostToDevice), "uploading the normals");
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
  this->Staging[0].Reserve(detail::StagingBytes, "allocating the staging buffers");
  this->Staging[1].Reserve(detail::StagingBytes, "allocating the staging buffers");
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
