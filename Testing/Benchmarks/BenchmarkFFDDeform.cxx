// SPDX-License-Identifier: BSD-3-Clause
/**
 * BenchmarkFFDDeform: points per second of the evaluation in vtkFFDDeform, each beside a machine limit
 * measured in the same run. Not a test: it prints tables and asserts nothing about time. Results and how to
 * read them: BENCHMARKS.md at the repository root.
 *
 * Two sections, on the armadillo subdivided to ~0.5 M and ~5 M points, float32 and float64, 1 and all threads:
 * - global: the Bernstein evaluation with 5^3 and 10^3 control points, against the FMA peak (compute-bound);
 * - bases: every basis (the global one over 4^3 voxels, the local ones over 4^3 voxels and over lattices of
 *   about 10^3 control points), against the copy bandwidth (std::memcpy): the bytes the evaluation must move
 *   per point (read the point and its 4-byte cell, write the point) per second, the copy measured beside each
 *   row; and CUBIC_BSPLINE against VTK's vtkBSplineTransform + vtkTransformFilter on the same mesh and lattice
 *   (with the largest difference between the two outputs, which must be rounding).
 *
 * What is timed: vtkFFDDeform::Update() after the lattice's points moved, the binding being cached (the
 * program checks that it was not recomputed). That is the evaluation as a user sees it: reading the lattice,
 * allocating the output points and X + sum B_i B_j B_k D_ijk at every point. Normals and the Jacobian are off.
 *
 * A third section, inverse, times the inverse map: vtkFFDInverseDeform against VTK's
 * vtkBSplineTransform::GetInverse() in a vtkTransformFilter, on the ~0.5 M-point mesh deformed by a moved
 * CUBIC_BSPLINE lattice of 7^3 voxels, with each one's largest error.
 *
 * Usage: BenchmarkFFDDeform [--quick] [--section global|bases|inverse|all] [--mesh path.vtp]
 *   --quick    small meshes and short runs, a smoke check of the program (seconds)
 *   --section  run one section only (default: all)
 *   --mesh     the mesh to subdivide (VTK XML PolyData); default: the armadillo of the test data
 */

#include "FFDBenchmarkUtilities.h"

#include "vtkFFDBuildLattice.h"
#include "vtkFFDDataContract.h"
#include "vtkFFDDeform.h"
#include "vtkFFDInverseDeform.h"
#include "vtkFFDVoxelize.h"

#include "vtkBSplineTransform.h"
#include "vtkDataArray.h"
#include "vtkImageData.h"
#include "vtkLinearSubdivisionFilter.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSMPTools.h"
#include "vtkSmartPointer.h"
#include "vtkStructuredGrid.h"
#include "vtkTransformFilter.h"
#include "vtkTriangleFilter.h"
#include "vtkXMLPolyDataReader.h"

#include <immintrin.h>

#include <algorithm>
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
//------------------------------------------------------------------------------------------------------------
// FMA throughput. Chains independent accumulators acc = acc * a + b hide the FMA latency (4-5 cycles on
// current x86) times the number of FMA pipes (2); 12 chains plus the two constants fit the 16 registers of
// SSE/AVX2. With a < 1 the accumulators converge to b / (1 - a) and never overflow or become subnormal.
// One function per instruction set, each compiled for that set alone (target attribute), so the default
// build still runs on any x86-64; the program asks the CPU which ones it can run.
constexpr int Chains = 12;

#define FFD_FMA_LOOP(Name, Target, Vec, Real, Set1, MulAdd, Lanes)                                                     \
  __attribute__((target(Target))) double Name(long iterations)                                                         \
  {                                                                                                                    \
    Vec acc[Chains];                                                                                                   \
    for (int c = 0; c < Chains; ++c)                                                                                   \
    {                                                                                                                  \
      acc[c] = Set1(Real(1) + Real(c) * Real(1e-3));                                                                   \
    }                                                                                                                  \
    const Vec a = Set1(Real(0.999999)), b = Set1(Real(1e-6));                                                          \
    for (long i = 0; i < iterations; ++i)                                                                              \
    {                                                                                                                  \
      _Pragma("GCC unroll 12") for (int c = 0; c < Chains; ++c)                                                        \
      {                                                                                                                \
        acc[c] = MulAdd(acc[c], a, b);                                                                                 \
      }                                                                                                                \
    }                                                                                                                  \
    Real lanes[Lanes];                                                                                                 \
    double sum = 0.0;                                                                                                  \
    for (int c = 0; c < Chains; ++c)                                                                                   \
    {                                                                                                                  \
      std::memcpy(lanes, &acc[c], sizeof(lanes));                                                                      \
      for (int l = 0; l < Lanes; ++l)                                                                                  \
      {                                                                                                                \
        sum += double(lanes[l]);                                                                                       \
      }                                                                                                                \
    }                                                                                                                  \
    return sum;                                                                                                        \
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
 * (FFDGridBasis.h, SumTensorProduct and BernsteinBasis): 3 FMAs per control point (sum over i), 3 per (j, k) and 3 per
 * k (the outer sums), 3 adds for X + D, and per axis of degree d the de Casteljau triangle's d(d+1)/2 steps of one FMA
 * and one multiply. Each counts as one operation, one issue of an FMA unit's lane.
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
  std::printf("| %4d | %9lld | %-7s | %2d | %8.3f | %8.4f | %8.4f | %9.2f | %8.2f | %6.1f %% |\n", r.ControlPoints,
    static_cast<long long>(r.Points), r.Precision, r.Threads, r.BindSeconds, r.Evaluation.Best, r.Evaluation.Median,
    pointsPerSecond * 1e-6, operations * 1e-9, r.PeakOperations > 0 ? 100.0 * operations / r.PeakOperations : 0.0);
  std::fflush(stdout);
}

/// A lattice of a basis over a mesh, as a copy whose points the benchmark moves (as a widget or a script
/// would), and its rest positions.
struct BenchmarkLattice
{
  vtkNew<vtkStructuredGrid> Grid;
  std::vector<double> Rest;
};

void BuildLattice(vtkPolyData* mesh, int basis, int divisions, BenchmarkLattice& lattice)
{
  vtkNew<vtkFFDVoxelize> voxelize;
  voxelize->SetInputData(mesh);
  voxelize->SetDivisions(divisions, divisions, divisions);
  vtkNew<vtkFFDBuildLattice> build;
  build->SetInputConnection(voxelize->GetOutputPort());
  build->SetBasis(basis);
  build->SetLatticeFormToDense();
  build->Update();
  lattice.Grid->DeepCopy(build->GetOutput());
  lattice.Rest.resize(3 * lattice.Grid->GetNumberOfPoints());
  for (vtkIdType p = 0; p < lattice.Grid->GetNumberOfPoints(); ++p)
  {
    lattice.Grid->GetPoint(p, &lattice.Rest[3 * p]);
  }
}

/// Sets up `deform` on `mesh` and `lattice` (normals and Jacobian off) and runs it once, which binds; returns
/// the seconds that took, or a negative value when the filter failed.
double BindOnce(vtkFFDDeform* deform, vtkPolyData* mesh, BenchmarkLattice& lattice, std::mt19937& rng)
{
  deform->SetInputData(mesh);
  deform->SetLatticeData(lattice.Grid);
  deform->TransformNormalsOff();
  deform->ComputeJacobianDeterminantOff();
  MoveLattice(lattice.Grid, lattice.Rest, rng);
  const Clock::time_point begin = Clock::now();
  deform->Update();
  const double seconds = Seconds(begin);
  if (deform->GetOutput()->GetNumberOfPoints() != mesh->GetNumberOfPoints())
  {
    std::fprintf(stderr, "vtkFFDDeform failed on %lld points\n", static_cast<long long>(mesh->GetNumberOfPoints()));
    return -1.0;
  }
  return seconds;
}

/// Times vtkFFDDeform::Update() after moving the lattice's points (the binding cached), on the threads
/// vtkSMPTools was initialized to; appends the times to `times`.
void TimeUpdates(vtkFFDDeform* deform, BenchmarkLattice& lattice, std::mt19937& rng, int minRepeats, double minSeconds,
  std::vector<double>& times)
{
  const vtkIdType bindings = deform->GetNumberOfBindings();
  RepeatInto(
    [&]()
    {
      MoveLattice(lattice.Grid, lattice.Rest, rng);
      const Clock::time_point begin = Clock::now();
      deform->Update();
      return Seconds(begin);
    },
    minRepeats, minSeconds, times);
  if (deform->GetNumberOfBindings() != bindings)
  {
    std::fprintf(stderr, "warning: the binding was recomputed; these timings include it\n");
  }
}

/// TimeUpdates() on `threads` threads; best and median.
Timing TimeEvaluation(
  vtkFFDDeform* deform, BenchmarkLattice& lattice, std::mt19937& rng, int threads, int minRepeats, double minSeconds)
{
  vtkSMPTools::Initialize(threads);
  std::vector<double> times;
  TimeUpdates(deform, lattice, rng, minRepeats, minSeconds, times);
  return Summarize(times);
}

/**
 * Builds voxelize -> lattice -> deform over `mesh` with `divisions` per axis, binds once, then for each thread
 * count times Update() after moving the lattice: repeated at least `minRepeats` times and until `minSeconds`
 * have been spent, best and median kept.
 */
void BenchmarkMesh(vtkPolyData* mesh, bool useDouble, int divisions, const std::vector<int>& threadCounts,
  int minRepeats, double minSeconds, const std::vector<double>& peaks, std::vector<Row>& rows)
{
  BenchmarkLattice lattice;
  BuildLattice(mesh, vtkFFDBuildLattice::BERNSTEIN, divisions, lattice);
  vtkNew<vtkFFDDeform> deform;
  std::mt19937 rng(8);
  const double bindSeconds = BindOnce(deform, mesh, lattice, rng);
  if (bindSeconds < 0.0)
  {
    return;
  }
  for (size_t t = 0; t < threadCounts.size(); ++t)
  {
    const Timing timing = TimeEvaluation(deform, lattice, rng, threadCounts[t], minRepeats, minSeconds);
    rows.push_back({ (divisions + 1) * (divisions + 1) * (divisions + 1), mesh->GetNumberOfPoints(),
      useDouble ? "float64" : "float32", vtkSMPTools::GetEstimatedNumberOfThreads(), bindSeconds, timing,
      OperationsPerPoint(divisions, divisions, divisions), peaks[2 * t + (useDouble ? 1 : 0)] });
    PrintRow(rows.back());
  }
}

//------------------------------------------------------------------------------------------------------------
// The global section: the FMA peak, then the Bernstein evaluation for 5^3 and 10^3 control points. Returns
// false when a pipeline failed.
bool RunGlobalSection(
  const std::vector<vtkSmartPointer<vtkPolyData>>& meshes, const std::vector<int>& threadCounts, bool quick)
{
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
      std::printf(
        "  %-13s %2d thread(s): float32 %7.2f G/s, float64 %7.2f G/s\n", kernel->Name, threads, f * 1e-9, d * 1e-9);
      if (kernel == best)
      {
        peaks.push_back(f);
        peaks.push_back(d);
      }
    }
  }

  std::printf("\nGlobal Bernstein evaluation (vtkFFDDeform::Update() after moving the lattice, binding cached).\n"
              "ops/point: 3 FMAs per control point + outer sums + basis (%.0f for 5^3, %.0f for 10^3);\n"
              "%% of peak: (points/s * ops/point) / the FMA peak above for the same precision and threads.\n"
              "bind+1st: the first Update(), binding included, on all threads; best, median: evaluation only.\n\n",
    OperationsPerPoint(4, 4, 4), OperationsPerPoint(9, 9, 9));
  std::printf(
    "| ctrl | points    | type    | th | bind+1st | best (s) | median   | Mpoints/s | Gops/s   | %% peak   |\n");
  std::printf(
    "|-----:|----------:|---------|---:|---------:|---------:|---------:|----------:|---------:|---------:|\n");
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
  return rows.size() == 2 * 2 * 2 * threadCounts.size();
}

//------------------------------------------------------------------------------------------------------------
// The bases section: every basis against the machine's copy bandwidth, and CUBIC_BSPLINE against VTK's
// vtkBSplineTransform.

/**
 * Two buffers of the same size for the copy bandwidth, both written once so that page faults are not timed.
 * Measure(): bytes read plus bytes written per second when `threads` threads each std::memcpy their share of
 * the source into the target at once, best of `trials`.
 */
struct CopyBuffers
{
  std::vector<char> Source, Target;

  explicit CopyBuffers(size_t bytes)
    : Source(bytes, 1)
    , Target(bytes, 0)
  {
  }

  double Measure(int threads, int trials)
  {
    const size_t bytes = this->Source.size();
    double best = 0.0;
    for (int trial = 0; trial < trials; ++trial)
    {
      std::vector<std::thread> pool;
      const Clock::time_point begin = Clock::now();
      for (int t = 0; t < threads; ++t)
      {
        pool.emplace_back(
          [this, bytes, threads, t]()
          {
            const size_t first = bytes * t / threads, last = bytes * (t + 1) / threads;
            std::memcpy(this->Target.data() + first, this->Source.data() + first, last - first);
          });
      }
      for (std::thread& th : pool)
      {
        th.join();
      }
      best = std::max(best, 2.0 * double(bytes) / Seconds(begin));
    }
    static volatile char sink = 0;
    sink = sink + this->Target[bytes / 2]; // the copies are used, so none is optimised away
    return best;
  }
};

/// The copy bandwidth and the evaluation of a row, measured side by side (MeasureSideBySide()).
struct SideBySide
{
  double Bandwidth = 0.0; // best over the rounds
  Timing Evaluation;      // best and median over every timed update of every round
};

/**
 * The copy bandwidth and vtkFFDDeform::Update() on `threads` threads, measured in `rounds` rounds spread over
 * the row's time, so that the best of each comes from the same seconds of a shared machine: each round copies
 * (CopyBuffers::Measure(), best of 2), runs one untimed update (the copy evicted what a 0.4 M-point mesh keeps
 * in the caches between a user's updates), then times updates for minSeconds / rounds. Measured once just
 * before the row instead, the copy met another load than the evaluation: in one run the 6.7 M-point float32 row
 * took 1.7x its time of the runs before and after, the copy beside it unchanged.
 */
SideBySide MeasureSideBySide(CopyBuffers& copy, vtkFFDDeform* deform, BenchmarkLattice& lattice, std::mt19937& rng,
  int threads, int rounds, int minRepeats, double minSeconds)
{
  SideBySide measured;
  std::vector<double> times;
  vtkSMPTools::Initialize(threads); // the copy starts its own threads
  for (int round = 0; round < rounds; ++round)
  {
    measured.Bandwidth = std::max(measured.Bandwidth, copy.Measure(threads, 2));
    MoveLattice(lattice.Grid, lattice.Rest, rng);
    deform->Update();
    TimeUpdates(deform, lattice, rng, (minRepeats + rounds - 1) / rounds, minSeconds / rounds, times);
  }
  measured.Evaluation = Summarize(times);
  return measured;
}

/// Bytes a local evaluation must move per point: read the input point and its 4-byte cell, write the output.
int BytesPerPoint(bool useDouble)
{
  const int point = 3 * (useDouble ? int(sizeof(double)) : int(sizeof(float)));
  return point + int(sizeof(int)) + point;
}

/**
 * Writes the lattice's displacements (points minus rest positions) into VTK's B-spline coefficients, which
 * are the same numbers: the CUBIC_BSPLINE lattice's control point (i, j, k) is coefficient (i, j, k).
 */
void SetCoefficients(vtkImageData* coefficients, const BenchmarkLattice& lattice)
{
  vtkDataArray* values = coefficients->GetPointData()->GetScalars();
  for (vtkIdType p = 0; p < lattice.Grid->GetNumberOfPoints(); ++p)
  {
    double x[3];
    lattice.Grid->GetPoint(p, x);
    values->SetTuple3(p, x[0] - lattice.Rest[3 * p], x[1] - lattice.Rest[3 * p + 1], x[2] - lattice.Rest[3 * p + 2]);
  }
  values->Modified();
  coefficients->Modified();
}

/// VTK's B-spline deformation of a mesh: vtkTransformFilter with a vtkBSplineTransform.
struct VtkBSpline
{
  vtkNew<vtkImageData> Coefficients;
  vtkNew<vtkBSplineTransform> Transform;
  vtkNew<vtkTransformFilter> Filter;

  /**
   * The B-spline grid of a CUBIC_BSPLINE lattice over an axis-aligned frame: origin at the rest position of
   * control point (0, 0, 0) (one spacing outside the frame), spacing = frame edge / divisions, border mode
   * Edge. False when the frame is not axis-aligned (vtkImageData has no orientation in VTK 9.1).
   */
  bool SetUp(vtkPolyData* mesh, const BenchmarkLattice& lattice, int divisions)
  {
    double frame[12];
    if (!vtkFFDDataContract::GetFrame(lattice.Grid, frame))
    {
      return false;
    }
    for (int axis = 0; axis < 3; ++axis)
    {
      for (int c = 0; c < 3; ++c)
      {
        if (c != axis && frame[3 + 3 * axis + c] != 0.0)
        {
          return false;
        }
      }
    }
    int dims[3];
    lattice.Grid->GetDimensions(dims);
    this->Coefficients->SetDimensions(dims);
    this->Coefficients->SetOrigin(lattice.Rest.data());
    this->Coefficients->SetSpacing(frame[3] / divisions, frame[7] / divisions, frame[11] / divisions);
    this->Coefficients->AllocateScalars(VTK_DOUBLE, 3);
    SetCoefficients(this->Coefficients, lattice);
    this->Transform->SetCoefficientData(this->Coefficients);
    this->Transform->SetBorderModeToEdge();
    this->Transform->SetDisplacementScale(1.0);
    this->Filter->SetInputData(mesh);
    this->Filter->SetTransform(this->Transform);
    return true;
  }

  /// Follows the lattice's current displacements and runs the filter; returns the seconds of Update().
  double Run(const BenchmarkLattice& lattice)
  {
    SetCoefficients(this->Coefficients, lattice);
    this->Transform->Modified();
    const Clock::time_point begin = Clock::now();
    this->Filter->Update();
    return Seconds(begin);
  }
};

/// Largest distance between the points of two point sets of the same size.
double MaxDistance(vtkPointSet* a, vtkPointSet* b)
{
  double largest = 0.0;
  for (vtkIdType p = 0; p < a->GetNumberOfPoints(); ++p)
  {
    double x[3], y[3];
    a->GetPoint(p, x);
    b->GetPoint(p, y);
    largest = std::max(largest,
      std::sqrt((x[0] - y[0]) * (x[0] - y[0]) + (x[1] - y[1]) * (x[1] - y[1]) + (x[2] - y[2]) * (x[2] - y[2])));
  }
  return largest;
}

/// The divisions of the CUBIC_BSPLINE lattice compared with VTK's vtkBSplineTransform (bases and inverse sections).
constexpr int VtkDivisions = 7;

/// One lattice set-up of the bases table.
struct BasisCase
{
  int Basis;
  int Divisions;
};

/// A VTK row: vtkBSplineTransform against vtkFFDDeform's CUBIC_BSPLINE on the same lattice.
struct VtkRow
{
  vtkIdType Points;
  const char* Precision;
  int Threads;
  Timing Vtk;
  Timing Ours;
  double RelativeDifference; // largest point distance / the mesh's bounding-box diagonal
};

/**
 * For each mesh, precision, basis case and thread count: vtkFFDDeform::Update() timed as in the global
 * section, its points per second turned into bytes per second (BytesPerPoint) and compared with the copy
 * bandwidth of the same thread count, the two measured side by side (MeasureSideBySide(): the load of a shared
 * machine drifts within a run, and a copy measured once at the start swung from 39 to 64 GB/s between runs
 * minutes apart). For CUBIC_BSPLINE over `VtkDivisions`, VTK's vtkBSplineTransform + vtkTransformFilter on the
 * same mesh and lattice, timed as in the global section. Returns false when a pipeline failed.
 */
bool RunBasesSection(
  const std::vector<vtkSmartPointer<vtkPolyData>>& meshes, const std::vector<int>& threadCounts, bool quick)
{
  // 256 MB per buffer: far beyond the caches (32 MB of L3 on this class of CPU), as the 5 M-point meshes are.
  CopyBuffers copy(size_t(quick ? 32 : 256) << 20);

  // Every basis over 4 x 4 x 4 voxels (the global one's cost grows with its degree, so it stays at 4), and the
  // local ones again over lattices of about 10^3 control points: their cost per point should not change.
  const std::vector<BasisCase> cases = { { vtkFFDBuildLattice::BERNSTEIN, 4 }, { vtkFFDBuildLattice::TRILINEAR, 4 },
    { vtkFFDBuildLattice::TRILINEAR, 9 }, { vtkFFDBuildLattice::TRIQUADRATIC_BEZIER, 4 },
    { vtkFFDBuildLattice::TRICUBIC_BEZIER, 4 }, { vtkFFDBuildLattice::TRICUBIC_BEZIER, 3 },
    { vtkFFDBuildLattice::CUBIC_BSPLINE, 4 }, { vtkFFDBuildLattice::CUBIC_BSPLINE, VtkDivisions } };
  const int minRepeats = quick ? 2 : 3;
  const double minSeconds = quick ? 0.0 : 0.5;
  const int rounds = quick ? 1 : 5; // of MeasureSideBySide()
  std::printf("\nEvaluation per basis (vtkFFDDeform::Update() after moving the lattice, binding cached).\n"
              "bytes/point: what the evaluation must move: read the point and its 4-byte cell, write the point "
              "(%d float32, %d float64);\nGB/s: Mpoints/s * bytes/point; copy: std::memcpy of a %zu MB buffer "
              "into another on the same threads, split between them, bytes read + written per second;\n"
              "the copy and the evaluation measured side by side, in rounds over the row's time (%d; each: 2 "
              "copies, one untimed update, updates for %.1f s), the best of each kept; %% copy: GB/s of copy.\n"
              "bind+1st: the first Update(), binding included, on all threads; best, median: evaluation only.\n\n",
    BytesPerPoint(false), BytesPerPoint(true), copy.Source.size() >> 20, rounds, minSeconds / rounds);
  std::printf("| basis               | div | ctrl | points    | type    | th | bind+1st | best (s) | median   | "
              "Mpoints/s | GB/s   | copy   | %% copy  |\n");
  std::printf("|---------------------|----:|-----:|----------:|---------|---:|---------:|---------:|---------:|"
              "----------:|-------:|-------:|--------:|\n");
  std::vector<VtkRow> vtkRows;
  bool ok = true;
  for (const auto& mesh : meshes)
  {
    for (bool useDouble : { false, true })
    {
      vtkSmartPointer<vtkPolyData> input = WithPrecision(mesh, useDouble);
      for (const BasisCase& c : cases)
      {
        BenchmarkLattice lattice;
        BuildLattice(input, c.Basis, c.Divisions, lattice);
        vtkNew<vtkFFDDeform> deform;
        std::mt19937 rng(8);
        const double bindSeconds = BindOnce(deform, input, lattice, rng);
        if (bindSeconds < 0.0)
        {
          ok = false;
          continue;
        }
        VtkBSpline vtk;
        const bool compare = c.Basis == vtkFFDBuildLattice::CUBIC_BSPLINE && c.Divisions == VtkDivisions;
        if (compare && !vtk.SetUp(input, lattice, c.Divisions))
        {
          std::fprintf(stderr, "The frame is not axis-aligned: VTK's B-spline grid cannot follow it\n");
          ok = false;
        }
        for (size_t t = 0; t < threadCounts.size(); ++t)
        {
          const SideBySide measured =
            MeasureSideBySide(copy, deform, lattice, rng, threadCounts[t], rounds, minRepeats, minSeconds);
          const double bandwidth = measured.Bandwidth;
          const Timing& timing = measured.Evaluation;
          const double pointsPerSecond = input->GetNumberOfPoints() / timing.Best;
          const double bytesPerSecond = pointsPerSecond * BytesPerPoint(useDouble);
          std::printf("| %-19s | %3d | %4lld | %9lld | %-7s | %2d | %8.3f | %8.4f | %8.4f | %9.2f | %6.2f | "
                      "%6.2f | %5.1f %% |\n",
            vtkFFDBuildLattice::GetBasisAsString(c.Basis), c.Divisions,
            static_cast<long long>(lattice.Grid->GetNumberOfPoints()),
            static_cast<long long>(input->GetNumberOfPoints()), useDouble ? "float64" : "float32",
            vtkSMPTools::GetEstimatedNumberOfThreads(), bindSeconds, timing.Best, timing.Median, pointsPerSecond * 1e-6,
            bytesPerSecond * 1e-9, bandwidth * 1e-9, 100.0 * bytesPerSecond / bandwidth);
          std::fflush(stdout);
          if (compare && ok)
          {
            // VTK on the same thread count (vtkSMPTools is still initialized to it), then both on one lattice
            // state, to check that they compute the same deformation.
            const Timing vtkTiming = Repeat(
              [&]()
              {
                MoveLattice(lattice.Grid, lattice.Rest, rng);
                return vtk.Run(lattice);
              },
              minRepeats, minSeconds);
            MoveLattice(lattice.Grid, lattice.Rest, rng);
            deform->Update();
            vtk.Run(lattice);
            vtkRows.push_back({ input->GetNumberOfPoints(), useDouble ? "float64" : "float32",
              vtkSMPTools::GetEstimatedNumberOfThreads(), vtkTiming, timing,
              MaxDistance(deform->GetOutput(), vtk.Filter->GetOutput()) / input->GetLength() });
          }
        }
      }
    }
  }

  std::printf("\nVTK's vtkBSplineTransform + vtkTransformFilter against CUBIC_BSPLINE over %d^3 voxels "
              "(%d^3 control points), the same mesh and lattice\n(coefficients = the lattice's displacements, "
              "origin = rest position of control point (0, 0, 0), spacing = frame edge / %d, border mode Edge).\n"
              "difference: largest distance between the two outputs / the mesh's bounding-box diagonal.\n\n",
    VtkDivisions, VtkDivisions + 3, VtkDivisions);
  std::printf("| points    | type    | th | VTK best (s) | VTK median | VTK Mpoints/s | ours best (s) | "
              "ours Mpoints/s | speed-up | difference |\n");
  std::printf("|----------:|---------|---:|-------------:|-----------:|--------------:|--------------:|"
              "---------------:|---------:|-----------:|\n");
  for (const VtkRow& r : vtkRows)
  {
    std::printf("| %9lld | %-7s | %2d | %12.4f | %10.4f | %13.2f | %13.4f | %14.2f | %7.1fx | %10.1e |\n",
      static_cast<long long>(r.Points), r.Precision, r.Threads, r.Vtk.Best, r.Vtk.Median, r.Points / r.Vtk.Best * 1e-6,
      r.Ours.Best, r.Points / r.Ours.Best * 1e-6, r.Vtk.Best / r.Ours.Best, r.RelativeDifference);
  }
  return ok && vtkRows.size() == 2 * 2 * threadCounts.size();
}
//------------------------------------------------------------------------------------------------------------
// The inverse section.

/// The diagonal |S + T + U| of a lattice's frame: what vtkFFDInverseDeform's Tolerance is relative to.
double FrameDiagonal(vtkDataObject* lattice)
{
  double f[12];
  if (!vtkFFDDataContract::GetFrame(lattice, f))
  {
    return 0.0;
  }
  return std::sqrt((f[3] + f[6] + f[9]) * (f[3] + f[6] + f[9]) + (f[4] + f[7] + f[10]) * (f[4] + f[7] + f[10]) +
    (f[5] + f[8] + f[11]) * (f[5] + f[8] + f[11]));
}

/// One row of the inverse table: a filter that maps the deformed mesh back to rest positions, its times and errors.
struct InverseRow
{
  const char* Name;
  vtkAlgorithm* Filter;
  int Threads; // vtkSMPTools' threads while it runs
  std::vector<double> Times;
  double RestError = 0.0;     // largest |x - x*| / d: x found, x* the mesh's own rest point, d the frame's diagonal
  double ResidualError = 0.0; // largest |F(x) - y| / d: F evaluated by vtkFFDDeform, y the deformed point
};

/// Times Update() of each row's filter `repeats` times (Modified() before each), the rows taking turns so that
/// a shared machine's load weighs on them alike; then their errors from their last outputs, against the rest
/// mesh and, mapped by `forward` again, against the deformed mesh.
void TimeInverses(std::vector<InverseRow>& rows, int repeats, vtkPolyData* rest, vtkPolyData* deformed,
  vtkFFDDeform* forward, double diagonal)
{
  for (int r = 0; r < repeats; ++r)
  {
    for (InverseRow& row : rows)
    {
      vtkSMPTools::Initialize(row.Threads);
      row.Filter->Modified();
      const Clock::time_point begin = Clock::now();
      row.Filter->Update();
      row.Times.push_back(Seconds(begin));
    }
  }
  for (InverseRow& row : rows)
  {
    vtkPointSet* found = vtkPointSet::SafeDownCast(row.Filter->GetOutputDataObject(0));
    row.RestError = MaxDistance(found, rest) / diagonal;
    vtkNew<vtkPolyData> copy;
    copy->ShallowCopy(found);
    forward->SetInputData(copy);
    forward->Update();
    row.ResidualError = MaxDistance(forward->GetOutput(), deformed) / diagonal;
  }
}

/**
 * vtkFFDInverseDeform against VTK's vtkBSplineTransform::GetInverse() in a vtkTransformFilter (the same
 * coefficients as in the bases section), at VTK's default InverseTolerance (0.001, in world units) and at
 * 1e-12 of the frame's diagonal (as vtkFFDInverseDeform's default Tolerance), in one run: the mesh (float64)
 * is deformed once by CUBIC_BSPLINE over VtkDivisions^3 voxels, its control points moved as in the other sections;
 * each inverse maps it back. Median and best of `repeats` updates, taking turns: vtkFFDInverseDeform on all threads
 * and on one (VTK's runs on one). Returns false on failure.
 */
bool RunInverseSection(vtkPolyData* mesh, bool quick)
{
  vtkSmartPointer<vtkPolyData> rest = WithPrecision(mesh, true);
  BenchmarkLattice lattice;
  BuildLattice(rest, vtkFFDBuildLattice::CUBIC_BSPLINE, VtkDivisions, lattice);
  std::mt19937 rng(8);
  MoveLattice(lattice.Grid, lattice.Rest, rng);
  const double diagonal = FrameDiagonal(lattice.Grid);
  vtkNew<vtkFFDDeform> forward;
  forward->SetInputData(rest);
  forward->SetLatticeData(lattice.Grid);
  forward->SetOutputPointsPrecision(vtkAlgorithm::DOUBLE_PRECISION);
  forward->Update();
  vtkNew<vtkPolyData> deformed;
  deformed->DeepCopy(forward->GetOutput());
  VtkBSpline vtk[2]; // at the default InverseTolerance, and at 1e-12 d
  for (VtkBSpline& v : vtk)
  {
    if (deformed->GetNumberOfPoints() != rest->GetNumberOfPoints() || !v.SetUp(deformed, lattice, VtkDivisions))
    {
      std::fprintf(stderr, "The inverse section could not deform the mesh, or its frame is not axis-aligned\n");
      return false;
    }
    v.Filter->SetTransform(v.Transform->GetInverse());
    v.Filter->SetOutputPointsPrecision(vtkAlgorithm::DOUBLE_PRECISION);
  }
  // Set on the forward transform: its inverse copies it at each update.
  vtk[1].Transform->SetInverseTolerance(1e-12 * diagonal);
  vtkNew<vtkFFDInverseDeform> ours;
  ours->SetInputData(deformed);
  ours->SetLatticeData(lattice.Grid);
  const int repeats = quick ? 1 : 7;
  const int all = vtkSMPTools::GetEstimatedNumberOfThreads();
  std::vector<InverseRow> rows = { { "vtkFFDInverseDeform, Tolerance 1e-12", ours, all },
    { "vtkFFDInverseDeform, 1 thread", ours, 1 }, { "VTK GetInverse(), InverseTolerance 0.001", vtk[0].Filter, all },
    { "VTK GetInverse(), InverseTolerance 1e-12 d", vtk[1].Filter, all } };
  TimeInverses(rows, repeats, rest, deformed, forward, diagonal);
  vtkSMPTools::Initialize(all);
  const vtkIdType unreliable = ours->GetNumberOfFoldedPoints() + ours->GetNumberOfUnconvergedPoints();

  std::printf("\nInverse: the mesh (%lld points, float64) deformed by CUBIC_BSPLINE over %d^3 voxels (%d^3 control "
              "points, moved as above), mapped back to its rest positions; vtkFFDInverseDeform on %d threads and on 1 "
              "(vtkTransformFilter runs VTK's inverse on one);\nmedian and best of %d "
              "updates, the filters taking turns; d: the frame's diagonal (%.4g); x - x*: to the mesh's own points; "
              "F(x) - y: x mapped forward again by vtkFFDDeform;\nvs ours: the median's ratio to "
              "vtkFFDInverseDeform's. vtkFFDInverseDeform: %lld points folded or not converged.\n\n",
    static_cast<long long>(rest->GetNumberOfPoints()), VtkDivisions, VtkDivisions + 3, all, repeats, diagonal,
    static_cast<long long>(unreliable));
  std::printf("| inverse                                    | median (s) | best (s) | max |x - x*| / d | "
              "max |F(x) - y| / d | vs ours |\n");
  std::printf("|--------------------------------------------|-----------:|---------:|----------------:|"
              "------------------:|--------:|\n");
  const double ourMedian = Summarize(rows[0].Times).Median;
  for (const InverseRow& r : rows)
  {
    const Timing t = Summarize(r.Times);
    std::printf("| %-42s | %10.4f | %8.4f | %15.1e | %18.1e | %6.1fx |\n", r.Name, t.Median, t.Best, r.RestError,
      r.ResidualError, t.Median / ourMedian);
  }
  std::fflush(stdout);
  return unreliable == 0;
}
} // namespace

int main(int argc, char* argv[])
{
  bool quick = false;
  std::string section = "all";
  std::string meshPath = std::string(VOXELFFD_MESH_DIR) + "/armadillo.vtp";
  int status = 0;
  if (!ParseArguments(argc, argv,
        { { "--quick", &quick }, { "--section", &section, "global|bases|inverse|all" }, { "--mesh", &meshPath } },
        "[--quick] [--section global|bases|inverse|all] [--mesh path.vtp]", status))
  {
    return status;
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
  // The inverse section alone needs the smaller only.
  meshes.push_back(section == "inverse" ? meshes[0] : Subdivide(meshes[0], levels[1] - levels[0]));
  std::printf("\nMesh %s: %lld points; subdivided %d and %d times: %lld and %lld points (%.1f s)\n", meshPath.c_str(),
    static_cast<long long>(base->GetNumberOfPoints()), levels[0], levels[1],
    static_cast<long long>(meshes[0]->GetNumberOfPoints()), static_cast<long long>(meshes[1]->GetNumberOfPoints()),
    Seconds(subdivideBegin));

  bool ok = true;
  if (section == "global" || section == "all")
  {
    ok = RunGlobalSection(meshes, threadCounts, quick) && ok;
  }
  if (section == "bases" || section == "all")
  {
    ok = RunBasesSection(meshes, threadCounts, quick) && ok;
  }
  if (section == "inverse" || section == "all")
  {
    ok = RunInverseSection(meshes[0], quick) && ok;
  }
  vtkSMPTools::Initialize(0);
  return ok ? 0 : 1;
}
