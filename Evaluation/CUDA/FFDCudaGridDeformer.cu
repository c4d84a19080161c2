// SPDX-License-Identifier: BSD-3-Clause
#include "FFDCudaGridDeformer.h"

#include "FFDCudaDevice.cuh"
#include "FFDCudaGridAdjoint.cuh"
#include "FFDGridDeformation.h"

#include <algorithm>
#include <memory>
#include <type_traits>
#include <vector>

namespace ffd
{
// In float32 without the Jacobian the lattice lives on the device as float4 (x, y, z, unused): SumTensorProduct
// then reads a control point with one 16-byte load instead of three 4-byte ones.
template <>
struct LatticeValues<float4>
{
  template <typename Real>
  __device__ __forceinline__ static Vec3<Real> Get(const float4* values, int index)
  {
    const float4 v = __ldg(values + index);
    return { Real(v.x), Real(v.y), Real(v.z) };
  }
};

namespace cuda
{
namespace
{
using detail::BlocksFor;
using detail::Check;
using detail::CudaError;
using detail::ThreadsPerBlock;

// A grid's deformation on a float4 lattice whose cells are split by ffd::CellSplit, for DeformPointsKernel.
template <typename GridDeformationT>
struct SplitCellDeformation
{
  GridDeformationT Grid;
  ffd::CellSplit Split;

  __device__ __forceinline__ ffd::Vec3<float> Deform(const ffd::Vec3<float>& x, int cell) const
  {
    int c[3];
    this->Grid.CellIndices(this->Split, cell, c);
    return this->Grid.DeformInCell(x, cell, c);
  }

  /// Four points of one cell, in place (DeformPointsKernel's Grouped path).
  __device__ __forceinline__ void DeformGroup(ffd::Vec3<float>* x, int cell) const
  {
    int c[3];
    this->Grid.CellIndices(this->Split, cell, c);
    ffd::Vec3<float> y[4];
    this->Grid.template DeformInCell<4>(x, cell, c, y);
    FFD_UNROLL
    for (int g = 0; g < 4; ++g)
    {
      x[g] = y[g];
    }
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
  cells[i] =
    ffd::BindToGrid(frame, basis, voxels, ffd::Vec3<double>{ double(p[0]), double(p[1]), double(p[2]) }, clampOutside);
}

// The global basis without Jacobian on small lattices (under 400 control points; BernsteinTensorKernel takes the
// larger ones). It computes ffd::GridDeformation::Deform's function, x + sum_ijk B_i(s) B_j(t) B_k(u) D_ijk at
// the clamped parameters of a bound point, with the same weights (ffd::BernsteinBasisBounded), but not through
// that function, for speed: the lattice sits in shared memory as float4 (one 16-byte broadcast load per control
// point), each thread evaluates four points so that each lattice value loaded serves all four, and the weights
// of the first axis stay in registers (MaxCount bounds the control points per axis at compile time).
// CUDA.CudaGridDeformer.GlobalBasisInFloatMatchesDouble and MatchesCpuForEveryBasis compare it with the CPU.
template <int MaxCount>
__global__ void __launch_bounds__(ThreadsPerBlock) BernsteinKernel(const float* __restrict__ points,
  const int* __restrict__ cells, std::int64_t count, ffd::Frame<float> frame, int dimS, int dimT, int dimU,
  const float4* __restrict__ displacements, float* __restrict__ outPoints)
{
  extern __shared__ float4 lattice[];
  const int total = dimS * dimT * dimU;
  for (int v = threadIdx.x; v < total; v += ThreadsPerBlock)
  {
    lattice[v] = displacements[v];
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

//------------------------------------------------------------------------------------------------------------
// The global basis on the tensor cores. It computes ffd::GridDeformation::Deform's function with the same weights
// (ffd::BernsteinBasisBounded) but not through that function, for speed: the sum x + sum_ijk Bs_i Bt_j Bu_k D_ijk
// over the lattice's control points is, for a tile of points, the matrix product
//   P[p, (j, c)] = sum_{i, k} (Bs_i Bu_k)[p] D[(i, k), (j, c)]
// followed by out[p, c] = x[p, c] + sum_j Bt_j[p] P[p, (j, c)]. The product runs as mma.sync m16n8k8 in TF32 with
// error compensation (3xTF32): each operand is split into a TF32 part and the float32 rest, and
// hi*hi + hi*lo + lo*hi is accumulated in float32, which leaves an error of about 2^-20 of each product instead of
// TF32's 2^-11, so that the results stay within float32 rounding of float64. K runs over i (padded to 8 KS) for
// each k, N over (j, c) = 3 j + c (padded to 8 NT). CUDA.CudaGridDeformer.GlobalBasisInFloatMatchesDouble
// compares it with the CPU's float64 evaluation.
//
// The lattice is stored in shared memory as the mma's B fragments, hi and lo of both rows of a lane in one
// float4, so a lane loads them with one 16-byte load. Each warp takes tiles of 32 points (two m16 tiles sharing
// every B fragment) from a persistent grid: lanes compute the three axes' weights of the tile's points into a
// per-warp table, then the k loop builds A = Bs_i Bu_k (split by truncation: hi = the top 19 bits, lo = the exact
// rest; cvt.rna, emulated on sm_90, is slower) and issues 3 mma per (k-step, n-tile, m-tile); the epilogue
// weights the columns by Bt_j and sums the four lanes of each row.
constexpr int TensorWarps = 8;       // warps per block
constexpr int TensorTilePoints = 32; // points per warp tile: two m16 tiles
constexpr int TensorTableFloats = TensorTilePoints * 17 * 2 + 16 * TensorTilePoints + 4 * TensorTilePoints;

__device__ __forceinline__ unsigned ToTF32(float v)
{
  unsigned r;
  asm("cvt.rna.tf32.f32 %0, %1;" : "=r"(r) : "f"(v));
  return r;
}

// d += a b for one m16n8k8 TF32 tile (fragments as in the PTX ISA's mma.m16n8k8 .tf32 layout).
__device__ __forceinline__ void MmaTF32(float (&d)[4], const unsigned (&a)[4], unsigned b0, unsigned b1)
{
  asm volatile("mma.sync.aligned.m16n8k8.row.col.f32.tf32.tf32.f32 {%0,%1,%2,%3}, {%4,%5,%6,%7}, {%8,%9}, "
               "{%0,%1,%2,%3};"
               : "+f"(d[0]), "+f"(d[1]), "+f"(d[2]), "+f"(d[3])
               : "r"(a[0]), "r"(a[1]), "r"(a[2]), "r"(a[3]), "r"(b0), "r"(b1));
}

/// Shared memory of BernsteinTensorKernel<KS, NT> for dimU control points along the third axis.
std::size_t TensorSharedBytes(int ks, int nt, int dimU)
{
  return std::size_t(dimU) * ks * nt * 32 * sizeof(float4) +
    std::size_t(TensorWarps) * TensorTableFloats * sizeof(float);
}

// TF32 mma needs sm_80 or later: built for an older target the kernel is empty, and LaunchBernstein, which reads
// the binary's version, does not launch it.
template <int KS, int NT>
__global__ void __launch_bounds__(32 * TensorWarps, 2) BernsteinTensorKernel(const float* __restrict__ points,
  const int* __restrict__ cells, std::int64_t count, ffd::Frame<float> frame, int dimS, int dimT, int dimU,
  const float4* __restrict__ displacements, float* __restrict__ outPoints)
{
  static_assert(KS >= 1 && KS <= 2 && NT >= 1 && NT <= 6, "up to 16 control points along each axis");
#if !defined(__CUDA_ARCH__) || __CUDA_ARCH__ >= 800
  constexpr int TP = TensorTilePoints;
  extern __shared__ float4 smem[];
  // B fragments: for k, k-step ks, n-tile nt, lane (g = lane / 4, q = lane % 4): rows i = 8 ks + q and 8 ks + q + 4,
  // column n = 8 nt + g, i.e. D[i, j = n / 3, k][c = n % 3], as (hi, hi, lo, lo); zero outside the lattice.
  float4* fragments = smem;
  const int fragmentCount = dimU * KS * NT * 32;
  for (int f = threadIdx.x; f < fragmentCount; f += blockDim.x)
  {
    const int lane = f % 32;
    const int nt = (f / 32) % NT, ks = (f / (32 * NT)) % KS, k = f / (32 * NT * KS);
    const int n = 8 * nt + lane / 4, j = n / 3, c = n % 3;
    float v[2];
    for (int h = 0; h < 2; ++h)
    {
      const int i = 8 * ks + lane % 4 + 4 * h;
      const float4 d = i < dimS && j < dimT ? displacements[i + dimS * (j + dimT * k)] : make_float4(0, 0, 0, 0);
      v[h] = c == 0 ? d.x : (c == 1 ? d.y : d.z);
    }
    const unsigned h0 = ToTF32(v[0]), h1 = ToTF32(v[1]);
    const unsigned l0 = ToTF32(v[0] - __uint_as_float(h0)), l1 = ToTF32(v[1] - __uint_as_float(h1));
    fragments[f] = make_float4(__uint_as_float(h0), __uint_as_float(h1), __uint_as_float(l0), __uint_as_float(l1));
  }
  // Per warp: the tile's weights Bs [TP][17], Bt [TP][17], Bu [16][TP] (padded against bank conflicts) and points.
  const int warp = threadIdx.x / 32, lane = threadIdx.x % 32;
  float* ws = reinterpret_cast<float*>(smem + fragmentCount) + warp * TensorTableFloats;
  float* wt = ws + TP * 17;
  float* wu = wt + TP * 17;
  float* xs = wu + 16 * TP; // x, y, z, bound
  __syncthreads();

  const int g = lane / 4, q = lane % 4;
  const std::int64_t tiles = (count + TP - 1) / TP;
  for (std::int64_t tile = blockIdx.x * std::int64_t(TensorWarps) + warp; tile < tiles;
       tile += std::int64_t(gridDim.x) * TensorWarps)
  {
    const std::int64_t base = tile * TP;
    // Lane l computes the weights of point l along each axis in turn (the same function as the CPU's).
    {
      const std::int64_t i = base + lane;
      const bool inRange = i < count;
      const float* p = points + 3 * (inRange ? i : 0);
      const ffd::Vec3<float> x = { p[0], p[1], p[2] };
      const bool bound = inRange && cells[i] >= 0;
      const ffd::Vec3<float> stu = frame.ToParametric(x);
      for (int axis = 0; axis < 3; ++axis)
      {
        // Unbound points (kept in place) get finite weights, so that no NaN enters the tile's products.
        const float t = bound ? ffd::Clamp01(axis == 0 ? stu.x : (axis == 1 ? stu.y : stu.z)) : 0.0f;
        const int dim = axis == 0 ? dimS : (axis == 1 ? dimT : dimU);
        float b[16];
        ffd::BernsteinBasisBounded<16>(dim - 1, t, b);
        FFD_UNROLL
        for (int e = 0; e < 16; ++e)
        {
          const float w = e < dim ? b[e] : 0.0f;
          if (axis == 0)
          {
            ws[lane * 17 + e] = w;
          }
          else if (axis == 1)
          {
            wt[lane * 17 + e] = w;
          }
          else
          {
            wu[e * TP + lane] = w;
          }
        }
      }
      xs[4 * lane] = x.x;
      xs[4 * lane + 1] = x.y;
      xs[4 * lane + 2] = x.z;
      xs[4 * lane + 3] = bound ? 1.0f : 0.0f;
    }
    __syncwarp();
    // Bs of this lane's A rows (g, g + 8 of each m-tile) and columns (q, q + 4 of each k-step).
    float as[2][2][KS][2];
    FFD_UNROLL
    for (int mt = 0; mt < 2; ++mt)
    {
      FFD_UNROLL
      for (int r = 0; r < 2; ++r)
      {
        FFD_UNROLL
        for (int ks = 0; ks < KS; ++ks)
        {
          as[mt][r][ks][0] = ws[(16 * mt + g + 8 * r) * 17 + 8 * ks + q];
          as[mt][r][ks][1] = ws[(16 * mt + g + 8 * r) * 17 + 8 * ks + q + 4];
        }
      }
    }
    float acc[2][NT][4];
    FFD_UNROLL
    for (int mt = 0; mt < 2; ++mt)
    {
      FFD_UNROLL
      for (int nt = 0; nt < NT; ++nt)
      {
        acc[mt][nt][0] = acc[mt][nt][1] = acc[mt][nt][2] = acc[mt][nt][3] = 0.0f;
      }
    }
#pragma unroll 2
    for (int k = 0; k < dimU; ++k)
    {
      float bu[2][2];
      FFD_UNROLL
      for (int mt = 0; mt < 2; ++mt)
      {
        bu[mt][0] = wu[k * TP + 16 * mt + g];
        bu[mt][1] = wu[k * TP + 16 * mt + g + 8];
      }
      FFD_UNROLL
      for (int ks = 0; ks < KS; ++ks)
      {
        float4 b[NT];
        FFD_UNROLL
        for (int nt = 0; nt < NT; ++nt)
        {
          b[nt] = fragments[((k * KS + ks) * NT + nt) * 32 + lane];
        }
        unsigned ahi[2][4], alo[2][4];
        FFD_UNROLL
        for (int mt = 0; mt < 2; ++mt)
        {
          const float a[4] = { as[mt][0][ks][0] * bu[mt][0], as[mt][1][ks][0] * bu[mt][1], as[mt][0][ks][1] * bu[mt][0],
            as[mt][1][ks][1] * bu[mt][1] };
          FFD_UNROLL
          for (int e = 0; e < 4; ++e)
          {
            ahi[mt][e] = __float_as_uint(a[e]) & 0xffffe000u;
            alo[mt][e] = __float_as_uint(a[e] - __uint_as_float(ahi[mt][e]));
          }
        }
        FFD_UNROLL
        for (int nt = 0; nt < NT; ++nt)
        {
          const unsigned bh0 = __float_as_uint(b[nt].x), bh1 = __float_as_uint(b[nt].y);
          const unsigned bl0 = __float_as_uint(b[nt].z), bl1 = __float_as_uint(b[nt].w);
          FFD_UNROLL
          for (int mt = 0; mt < 2; ++mt)
          {
            MmaTF32(acc[mt][nt], alo[mt], bh0, bh1);
            MmaTF32(acc[mt][nt], ahi[mt], bl0, bl1);
            MmaTF32(acc[mt][nt], ahi[mt], bh0, bh1);
          }
        }
      }
    }
    // out[p, c] = x[p, c] + sum_j Bt_j[p] P[p, (j, c)]: this lane holds rows g, g + 8 (r = 0, 1) of each m-tile and
    // columns n = 8 nt + 2 q + e, whose sums over the four lanes of the row are the results.
    float sum[2][2][3];
    FFD_UNROLL
    for (int mt = 0; mt < 2; ++mt)
    {
      FFD_UNROLL
      for (int r = 0; r < 2; ++r)
      {
        sum[mt][r][0] = sum[mt][r][1] = sum[mt][r][2] = 0.0f;
        const float* bt = wt + (16 * mt + g + 8 * r) * 17;
        FFD_UNROLL
        for (int nt = 0; nt < NT; ++nt)
        {
          FFD_UNROLL
          for (int e = 0; e < 2; ++e)
          {
            const int n = 8 * nt + 2 * q + e, j = (n * 43) >> 7, c = n - 3 * j; // j = n / 3 for n < 128
            const float v = bt[j] * acc[mt][nt][2 * r + e];
            sum[mt][r][0] += c == 0 ? v : 0.0f;
            sum[mt][r][1] += c == 1 ? v : 0.0f;
            sum[mt][r][2] += c == 2 ? v : 0.0f;
          }
        }
        FFD_UNROLL
        for (int c = 0; c < 3; ++c)
        {
          sum[mt][r][c] += __shfl_xor_sync(0xffffffffu, sum[mt][r][c], 1);
          sum[mt][r][c] += __shfl_xor_sync(0xffffffffu, sum[mt][r][c], 2);
        }
      }
    }
    // Lane (g, q) writes point 16 mt + g + 8 r with 2 mt + r = q.
    FFD_UNROLL
    for (int mt = 0; mt < 2; ++mt)
    {
      FFD_UNROLL
      for (int r = 0; r < 2; ++r)
      {
        const int p = 16 * mt + g + 8 * r;
        const std::int64_t i = base + p;
        if (q == 2 * mt + r && i < count)
        {
          const bool bound = xs[4 * p + 3] != 0.0f;
          FFD_UNROLL
          for (int c = 0; c < 3; ++c)
          {
            outPoints[3 * i + c] = bound ? xs[4 * p + c] + sum[mt][r][c] : xs[4 * p + c];
          }
        }
      }
    }
    __syncwarp(); // the tables are rewritten by the next tile
  }
#endif
}
} // namespace

//------------------------------------------------------------------------------------------------------------
struct GridDeformer::Impl : ResidentPoints::State
{
  ffd::GridBasis Basis = ffd::GridBasis::Bernstein;
  int Divisions[3] = { 0, 0, 0 };
  double Frame[12] = {};
  // A sparse lattice's cells (BindSparse()); SparseControlPoints is 0 for a dense lattice.
  Buffer CellVoxels, CellSupports;
  std::int64_t SparseControlPoints = 0;
  std::unique_ptr<detail::AdjointPlan> Plan; // the adjoint's, made for the binding it names

  void Release() override
  {
    this->Plan.reset();
    this->State::Release();
  }

  // Calls f(storage) with the ffd::GridStorage of the bound lattice (a std::integral_constant): the kernels are
  // instantiated for dense and sparse lattices apart. The global basis is always dense.
  template <int StaticBasis, typename F>
  void WithStorage(F&& f) const
  {
    using Dense = std::integral_constant<ffd::GridStorage, ffd::GridStorage::Dense>;
    using Sparse = std::integral_constant<ffd::GridStorage, ffd::GridStorage::Sparse>;
    if constexpr (StaticBasis == int(ffd::GridBasis::Bernstein))
    {
      f(Dense());
    }
    else if (this->SparseControlPoints > 0)
    {
      f(Sparse());
    }
    else
    {
      f(Dense());
    }
  }

  // The deformation `d` over the device's lattice `values`, a sparse lattice's cells included.
  template <typename Deformation>
  Deformation WithCells(Deformation d) const
  {
    if (this->SparseControlPoints > 0)
    {
      d.CellVoxels = this->CellVoxels.As<int>();
      d.CellSupports = this->CellSupports.As<int>();
    }
    return d;
  }

  void RunBindSparse(const int* cellOfPoint, const int* cellVoxels, const int* cellSupports, std::int64_t cells,
    std::int64_t controlPoints)
  {
    // An index out of range would read outside the device's arrays: refused here, for the price of one pass.
    const int n = ffd::SupportSize(this->Basis, this->Divisions[0]);
    const std::int64_t supportCount = cells * n * n * n;
    for (std::int64_t i = 0; i < this->Count; ++i)
    {
      if (cellOfPoint[i] < -1 || cellOfPoint[i] >= cells)
      {
        throw CudaError{ cudaErrorInvalidValue, "binding: a point's cell is out of range" };
      }
    }
    for (std::int64_t i = 0; i < supportCount; ++i)
    {
      if (cellSupports[i] < 0 || cellSupports[i] >= controlPoints)
      {
        throw CudaError{ cudaErrorInvalidValue, "binding: a cell's control point is out of range" };
      }
    }
    const std::size_t pointBytes = std::size_t(this->Count) * sizeof(int);
    const std::size_t voxelBytes = std::size_t(3 * cells) * sizeof(int);
    const std::size_t supportBytes = std::size_t(supportCount) * sizeof(int);
    this->Cells.Reserve(pointBytes, "allocating the binding");
    this->CellVoxels.Reserve(voxelBytes, "allocating the lattice's cells");
    this->CellSupports.Reserve(supportBytes, "allocating the lattice's cells");
    Check(cudaMemcpyAsync(this->Cells.Data, cellOfPoint, pointBytes, cudaMemcpyHostToDevice, this->Stream),
      "uploading the binding");
    Check(cudaMemcpyAsync(this->CellVoxels.Data, cellVoxels, voxelBytes, cudaMemcpyHostToDevice, this->Stream),
      "uploading the lattice's cells");
    Check(cudaMemcpyAsync(this->CellSupports.Data, cellSupports, supportBytes, cudaMemcpyHostToDevice, this->Stream),
      "uploading the lattice's cells");
    this->SparseControlPoints = controlPoints;
  }

  template <typename Real>
  void RunBind(const ffd::Frame<double>& frame, bool clampOutside)
  {
    BindKernel<Real><<<BlocksFor(this->Count), ThreadsPerBlock, 0, this->Stream>>>(this->Points.As<Real>(), this->Count,
      frame, this->Basis, this->Divisions[0], this->Divisions[1], this->Divisions[2], clampOutside,
      this->Cells.As<int>());
    Check(cudaGetLastError(), "launching the binding");
    Check(cudaStreamSynchronize(this->Stream), "binding the points");
  }

  // Throws unless `controlPoints` is the bound lattice's count; dims: its control points along each axis.
  void RequireControlPoints(std::int64_t controlPoints, int dims[3]) const
  {
    for (int a = 0; a < 3; ++a)
    {
      dims[a] = ffd::ControlPointsAlongAxis(this->Basis, this->Divisions[a]);
    }
    const std::int64_t expected =
      this->SparseControlPoints > 0 ? this->SparseControlPoints : std::int64_t(dims[0]) * dims[1] * dims[2];
    if (controlPoints != expected)
    {
      throw CudaError{ cudaErrorInvalidValue, "evaluating: the lattice does not match the binding's basis" };
    }
  }

  template <typename Real>
  void RunEvaluate(const double* displacements, std::int64_t controlPoints, bool withNormals, bool withDeterminants)
  {
    this->RequireBound<Real>(withNormals);
    int dims[3];
    this->RequireControlPoints(controlPoints, dims);
    // The lattice: the only upload of an update. Float32 without the Jacobian on the trilinear and global bases
    // takes it as float4 (their kernels read one 16-byte word per control point), the others as 3 numbers per
    // control point (the float4 lattice made the gathers of the other local bases slower).
    const bool withJacobian = withNormals || withDeterminants;
    const bool asFloat4 = std::is_same<Real, float>::value && !withJacobian &&
      (this->Basis == ffd::GridBasis::Trilinear || this->Basis == ffd::GridBasis::Bernstein);
    const int stride = asFloat4 ? 4 : 3;
    const std::size_t latticeBytes = std::size_t(controlPoints) * stride * sizeof(Real);
    Real* staged = static_cast<Real*>(this->StageLattice(latticeBytes));
    for (std::int64_t v = 0; v < controlPoints; ++v)
    {
      for (int c = 0; c < 3; ++c)
      {
        staged[stride * v + c] = Real(displacements[3 * v + c]);
      }
      if (asFloat4)
      {
        staged[stride * v + 3] = Real(0);
      }
    }
    this->UploadLattice(latticeBytes);

    this->BeginEvaluation<Real>(withNormals, withDeterminants);
    Real* normalsOut = withNormals ? this->OutNormals.As<Real>() : nullptr;
    Real* determinantsOut = withDeterminants ? this->OutDeterminants.As<Real>() : nullptr;
    if constexpr (std::is_same<Real, float>::value)
    {
      if (asFloat4)
      {
        this->LaunchFloat4(this->Lattice.As<float4>(), dims);
      }
      else
      {
        this->LaunchGeneric<float>(this->Lattice.As<float>(), dims, normalsOut, determinantsOut);
      }
    }
    else
    {
      this->LaunchGeneric<Real>(this->Lattice.As<Real>(), dims, normalsOut, determinantsOut);
    }
    this->FinishEvaluation(withNormals, withDeterminants, false);
  }

  // W^T g (FFDCudaGridAdjoint.cuh): the plan made once per binding, then the chunks' partials and their gather.
  template <typename Real>
  void RunAdjoint(const double* gradient, std::int64_t controlPoints, double* sums)
  {
    this->RequireBound<Real>(false);
    int dims[3];
    this->RequireControlPoints(controlPoints, dims);
    const ffd::Frame<Real> frame = ffd::Frame<Real>::FromArray(this->Frame);
    ffd::WithStaticBasis(this->Basis,
      [&](auto maxCount, auto basis)
      {
        this->WithStorage<decltype(basis)::value>(
          [&](auto storage)
          {
            constexpr int MaxCount = decltype(maxCount)::value;
            using Deformation =
              ffd::GridDeformation<MaxCount, Real, decltype(basis)::value, Real, false, decltype(storage)::value>;
            const Deformation deformation =
              this->WithCells(Deformation{ this->Basis, { this->Divisions[0], this->Divisions[1], this->Divisions[2] },
                { dims[0], dims[1], dims[2] }, nullptr, frame });
            this->EnsureAdjointPlan<Real, MaxCount>(deformation, controlPoints);
            this->Counts.BytesDownloaded += detail::RunAdjointUpdate<Real>(*this->Plan, gradient, this->Count,
              controlPoints, this->Stream, this->KernelStart, this->KernelStop, this->Counts.LastKernelMilliseconds,
              sums, [&] { this->LaunchAdjointChunks<Real, MaxCount>(deformation); });
          });
      });
  }

  // The adjoint's plan for the current binding, made where there is none.
  template <typename Real, int MaxCount, typename Deformation>
  void EnsureAdjointPlan(const Deformation& deformation, std::int64_t controlPoints)
  {
    if (this->Plan && this->Plan->ForBinding == this->Counts.Bindings)
    {
      return;
    }
    this->Plan.reset(new detail::AdjointPlan);
    detail::AdjointPlan& plan = *this->Plan;
    for (int a = 0; a < 3; ++a)
    {
      plan.Counts[a] = ffd::SupportSize(this->Basis, this->Divisions[a]);
    }
    plan.Terms = plan.Counts[0] * plan.Counts[1] * plan.Counts[2];
    plan.ChunkPoints = ffd::AdjointChunkPoints(this->Count, plan.Terms);
    detail::SortAdjointPoints(plan, this->Cells.As<int>(), this->Count, this->Stream);
    const std::int64_t terms = plan.Chunks * plan.Terms;
    plan.Keys.Reserve(std::size_t(terms) * sizeof(int), "allocating the adjoint's plan");
    plan.Values.Reserve(std::size_t(terms) * sizeof(int), "allocating the adjoint's plan");
    if (terms > 0)
    {
      detail::AdjointTermKernel<Deformation, Real, MaxCount><<<BlocksFor(terms), ThreadsPerBlock, 0, this->Stream>>>(
        this->Points.As<Real>(), plan.Order.As<int>(), plan.ChunkStart.As<std::int64_t>(), plan.ChunkCell.As<int>(),
        terms, plan.Counts[0], plan.Counts[1], plan.Counts[2], deformation, plan.Keys.As<int>(), plan.Values.As<int>());
      Check(cudaGetLastError(), "launching the adjoint's plan");
    }
    detail::FinishAdjointPlan(plan, this->Count, controlPoints, sizeof(Real), this->Stream);
    plan.ForBinding = this->Counts.Bindings;
    ++this->Counts.AdjointPlans;
  }

  // The chunks' sums (AdjointChunkKernel), a block per chunk and block of columns.
  template <typename Real, int MaxCount, typename Deformation>
  void LaunchAdjointChunks(const Deformation& deformation)
  {
    const detail::AdjointPlan& plan = *this->Plan;
    const detail::AdjointLayout layout(plan.Counts, sizeof(Real));
    const dim3 blocks(unsigned(plan.Chunks), unsigned(layout.ColumnBlocks()));
    detail::AdjointChunkKernel<Deformation, Real, MaxCount>
      <<<blocks, detail::AdjointThreads, layout.SharedBytes(sizeof(Real)), this->Stream>>>(this->Points.As<Real>(),
        plan.Order.As<int>(), plan.ChunkStart.As<std::int64_t>(), plan.ChunkCell.As<int>(), plan.Gradient.As<Real>(),
        layout, deformation, plan.Partials.As<double>());
  }

  // DeformKernel on a lattice of 3 numbers per control point: with the Jacobian, float64 points, and float32
  // points without the Jacobian on the local bases of 3 or 4 control points per axis.
  template <typename Real>
  void LaunchGeneric(const Real* d, const int dims[3], Real* normalsOut, Real* determinantsOut)
  {
    const ffd::Frame<Real> frame = ffd::Frame<Real>::FromArray(this->Frame);
    ffd::WithStaticBasis(this->Basis,
      [&](auto maxCount, auto basis)
      {
        this->WithStorage<decltype(basis)::value>(
          [&](auto storage)
          {
            using Deformation = ffd::GridDeformation<decltype(maxCount)::value, Real, decltype(basis)::value, Real,
              false, decltype(storage)::value>;
            const Deformation deformation =
              this->WithCells(Deformation{ this->Basis, { this->Divisions[0], this->Divisions[1], this->Divisions[2] },
                { dims[0], dims[1], dims[2] }, d, frame });
            // Float32 points alone on a local basis: four consecutive points a thread, those of one cell deformed
            // together, each control point read once for the four (DeformPointsKernel's Grouped path).
            if constexpr (std::is_same<Real, float>::value && decltype(basis)::value != int(ffd::GridBasis::Bernstein))
            {
              if (!normalsOut && !determinantsOut)
              {
                detail::LaunchDeformPoints<true>(
                  SplitCellDeformation<Deformation>{ deformation, ffd::CellSplit::For(this->Basis, this->Divisions) },
                  this->Points.As<float>(), this->Cells.As<int>(), this->Count, this->OutPoints.As<float>(),
                  this->Stream);
                return;
              }
            }
            detail::LaunchDeform(deformation, this->Points.As<Real>(), this->Cells.As<int>(), this->Count,
              this->OutPoints.As<Real>(), this->Normals.As<Real>(), normalsOut, determinantsOut, this->Stream);
          });
      });
  }

  // Float32 without the Jacobian on the float4 lattice (trilinear and the global basis): the global basis's own
  // kernels where they apply (LaunchBernstein), otherwise DeformPointsKernel.
  void LaunchFloat4(const float4* d, const int dims[3])
  {
    const ffd::Frame<float> frame = ffd::Frame<float>::FromArray(this->Frame);
    const ffd::CellSplit split = ffd::CellSplit::For(this->Basis, this->Divisions);
    auto launch = [&](auto maxCount, auto basis)
    {
      this->WithStorage<decltype(basis)::value>(
        [&](auto storage)
        {
          using Deformation = ffd::GridDeformation<decltype(maxCount)::value, float4, decltype(basis)::value, float,
            false, decltype(storage)::value>;
          const Deformation grid = this->WithCells(Deformation{ this->Basis,
            { this->Divisions[0], this->Divisions[1], this->Divisions[2] }, { dims[0], dims[1], dims[2] }, d, frame });
          detail::LaunchDeformPoints(SplitCellDeformation<Deformation>{ grid, split }, this->Points.As<float>(),
            this->Cells.As<int>(), this->Count, this->OutPoints.As<float>(), this->Stream);
        });
    };
    if (this->Basis == ffd::GridBasis::Trilinear)
    {
      launch(std::integral_constant<int, 4>(), std::integral_constant<int, int(ffd::GridBasis::Trilinear)>());
    }
    else if (!this->LaunchBernstein(d, dims)) // more than 16 control points along an axis
    {
      launch(std::integral_constant<int, ffd::MaxBernsteinDegree + 1>(),
        std::integral_constant<int, int(ffd::GridBasis::Bernstein)>());
    }
  }

  // The global basis's own kernels, when they apply (at most 16 control points per axis): on the tensor cores
  // (BernsteinTensorKernel) from 400 control points on, below that BernsteinKernel, which is faster on small
  // lattices (BENCHMARKS.md). False otherwise.
  bool LaunchBernstein(const float4* displacements, const int dims[3])
  {
    const int largest = std::max(dims[0], std::max(dims[1], dims[2]));
    if (largest > 16)
    {
      return false;
    }
    const ffd::Frame<float> frame = ffd::Frame<float>::FromArray(this->Frame);
    const int controlPoints = dims[0] * dims[1] * dims[2];
    if (controlPoints >= 400 && this->LaunchBernsteinTensor(displacements, dims, frame))
    {
      return true;
    }
    return this->LaunchBernsteinShared(displacements, dims, frame, largest);
  }

  // BernsteinTensorKernel instantiated for the lattice's k-steps and n-tiles. False, launching nothing, where the
  // binary was built for a device without TF32 tensor cores.
  bool LaunchBernsteinTensor(const float4* displacements, const int dims[3], const ffd::Frame<float>& frame)
  {
    const int ks = (dims[0] + 7) / 8, nt = (3 * dims[1] + 7) / 8;
    const std::size_t shared = TensorSharedBytes(ks, nt, dims[2]);
    auto withNT = [&](auto ksConstant)
    {
      constexpr int KS = decltype(ksConstant)::value;
      switch (nt)
      {
        case 1:
          return this->LaunchTensorKernel<KS, 1>(displacements, dims, frame, shared);
        case 2:
          return this->LaunchTensorKernel<KS, 2>(displacements, dims, frame, shared);
        case 3:
          return this->LaunchTensorKernel<KS, 3>(displacements, dims, frame, shared);
        case 4:
          return this->LaunchTensorKernel<KS, 4>(displacements, dims, frame, shared);
        case 5:
          return this->LaunchTensorKernel<KS, 5>(displacements, dims, frame, shared);
        default:
          return this->LaunchTensorKernel<KS, 6>(displacements, dims, frame, shared);
      }
    };
    return ks == 1 ? withNT(std::integral_constant<int, 1>()) : withNT(std::integral_constant<int, 2>());
  }

  // One instantiation of BernsteinTensorKernel, in as many blocks as the device holds at once (fewer where the
  // points need fewer); false, launching nothing, where the binary has no TF32 tensor cores.
  template <int KS, int NT>
  bool LaunchTensorKernel(
    const float4* displacements, const int dims[3], const ffd::Frame<float>& frame, std::size_t shared)
  {
    const auto kernel = BernsteinTensorKernel<KS, NT>;
    cudaFuncAttributes attributes;
    Check(cudaFuncGetAttributes(&attributes, kernel), "querying the evaluation kernel");
    if (attributes.binaryVersion < 80)
    {
      return false; // built for a device without TF32 tensor cores
    }
    Check(cudaFuncSetAttribute(kernel, cudaFuncAttributeMaxDynamicSharedMemorySize, int(shared)),
      "allowing the evaluation's shared memory");
    int perMultiprocessor = 0;
    Check(cudaOccupancyMaxActiveBlocksPerMultiprocessor(&perMultiprocessor, kernel, 32 * TensorWarps, shared),
      "sizing the evaluation");
    const std::int64_t tiles = (this->Count + TensorTilePoints - 1) / TensorTilePoints;
    const std::int64_t blocks = std::min<std::int64_t>(
      std::int64_t(std::max(perMultiprocessor, 1)) * this->Multiprocessors, (tiles + TensorWarps - 1) / TensorWarps);
    kernel<<<unsigned(blocks), 32 * TensorWarps, shared, this->Stream>>>(this->Points.As<float>(),
      this->Cells.As<int>(), this->Count, frame, dims[0], dims[1], dims[2], displacements, this->OutPoints.As<float>());
    return true;
  }

  // BernsteinKernel, the lattice in shared memory: false where it does not fit (48 KiB).
  bool LaunchBernsteinShared(
    const float4* displacements, const int dims[3], const ffd::Frame<float>& frame, int largest)
  {
    const int controlPoints = dims[0] * dims[1] * dims[2];
    const std::size_t shared = std::size_t(controlPoints) * sizeof(float4);
    if (shared > 48 * 1024)
    {
      return false;
    }
    const unsigned blocks = unsigned((this->Count + 4 * ThreadsPerBlock - 1) / (4 * ThreadsPerBlock));
    // The smaller instantiation that holds the lattice's axes. (A third one, for up to 12 control points per
    // axis, made 11^3 lattices slower: 3.4 instead of 3.6 G points/s on an H200.)
    auto launch = [&](auto maxCount)
    {
      BernsteinKernel<decltype(maxCount)::value>
        <<<blocks, ThreadsPerBlock, shared, this->Stream>>>(this->Points.As<float>(), this->Cells.As<int>(),
          this->Count, frame, dims[0], dims[1], dims[2], displacements, this->OutPoints.As<float>());
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
};

//------------------------------------------------------------------------------------------------------------
GridDeformer::GridDeformer()
  : ResidentPoints(std::unique_ptr<State>(new Impl))
{
}

bool GridDeformer::Bind(const double frame[12], int basis, const int divisions[3], bool clampOutside)
{
  Impl& p = static_cast<Impl&>(*this->S);
  return p.Guard(
    [&]
    {
      if (p.Count == 0 || !ffd::IsGridBasis(basis))
      {
        throw CudaError{ cudaErrorInvalidValue, "binding: no points, or an unknown basis" };
      }
      std::copy(frame, frame + 12, p.Frame);
      std::copy(divisions, divisions + 3, p.Divisions);
      p.Basis = static_cast<ffd::GridBasis>(basis);
      p.SparseControlPoints = 0;
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

bool GridDeformer::BindSparse(const double frame[12], int basis, const int divisions[3], const int* cellOfPoint,
  const int* cellVoxels, const int* cellSupports, std::int64_t cells, std::int64_t controlPoints)
{
  Impl& p = static_cast<Impl&>(*this->S);
  return p.Guard(
    [&]
    {
      if (p.Count == 0 || !ffd::IsGridBasis(basis) || basis == int(ffd::GridBasis::Bernstein) || cells <= 0 ||
        controlPoints <= 0)
      {
        throw CudaError{ cudaErrorInvalidValue, "binding: no points, or not a sparse lattice of a local basis" };
      }
      std::copy(frame, frame + 12, p.Frame);
      std::copy(divisions, divisions + 3, p.Divisions);
      p.Basis = static_cast<ffd::GridBasis>(basis);
      p.SparseControlPoints = 0; // valid again once uploaded
      p.RunBindSparse(cellOfPoint, cellVoxels, cellSupports, cells, controlPoints);
      p.Bound = true;
      p.Evaluated = false;
      ++p.Counts.Bindings;
    });
}

bool GridDeformer::Adjoint(const double* gradient, std::int64_t controlPoints, double* sums)
{
  Impl& p = static_cast<Impl&>(*this->S);
  return p.Guard(
    [&]
    {
      if (p.IsDouble)
      {
        p.RunAdjoint<double>(gradient, controlPoints, sums);
      }
      else
      {
        p.RunAdjoint<float>(gradient, controlPoints, sums);
      }
    });
}

bool GridDeformer::Evaluate(
  const double* displacements, std::int64_t controlPoints, bool withNormals, bool withDeterminants)
{
  return ResidentPoints::State::EvaluateInPrecision(
    static_cast<Impl&>(*this->S), displacements, controlPoints, withNormals, withDeterminants);
}

} // namespace cuda
} // namespace ffd
