// SPDX-License-Identifier: BSD-3-Clause
// GPU benchmark of the CUDA backend's kernels (ffd::cuda::GridDeformer): points per second of the evaluation of
// every grid basis for 1 M, 16 M and 64 M points, float32 and float64, the triquadratic and cubic bases
// from cell tables and as weighted sums side by side, beside the device-to-device copy bandwidth measured in the
// same run: the fraction of the bandwidth roofline each evaluation reaches (bytes it must move: the point and its
// 4-byte binding in, the deformed point out) and of the multiply-add peak (multiply-adds counted from the
// kernels); the float32 accuracy of the global basis against float64; the tetrahedral lattices' evaluation
// (ffd::cuda::TetrahedralDeformer) for 1 M and 16 M points in about 10 k and 100 k tetrahedra, float32 and
// float64, beside the trilinear grid's in the same run, with what an update would cost if it uploaded the
// tetrahedra's maps instead of the nodes' displacements. Last, the adjoint (W^T g) of every basis beside its
// forward evaluation, for 1 M and 16 M points. The host side (end-to-end updates, a billion points) is
// BenchmarkFFDCudaTransfers's.
// It prints tables and asserts nothing. Options: --quick (1 M points only), --grid, --tetrahedra, --adjoint (that
// section alone), --profile (each grid evaluation of 16 M points once, for Nsight Compute).
#include "FFDBenchmarkUtilities.h"
#include "FFDCudaGridDeformer.h"
#include "FFDCudaTestSupport.h"
#include "FFDCudaTetrahedralDeformer.h"
#include "FFDGridBasis.h"

#include <cuda_runtime.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <random>
#include <string>
#include <vector>

namespace
{
void Require(bool ok, const ffd::cuda::ResidentPoints& gpu, const char* what)
{
  if (!ok)
  {
    std::fprintf(stderr, "%s failed: %s\n", what, gpu.GetLastError().c_str());
    std::exit(1);
  }
}

void RequireCuda(cudaError_t code, const char* what)
{
  if (code != cudaSuccess)
  {
    std::fprintf(stderr, "%s failed: %s\n", what, cudaGetErrorString(code));
    std::exit(1);
  }
}

// Device-to-device copy bandwidth, bytes read plus written per second, best of 10 on 1 GiB.
double CopyBandwidth()
{
  const std::size_t bytes = std::size_t(1) << 30;
  void *a = nullptr, *b = nullptr;
  RequireCuda(cudaMalloc(&a, bytes), "cudaMalloc");
  RequireCuda(cudaMalloc(&b, bytes), "cudaMalloc");
  RequireCuda(cudaMemset(a, 1, bytes), "cudaMemset");
  cudaEvent_t start, stop;
  cudaEventCreate(&start);
  cudaEventCreate(&stop);
  float best = 1e30f;
  for (int r = 0; r < 10; ++r)
  {
    cudaEventRecord(start);
    cudaMemcpy(b, a, bytes, cudaMemcpyDeviceToDevice);
    cudaEventRecord(stop);
    cudaEventSynchronize(stop);
    float ms = 0;
    cudaEventElapsedTime(&ms, start, stop);
    best = std::min(best, ms);
  }
  cudaFree(a);
  cudaFree(b);
  return 2.0 * bytes / (best * 1e-3);
}

// What the device can do, measured or from its properties: the device-to-device copy bandwidth (bytes read plus
// written per second) and the multiply-add peaks of its CUDA cores (128 float32 and 64 float64 lanes a
// multiprocessor on sm_90, at the clock the device reports).
struct Device
{
  double Bandwidth, Float32MultiplyAdds, Float64MultiplyAdds;
};

Device MeasureDevice(const cudaDeviceProp& prop)
{
  int kilohertz = 0;
  RequireCuda(cudaDeviceGetAttribute(&kilohertz, cudaDevAttrClockRate, 0), "cudaDeviceGetAttribute");
  const double lanes = double(prop.multiProcessorCount) * kilohertz * 1e3;
  return { CopyBandwidth(), 128 * lanes, 64 * lanes };
}

const double Frame[12] = { -1.0, -1.5, -0.5, 2.0, 0.0, 0.0, 0.0, 3.0, 0.0, 0.0, 0.0, 1.0 };

struct Case
{
  ffd::GridBasis Basis;
  const char* Name;
  int Divisions;
};

// Points uniformly distributed in the frame. In voxel order (the default) consecutive points lie in the same or
// neighbouring voxels of a 32^3 grid, as consecutive vertices of a mesh do; otherwise in random order, the worst
// case for the caches that serve the lattice.
std::vector<double> RandomPoints(std::int64_t count, std::mt19937& rng, bool voxelOrder = true)
{
  const ffd::Frame<double> frame = ffd::Frame<double>::FromArray(Frame);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const std::int64_t cells = 32 * 32 * 32;
  std::vector<double> points(3 * count);
  for (std::int64_t i = 0; i < count; ++i)
  {
    ffd::Vec3<double> p = { u(rng), u(rng), u(rng) };
    if (voxelOrder)
    {
      const std::int64_t c = i * cells / count;
      p = { (double(c % 32) + p.x) / 32, (double((c / 32) % 32) + p.y) / 32, (double(c / 1024) + p.z) / 32 };
    }
    const ffd::Vec3<double> x = frame.ToWorld(p);
    points[3 * i] = x.x;
    points[3 * i + 1] = x.y;
    points[3 * i + 2] = x.z;
  }
  return points;
}

std::vector<double> RandomDisplacements(const Case& c, std::mt19937& rng)
{
  std::int64_t n = 1;
  for (int a = 0; a < 3; ++a)
  {
    n *= ffd::ControlPointsAlongAxis(c.Basis, c.Divisions);
  }
  std::uniform_real_distribution<double> d(-0.1, 0.1);
  std::vector<double> v(3 * n);
  for (double& x : v)
  {
    x = d(rng);
  }
  return v;
}
// Kernel times of `evaluate` (median of 20 after a warm-up): the whole call, the lattice's kernels, the points'.
struct Times
{
  double Call, Lattice, Points;
};

template <typename Evaluate>
Times TimeEvaluations(const ffd::cuda::ResidentPoints& gpu, Evaluate&& evaluate, int runs = 20)
{
  evaluate();
  std::vector<double> lattice, points;
  const double call = MedianSeconds(runs,
    [&]
    {
      evaluate();
      lattice.push_back(gpu.GetCounters().LastLatticeKernelMilliseconds * 1e-3);
      points.push_back(gpu.GetCounters().LastKernelMilliseconds * 1e-3);
    });
  return { call, Median(lattice), Median(points) };
}

// TimeEvaluations() of the grid's evaluation of `displacements` into its resident points.
// With the Jacobian: the normals transformed and det J too (SetNormals() first).
Times TimeGridEvaluation(
  ffd::cuda::GridDeformer& gpu, const std::vector<double>& displacements, int runs = 20, bool withJacobian = false)
{
  const std::int64_t controlPoints = std::int64_t(displacements.size() / 3);
  return TimeEvaluations(
    gpu,
    [&] { Require(gpu.Evaluate(displacements.data(), controlPoints, withJacobian, withJacobian), gpu, "Evaluate"); },
    runs);
}

template <typename Real>
const char* PrecisionName()
{
  return sizeof(Real) == sizeof(float) ? "float32" : "float64";
}

// Multiply-adds a point of an evaluation without the Jacobian, counted from the kernels: the parametric coordinates
// (9), then the weighted sum over n control points an axis, 3 (n^3 + n^2 + n), or from a cell table the local
// coordinates (3) and Horner's rule over the cell's n^3 monomials, 3 (n^3 - 1). The weights are not counted (about
// 10 operations an axis), nor the global basis's tensor cores (its count is that of the same sum on CUDA cores).
int MultiplyAdds(ffd::GridBasis basis, int divisions, bool cellTable)
{
  const int n = ffd::SupportSize(basis, divisions);
  return 9 + (cellTable ? 3 + 3 * (n * n * n - 1) : 3 * (n * n * n + n * n + n));
}

// One row of the grid table. Bytes a point must move: the point and its 4-byte binding in, the point out (and with
// the Jacobian its normal in and out and det J out); rates from the kernels' time, the cell table's included.
// multiplyAdds 0: not counted (the Jacobian's rows).
template <typename Real>
void PrintGridRow(const char* basis, const char* variant, std::int64_t n, const Times& t, const Device& device,
  int multiplyAdds, bool withJacobian = false)
{
  const double seconds = t.Lattice + t.Points;
  const double bytes = double(n) * ((withJacobian ? 13 : 6) * sizeof(Real) + 4);
  if (multiplyAdds == 0)
  {
    std::printf("| %s%s | %s | %lld | %.3f | %.3f | %.3f | %.2f | %.0f %% | | |\n", basis, variant,
      PrecisionName<Real>(), static_cast<long long>(n), t.Call * 1e3, t.Lattice * 1e3, t.Points * 1e3,
      n / seconds * 1e-9, 100.0 * bytes / seconds / device.Bandwidth);
    return;
  }
  const double peak = sizeof(Real) == sizeof(float) ? device.Float32MultiplyAdds : device.Float64MultiplyAdds;
  std::printf("| %s%s | %s | %lld | %.3f | %.3f | %.3f | %.2f | %.0f %% | %d | %.0f %% |\n", basis, variant,
    PrecisionName<Real>(), static_cast<long long>(n), t.Call * 1e3, t.Lattice * 1e3, t.Points * 1e3, n / seconds * 1e-9,
    100.0 * bytes / seconds / device.Bandwidth, multiplyAdds, 100.0 * n * multiplyAdds / seconds / peak);
}

// The grid table's rows for points in voxel order in the precision Real: every basis (the global one in float32
// only), the triquadratic and cubic bases from cell tables and as weighted sums, side by side on the same points;
// `runs` evaluations a row (median); with the Jacobian, normals transformed and det J too.
template <typename Real>
void GridSection(const Case* cases, std::size_t caseCount, const std::vector<std::int64_t>& sizes, const Device& device,
  int runs, std::mt19937& rng, bool withJacobian = false)
{
  for (std::int64_t n : sizes)
  {
    const std::vector<double> points64 = RandomPoints(n, rng);
    const std::vector<Real> points(points64.begin(), points64.end());
    for (std::size_t k = 0; k < caseCount; ++k)
    {
      const Case& c = cases[k];
      if (sizeof(Real) == sizeof(double) && c.Basis == ffd::GridBasis::Bernstein)
      {
        continue;
      }
      const std::vector<double> displacements = RandomDisplacements(c, rng);
      const int divisions[3] = { c.Divisions, c.Divisions, c.Divisions };
      ffd::cuda::GridDeformer gpu;
      Require(gpu.SetPoints(points.data(), n) && gpu.Bind(Frame, int(c.Basis), divisions, false), gpu, "Bind");
      if (withJacobian)
      {
        std::vector<Real> normals(points.size(), Real(0));
        for (std::size_t v = 2; v < normals.size(); v += 3)
        {
          normals[v] = Real(1);
        }
        Require(gpu.SetNormals(normals.data()), gpu, "SetNormals");
      }
      const std::int64_t cells = std::int64_t(c.Divisions) * c.Divisions * c.Divisions;
      const bool worthTable = ffd::cuda::GridDeformer::WorthCellTable(int(c.Basis), cells, n);
      for (bool table : { true, false })
      {
        gpu.SetCellTables(table);
        const Times t = TimeGridEvaluation(gpu, displacements, runs, withJacobian);
        const bool takesTable = table && worthTable;
        const std::string variant = std::string(withJacobian ? ", normals and det J" : "") +
          (takesTable ? ", cell table" : (worthTable ? ", weighted sum" : ""));
        PrintGridRow<Real>(c.Name, variant.c_str(), n, t, device,
          withJacobian ? 0 : MultiplyAdds(c.Basis, c.Divisions, takesTable), withJacobian);
        if (!worthTable)
        {
          break; // no table to compare with
        }
      }
    }
  }
}

// One row of the tetrahedral table. Bytes a point must move: the point and its 4-byte binding in, the point out.
template <typename Real>
void PrintRow(const char* lattice, std::int64_t n, const Times& t, double bandwidth)
{
  const double bytes = double(n) * (2 * 3 * sizeof(Real) + 4);
  std::printf("| %s | %s | %lld | %.3f | %.3f | %.3f | %.2f | %.0f %% | %.2f |\n", lattice, PrecisionName<Real>(),
    static_cast<long long>(n), t.Call * 1e3, t.Lattice * 1e3, t.Points * 1e3, n / t.Points * 1e-9,
    100.0 * bytes / t.Points / bandwidth, n / (t.Lattice + t.Points) * 1e-9);
}

// Trilinear over 32^3 voxels and tetrahedral lattices of 10 368 and 105 456 tetrahedra (jittered cubes, 6 each)
// on the same points count and precision; points in voxel / mesh order.
template <typename Real>
void TetrahedraSection(const std::vector<std::int64_t>& sizes, double bandwidth, std::mt19937& rng)
{
  const int cubes[] = { 12, 26 };
  std::vector<ffdtest::TetrahedralMesh> meshes;
  for (int n : cubes)
  {
    meshes.push_back(ffdtest::JitteredTetrahedra(n, rng));
  }
  for (std::int64_t n : sizes)
  {
    {
      const Case c = { ffd::GridBasis::Trilinear, "TRILINEAR 32^3 vox", 32 };
      const std::vector<double> points64 = RandomPoints(n, rng);
      const std::vector<Real> points(points64.begin(), points64.end());
      const std::vector<double> displacements = RandomDisplacements(c, rng);
      const int divisions[3] = { c.Divisions, c.Divisions, c.Divisions };
      ffd::cuda::GridDeformer gpu;
      Require(gpu.SetPoints(points.data(), n) && gpu.Bind(Frame, int(c.Basis), divisions, false), gpu, "Bind");
      const Times t = TimeEvaluations(gpu,
        [&]
        {
          Require(
            gpu.Evaluate(displacements.data(), std::int64_t(displacements.size() / 3), false, false), gpu, "Evaluate");
        });
      PrintRow<Real>(c.Name, n, t, bandwidth);
    }
    for (const ffdtest::TetrahedralMesh& mesh : meshes)
    {
      std::vector<double> points64;
      std::vector<int> cells;
      ffdtest::PointsInTetrahedra(mesh, n, true, rng, points64, cells);
      const std::vector<Real> points(points64.begin(), points64.end());
      points64 = std::vector<double>();
      const std::vector<ffd::Frame<double>> frames = mesh.RestFrames();
      std::uniform_real_distribution<double> d(-0.02, 0.02);
      std::vector<double> displacements(mesh.Nodes.size());
      for (double& v : displacements)
      {
        v = d(rng);
      }
      ffd::cuda::TetrahedralDeformer gpu;
      Require(gpu.SetPoints(points.data(), n) &&
          gpu.Bind(
            cells.data(), frames.data(), mesh.Tetrahedra.data(), mesh.NumberOfTetrahedra(), mesh.NumberOfNodes()),
        gpu, "Bind");
      const Times t = TimeEvaluations(
        gpu, [&] { Require(gpu.Evaluate(displacements.data(), mesh.NumberOfNodes(), false, false), gpu, "Evaluate"); });
      const std::string name = "TETRAHEDRA " + std::to_string(mesh.NumberOfTetrahedra());
      PrintRow<Real>(name.c_str(), n, t, bandwidth);
    }
  }
}

// What an update uploads: the nodes' displacements (the maps are built on the device), against the maps
// computed on the host (one thread) and uploaded from pageable memory, as the CPU path holds them.
template <typename Real>
void UpdateCostSection(std::mt19937& rng)
{
  for (int cubes : { 12, 26 })
  {
    const ffdtest::TetrahedralMesh mesh = ffdtest::JitteredTetrahedra(cubes, rng);
    const std::vector<ffd::Frame<double>> frames = mesh.RestFrames();
    std::uniform_real_distribution<double> d(-0.02, 0.02);
    std::vector<double> displacements(mesh.Nodes.size());
    for (double& v : displacements)
    {
      v = d(rng);
    }
    const std::int64_t tetrahedra = mesh.NumberOfTetrahedra();
    std::vector<int> cells(1024, 0);
    std::vector<Real> points(3 * cells.size(), Real(0));
    ffd::cuda::TetrahedralDeformer gpu;
    Require(gpu.SetPoints(points.data(), std::int64_t(cells.size())) &&
        gpu.Bind(cells.data(), frames.data(), mesh.Tetrahedra.data(), tetrahedra, mesh.NumberOfNodes()),
      gpu, "Bind");
    const Times t = TimeEvaluations(
      gpu, [&] { Require(gpu.Evaluate(displacements.data(), mesh.NumberOfNodes(), false, false), gpu, "Evaluate"); });

    std::vector<ffd::TetrahedronMap<Real>> maps(tetrahedra);
    const double host = MedianSeconds(20,
      [&]
      {
        for (std::int64_t k = 0; k < tetrahedra; ++k)
        {
          auto node = [&](int corner)
          { return ffd::Vec3<double>::From(displacements.data() + 3 * mesh.Tetrahedra[4 * k + corner]); };
          maps[k] = ffd::MakeTetrahedronMap(frames[k], node(0), node(1), node(2), node(3)).template As<Real>();
        }
      });
    const std::size_t mapBytes = maps.size() * sizeof(ffd::TetrahedronMap<Real>);
    void* device = nullptr;
    RequireCuda(cudaMalloc(&device, mapBytes), "cudaMalloc");
    const double upload = MedianSeconds(
      20, [&] { RequireCuda(cudaMemcpy(device, maps.data(), mapBytes, cudaMemcpyHostToDevice), "cudaMemcpy"); });
    cudaFree(device);
    std::printf("| %lld | %lld | %s | %.0f | %.3f (maps kernel %.3f) | %.0f | %.3f + %.3f = %.3f |\n",
      static_cast<long long>(tetrahedra), static_cast<long long>(mesh.NumberOfNodes()), PrecisionName<Real>(),
      mesh.NumberOfNodes() * 24 / 1024.0, t.Call * 1e3, t.Lattice * 1e3, mapBytes / 1024.0, host * 1e3, upload * 1e3,
      (host + upload) * 1e3);
  }
}

void Tetrahedra(const std::vector<std::int64_t>& sizes, double bandwidth, std::mt19937& rng)
{
  std::printf("\nTetrahedral lattices beside the trilinear grid, same device and run, points in mesh (voxel) order, "
              "median of 20: the whole Evaluate() call (nodes' upload, maps kernel, points kernel, synchronize), "
              "each kernel (CUDA events); rates from the points kernel, the last column from both kernels\n");
  std::printf("| lattice | precision | points | Evaluate() ms | maps kernel ms | points kernel ms | G points/s | "
              "%% of copy roofline | G points/s with maps |\n"
              "|---|---|---:|---:|---:|---:|---:|---:|---:|\n");
  TetrahedraSection<float>(sizes, bandwidth, rng);
  TetrahedraSection<double>(sizes, bandwidth, rng);

  std::printf("\nAn update's lattice: the nodes' displacements uploaded and the maps built on the device (Evaluate() "
              "of 1024 points, median of 20), against the maps built on the host (1 thread) and uploaded from "
              "pageable memory (cudaMemcpy)\n");
  std::printf("| tetrahedra | nodes | precision | nodes KiB | Evaluate() ms | maps KiB | host maps + upload ms |\n"
              "|---:|---:|---|---:|---:|---:|---:|\n");
  UpdateCostSection<float>(rng);
  UpdateCostSection<double>(rng);

  // End to end: evaluation and download of 1 M float32 points in 10 368 tetrahedra, against the bare download.
  const std::int64_t n = std::int64_t(1) << 20;
  const ffdtest::TetrahedralMesh mesh = ffdtest::JitteredTetrahedra(12, rng);
  std::vector<double> points64;
  std::vector<int> cells;
  ffdtest::PointsInTetrahedra(mesh, n, true, rng, points64, cells);
  const std::vector<float> points(points64.begin(), points64.end());
  const std::vector<ffd::Frame<double>> frames = mesh.RestFrames();
  const std::vector<double> displacements(mesh.Nodes.size(), 0.01);
  ffd::cuda::TetrahedralDeformer gpu;
  Require(gpu.SetPoints(points.data(), n) &&
      gpu.Bind(cells.data(), frames.data(), mesh.Tetrahedra.data(), mesh.NumberOfTetrahedra(), mesh.NumberOfNodes()),
    gpu, "Bind");
  std::vector<float> out(points.size());
  Require(gpu.Evaluate(displacements.data(), mesh.NumberOfNodes(), false, false), gpu, "Evaluate");
  const double endToEnd = MedianSeconds(20,
    [&]
    {
      Require(gpu.Evaluate(displacements.data(), mesh.NumberOfNodes(), false, false) &&
          gpu.Download(out.data(), nullptr, nullptr),
        gpu, "Evaluate");
    });
  void* device = nullptr;
  RequireCuda(cudaMalloc(&device, points.size() * sizeof(float)), "cudaMalloc");
  const double bare = MedianSeconds(20,
    [&] {
      RequireCuda(cudaMemcpy(out.data(), device, points.size() * sizeof(float), cudaMemcpyDeviceToHost), "cudaMemcpy");
    });
  cudaFree(device);
  std::printf("\nEnd-to-end update of %lld float32 points in %lld tetrahedra (nodes' upload + maps + evaluation + "
              "download into pageable memory) against the bare download, median of 20: %.3f ms vs %.3f ms, "
              "ratio %.2f\n",
    static_cast<long long>(n), static_cast<long long>(mesh.NumberOfTetrahedra()), endToEnd * 1e3, bare * 1e3,
    endToEnd / bare);
}
} // namespace

// The adjoint W^T g (GridDeformer::Adjoint()) beside the forward evaluation of the same basis, points and device,
// in one run: kernel times (median of 20; CUDA events: the chunks' sums and the gather for the adjoint), the
// whole Adjoint() call (the gradient's upload from pageable memory and the sensitivities' download included),
// and the plan, made once per binding (the first call's extra time).
void AdjointSection(const Case* cases, std::size_t caseCount, const std::vector<std::int64_t>& sizes, std::mt19937& rng)
{
  std::printf("\nAdjoint (W^T g) beside the forward evaluation, float32 points in voxel order, median of 20; rates "
              "from the kernel times\n");
  std::printf("| basis | points | forward kernel ms | forward G points/s | adjoint kernels ms | adjoint G points/s | "
              "adjoint / forward | Adjoint() call ms | plan ms |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (std::int64_t n : sizes)
  {
    const std::vector<double> points64 = RandomPoints(n, rng);
    const std::vector<float> points(points64.begin(), points64.end());
    std::vector<double> gradient(points64.size());
    for (double& v : gradient)
    {
      v = unit(rng);
    }
    for (std::size_t k = 0; k < caseCount; ++k)
    {
      const Case& c = cases[k];
      const std::vector<double> displacements = RandomDisplacements(c, rng);
      const std::int64_t controlPoints = std::int64_t(displacements.size() / 3);
      std::vector<double> sums(displacements.size());
      const int divisions[3] = { c.Divisions, c.Divisions, c.Divisions };
      ffd::cuda::GridDeformer gpu;
      Require(gpu.SetPoints(points.data(), n) && gpu.Bind(Frame, int(c.Basis), divisions, false), gpu, "Bind");
      const Times forward = TimeGridEvaluation(gpu, displacements);
      auto adjoint = [&] { Require(gpu.Adjoint(gradient.data(), controlPoints, sums.data()), gpu, "Adjoint"); };
      const double first = MedianSeconds(1, adjoint);
      std::vector<double> kernels;
      const double call = MedianSeconds(20,
        [&]
        {
          adjoint();
          kernels.push_back(gpu.GetCounters().LastKernelMilliseconds * 1e-3);
        });
      const double kernel = Median(kernels);
      std::printf("| %s | %lld | %.3f | %.2f | %.3f | %.2f | %.2f | %.3f | %.3f |\n", c.Name, static_cast<long long>(n),
        forward.Points * 1e3, n / forward.Points * 1e-9, kernel * 1e3, n / kernel * 1e-9, forward.Points / kernel,
        call * 1e3, (first - call) * 1e3);
    }
  }
}

int main(int argc, char* argv[])
{
  bool quick = false, gridOnly = false, tetrahedraOnly = false, adjointOnly = false, profile = false;
  int status = 0;
  if (!ParseArguments(argc, argv,
        { { "--quick", &quick }, { "--grid", &gridOnly }, { "--tetrahedra", &tetrahedraOnly },
          { "--adjoint", &adjointOnly }, { "--profile", &profile } },
        "[--quick] [--grid] [--tetrahedra] [--adjoint] [--profile]", status))
  {
    return status;
  }
  std::string why;
  if (!ffd::cuda::DeviceAvailable(&why))
  {
    std::printf("no CUDA device (%s): nothing to measure\n", why.c_str());
    return 0;
  }
  cudaDeviceProp prop;
  RequireCuda(cudaGetDeviceProperties(&prop, 0), "cudaGetDeviceProperties");
  const Device device = MeasureDevice(prop);
  std::printf("device: %s, %d SMs; device-to-device copy: %.0f GB/s (read + write); multiply-add peak: %.1f T/s "
              "float32, %.1f T/s float64\n\n",
    prop.name, prop.multiProcessorCount, device.Bandwidth * 1e-9, device.Float32MultiplyAdds * 1e-12,
    device.Float64MultiplyAdds * 1e-12);

  const Case cases[] = {
    { ffd::GridBasis::Bernstein, "BERNSTEIN 11^3", 10 },
    { ffd::GridBasis::Trilinear, "TRILINEAR 32^3 vox", 32 },
    { ffd::GridBasis::TriquadraticBezier, "TRIQUADRATIC 32^3 vox", 32 },
    { ffd::GridBasis::TricubicBezier, "TRICUBIC 32^3 vox", 32 },
    { ffd::GridBasis::CubicBSpline, "CUBIC_BSPLINE 32^3 vox", 32 },
  };
  std::vector<std::int64_t> sizes = { std::int64_t(1) << 20, std::int64_t(16) << 20, std::int64_t(64) << 20 };
  if (quick)
  {
    sizes.resize(1);
  }
  const std::vector<std::int64_t> tetrahedraSizes(
    sizes.begin(), sizes.begin() + std::min<std::size_t>(2, sizes.size())); // 1 M and 16 M

  std::mt19937 rng(2026);
  if (tetrahedraOnly)
  {
    Tetrahedra(tetrahedraSizes, device.Bandwidth, rng);
    return 0;
  }
  if (adjointOnly)
  {
    AdjointSection(cases, std::size(cases), tetrahedraSizes, rng);
    return 0;
  }
  const char* header = "| basis | precision | points | Evaluate() ms | cell table ms | points kernel ms | G points/s | "
                       "%% of copy roofline | multiply-adds a point | %% of multiply-add peak |\n"
                       "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  if (profile)
  {
    const std::vector<std::int64_t> one = { std::int64_t(16) << 20 };
    std::printf(header);
    GridSection<float>(cases, std::size(cases), one, device, 1, rng);
    GridSection<double>(cases, std::size(cases), one, device, 1, rng);
    return 0;
  }
  std::printf("Evaluation of points in voxel order, median of 20: the whole Evaluate() call (lattice upload, "
              "kernels, synchronize) and the kernels alone (CUDA events); rates from the kernels' time\n");
  std::printf(header);
  GridSection<float>(cases, std::size(cases), sizes, device, 20, rng);
  const std::vector<std::int64_t> larger(sizes.begin() + (sizes.size() > 1 ? 1 : 0), sizes.end()); // 16 M, 64 M
  GridSection<double>(cases, std::size(cases), larger, device, 20, rng);
  const std::vector<std::int64_t> middle(larger.begin(), larger.begin() + 1); // 16 M (1 M with --quick)
  GridSection<float>(cases, std::size(cases), middle, device, 20, rng, true);
  GridSection<double>(cases, std::size(cases), middle, device, 20, rng, true);

  // The same trilinear evaluation on points in random order.
  {
    const std::int64_t n = sizes.size() > 1 ? sizes[1] : sizes[0];
    const Case& c = cases[1];
    const std::vector<double> points64 = RandomPoints(n, rng, false);
    const std::vector<float> points(points64.begin(), points64.end());
    const std::vector<double> displacements = RandomDisplacements(c, rng);
    const int divisions[3] = { c.Divisions, c.Divisions, c.Divisions };
    ffd::cuda::GridDeformer gpu;
    Require(gpu.SetPoints(points.data(), n) && gpu.Bind(Frame, int(c.Basis), divisions, false), gpu, "Bind");
    PrintGridRow<float>(c.Name, ", random point order", n, TimeGridEvaluation(gpu, displacements), device,
      MultiplyAdds(c.Basis, c.Divisions, false));
  }

  // float32 accuracy against float64 on the device, relative to the frame's scale (3): the global basis (its
  // tensor cores) and the bases evaluated from cell tables (4 M points, 128 a cell).
  for (std::size_t k : { std::size_t(0), std::size_t(2), std::size_t(3), std::size_t(4) })
  {
    const std::int64_t n = std::int64_t(4) << 20;
    const Case& c = cases[k];
    const std::vector<double> points64 = RandomPoints(n, rng);
    const std::vector<float> points32(points64.begin(), points64.end());
    const std::vector<double> displacements = RandomDisplacements(c, rng);
    const int divisions[3] = { c.Divisions, c.Divisions, c.Divisions };
    ffd::cuda::GridDeformer gpu32, gpu64;
    std::vector<float> out32(points32.size());
    std::vector<double> out64(points64.size());
    Require(gpu32.SetPoints(points32.data(), n) && gpu32.Bind(Frame, int(c.Basis), divisions, false) &&
        gpu32.Evaluate(displacements.data(), std::int64_t(displacements.size() / 3), false, false) &&
        gpu32.Download(out32.data(), nullptr, nullptr),
      gpu32, "float32 run");
    // The float64 run starts from the float32 points, so that only the arithmetic differs.
    const std::vector<double> same(points32.begin(), points32.end());
    Require(gpu64.SetPoints(same.data(), n) && gpu64.Bind(Frame, int(c.Basis), divisions, false) &&
        gpu64.Evaluate(displacements.data(), std::int64_t(displacements.size() / 3), false, false) &&
        gpu64.Download(out64.data(), nullptr, nullptr),
      gpu64, "float64 run");
    double worst = 0;
    for (std::size_t v = 0; v < out64.size(); ++v)
    {
      worst = std::max(worst, std::fabs(double(out32[v]) - out64[v]));
    }
    std::printf("%s%s float32 vs float64: max error %.2e relative to the frame's scale\n", c.Name,
      gpu32.GetCounters().CellTables > 0 ? " (cell table)" : "", worst / 3.0);
  }
  if (gridOnly)
  {
    return 0;
  }
  Tetrahedra(tetrahedraSizes, device.Bandwidth, rng);
  AdjointSection(cases, std::size(cases), tetrahedraSizes, rng);
  return 0;
}
