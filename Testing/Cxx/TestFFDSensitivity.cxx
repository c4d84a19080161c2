// SPDX-License-Identifier: BSD-3-Clause
// vtkFFDSensitivity: dJ/dP = W^T g against central differences of vtkFFDDeform in float64, for every grid basis,
// dense and sparse, and tetrahedral lattices, points kept outside, clamped and extrapolated; the same bits for any
// number of threads; bad input.
//
// The reference: J(P) = sum_i g_i . X_i(P), X from vtkFFDDeform on the CPU in float64. X is affine in the control
// points, so the central difference (J(P + h e) - J(P - h e)) / 2h equals dJ/dP . e exactly, for any step; with
// h = 1 its only error is rounding: each J is summed here over N terms, within N eps sum_i |g_i| |X_i| of its
// value (|.| the 1-norm), on top of X's own rounding (a few eps |X|). The tolerance is (2 N + 16) eps S / 2h,
// S = sum_i |g_i| (|X_i| at P + h e and at P - h e, the larger). Any wrong weight, control point or point moves the
// difference by a term of the size of g, far above it.
#include "FFDTestErrorObserver.h"
#include "FFDTestLattices.h"
#include "FFDTestMeshes.h"

#include "vtkDoubleArray.h"
#include "vtkFFDBuildLattice.h"
#include "vtkFFDBuildTetrahedralLattice.h"
#include "vtkFFDDeform.h"
#include "vtkFFDSensitivity.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSMPTools.h"
#include "vtkUnstructuredGrid.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

namespace
{
constexpr double Eps = std::numeric_limits<double>::epsilon();

/// The bear's points in float64 and `outside` more around it (up to 30 % of the box beyond it), with a random
/// gradient array `g` of components in [-1, 1].
vtkSmartPointer<vtkPolyData> CloudWithGradient(vtkPolyData* bear, int outside, std::mt19937& rng)
{
  vtkSmartPointer<vtkPolyData> cloud = PointsAround(bear, outside, rng);
  vtkPoints* points = cloud->GetPoints();
  std::uniform_real_distribution<double> component(-1.0, 1.0);
  vtkNew<vtkDoubleArray> g;
  g->SetName("g");
  g->SetNumberOfComponents(3);
  g->SetNumberOfTuples(points->GetNumberOfPoints());
  for (vtkIdType v = 0; v < 3 * points->GetNumberOfPoints(); ++v)
  {
    g->SetValue(v, component(rng));
  }
  cloud->GetPointData()->AddArray(g);
  return cloud;
}

/// J = sum_i g_i . X_i and S = sum_i |g_i| |X_i| of the deformed cloud.
void Objective(vtkFFDDeform* deform, vtkDataArray* g, double& j, double& s)
{
  deform->Update();
  vtkPoints* x = vtkPointSet::SafeDownCast(deform->GetOutputDataObject(0))->GetPoints();
  j = s = 0.0;
  for (vtkIdType p = 0; p < x->GetNumberOfPoints(); ++p)
  {
    double y[3];
    x->GetPoint(p, y);
    for (int c = 0; c < 3; ++c)
    {
      j += g->GetComponent(p, c) * y[c];
      s += std::fabs(g->GetComponent(p, c)) * std::fabs(y[c]);
    }
  }
}

vtkSmartPointer<vtkDataArray> Sensitivity(
  vtkPolyData* cloud, vtkPointSet* lattice, int policy, int backend = vtkFFDDeform::AUTOMATIC)
{
  vtkNew<vtkFFDSensitivity> sensitivity;
  sensitivity->SetBackend(backend);
  sensitivity->SetInputData(cloud);
  sensitivity->SetLatticeData(lattice);
  sensitivity->SetInputArrayToProcess(0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, "g");
  sensitivity->SetOutsidePolicy(policy);
  sensitivity->Update();
  vtkPointSet* out = vtkPointSet::SafeDownCast(sensitivity->GetOutputDataObject(0));
  return out ? out->GetPointData()->GetArray("Sensitivity") : nullptr;
}

/// Central differences of `picks` random control points of `lattice` against vtkFFDSensitivity; the count of
/// components beyond the tolerance, and the largest difference relative to it.
void ExpectMatchesCentralDifferences(vtkPolyData* cloud, vtkPointSet* lattice, int policy, int picks, std::mt19937& rng,
  const char* what, int backend = vtkFFDDeform::AUTOMATIC)
{
  vtkSmartPointer<vtkDataArray> dJdP = Sensitivity(cloud, lattice, policy, backend);
  ASSERT_TRUE(dJdP) << what;
  ASSERT_EQ(dJdP->GetNumberOfTuples(), lattice->GetNumberOfPoints()) << what;
  vtkNew<vtkFFDDeform> deform;
  deform->SetBackendToCPU();
  deform->SetOutputPointsPrecision(vtkAlgorithm::DOUBLE_PRECISION);
  deform->SetOutsidePolicy(policy);
  deform->SetInputData(cloud);
  deform->SetLatticeData(lattice);
  vtkDataArray* g = cloud->GetPointData()->GetArray("g");
  const double n = double(cloud->GetNumberOfPoints());
  std::uniform_int_distribution<vtkIdType> pick(0, lattice->GetNumberOfPoints() - 1);
  int wrong = 0, nonzero = 0;
  double worst = 0.0;
  for (int k = 0; k < picks; ++k)
  {
    const vtkIdType c = pick(rng);
    double rest[3];
    lattice->GetPoint(c, rest);
    for (int axis = 0; axis < 3; ++axis)
    {
      double jPlus, sPlus, jMinus, sMinus, x[3] = { rest[0], rest[1], rest[2] };
      x[axis] = rest[axis] + 1.0;
      lattice->GetPoints()->SetPoint(c, x);
      lattice->GetPoints()->Modified();
      Objective(deform, g, jPlus, sPlus);
      x[axis] = rest[axis] - 1.0;
      lattice->GetPoints()->SetPoint(c, x);
      lattice->GetPoints()->Modified();
      Objective(deform, g, jMinus, sMinus);
      lattice->GetPoints()->SetPoint(c, rest);
      lattice->GetPoints()->Modified();
      const double difference = (jPlus - jMinus) / 2.0;
      const double tolerance = (2.0 * n + 16.0) * Eps * std::max(sPlus, sMinus) / 2.0;
      const double error = std::fabs(dJdP->GetComponent(c, axis) - difference);
      worst = std::max(worst, error / tolerance);
      wrong += error <= tolerance ? 0 : 1;
      nonzero += dJdP->GetComponent(c, axis) != 0.0 ? 1 : 0;
    }
  }
  EXPECT_EQ(wrong, 0) << what << ": worst error " << worst << " of the tolerance";
  EXPECT_GT(nonzero, 0) << what << ": every picked control point had no sensitivity";
}
} // namespace

TEST(vtkFFDSensitivity, MatchesCentralDifferencesForEveryGridBasis)
{
  vtkSmartPointer<vtkPolyData> bear = ReadTestMesh("bear");
  std::mt19937 rng(20261129);
  vtkSmartPointer<vtkPolyData> cloud = CloudWithGradient(bear, 400, rng);
  for (int basis = vtkFFDBuildLattice::BERNSTEIN; basis <= vtkFFDBuildLattice::CUBIC_BSPLINE; ++basis)
  {
    const int n[3] = { 2, 3, 2 };
    for (int form : { vtkFFDBuildLattice::DENSE, vtkFFDBuildLattice::SPARSE })
    {
      if (basis == vtkFFDBuildLattice::BERNSTEIN && form == vtkFFDBuildLattice::SPARSE)
      {
        continue; // the global basis is dense only
      }
      vtkSmartPointer<vtkPointSet> lattice = ffdtest::MovedLattice(bear, basis, n, form, rng);
      for (int policy : { vtkFFDDeform::KEEP_POSITION, vtkFFDDeform::CLAMP_TO_EDGE })
      {
        const std::string what = std::string(vtkFFDBuildLattice::GetBasisAsString(basis)) +
          (form == vtkFFDBuildLattice::DENSE ? " dense" : " sparse") + (policy ? " clamped" : " kept");
        ExpectMatchesCentralDifferences(cloud, lattice, policy, 12, rng, what.c_str());
      }
    }
  }
}

// The CPU's sums at every SIMD level this machine runs (VOXELFFD_MAX_SIMD, read at each update; "none": point by
// point), each against central differences as above.
TEST(vtkFFDSensitivity, EverySimdLevelMatchesCentralDifferences)
{
  vtkSmartPointer<vtkPolyData> bear = ReadTestMesh("bear");
  std::mt19937 rng(43);
  vtkSmartPointer<vtkPolyData> cloud = CloudWithGradient(bear, 200, rng);
  const int n[3] = { 3, 2, 3 };
  const std::pair<int, int> cases[] = { { vtkFFDBuildLattice::BERNSTEIN, vtkFFDBuildLattice::DENSE },
    { vtkFFDBuildLattice::TRIQUADRATIC_BEZIER, vtkFFDBuildLattice::SPARSE },
    { vtkFFDBuildLattice::CUBIC_BSPLINE, vtkFFDBuildLattice::DENSE } };
  const char* saved = std::getenv("VOXELFFD_MAX_SIMD");
  const std::string restore = saved ? saved : "";
  for (const char* level : { "none", "sse2", "avx2", "avx512" })
  {
    setenv("VOXELFFD_MAX_SIMD", level, 1);
    for (const auto& [basis, form] : cases)
    {
      vtkSmartPointer<vtkPointSet> lattice = ffdtest::MovedLattice(bear, basis, n, form, rng);
      const std::string what = std::string(level) + " " + vtkFFDBuildLattice::GetBasisAsString(basis);
      ExpectMatchesCentralDifferences(
        cloud, lattice, vtkFFDDeform::CLAMP_TO_EDGE, 6, rng, what.c_str(), vtkFFDDeform::CPU);
    }
  }
  if (saved)
  {
    setenv("VOXELFFD_MAX_SIMD", restore.c_str(), 1);
  }
  else
  {
    unsetenv("VOXELFFD_MAX_SIMD");
  }
}

/// The bear's tetrahedral control mesh (its hull and centroid, subdivided once), its nodes moved at random by up to
/// 5 % of the bear's size.
vtkSmartPointer<vtkUnstructuredGrid> MovedTetrahedra(vtkPolyData* bear, std::mt19937& rng)
{
  vtkNew<vtkFFDBuildTetrahedralLattice> build;
  build->SetInputData(bear);
  build->SetSubdivisionLevels(1);
  build->Update();
  auto lattice = vtkSmartPointer<vtkUnstructuredGrid>::New();
  lattice->DeepCopy(build->GetOutput());
  const double size = bear->GetLength();
  std::uniform_real_distribution<double> move(-0.05 * size, 0.05 * size);
  for (vtkIdType p = 0; p < lattice->GetNumberOfPoints(); ++p)
  {
    double x[3];
    lattice->GetPoint(p, x);
    lattice->GetPoints()->SetPoint(p, x[0] + move(rng), x[1] + move(rng), x[2] + move(rng));
  }
  return lattice;
}

TEST(vtkFFDSensitivity, MatchesCentralDifferencesForTetrahedralLattices)
{
  vtkSmartPointer<vtkPolyData> bear = ReadTestMesh("bear");
  std::mt19937 rng(1129);
  vtkSmartPointer<vtkPolyData> cloud = CloudWithGradient(bear, 400, rng);
  vtkSmartPointer<vtkUnstructuredGrid> lattice = MovedTetrahedra(bear, rng);
  for (int policy : { vtkFFDDeform::KEEP_POSITION, vtkFFDDeform::CLAMP_TO_EDGE, vtkFFDDeform::EXTRAPOLATE })
  {
    const std::string what = "tetrahedra, policy " + std::to_string(policy);
    ExpectMatchesCentralDifferences(cloud, lattice, policy, 30, rng, what.c_str());
  }
}

// The same bits for 3, 2 and 1 threads, and again on 1: no atomics, one order of the terms of each control
// point. (Descending: TBB ignores a request for more workers than an earlier limit allowed.)
TEST(vtkFFDSensitivity, SameBitsForAnyNumberOfThreads)
{
  vtkSmartPointer<vtkPolyData> bear = ReadTestMesh("bear");
  std::mt19937 rng(7);
  vtkSmartPointer<vtkPolyData> cloud = CloudWithGradient(bear, 1000, rng);
  for (int basis : { vtkFFDBuildLattice::BERNSTEIN, vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::TRICUBIC_BEZIER,
         vtkFFDBuildLattice::CUBIC_BSPLINE })
  {
    const int n[3] = { 5, 6, 4 };
    vtkSmartPointer<vtkPointSet> lattice = ffdtest::MovedLattice(bear, basis, n, vtkFFDBuildLattice::DENSE, rng);
    std::vector<std::vector<double>> runs;
    for (int threads : { 3, 2, 1, 1 })
    {
      vtkSMPTools::Initialize(threads);
      vtkSmartPointer<vtkDataArray> s = Sensitivity(cloud, lattice, vtkFFDDeform::CLAMP_TO_EDGE);
      ASSERT_TRUE(s);
      auto* values = vtkDoubleArray::SafeDownCast(s);
      runs.emplace_back(values->GetPointer(0), values->GetPointer(0) + 3 * values->GetNumberOfTuples());
    }
    vtkSMPTools::Initialize(); // back to the default
    for (const std::vector<double>& run : runs)
    {
      ASSERT_EQ(run.size(), runs[0].size());
      EXPECT_EQ(std::memcmp(run.data(), runs[0].data(), run.size() * sizeof(double)), 0)
        << vtkFFDBuildLattice::GetBasisAsString(basis);
    }
  }
  vtkSmartPointer<vtkUnstructuredGrid> tetrahedra = MovedTetrahedra(bear, rng);
  std::vector<std::vector<double>> runs;
  for (int threads : { 3, 2, 1, 1 })
  {
    vtkSMPTools::Initialize(threads);
    vtkSmartPointer<vtkDataArray> s = Sensitivity(cloud, tetrahedra, vtkFFDDeform::CLAMP_TO_EDGE);
    ASSERT_TRUE(s);
    auto* values = vtkDoubleArray::SafeDownCast(s);
    runs.emplace_back(values->GetPointer(0), values->GetPointer(0) + 3 * values->GetNumberOfTuples());
  }
  vtkSMPTools::Initialize();
  for (const std::vector<double>& run : runs)
  {
    EXPECT_EQ(std::memcmp(run.data(), runs[0].data(), run.size() * sizeof(double)), 0) << "tetrahedra";
  }
}

// With SetDeform(), the sums use the vtkFFDDeform's binding (on the host, or on the device where CUDA deforms) and
// its outside policy: no second binding, the same bits as a binding of the filter's own under that policy, and the
// deformation's next update binds nothing either.
TEST(vtkFFDSensitivity, ReusesTheDeformsBinding)
{
  vtkSmartPointer<vtkPolyData> bear = ReadTestMesh("bear");
  std::mt19937 rng(11);
  vtkSmartPointer<vtkPolyData> cloud = CloudWithGradient(bear, 300, rng);
  const int n[3] = { 3, 4, 3 };
  std::vector<vtkSmartPointer<vtkPointSet>> lattices = { ffdtest::MovedLattice(bear, vtkFFDBuildLattice::CUBIC_BSPLINE,
                                                           n, vtkFFDBuildLattice::DENSE, rng),
    ffdtest::MovedLattice(bear, vtkFFDBuildLattice::TRIQUADRATIC_BEZIER, n, vtkFFDBuildLattice::SPARSE, rng),
    MovedTetrahedra(bear, rng) };
  for (vtkPointSet* lattice : lattices)
  {
    vtkNew<vtkFFDDeform> deform;
    deform->SetInputData(cloud);
    deform->SetLatticeData(lattice);
    deform->SetOutsidePolicy(vtkFFDDeform::CLAMP_TO_EDGE);
    deform->Update();
    ASSERT_EQ(deform->GetNumberOfBindings(), 1);
    vtkNew<vtkFFDSensitivity> sensitivity;
    sensitivity->SetInputData(cloud);
    sensitivity->SetLatticeData(lattice);
    sensitivity->SetInputArrayToProcess(0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, "g");
    sensitivity->SetDeform(deform);
    sensitivity->Update();
    EXPECT_EQ(sensitivity->GetNumberOfBindings(), 0) << lattice->GetClassName();
    vtkDataArray* shared =
      vtkPointSet::SafeDownCast(sensitivity->GetOutputDataObject(0))->GetPointData()->GetArray("Sensitivity");
    vtkSmartPointer<vtkDataArray> own = Sensitivity(cloud, lattice, vtkFFDDeform::CLAMP_TO_EDGE);
    ASSERT_TRUE(shared && own);
    EXPECT_EQ(std::memcmp(vtkDoubleArray::SafeDownCast(shared)->GetPointer(0),
                vtkDoubleArray::SafeDownCast(own)->GetPointer(0), 3 * own->GetNumberOfTuples() * sizeof(double)),
      0)
      << lattice->GetClassName() << ": not the sums of the filter's own binding";
    lattice->GetPoints()->Modified(); // a moved lattice: the deformation evaluates again, without binding
    deform->Update();
    EXPECT_EQ(deform->GetNumberOfBindings(), 1) << lattice->GetClassName();
    if (!vtkUnstructuredGrid::SafeDownCast(lattice))
    {
      EXPECT_STREQ(sensitivity->GetLastBackendUsed(), deform->GetLastBackendUsed());
    }
  }
}

TEST(vtkFFDSensitivity, BadInputIsAnErrorAndAnEmptyOutput)
{
  vtkSmartPointer<vtkPolyData> bear = ReadTestMesh("bear");
  std::mt19937 rng(3);
  vtkSmartPointer<vtkPolyData> cloud = CloudWithGradient(bear, 0, rng);
  const int n[3] = { 2, 2, 2 };
  vtkSmartPointer<vtkPointSet> lattice =
    ffdtest::MovedLattice(bear, vtkFFDBuildLattice::TRILINEAR, n, vtkFFDBuildLattice::DENSE, rng);
  vtkNew<vtkDoubleArray> twoComponents;
  twoComponents->SetName("flat");
  twoComponents->SetNumberOfComponents(2);
  twoComponents->SetNumberOfTuples(cloud->GetNumberOfPoints());
  twoComponents->Fill(0.0);
  cloud->GetPointData()->AddArray(twoComponents);
  struct Case
  {
    const char* Array;
    int Policy;
    const char* Expected;
  };
  for (const Case& c : { Case{ nullptr, 0, "gradient" }, Case{ "flat", 0, "3 components" },
         Case{ "missing", 0, "gradient" }, Case{ "g", vtkFFDDeform::EXTRAPOLATE, "EXTRAPOLATE" } })
  {
    vtkNew<vtkFFDSensitivity> sensitivity;
    vtkNew<FFDTestErrorObserver> errors;
    errors->WatchWithExecutive(sensitivity);
    sensitivity->SetInputData(cloud);
    sensitivity->SetLatticeData(lattice);
    sensitivity->SetOutsidePolicy(c.Policy);
    if (c.Array)
    {
      sensitivity->SetInputArrayToProcess(0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, c.Array);
    }
    sensitivity->Update();
    EXPECT_NE(errors->Errors.find(c.Expected), std::string::npos) << errors->Errors;
    EXPECT_EQ(vtkPointSet::SafeDownCast(sensitivity->GetOutputDataObject(0))->GetNumberOfPoints(), 0);
  }
}
