// SPDX-License-Identifier: BSD-3-Clause
// vtkFFDBuildDetailLattice: adaptive refinement by a detail lattice added to the base one (vtkFFDDeformBlocks,
// ADD). At rest it changes nothing, bit for bit; moved, it changes only the points of its cells; its deformation
// vanishes on its region's boundary, to third order for the B-spline (C2) and to first order for the Bezier bases
// (C0); the second-derivative criterion selects the voxels that bend and no others.

#include "FFDTestErrorObserver.h"
#include "FFDTestLattices.h"
#include "FFDTestMeshes.h"

#include "vtkCellData.h"
#include "vtkFFDBuildDetailLattice.h"
#include "vtkFFDDeformBlocks.h"
#include "vtkIntArray.h"
#include "vtkMath.h"
#include "vtkUnstructuredGrid.h"

#include <gtest/gtest.h>

#include <limits>
#include <random>
#include <set>

namespace
{
/// A lattice of `basis` over `mesh` at rest, n voxels along each axis.
vtkSmartPointer<vtkPointSet> Lattice(vtkPointSet* mesh, int basis, int n, int form)
{
  std::mt19937 unused(0);
  const int divisions[3] = { n, n, n };
  return ffdtest::MovedLattice(mesh, basis, divisions, form, unused, 0.0);
}

vtkSmartPointer<vtkUnstructuredGrid> Detail(vtkPointSet* lattice, const std::vector<std::array<int, 3>>& voxels)
{
  vtkNew<vtkIntArray> selected;
  selected->SetNumberOfComponents(3);
  for (const auto& v : voxels)
  {
    selected->InsertNextTypedTuple(v.data());
  }
  vtkNew<vtkFFDBuildDetailLattice> detail;
  detail->SetInputData(lattice);
  detail->SetSelectedVoxels(selected);
  detail->Update();
  auto copy = vtkSmartPointer<vtkUnstructuredGrid>::New();
  copy->DeepCopy(detail->GetOutput());
  return copy;
}

vtkSmartPointer<vtkPointSet> Added(vtkPointSet* mesh, vtkPointSet* base, vtkPointSet* detail)
{
  vtkNew<vtkFFDDeformBlocks> add;
  add->SetCompositionToAdd();
  add->SetInputData(mesh);
  add->AddLatticeData(base);
  add->AddLatticeData(detail);
  add->Update();
  return vtkPointSet::SafeDownCast(add->GetOutputDataObject(0));
}

/// Moves the detail lattice's movable (Active) points at random by up to `amplitude`; returns the largest move.
double MoveMovable(vtkPointSet* detail, std::mt19937& rng, double amplitude)
{
  std::uniform_real_distribution<double> d(-amplitude, amplitude);
  vtkDataArray* active = detail->GetPointData()->GetArray("Active");
  for (vtkIdType p = 0; p < detail->GetNumberOfPoints(); ++p)
  {
    if (active->GetComponent(p, 0) != 0)
    {
      double x[3];
      detail->GetPoint(p, x);
      detail->GetPoints()->SetPoint(p, x[0] + d(rng), x[1] + d(rng), x[2] + d(rng));
    }
  }
  detail->GetPoints()->Modified();
  return amplitude * std::sqrt(3.0);
}
} // namespace

TEST(vtkFFDBuildDetailLattice, AtRestItChangesNothingMovedItChangesOnlyItsCells)
{
  vtkSmartPointer<vtkPolyData> bear = ReadTestMesh("bear");
  std::mt19937 rng(26);
  for (int basis : { vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::TRIQUADRATIC_BEZIER,
         vtkFFDBuildLattice::TRICUBIC_BEZIER, vtkFFDBuildLattice::CUBIC_BSPLINE })
  {
    vtkSmartPointer<vtkPointSet> base = Lattice(bear, basis, 4, vtkFFDBuildLattice::SPARSE);
    ffdtest::Perturb(base, rng, 0.02);
    vtkSmartPointer<vtkUnstructuredGrid> detail = Detail(base, { { 1, 2, 2 }, { 2, 2, 2 } });
    ASSERT_GT(detail->GetNumberOfPoints(), 0);
    int divisions[3];
    ASSERT_TRUE(vtkFFDDataContract::GetDivisions(detail, divisions));
    EXPECT_EQ(divisions[0], 8);

    vtkNew<vtkFFDDeform> alone;
    alone->SetInputData(bear);
    alone->SetLatticeData(base);
    alone->Update();
    vtkPointSet* baseOnly = vtkPointSet::SafeDownCast(alone->GetOutputDataObject(0));
    vtkSmartPointer<vtkPointSet> atRest = Added(bear, base, detail);
    EXPECT_TRUE(ffdtest::SamePoints(atRest, baseOnly)) << vtkFFDBuildLattice::GetBasisAsString(basis);

    // Moved: only points in the detail's cells move, and some do.
    MoveMovable(detail, rng, 0.01);
    vtkSmartPointer<vtkPointSet> moved = Added(bear, base, detail);
    std::set<std::array<int, 3>> cells;
    vtkDataArray* voxelIndex = detail->GetCellData()->GetArray("VoxelIndex");
    for (vtkIdType c = 0; c < detail->GetNumberOfCells(); ++c)
    {
      cells.insert({ int(voxelIndex->GetComponent(c, 0)), int(voxelIndex->GetComponent(c, 1)),
        int(voxelIndex->GetComponent(c, 2)) });
    }
    const ffdref::Frame f = ffdtest::FrameOf(detail);
    vtkIdType changedOutside = 0, changedInside = 0;
    for (vtkIdType p = 0; p < bear->GetNumberOfPoints(); ++p)
    {
      double x[3], y[3], z[3];
      bear->GetPoint(p, x);
      moved->GetPoint(p, y);
      baseOnly->GetPoint(p, z);
      const ffdtest::Vec stu = ffdref::Parameters(f, { x[0], x[1], x[2] });
      std::array<int, 3> voxel;
      for (int a = 0; a < 3; ++a)
      {
        voxel[a] = std::clamp(int(std::floor(stu[a] * 8)), 0, 7);
      }
      const bool changed = y[0] != z[0] || y[1] != z[1] || y[2] != z[2];
      (cells.count(voxel) ? changedInside : changedOutside) += changed;
    }
    EXPECT_EQ(changedOutside, 0) << vtkFFDBuildLattice::GetBasisAsString(basis);
    EXPECT_GT(changedInside, 0) << vtkFFDBuildLattice::GetBasisAsString(basis);
  }
}

TEST(vtkFFDBuildDetailLattice, TheDetailVanishesOnItsBoundaryAsTheBasisIsContinuous)
{
  // Along a line crossing the region's boundary at voxel coordinate v0 (x = (v0 + delta) / 12 of the frame), the
  // detail's displacement is 0 on the boundary and, at delta voxels inside, at most 64 w(delta) times the
  // largest move: w = delta^3 / 6 for the B-spline's tail (its value and two derivatives vanish: C2), and
  // w = 3 delta for a Bezier basis of degree <= 3 (C0).
  vtkSmartPointer<vtkPolyData> bear = ReadTestMesh("bear");
  std::mt19937 rng(27);
  for (int basis :
    { vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::TRICUBIC_BEZIER, vtkFFDBuildLattice::CUBIC_BSPLINE })
  {
    // Voxels 2 and 3 of 6 along each axis: the region's cells stay inside the frame.
    vtkSmartPointer<vtkPointSet> base = Lattice(bear, basis, 6, vtkFFDBuildLattice::SPARSE);
    vtkSmartPointer<vtkUnstructuredGrid> detail = Detail(
      base, { { 2, 2, 2 }, { 3, 2, 2 }, { 2, 3, 2 }, { 3, 3, 2 }, { 2, 2, 3 }, { 3, 2, 3 }, { 2, 3, 3 }, { 3, 3, 3 } });
    const double largest = MoveMovable(detail, rng, 0.01);
    // The region's lowest cell along s, at the middle of the others.
    int lowest = 12;
    vtkDataArray* voxelIndex = detail->GetCellData()->GetArray("VoxelIndex");
    for (vtkIdType c = 0; c < detail->GetNumberOfCells(); ++c)
    {
      lowest = std::min(lowest, int(voxelIndex->GetComponent(c, 0)));
    }
    const ffdref::Frame f = ffdtest::FrameOf(detail);
    ASSERT_GT(lowest, 0) << "an interior boundary";
    const bool bspline = basis == vtkFFDBuildLattice::CUBIC_BSPLINE;
    std::vector<std::array<double, 3>> xs;
    const double deltas[] = { 0.0, 1e-2, 1e-1, 1.0 };
    for (double delta : deltas)
    {
      xs.push_back(ffdtest::At(f, (lowest + delta) / 12, 0.5, 0.5));
    }
    vtkSmartPointer<vtkPolyData> line = PointCloud(xs);
    vtkNew<vtkFFDDeform> deform;
    deform->SetInputData(line);
    deform->SetLatticeData(detail);
    deform->Update();
    for (int i = 0; i < 4; ++i)
    {
      double x[3], y[3];
      line->GetPoint(i, x);
      vtkPointSet::SafeDownCast(deform->GetOutputDataObject(0))->GetPoint(i, y);
      const double moved = std::sqrt(vtkMath::Distance2BetweenPoints(x, y));
      const double delta = deltas[i];
      if (delta == 1.0)
      {
        EXPECT_GT(moved, 1e-3 * largest) << "a voxel inside, the detail moves points";
        continue;
      }
      const double bound = 64 * (bspline ? delta * delta * delta / 6 : 3 * delta) * largest + 1e-15;
      EXPECT_LE(moved, bound) << vtkFFDBuildLattice::GetBasisAsString(basis) << " at delta " << delta;
    }
  }
}

TEST(vtkFFDBuildDetailLattice, TheSecondDerivativeSelectsTheVoxelsThatBend)
{
  vtkSmartPointer<vtkPolyData> bear = ReadTestMesh("bear");
  vtkSmartPointer<vtkPointSet> lattice = Lattice(bear, vtkFFDBuildLattice::TRILINEAR, 6, vtkFFDBuildLattice::DENSE);
  const ffdref::Frame f = ffdtest::FrameOf(lattice);
  const double length = ffdtest::Length(f.S);
  // An affine map everywhere, plus a quadratic bulge along u where s < 1/3.
  vtkDataArray* rest = lattice->GetPointData()->GetArray("RestPosition");
  for (vtkIdType p = 0; p < lattice->GetNumberOfPoints(); ++p)
  {
    double x[3];
    rest->GetTuple(p, x);
    const double s = ffdref::Parameters(f, { x[0], x[1], x[2] })[0];
    const double bulge = s < 1.0 / 3 ? 2 * (1.0 / 3 - s) * (1.0 / 3 - s) * length : 0.0;
    lattice->GetPoints()->SetPoint(p, 1.1 * x[0] + 0.2 * x[1], x[1] - 0.1 * x[2], x[2] + bulge);
  }
  vtkNew<vtkFFDBuildDetailLattice> detail;
  detail->SetInputData(lattice);
  // The bulge's second derivative: 4 length / |S|^2 per unit parameter squared = 4 / length in world units; the
  // affine part has none (rounding: 1e-15 length / h^2 = 36e-15 / length). Half of it is the threshold.
  detail->SetSecondDerivativeThreshold(2.0 / length);
  detail->Update();
  EXPECT_GT(detail->GetNumberOfRefinedVoxels(), 0);
  vtkDataArray* voxelIndex = detail->GetOutput()->GetCellData()->GetArray("VoxelIndex");
  int highest = -1;
  for (vtkIdType c = 0; c < detail->GetOutput()->GetNumberOfCells(); ++c)
  {
    highest = std::max(highest, int(voxelIndex->GetComponent(c, 0)));
  }
  // The bend is in the input's voxels 0 to 2 along s (its kink at s = 1/3 shows in voxel 2's neighbourhood): the
  // fine cells lie below fine voxel 2 * 3 + 1 (the halves, plus the ring one voxel beyond).
  EXPECT_LE(highest, 7);
  EXPECT_GE(highest, 3);

  // An affine lattice selects nothing.
  for (vtkIdType p = 0; p < lattice->GetNumberOfPoints(); ++p)
  {
    double x[3];
    rest->GetTuple(p, x);
    lattice->GetPoints()->SetPoint(p, 1.1 * x[0] + 0.2 * x[1], x[1] - 0.1 * x[2], x[2]);
  }
  lattice->GetPoints()->Modified();
  detail->Modified();
  detail->Update();
  EXPECT_EQ(detail->GetNumberOfRefinedVoxels(), 0);
  EXPECT_EQ(detail->GetOutput()->GetNumberOfPoints(), 0);
}

TEST(vtkFFDBuildDetailLattice, RefusesWhatItCannotRefine)
{
  vtkSmartPointer<vtkPolyData> cow = ReadTestMesh("cow");
  vtkSmartPointer<vtkPointSet> bernstein = Lattice(cow, vtkFFDBuildLattice::BERNSTEIN, 3, vtkFFDBuildLattice::DENSE);
  vtkSmartPointer<vtkPointSet> trilinear = Lattice(cow, vtkFFDBuildLattice::TRILINEAR, 3, vtkFFDBuildLattice::SPARSE);
  struct Case
  {
    vtkPointSet* Input;
    std::array<int, 3> Voxel;
    const char* Says;
  };
  const Case cases[] = { { bernstein, { 0, 0, 0 }, "vtkFFDRefineLattice" }, { trilinear, { 3, 0, 0 }, "outside" },
    { cow, { 0, 0, 0 }, "Cannot refine the input" } };
  for (const Case& c : cases)
  {
    vtkNew<vtkIntArray> selected;
    selected->SetNumberOfComponents(3);
    selected->InsertNextTypedTuple(c.Voxel.data());
    vtkNew<vtkFFDBuildDetailLattice> detail;
    vtkNew<FFDTestErrorObserver> errors;
    errors->WatchWithExecutive(detail);
    detail->SetInputData(c.Input);
    detail->SetSelectedVoxels(selected);
    detail->Update();
    EXPECT_NE(errors->Errors.find(c.Says), std::string::npos) << errors->Errors;
    EXPECT_EQ(detail->GetOutput()->GetNumberOfPoints(), 0);
  }

  // Issue 30, item 1: a NaN threshold passed the setter's clamp and turned the threshold off without a word.
  vtkNew<vtkFFDBuildDetailLattice> detail;
  vtkNew<FFDTestErrorObserver> errors;
  errors->WatchWithExecutive(detail);
  detail->SetInputData(trilinear);
  detail->SetSecondDerivativeThreshold(std::numeric_limits<double>::quiet_NaN());
  detail->Update();
  EXPECT_NE(errors->Errors.find("give SetSecondDerivativeThreshold() a number >= 0"), std::string::npos)
    << errors->Errors;
  EXPECT_EQ(detail->GetOutput()->GetNumberOfPoints(), 0);
}
