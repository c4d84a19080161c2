// SPDX-License-Identifier: BSD-3-Clause
#include "FFDCudaGridDeformer.h"

#include "FFDGridDeformation.h"

#include <cuda_runtime.h>

#include <algorithm>
#include <cstring>
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
constexpr int ThreadsPerBlock = 256;
// Size of each of the two pinned buffers that stage a download: large enough to run the bus at full speed,
// small enough that the host copy of one chunk overlaps the transfer of the next (8 MB chunks made an update
// of 1 M points 1.4-1.6 times the bare download, the host copy of the first chunk waiting alone).
constexpr std::size_t StagingBytes = std::size_t(2) << 20;

unsigned BlocksFor(std::int64_t n)
{
  return unsigned((n + ThreadsPerBlock - 1) / ThreadsPerBlock);
}

// The binding's flat cell index ci + cx (cj + cy ck) taken apart with multiplications instead of the integer
// divisions of GridDeformation::CellIndices() (some 30 instructions a point less; same indices). n / d is
// (n M) >> S with S = 31 + ceil(log2 d) and M = ceil(2^S / d) < 2^32, exact for every 0 <= n < 2^31 (Granlund and
// Montgomery, "Division by invariant integers using multiplication", 1994: M d - 2^S < d <= 2^(S - 31)).
struct CellSplit
{
  unsigned M[2];
  int S[2];
  int D[2];

  static CellSplit For(ffd::GridBasis basis, const int divisions[3])
  {
    CellSplit split;
    for (int a = 0; a < 2; ++a)
    {
      const int d = ffd::BindingCells(basis, divisions[a]);
      int log2 = 0;
      while ((std::uint64_t(1) << log2) < std::uint64_t(d))
      {
        ++log2;
      }
      split.S[a] = 31 + log2;
      split.M[a] = unsigned(((std::uint64_t(1) << split.S[a]) + std::uint64_t(d) - 1) / std::uint64_t(d));
      split.D[a] = d;
    }
    return split;
  }

  __device__ __forceinline__ void Apply(int cell, int c[3]) const
  {
    FFD_UNROLL
    for (int a = 0; a < 2; ++a)
    {
      const int q = int((unsigned long long)unsigned(cell) * this->M[a] >> this->S[a]);
      c[a] = cell - q * this->D[a];
      cell = q;
    }
    c[2] = cell;
  }
};

// A CUDA failure, turned into a message by Check().
struct CudaError
{
  cudaError_t Code;
  const char* What;
};

void Check(cudaError_t code, const char* what)
{
  if (code != cudaSuccess)
  {
    throw CudaError{ code, what };
  }
}

// Device memory (cudaMalloc), or pinned host memory (cudaMallocHost) for the staging of transfers.
struct Buffer
{
  const bool Pinned;
  void* Data = nullptr;
  std::size_t Bytes = 0;

  explicit Buffer(bool pinned = false)
    : Pinned(pinned)
  {
  }
  ~Buffer() { this->Free(); }

  void Reserve(std::size_t bytes, const char* what)
  {
    if (bytes <= this->Bytes)
    {
      return;
    }
    this->Free();
    Check(this->Pinned ? cudaMallocHost(&this->Data, bytes) : cudaMalloc(&this->Data, bytes), what);
    this->Bytes = bytes;
  }
  void Free()
  {
    if (this->Data)
    {
      this->Pinned ? cudaFreeHost(this->Data) : cudaFree(this->Data);
    }
    this->Data = nullptr;
    this->Bytes = 0;
  }
  template <typename T>
  T* As() const
  {
    return static_cast<T*>(this->Data);
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
  cells[i] = ffd::BindToGrid(frame, basis, voxels, ffd::Vec3<double>{ double(p[0]), double(p[1]), double(p[2]) },
    clampOutside);
}

// With the Jacobian (normals, determinants) one point a thread; without, four points a thread, ThreadsPerBlock
// apart (consecutive threads, consecutive points), so that their independent lattice gathers overlap, and an
// instantiation that needs fewer registers. Launch bounds keep at least 4 (6) blocks of 256 threads on a
// multiprocessor: the gathers are dependent loads, and more threads in flight hide their latency. Trilinear on
// an H200: 58-62 % of the copy roofline with one point a thread, 64-70 % with four. (Staging the points through
// shared memory was slower.) For float32 trilinear without the Jacobian DeformPointsKernel is faster; for the
// local bases of 3 or 4 control points per axis its layout, the float4 lattice or CellSplit here were up to
// 20 % slower on an H200 (BENCHMARKS.md), so they stay on this kernel.
template <typename Deformer, typename Real, bool WithJacobian>
__global__ void __launch_bounds__(ThreadsPerBlock, WithJacobian ? 4 : 6) DeformKernel(const Real* __restrict__ points,
  const int* __restrict__ cells, std::int64_t count, Deformer deformation,
  Real* __restrict__ outPoints, const float* __restrict__ normals, float* __restrict__ outNormals,
  Real* __restrict__ determinants)
{
  constexpr int PointsPerThread = WithJacobian ? 1 : 4;
  FFD_UNROLL
  for (int r = 0; r < PointsPerThread; ++r)
  {
    const std::int64_t i =
      blockIdx.x * std::int64_t(PointsPerThread * ThreadsPerBlock) + r * ThreadsPerBlock + threadIdx.x;
    if (i >= count)
    {
      return;
    }
    const Real* p = points + 3 * i;
    const ffd::Vec3<Real> x = { p[0], p[1], p[2] };
    const int cell = cells[i];
    ffd::Vec3<Real> y = x;
    ffd::Mat3<Real> jacobian = ffd::Mat3<Real>::Identity();
    if (cell >= 0)
    {
      y = WithJacobian ? deformation.Deform(x, cell, jacobian) : deformation.Deform(x, cell);
    }
    Real* out = outPoints + 3 * i;
    out[0] = y.x;
    out[1] = y.y;
    out[2] = y.z;
    if (!WithJacobian)
    {
      continue;
    }
    if (outNormals)
    {
      const ffd::Vec3<Real> n = ffd::TransformNormal(jacobian, ffd::Vec3<Real>::From(normals + 3 * i));
      outNormals[3 * i] = float(n.x);
      outNormals[3 * i + 1] = float(n.y);
      outNormals[3 * i + 2] = float(n.z);
    }
    if (determinants)
    {
      determinants[i] = ffd::Determinant(jacobian);
    }
  }
}

// Float32 points without the Jacobian (the common update): each thread deforms four consecutive points, read as
// three 16-byte words (and their cells as one) with streaming hints (they are touched once) and written alike; the
// lattice is float4 (LatticeValues<float4>) and the cell is split by multiplications (CellSplit). Launch bounds
// allow 64 registers: all four points' loads are issued before the first lattice gather. Trilinear on an H200,
// 16 M points: 0.158-0.161 ms with DeformKernel, 0.135-0.139 ms so (BENCHMARKS.md says what each part gave).
template <typename Deformer>
__global__ void __launch_bounds__(ThreadsPerBlock, 4) DeformPointsKernel(const float* __restrict__ points,
  const int* __restrict__ cells, std::int64_t count, Deformer deformation, CellSplit split,
  float* __restrict__ outPoints)
{
  auto deform = [&](ffd::Vec3<float>& x, int cell) {
    if (cell >= 0)
    {
      int c[3];
      split.Apply(cell, c);
      x = deformation.DeformInCell(x, c);
    }
  };
  const std::int64_t group = blockIdx.x * std::int64_t(ThreadsPerBlock) + threadIdx.x;
  const std::int64_t first = 4 * group;
  if (first + 4 <= count)
  {
    const float4* in = reinterpret_cast<const float4*>(points) + 3 * group;
    const float4 a = __ldcs(in), b = __ldcs(in + 1), c = __ldcs(in + 2);
    const int4 cell = __ldcs(reinterpret_cast<const int4*>(cells) + group);
    ffd::Vec3<float> x[4] = { { a.x, a.y, a.z }, { a.w, b.x, b.y }, { b.z, b.w, c.x }, { c.y, c.z, c.w } };
    deform(x[0], cell.x);
    deform(x[1], cell.y);
    deform(x[2], cell.z);
    deform(x[3], cell.w);
    float4* out = reinterpret_cast<float4*>(outPoints) + 3 * group;
    __stcs(out, make_float4(x[0].x, x[0].y, x[0].z, x[1].x));
    __stcs(out + 1, make_float4(x[1].y, x[1].z, x[2].x, x[2].y));
    __stcs(out + 2, make_float4(x[2].z, x[3].x, x[3].y, x[3].z));
    return;
  }
  for (std::int64_t i = first; i < count; ++i) // the last one to three points
  {
    ffd::Vec3<float> x = { points[3 * i], points[3 * i + 1], points[3 * i + 2] };
    deform(x, cells[i]);
    outPoints[3 * i] = x.x;
    outPoints[3 * i + 1] = x.y;
    outPoints[3 * i + 2] = x.z;
  }
}

// The global basis without Jacobian on small lattices (under 400 control points; BernsteinTensorKernel takes the
// larger ones): the lattice sits in shared memory as float4 (one 16-byte broadcast load per control point), each
// thread evaluates four points (each lattice value loaded serves all four, twelve FMAs; two points per thread ran
// at 3.1 G points/s, four at 3.6 for 11^3 on an H200), and the weights of the first axis stay in registers
// (MaxCount bounds the control points per axis at compile time). The same function as
// ffd::GridDeformation::Deform (the tests compare the two): x + sum_ijk B_i(s) B_j(t) B_k(u) D_ijk at the clamped
// parameters of a bound point.
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
// The global basis on the tensor cores. The sum x + sum_ijk Bs_i Bt_j Bu_k D_ijk over the lattice's control
// points (the same function as BernsteinKernel and ffd::GridDeformation, whose weights it computes with the same
// ffd::BernsteinBasisBounded) is, for a tile of points, the matrix product
//   P[p, (j, c)] = sum_{i, k} (Bs_i Bu_k)[p] D[(i, k), (j, c)]
// followed by out[p, c] = x[p, c] + sum_j Bt_j[p] P[p, (j, c)]. The product runs as mma.sync m16n8k8 in TF32 with
// error compensation (3xTF32): each operand is split into a TF32 part and the float32 rest, and
// hi*hi + hi*lo + lo*hi is accumulated in float32, which leaves an error of about 2^-20 of each product instead of
// TF32's 2^-11: the results stay within float32 rounding of float64 (BENCHMARKS.md). K runs over i (padded to
// 8 KS) for each k, N over (j, c) = 3 j + c (padded to 8 NT).
//
// The lattice is stored in shared memory as the mma's B fragments, hi and lo of both rows of a lane in one
// float4, so a lane loads them with one 16-byte load. Each warp takes tiles of 32 points (two m16 tiles sharing
// every B fragment) from a persistent grid: lanes compute the three axes' weights of the tile's points into a
// per-warp table, then the k loop builds A = Bs_i Bu_k (split by truncation: hi = the top 19 bits, lo = the exact
// rest) and issues 3 mma per (k-step, n-tile, m-tile); the epilogue weights the columns by Bt_j and sums the
// four lanes of each row. 11^3 control points on an H200, 16 M points: 4.75 G points/s against 3.57 for
// BernsteinKernel. (Converting A with cvt.rna, which sm_90 emulates in 4 instructions, ran at 3.5; one m16 tile a
// warp at 3.9; 4 warps a block at 4.0; the k loop unrolled 4 times at 4.3.)
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
          const float a[4] = { as[mt][0][ks][0] * bu[mt][0], as[mt][1][ks][0] * bu[mt][1],
            as[mt][0][ks][1] * bu[mt][0], as[mt][1][ks][1] * bu[mt][1] };
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
struct GridDeformer::Impl
{
  std::int64_t Count = 0;
  bool IsDouble = false;
  bool HasNormals = false;
  bool Bound = false;
  bool Evaluated = false, EvaluatedNormals = false, EvaluatedDeterminants = false;
  ffd::GridBasis Basis = ffd::GridBasis::Bernstein;
  int Divisions[3] = { 0, 0, 0 };
  double Frame[12] = {};
  Buffer Points, Normals, Cells, Displacements, OutPoints, OutNormals, OutDeterminants;
  Buffer Staging[2] = { Buffer(true), Buffer(true) };
  Buffer LatticeStaging{ true };
  cudaStream_t Stream = nullptr;
  cudaEvent_t ChunkDone[2] = { nullptr, nullptr };
  cudaEvent_t KernelStart = nullptr, KernelStop = nullptr; // to time the evaluation kernel
  int Multiprocessors = 0;                                   // of the current device, for persistent grids
  std::string LastError;
  Counters Counts;

  void EnsureStream()
  {
    if (!this->Stream)
    {
      int device = 0;
      Check(cudaGetDevice(&device), "querying the device");
      Check(cudaDeviceGetAttribute(&this->Multiprocessors, cudaDevAttrMultiProcessorCount, device),
        "querying the device");
      Check(cudaStreamCreateWithFlags(&this->Stream, cudaStreamNonBlocking), "creating a stream");
      Check(cudaEventCreateWithFlags(&this->ChunkDone[0], cudaEventDisableTiming), "creating an event");
      Check(cudaEventCreateWithFlags(&this->ChunkDone[1], cudaEventDisableTiming), "creating an event");
      Check(cudaEventCreate(&this->KernelStart), "creating an event");
      Check(cudaEventCreate(&this->KernelStop), "creating an event");
    }
  }

  void Release()
  {
    for (Buffer* b : { &this->Points, &this->Normals, &this->Cells, &this->Displacements, &this->OutPoints,
           &this->OutNormals, &this->OutDeterminants })
    {
      b->Free();
    }
    this->Staging[0].Free();
    this->Staging[1].Free();
    this->LatticeStaging.Free();
    for (cudaEvent_t* e : { &this->ChunkDone[0], &this->ChunkDone[1], &this->KernelStart, &this->KernelStop })
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

  // Runs `step`, turning a CUDA failure into false, a message and no device state.
  template <typename Step>
  bool Guard(Step&& step)
  {
    try
    {
      step();
      return true;
    }
    catch (const CudaError& e)
    {
      this->LastError = std::string("CUDA failed while ") + e.What + ": " + cudaGetErrorString(e.Code);
      cudaGetLastError(); // clear a non-sticky error so that later calls start clean
      this->Release();
      return false;
    }
  }

  template <typename Real>
  void Upload(const Real* xyz, std::int64_t count)
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

  template <typename Real>
  void RunBind(const ffd::Frame<double>& frame, bool clampOutside)
  {
    BindKernel<Real><<<BlocksFor(this->Count), ThreadsPerBlock, 0, this->Stream>>>(this->Points.As<Real>(),
      this->Count, frame, this->Basis, this->Divisions[0], this->Divisions[1], this->Divisions[2], clampOutside,
      this->Cells.As<int>());
    Check(cudaGetLastError(), "launching the binding");
    Check(cudaStreamSynchronize(this->Stream), "binding the points");
  }

  // Copies `bytes` from the device to pageable host memory through the two pinned buffers, so that the host
  // copy of one chunk overlaps the transfer of the next.
  void Download(const void* device, void* host, std::size_t bytes)
  {
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
  void RunEvaluate(const double* displacements, std::int64_t controlPoints, bool withNormals, bool withDeterminants)
  {
    if (!this->Bound || (this->IsDouble != (sizeof(Real) == sizeof(double))))
    {
      throw CudaError{ cudaErrorInvalidValue, "evaluating: no points bound in this precision" };
    }
    if (withNormals && !this->HasNormals)
    {
      throw CudaError{ cudaErrorInvalidValue, "evaluating: normals asked for but none uploaded" };
    }
    const int dims[3] = { ffd::ControlPointsAlongAxis(this->Basis, this->Divisions[0]),
      ffd::ControlPointsAlongAxis(this->Basis, this->Divisions[1]),
      ffd::ControlPointsAlongAxis(this->Basis, this->Divisions[2]) };
    if (controlPoints != std::int64_t(dims[0]) * dims[1] * dims[2])
    {
      throw CudaError{ cudaErrorInvalidValue, "evaluating: the lattice does not match the binding's basis" };
    }
    // The lattice: the only upload of an update. Float32 without the Jacobian on the trilinear and global bases
    // takes it as float4 (their kernels read one 16-byte word per control point), the others as 3 numbers per
    // control point (the float4 lattice made the gathers of the other local bases slower).
    const bool withJacobian = withNormals || withDeterminants;
    const bool asFloat4 = std::is_same<Real, float>::value && !withJacobian &&
      (this->Basis == ffd::GridBasis::Trilinear || this->Basis == ffd::GridBasis::Bernstein);
    const int stride = asFloat4 ? 4 : 3;
    const std::size_t latticeBytes = std::size_t(controlPoints) * stride * sizeof(Real);
    this->LatticeStaging.Reserve(latticeBytes, "allocating the lattice's staging buffer");
    Real* staged = static_cast<Real*>(this->LatticeStaging.Data);
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
    this->Displacements.Reserve(latticeBytes, "allocating the lattice");
    Check(cudaMemcpyAsync(this->Displacements.Data, staged, latticeBytes, cudaMemcpyHostToDevice, this->Stream),
      "uploading the lattice");
    ++this->Counts.LatticeUploads;
    this->Counts.LatticeBytes += latticeBytes;

    this->OutPoints.Reserve(std::size_t(this->Count) * 3 * sizeof(Real), "allocating the deformed points");
    if (withNormals)
    {
      this->OutNormals.Reserve(std::size_t(this->Count) * 3 * sizeof(float), "allocating the normals");
    }
    if (withDeterminants)
    {
      this->OutDeterminants.Reserve(std::size_t(this->Count) * sizeof(Real), "allocating the determinants");
    }
    float* normalsOut = withNormals ? this->OutNormals.As<float>() : nullptr;
    Real* determinantsOut = withDeterminants ? this->OutDeterminants.As<Real>() : nullptr;
    Check(cudaEventRecord(this->KernelStart, this->Stream), "recording an event");
    if constexpr (std::is_same<Real, float>::value)
    {
      if (asFloat4)
      {
        this->LaunchFloat4(this->Displacements.As<float4>(), dims);
      }
      else
      {
        this->LaunchGeneric<float>(this->Displacements.As<float>(), dims, normalsOut, determinantsOut);
      }
    }
    else
    {
      this->LaunchGeneric<Real>(this->Displacements.As<Real>(), dims, normalsOut, determinantsOut);
    }
    Check(cudaGetLastError(), "launching the evaluation");
    Check(cudaEventRecord(this->KernelStop, this->Stream), "recording an event");
    Check(cudaStreamSynchronize(this->Stream), "evaluating");
    Check(cudaEventElapsedTime(&this->Counts.LastKernelMilliseconds, this->KernelStart, this->KernelStop),
      "timing the evaluation");
    this->Evaluated = true;
    this->EvaluatedNormals = withNormals;
    this->EvaluatedDeterminants = withDeterminants;
    ++this->Counts.Evaluations;
  }

  // Calls launch(maxCount, basis) with the basis as a compile-time constant (one kernel per basis, see
  // ffd::GridDeformation's StaticBasis) and the most control points per axis that influence a point: every one
  // for the global basis, at most 4 for a local one.
  template <typename Launch>
  void WithStaticBasis(Launch&& launch)
  {
    using ffd::GridBasis;
    using Local = std::integral_constant<int, 4>;
    switch (this->Basis)
    {
      case GridBasis::Bernstein:
        launch(std::integral_constant<int, ffd::MaxBernsteinDegree + 1>(),
          std::integral_constant<int, int(GridBasis::Bernstein)>());
        break;
      case GridBasis::Trilinear:
        launch(Local(), std::integral_constant<int, int(GridBasis::Trilinear)>());
        break;
      case GridBasis::TriquadraticBezier:
        launch(Local(), std::integral_constant<int, int(GridBasis::TriquadraticBezier)>());
        break;
      case GridBasis::TricubicBezier:
        launch(Local(), std::integral_constant<int, int(GridBasis::TricubicBezier)>());
        break;
      case GridBasis::CubicBSpline:
        launch(Local(), std::integral_constant<int, int(GridBasis::CubicBSpline)>());
        break;
    }
  }

  // DeformKernel on a lattice of 3 numbers per control point: with the Jacobian, float64 points, and float32
  // points without the Jacobian on the local bases of 3 or 4 control points per axis.
  template <typename Real>
  void LaunchGeneric(const Real* d, const int dims[3], float* normalsOut, Real* determinantsOut)
  {
    const ffd::Frame<Real> frame = ffd::Frame<Real>::FromArray(this->Frame);
    this->WithStaticBasis([&](auto maxCount, auto basis) {
      using Deformer = ffd::GridDeformation<decltype(maxCount)::value, Real, decltype(basis)::value>;
      const Deformer deformation{ this->Basis, { this->Divisions[0], this->Divisions[1], this->Divisions[2] },
        { dims[0], dims[1], dims[2] }, d, frame };
      if (normalsOut || determinantsOut)
      {
        DeformKernel<Deformer, Real, true><<<BlocksFor(this->Count), ThreadsPerBlock, 0, this->Stream>>>(
          this->Points.As<Real>(), this->Cells.As<int>(), this->Count, deformation, this->OutPoints.As<Real>(),
          this->Normals.As<float>(), normalsOut, determinantsOut);
      }
      else
      {
        DeformKernel<Deformer, Real, false><<<BlocksFor((this->Count + 3) / 4), ThreadsPerBlock, 0, this->Stream>>>(
          this->Points.As<Real>(), this->Cells.As<int>(), this->Count, deformation, this->OutPoints.As<Real>(),
          nullptr, nullptr, nullptr);
      }
    });
  }

  // Float32 without the Jacobian on the float4 lattice (trilinear and the global basis): the global basis's own
  // kernels where they apply (LaunchBernstein), otherwise DeformPointsKernel.
  void LaunchFloat4(const float4* d, const int dims[3])
  {
    const ffd::Frame<float> frame = ffd::Frame<float>::FromArray(this->Frame);
    const CellSplit split = CellSplit::For(this->Basis, this->Divisions);
    auto launch = [&](auto maxCount, auto basis) {
      using Deformer = ffd::GridDeformation<decltype(maxCount)::value, float4, decltype(basis)::value, float>;
      const Deformer deformation{ this->Basis, { this->Divisions[0], this->Divisions[1], this->Divisions[2] },
        { dims[0], dims[1], dims[2] }, d, frame };
      DeformPointsKernel<Deformer><<<BlocksFor((this->Count + 3) / 4), ThreadsPerBlock, 0, this->Stream>>>(
        this->Points.As<float>(), this->Cells.As<int>(), this->Count, deformation, split, this->OutPoints.As<float>());
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
  // lattices (H200, G points/s, BernsteinKernel against BernsteinTensorKernel: 6^3 16 against 11.5, 7^3 11.0
  // against 10.8, 8^3 8.4 against 10.1). False otherwise.
  bool LaunchBernstein(const float4* displacements, const int dims[3])
  {
    const int largest = std::max(dims[0], std::max(dims[1], dims[2]));
    if (largest > 16)
    {
      return false;
    }
    const ffd::Frame<float> frame = ffd::Frame<float>::FromArray(this->Frame);
    const int controlPoints = dims[0] * dims[1] * dims[2];
    bool tensor = controlPoints >= 400;
    if (tensor)
    {
      const int ks = (dims[0] + 7) / 8, nt = (3 * dims[1] + 7) / 8;
      const std::size_t shared = TensorSharedBytes(ks, nt, dims[2]);
      auto launch = [&](auto ksConstant, auto ntConstant) {
        const auto kernel = BernsteinTensorKernel<decltype(ksConstant)::value, decltype(ntConstant)::value>;
        cudaFuncAttributes attributes;
        Check(cudaFuncGetAttributes(&attributes, kernel), "querying the evaluation kernel");
        if (attributes.binaryVersion < 80)
        {
          tensor = false; // built for a device without TF32 tensor cores
          return;
        }
        Check(cudaFuncSetAttribute(kernel, cudaFuncAttributeMaxDynamicSharedMemorySize, int(shared)),
          "allowing the evaluation's shared memory");
        int perMultiprocessor = 0;
        Check(cudaOccupancyMaxActiveBlocksPerMultiprocessor(&perMultiprocessor, kernel, 32 * TensorWarps, shared),
          "sizing the evaluation");
        const std::int64_t tiles = (this->Count + TensorTilePoints - 1) / TensorTilePoints;
        const std::int64_t blocks = std::min<std::int64_t>(std::int64_t(std::max(perMultiprocessor, 1)) *
            this->Multiprocessors, (tiles + TensorWarps - 1) / TensorWarps);
        kernel<<<unsigned(blocks), 32 * TensorWarps, shared, this->Stream>>>(this->Points.As<float>(),
          this->Cells.As<int>(), this->Count, frame, dims[0], dims[1], dims[2], displacements,
          this->OutPoints.As<float>());
      };
      auto withNT = [&](auto ksConstant) {
        switch (nt)
        {
          case 1: launch(ksConstant, std::integral_constant<int, 1>()); break;
          case 2: launch(ksConstant, std::integral_constant<int, 2>()); break;
          case 3: launch(ksConstant, std::integral_constant<int, 3>()); break;
          case 4: launch(ksConstant, std::integral_constant<int, 4>()); break;
          case 5: launch(ksConstant, std::integral_constant<int, 5>()); break;
          default: launch(ksConstant, std::integral_constant<int, 6>()); break;
        }
      };
      if (ks == 1)
      {
        withNT(std::integral_constant<int, 1>());
      }
      else
      {
        withNT(std::integral_constant<int, 2>());
      }
    }
    if (tensor)
    {
      return true;
    }
    const std::size_t shared = std::size_t(controlPoints) * sizeof(float4);
    if (shared > 48 * 1024)
    {
      return false;
    }
    const unsigned blocks = unsigned((this->Count + 4 * ThreadsPerBlock - 1) / (4 * ThreadsPerBlock));
    // The smaller instantiation that holds the lattice's axes. (A third one, for up to 12 control points per
    // axis, made 11^3 lattices slower: 3.4 instead of 3.6 G points/s on an H200.)
    auto launch = [&](auto maxCount) {
      BernsteinKernel<decltype(maxCount)::value><<<blocks, ThreadsPerBlock, shared, this->Stream>>>(
        this->Points.As<float>(), this->Cells.As<int>(), this->Count, frame, dims[0], dims[1], dims[2],
        displacements, this->OutPoints.As<float>());
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

  template <typename Real>
  void RunDownload(Real* outPoints, float* outNormals, Real* outDeterminants)
  {
    if (!this->Evaluated || (this->IsDouble != (sizeof(Real) == sizeof(double))) ||
      (outNormals && !this->EvaluatedNormals) || (outDeterminants && !this->EvaluatedDeterminants))
    {
      throw CudaError{ cudaErrorInvalidValue, "downloading: nothing of that was evaluated" };
    }
    this->Staging[0].Reserve(StagingBytes, "allocating the staging buffers");
    this->Staging[1].Reserve(StagingBytes, "allocating the staging buffers");
    this->Download(this->OutPoints.Data, outPoints, std::size_t(this->Count) * 3 * sizeof(Real));
    if (outNormals)
    {
      this->Download(this->OutNormals.Data, outNormals, std::size_t(this->Count) * 3 * sizeof(float));
    }
    if (outDeterminants)
    {
      this->Download(this->OutDeterminants.Data, outDeterminants, std::size_t(this->Count) * sizeof(Real));
    }
  }
};

//------------------------------------------------------------------------------------------------------------
GridDeformer::GridDeformer()
  : P(new Impl)
{
}

GridDeformer::~GridDeformer()
{
  this->P->Release();
}

bool GridDeformer::SetPoints(const float* xyz, std::int64_t count)
{
  return this->P->Guard([&] { this->P->Upload(xyz, count); });
}

bool GridDeformer::SetPoints(const double* xyz, std::int64_t count)
{
  return this->P->Guard([&] { this->P->Upload(xyz, count); });
}

bool GridDeformer::SetNormals(const float* normals)
{
  return this->P->Guard([&] {
    const std::size_t bytes = std::size_t(this->P->Count) * 3 * sizeof(float);
    this->P->Normals.Reserve(bytes, "allocating the normals");
    Check(cudaMemcpy(this->P->Normals.Data, normals, bytes, cudaMemcpyHostToDevice), "uploading the normals");
    this->P->HasNormals = true;
    ++this->P->Counts.NormalUploads;
  });
}

bool GridDeformer::Bind(const double frame[12], int basis, const int divisions[3], bool clampOutside)
{
  return this->P->Guard([&] {
    Impl& p = *this->P;
    if (p.Count == 0 || !ffd::IsGridBasis(basis))
    {
      throw CudaError{ cudaErrorInvalidValue, "binding: no points, or an unknown basis" };
    }
    std::copy(frame, frame + 12, p.Frame);
    std::copy(divisions, divisions + 3, p.Divisions);
    p.Basis = static_cast<ffd::GridBasis>(basis);
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

bool GridDeformer::Evaluate(const double* displacements, std::int64_t controlPoints, bool withNormals,
  bool withDeterminants)
{
  return this->P->Guard([&] {
    if (this->P->IsDouble)
    {
      this->P->RunEvaluate<double>(displacements, controlPoints, withNormals, withDeterminants);
    }
    else
    {
      this->P->RunEvaluate<float>(displacements, controlPoints, withNormals, withDeterminants);
    }
  });
}

bool GridDeformer::Download(float* outPoints, float* outNormals, float* outDeterminants)
{
  return this->P->Guard([&] { this->P->RunDownload(outPoints, outNormals, outDeterminants); });
}

bool GridDeformer::Download(double* outPoints, float* outNormals, double* outDeterminants)
{
  return this->P->Guard([&] { this->P->RunDownload(outPoints, outNormals, outDeterminants); });
}

void GridDeformer::Release()
{
  this->P->Release();
}

const std::string& GridDeformer::GetLastError() const
{
  return this->P->LastError;
}

const Counters& GridDeformer::GetCounters() const
{
  return this->P->Counts;
}

} // namespace cuda
} // namespace ffd
