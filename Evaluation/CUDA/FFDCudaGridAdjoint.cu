// SPDX-License-Identifier: BSD-3-Clause
#include "FFDCudaGridAdjoint.cuh"

#include <cub/device/device_radix_sort.cuh>
#include <cub/device/device_scan.cuh>

namespace ffd
{
namespace cuda
{
namespace detail
{
namespace
{
// The first position of `sorted[0 .. n)` (ascending) whose key is >= key.
__device__ __forceinline__ std::int64_t LowerBound(const int* sorted, std::int64_t n, int key)
{
  std::int64_t lo = 0, hi = n;
  while (lo < hi)
  {
    const std::int64_t mid = (lo + hi) / 2;
    if (sorted[mid] < key)
    {
      lo = mid + 1;
    }
    else
    {
      hi = mid;
    }
  }
  return lo;
}

__global__ void IotaKernel(int* values, std::int64_t n)
{
  const std::int64_t i = blockIdx.x * std::int64_t(blockDim.x) + threadIdx.x;
  if (i < n)
  {
    values[i] = int(i);
  }
}

// flags[q] = 1 where a chunk starts at sorted position q: a bound point whose rank in its cell is a multiple of
// chunkPoints.
__global__ void ChunkFlagKernel(const int* sortedCells, std::int64_t n, std::int64_t chunkPoints, int* flags)
{
  const std::int64_t q = blockIdx.x * std::int64_t(blockDim.x) + threadIdx.x;
  if (q >= n)
  {
    return;
  }
  const int cell = sortedCells[q];
  flags[q] = cell >= 0 && (q - LowerBound(sortedCells, q, cell)) % chunkPoints == 0 ? 1 : 0;
}

// ChunkStart[chunk] and ChunkCell[chunk] of each chunk's first position (`index`: the flags' exclusive sum).
__global__ void ChunkStartKernel(
  const int* sortedCells, const int* flags, const int* index, std::int64_t n, std::int64_t* chunkStart, int* chunkCell)
{
  const std::int64_t q = blockIdx.x * std::int64_t(blockDim.x) + threadIdx.x;
  if (q < n && flags[q])
  {
    chunkStart[index[q]] = q;
    chunkCell[index[q]] = sortedCells[q];
  }
}

// TermStart[cp] for cp in [0, controlPoints]: the first position of the sorted terms' control points >= cp.
__global__ void TermStartKernel(const int* sortedKeys, std::int64_t terms, std::int64_t controlPoints, int* termStart)
{
  const std::int64_t cp = blockIdx.x * std::int64_t(blockDim.x) + threadIdx.x;
  if (cp <= controlPoints)
  {
    termStart[cp] = int(LowerBound(sortedKeys, terms, int(cp)));
  }
}

__global__ void GatherKernel(
  const int* termOrder, const int* termStart, const double* partials, std::int64_t controlPoints, double* sums)
{
  const std::int64_t cp = blockIdx.x * std::int64_t(blockDim.x) + threadIdx.x;
  if (cp >= controlPoints)
  {
    return;
  }
  double sum[3] = { 0.0, 0.0, 0.0 };
  for (int q = termStart[cp]; q < termStart[cp + 1]; ++q)
  {
    const double* partial = partials + 3 * std::int64_t(termOrder[q]);
    sum[0] += partial[0];
    sum[1] += partial[1];
    sum[2] += partial[2];
  }
  sums[3 * cp] = sum[0];
  sums[3 * cp + 1] = sum[1];
  sums[3 * cp + 2] = sum[2];
}

// Sorts n (key, value) pairs of plan.Keys / plan.Values, stably by key, into `keysOut` and `valuesOut`.
void SortPairs(AdjointPlan& plan, std::int64_t n, Buffer& keysOut, Buffer& valuesOut, cudaStream_t stream)
{
  keysOut.Reserve(std::size_t(n) * sizeof(int), "allocating the adjoint's plan");
  valuesOut.Reserve(std::size_t(n) * sizeof(int), "allocating the adjoint's plan");
  std::size_t bytes = 0;
  Check(cub::DeviceRadixSort::SortPairs(nullptr, bytes, plan.Keys.As<int>(), keysOut.As<int>(), plan.Values.As<int>(),
          valuesOut.As<int>(), int(n), 0, 32, stream),
    "sizing the adjoint's sort");
  plan.Scratch.Reserve(bytes, "allocating the adjoint's sort");
  Check(cub::DeviceRadixSort::SortPairs(plan.Scratch.Data, bytes, plan.Keys.As<int>(), keysOut.As<int>(),
          plan.Values.As<int>(), valuesOut.As<int>(), int(n), 0, 32, stream),
    "sorting for the adjoint");
}
} // namespace

//------------------------------------------------------------------------------------------------------------
void SortAdjointPoints(AdjointPlan& plan, const int* cells, std::int64_t count, cudaStream_t stream)
{
  plan.Keys.Reserve(std::size_t(count) * sizeof(int), "allocating the adjoint's plan");
  plan.Values.Reserve(std::size_t(count) * sizeof(int), "allocating the adjoint's plan");
  Check(cudaMemcpyAsync(plan.Keys.Data, cells, std::size_t(count) * sizeof(int), cudaMemcpyDeviceToDevice, stream),
    "copying the binding");
  IotaKernel<<<BlocksFor(count), ThreadsPerBlock, 0, stream>>>(plan.Values.As<int>(), count);
  Buffer sortedCells;
  SortPairs(plan, count, sortedCells, plan.Order, stream);
  // Chunks: flags, their exclusive sum (each chunk's index), then each chunk's start and cell.
  plan.Flags.Reserve(std::size_t(count) * sizeof(int), "allocating the adjoint's plan");
  ChunkFlagKernel<<<BlocksFor(count), ThreadsPerBlock, 0, stream>>>(
    sortedCells.As<int>(), count, plan.ChunkPoints, plan.Flags.As<int>());
  std::size_t bytes = 0;
  Check(cub::DeviceScan::ExclusiveSum(nullptr, bytes, plan.Flags.As<int>(), plan.Keys.As<int>(), int(count), stream),
    "sizing the adjoint's scan");
  plan.Scratch.Reserve(bytes, "allocating the adjoint's scan");
  Check(cub::DeviceScan::ExclusiveSum(
          plan.Scratch.Data, bytes, plan.Flags.As<int>(), plan.Keys.As<int>(), int(count), stream),
    "numbering the adjoint's chunks");
  int last[2] = { 0, 0 };
  Check(cudaMemcpyAsync(&last[0], plan.Keys.As<int>() + count - 1, sizeof(int), cudaMemcpyDeviceToHost, stream),
    "counting the adjoint's chunks");
  Check(cudaMemcpyAsync(&last[1], plan.Flags.As<int>() + count - 1, sizeof(int), cudaMemcpyDeviceToHost, stream),
    "counting the adjoint's chunks");
  Check(cudaStreamSynchronize(stream), "counting the adjoint's chunks");
  plan.Chunks = std::int64_t(last[0]) + last[1];
  plan.ChunkStart.Reserve(std::size_t(plan.Chunks + 1) * sizeof(std::int64_t), "allocating the adjoint's plan");
  plan.ChunkCell.Reserve(std::size_t(plan.Chunks + 1) * sizeof(int), "allocating the adjoint's plan");
  ChunkStartKernel<<<BlocksFor(count), ThreadsPerBlock, 0, stream>>>(sortedCells.As<int>(), plan.Flags.As<int>(),
    plan.Keys.As<int>(), count, plan.ChunkStart.As<std::int64_t>(), plan.ChunkCell.As<int>());
  const std::int64_t end = count;
  Check(cudaMemcpyAsync(
          plan.ChunkStart.As<std::int64_t>() + plan.Chunks, &end, sizeof(end), cudaMemcpyHostToDevice, stream),
    "ending the adjoint's chunks");
  Check(cudaGetLastError(), "launching the adjoint's plan");
  Check(cudaStreamSynchronize(stream), "planning the adjoint");
}

void FinishAdjointPlan(
  AdjointPlan& plan, std::int64_t points, std::int64_t controlPoints, std::size_t realBytes, cudaStream_t stream)
{
  const std::int64_t terms = plan.Chunks * plan.Terms;
  Buffer sortedKeys;
  SortPairs(plan, terms, sortedKeys, plan.TermOrder, stream);
  plan.TermStart.Reserve(std::size_t(controlPoints + 1) * sizeof(int), "allocating the adjoint's plan");
  TermStartKernel<<<BlocksFor(controlPoints + 1), ThreadsPerBlock, 0, stream>>>(
    sortedKeys.As<int>(), terms, controlPoints, plan.TermStart.As<int>());
  Check(cudaGetLastError(), "launching the adjoint's plan");
  Check(cudaStreamSynchronize(stream), "planning the adjoint");
  // What the plan no longer needs: the sort's keys, values, flags and scratch.
  plan.Keys.Free();
  plan.Values.Free();
  plan.Flags.Free();
  plan.Scratch.Free();
  plan.Partials.Reserve(std::size_t(terms) * 3 * sizeof(double), "allocating the adjoint's partials");
  plan.Sums.Reserve(std::size_t(controlPoints) * 3 * sizeof(double), "allocating the sensitivities");
  plan.Gradient.Reserve(std::size_t(points) * 3 * realBytes, "allocating the gradient");
}

std::size_t GatherAndDownloadAdjoint(AdjointPlan& plan, std::int64_t controlPoints, cudaStream_t stream,
  cudaEvent_t start, cudaEvent_t stop, float& milliseconds, double* sums)
{
  GatherKernel<<<BlocksFor(controlPoints), ThreadsPerBlock, 0, stream>>>(plan.TermOrder.As<int>(),
    plan.TermStart.As<int>(), plan.Partials.As<double>(), controlPoints, plan.Sums.As<double>());
  Check(cudaGetLastError(), "launching the adjoint's gather");
  Check(cudaEventRecord(stop, stream), "recording an event");
  Check(cudaEventSynchronize(stop), "computing the adjoint");
  Check(cudaEventElapsedTime(&milliseconds, start, stop), "timing the adjoint");
  const std::size_t bytes = std::size_t(controlPoints) * 3 * sizeof(double);
  Check(cudaMemcpy(sums, plan.Sums.Data, bytes, cudaMemcpyDeviceToHost), "downloading the sensitivities");
  return bytes;
}

} // namespace detail
} // namespace cuda
} // namespace ffd
