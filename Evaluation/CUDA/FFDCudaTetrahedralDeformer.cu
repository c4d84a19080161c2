// SPDX-License-Identifier: BSD-3-Clause
#include "FFDCudaTetrahedralDeformer.h"

#include "FFDCudaDevice.cuh"
#include "FFDCudaGridAdjoint.cuh"
#include "FFDTetrahedra.h"

#include <cstring>
#include <memory>
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

// The adjoint's terms (FFDCudaGridAdjoint.cuh): term e = 4 chunk + k is node k of the chunk's tetrahedron.
__global__ void TetrahedronTermKernel(
  const int* __restrict__ chunkCell, const int4* __restrict__ nodes, std::int64_t terms, int* keys, int* values)
{
  const std::int64_t e = blockIdx.x * std::int64_t(blockDim.x) + threadIdx.x;
  if (e < terms)
  {
    const int4 n = nodes[chunkCell[e / 4]];
    const int k = int(e % 4);
    keys[e] = k == 0 ? n.x : (k == 1 ? n.y : (k == 2 ? n.z : n.w));
    values[e] = int(e);
  }
}

// The adjoint's partials, a warp per chunk of one tetrahedron: lane l sums the chunk's points l, l + 32, ... with
// their barycentric weights (1 - s - t - u, s, t, u) at the point, in float64 as the CPU's; then the lanes are
// added in a fixed tree (offsets 16, 8, 4, 2, 1), the same order at every run.
template <typename Real>
__global__ void TetrahedronChunkKernel(const Real* __restrict__ points, const int* __restrict__ order,
  const std::int64_t* __restrict__ chunkStart, const int* __restrict__ chunkCell, const Real* __restrict__ gradient,
  const ffd::Frame<double>* __restrict__ frames, std::int64_t chunks, double* __restrict__ partials)
{
  const std::int64_t chunk = (blockIdx.x * std::int64_t(blockDim.x) + threadIdx.x) / 32;
  const int lane = threadIdx.x % 32;
  if (chunk >= chunks)
  {
    return; // a whole warp
  }
  const ffd::Frame<double> frame = frames[chunkCell[chunk]];
  double sum[4][3] = {};
  for (std::int64_t q = chunkStart[chunk] + lane; q < chunkStart[chunk + 1]; q += 32)
  {
    const std::int64_t p = order[q];
    const Real* x = points + 3 * p;
    const ffd::Vec3<double> stu = frame.ToParametric({ double(x[0]), double(x[1]), double(x[2]) });
    const double w[4] = { 1.0 - stu.x - stu.y - stu.z, stu.x, stu.y, stu.z };
    for (int k = 0; k < 4; ++k)
    {
      for (int c = 0; c < 3; ++c)
      {
        sum[k][c] += w[k] * double(gradient[3 * p + c]);
      }
    }
  }
  for (int k = 0; k < 4; ++k)
  {
    for (int c = 0; c < 3; ++c)
    {
      for (int offset = 16; offset > 0; offset /= 2)
      {
        sum[k][c] += __shfl_down_sync(0xffffffffu, sum[k][c], offset);
      }
      if (lane == 0)
      {
        partials[3 * (4 * chunk + k) + c] = sum[k][c];
      }
    }
  }
}

} // namespace

//------------------------------------------------------------------------------------------------------------
struct TetrahedralDeformer::Impl : ResidentPoints::State
{
  Buffer Frames, Nodes, Maps; // rest frame and nodes (int4) per tetrahedron; this update's maps
  std::int64_t Tetrahedra = 0, NodeCount = 0;
  std::unique_ptr<detail::AdjointPlan> Plan; // the adjoint's, made for the binding it names

  void Release() override
  {
    this->Plan.reset();
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
    Check(cudaMemcpyAsync(this->Cells.Data, cells, cellBytes, cudaMemcpyHostToDevice, this->Stream),
      "uploading the binding");
    Check(cudaMemcpyAsync(this->Frames.Data, frames, frameBytes, cudaMemcpyHostToDevice, this->Stream),
      "uploading the tetrahedra");
    Check(cudaMemcpyAsync(this->Nodes.Data, nodes, nodeBytes, cudaMemcpyHostToDevice, this->Stream),
      "uploading the tetrahedra");
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

  // W^T g of the nodes: the plan (chunks of one tetrahedron, its 4 nodes their terms) made once per binding, then
  // the chunks' partials and their gather (FFDCudaGridAdjoint.cuh).
  template <typename Real>
  void RunAdjoint(const double* gradient, std::int64_t nodes, double* sums)
  {
    this->RequireBound<Real>(false);
    if (nodes != this->NodeCount)
    {
      throw CudaError{ cudaErrorInvalidValue, "the adjoint: the nodes do not match the bound ones" };
    }
    if (!this->Plan || this->Plan->ForBinding != this->Counts.Bindings)
    {
      this->Plan.reset(new detail::AdjointPlan);
      detail::AdjointPlan& plan = *this->Plan;
      const int counts[3] = { 1, 1, 4 }; // a tetrahedron's 4 nodes
      detail::MakeAdjointPlan(plan, counts, this->Cells.As<int>(), this->Count, nodes, sizeof(Real), this->Stream,
        [&](std::int64_t terms)
        {
          TetrahedronTermKernel<<<BlocksFor(terms), ThreadsPerBlock, 0, this->Stream>>>(
            plan.ChunkCell.As<int>(), this->Nodes.As<int4>(), terms, plan.Keys.As<int>(), plan.Values.As<int>());
        });
      plan.ForBinding = this->Counts.Bindings;
      ++this->Counts.AdjointPlans;
    }
    detail::AdjointPlan& plan = *this->Plan;
    this->Counts.BytesDownloaded += detail::RunAdjointUpdate<Real>(plan, gradient, this->Count, nodes, this->Stream,
      this->KernelStart, this->KernelStop, this->Counts.LastKernelMilliseconds, sums,
      [&]
      {
        TetrahedronChunkKernel<Real><<<BlocksFor(32 * plan.Chunks), ThreadsPerBlock, 0, this->Stream>>>(
          this->Points.As<Real>(), plan.Order.As<int>(), plan.ChunkStart.As<std::int64_t>(), plan.ChunkCell.As<int>(),
          plan.Gradient.As<Real>(), this->Frames.As<ffd::Frame<double>>(), plan.Chunks, plan.Partials.As<double>());
      });
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

bool TetrahedralDeformer::Adjoint(const double* gradient, std::int64_t nodes, double* sums)
{
  Impl& p = static_cast<Impl&>(*this->S);
  return p.Guard(
    [&]
    {
      if (p.IsDouble)
      {
        p.RunAdjoint<double>(gradient, nodes, sums);
      }
      else
      {
        p.RunAdjoint<float>(gradient, nodes, sums);
      }
    });
}

bool TetrahedralDeformer::Evaluate(
  const double* displacements, std::int64_t nodes, bool withNormals, bool withDeterminants)
{
  return ResidentPoints::State::EvaluateInPrecision(
    static_cast<Impl&>(*this->S), displacements, nodes, withNormals, withDeterminants);
}

} // namespace cuda
} // namespace ffd
