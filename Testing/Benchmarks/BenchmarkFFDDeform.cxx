// SPDX-License-Identifier: BSD-3-Clause
/**
 * BenchmarkFFDDeform: points per second of the global (Bernstein) FFD evaluation in vtkFFDDeform, beside the
 * machine's FMA peak measured in the same run. Not a test: it prints a table and asserts nothing about time.
 * Results and how to read them: BENCHMARKS.md at the repository root.
 *
 * What is timed: vtkFFDDeform::Update() after the lattice's points moved, the binding being cached (the
 * program checks that it was not recomputed). That is the evaluation as a user sees it: reading the lattice,
 * allocating the output points and X + sum B_i B_j B_k D_ijk at every point. Normals and the Jacobian are off.
 *
 * Usage: BenchmarkFFDDeform [--quick] [--mesh path.vtp]
 *   --quick  small meshes and short runs, a smoke check of the program (seconds)
 *   --mesh   the mesh to subdivide (VTK XML PolyData); default: the armadillo of the test data
 */

#include "vtkFFDBuildLattice.h"
#include "vtkFFDDeform.h"
#include "vtkFFDVoxelize.h"

#include "vtkLinearSubdivisionFilter.h"
#include "vtkNew.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSMPTools.h"
#include "vtkSmartPointer.h"
#include "vtkStructuredGrid.h"
#include "vtkTriangleFilter.h"
#include "vtkXMLPolyDataReader.h"

#include <immintrin.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <random>
#include <string>
#include <thread>
#include <vector>

namespace
{
using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point begin)
{
  return std::chrono::duration<double>(Clock::now() - begin).count();
}

//------------------------------------------------------------------------------------------------------------
// FMA throughput. Chains independent accumulators acc = acc * a + b hide the FMA latency (4-5 cycles on
// current x86) times the number of FMA pipes (2); 12 chains plus the two constants fit the 16 registers of
// SSE/AVX2. With a < 1 the accumulators converge to b / (1 - a) and never overflow or become subnormal.
// One function per instruction set, each compiled for that set alone (target attribute), so the default
// build still runs on any x86-64; the program asks the CPU which ones it can run.
constexpr int Chains = 12;

#define FFD_FMA_LOOP(Name, Target, Vec, Real, Set1, MulAdd, Lanes)                                           \
  __attribute__((target(Target))) double Name(long iterations)                                              \
  {                                                                                                          \
    Vec acc[Chains];                                                                                         \
    for (int c = 0; c < Chains; ++c)                                                                         \
    {                                                                                                        \
      acc[c] = Set1(Real(1) + Real(c) * Real(1e-3));                                                         \
    }                                                                                                        \
    const Vec a = Set1(Real(0.999999)), b = Set1(Real(1e-6));                                                \
    for (long i = 0; i < iterations; ++i)                                                                    \
    {                                                                                                        \
      _Pragma("GCC unroll 12") for (int c = 0; c < Chains; ++c) { acc[c] = MulAdd(acc[c], a, b); }           \
    }                                                                                                        \
    Real lanes[Lanes];                                                                                       \
    double sum = 0.0;                                                                                        \
    for (int c = 0; c < Chains; ++c)                                                                         \
    {                                                                                                        \
      std::memcpy(lanes, &acc[c], sizeof(lanes));                                                            \
      for (int l = 0; l < Lanes; ++l)                                                                        \
      {                                                                                                      \
        sum += double(lanes[l]);                                                                             \
      }                                                                                                      \
    }                                                                                                        \
    return sum;                                                                                              \
  }

#define FFD_SSE_MULADD_PD(x, a, b) _mm_add_pd(_mm_mul_pd(x, a), b)
#define FFD_SSE_MULADD_PS(x, a, b) _mm_add_ps(_mm_mul_ps(x, a), b)
// The baseline x86-64 has no FMA: a default build turns each multiply-add into a multiply and an add.
FFD_FMA_LOOP(MulAddSse2Double, "sse2", __m128d, double, _mm_set1_pd, FFD_SSE_MULADD_PD, 2)
FFD_FMA_LOOP(MulAddSse2Float, "sse2", __m128, float, _mm_set1_ps, FFD_SSE_MULADD_PS, 4)
FFD_FMA_LOOP(FmaAvx2Double, "avx2,fma", __m256d, double, _mm256_set1_pd, _mm256_fmadd_pd, 4)
FFD_FMA_LOOP(FmaAvx2Float, "avx2,fma", __m256, float, _mm256_set1_ps, _mm256_fmadd_ps, 8)
FFD_FMA_LOOP(FmaAvx512Double, "avx512f,fma", __m512d, double, _mm512_set1_pd, _mm512_fmadd_pd, 8)
FFD_FMA_LOOP(FmaAvx512Float, "avx512f,fma", __m512, float, _mm512_set1_ps, _mm512_fmadd_ps, 16)
#undef FFD_FMA_LOOP

/// One instruction set's loops: multiply-adds per second are iterations * Chains * lanes / time.
struct FmaKernel
{
  const char* Name;
  double (*Double)(long);
  double (*Float)(long);
  int DoubleLanes;
};

/// The best FMA instruction set this CPU runs (nullptr if none), and the SSE2 baseline of a default build.
const FmaKernel* BestFmaKernel()
{
  static const FmaKernel avx512 = { "AVX-512 FMA", FmaAvx512Double, FmaAvx512Float, 8 };
  static const FmaKernel avx2 = { "AVX2 FMA", FmaAvx2Double, FmaAvx2Float, 4 };
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("fma"))
  {
    return &avx512;
  }
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"))
  {
    return &avx2;
  }
  return nullptr;
}

const FmaKernel Sse2Baseline = { "SSE2 mul+add", MulAddSse2Double, MulAddSse2Float, 2 };

/**
 * Multiply-adds per second (one per lane, whether fused or not) of `threads` copies of the loop run at once,
 * best of 3. Results are summed into a volatile so that no loop is optimised away.
 */
double MeasurePeak(const FmaKernel& kernel, bool useDouble, int threads, long iterations)
{
  static volatile double sink = 0.0;
  const int lanes = useDouble ? kernel.DoubleLanes : 2 * kernel.DoubleLanes;
  double best = 0.0;
  for (int trial = 0; trial < 3; ++trial)
  {
    std::vector<std::thread> pool;
    std::vector<double> results(threads);
    const Clock::time_point begin = Clock::now();
    for (int t = 0; t < threads; ++t)
    {
      pool.emplace_back([&, t]() { results[t] = (useDouble ? kernel.Double : kernel.Float)(iterations); });
    }
    for (std::thread& th : pool)
    {
      th.join();
    }
    const double elapsed = Seconds(begin);
    for (double r : results)
    {
      sink = sink + r;
    }
    best = std::max(best, double(threads) * iterations * Chains * lanes / elapsed);
  }
  return best;
}

//------------------------------------------------------------------------------------------------------------
/**
 * Operations per point of the global evaluation of degree (l, m, n), counted from the kernel
 * (FFDGlobalBernstein.h): 3 FMAs per control point (sum over i), 3 per (j, k) and 3 per k (the outer sums),
 * 3 adds for X + D, and per axis of degree d the de Casteljau triangle's d(d+1)/2 steps of one FMA and one
 * multiply. Each counts as one operation, one issue of an FMA unit's lane.
 */
double OperationsPerPoint(int l, int m, int n)
{
  const double sum = 3.0 * ((l + 1) * (m + 1) * (n + 1) + (m + 1) * (n + 1) + (n + 1) + 1);
  return sum + l * (l + 1) + m * (m + 1) + n * (n + 1);
}

std::string CpuModel()
{
  std::ifstream cpuinfo("/proc/cpuinfo");
  std::string line;
  while (std::getline(cpuinfo, line))
  {
    if (line.rfind("model name", 0) == 0)
    {
      return line.substr(line.find(':') + 2);
    }
  }
  return "unknown";
}

//------------------------------------------------------------------------------------------------------------
/// The mesh subdivided `levels` times (each level splits every triangle in four).
vtkSmartPointer<vtkPolyData> Subdivide(vtkPolyData* mesh, int levels)
{
  if (levels == 0)
  {
    return mesh;
  }
  vtkNew<vtkLinearSubdivisionFilter> subdivide;
  subdivide->SetInputData(mesh);
  subdivide->SetNumberOfSubdivisions(levels);
  subdivide->Update();
  return subdivide->GetOutput();
}

/// Points and triangles only (no point data to pass along), points converted to float or double.
vtkSmartPointer<vtkPolyData> WithPrecision(vtkPolyData* mesh, bool useDouble)
{
  vtkNew<vtkPoints> points;
  points->SetDataType(useDouble ? VTK_DOUBLE : VTK_FLOAT);
  points->DeepCopy(mesh->GetPoints()); // DeepCopy converts to this vtkPoints' type
  auto copy = vtkSmartPointer<vtkPolyData>::New();
  copy->SetPoints(points);
  copy->SetPolys(mesh->GetPolys());
  return copy;
}

struct Timing
{
  double Best = 0.0, Median = 0.0;
};

/// Moves every lattice point by up to 2 % of the lattice's diagonal, a new random displacement each call.
void MoveLattice(vtkStructuredGrid* lattice, const std::vector<double>& rest, std::mt19937& rng)
{
  double bounds[6];
  lattice->GetBounds(bounds);
  const double diagonal = std::sqrt((bounds[1] - bounds[0]) * (bounds[1] - bounds[0]) +
    (bounds[3] - bounds[2]) * (bounds[3] - bounds[2]) + (bounds[5] - bounds[4]) * (bounds[5] - bounds[4]));
  std::uniform_real_distribution<double> move(-0.02 * diagonal, 0.02 * diagonal);
  vtkPoints* points = lattice->GetPoints();
  for (vtkIdType p = 0; p < points->GetNumberOfPoints(); ++p)
  {
    points->SetPoint(p, rest[3 * p] + move(rng), rest[3 * p + 1] + move(rng), rest[3 * p + 2] + move(rng));
  }
  points->Modified();
  lattice->Modified();
}

struct Row
{
  int ControlPoints;
  vtkIdType Points;
  const char* Precision;
  int Threads;
  double BindSeconds;
  Timing Evaluation;
  double OperationsPerPoint;
  double PeakOperations; // the FMA peak of this precision and thread count
};

void PrintRow(const Row& r)
{
  const double pointsPerSecond = r.Points / r.Evaluation.Best;
  const double operations = pointsPerSecond * r.OperationsPerPoint;
  std::printf("| %4d | %9lld | %-7s | %2d | %8.3f | %8.4f | %8.4f | %9.2f | %8.2f | %6.1f %% |\n",
    r.ControlPoints, static_cast<long long>(r.Points), r.Precision, r.Threads, r.BindSeconds, r.Evaluation.Best,
    r.Evaluation.Median, pointsPerSecond * 1e-6, operations * 1e-9,
    r.PeakOperations > 0 ? 100.0 * operations / r.PeakOperations : 0.0);
  std::fflush(stdout);
}

/**
 * Builds voxelize -> lattice -> deform over `mesh` with `divisions` per axis, binds once, then for each thread
 * count times Update() after moving the lattice: repeated at least `minRepeats` times and until `minSeconds`
 * have been spent, best and median kept.
 */
void BenchmarkMesh(vtkPolyData* mesh, bool useDouble, int divisions, const std::vector<int>& threadCounts,
  int minRepeats, double minSeconds, const std::vector<double>& peaks, std::vector<Row>& rows)
{
  vtkNew<vtkFFDVoxelize> voxelize;
  voxelize->SetInputData(mesh);
  voxelize->SetDivisions(divisions, divisions, divisions);
  vtkNew<vtkFFDBuildLattice> build;
  build->SetInputConnection(voxelize->GetOutputPort());
  build->SetBasisToBernstein();
  build->Update();

  // A copy of the lattice whose points the benchmark moves, as a widget or a script would.
  vtkNew<vtkStructuredGrid> lattice;
  lattice->DeepCopy(build->GetOutput());
  std::vector<double> rest(3 * lattice->GetNumberOfPoints());
  for (vtkIdType p = 0; p < lattice->GetNumberOfPoints(); ++p)
  {
    lattice->GetPoint(p, &rest[3 * p]);
  }

  vtkNew<vtkFFDDeform> deform;
  deform->SetInputData(mesh);
  deform->SetLatticeData(lattice);
  deform->TransformNormalsOff();
  deform->ComputeJacobianDeterminantOff();
  std::mt19937 rng(8);
  MoveLattice(lattice, rest, rng);
  const Clock::time_point bindBegin = Clock::now();
  deform->Update();
  const double bindSeconds = Seconds(bindBegin);
  if (deform->GetOutput()->GetNumberOfPoints() != mesh->GetNumberOfPoints())
  {
    std::fprintf(stderr, "vtkFFDDeform failed on %lld points\n", static_cast<long long>(mesh->GetNumberOfPoints()));
    return;
  }

  const vtkIdType bindings = deform->GetNumberOfBindings();
  for (size_t t = 0; t < threadCounts.size(); ++t)
  {
    vtkSMPTools::Initialize(threadCounts[t]);
    std::vector<double> times;
    const Clock::time_point begin = Clock::now();
    while (int(times.size()) < minRepeats || Seconds(begin) < minSeconds)
    {
      MoveLattice(lattice, rest, rng);
      const Clock::time_point updateBegin = Clock::now();
      deform->Update();
      times.push_back(Seconds(updateBegin));
    }
    if (deform->GetNumberOfBindings() != bindings)
    {
      std::fprintf(stderr, "warning: the binding was recomputed; these timings include it\n");
    }
    std::sort(times.begin(), times.end());
    const Timing timing = { times.front(), times[times.size() / 2] };
    rows.push_back({ (divisions + 1) * (divisions + 1) * (divisions + 1), mesh->GetNumberOfPoints(),
      useDouble ? "float64" : "float32", vtkSMPTools::GetEstimatedNumberOfThreads(), bindSeconds, timing,
      OperationsPerPoint(divisions, divisions, divisions), peaks[2 * t + (useDouble ? 1 : 0)] });
    PrintRow(rows.back());
  }
}
} // namespace

int main(int argc, char* argv[])
{
  bool quick = false;
  std::string meshPath = std::string(VOXELFFD_MESH_DIR) + "/armadillo.vtp";
  for (int a = 1; a < argc; ++a)
  {
    const std::string arg = argv[a];
    if (arg == "--quick")
    {
      quick = true;
    }
    else if (arg == "--mesh" && a + 1 < argc)
    {
      meshPath = argv[++a];
    }
    else
    {
      std::fprintf(stderr, "usage: %s [--quick] [--mesh path.vtp]\n", argv[0]);
      return arg == "--help" || arg == "-h" ? 0 : 1;
    }
  }

  // Thread counts: one, and every thread the SMP backend would use by default.
  vtkSMPTools::Initialize(0);
  const int allThreads = vtkSMPTools::GetEstimatedNumberOfThreads();
  std::vector<int> threadCounts = { 1 };
  if (allThreads > 1)
  {
    threadCounts.push_back(allThreads);
  }
  std::printf("CPU: %s, %u hardware threads\n", CpuModel().c_str(), std::thread::hardware_concurrency());
  std::printf("vtkSMPTools backend: %s, thread counts: 1", vtkSMPTools::GetBackend());
  std::printf(allThreads > 1 ? " and %d\n" : "\n", allThreads);

  // FMA peak, per thread count and precision (index 2 * thread + double).
  const long iterations = quick ? 2000000 : 50000000;
  const FmaKernel* best = BestFmaKernel();
  std::vector<double> peaks;
  std::printf("\nFMA peak (multiply-adds per second, one per lane; %d independent chains, best of 3):\n", Chains);
  for (const FmaKernel* kernel : { best, &Sse2Baseline })
  {
    if (!kernel)
    {
      std::printf("  no FMA instruction set on this CPU: %% of peak is left at 0\n");
      peaks.assign(2 * threadCounts.size(), 0.0);
      continue;
    }
    for (int threads : threadCounts)
    {
      const double f = MeasurePeak(*kernel, false, threads, iterations);
      const double d = MeasurePeak(*kernel, true, threads, iterations);
      std::printf("  %-13s %2d thread(s): float32 %7.2f G/s, float64 %7.2f G/s\n", kernel->Name, threads,
        f * 1e-9, d * 1e-9);
      if (kernel == best)
      {
        peaks.push_back(f);
        peaks.push_back(d);
      }
    }
  }

  vtkNew<vtkXMLPolyDataReader> reader;
  if (!std::ifstream(meshPath).good())
  {
    std::fprintf(stderr, "%s is missing: run Utilities/setup.sh, or pass --mesh\n", meshPath.c_str());
    return 1;
  }
  reader->SetFileName(meshPath.c_str());
  vtkNew<vtkTriangleFilter> triangles;
  triangles->SetInputConnection(reader->GetOutputPort());
  triangles->PassVertsOff();
  triangles->PassLinesOff();
  triangles->Update();
  vtkSmartPointer<vtkPolyData> base = triangles->GetOutput();

  // ~0.5 M and ~5 M points: the armadillo (26 k points) subdivided 2 and 4 times (416 k and 6.6 M points);
  // the larger is made from the smaller. --quick: 0 and 1 level.
  const std::vector<int> levels = quick ? std::vector<int>{ 0, 1 } : std::vector<int>{ 2, 4 };
  std::vector<vtkSmartPointer<vtkPolyData>> meshes;
  const Clock::time_point subdivideBegin = Clock::now();
  meshes.push_back(Subdivide(base, levels[0]));
  meshes.push_back(Subdivide(meshes[0], levels[1] - levels[0]));
  std::printf("\nMesh %s: %lld points; subdivided %d and %d times: %lld and %lld points (%.1f s)\n",
    meshPath.c_str(), static_cast<long long>(base->GetNumberOfPoints()), levels[0], levels[1],
    static_cast<long long>(meshes[0]->GetNumberOfPoints()), static_cast<long long>(meshes[1]->GetNumberOfPoints()),
    Seconds(subdivideBegin));

  std::printf("\nGlobal Bernstein evaluation (vtkFFDDeform::Update() after moving the lattice, binding cached).\n"
              "ops/point: 3 FMAs per control point + outer sums + basis (%.0f for 5^3, %.0f for 10^3);\n"
              "%% of peak: (points/s * ops/point) / the FMA peak above for the same precision and threads.\n"
              "bind+1st: the first Update(), binding included, on all threads; best, median: evaluation only.\n\n",
    OperationsPerPoint(4, 4, 4), OperationsPerPoint(9, 9, 9));
  std::printf("| ctrl | points    | type    | th | bind+1st | best (s) | median   | Mpoints/s | Gops/s   | %% peak   |\n");
  std::printf("|-----:|----------:|---------|---:|---------:|---------:|---------:|----------:|---------:|---------:|\n");
  std::vector<Row> rows;
  const int minRepeats = quick ? 2 : 3;
  const double minSeconds = quick ? 0.0 : 1.0;
  for (const auto& mesh : meshes)
  {
    for (bool useDouble : { false, true })
    {
      vtkSmartPointer<vtkPolyData> input = WithPrecision(mesh, useDouble);
      for (int divisions : { 4, 9 })
      {
        BenchmarkMesh(input, useDouble, divisions, threadCounts, minRepeats, minSeconds, peaks, rows);
      }
    }
  }
  vtkSMPTools::Initialize(0);
  return rows.size() == 2 * 2 * 2 * threadCounts.size() ? 0 : 1;
}
