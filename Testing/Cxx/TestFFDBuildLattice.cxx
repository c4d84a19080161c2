// SPDX-License-Identifier: BSD-3-Clause
// vtkFFDBuildLattice: the Bernstein rest lattice against equation 1 (ffdref::RestLattice), the data contract
// of the output, culling, and every bad input.
#include "vtkFFDBuildLattice.h"

#include "vtkCellData.h"
#include "vtkDataSetAttributes.h"
#include "vtkDoubleArray.h"
#include "vtkExecutive.h"
#include "vtkFFDDataContract.h"
#include "vtkFFDVoxelize.h"
#include "vtkFieldData.h"
#include "vtkInformation.h"
#include "vtkIntArray.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkStructuredGrid.h"
#include "vtkUnsignedCharArray.h"

#include "FFDBernstein.h"
#include "FFDReference.h"
#include "FFDTestErrorObserver.h"
#include "FFDTestMeshes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

namespace
{
using ffdref::Vec;

// A skewed parallelepiped away from the origin.
const double SkewedFrame[12] = { -1.5, 2.0, 0.25, 3.0, 0.4, -0.1, 0.5, 2.0, 0.3, -0.2, 0.6, 1.5 };

/// A voxel grid as vtkFFDVoxelize makes it, built by hand: corners, field arrays, and the voxels for which
/// `hidden(i, j, k)` holds marked HIDDENCELL (no ghost array when `hidden` is empty).
vtkSmartPointer<vtkStructuredGrid> MakeVoxelGrid(
  const double frame[12], const int n[3], const std::function<bool(int, int, int)>& hidden = {})
{
  auto grid = vtkSmartPointer<vtkStructuredGrid>::New();
  grid->SetDimensions(n[0] + 1, n[1] + 1, n[2] + 1);
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  for (int k = 0; k <= n[2]; ++k)
    for (int j = 0; j <= n[1]; ++j)
      for (int i = 0; i <= n[0]; ++i)
      {
        double x[3];
        for (int c = 0; c < 3; ++c)
        {
          x[c] = frame[c] + frame[3 + c] * i / n[0] + frame[6 + c] * j / n[1] + frame[9 + c] * k / n[2];
        }
        points->InsertNextPoint(x);
      }
  grid->SetPoints(points);
  if (hidden)
  {
    vtkNew<vtkUnsignedCharArray> ghosts;
    ghosts->SetName(vtkDataSetAttributes::GhostArrayName());
    for (int k = 0; k < n[2]; ++k)
      for (int j = 0; j < n[1]; ++j)
        for (int i = 0; i < n[0]; ++i)
        {
          ghosts->InsertNextValue(hidden(i, j, k) ? vtkDataSetAttributes::HIDDENCELL : 0);
        }
    grid->GetCellData()->AddArray(ghosts);
  }
  vtkFFDDataContract::SetFrame(grid, frame);
  vtkFFDDataContract::SetDivisions(grid, n);
  return grid;
}

int RunPipeline(vtkFFDBuildLattice* filter, FFDTestErrorObserver* observer)
{
  observer->Watch(filter);
  observer->Watch(filter->GetExecutive());
  return filter->GetExecutive()->Update();
}

/// Builds the lattice of `grid` and expects success without any error.
vtkStructuredGrid* Build(vtkFFDBuildLattice* filter, vtkDataObject* grid)
{
  vtkNew<FFDTestErrorObserver> observer;
  filter->SetInputData(grid);
  EXPECT_EQ(RunPipeline(filter, observer), 1) << observer->Errors;
  EXPECT_EQ(observer->Errors, "");
  return filter->GetOutput();
}

/// Expects the filter to fail on `grid` with an error containing every string of `messages`.
void ExpectFailure(vtkFFDBuildLattice* filter, vtkDataObject* grid, const std::vector<std::string>& messages)
{
  vtkNew<FFDTestErrorObserver> observer;
  filter->SetInputData(grid);
  EXPECT_EQ(RunPipeline(filter, observer), 0);
  for (const std::string& message : messages)
  {
    EXPECT_NE(observer->Errors.find(message), std::string::npos) << message << " not in: " << observer->Errors;
  }
  EXPECT_EQ(filter->GetNumberOfActiveControlPoints(), 0);
}

vtkUnsignedCharArray* ActiveArray(vtkStructuredGrid* lattice)
{
  return vtkUnsignedCharArray::SafeDownCast(
    lattice->GetPointData()->GetAbstractArray(vtkFFDDataContract::ActiveArrayName()));
}
} // namespace

TEST(vtkFFDBuildLattice, BernsteinRestPositionsFollowEquation1)
{
  const ffdref::Frame f = { { SkewedFrame[0], SkewedFrame[1], SkewedFrame[2] },
    { SkewedFrame[3], SkewedFrame[4], SkewedFrame[5] }, { SkewedFrame[6], SkewedFrame[7], SkewedFrame[8] },
    { SkewedFrame[9], SkewedFrame[10], SkewedFrame[11] } };
  for (const std::vector<int>& n : { std::vector<int>{ 1, 1, 1 }, { 2, 3, 4 }, { 7, 1, 5 } })
  {
    SCOPED_TRACE(n[0] * 100 + n[1] * 10 + n[2]);
    vtkNew<vtkFFDBuildLattice> build;
    vtkStructuredGrid* lattice = Build(build, MakeVoxelGrid(SkewedFrame, n.data()));
    const std::vector<Vec> expected = ffdref::RestLattice(f, n[0], n[1], n[2]);
    ASSERT_EQ(lattice->GetNumberOfPoints(), static_cast<vtkIdType>(expected.size()));
    vtkDoubleArray* rest = vtkDoubleArray::SafeDownCast(
      lattice->GetPointData()->GetAbstractArray(vtkFFDDataContract::RestPositionArrayName()));
    ASSERT_NE(rest, nullptr);
    // Both sides compute X0 + aS + bT + cU from the same doubles: at most a few roundings apart, 1e-15 of the
    // coordinates' scale.
    const double scale = 6.0;
    for (vtkIdType id = 0; id < lattice->GetNumberOfPoints(); ++id)
    {
      double x[3];
      lattice->GetPoint(id, x);
      for (int c = 0; c < 3; ++c)
      {
        ASSERT_NEAR(x[c], expected[id][c], 1e-15 * scale) << id;
        ASSERT_EQ(rest->GetComponent(id, c), x[c]) << id;
      }
    }
  }
}

TEST(vtkFFDBuildLattice, OutputFollowsTheDataContract)
{
  const int n[3] = { 3, 4, 2 };
  vtkNew<vtkFFDBuildLattice> build;
  build->SetBasisToBernstein();
  vtkStructuredGrid* lattice = Build(build, MakeVoxelGrid(SkewedFrame, n));

  int dims[3];
  lattice->GetDimensions(dims);
  EXPECT_EQ(dims[0], 4);
  EXPECT_EQ(dims[1], 5);
  EXPECT_EQ(dims[2], 3);
  int whole[6];
  build->GetOutputInformation(0)->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), whole);
  EXPECT_EQ(std::vector<int>(whole, whole + 6), (std::vector<int>{ 0, 3, 0, 4, 0, 2 }));
  EXPECT_EQ(lattice->GetPoints()->GetDataType(), VTK_DOUBLE);

  vtkDoubleArray* rest = vtkDoubleArray::SafeDownCast(
    lattice->GetPointData()->GetAbstractArray(vtkFFDDataContract::RestPositionArrayName()));
  ASSERT_NE(rest, nullptr);
  EXPECT_EQ(rest->GetNumberOfComponents(), 3);
  EXPECT_EQ(rest->GetNumberOfTuples(), 60);
  vtkUnsignedCharArray* active = ActiveArray(lattice);
  ASSERT_NE(active, nullptr);
  EXPECT_EQ(active->GetNumberOfComponents(), 1);
  EXPECT_EQ(active->GetNumberOfTuples(), 60);

  double frame[12];
  ASSERT_TRUE(vtkFFDDataContract::GetFrame(lattice, frame));
  EXPECT_EQ(std::vector<double>(frame, frame + 12), std::vector<double>(SkewedFrame, SkewedFrame + 12));
  int divisions[3];
  ASSERT_TRUE(vtkFFDDataContract::GetDivisions(lattice, divisions));
  EXPECT_EQ(std::vector<int>(divisions, divisions + 3), std::vector<int>(n, n + 3));
  int basis = -1;
  ASSERT_TRUE(vtkFFDDataContract::GetBasis(lattice, basis));
  EXPECT_EQ(basis, vtkFFDBuildLattice::BERNSTEIN);
  EXPECT_STREQ(build->GetBasisAsString(), "BERNSTEIN");
  EXPECT_STREQ(vtkFFDBuildLattice::GetBasisAsString(vtkFFDBuildLattice::CUBIC_BSPLINE), "CUBIC_BSPLINE");
}

TEST(vtkFFDBuildLattice, GlobalBasisKeepsEveryControlPointOfAnActiveGrid)
{
  // Only one voxel active, in a corner: the global basis still needs every control point.
  const int n[3] = { 4, 3, 5 };
  for (bool oneVoxel : { false, true })
  {
    SCOPED_TRACE(oneVoxel);
    vtkSmartPointer<vtkStructuredGrid> grid = oneVoxel
      ? MakeVoxelGrid(SkewedFrame, n, [](int i, int j, int k) { return i + j + k != 0; })
      : MakeVoxelGrid(SkewedFrame, n);
    vtkNew<vtkFFDBuildLattice> build;
    vtkStructuredGrid* lattice = Build(build, grid);
    vtkUnsignedCharArray* active = ActiveArray(lattice);
    ASSERT_NE(active, nullptr);
    for (vtkIdType id = 0; id < active->GetNumberOfValues(); ++id)
    {
      ASSERT_EQ(active->GetValue(id), 1) << id;
    }
    EXPECT_EQ(build->GetNumberOfActiveControlPoints(), 5 * 4 * 6);
    EXPECT_EQ(lattice->GetPointData()->GetArray(vtkDataSetAttributes::GhostArrayName()), nullptr);
  }
}

TEST(vtkFFDBuildLattice, AllInactiveVoxelsCullEveryControlPoint)
{
  const int n[3] = { 2, 3, 2 };
  vtkNew<vtkFFDBuildLattice> build;
  vtkStructuredGrid* lattice = Build(build, MakeVoxelGrid(SkewedFrame, n, [](int, int, int) { return true; }));
  EXPECT_EQ(build->GetNumberOfActiveControlPoints(), 0);
  vtkUnsignedCharArray* active = ActiveArray(lattice);
  vtkUnsignedCharArray* ghosts =
    vtkUnsignedCharArray::SafeDownCast(lattice->GetPointData()->GetArray(vtkDataSetAttributes::GhostArrayName()));
  ASSERT_NE(active, nullptr);
  ASSERT_NE(ghosts, nullptr);
  ASSERT_EQ(lattice->GetNumberOfPoints(), 3 * 4 * 3);
  for (vtkIdType id = 0; id < lattice->GetNumberOfPoints(); ++id)
  {
    EXPECT_EQ(active->GetValue(id), 0);
    EXPECT_TRUE(ghosts->GetValue(id) & vtkDataSetAttributes::HIDDENPOINT);
  }
}

TEST(vtkFFDBuildLattice, PipelineFromVoxelizeOnTheBear)
{
  vtkNew<vtkFFDVoxelize> voxelize;
  voxelize->SetInputData(ReadTestMesh("bear"));
  voxelize->SetDivisions(2, 3, 4); // the paper's Figure 12: 3 x 4 x 5 control points
  vtkNew<vtkFFDBuildLattice> build;
  build->SetInputConnection(voxelize->GetOutputPort());
  vtkNew<FFDTestErrorObserver> observer;
  ASSERT_EQ(RunPipeline(build, observer), 1) << observer->Errors;
  EXPECT_EQ(build->GetOutput()->GetNumberOfPoints(), 60);
  EXPECT_EQ(build->GetNumberOfActiveControlPoints(), 60);
  EXPECT_GT(voxelize->GetNumberOfActiveVoxels(), 0);

  // Every point outside the explicit frame: no voxel is active, so every control point is culled.
  const double o[3] = { 1e6, 1e6, 1e6 }, s[3] = { 1, 0, 0 }, t[3] = { 0, 1, 0 }, u[3] = { 0, 0, 1 };
  voxelize->SetFrameModeToExplicit();
  voxelize->SetFrame(o, s, t, u);
  ASSERT_EQ(RunPipeline(build, observer), 1) << observer->Errors;
  EXPECT_EQ(voxelize->GetNumberOfActiveVoxels(), 0);
  EXPECT_EQ(build->GetOutput()->GetNumberOfPoints(), 60);
  EXPECT_EQ(build->GetNumberOfActiveControlPoints(), 0);
  EXPECT_EQ(observer->Errors, "");
}

TEST(vtkFFDBuildLattice, EmptyInputGivesEmptyOutput)
{
  vtkNew<vtkFFDVoxelize> voxelize;
  voxelize->SetInputData(vtkSmartPointer<vtkPolyData>::New());
  vtkNew<vtkFFDBuildLattice> build;
  build->SetInputConnection(voxelize->GetOutputPort());
  vtkNew<FFDTestErrorObserver> observer;
  EXPECT_EQ(RunPipeline(build, observer), 1);
  EXPECT_EQ(observer->Errors, "");
  EXPECT_EQ(build->GetOutput()->GetNumberOfPoints(), 0);
  EXPECT_EQ(build->GetNumberOfActiveControlPoints(), 0);

  vtkNew<vtkFFDBuildLattice> direct;
  EXPECT_EQ(Build(direct, vtkSmartPointer<vtkStructuredGrid>::New())->GetNumberOfPoints(), 0);
}

TEST(vtkFFDBuildLattice, MissingOrBadContractArraysAreAnError)
{
  const int n[3] = { 2, 2, 2 };
  {
    vtkSmartPointer<vtkStructuredGrid> grid = MakeVoxelGrid(SkewedFrame, n);
    grid->GetFieldData()->RemoveArray(vtkFFDDataContract::FrameArrayName());
    vtkNew<vtkFFDBuildLattice> build;
    ExpectFailure(build, grid, { "FFDFrame", "connect the output of vtkFFDVoxelize" });
  }
  {
    vtkSmartPointer<vtkStructuredGrid> grid = MakeVoxelGrid(SkewedFrame, n);
    grid->GetFieldData()->RemoveArray(vtkFFDDataContract::DivisionsArrayName());
    vtkNew<vtkFFDBuildLattice> build;
    ExpectFailure(build, grid, { "FFDDivisions", "connect the output of vtkFFDVoxelize" });
  }
  {
    // Divisions that disagree with the grid's dimensions.
    vtkSmartPointer<vtkStructuredGrid> grid = MakeVoxelGrid(SkewedFrame, n);
    const int other[3] = { 2, 3, 2 };
    vtkFFDDataContract::SetDivisions(grid, other);
    vtkNew<vtkFFDBuildLattice> build;
    ExpectFailure(build, grid, { "do not match", "FFDDivisions" });
  }
  {
    double nonFinite[12];
    std::copy(SkewedFrame, SkewedFrame + 12, nonFinite);
    nonFinite[7] = std::numeric_limits<double>::quiet_NaN();
    vtkNew<vtkFFDBuildLattice> build;
    ExpectFailure(build, MakeVoxelGrid(nonFinite, n), { "FFDFrame" });
  }
  {
    double flat[12] = { 0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0 };
    vtkSmartPointer<vtkStructuredGrid> grid = MakeVoxelGrid(SkewedFrame, n);
    vtkFFDDataContract::SetFrame(grid, flat);
    vtkNew<vtkFFDBuildLattice> build;
    ExpectFailure(build, grid, { "zero volume" });
  }
}

TEST(vtkFFDBuildLattice, UnimplementedBasesAreAnError)
{
  const int n[3] = { 2, 2, 2 };
  for (int basis : { vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::TRIQUADRATIC_BEZIER,
         vtkFFDBuildLattice::TRICUBIC_BEZIER, vtkFFDBuildLattice::CUBIC_BSPLINE })
  {
    vtkNew<vtkFFDBuildLattice> build;
    build->SetBasis(basis);
    ExpectFailure(build, MakeVoxelGrid(SkewedFrame, n),
      { std::string("basis ") + vtkFFDBuildLattice::GetBasisAsString(basis) + " is not implemented yet",
        "use BERNSTEIN" });
  }
}

TEST(vtkFFDBuildLattice, DivisionsAboveTheMaximumBernsteinDegreeAreAnError)
{
  const int ok[3] = { ffd::MaxBernsteinDegree, 1, 1 };
  vtkNew<vtkFFDBuildLattice> accepted;
  EXPECT_EQ(Build(accepted, MakeVoxelGrid(SkewedFrame, ok))->GetNumberOfPoints(), ffd::MaxBernsteinDegree * 4 + 4);

  const int tooMany[3] = { 1, ffd::MaxBernsteinDegree + 1, 1 };
  vtkNew<vtkFFDBuildLattice> build;
  ExpectFailure(build, MakeVoxelGrid(SkewedFrame, tooMany),
    { "degree " + std::to_string(ffd::MaxBernsteinDegree + 1), "at most " + std::to_string(ffd::MaxBernsteinDegree) });
}
