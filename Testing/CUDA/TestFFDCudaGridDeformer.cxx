// SPDX-License-Identifier: BSD-3-Clause
// The CUDA backend against the CPU path (the same Evaluation/Kernels functions run on the host) for every grid
// basis, on fresh random inputs with fixed seeds, the deformation and its adjoint; device residency (what is
// uploaded on an update); failures.
// Without a CUDA device every test skips.
#include "FFDCellTable.h"
#include "FFDCudaGridDeformer.h"
#include "FFDCudaTestSupport.h"
#include "FFDTestComparisons.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

namespace
{
// A random problem: a skewed frame, divisions, points (mostly inside, some outside, a few non-finite) and
// displacements of up to a fifth of the frame.
struct Problem
{
  double Frame[12];
  int Divisions[3];
  int Basis;
  int Dims[3];
  std::vector<double> Points;
  std::vector<float> Normals;
  std::vector<double> Displacements;

  // Divisions at random (up to 15 for the global basis, 5 for the local ones), or those given.
  Problem(int basis, std::int64_t count, std::mt19937& rng, const int* givenDivisions = nullptr)
    : Basis(basis)
  {
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    // Global degrees up to 15 reach every kernel of the global basis: the tensor-core one (from 400 control
    // points on), both instantiations of the shared-memory one (up to 8 and 16 control points per axis) below.
    std::uniform_int_distribution<int> divisions(1, basis == int(ffd::GridBasis::Bernstein) ? 15 : 5);
    const double base[12] = { -1, -2, 0.5, 2, 0, 0, 0, 3, 0, 0, 0, 1.5 };
    for (int c = 0; c < 12; ++c)
    {
      this->Frame[c] = base[c] + 0.2 * unit(rng);
    }
    const ffd::Frame<double> frame = ffd::Frame<double>::FromArray(this->Frame);
    std::int64_t controlPoints = 1;
    for (int a = 0; a < 3; ++a)
    {
      this->Divisions[a] = givenDivisions ? givenDivisions[a] : divisions(rng);
      this->Dims[a] = ffd::ControlPointsAlongAxis(ffd::GridBasis(basis), this->Divisions[a]);
      controlPoints *= this->Dims[a];
    }
    // Parameters keep 1e-4 away from the frame's faces: within float32 rounding of the band that counts as
    // inside (1e-5 wide in float32), the two sides could clamp differently and so differ in their Jacobians.
    std::uniform_real_distribution<double> parameter(-0.1, 1.1);
    auto draw = [&]
    {
      double v;
      do
      {
        v = parameter(rng);
      } while (std::fabs(v) < 1e-4 || std::fabs(v - 1.0) < 1e-4);
      return v;
    };
    for (std::int64_t i = 0; i < count; ++i)
    {
      const ffd::Vec3<double> x = frame.ToWorld({ draw(), draw(), draw() });
      this->Points.insert(this->Points.end(), { x.x, x.y, x.z });
      const ffd::Vec3<double> n = { unit(rng), unit(rng), unit(rng) };
      const double length = std::sqrt(ffd::Dot(n, n)) + 1e-3;
      this->Normals.insert(this->Normals.end(), { float(n.x / length), float(n.y / length), float(n.z / length) });
    }
    if (count > 11)
    {
      this->Points[3 * 7] = std::numeric_limits<double>::quiet_NaN();
      this->Points[3 * 11 + 1] = std::numeric_limits<double>::infinity();
    }
    for (std::int64_t v = 0; v < 3 * controlPoints; ++v)
    {
      this->Displacements.push_back(0.2 * unit(rng));
    }
  }

  std::int64_t Count() const { return std::int64_t(this->Points.size() / 3); }
  std::int64_t ControlPoints() const { return std::int64_t(this->Dims[0]) * this->Dims[1] * this->Dims[2]; }
  int Cells() const { return this->Divisions[0] * this->Divisions[1] * this->Divisions[2]; }
  bool TakesCellTable() const
  {
    return ffd::cuda::GridDeformer::WorthCellTable(this->Basis, this->Cells(), this->Count());
  }
};

// The CPU path: the same kernels on the host, in the precision Real of the GPU run (the binding in double, as
// on both backends), from a cell table (ffd::FillCellTable()) where CellTable.
template <int MaxCount, typename Real, bool CellTable>
void CpuDeform(const Problem& p, bool clampOutside, std::vector<double>& points, std::vector<double>& normals,
  std::vector<double>& determinants, std::vector<double>& jacobianScales)
{
  const ffd::Frame<double> binding = ffd::Frame<double>::FromArray(p.Frame);
  const std::vector<Real> displacements(p.Displacements.begin(), p.Displacements.end());
  ffd::GridDeformation<MaxCount, Real, -1, Real, CellTable> deformation{ ffd::GridBasis(p.Basis),
    { p.Divisions[0], p.Divisions[1], p.Divisions[2] }, { p.Dims[0], p.Dims[1], p.Dims[2] }, displacements.data(),
    ffd::Frame<Real>::FromArray(p.Frame) };
  std::vector<Real> table;
  if constexpr (CellTable)
  {
    const int cells = p.Cells();
    table.resize(std::size_t(cells) * ffd::CellTableStride(ffd::CellDegree(ffd::GridBasis(p.Basis))));
    ffd::FillCellTable(
      ffd::GridBasis(p.Basis), displacements.data(), p.Divisions, p.Dims, nullptr, nullptr, table.data(), 0, cells);
    deformation.CellTable = table.data();
  }
  for (std::int64_t i = 0; i < p.Count(); ++i)
  {
    const ffd::Vec3<Real> x = ffd::Vec3<Real>::From(&p.Points[3 * i]);
    const int cell = ffd::BindToGrid(
      binding, ffd::GridBasis(p.Basis), p.Divisions, { double(x.x), double(x.y), double(x.z) }, clampOutside);
    ffd::Mat3<Real> j = ffd::Mat3<Real>::Identity();
    const ffd::Vec3<Real> y = cell >= 0 ? deformation.Deform(x, cell, j) : x;
    const ffd::Vec3<Real> n = ffd::TransformNormal(j, ffd::Vec3<Real>::From(&p.Normals[3 * i]));
    points.insert(points.end(), { double(y.x), double(y.y), double(y.z) });
    normals.insert(normals.end(), { double(n.x), double(n.y), double(n.z) });
    determinants.push_back(double(ffd::Determinant(j)));
    // The size of det(J)'s terms, |J e0| |J e1| |J e2|: the scale its rounding error is relative to.
    double scale = 1.0;
    for (int c = 0; c < 3; ++c)
    {
      scale *= std::sqrt(double(j.M[0][c] * j.M[0][c] + j.M[1][c] * j.M[1][c] + j.M[2][c] * j.M[2][c]));
    }
    jacobianScales.push_back(scale);
  }
}

// The CPU path as the device takes it: from a cell table where GridDeformer::WorthCellTable() says the device
// builds one, the same table evaluated by the same Horner's rule (PowerForm()).
template <typename Real>
void CpuDeform(const Problem& p, bool clampOutside, std::vector<double>& points, std::vector<double>& normals,
  std::vector<double>& determinants, std::vector<double>& jacobianScales)
{
  if (p.Basis == int(ffd::GridBasis::Bernstein))
  {
    CpuDeform<ffd::MaxBernsteinDegree + 1, Real, false>(p, clampOutside, points, normals, determinants, jacobianScales);
  }
  else if (p.TakesCellTable())
  {
    CpuDeform<4, Real, true>(p, clampOutside, points, normals, determinants, jacobianScales);
  }
  else
  {
    CpuDeform<4, Real, false>(p, clampOutside, points, normals, determinants, jacobianScales);
  }
}

FFD_REAL_TYPED_TEST_SUITE(CudaGridDeformerTest);

// GPU and CPU agree for every basis and outside policy, each in the precision of the points. Tolerance: 1e-5
// relative to the frame's scale (about 3) in float32, the bound, and 1e-12 in double (the same
// operations; only the compilers' contraction into FMAs differs). Outputs are poisoned first, so unwritten
// values are caught.
TYPED_TEST(CudaGridDeformerTest, MatchesCpuForEveryBasis)
{
  FFD_REQUIRE_DEVICE();
  using Real = TypeParam;
  const double tolerance = (sizeof(Real) == sizeof(float) ? 1e-5 : 1e-12) * 3.0;
  std::mt19937 rng(4242);
  for (int basis = 0; basis <= int(ffd::GridBasis::CubicBSpline); ++basis)
  {
    for (bool clamp : { false, true })
    {
      const Problem p(basis, 100003, rng); // not a multiple of the block size
      std::vector<double> cpuPoints, cpuNormals, cpuDeterminants, jacobianScales;
      CpuDeform<Real>(p, clamp, cpuPoints, cpuNormals, cpuDeterminants, jacobianScales);

      const std::vector<Real> points(p.Points.begin(), p.Points.end());
      ffd::cuda::GridDeformer gpu;
      ASSERT_TRUE(gpu.SetPoints(points.data(), p.Count())) << gpu.GetLastError();
      const std::vector<Real> normals(p.Normals.begin(), p.Normals.end()); // in the points' precision
      ASSERT_TRUE(gpu.SetNormals(normals.data())) << gpu.GetLastError();
      ASSERT_TRUE(gpu.Bind(p.Frame, basis, p.Divisions, clamp)) << gpu.GetLastError();
      const Real poison = Real(-12345.0);
      std::vector<Real> outPoints(points.size(), poison), outDeterminants(p.Count(), poison);
      std::vector<Real> outNormals(points.size(), poison);
      ASSERT_TRUE(gpu.Evaluate(p.Displacements.data(), p.ControlPoints(), true, true)) << gpu.GetLastError();
      ASSERT_TRUE(gpu.Download(outPoints.data(), outNormals.data(), outDeterminants.data())) << gpu.GetLastError();

      // Normals and det(J) carry the rounding of the Jacobian, which the conditioning of J amplifies: det(J)
      // within 1e-5 in float32 (1e-12 in double) of the size of its terms, |J e0||J e1||J e2|; unit normals
      // within 1e-5 times the ratio of that size to |det J| (a bound on J's condition number) in float32, and
      // 1e-12 times it in double (normals are uploaded, transformed and downloaded in the points' precision).
      const bool single = sizeof(Real) == sizeof(float);
      ffdtest::Mismatches wrong;
      const auto check = [&](const char* what, std::int64_t i, double got, double expected, double tol)
      { wrong.Check(what, i, got, expected, tol); };
      for (std::int64_t i = 0; i < p.Count(); ++i)
      {
        for (int c = 0; c < 3; ++c)
        {
          check("position", i, double(outPoints[3 * i + c]), cpuPoints[3 * i + c], tolerance);
          const double conditioning = jacobianScales[i] / std::max(std::fabs(cpuDeterminants[i]), 1e-300);
          check(
            "normal", i, double(outNormals[3 * i + c]), cpuNormals[3 * i + c], (single ? 1e-5 : 1e-12) * conditioning);
        }
        check("det", i, double(outDeterminants[i]), cpuDeterminants[i],
          (single ? 1e-5 : 1e-12) * std::max(1.0, jacobianScales[i]));
      }
      // Without normals and determinants the global basis takes its own kernel (BernsteinKernel): the points
      // alone, evaluated again into a freshly poisoned buffer.
      std::fill(outPoints.begin(), outPoints.end(), poison);
      ASSERT_TRUE(gpu.Evaluate(p.Displacements.data(), p.ControlPoints(), false, false)) << gpu.GetLastError();
      ASSERT_TRUE(gpu.Download(outPoints.data(), nullptr, nullptr)) << gpu.GetLastError();
      for (std::size_t v = 0; v < outPoints.size(); ++v)
      {
        check("position without Jacobian", std::int64_t(v / 3), double(outPoints[v]), cpuPoints[v], tolerance);
      }
      EXPECT_EQ(wrong.Count, 0) << "basis " << basis << (clamp ? " clamped" : " kept") << ": " << wrong.First;
      // 100003 points in at most 125 cells: both evaluations of the triquadratic and cubic bases from tables.
      const bool tables = basis >= int(ffd::GridBasis::TriquadraticBezier);
      EXPECT_EQ(gpu.GetCounters().CellTables, tables ? 2u : 0u) << "basis " << basis;
    }
  }
}

// The problem's points (and normals) in the order of the cells they are bound to (unbound ones first).
void SortByCell(Problem& p, bool clamp)
{
  const ffd::Frame<double> frame = ffd::Frame<double>::FromArray(p.Frame);
  std::vector<std::pair<int, std::int64_t>> order;
  for (std::int64_t i = 0; i < p.Count(); ++i)
  {
    order.emplace_back(
      ffd::BindToGrid(frame, ffd::GridBasis(p.Basis), p.Divisions, ffd::Vec3<double>::From(&p.Points[3 * i]), clamp),
      i);
  }
  std::stable_sort(order.begin(), order.end());
  std::vector<double> points;
  std::vector<float> normals;
  for (const auto& entry : order)
  {
    points.insert(points.end(), p.Points.begin() + 3 * entry.second, p.Points.begin() + 3 * entry.second + 3);
    normals.insert(normals.end(), p.Normals.begin() + 3 * entry.second, p.Normals.begin() + 3 * entry.second + 3);
  }
  p.Points.swap(points);
  p.Normals.swap(normals);
}

// Float32 points without normals or determinants (the kernels of an ordinary update: the float4 lattice, the
// global basis's tensor-core and shared-memory kernels, DeformPointsKernel, DeformKernel, the cell tables) against
// the CPU path (from the same cell table where the device takes one, which the device's counter confirms), on
// fresh random problems, within 1e-5 of the frame's scale (about 3), the bound: for the global basis
// against the CPU in float64 (the tensor cores' error-compensated TF32 must keep float32 accuracy), for the local
// ones against the CPU in float32, the same function in the same precision (at 255 voxels along an axis float32
// parameters alone, on the CPU as on the GPU, are 2e-5 away from float64). Outputs are poisoned first. Counts
// that are not multiples of the kernels' 4 points a thread or 32-point tiles, and lattices that reach each
// kernel: for the global basis up to and past 16 control points per axis, on either side of the 400 control
// points where the tensor-core kernel takes over; for the local ones many voxels per axis (the cell index is
// split by multiplications on the device).
void ExpectFloatMatchesCpu(int basis, const int divisions[3], std::int64_t count, bool clamp, bool againstDouble,
  std::mt19937& rng, double* worst = nullptr, bool cellOrder = false)
{
  Problem p(basis, count, rng, divisions);
  if (cellOrder) // grouped by cell, as a mesh's points mostly are: the kernels' paths for points of one cell
  {
    SortByCell(p, clamp);
  }
  std::vector<double> cpuPoints, cpuNormals, cpuDeterminants, jacobianScales;
  if (againstDouble)
  {
    CpuDeform<double>(p, clamp, cpuPoints, cpuNormals, cpuDeterminants, jacobianScales);
  }
  else
  {
    CpuDeform<float>(p, clamp, cpuPoints, cpuNormals, cpuDeterminants, jacobianScales);
  }
  const std::vector<float> points(p.Points.begin(), p.Points.end());
  ffd::cuda::GridDeformer gpu;
  ASSERT_TRUE(gpu.SetPoints(points.data(), p.Count())) << gpu.GetLastError();
  ASSERT_TRUE(gpu.Bind(p.Frame, basis, p.Divisions, clamp)) << gpu.GetLastError();
  std::vector<float> out(points.size(), -12345.0f);
  ASSERT_TRUE(gpu.Evaluate(p.Displacements.data(), p.ControlPoints(), false, false)) << gpu.GetLastError();
  ASSERT_TRUE(gpu.Download(out.data(), nullptr, nullptr)) << gpu.GetLastError();
  double largest = 0;
  ffdtest::Mismatches wrong;
  for (std::size_t v = 0; v < out.size(); ++v)
  {
    // Against float64, the float32 rounding of the input point itself is no error of the evaluation: the
    // reference starts from the double point, so compare the displacements (y - x). Kept points exactly.
    const double x = againstDouble ? p.Points[v] : double(points[v]), expected = cpuPoints[v], got = double(out[v]);
    const double error = std::isfinite(expected) ? std::fabs((got - double(points[v])) - (expected - x)) : 0.0;
    const bool ok = std::isfinite(expected) ? error <= 1e-5 * 3.0 : ffdtest::Same(got, double(points[v]), 0.0);
    largest = std::max(largest, std::isfinite(error) ? error : 1e30);
    if (!ok)
    {
      wrong.Add("value " + std::to_string(v), got, expected);
    }
  }
  EXPECT_EQ(wrong.Count, 0) << "basis " << basis << " divisions " << divisions[0] << "x" << divisions[1] << "x"
                            << divisions[2] << ", " << count << " points" << (clamp ? " clamped" : "") << ": "
                            << wrong.First;
  EXPECT_EQ(gpu.GetCounters().CellTables, p.TakesCellTable() ? 1u : 0u) << "the reference took the other path";
  if (worst)
  {
    *worst = std::max(*worst, largest);
  }
}

TEST(CudaGridDeformer, GlobalBasisInFloatMatchesDouble)
{
  FFD_REQUIRE_DEVICE();
  std::mt19937 rng(20261123);
  const int cases[][3] = { { 10, 10, 10 }, { 15, 15, 15 }, { 7, 7, 7 }, { 6, 6, 6 }, { 15, 2, 8 }, { 1, 15, 4 },
    { 8, 15, 11 }, { 12, 1, 15 }, { 3, 3, 3 }, { 7, 9, 5 }, { 16, 4, 4 } };
  double worst = 0;
  int n = 0;
  for (const auto& divisions : cases)
  {
    const std::int64_t count = n % 3 == 0 ? 100003 : (n % 3 == 1 ? 31 : 4099);
    ExpectFloatMatchesCpu(int(ffd::GridBasis::Bernstein), divisions, count, n % 2 == 1, true, rng, &worst);
    ++n;
  }
  std::printf("global basis, float32 without Jacobian against float64: largest error %.2e\n", worst);
}

TEST(CudaGridDeformer, LocalBasesInFloatMatchCpu)
{
  FFD_REQUIRE_DEVICE();
  std::mt19937 rng(1123);
  const int cases[][3] = { { 1, 1, 1 }, { 33, 7, 100 }, { 127, 64, 3 }, { 2, 255, 9 }, { 5, 5, 5 } };
  const std::int64_t counts[] = { 100003, 4, 3, 50001, 7 };
  double worst = 0;
  for (int basis = int(ffd::GridBasis::Trilinear); basis <= int(ffd::GridBasis::CubicBSpline); ++basis)
  {
    for (int c = 0; c < 5; ++c)
    {
      ExpectFloatMatchesCpu(basis, cases[c], counts[(c + basis) % 5], (c + basis) % 2 == 0, false, rng, &worst);
      // Points grouped by cell: most fours of a thread share their cell (DeformPointsKernel's Grouped path).
      ExpectFloatMatchesCpu(basis, cases[c], counts[(c + basis) % 5], (c + basis) % 2 == 1, false, rng, &worst, true);
    }
    // Enough points a cell for a cell table (triquadratic and cubic bases), in random and in cell order.
    const int few[3] = { 3, 4, 2 };
    ExpectFloatMatchesCpu(basis, few, 20011, basis % 2 == 0, false, rng, &worst);
    ExpectFloatMatchesCpu(basis, few, 20011, basis % 2 == 1, false, rng, &worst, true);
  }
  std::printf("local bases, float32 without Jacobian against the CPU in float32: largest error %.2e\n", worst);
}

// Downloads on either side of the size from which they go through two lanes (two staging buffers' worth, 4 MB:
// each half through its own stream and host thread), the halves split inside a point: every value arrives, as the
// CPU computes it (outputs poisoned first).
TEST(CudaGridDeformer, DownloadsOfEverySizeArriveWhole)
{
  FFD_REQUIRE_DEVICE();
  std::mt19937 rng(4096);
  const int divisions[3] = { 3, 2, 4 };
  for (std::int64_t count : { 349525, 349526, 1000003 }) // 4 MB = 349525.3 points
  {
    ExpectFloatMatchesCpu(int(ffd::GridBasis::Trilinear), divisions, count, false, false, rng);
  }
}

// Only the lattice crosses the bus on an update: the points and the binding stay on the device.
TEST(CudaGridDeformer, UpdatesUploadOnlyTheLattice)
{
  FFD_REQUIRE_DEVICE();
  std::mt19937 rng(7);
  const Problem p(int(ffd::GridBasis::CubicBSpline), 50000, rng);
  const std::vector<float> points(p.Points.begin(), p.Points.end());
  ffd::cuda::GridDeformer gpu;
  ASSERT_TRUE(gpu.SetPoints(points.data(), p.Count()));
  ASSERT_TRUE(gpu.Bind(p.Frame, p.Basis, p.Divisions, false));
  std::vector<float> first(points.size(), -1.0f), second(points.size(), -1.0f);
  ASSERT_TRUE(gpu.Evaluate(p.Displacements.data(), p.ControlPoints(), false, false));
  ASSERT_TRUE(gpu.Download(first.data(), nullptr, nullptr));
  std::vector<double> moved = p.Displacements;
  moved[3 * (p.ControlPoints() / 2)] += 0.5;
  ASSERT_TRUE(gpu.Evaluate(moved.data(), p.ControlPoints(), false, false));
  ASSERT_TRUE(gpu.Download(second.data(), nullptr, nullptr));

  const ffd::cuda::Counters& c = gpu.GetCounters();
  EXPECT_EQ(c.PointUploads, 1u);
  EXPECT_EQ(c.Bindings, 1u);
  EXPECT_EQ(c.LatticeUploads, 2u);
  EXPECT_EQ(c.LatticeBytes, 2u * std::uint64_t(p.ControlPoints()) * 3 * sizeof(float));
  EXPECT_EQ(c.BytesDownloaded, 2u * points.size() * sizeof(float));
  EXPECT_NE(first, second); // the moved control point moved some points

  // Trilinear in float32 without normals or determinants takes the lattice as float4: 16 bytes per control point.
  const Problem t(int(ffd::GridBasis::Trilinear), 1000, rng);
  const std::vector<float> tPoints(t.Points.begin(), t.Points.end());
  ffd::cuda::GridDeformer trilinear;
  std::vector<float> out(tPoints.size());
  ASSERT_TRUE(trilinear.SetPoints(tPoints.data(), t.Count()) && trilinear.Bind(t.Frame, t.Basis, t.Divisions, false));
  ASSERT_TRUE(trilinear.Evaluate(t.Displacements.data(), t.ControlPoints(), false, false));
  ASSERT_TRUE(trilinear.Download(out.data(), nullptr, nullptr));
  EXPECT_EQ(trilinear.GetCounters().LatticeBytes, std::uint64_t(t.ControlPoints()) * 4 * sizeof(float));
  EXPECT_EQ(trilinear.GetCounters().PointUploads, 1u);
}

// The bounds of the deformed points, reduced on the device for a renderer that draws from it (GPU–GL interop),
// equal the host's bounds of the downloaded points exactly (minima and maxima round nothing), non-finite
// coordinates skipped, for one point, one block's worth and many blocks, in float32 and float64; only the six
// values cross the bus.
template <typename Real>
void ExpectDeviceBoundsMatchHost(std::int64_t count, std::mt19937& rng)
{
  const Problem p(int(ffd::GridBasis::CubicBSpline), count, rng);
  const std::vector<Real> points(p.Points.begin(), p.Points.end());
  ffd::cuda::GridDeformer gpu;
  ASSERT_TRUE(gpu.SetPoints(points.data(), p.Count()) && gpu.Bind(p.Frame, p.Basis, p.Divisions, false));
  ASSERT_TRUE(gpu.Evaluate(p.Displacements.data(), p.ControlPoints(), false, false)) << gpu.GetLastError();
  std::vector<Real> out(points.size());
  ASSERT_TRUE(gpu.Download(out.data(), nullptr, nullptr)) << gpu.GetLastError();
  double expected[6] = { INFINITY, -INFINITY, INFINITY, -INFINITY, INFINITY, -INFINITY };
  for (std::size_t v = 0; v < out.size(); ++v)
  {
    const int c = int(v % 3);
    if (std::isfinite(out[v]))
    {
      expected[2 * c] = std::min(expected[2 * c], double(out[v]));
      expected[2 * c + 1] = std::max(expected[2 * c + 1], double(out[v]));
    }
  }
  const std::uint64_t before = gpu.GetCounters().BytesDownloaded;
  double bounds[6];
  ASSERT_TRUE(gpu.ComputeBounds(bounds)) << gpu.GetLastError();
  for (int b = 0; b < 6; ++b)
  {
    EXPECT_EQ(bounds[b], expected[b]) << count << " points, bound " << b;
  }
  EXPECT_EQ(gpu.GetCounters().BytesDownloaded - before, 6 * sizeof(Real));
}

TEST(CudaGridDeformer, BoundsAreReducedOnTheDevice)
{
  FFD_REQUIRE_DEVICE();
  std::mt19937 rng(20261129);
  for (const std::int64_t count : { std::int64_t(1), std::int64_t(256), std::int64_t(100003), std::int64_t(3000001) })
  {
    ExpectDeviceBoundsMatchHost<float>(count, rng);
    ExpectDeviceBoundsMatchHost<double>(count, rng);
  }
}

// W^T g on the host: the CPU path's weights (GridDeformation::ForEachWeight, in float64), summed in point order,
// and per control point the size of its terms, S_c = sum_p |w_c(p)| |g_p|, to which its rounding is relative.
template <int MaxCount>
void HostAdjoint(const Problem& p, bool clampOutside, const std::vector<double>& g, std::vector<double>& sums,
  std::vector<double>& sizes)
{
  const ffd::Frame<double> frame = ffd::Frame<double>::FromArray(p.Frame);
  const ffd::GridDeformation<MaxCount, double> deformation{ ffd::GridBasis(p.Basis),
    { p.Divisions[0], p.Divisions[1], p.Divisions[2] }, { p.Dims[0], p.Dims[1], p.Dims[2] }, p.Displacements.data(),
    frame };
  sums.assign(3 * std::size_t(p.ControlPoints()), 0.0);
  sizes.assign(std::size_t(p.ControlPoints()), 0.0);
  for (std::int64_t i = 0; i < p.Count(); ++i)
  {
    const ffd::Vec3<double> x = ffd::Vec3<double>::From(&p.Points[3 * i]);
    const int cell = ffd::BindToGrid(frame, ffd::GridBasis(p.Basis), p.Divisions, x, clampOutside);
    if (cell < 0)
    {
      continue;
    }
    deformation.ForEachWeight(x, cell,
      [&](int c, double w)
      {
        for (int k = 0; k < 3; ++k)
        {
          sums[3 * c + k] += w * g[3 * i + k];
          sizes[c] += std::fabs(w * g[3 * i + k]);
        }
      });
  }
}

// The device's W^T g in the precision Real, for a fresh deformer.
template <typename Real>
std::vector<double> DeviceAdjoint(
  const Problem& p, bool clamp, const std::vector<double>& g, std::uint64_t* plans = nullptr, int calls = 1)
{
  const std::vector<Real> points(p.Points.begin(), p.Points.end());
  ffd::cuda::GridDeformer gpu;
  std::vector<double> sums(3 * std::size_t(p.ControlPoints()), -12345.0); // poisoned: unwritten values show
  EXPECT_TRUE(gpu.SetPoints(points.data(), p.Count())) << gpu.GetLastError();
  EXPECT_TRUE(gpu.Bind(p.Frame, p.Basis, p.Divisions, clamp)) << gpu.GetLastError();
  for (int call = 0; call < calls; ++call)
  {
    EXPECT_TRUE(gpu.Adjoint(g.data(), p.ControlPoints(), sums.data())) << gpu.GetLastError();
  }
  if (plans)
  {
    *plans = gpu.GetCounters().AdjointPlans;
  }
  return sums;
}

// The adjoint on the device against the host's, for every basis and outside policy, on random problems (some
// points outside, two non-finite). Float64: both sum the same float64 terms (the weights but for the compilers'
// contraction into FMAs, a few eps) in different orders, each within (n - 1) eps S_c of the exact sum for n <= N
// terms: |difference| <= (2 N + 32) eps S_c. Float32: the forward map's bound (MatchesCpuForEveryBasis: points
// within 3e-5 where displacements reach 0.2) bounds each point's weights' errors, summed, by 1.5e-4, so the
// control points' errors sum to at most 1.5e-4 sum_p |g_p|_1 (the transpose of that bound). Then the same bits
// again, on a fresh deformer, with the plan made once per binding.
TYPED_TEST(CudaGridDeformerTest, AdjointMatchesHostForEveryBasis)
{
  FFD_REQUIRE_DEVICE();
  using Real = TypeParam;
  const bool single = sizeof(Real) == sizeof(float);
  std::mt19937 rng(3141);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int basis = 0; basis <= int(ffd::GridBasis::CubicBSpline); ++basis)
  {
    for (bool clamp : { false, true })
    {
      const Problem p(basis, 20011, rng);
      std::vector<double> g(p.Points.size());
      double gradientSize = 0.0;
      for (double& v : g)
      {
        v = unit(rng);
        gradientSize += std::fabs(v);
      }
      std::vector<double> expected, sizes;
      if (basis == int(ffd::GridBasis::Bernstein))
      {
        HostAdjoint<ffd::MaxBernsteinDegree + 1>(p, clamp, g, expected, sizes);
      }
      else
      {
        HostAdjoint<4>(p, clamp, g, expected, sizes);
      }
      std::uint64_t plans = 0;
      const std::vector<double> got = DeviceAdjoint<Real>(p, clamp, g, &plans, 2);
      EXPECT_EQ(plans, 1u) << "one plan for two calls on one binding";
      double l1 = 0.0;
      ffdtest::Mismatches wrong;
      for (std::int64_t c = 0; c < p.ControlPoints(); ++c)
      {
        for (int k = 0; k < 3; ++k)
        {
          l1 += std::fabs(got[3 * c + k] - expected[3 * c + k]);
          if (!single)
          {
            const double tolerance = (2.0 * double(p.Count()) + 32.0) * 1.1102230246251565e-16 * sizes[c];
            wrong.Check("sensitivity", c, got[3 * c + k], expected[3 * c + k], tolerance);
          }
        }
      }
      EXPECT_EQ(wrong.Count, 0) << "basis " << basis << (clamp ? " clamped" : " kept") << ": " << wrong.First;
      EXPECT_LE(l1, (single ? 1.5e-4 : 1e-12) * gradientSize) << "basis " << basis;
      const std::vector<double> again = DeviceAdjoint<Real>(p, clamp, g);
      EXPECT_EQ(std::memcmp(got.data(), again.data(), got.size() * sizeof(double)), 0)
        << "basis " << basis << ": not the same bits on a fresh deformer";
    }
  }
}

// No point bound (all outside, kept): every sensitivity is 0, none left unwritten.
TEST(CudaGridDeformer, AdjointOfNoBoundPointIsZero)
{
  FFD_REQUIRE_DEVICE();
  std::mt19937 rng(5);
  Problem p(int(ffd::GridBasis::CubicBSpline), 100, rng);
  for (double& v : p.Points)
  {
    v += 1000.0;
  }
  const std::vector<double> g(p.Points.size(), 1.0);
  const std::vector<double> sums = DeviceAdjoint<float>(p, false, g);
  EXPECT_EQ(std::count(sums.begin(), sums.end(), 0.0), std::ptrdiff_t(sums.size()));
}

// Failures are reported, leave no device state behind, and a later use starts clean.
TEST(CudaGridDeformer, FailuresAreReportedAndRecoverable)
{
  FFD_REQUIRE_DEVICE();
  ffd::cuda::GridDeformer gpu;
  std::vector<float> out(30);
  EXPECT_FALSE(gpu.Evaluate(nullptr, 0, false, false)); // nothing bound
  EXPECT_NE(gpu.GetLastError().find("no points bound"), std::string::npos) << gpu.GetLastError();

  // Out of device memory: 2^42 points would need 48 TiB; the allocation fails before anything is read.
  EXPECT_FALSE(gpu.SetPoints(out.data(), std::int64_t(1) << 42));
  EXPECT_NE(gpu.GetLastError().find("allocating the points"), std::string::npos) << gpu.GetLastError();

  std::mt19937 rng(9);
  const Problem p(int(ffd::GridBasis::Trilinear), 10, rng);
  const std::vector<float> points(p.Points.begin(), p.Points.end());
  ASSERT_TRUE(gpu.SetPoints(points.data(), p.Count())) << gpu.GetLastError();
  ASSERT_TRUE(gpu.Bind(p.Frame, p.Basis, p.Divisions, false)) << gpu.GetLastError();
  EXPECT_FALSE(gpu.Evaluate(p.Displacements.data(), p.ControlPoints() + 1, false, false)); // wrong lattice
  EXPECT_FALSE(gpu.Download(out.data(), nullptr, nullptr)); // the failure dropped the device state
}

// Without a device the backend says so instead of crashing (this runs on machines without a GPU).
TEST(CudaGridDeformer, DeviceQueryNeverCrashes)
{
  std::string why;
  const bool available = ffd::cuda::DeviceAvailable(&why);
  EXPECT_TRUE(available || !why.empty());
  if (!available)
  {
    ffd::cuda::GridDeformer gpu;
    std::vector<float> points(30, 0.0f);
    EXPECT_FALSE(gpu.SetPoints(points.data(), 10));
    EXPECT_FALSE(gpu.GetLastError().empty());
  }
}
} // namespace
