// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDCudaCellTableKernels.cuh
 * @brief The local bases' cell tables on the device, for FFDCudaGridDeformer.cu only: the table built at each
 * update (the CPU's ffd::detail::FillCellEntry(), a thread per cell and component) and the deformation that
 * DeformPointsKernel evaluates from it (ffd::PowerForm(), four points of a cell together).
 * GridDeformer::Impl::LaunchFromCellTable() runs them where GridDeformer::WorthCellTable() says so.
 */
#ifndef FFDCudaCellTableKernels_cuh
#define FFDCudaCellTableKernels_cuh

#include "FFDCellTable.h"
#include "FFDCudaDevice.cuh"

namespace ffd
{
namespace cuda
{
namespace detail
{
// A grid's deformation from its cell table, for DeformPointsKernel: four points of one cell in power form together,
// each coefficient read once for them (GridDeformation::Deform<4>()).
template <typename GridDeformationT>
struct CellTableDeformation
{
  using Real = typename GridDeformationT::Value;
  GridDeformationT Grid;

  __device__ __forceinline__ ffd::Vec3<Real> Deform(const ffd::Vec3<Real>& x, int cell) const
  {
    return this->Grid.Deform(x, cell);
  }

  __device__ __forceinline__ void DeformGroup(ffd::Vec3<Real>* x, int cell) const
  {
    ffd::Vec3<Real> y[4];
    this->Grid.template Deform<4>(x, cell, y);
    FFD_UNROLL
    for (int g = 0; g < 4; ++g)
    {
      x[g] = y[g];
    }
  }
};

// The cell table of a local basis (ffd::FillCellTable()), the CPU's function: a block per TableTileCells
// consecutive cells, a thread per cell and component, its entries staged in shared memory and written out as one
// contiguous span (a thread's own writes, 3 numbers of an entry in every 800 bytes, kept L2 busy).
template <typename Real>
constexpr int TableTileCells = 128 / sizeof(Real); // 25.6 KB of tile for a cubic basis in either precision

template <ffd::GridBasis Basis, typename Real>
__global__ void __launch_bounds__(3 * TableTileCells<Real>) FillCellTableKernel(const Real* displacements, int3 voxels,
  int3 dims, const int* cellVoxels, const int* cellSupports, int cells, Real* table)
{
  constexpr int stride = ffd::CellTableStride(ffd::CellDegree(Basis));
  __shared__ Real tile[TableTileCells<Real> * stride];
  const int firstCell = blockIdx.x * TableTileCells<Real>;
  const int local = threadIdx.x / 3, component = threadIdx.x % 3;
  const int cell = firstCell + local;
  if (cell < cells)
  {
    const int v[3] = { voxels.x, voxels.y, voxels.z }, d[3] = { dims.x, dims.y, dims.z };
    ffd::detail::FillCellEntry<Basis>(
      displacements, v, d, cellVoxels, cellSupports, cell, component, component + 1, tile + local * stride);
  }
  __syncthreads();
  const int count = min(TableTileCells<Real>, cells - firstCell) * stride;
  Real* out = table + std::size_t(firstCell) * stride;
  for (int i = threadIdx.x; i < count; i += blockDim.x)
  {
    out[i] = tile[i];
  }
}

} // namespace detail
} // namespace cuda
} // namespace ffd

#endif
