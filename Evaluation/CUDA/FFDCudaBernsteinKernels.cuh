// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDCudaBernsteinKernels.cuh
 * @brief The global Bernstein basis's own float32 kernels (no Jacobian), for FFDCudaGridDeformer.cu only: a
 * shared-memory kernel for small lattices and a tensor-core one (3xTF32 mma.sync) from 400 control points on.
 * GridDeformer::Impl::LaunchBernstein() chooses between them.
 */
#ifndef FFDCudaBernsteinKernels_cuh
#define FFDCudaBernsteinKernels_cuh

#include "FFDBernstein.h"
#include "FFDCudaDevice.cuh"
#include "FFDFrame.h"

#include <cstdint>

namespace ffd
{
namespace cuda
{
namespace detail
{
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
inline std::size_t TensorSharedBytes(int ks, int nt, int dimU)
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
} // namespace detail
} // namespace cuda
} // namespace ffd

#endif
