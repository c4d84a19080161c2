// SPDX-License-Identifier: BSD-3-Clause
// vtkFFDInverseDeform (issue 21, inverse mapping): real meshes deformed by vtkFFDDeform come back to their rest
// positions for every grid basis (dense and sparse) and tetrahedral lattices, normals too; the rest positions
// found are checked against the independent float64 reference (FFDReference.h), not only against our own forward
// map; folds and unconverged points are reported, never passed off as rest positions; bad input.
//
// Tolerances. Newton stops at |F(x) - y| <= 1e-12 d (d the frame's diagonal), so |x - x*| <= |J^-1| 1e-12 d; the
// lattices here move control points by at most 0.5% of d (det J > 0.5 is asserted at every point; |J^-1| stays
// below 2 for such small gradients): 2e-12 d, plus the forward map's rounding (a float64 sum of at most
// 64 terms of size d: 64 eps d = 1.4e-14 d). The issue asks for 1e-9 d; 1e-11 d holds with margin and is what is
// asserted. The reference's residual at the rest position found is bounded by the same 1e-12 d plus both
// evaluations' rounding: 1e-11 d. Tetrahedral lattices are inverted exactly (an affine map per tetrahedron, each
// way rounding within a few eps d): 1e-12 d.

#include "FFDTestErrorObserver.h"
#include "FFDTestInputChecks.h"
#include "FFDTestLattices.h"
#include "FFDTestMeshes.h"

#include "vtkCell.h"
#include "vtkCellData.h"
#include "vtkFFDBuildTetrahedralLattice.h"
#include "vtkFFDInverseDeform.h"
#include "vtkGenericCell.h"
#include "vtkMath.h"
#include "vtkSMPTools.h"
#include "vtkStaticCellLocator.h"
#include "vtkUnsignedCharArray.h"
#include "vtkUnstructuredGrid.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <vector>

namespace
{
using ffdtest::Vec;

double Distance(const double a[3], const double b[3])
{
  return std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
}

double BoundsDiagonal(vtkDataSet* data)
{
  double b[6];
  data->GetBounds(b);
  return std::hypot(b[1] - b[0], b[3] - b[2], b[5] - b[4]);
}

vtkSmartPointer<vtkPointSet> Deformed(vtkPointSet* mesh, vtkPointSet* lattice)
{
  vtkNew<vtkFFDDeform> deform;
  deform->SetInputData(mesh);
  deform->SetLatticeData(lattice);
  deform->SetBackendToCPU();
  deform->SetOutputPointsPrecision(vtkAlgorithm::DOUBLE_PRECISION);
  deform->Update();
  return deform->GetOutput();
}

/// The smallest det J of `lattice`'s deformation at `mesh`'s points.
double SmallestDeterminant(vtkPointSet* mesh, vtkPointSet* lattice)
{
  vtkNew<vtkFFDDeform> deform;
  deform->SetInputData(mesh);
  deform->SetLatticeData(lattice);
  deform->SetBackendToCPU();
  deform->ComputeJacobianDeterminantOn();
  deform->Update();
  return deform->GetOutput()->GetPointData()->GetArray(vtkFFDDeform::JacobianDeterminantArrayName())->GetRange()[0];
}

/// vtkFFDInverseDeform of `deformed` by `lattice`, its errors and warnings caught by `observer`.
vtkSmartPointer<vtkPointSet> Inverted(
  vtkPointSet* deformed, vtkPointSet* lattice, vtkFFDInverseDeform* inverse, FFDTestErrorObserver* observer)
{
  observer->WatchWithExecutive(inverse);
  inverse->SetInputData(deformed);
  inverse->SetLatticeData(lattice);
  inverse->Update();
  return inverse->GetOutput();
}

vtkUnsignedCharArray* StatusOf(vtkPointSet* output)
{
  return vtkUnsignedCharArray::SafeDownCast(
    output->GetPointData()->GetArray(vtkFFDInverseDeform::InverseStatusArrayName()));
}

/// Inverted() by the one-point search alone (VOXELFFD_MAX_SIMD=none, read at each update), the variable restored.
vtkSmartPointer<vtkPointSet> InvertedOnePointAtATime(
  vtkPointSet* deformed, vtkPointSet* lattice, FFDTestErrorObserver* observer)
{
  const char* cap = std::getenv("VOXELFFD_MAX_SIMD");
  const std::string saved = cap ? cap : "";
  setenv("VOXELFFD_MAX_SIMD", "none", 1);
  vtkNew<vtkFFDInverseDeform> inverse;
  vtkSmartPointer<vtkPointSet> rest = Inverted(deformed, lattice, inverse, observer);
  if (cap)
  {
    setenv("VOXELFFD_MAX_SIMD", saved.c_str(), 1);
  }
  else
  {
    unsetenv("VOXELFFD_MAX_SIMD");
  }
  return rest;
}

/// Two inversions of the same points agree: positions within `tolerance`, the same statuses, the normals (where
/// present) within 4 float epsilons.
void ExpectSameInversions(vtkPointSet* a, vtkPointSet* b, double tolerance)
{
  ASSERT_EQ(a->GetNumberOfPoints(), b->GetNumberOfPoints());
  EXPECT_LE(LargestDistance(a, b), tolerance);
  vtkUnsignedCharArray* status[2] = { StatusOf(a), StatusOf(b) };
  ASSERT_TRUE(status[0] && status[1]);
  for (vtkIdType p = 0; p < a->GetNumberOfPoints(); ++p)
  {
    ASSERT_EQ(status[0]->GetValue(p), status[1]->GetValue(p)) << "point " << p;
  }
  vtkDataArray* normals[2] = { a->GetPointData()->GetNormals(), b->GetPointData()->GetNormals() };
  ASSERT_EQ(normals[0] != nullptr, normals[1] != nullptr);
  double worst = 0;
  for (vtkIdType p = 0; normals[0] && p < a->GetNumberOfPoints(); ++p)
  {
    double x[3], y[3];
    normals[0]->GetTuple(p, x);
    normals[1]->GetTuple(p, y);
    worst = std::max(worst, Distance(x, y));
  }
  EXPECT_LE(worst, 4 * std::numeric_limits<float>::epsilon());
}

} // namespace

//------------------------------------------------------------------------------------------------------------
// Every grid basis, dense and sparse, on the bear and the elephant: x -> F(x) -> x within 1e-11 d, normals back
// within 4 float epsilons (the forward normals are stored in the input normals' float type: half an ulp a
// component, carried back through J^T with cond J < 2, renormalised), and the reference's F at the rest position found
// equals y within 1e-11 d.
TEST(vtkFFDInverseDeform, RoundTripsEveryGridBasis)
{
  std::mt19937 rng(2101);
  for (const char* name : { "bear", "elephant" })
  {
    vtkSmartPointer<vtkPolyData> mesh = ffdtest::WithPointNormals(ReadTestMesh(name));
    const int n[3] = { 4, 3, 5 };
    for (int basis :
      { vtkFFDBuildLattice::BERNSTEIN, vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::TRIQUADRATIC_BEZIER,
        vtkFFDBuildLattice::TRICUBIC_BEZIER, vtkFFDBuildLattice::CUBIC_BSPLINE })
    {
      for (int form : { vtkFFDBuildLattice::DENSE, vtkFFDBuildLattice::SPARSE })
      {
        if (basis == vtkFFDBuildLattice::BERNSTEIN && form == vtkFFDBuildLattice::SPARSE)
        {
          continue; // a sparse Bernstein lattice is an error
        }
        SCOPED_TRACE(std::string(name) + " basis " + std::to_string(basis) + " form " + std::to_string(form));
        vtkSmartPointer<vtkPointSet> lattice = ffdtest::MovedLattice(mesh, basis, n, form, rng, 0.005);
        const double d = ffdtest::Diagonal(ffdtest::FrameOf(lattice));
        vtkSmartPointer<vtkPointSet> deformed = Deformed(mesh, lattice);
        ASSERT_GT(SmallestDeterminant(mesh, lattice), 0.5); // the premise of the bound: no fold, |J^-1| small
        vtkNew<vtkFFDInverseDeform> inverse;
        vtkNew<FFDTestErrorObserver> observer;
        vtkSmartPointer<vtkPointSet> rest = Inverted(deformed, lattice, inverse, observer);
        EXPECT_EQ(observer->Errors + observer->Warnings, "");
        ASSERT_EQ(rest->GetNumberOfPoints(), mesh->GetNumberOfPoints());
        EXPECT_LE(LargestDistance(rest, mesh), 1e-11 * d);
        vtkUnsignedCharArray* status = StatusOf(rest);
        ASSERT_NE(status, nullptr);
        EXPECT_EQ(status->GetValueRange()[1], 0);
        EXPECT_EQ(inverse->GetNumberOfFoldedPoints() + inverse->GetNumberOfUnconvergedPoints(), 0);

        vtkDataArray* before = mesh->GetPointData()->GetNormals();
        vtkDataArray* after = rest->GetPointData()->GetNormals();
        ASSERT_NE(after, nullptr);
        double worstNormal = 0;
        for (vtkIdType p = 0; p < mesh->GetNumberOfPoints(); ++p)
        {
          double a[3], b[3];
          before->GetTuple(p, a);
          after->GetTuple(p, b);
          worstNormal = std::max(worstNormal, Distance(a, b));
        }
        EXPECT_LE(worstNormal, 4 * std::numeric_limits<float>::epsilon());

        if (form == vtkFFDBuildLattice::DENSE)
        {
          const ffdtest::Reference reference = ffdtest::ReferenceOf(lattice);
          double worst = 0;
          for (vtkIdType p = 0; p < mesh->GetNumberOfPoints(); p += 7)
          {
            Vec x, y;
            rest->GetPoint(p, x.data());
            deformed->GetPoint(p, y.data());
            const Vec fx = reference.Deform(x);
            worst = std::max(worst, Distance(fx.data(), y.data()));
          }
          EXPECT_LE(worst, 1e-11 * d);
        }
      }
    }
  }
}

//------------------------------------------------------------------------------------------------------------
// Issue 30, item 19: the grid inversion runs Newton's method in SIMD lanes (several cells a lane group, chord
// steps without the Jacobian where no normals need it), leaving what it cannot settle to the one-point search. Its
// rest positions match the one-point search's (VOXELFFD_MAX_SIMD=none) for every basis, dense and sparse, with and
// without normals, within 1e-11 d (each within 2e-12 d of the true rest position, per the derivation above), and
// so do the statuses and normals (4 float epsilons, as above). The elephant (2,775 points) over 60 voxels has its
// quadratic and cubic cells evaluated by weighted sums; the bear (13,826) over 12, every local basis's but the
// tricubic Bezier's in power form (ffd::WorthCellTable(): enough points a cell).
TEST(vtkFFDInverseDeform, LanesMatchTheOnePointSearch)
{
  std::mt19937 rng(2106);
  struct Case
  {
    const char* Mesh;
    int N[3];
  };
  for (const Case& c : { Case{ "elephant", { 5, 4, 3 } }, Case{ "bear", { 3, 2, 2 } } })
  {
    vtkSmartPointer<vtkPolyData> plain = ReadTestMesh(c.Mesh);
    vtkSmartPointer<vtkPolyData> shaded = ffdtest::WithPointNormals(plain);
    for (int basis :
      { vtkFFDBuildLattice::BERNSTEIN, vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::TRIQUADRATIC_BEZIER,
        vtkFFDBuildLattice::TRICUBIC_BEZIER, vtkFFDBuildLattice::CUBIC_BSPLINE })
    {
      for (int form : { vtkFFDBuildLattice::DENSE, vtkFFDBuildLattice::SPARSE })
      {
        if (basis == vtkFFDBuildLattice::BERNSTEIN && form == vtkFFDBuildLattice::SPARSE)
        {
          continue; // a sparse Bernstein lattice is an error
        }
        vtkSmartPointer<vtkPointSet> lattice = ffdtest::MovedLattice(plain, basis, c.N, form, rng, 0.005);
        const double d = ffdtest::Diagonal(ffdtest::FrameOf(lattice));
        for (vtkPolyData* mesh : { plain.Get(), shaded.Get() })
        {
          SCOPED_TRACE(std::string(c.Mesh) + " basis " + std::to_string(basis) + " form " + std::to_string(form) +
            (mesh == shaded ? " with normals" : ""));
          vtkSmartPointer<vtkPointSet> deformed = Deformed(mesh, lattice);
          vtkNew<vtkFFDInverseDeform> inverse;
          vtkNew<FFDTestErrorObserver> observer;
          vtkSmartPointer<vtkPointSet> lanes = Inverted(deformed, lattice, inverse, observer);
          vtkSmartPointer<vtkPointSet> alone = InvertedOnePointAtATime(deformed, lattice, observer);
          EXPECT_EQ(observer->Errors + observer->Warnings, "");
          EXPECT_LE(LargestDistance(lanes, mesh), 1e-11 * d);
          ExpectSameInversions(lanes, alone, 1e-11 * d);
        }
      }
    }
  }
}

//------------------------------------------------------------------------------------------------------------
// The lane groups, and so the rest positions to the last bit, do not depend on how the threads split the points
// (the header's promise): the same output on 1, 2 and 3 threads, without normals (where a group's chord steps
// depend on all its lanes) and with.
TEST(vtkFFDInverseDeform, SameRestPositionsWhateverTheNumberOfThreads)
{
  vtkSmartPointer<vtkPolyData> plain = ReadTestMesh("armadillo");
  vtkSmartPointer<vtkPolyData> shaded = ffdtest::WithPointNormals(plain);
  const int n[3] = { 7, 7, 7 };
  std::mt19937 rng(2107);
  for (int basis : { vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::CUBIC_BSPLINE })
  {
    vtkSmartPointer<vtkPointSet> lattice = ffdtest::MovedLattice(plain, basis, n, vtkFFDBuildLattice::DENSE, rng, 0.02);
    for (vtkPolyData* mesh : { plain.Get(), shaded.Get() })
    {
      SCOPED_TRACE("basis " + std::to_string(basis) + (mesh == shaded ? " with normals" : ""));
      vtkSmartPointer<vtkPointSet> deformed = Deformed(mesh, lattice);
      std::vector<vtkSmartPointer<vtkPointSet>> found;
      for (int threads : { 1, 2, 3 })
      {
        vtkSMPTools::Initialize(threads);
        vtkNew<vtkFFDInverseDeform> inverse;
        vtkNew<FFDTestErrorObserver> observer;
        found.push_back(Inverted(deformed, lattice, inverse, observer));
        EXPECT_EQ(observer->Errors + observer->Warnings, "");
      }
      vtkSMPTools::Initialize(); // back to the default
      for (size_t t = 1; t < found.size(); ++t)
      {
        ASSERT_EQ(found[t]->GetNumberOfPoints(), found[0]->GetNumberOfPoints());
        for (vtkIdType p = 0; p < found[0]->GetNumberOfPoints(); ++p)
        {
          double a[3], b[3];
          found[0]->GetPoint(p, a);
          found[t]->GetPoint(p, b);
          ASSERT_TRUE(a[0] == b[0] && a[1] == b[1] && a[2] == b[2]) << "point " << p << ", " << t + 1 << " threads";
        }
      }
    }
  }
}

//------------------------------------------------------------------------------------------------------------
// Points far from their rest places (a twist of the whole lattice, largest displacement a fifth of the frame)
// need several Newton steps across cells: still within 1e-11 d, single precision kept for float input.
TEST(vtkFFDInverseDeform, RoundTripsALargeDeformationAndKeepsFloatPoints)
{
  vtkSmartPointer<vtkPolyData> mesh = ReadTestMesh("armadillo");
  const int n[3] = { 5, 5, 5 };
  std::mt19937 rng(2102);
  vtkSmartPointer<vtkPointSet> lattice =
    ffdtest::MovedLattice(mesh, vtkFFDBuildLattice::CUBIC_BSPLINE, n, vtkFFDBuildLattice::DENSE, rng, 0.0);
  const ffdref::Frame f = ffdtest::FrameOf(lattice);
  const double d = ffdtest::Diagonal(f);
  vtkDataArray* restPositions = lattice->GetPointData()->GetArray("RestPosition");
  for (vtkIdType p = 0; p < lattice->GetNumberOfPoints(); ++p)
  {
    double x[3];
    restPositions->GetTuple(p, x);
    // A twist about the frame's vertical axis: 0 at the bottom, 0.5 rad at the top.
    const Vec stu = ffdref::Parameters(f, { x[0], x[1], x[2] });
    const Vec c = ffdtest::At(f, 0.5, 0.5, stu[2]);
    const double angle = 0.5 * stu[2], co = std::cos(angle), si = std::sin(angle);
    const double dx = x[0] - c[0], dy = x[1] - c[1];
    lattice->GetPoints()->SetPoint(p, c[0] + co * dx - si * dy, c[1] + si * dx + co * dy, x[2]);
  }
  vtkSmartPointer<vtkPointSet> deformed = Deformed(mesh, lattice);
  const double moved = LargestDistance(deformed, mesh);
  EXPECT_GT(moved, 0.1 * d);
  vtkNew<vtkFFDInverseDeform> inverse;
  vtkNew<FFDTestErrorObserver> observer;
  vtkSmartPointer<vtkPointSet> rest = Inverted(deformed, lattice, inverse, observer);
  EXPECT_EQ(observer->Errors + observer->Warnings, "");
  EXPECT_LE(LargestDistance(rest, mesh), 1e-11 * d);

  vtkSmartPointer<vtkPolyData> floats = WithFloatPoints(vtkPolyData::SafeDownCast(deformed));
  inverse->SetInputData(floats);
  inverse->Update();
  EXPECT_EQ(inverse->GetOutput()->GetPoints()->GetDataType(), VTK_FLOAT);
  // The float input's rounding (half a float ulp of coordinates of size d), carried back through J^-1 (< 2 here).
  EXPECT_LE(LargestDistance(inverse->GetOutput(), mesh), 2 * std::numeric_limits<float>::epsilon() * d);
}

//------------------------------------------------------------------------------------------------------------
// A sparse lattice whose moves push mesh points out of its cells (into voxels without one, where vtkFFDDeform
// keeps points: each such y is also its own image): the rest positions inside the cells are found, within 1e-11 d
// (the tolerance derivation above; det J > 0.5 asserted).
TEST(vtkFFDInverseDeform, FindsPointsPushedOutOfASparseLatticesCells)
{
  vtkSmartPointer<vtkPolyData> mesh = ReadTestMesh("armadillo");
  const int n[3] = { 8, 8, 8 };
  std::mt19937 rng(2107);
  for (int basis : { vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::CUBIC_BSPLINE })
  {
    SCOPED_TRACE("basis " + std::to_string(basis));
    vtkSmartPointer<vtkPointSet> lattice = ffdtest::MovedLattice(mesh, basis, n, vtkFFDBuildLattice::SPARSE, rng, 0.01);
    ASSERT_GT(SmallestDeterminant(mesh, lattice), 0.5);
    const ffdref::Frame f = ffdtest::FrameOf(lattice);
    const double d = ffdtest::Diagonal(f);
    vtkSmartPointer<vtkPointSet> deformed = Deformed(mesh, lattice);
    // The premise: some deformed points lie in voxels without a cell.
    std::set<std::array<int, 3>> cells;
    vtkDataArray* voxels = lattice->GetCellData()->GetArray("VoxelIndex");
    for (vtkIdType c = 0; c < lattice->GetNumberOfCells(); ++c)
    {
      cells.insert(
        { int(voxels->GetComponent(c, 0)), int(voxels->GetComponent(c, 1)), int(voxels->GetComponent(c, 2)) });
    }
    vtkIdType pushedOut = 0;
    for (vtkIdType p = 0; p < deformed->GetNumberOfPoints(); ++p)
    {
      Vec y;
      deformed->GetPoint(p, y.data());
      const Vec stu = ffdref::Parameters(f, y);
      std::array<int, 3> v;
      for (int a = 0; a < 3; ++a)
      {
        v[a] = std::clamp(int(std::floor(stu[a] * n[a])), 0, n[a] - 1);
      }
      pushedOut += cells.count(v) == 0;
    }
    EXPECT_GT(pushedOut, 0);
    vtkNew<vtkFFDInverseDeform> inverse;
    vtkNew<FFDTestErrorObserver> observer;
    vtkSmartPointer<vtkPointSet> rest = Inverted(deformed, lattice, inverse, observer);
    EXPECT_EQ(observer->Errors + observer->Warnings, "");
    EXPECT_LE(LargestDistance(rest, mesh), 1e-11 * d);
  }
}

//------------------------------------------------------------------------------------------------------------
// Tetrahedral lattices: the inverse is exact per tetrahedron: within 1e-12 d, normals within 4 float epsilons
// (stored in float, as above).
TEST(vtkFFDInverseDeform, RoundTripsTetrahedralLattices)
{
  vtkSmartPointer<vtkPolyData> mesh = ffdtest::WithPointNormals(ReadTestMesh("bear"));
  vtkNew<vtkFFDBuildTetrahedralLattice> build;
  build->SetInputData(mesh);
  build->Update();
  vtkNew<vtkUnstructuredGrid> lattice;
  lattice->DeepCopy(build->GetOutput());
  const double d = BoundsDiagonal(lattice);
  // A smooth move of every node, gradient at most 0.01 * 2 pi = 0.06 (the hull makes thin tetrahedra
  // that flip under larger moves: the premise, no fold at the mesh's points, is asserted).
  for (vtkIdType p = 0; p < lattice->GetNumberOfPoints(); ++p)
  {
    double x[3];
    lattice->GetPoint(p, x);
    const double w = 2 * vtkMath::Pi() / d;
    lattice->GetPoints()->SetPoint(p, x[0] + 0.01 * d * std::sin(w * x[1]), x[1] + 0.01 * d * std::sin(w * x[2]),
      x[2] + 0.01 * d * std::sin(w * x[0]));
  }
  ASSERT_GT(SmallestDeterminant(mesh, lattice), 0.5);
  vtkSmartPointer<vtkPointSet> deformed = Deformed(mesh, lattice);
  vtkNew<vtkFFDInverseDeform> inverse;
  vtkNew<FFDTestErrorObserver> observer;
  vtkSmartPointer<vtkPointSet> rest = Inverted(deformed, lattice, inverse, observer);
  EXPECT_EQ(observer->Errors + observer->Warnings, "");
  EXPECT_LE(LargestDistance(rest, mesh), 1e-12 * d);
  EXPECT_EQ(StatusOf(rest)->GetValueRange()[1], 0);
  // Normals only where the point lies inside one tetrahedron: on a shared edge or face (each hull node's own mesh
  // point lies on the edge from the centroid to that node) the map's gradient jumps, and the forward and the
  // inverse binding may take different sides.
  vtkNew<vtkUnstructuredGrid> atRest;
  atRest->DeepCopy(lattice);
  atRest->GetPoints()->GetData()->DeepCopy(lattice->GetPointData()->GetArray("RestPosition"));
  vtkNew<vtkStaticCellLocator> locator;
  locator->SetDataSet(atRest);
  locator->BuildLocator();
  vtkNew<vtkGenericCell> cell;
  double worstNormal = 0;
  vtkIdType compared = 0;
  for (vtkIdType p = 0; p < mesh->GetNumberOfPoints(); ++p)
  {
    double x[3], pcoords[3], weights[4];
    mesh->GetPoint(p, x);
    if (locator->FindCell(x, 0.0, cell, pcoords, weights) < 0 || *std::min_element(weights, weights + 4) < 1e-9)
    {
      continue;
    }
    ++compared;
    double a[3], b[3];
    mesh->GetPointData()->GetNormals()->GetTuple(p, a);
    rest->GetPointData()->GetNormals()->GetTuple(p, b);
    worstNormal = std::max(worstNormal, Distance(a, b));
  }
  EXPECT_GT(compared, mesh->GetNumberOfPoints() * 4 / 5);
  EXPECT_LE(worstNormal, 4 * std::numeric_limits<float>::epsilon());
}

//------------------------------------------------------------------------------------------------------------
// A fold: the middle control point of a 2x2x2 trilinear lattice pushed past its neighbours turns the voxels
// around it inside out. Points there are reported (status 1 and a warning), and every point reported as found
// is a true rest position: the reference maps it to y within 1e-11 d, and its Jacobian (central differences of
// the reference, step 1e-6 d: error O(h^2) with second derivatives of order |move| / voxel^2) is positive.
TEST(vtkFFDInverseDeform, ReportsFolds)
{
  vtkSmartPointer<vtkPolyData> mesh = ReadTestMesh("bear");
  const int n[3] = { 2, 2, 2 };
  std::mt19937 rng(2104);
  vtkSmartPointer<vtkPointSet> lattice =
    ffdtest::MovedLattice(mesh, vtkFFDBuildLattice::TRILINEAR, n, vtkFFDBuildLattice::DENSE, rng, 0.0);
  const ffdref::Frame f = ffdtest::FrameOf(lattice);
  const double d = ffdtest::Diagonal(f);
  const vtkIdType middle = 1 + 3 * (1 + 3 * 1);
  double x[3];
  lattice->GetPoint(middle, x);
  lattice->GetPoints()->SetPoint(middle, x[0] + 0.8 * f.S[0], x[1] + 0.8 * f.S[1], x[2] + 0.8 * f.S[2]);
  vtkSmartPointer<vtkPointSet> deformed = Deformed(mesh, lattice);
  vtkNew<vtkFFDInverseDeform> inverse;
  vtkNew<FFDTestErrorObserver> observer;
  vtkSmartPointer<vtkPointSet> rest = Inverted(deformed, lattice, inverse, observer);
  EXPECT_EQ(observer->Errors, "");
  EXPECT_GT(inverse->GetNumberOfFoldedPoints(), 0);
  EXPECT_NE(observer->Warnings.find("where the deformation folds"), std::string::npos) << observer->Warnings;
  vtkUnsignedCharArray* status = StatusOf(rest);
  const ffdtest::Reference reference = ffdtest::ReferenceOf(lattice);
  vtkIdType folded = 0, found = 0;
  for (vtkIdType p = 0; p < mesh->GetNumberOfPoints(); ++p)
  {
    if (status->GetValue(p) != 0)
    {
      folded += status->GetValue(p) == 1;
      continue;
    }
    ++found;
    Vec xr, y;
    rest->GetPoint(p, xr.data());
    deformed->GetPoint(p, y.data());
    const Vec fx = reference.Deform(xr);
    ASSERT_LE(Distance(fx.data(), y.data()), 1e-11 * d) << "point " << p;
    const ffdtest::Matrix j = reference.Jacobian(xr, 1e-6 * d);
    const double det = j[0][0] * (j[1][1] * j[2][2] - j[1][2] * j[2][1]) -
      j[0][1] * (j[1][0] * j[2][2] - j[1][2] * j[2][0]) + j[0][2] * (j[1][0] * j[2][1] - j[1][1] * j[2][0]);
    ASSERT_GT(det, 0.0) << "point " << p;
  }
  EXPECT_EQ(folded, inverse->GetNumberOfFoldedPoints());
  EXPECT_GT(found, 0);
}

//------------------------------------------------------------------------------------------------------------
// A tetrahedron turned inside out: points the inverse locates in it are reported as folded.
TEST(vtkFFDInverseDeform, ReportsInvertedTetrahedra)
{
  vtkSmartPointer<vtkPolyData> mesh = ReadTestMesh("bear");
  vtkNew<vtkFFDBuildTetrahedralLattice> build;
  build->SetInputData(mesh);
  build->Update();
  vtkNew<vtkUnstructuredGrid> lattice;
  lattice->DeepCopy(build->GetOutput());
  // The centroid node (the one every tetrahedron shares) pushed far through the hull: the tetrahedra on the far
  // side turn inside out.
  double b[6];
  lattice->GetBounds(b);
  std::vector<int> uses(lattice->GetNumberOfPoints());
  for (vtkIdType t = 0; t < lattice->GetNumberOfCells(); ++t)
  {
    vtkCell* cell = lattice->GetCell(t);
    for (vtkIdType i = 0; i < cell->GetNumberOfPoints(); ++i)
    {
      ++uses[cell->GetPointId(i)];
    }
  }
  const vtkIdType centroid = std::max_element(uses.begin(), uses.end()) - uses.begin();
  ASSERT_EQ(uses[centroid], lattice->GetNumberOfCells());
  double c[3];
  lattice->GetPoint(centroid, c);
  lattice->GetPoints()->SetPoint(centroid, c[0] + 2 * (b[1] - b[0]), c[1], c[2]);
  vtkSmartPointer<vtkPointSet> deformed = Deformed(mesh, lattice);
  vtkNew<vtkFFDInverseDeform> inverse;
  vtkNew<FFDTestErrorObserver> observer;
  Inverted(deformed, lattice, inverse, observer);
  EXPECT_EQ(observer->Errors, "");
  EXPECT_GT(inverse->GetNumberOfFoldedPoints(), 0);
  EXPECT_NE(observer->Warnings.find("folds"), std::string::npos);
}

//------------------------------------------------------------------------------------------------------------
// One Newton step is not enough far from the rest positions: unconverged points are counted and marked 2.
TEST(vtkFFDInverseDeform, ReportsUnconvergedPoints)
{
  vtkSmartPointer<vtkPolyData> mesh = ReadTestMesh("bear");
  const int n[3] = { 3, 3, 3 };
  std::mt19937 rng(2105);
  vtkSmartPointer<vtkPointSet> lattice =
    ffdtest::MovedLattice(mesh, vtkFFDBuildLattice::TRICUBIC_BEZIER, n, vtkFFDBuildLattice::DENSE, rng, 0.03);
  vtkSmartPointer<vtkPointSet> deformed = Deformed(mesh, lattice);
  vtkNew<vtkFFDInverseDeform> inverse;
  inverse->SetMaximumNumberOfIterations(1);
  vtkNew<FFDTestErrorObserver> observer;
  vtkSmartPointer<vtkPointSet> rest = Inverted(deformed, lattice, inverse, observer);
  EXPECT_GT(inverse->GetNumberOfUnconvergedPoints(), 0);
  EXPECT_EQ(StatusOf(rest)->GetValueRange()[1], 2);
  EXPECT_NE(observer->Warnings.find("did not converge"), std::string::npos);
}

//------------------------------------------------------------------------------------------------------------
// Points outside the lattice and non-finite points keep their position; bad input is an error, not a crash.
TEST(vtkFFDInverseDeform, KeepsOutsidePointsAndRefusesBadInput)
{
  vtkSmartPointer<vtkPolyData> mesh = ReadTestMesh("bear");
  const int n[3] = { 3, 3, 3 };
  std::mt19937 rng(2106);
  vtkSmartPointer<vtkPointSet> lattice =
    ffdtest::MovedLattice(mesh, vtkFFDBuildLattice::CUBIC_BSPLINE, n, vtkFFDBuildLattice::SPARSE, rng, 0.02);
  const ffdref::Frame f = ffdtest::FrameOf(lattice);
  const Vec outside = ffdtest::At(f, 1.5, 0.5, 0.5);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  vtkSmartPointer<vtkPolyData> points = PointCloud({ { outside[0], outside[1], outside[2] }, { nan, 0, 0 } });
  vtkNew<vtkFFDInverseDeform> inverse;
  vtkNew<FFDTestErrorObserver> observer;
  vtkSmartPointer<vtkPointSet> rest = Inverted(points, lattice, inverse, observer);
  EXPECT_EQ(observer->Errors + observer->Warnings, "");
  double x[3];
  rest->GetPoint(0, x);
  EXPECT_EQ(Vec({ x[0], x[1], x[2] }), outside);
  rest->GetPoint(1, x);
  EXPECT_TRUE(std::isnan(x[0]));

  // No lattice.
  vtkNew<vtkFFDInverseDeform> alone;
  vtkNew<FFDTestErrorObserver> aloneObserver;
  aloneObserver->WatchWithExecutive(alone);
  alone->SetInputData(mesh);
  alone->Update();
  EXPECT_NE(aloneObserver->Errors, "");

  // A lattice without its rest positions, grid and tetrahedral.
  vtkSmartPointer<vtkPointSet> dense =
    ffdtest::MovedLattice(mesh, vtkFFDBuildLattice::TRILINEAR, n, vtkFFDBuildLattice::DENSE, rng, 0.02);
  dense->GetPointData()->RemoveArray("RestPosition");
  vtkNew<vtkFFDInverseDeform> bad;
  vtkNew<FFDTestErrorObserver> badObserver;
  Inverted(mesh, dense, bad, badObserver);
  EXPECT_NE(badObserver->Errors.find("RestPosition"), std::string::npos) << badObserver->Errors;

  vtkNew<vtkFFDBuildTetrahedralLattice> build;
  build->SetInputData(mesh);
  build->Update();
  vtkNew<vtkUnstructuredGrid> tetrahedra;
  tetrahedra->DeepCopy(build->GetOutput());
  tetrahedra->GetPointData()->RemoveArray("RestPosition");
  vtkNew<vtkFFDInverseDeform> badTetrahedra;
  vtkNew<FFDTestErrorObserver> badTetrahedraObserver;
  Inverted(mesh, tetrahedra, badTetrahedra, badTetrahedraObserver);
  EXPECT_NE(badTetrahedraObserver->Errors.find("RestPosition"), std::string::npos) << badTetrahedraObserver->Errors;

  // Issue 30, item 1: a NaN Tolerance passed the setter's clamp, and no point could converge.
  vtkNew<vtkFFDInverseDeform> nanTolerance;
  nanTolerance->SetTolerance(nan);
  vtkNew<FFDTestErrorObserver> nanObserver;
  Inverted(mesh, lattice, nanTolerance, nanObserver);
  EXPECT_NE(nanObserver->Errors.find("give SetTolerance() a finite number"), std::string::npos) << nanObserver->Errors;
  EXPECT_EQ(nanTolerance->GetOutput()->GetNumberOfPoints(), 0);
}

// Issue 30, item 17: a missing or wrong-typed input failed with only the executive's "returned failure".
TEST(vtkFFDInverseDeform, SaysWhichInputIsMissingOrWrong)
{
  vtkSmartPointer<vtkPolyData> cow = ReadTestMesh("cow");
  std::mt19937 rng(32);
  const int n[3] = { 2, 2, 2 };
  vtkNew<vtkFFDInverseDeform> inverse;
  inverse->SetInputData(cow);
  inverse->SetLatticeData(
    ffdtest::MovedLattice(cow, vtkFFDBuildLattice::TRILINEAR, n, vtkFFDBuildLattice::DENSE, rng, 0.01));
  ffdtest::ExpectClearInputErrors(inverse, 0, "the deformed points", "SetInputConnection() to the deformed mesh");
  ffdtest::ExpectClearInputErrors(inverse, 1, "the lattice", "SetLatticeConnection()");
}
