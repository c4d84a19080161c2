// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDCudaGridAdjoint.cuh
 * @brief The adjoint of a grid lattice's deformation on the device, W^T g, without floating-point atomics: for
 * FFDCudaGridDeformer.cu only.
 *
 * A plan, made once per binding (MakeAdjointPlan()): the bound points sorted by cell (a stable radix sort, so in
 * increasing id within a cell), cut into chunks of at most ChunkPoints points of one cell; and the chunks'
 * terms (chunk, k), k the control point of the cell's support, sorted by control point (stable: by chunk, then
 * k). An evaluation (RunAdjoint()): AdjointChunkKernel sums each chunk's points into one float64 partial per
 * term, in a fixed order; AdjointGatherKernel adds each control point's partials in the plan's order. Every sum
 * has one order, set by the points, their binding and ChunkPoints alone, never by the launch or the hardware:
 * the same bits at every run.
 */
#ifndef FFDCudaGridAdjoint_cuh
#define FFDCudaGridAdjoint_cuh

#include "FFDAdjoint.h"
#include "FFDCudaDevice.cuh"
#include "FFDGridDeformation.h"

#include <cstdint>
#include <vector>

namespace ffd
{
namespace cuda
{
namespace detail
{
constexpr int AdjointThreads = 128; // a chunk's block

/// The plan of the adjoint of one binding (see the file's description), on the device.
struct AdjointPlan
{
  std::uint64_t ForBinding = 0; // Counters::Bindings when made; 0: none
  std::int64_t ChunkPoints = 0; // ffd::AdjointChunkPoints()
  std::int64_t Chunks = 0;
  int Terms = 0;         // K, control points of a cell's support
  int Counts[3] = {};    // K along each axis (i fastest)
  Buffer Order;          // int: the bound points by cell, then id
  Buffer ChunkStart;     // int64: Chunks + 1 positions in Order
  Buffer ChunkCell;      // int: each chunk's cell
  Buffer TermOrder;      // int: the terms (chunk K + k) by control point, then term
  Buffer TermStart;      // int: per control point (and one past the last), its first position in TermOrder
  Buffer Partials;       // double: 3 per term
  Buffer Sums, Gradient; // double, 3 per control point; the gradient, 3 per point in the points' precision
  Buffer Keys, Values, Flags, Scratch;
};

/**
 * The plan's first part, up to the chunks (Order, ChunkStart, ChunkCell, Chunks): `cells` are the binding's,
 * one per point (-1: unbound). Its second part needs the deformation: AdjointTermKernel, then FinishAdjointPlan().
 */
void SortAdjointPoints(AdjointPlan& plan, const int* cells, std::int64_t count, cudaStream_t stream);

/// The plan's last part: the Chunks x Terms terms, whose control points AdjointTermKernel (or the tetrahedra's
/// term kernel) wrote into Keys (and their indices into Values, both reserved for them), sorted by control
/// point; then the partials, sums and gradient (`realBytes` a value) allocated.
void FinishAdjointPlan(
  AdjointPlan& plan, std::int64_t points, std::int64_t controlPoints, std::size_t realBytes, cudaStream_t stream);

/**
 * Makes `plan` for a binding (`cells`, one per point of `count`) whose chunks' supports have `counts` control
 * points along each axis: SortAdjointPoints(), then writeTerms(terms) (the lattice's term kernel, writing Keys
 * and Values, launched where there are terms), then FinishAdjointPlan(). The same steps for grids and tetrahedra.
 */
template <typename WriteTerms>
void MakeAdjointPlan(AdjointPlan& plan, const int counts[3], const int* cells, std::int64_t count,
  std::int64_t controlPoints, std::size_t realBytes, cudaStream_t stream, WriteTerms&& writeTerms)
{
  for (int a = 0; a < 3; ++a)
  {
    plan.Counts[a] = counts[a];
  }
  plan.Terms = counts[0] * counts[1] * counts[2];
  plan.ChunkPoints = ffd::AdjointChunkPoints(count, plan.Terms);
  SortAdjointPoints(plan, cells, count, stream);
  const std::int64_t terms = plan.Chunks * plan.Terms;
  plan.Keys.Reserve(std::size_t(terms) * sizeof(int), "allocating the adjoint's plan");
  plan.Values.Reserve(std::size_t(terms) * sizeof(int), "allocating the adjoint's plan");
  if (terms > 0)
  {
    writeTerms(terms);
    Check(cudaGetLastError(), "launching the adjoint's plan");
  }
  FinishAdjointPlan(plan, count, controlPoints, realBytes, stream);
}

/**
 * An adjoint's update once its plan is made, for a grid or a tetrahedral lattice alike: the gradient (3 doubles a
 * point) uploaded in the points' precision Real, sumChunks() (the lattice's chunk kernel, into Partials), the
 * partials gathered into Sums in the plan's order, the kernels timed from `start` to `stop` into `milliseconds`,
 * and the sums (3 doubles per control point) downloaded into `sums`. Returns the bytes downloaded.
 */
template <typename Real, typename SumChunks>
std::size_t RunAdjointUpdate(AdjointPlan& plan, const double* gradient, std::int64_t points, std::int64_t controlPoints,
  cudaStream_t stream, cudaEvent_t start, cudaEvent_t stop, float& milliseconds, double* sums, SumChunks&& sumChunks);

/// The steps of RunAdjointUpdate() that do not depend on the precision: the gather, the timing, the download.
std::size_t GatherAndDownloadAdjoint(AdjointPlan& plan, std::int64_t controlPoints, cudaStream_t stream,
  cudaEvent_t start, cudaEvent_t stop, float& milliseconds, double* sums);

template <typename Real, typename SumChunks>
std::size_t RunAdjointUpdate(AdjointPlan& plan, const double* gradient, std::int64_t points, std::int64_t controlPoints,
  cudaStream_t stream, cudaEvent_t start, cudaEvent_t stop, float& milliseconds, double* sums, SumChunks&& sumChunks)
{
  const std::vector<Real> g(gradient, gradient + 3 * points);
  Check(cudaMemcpyAsync(plan.Gradient.Data, g.data(), g.size() * sizeof(Real), cudaMemcpyHostToDevice, stream),
    "uploading the gradient");
  Check(cudaEventRecord(start, stream), "recording an event");
  if (plan.Chunks > 0)
  {
    sumChunks();
    Check(cudaGetLastError(), "launching the adjoint");
  }
  return GatherAndDownloadAdjoint(plan, controlPoints, stream, start, stop, milliseconds, sums);
}

/// Keys[e] = the control point of term e = chunk K + k (k = i + c0 (j + c1 l) of the support, K = c0 c1 c2),
/// Values[e] = e: from the weights of the chunk's first point (their First is the cell's).
template <typename Deformation, typename Real, int MaxCount>
__global__ void AdjointTermKernel(const Real* __restrict__ points, const int* __restrict__ order,
  const std::int64_t* __restrict__ chunkStart, const int* __restrict__ chunkCell, std::int64_t terms, int c0, int c1,
  int c2, Deformation deformation, int* __restrict__ keys, int* __restrict__ values)
{
  const std::int64_t e = blockIdx.x * std::int64_t(blockDim.x) + threadIdx.x;
  if (e >= terms)
  {
    return;
  }
  const int perChunk = c0 * c1 * c2, k = int(e % perChunk);
  const std::int64_t chunk = e / perChunk;
  const int cell = chunkCell[chunk];
  ffd::AxisWeights<MaxCount, Real> axes[3];
  deformation.WeightsAt(ffd::Vec3<Real>::From(points + 3 * std::int64_t(order[chunkStart[chunk]])), cell, axes);
  keys[e] = deformation.ControlPointOf(cell, axes, k % c0, (k / c0) % c1, k / (c0 * c1));
  values[e] = int(e);
}

/**
 * How AdjointChunkKernel shares a chunk's terms (i, j, l), K = c0 c1 c2 of them, among blocks and threads: the
 * pairs (j, l), numbered jl = j + c1 l, go by `Columns` consecutive ones to a block (all c1 c2 of a local basis's
 * in one; blockIdx.y numbers them), a term a thread, `Slots` = c0 Columns of them; where those are fewer than the
 * threads, `Groups` threads share a term, each summing every Groups-th point of a tile. A tile is `Tile` points
 * (one a thread, fewer where their products would pass 40 KiB of shared memory). All are set by the basis's
 * counts and the precision alone, and so is the order of the sums.
 */
struct AdjointLayout
{
  int C[3], Columns, Slots, Groups, Tile, WsgStride, WtuStride;

  AdjointLayout(const int counts[3], std::size_t realBytes)
    : C{ counts[0], counts[1], counts[2] }
  {
    const int columns = AdjointThreads / counts[0], pairs = counts[1] * counts[2];
    this->Columns = columns < 1 ? 1 : (columns > pairs ? pairs : columns);
    this->Slots = counts[0] * this->Columns;
    this->Groups = this->Slots >= AdjointThreads ? 1 : AdjointThreads / this->Slots;
    // Odd strides: the threads of a warp write their points' products to distinct banks.
    this->WsgStride = 3 * counts[0] | 1;
    this->WtuStride = this->Columns | 1;
    const std::size_t fit = (std::size_t(40) << 10) / (std::size_t(this->WsgStride + this->WtuStride) * realBytes);
    this->Tile = int(fit < 1 ? 1 : (fit > std::size_t(AdjointThreads) ? std::size_t(AdjointThreads) : fit));
  }
  int ColumnBlocks() const { return (this->C[1] * this->C[2] + this->Columns - 1) / this->Columns; }
  std::size_t SharedBytes(std::size_t realBytes) const
  {
    return std::size_t(this->Tile) * std::size_t(this->WsgStride + this->WtuStride) * realBytes;
  }
};

/// A point's products for AdjointChunkKernel: wsg[3 i + c] = W0[i] g[c], wtu[m] = W1[j] W2[l] for the block's
/// pairs jl = jl0 + m. Unrolled for the local bases (every index of the weights a constant: they stay in
/// registers).
template <int MaxCount, typename Real>
__device__ __forceinline__ void StoreTermProducts(const ffd::AxisWeights<MaxCount, Real>* axes, const Real g[3],
  const AdjointLayout& layout, int jl0, Real* wsg, Real* wtu)
{
  const int c0 = layout.C[0], c1 = layout.C[1], c2 = layout.C[2];
  if constexpr (MaxCount <= 4)
  {
    FFD_UNROLL
    for (int n = 0; n < MaxCount; ++n)
    {
      if (n < c0)
      {
        wsg[3 * n] = axes[0].W[n] * g[0];
        wsg[3 * n + 1] = axes[0].W[n] * g[1];
        wsg[3 * n + 2] = axes[0].W[n] * g[2];
      }
    }
    FFD_UNROLL
    for (int l = 0; l < MaxCount; ++l)
    {
      FFD_UNROLL
      for (int j = 0; j < MaxCount; ++j)
      {
        const int m = j + c1 * l - jl0;
        if (j < c1 && l < c2 && m >= 0 && m < layout.Columns)
        {
          wtu[m] = axes[1].W[j] * axes[2].W[l];
        }
      }
    }
  }
  else
  {
    for (int n = 0; n < c0; ++n)
    {
      wsg[3 * n] = axes[0].W[n] * g[0];
      wsg[3 * n + 1] = axes[0].W[n] * g[1];
      wsg[3 * n + 2] = axes[0].W[n] * g[2];
    }
    for (int m = 0; m < layout.Columns && jl0 + m < c1 * c2; ++m)
    {
      wtu[m] = axes[1].W[(jl0 + m) % c1] * axes[2].W[(jl0 + m) / c1];
    }
  }
}

/**
 * Partials[3 (chunk K + k) + c] = sum over the chunk's points p of w_k(p) g_p[c], the sum in float64: a block per
 * chunk (blockIdx.x) and block of columns (blockIdx.y), threads as AdjointLayout says. For a tile of points, a
 * thread a point computes its weights (WeightsAt(), as the evaluation's) and the products W0[i] g[c] and
 * W1[j] W2[l] into shared memory, so that a term costs its thread four loads and three multiply-adds a point:
 * w_k g = (W1[j] W2[l]) (W0[i] g). A thread sums its group's points of a tile in the points' precision Real and
 * adds that to its float64 sum; the groups' sums are added in group order.
 */
template <typename Deformation, typename Real, int MaxCount>
__global__ void __launch_bounds__(AdjointThreads) AdjointChunkKernel(const Real* __restrict__ points,
  const int* __restrict__ order, const std::int64_t* __restrict__ chunkStart, const int* __restrict__ chunkCell,
  const Real* __restrict__ gradient, AdjointLayout layout, Deformation deformation, double* __restrict__ partials)
{
  extern __shared__ double shared[];
  Real* wsg = reinterpret_cast<Real*>(shared);
  Real* wtu = wsg + layout.WsgStride * layout.Tile;
  __shared__ double groupSums[AdjointThreads][3];
  const std::int64_t chunk = blockIdx.x;
  const int cell = chunkCell[chunk];
  const std::int64_t begin = chunkStart[chunk], end = chunkStart[chunk + 1];
  const int c0 = layout.C[0], jl0 = blockIdx.y * layout.Columns;
  const int slot = threadIdx.x % layout.Slots, group = threadIdx.x / layout.Slots;
  const int i = slot % c0, m = slot / c0;
  const bool active = group < layout.Groups && jl0 + m < layout.C[1] * layout.C[2];
  double sum[3] = { 0.0, 0.0, 0.0 };
  for (std::int64_t first = begin; first < end; first += layout.Tile)
  {
    const int inTile = int(end - first < layout.Tile ? end - first : layout.Tile);
    if (threadIdx.x < inTile)
    {
      const std::int64_t p = order[first + threadIdx.x];
      ffd::AxisWeights<MaxCount, Real> axes[3];
      deformation.WeightsAt(ffd::Vec3<Real>::From(points + 3 * p), cell, axes);
      const Real g[3] = { gradient[3 * p], gradient[3 * p + 1], gradient[3 * p + 2] };
      StoreTermProducts(
        axes, g, layout, jl0, wsg + threadIdx.x * layout.WsgStride, wtu + threadIdx.x * layout.WtuStride);
    }
    __syncthreads();
    if (active)
    {
      Real partial[3] = { Real(0), Real(0), Real(0) };
      for (int p = group; p < inTile; p += layout.Groups)
      {
        const Real w = wtu[p * layout.WtuStride + m];
        const Real* a = wsg + p * layout.WsgStride + 3 * i;
        partial[0] += w * a[0];
        partial[1] += w * a[1];
        partial[2] += w * a[2];
      }
      sum[0] += double(partial[0]);
      sum[1] += double(partial[1]);
      sum[2] += double(partial[2]);
    }
    __syncthreads();
  }
  for (int c = 0; c < 3; ++c)
  {
    groupSums[threadIdx.x][c] = sum[c];
  }
  __syncthreads();
  if (active && group == 0)
  {
    for (int other = 1; other < layout.Groups; ++other)
    {
      for (int c = 0; c < 3; ++c)
      {
        sum[c] += groupSums[other * layout.Slots + slot][c];
      }
    }
    double* out = partials + 3 * (chunk * (c0 * layout.C[1] * layout.C[2]) + i + c0 * (jl0 + m));
    out[0] = sum[0];
    out[1] = sum[1];
    out[2] = sum[2];
  }
}

} // namespace detail
} // namespace cuda
} // namespace ffd

#endif
