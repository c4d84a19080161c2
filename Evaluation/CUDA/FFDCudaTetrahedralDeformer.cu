// SPDX-License-Identifier: BSD-3-Clause
#include "FFDCudaTetrahedralDeformer.h"

#include "FFDCudaDevice.cuh"
#include "FFDTetrahedra.h"

#include <cstring>
#include <type_traits>

namespace ffd
{
namespace cuda
{
namespace
{
using detail::BlocksFor;
using detail::Check;
using detail::CudaError;
using detail::ThreadsPerBlock;

// Every tetrahedron's map for this update, from its rest frame and its nodes' displacements: the CPU's
// ffd::MakeTetrahedronMap in double, rounded to the points' precision as the CPU rounds it.
template <typename Real>
__global__ void MapKernel(const ffd::Frame<double>* __restrict__ frames, const int4* __restrict__ nodes,
  std::int64_t tetrahedra, const double* __restrict__ displacements, ffd::TetrahedronMap<Real>* __restrict__ maps)
{
  const std::int64_t t = blockIdx.x * std::int64_t(blockDim.x) + threadIdx.x;
  if (t >= tetrahedra)
  {
    return;
  }
  const int4 n = nodes[t];
  auto d = [&](int node) { return ffd::Vec3<double>::From(displacements + 3 * std::int64_t(node)); };
  maps[t] = ffd::MakeTetrahedronMap(frames[t], d(n.x), d(n.y), d(n.z), d(n.w)).template As<Real>();
}

} // namespace

//------------------------------------------------------------------------------------------------------------
struct TetrahedralDeformer::Impl : ResidentPoints::State
{
  Buffer Frames, Nodes, Maps; // rest frame and nodes (int4) per tetrahedron; this update's maps
  std::int64_t Tetrahedra = 0, NodeCount = 0;

  void Release() override
  {
    this->Frames.Free();
    this->Nodes.Free();
    this->Maps.Free();
    this->Tetrahedra = 0;
    this->NodeCount = 0;
    this->State::Release();
  }

  void RunBind(const int* cells, const ffd::Frame<double>* frames, const int* nodes, std::int64_t tetrahedra,
    std::int64_t nodeCount)
  {
    if (this->Count == 0)
    {
      throw CudaError{ cudaErrorInvalidValue, "binding: no points" };
    }
    // An index out of range would read outside the device's arrays: refused here, for the price of one pass.
    for (std::int64_t i = 0; i < this->Count; ++i)
    {
      if (cells[i] < -1 || cells[i] >= tetrahedra)
      {
        throw CudaError{ cudaErrorInvalidValue, "binding: a point's tetrahedron is out of range" };
      }
    }
    for (std::int64_t i = 0; i < 4 * tetrahedra; ++i)
    {
      if (nodes[i] < 0 || nodes[i] >= nodeCount)
      {
        throw CudaError{ cudaErrorInvalidValue, "binding: a tetrahedron's node is out of range" };
      }
    }
    const std::size_t cellBytes = std::size_t(this->Count) * sizeof(int);
    const std::size_t frameBytes = std::size_t(tetrahedra) * sizeof(ffd::Frame<double>);
    const std::size_t nodeBytes = std::size_t(tetrahedra) * sizeof(int4);
    this->Cells.Reserve(cellBytes, "allocating the binding");
    this->Frames.Reserve(frameBytes, "allocating the tetrahedra");
    this->Nodes.Reserve(nodeBytes, "allocating the tetrahedra");
    Check(cudaMemcpy(this->Cells.Data, cells, cellBytes, cudaMemcpyHostToDevice), "uploading the binding");
    Check(cudaMemcpy(this->Frames.Data, frames, frameBytes, cudaMemcpyHostToDevice), "uploading the tetrahedra");
    Check(cudaMemcpy(this->Nodes.Data, nodes, nodeBytes, cudaMemcpyHostToDevice), "uploading the tetrahedra");
    this->Tetrahedra = tetrahedra;
    this->NodeCount = nodeCount;
    this->Bound = true;
    this->Evaluated = false;
    ++this->Counts.Bindings;
  }

  template <typename Real>
  void RunEvaluate(const double* displacements, std::int64_t nodes, bool withNormals, bool withDeterminants)
  {
    this->RequireBound<Real>(withNormals);
    if (nodes != this->NodeCount)
    {
      throw CudaError{ cudaErrorInvalidValue, "evaluating: the displacements do not match the bound nodes" };
    }
    const std::size_t bytes = std::size_t(nodes) * 3 * sizeof(double);
    std::memcpy(this->StageLattice(bytes), displacements, bytes);
    this->UploadLattice(bytes);
    this->Maps.Reserve(std::size_t(this->Tetrahedra) * sizeof(ffd::TetrahedronMap<Real>), "allocating the maps");

    this->BeginEvaluation<Real>(withNormals, withDeterminants);
    auto* maps = this->Maps.As<ffd::TetrahedronMap<Real>>();
    if (this->Tetrahedra > 0)
    {
      MapKernel<Real>
        <<<BlocksFor(this->Tetrahedra), ThreadsPerBlock, 0, this->Stream>>>(this->Frames.As<ffd::Frame<double>>(),
          this->Nodes.As<int4>(), this->Tetrahedra, this->Lattice.As<double>(), maps);
    }
    this->LatticeKernelsDone();
    const ffd::TetrahedralDeformation<Real> deformation{ maps };
    Real* normalsOut = withNormals ? this->OutNormals.As<Real>() : nullptr;
    Real* determinantsOut = withDeterminants ? this->OutDeterminants.As<Real>() : nullptr;
    // Float32 points alone (an ordinary update) take the kernel of 16-byte point loads and stores, as trilinear
    // grids do (BENCHMARKS.md).
    if constexpr (std::is_same<Real, float>::value)
    {
      if (!withNormals && !withDeterminants)
      {
        detail::LaunchDeformPoints(deformation, this->Points.As<float>(), this->Cells.As<int>(), this->Count,
          this->OutPoints.As<float>(), this->Stream);
        this->FinishEvaluation(false, false, true);
        return;
      }
    }
    detail::LaunchDeform(deformation, this->Points.As<Real>(), this->Cells.As<int>(), this->Count,
      this->OutPoints.As<Real>(), this->Normals.As<Real>(), normalsOut, determinantsOut, this->Stream);
    this->FinishEvaluation(withNormals, withDeterminants, true);
  }
};

//------------------------------------------------------------------------------------------------------------
TetrahedralDeformer::TetrahedralDeformer()
  : ResidentPoints(std::unique_ptr<State>(new Impl))
{
}

bool TetrahedralDeformer::Bind(const int* tetrahedronOfPoint, const ffd::Frame<double>* restFrames,
  const int* tetrahedronNodes, std::int64_t tetrahedra, std::int64_t nodes)
{
  Impl& p = static_cast<Impl&>(*this->S);
  return p.Guard([&] { p.RunBind(tetrahedronOfPoint, restFrames, tetrahedronNodes, tetrahedra, nodes); });
}

bool TetrahedralDeformer::Evaluate(
  const double* displacements, std::int64_t nodes, bool withNormals, bool withDeterminants)
{
  return ResidentPoints::State::EvaluateInPrecision(
    static_cast<Impl&>(*this->S), displacements, nodes, withNormals, withDeterminants);
}

} // namespace cuda
} // namespace ffd
