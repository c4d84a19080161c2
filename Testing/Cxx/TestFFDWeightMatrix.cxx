// SPDX-License-Identifier: BSD-3-Clause
// vtkFFDWeightMatrix from C++: the same CSR arrays for any number of threads, rows that reproduce vtkFFDDeform's
// displacement, and bad input an error and an empty matrix. Python.test_weight_matrix checks W against its peers
// for every basis, form and policy; these are the C++ API's own checks.
#include "FFDTestErrorObserver.h"
#include "FFDTestLattices.h"
#include "FFDTestMeshes.h"

#include "vtkDoubleArray.h"
#include "vtkFFDBuildLattice.h"
#include "vtkFFDBuildTetrahedralLattice.h"
#include "vtkFFDDeform.h"
#include "vtkFFDWeightMatrix.h"
#include "vtkIdTypeArray.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSMPTools.h"
#include "vtkUnstructuredGrid.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

namespace
{
constexpr double Eps = std::numeric_limits<double>::epsilon();

/// The CSR arrays of one Compute(), copied.
struct Csr
{
  std::vector<vtkIdType> Offsets, Columns;
  std::vector<double> Values;

  explicit Csr(vtkFFDWeightMatrix* m)
    : Offsets(m->GetRowOffsets()->GetPointer(0), m->GetRowOffsets()->GetPointer(0) + m->GetNumberOfRows() + 1)
    , Columns(m->GetColumnIds()->GetPointer(0), m->GetColumnIds()->GetPointer(0) + this->Offsets.back())
    , Values(m->GetValues()->GetPointer(0), m->GetValues()->GetPointer(0) + this->Offsets.back())
  {
  }
  bool operator==(const Csr& o) const
  {
    return this->Offsets == o.Offsets && this->Columns == o.Columns && this->Values.size() == o.Values.size() &&
      std::memcmp(this->Values.data(), o.Values.data(), this->Values.size() * sizeof(double)) == 0;
  }
};

vtkSmartPointer<vtkUnstructuredGrid> Tetrahedra(vtkPolyData* bear)
{
  vtkNew<vtkFFDBuildTetrahedralLattice> build;
  build->SetInputData(bear);
  build->Update();
  auto lattice = vtkSmartPointer<vtkUnstructuredGrid>::New();
  lattice->DeepCopy(build->GetOutput());
  return lattice;
}

/// The lattices of the tests: a dense Bernstein, a sparse cubic B-spline, a dense trilinear lattice (moved), and
/// a tetrahedral one at rest.
std::vector<vtkSmartPointer<vtkPointSet>> Lattices(vtkPolyData* bear, std::mt19937& rng)
{
  const int n[3] = { 4, 5, 3 };
  return { ffdtest::MovedLattice(bear, vtkFFDBuildLattice::BERNSTEIN, n, vtkFFDBuildLattice::DENSE, rng),
    ffdtest::MovedLattice(bear, vtkFFDBuildLattice::CUBIC_BSPLINE, n, vtkFFDBuildLattice::SPARSE, rng),
    ffdtest::MovedLattice(bear, vtkFFDBuildLattice::TRILINEAR, n, vtkFFDBuildLattice::DENSE, rng), Tetrahedra(bear) };
}
} // namespace

// The same arrays on 3, 2 and 1 threads and again on 1 (descending: TBB ignores a request for more workers than
// an earlier limit allowed), with points clamped from outside.
TEST(vtkFFDWeightMatrix, SameArraysForAnyNumberOfThreads)
{
  vtkSmartPointer<vtkPolyData> bear = ReadTestMesh("bear");
  std::mt19937 rng(11);
  vtkSmartPointer<vtkPolyData> cloud = PointsAround(bear, 1000, rng);
  for (vtkPointSet* lattice : Lattices(bear, rng))
  {
    std::vector<Csr> runs;
    for (int threads : { 3, 2, 1, 1 })
    {
      vtkSMPTools::Initialize(threads);
      vtkNew<vtkFFDWeightMatrix> matrix; // a fresh one: it binds again
      matrix->SetOutsidePolicy(vtkFFDDeform::CLAMP_TO_EDGE);
      ASSERT_EQ(matrix->Compute(cloud, lattice), 1);
      runs.emplace_back(matrix);
    }
    vtkSMPTools::Initialize(); // back to the default
    EXPECT_EQ(runs[0].Offsets.size(), std::size_t(cloud->GetNumberOfPoints()) + 1);
    EXPECT_GT(runs[0].Values.size(), 0u);
    for (const Csr& run : runs)
    {
      EXPECT_TRUE(run == runs[0]) << lattice->GetClassName();
    }
  }
}

// x + W (P - P_rest) is vtkFFDDeform's output: within (m + 8) u of the row's scale max|x| + sum |w| max|D|, m the
// row's entries (Python.test_weight_matrix derives it; the tetrahedra here are at rest, so D = 0).
TEST(vtkFFDWeightMatrix, RowsGiveTheDeformation)
{
  vtkSmartPointer<vtkPolyData> bear = ReadTestMesh("bear");
  std::mt19937 rng(12);
  vtkSmartPointer<vtkPolyData> cloud = PointsAround(bear, 500, rng);
  for (vtkPointSet* lattice : Lattices(bear, rng))
  {
    vtkNew<vtkFFDWeightMatrix> matrix;
    ASSERT_EQ(matrix->Compute(cloud, lattice), 1);
    EXPECT_EQ(matrix->GetNumberOfColumns(), lattice->GetNumberOfPoints());
    vtkNew<vtkFFDDeform> deform;
    deform->SetInputData(cloud);
    deform->SetLatticeData(lattice);
    deform->Update();
    const Csr w(matrix);
    vtkDataArray* rest = lattice->GetPointData()->GetArray("RestPosition");
    double worst = 0.0;
    for (vtkIdType p = 0; p < cloud->GetNumberOfPoints(); ++p)
    {
      double x[3], y[3], sum[3] = { 0, 0, 0 }, scale = 0.0;
      cloud->GetPoint(p, x);
      deform->GetOutput()->GetPoint(p, y);
      for (vtkIdType e = w.Offsets[p]; e < w.Offsets[p + 1]; ++e)
      {
        double at[3], r[3], largest = 0.0;
        lattice->GetPoint(w.Columns[e], at);
        rest->GetTuple(w.Columns[e], r);
        for (int a = 0; a < 3; ++a)
        {
          sum[a] += w.Values[e] * (at[a] - r[a]);
          largest = std::max(largest, std::abs(at[a] - r[a]));
        }
        scale += std::abs(w.Values[e]) * largest;
      }
      scale += std::max({ std::abs(x[0]), std::abs(x[1]), std::abs(x[2]) });
      for (int a = 0; a < 3; ++a)
      {
        const double m = double(w.Offsets[p + 1] - w.Offsets[p]);
        worst = std::max(worst, std::abs(x[a] + sum[a] - y[a]) / ((m + 8) * Eps / 2 * scale));
      }
    }
    EXPECT_LE(worst, 1.0) << lattice->GetClassName();
  }
}

TEST(vtkFFDWeightMatrix, BadInputIsAnErrorAndAnEmptyMatrix)
{
  vtkSmartPointer<vtkPolyData> bear = ReadTestMesh("bear");
  std::mt19937 rng(13);
  const int n[3] = { 2, 2, 2 };
  vtkSmartPointer<vtkPointSet> grid =
    ffdtest::MovedLattice(bear, vtkFFDBuildLattice::TRILINEAR, n, vtkFFDBuildLattice::DENSE, rng);
  vtkNew<vtkUnstructuredGrid> noRest; // a tetrahedral lattice by its type, without RestPosition or cells
  noRest->SetPoints(bear->GetPoints());
  struct Case
  {
    vtkPointSet* Mesh;
    vtkPointSet* Lattice;
    int Policy;
    const char* Expected;
  };
  for (const Case& c : { Case{ nullptr, grid, 0, "the mesh is null" }, Case{ bear, nullptr, 0, "the lattice is null" },
         Case{ bear, grid, vtkFFDDeform::EXTRAPOLATE, "EXTRAPOLATE" }, Case{ bear, bear, 0, "FFDFrame" },
         Case{ bear, noRest, 0, "RestPosition" } })
  {
    vtkNew<vtkFFDWeightMatrix> matrix;
    ASSERT_EQ(matrix->Compute(bear, grid), 1); // a matrix that the failure below must empty
    vtkNew<FFDTestErrorObserver> errors;
    errors->Watch(matrix);
    matrix->SetOutsidePolicy(c.Policy);
    EXPECT_EQ(matrix->Compute(c.Mesh, c.Lattice), 0);
    EXPECT_NE(errors->Errors.find(c.Expected), std::string::npos) << errors->Errors;
    EXPECT_EQ(matrix->GetNumberOfRows(), 0);
    EXPECT_EQ(matrix->GetNumberOfColumns(), 0);
    ASSERT_EQ(matrix->GetRowOffsets()->GetNumberOfValues(), 1);
    EXPECT_EQ(matrix->GetRowOffsets()->GetValue(0), 0);
    EXPECT_EQ(matrix->GetColumnIds()->GetNumberOfValues(), 0);
    EXPECT_EQ(matrix->GetValues()->GetNumberOfValues(), 0);
  }
}
