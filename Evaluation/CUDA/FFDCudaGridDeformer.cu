// SPDX-License-Identifier: BSD-3-Clause
#include "FFDCudaGridDeformer.h"

#include "FFDCudaBernsteinKernels.cuh"
#include "FFDCudaCellTableKernels.cuh"
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
using detail::BernsteinKernel;
using detail::BernsteinTensorKernel;
using detail::BlocksFor;
using detail::CellTableDeformation;
using detail::Check;
using detail::CudaError;
using detail::FillCellTableKernel;
using detail::TableTileCells;
using detail::TensorSharedBytes;
using detail::TensorTilePoints;
using detail::TensorWarps;
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

} // namespace

//------------------------------------------------------------------------------------------------------------
struct GridDeformer::Impl : ResidentPoints::State
{
  ffd::GridBasis Basis = ffd::GridBasis::Bernstein;
  int Divisions[3] = { 0, 0, 0 };
  double Frame[12] = {};
  // A sparse lattice's cells (BindSparse()); SparseControlPoints is 0 for a dense lattice.
  Buffer CellVoxels, CellSupports;
  std::int64_t SparseControlPoints = 0, SparseCells = 0;
  Buffer CellTable; // FillCellTable() of the last evaluation's lattice, where it took one
  bool CellTablesAllowed = true;
  std::unique_ptr<detail::AdjointPlan> Plan; // the adjoint's, made for the binding it names

  void Release() override
  {
    this->Plan.reset();
    this->CellTable.Free();
    this->State::Release();
  }

  // The cells of the bound lattice: its voxels, a sparse lattice's cells, one for the global basis.
  std::int64_t LatticeCells() const
  {
    if (this->SparseControlPoints > 0)
    {
      return this->SparseCells;
    }
    std::int64_t cells = 1;
    for (int a = 0; a < 3; ++a)
    {
      cells *= ffd::BindingCells(this->Basis, this->Divisions[a]);
    }
    return cells;
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
    this->SparseCells = cells;
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
    if (this->CellTablesAllowed && GridDeformer::WorthCellTable(int(this->Basis), this->LatticeCells(), this->Count))
    {
      this->LaunchFromCellTable<Real>(this->Lattice.As<Real>(), dims, normalsOut, determinantsOut);
      this->FinishEvaluation(withNormals, withDeterminants, true);
      ++this->Counts.CellTables;
      return;
    }
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
    int counts[3];
    for (int a = 0; a < 3; ++a)
    {
      counts[a] = ffd::SupportSize(this->Basis, this->Divisions[a]);
    }
    detail::MakeAdjointPlan(plan, counts, this->Cells.As<int>(), this->Count, controlPoints, sizeof(Real), this->Stream,
      [&](std::int64_t terms)
      {
        detail::AdjointTermKernel<Deformation, Real, MaxCount><<<BlocksFor(terms), ThreadsPerBlock, 0, this->Stream>>>(
          this->Points.As<Real>(), plan.Order.As<int>(), plan.ChunkStart.As<std::int64_t>(), plan.ChunkCell.As<int>(),
          terms, counts[0], counts[1], counts[2], deformation, plan.Keys.As<int>(), plan.Values.As<int>());
      });
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

  // The triquadratic or a cubic lattice d through its cell table: the table built (FillCellTableKernel),
  // then every point in power form, four of one cell together where the points go alone (no Jacobian).
  template <typename Real>
  void LaunchFromCellTable(const Real* d, const int dims[3], Real* normalsOut, Real* determinantsOut)
  {
    const std::int64_t cells = this->LatticeCells();
    const int stride = ffd::CellTableStride(ffd::CellDegree(this->Basis));
    this->CellTable.Reserve(std::size_t(cells) * stride * sizeof(Real), "allocating the cell table");
    const ffd::Frame<Real> frame = ffd::Frame<Real>::FromArray(this->Frame);
    auto launch = [&](auto basis)
    {
      constexpr ffd::GridBasis Basis = ffd::GridBasis(decltype(basis)::value);
      this->WithStorage<int(Basis)>(
        [&](auto storage)
        {
          using Deformation = ffd::GridDeformation<4, Real, int(Basis), Real, true, decltype(storage)::value>;
          Deformation deformation = this->WithCells(Deformation{ this->Basis,
            { this->Divisions[0], this->Divisions[1], this->Divisions[2] }, { dims[0], dims[1], dims[2] }, d, frame });
          deformation.CellTable = this->CellTable.As<Real>();
          const unsigned tiles = unsigned((cells + TableTileCells<Real> - 1) / TableTileCells<Real>);
          FillCellTableKernel<Basis, Real><<<tiles, 3 * TableTileCells<Real>, 0, this->Stream>>>(d,
            make_int3(this->Divisions[0], this->Divisions[1], this->Divisions[2]), make_int3(dims[0], dims[1], dims[2]),
            deformation.CellVoxels, deformation.CellSupports, int(cells), this->CellTable.As<Real>());
          this->LatticeKernelsDone();
          if (!normalsOut && !determinantsOut)
          {
            constexpr int minBlocks = std::is_same<Real, float>::value ? 3 : 2;
            detail::LaunchDeformPoints<true, minBlocks>(CellTableDeformation<Deformation>{ deformation },
              this->Points.As<Real>(), this->Cells.As<int>(), this->Count, this->OutPoints.As<Real>(), this->Stream);
            return;
          }
          detail::LaunchDeform(deformation, this->Points.As<Real>(), this->Cells.As<int>(), this->Count,
            this->OutPoints.As<Real>(), this->Normals.As<Real>(), normalsOut, determinantsOut, this->Stream);
        });
    };
    if (this->Basis == ffd::GridBasis::TriquadraticBezier)
    {
      launch(std::integral_constant<int, int(ffd::GridBasis::TriquadraticBezier)>());
    }
    else if (this->Basis == ffd::GridBasis::TricubicBezier)
    {
      launch(std::integral_constant<int, int(ffd::GridBasis::TricubicBezier)>());
    }
    else
    {
      launch(std::integral_constant<int, int(ffd::GridBasis::CubicBSpline)>());
    }
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

void GridDeformer::SetCellTables(bool allowed)
{
  static_cast<Impl&>(*this->S).CellTablesAllowed = allowed;
}

bool GridDeformer::WorthCellTable(int basis, std::int64_t cells, std::int64_t points)
{
  const bool powerForm = ffd::IsGridBasis(basis) && ffd::CellDegree(ffd::GridBasis(basis)) > 1;
  return powerForm && cells > 0 && cells <= points / 64;
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
