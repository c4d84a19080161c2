// SPDX-License-Identifier: BSD-3-Clause
// GPU benchmark of the CUDA backend (ffd::cuda::GridDeformer): points per second of the evaluation of every grid
// basis for 1 M, 16 M and 64 M points, beside the device-to-device copy bandwidth measured in the same run, the
// fraction of the bandwidth roofline each evaluation reaches (bytes it must move: the point and its 4-byte
// binding in, the deformed point out), the float32 accuracy of the global basis against float64, and the
// end-to-end update (lattice upload + evaluation + download) against the bare download of the same bytes.
// It prints tables and asserts nothing. Options: --quick (1 M points only).
#include "FFDCudaGridDeformer.h"
#include "FFDGridBasis.h"

#include <cuda_runtime.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <vector>

namespace
{
using Clock = std::chrono::steady_clock;

double Median(std::vector<double> v)
{
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

template <typename F>
double MedianSeconds(int repeats, F&& f)
{
  std::vector<double> times;
  for (int r = 0; r < repeats; ++r)
  {
    const auto start = Clock::now();
    f();
    times.push_back(std::chrono::duration<double>(Clock::now() - start).count());
  }
  return Median(times);
}

void Require(bool ok, const ffd::cuda::GridDeformer& gpu, const char* what)
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
} // namespace

int main(int argc, char* argv[])
{
  const bool quick = argc > 1 && std::string(argv[1]) == "--quick";
  std::string why;
  if (!ffd::cuda::DeviceAvailable(&why))
  {
    std::printf("no CUDA device (%s): nothing to measure\n", why.c_str());
    return 0;
  }
  cudaDeviceProp prop;
  RequireCuda(cudaGetDeviceProperties(&prop, 0), "cudaGetDeviceProperties");
  const double bandwidth = CopyBandwidth();
  std::printf("device: %s, %d SMs; device-to-device copy: %.0f GB/s (read + write)\n\n", prop.name,
    prop.multiProcessorCount, bandwidth * 1e-9);

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

  std::mt19937 rng(2026);
  std::printf("Evaluation of float32 points in voxel order, median of 20: the whole Evaluate() call (lattice "
              "upload, kernel, synchronize) and the kernel alone (CUDA events); rates from the kernel time\n");
  std::printf("| basis | points | Evaluate() ms | kernel ms | G points/s | GB/s moved | %% of copy roofline |\n"
              "|---|---:|---:|---:|---:|---:|---:|\n");
  double endToEnd = 0, bareDownload = 0;
  for (std::int64_t n : sizes)
  {
    const std::vector<double> points64 = RandomPoints(n, rng);
    const std::vector<float> points(points64.begin(), points64.end());
    std::vector<float> out(points.size());
    for (const Case& c : cases)
    {
      const std::vector<double> displacements = RandomDisplacements(c, rng);
      const std::int64_t controlPoints = std::int64_t(displacements.size() / 3);
      const int divisions[3] = { c.Divisions, c.Divisions, c.Divisions };
      ffd::cuda::GridDeformer gpu;
      Require(gpu.SetPoints(points.data(), n), gpu, "SetPoints");
      Require(gpu.Bind(Frame, int(c.Basis), divisions, false), gpu, "Bind");
      Require(gpu.Evaluate(displacements.data(), controlPoints, false, false), gpu, "Evaluate"); // warm-up
      std::vector<double> kernelSeconds;
      const double seconds = MedianSeconds(20, [&] {
        Require(gpu.Evaluate(displacements.data(), controlPoints, false, false), gpu, "Evaluate");
        kernelSeconds.push_back(gpu.GetCounters().LastKernelMilliseconds * 1e-3);
      });
      const double kernel = Median(kernelSeconds);
      const double bytes = double(n) * (12 + 4 + 12);
      std::printf("| %s | %lld | %.3f | %.3f | %.2f | %.0f | %.0f %% |\n", c.Name, static_cast<long long>(n),
        seconds * 1e3, kernel * 1e3, n / kernel * 1e-9, bytes / kernel * 1e-9, 100.0 * bytes / kernel / bandwidth);

      if (n == sizes.front() && c.Basis == ffd::GridBasis::Trilinear)
      {
        endToEnd = MedianSeconds(20, [&] {
          Require(gpu.Evaluate(displacements.data(), controlPoints, false, false), gpu, "Evaluate");
          Require(gpu.Download(out.data(), nullptr, nullptr), gpu, "Download");
        });
        void* device = nullptr;
        RequireCuda(cudaMalloc(&device, points.size() * sizeof(float)), "cudaMalloc");
        bareDownload = MedianSeconds(20, [&] {
          RequireCuda(cudaMemcpy(out.data(), device, points.size() * sizeof(float), cudaMemcpyDeviceToHost),
            "cudaMemcpy");
        });
        cudaFree(device);
      }
    }
  }

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
    const std::int64_t controlPoints = std::int64_t(displacements.size() / 3);
    Require(gpu.Evaluate(displacements.data(), controlPoints, false, false), gpu, "Evaluate");
    std::vector<double> kernelSeconds;
    const double seconds = MedianSeconds(20, [&] {
      Require(gpu.Evaluate(displacements.data(), controlPoints, false, false), gpu, "Evaluate");
      kernelSeconds.push_back(gpu.GetCounters().LastKernelMilliseconds * 1e-3);
    });
    const double kernel = Median(kernelSeconds);
    const double bytes = double(n) * (12 + 4 + 12);
    std::printf("| %s, random point order | %lld | %.3f | %.3f | %.2f | %.0f | %.0f %% |\n", c.Name,
      static_cast<long long>(n), seconds * 1e3, kernel * 1e3, n / kernel * 1e-9, bytes / kernel * 1e-9,
      100.0 * bytes / kernel / bandwidth);
  }

  std::printf("\nEnd-to-end update of %lld points (TRILINEAR; lattice upload + evaluation + download into pageable "
              "memory) against the bare download of the same %lld bytes (cudaMemcpy to pageable memory), median "
              "of 20: %.3f ms vs %.3f ms, ratio %.2f\n",
    static_cast<long long>(sizes.front()), static_cast<long long>(sizes.front() * 12), endToEnd * 1e3,
    bareDownload * 1e3, endToEnd / bareDownload);

  // float32 accuracy of the global basis against float64 on the device, relative to the frame's scale (3).
  {
    const std::int64_t n = std::int64_t(1) << 20;
    const Case& c = cases[0];
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
    std::printf("BERNSTEIN 11^3 float32 vs float64: max error %.2e relative to the frame's scale\n", worst / 3.0);
  }
  return 0;
}
