// SPDX-License-Identifier: BSD-3-Clause
// GPU benchmark of the CUDA backend's host side (ffd::cuda::GridDeformer): what an update costs from the caller's
// arrays and back, and how far the resident path scales.
// 1. End to end: an update of 1 M float32 points (lattice upload, evaluation, download into the caller's pageable
//    array) against the bare download of the same bytes (cudaMemcpy to pageable memory), in rounds side by side,
//    with its two calls apart (Evaluate(), Download()).
// 2. A billion points (--points N to change it): the upload (SetPoints(), pageable), the binding, an update of the
//    trilinear and cubic B-spline lattices resident on the device (kernel times, median of 5), the device memory
//    they hold, and the download of the deformed points into pageable memory.
// It prints tables and asserts nothing. Options: --end-to-end (that section alone), --points N.
#include "FFDBenchmarkUtilities.h"
#include "FFDCudaGridDeformer.h"
#include "FFDGridBasis.h"

#include <cuda_runtime.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <thread>
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

const double Frame[12] = { -1.0, -1.5, -0.5, 2.0, 0.0, 0.0, 0.0, 3.0, 0.0, 0.0, 0.0, 1.0 };
constexpr int Divisions = 32;

// `count` float32 points in voxel order over the frame's 32^3 voxels (consecutive points in the same or the next
// voxel, as a mesh's vertices), uniform within their voxel; filled by all the host's threads, each from its own
// seed, so that a billion take seconds.
std::vector<float> VoxelOrderPoints(std::int64_t count)
{
  std::vector<float> points(3 * std::size_t(count));
  const ffd::Frame<double> frame = ffd::Frame<double>::FromArray(Frame);
  const std::int64_t cells = std::int64_t(Divisions) * Divisions * Divisions;
  const unsigned threads = std::max(1u, std::thread::hardware_concurrency());
  std::vector<std::thread> workers;
  for (unsigned t = 0; t < threads; ++t)
  {
    workers.emplace_back(
      [&, t]
      {
        std::mt19937_64 rng(2026 + t);
        std::uniform_real_distribution<double> u(0.0, 1.0);
        for (std::int64_t i = count * t / threads; i < count * (t + 1) / threads; ++i)
        {
          const std::int64_t c = i * cells / count;
          const ffd::Vec3<double> p = { (double(c % Divisions) + u(rng)) / Divisions,
            (double((c / Divisions) % Divisions) + u(rng)) / Divisions,
            (double(c / (Divisions * Divisions)) + u(rng)) / Divisions };
          const ffd::Vec3<double> x = frame.ToWorld(p);
          points[3 * i] = float(x.x);
          points[3 * i + 1] = float(x.y);
          points[3 * i + 2] = float(x.z);
        }
      });
  }
  for (std::thread& w : workers)
  {
    w.join();
  }
  return points;
}

std::vector<double> RandomDisplacements(ffd::GridBasis basis, std::mt19937& rng)
{
  const int along = ffd::ControlPointsAlongAxis(basis, Divisions);
  std::uniform_real_distribution<double> d(-0.1, 0.1);
  std::vector<double> v(3 * std::size_t(along) * along * along);
  for (double& x : v)
  {
    x = d(rng);
  }
  return v;
}

double UsedDeviceGigabytes()
{
  std::size_t free = 0, total = 0;
  cudaMemGetInfo(&free, &total);
  return double(total - free) / 1e9;
}

// Section 1: rounds of (update, bare download) side by side, each the median of 50.
void EndToEnd(std::mt19937& rng)
{
  const std::int64_t n = std::int64_t(1) << 20;
  const std::vector<float> points = VoxelOrderPoints(n);
  std::vector<float> out(points.size());
  std::printf("End-to-end update of %lld float32 points against the bare download of their %lld bytes into the same "
              "pageable array (cudaMemcpy), median of 50 each, rounds side by side\n",
    static_cast<long long>(n), static_cast<long long>(n * 12));
  std::printf("| basis | round | Evaluate() ms | Download() ms | update ms | bare download ms | update / bare |\n"
              "|---|---:|---:|---:|---:|---:|---:|\n");
  void* device = nullptr;
  if (cudaMalloc(&device, points.size() * sizeof(float)) != cudaSuccess)
  {
    std::exit(1);
  }
  for (ffd::GridBasis basis : { ffd::GridBasis::Trilinear, ffd::GridBasis::CubicBSpline })
  {
    const std::vector<double> displacements = RandomDisplacements(basis, rng);
    const std::int64_t controlPoints = std::int64_t(displacements.size() / 3);
    const int divisions[3] = { Divisions, Divisions, Divisions };
    ffd::cuda::GridDeformer gpu;
    Require(gpu.SetPoints(points.data(), n) && gpu.Bind(Frame, int(basis), divisions, false), gpu, "Bind");
    auto evaluate = [&] { Require(gpu.Evaluate(displacements.data(), controlPoints, false, false), gpu, "Evaluate"); };
    auto download = [&] { Require(gpu.Download(out.data(), nullptr, nullptr), gpu, "Download"); };
    for (int round = 1; round <= 3; ++round)
    {
      const double evaluation = MedianSeconds(50, evaluate);
      const double downloadOnly = MedianSeconds(50, download);
      const double update = MedianSeconds(50,
        [&]
        {
          evaluate();
          download();
        });
      const double bare = MedianSeconds(
        50, [&] { cudaMemcpy(out.data(), device, points.size() * sizeof(float), cudaMemcpyDeviceToHost); });
      std::printf("| %s | %d | %.3f | %.3f | %.3f | %.3f | %.2f |\n",
        basis == ffd::GridBasis::Trilinear ? "TRILINEAR" : "CUBIC_BSPLINE", round, evaluation * 1e3, downloadOnly * 1e3,
        update * 1e3, bare * 1e3, update / bare);
    }
  }
  cudaFree(device);
}

// Section 2: a billion points, resident.
void Billion(std::int64_t n, std::mt19937& rng)
{
  const double before = UsedDeviceGigabytes();
  const std::vector<float> points = VoxelOrderPoints(n);
  std::printf("\n%lld float32 points in voxel order over 32^3 voxels (%.1f GB), on the device\n",
    static_cast<long long>(n), points.size() * 4 / 1e9);
  std::printf("| step | basis | ms | G points/s | GB/s over the bus | device memory GB |\n"
              "|---|---|---:|---:|---:|---:|\n");
  ffd::cuda::GridDeformer gpu;
  const double upload = MedianSeconds(1, [&] { Require(gpu.SetPoints(points.data(), n), gpu, "SetPoints"); });
  std::printf("| SetPoints() from pageable memory | | %.1f | %.2f | %.1f | %.1f |\n", upload * 1e3, n / upload * 1e-9,
    points.size() * 4 / upload * 1e-9, UsedDeviceGigabytes() - before);
  std::vector<float> out(points.size());
  for (ffd::GridBasis basis : { ffd::GridBasis::Trilinear, ffd::GridBasis::CubicBSpline })
  {
    const char* name = basis == ffd::GridBasis::Trilinear ? "TRILINEAR" : "CUBIC_BSPLINE (cell table)";
    const int divisions[3] = { Divisions, Divisions, Divisions };
    const double bind = MedianSeconds(1, [&] { Require(gpu.Bind(Frame, int(basis), divisions, false), gpu, "Bind"); });
    std::printf(
      "| Bind() | %s | %.1f | %.2f | | %.1f |\n", name, bind * 1e3, n / bind * 1e-9, UsedDeviceGigabytes() - before);
    const std::vector<double> displacements = RandomDisplacements(basis, rng);
    std::vector<double> kernels, tables;
    const double call = MedianSeconds(5,
      [&]
      {
        Require(
          gpu.Evaluate(displacements.data(), std::int64_t(displacements.size() / 3), false, false), gpu, "Evaluate");
        kernels.push_back(gpu.GetCounters().LastKernelMilliseconds * 1e-3);
        tables.push_back(gpu.GetCounters().LastLatticeKernelMilliseconds * 1e-3);
      });
    const double kernel = Median(kernels) + Median(tables);
    std::printf("| update, resident: kernels (Evaluate() call %.1f ms) | %s | %.1f | %.1f | | %.1f |\n", call * 1e3,
      name, kernel * 1e3, n / kernel * 1e-9, UsedDeviceGigabytes() - before);
    const double download =
      MedianSeconds(1, [&] { Require(gpu.Download(out.data(), nullptr, nullptr), gpu, "Download"); });
    std::printf("| Download() into pageable memory | %s | %.1f | %.2f | %.1f | |\n", name, download * 1e3,
      n / download * 1e-9, out.size() * 4 / download * 1e-9);
  }
}
} // namespace

int main(int argc, char* argv[])
{
  bool endToEndOnly = false;
  int count = 1000000000;
  int status = 0;
  if (!ParseArguments(argc, argv, { { "--end-to-end", &endToEndOnly }, { "--points", &count } },
        "[--end-to-end] [--points N]", status))
  {
    return status;
  }
  std::string why;
  if (!ffd::cuda::DeviceAvailable(&why))
  {
    std::printf("no CUDA device (%s): nothing to measure\n", why.c_str());
    return 0;
  }
  std::mt19937 rng(2034);
  EndToEnd(rng);
  if (!endToEndOnly)
  {
    Billion(std::max(count, 1), rng);
  }
  return 0;
}
