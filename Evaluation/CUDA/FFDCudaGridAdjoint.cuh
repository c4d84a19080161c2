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

#include "FFDCudaDevice.cuh"
#include "FFDGridDeformation.h"

#include <cstdint>

namespace ffd
{
namespace cuda
{
namespace detail
{
constexpr int AdjointThreads = 128; // a chunk's block
constexpr int AdjointTile = 32;     // points whose weights a block holds in shared memory at once

/// The plan of the adjoint of one binding (see the file's description), on the device.
struct AdjointPlan
{
  std::uint64_t ForBinding = 0; // Counters::Bindings when made; 0: none
  std::int64_t ChunkPoints = 0; // AdjointChunkPoints()
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

/// Points per chunk: 256, more where the partials (chunks x K terms) would pass 2^22 terms (the global basis).
inline std::int64_t AdjointChunkPoints(std::int64_t points, int terms)
{
  const std::int64_t byTerms = (points * terms + (std::int64_t(1) << 22) - 1) >> 22;
  return byTerms > 256 ? byTerms : 256;
}

/**
 * The plan's first part, up to the chunks (Order, ChunkStart, ChunkCell, Chunks): `cells` are the binding's,
 * one per point (-1: unbound). Its second part needs the deformation: AdjointTermKernel, then FinishAdjointPlan().
 */
void SortAdjointPoints(AdjointPlan& plan, const int* cells, std::int64_t count, cudaStream_t stream);

/// The plan's last part: the Chunks x Terms terms, whose control points AdjointTermKernel wrote into Keys (and
/// their indices into Values, both reserved for them), sorted by control point.
void FinishAdjointPlan(AdjointPlan& plan, std::int64_t controlPoints, cudaStream_t stream);

/// Gathers the partials into Sums (3 per control point) in the plan's order.
void GatherAdjoint(AdjointPlan& plan, std::int64_t controlPoints, cudaStream_t stream);

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
 * Partials[3 (chunk K + k) + c] = sum over the chunk's points p of w_k(p) g_p[c], in float64. A block per chunk
 * (blockIdx.x) and per slice of `slots` terms (blockIdx.y; more than one for the global basis only). Where the
 * terms are fewer than the threads, `groups` threads share a term: group g sums the tile's points g, g + groups,
 * ..., and the groups' sums are added in group order: an order set by K alone. Each tile's weights are computed
 * once (WeightsAt(), as the evaluation's) into shared memory; a term's weight is W0[i] W1[j] W2[l], the product
 * in ForEachWeight()'s order.
 */
template <typename Deformation, typename Real, int MaxCount>
__global__ void __launch_bounds__(AdjointThreads)
  AdjointChunkKernel(const Real* __restrict__ points, const int* __restrict__ order,
    const std::int64_t* __restrict__ chunkStart, const int* __restrict__ chunkCell, const Real* __restrict__ gradient,
    int c0, int c1, int c2, int slots, int groups, Deformation deformation, double* __restrict__ partials)
{
  __shared__ Real weights[3][AdjointTile][MaxCount];
  __shared__ Real g[AdjointTile][3];
  __shared__ double sums[AdjointThreads][3];
  const std::int64_t chunk = blockIdx.x;
  const int cell = chunkCell[chunk];
  const std::int64_t begin = chunkStart[chunk], end = chunkStart[chunk + 1];
  const int terms = c0 * c1 * c2, slot = threadIdx.x % slots, group = threadIdx.x / slots;
  const int k = blockIdx.y * slots + slot;
  const bool active = group < groups && k < terms;
  const int i = k % c0, j = (k / c0) % c1, l = k / (c0 * c1);
  double sum[3] = { 0.0, 0.0, 0.0 };
  for (std::int64_t tile = begin; tile < end; tile += AdjointTile)
  {
    const int inTile = int(end - tile < AdjointTile ? end - tile : AdjointTile);
    if (threadIdx.x < inTile)
    {
      const std::int64_t p = order[tile + threadIdx.x];
      ffd::AxisWeights<MaxCount, Real> axes[3];
      deformation.WeightsAt(ffd::Vec3<Real>::From(points + 3 * p), cell, axes);
      for (int a = 0; a < 3; ++a)
      {
        for (int n = 0; n < axes[a].Count; ++n)
        {
          weights[a][threadIdx.x][n] = axes[a].W[n];
        }
        g[threadIdx.x][a] = gradient[3 * p + a];
      }
    }
    __syncthreads();
    if (active)
    {
      for (int p = group; p < inTile; p += groups)
      {
        const double w = double(weights[0][p][i] * weights[1][p][j] * weights[2][p][l]);
        sum[0] += w * double(g[p][0]);
        sum[1] += w * double(g[p][1]);
        sum[2] += w * double(g[p][2]);
      }
    }
    __syncthreads();
  }
  for (int c = 0; c < 3; ++c)
  {
    sums[threadIdx.x][c] = sum[c];
  }
  __syncthreads();
  if (active && group == 0)
  {
    for (int other = 1; other < groups; ++other)
    {
      for (int c = 0; c < 3; ++c)
      {
        sum[c] += sums[other * slots + slot][c];
      }
    }
    double* out = partials + 3 * (chunk * terms + k);
    out[0] = sum[0];
    out[1] = sum[1];
    out[2] = sum[2];
  }
}

} // namespace detail
} // namespace cuda
} // namespace ffd

#endif
