// SPDX-License-Identifier: BSD-3-Clause
// vtkFFDBuildLattice: the Bernstein rest lattice against equation 1 (ffdref::RestLattice), every basis's
// dimensions and rest positions against the formulas of the paper, culling by support against a brute force
// on hand-made grids and real meshes, the figure-caption statistics, the data contract, and every bad input.
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
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkStructuredGrid.h"
#include "vtkUnsignedCharArray.h"

#include "FFDBernstein.h"
#include "FFDReference.h"
#include "FFDTestComparisons.h"
#include "FFDTestErrorObserver.h"
#include "FFDTestMeshes.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <functional>
#include <iostream>
#include <limits>
#include <random>
#include <set>
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
  observer->WatchWithExecutive(filter);
  return filter->GetExecutive()->Update();
}

/// Builds the lattice of `grid` and expects success without any error.
vtkStructuredGrid* Build(vtkFFDBuildLattice* filter, vtkDataObject* grid)
{
  vtkNew<FFDTestErrorObserver> observer;
  filter->SetInputData(grid);
  // The producer of `grid` complains when asked for an extent it does not hold.
  observer->WatchWithExecutive(filter->GetInputAlgorithm());
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

const int AllBases[] = { vtkFFDBuildLattice::BERNSTEIN, vtkFFDBuildLattice::TRILINEAR,
  vtkFFDBuildLattice::TRIQUADRATIC_BEZIER, vtkFFDBuildLattice::TRICUBIC_BEZIER, vtkFFDBuildLattice::CUBIC_BSPLINE };

// The formulas below are written out from the issue and the paper (Listings 1 and 2, equation 4, the uniform
// cubic B-spline), independently of Filters/Kernels/FFDGridBasis.h.

/// Control points along an axis of n voxels.
int ExpectedPointsAlongAxis(int basis, int n)
{
  switch (basis)
  {
    case vtkFFDBuildLattice::BERNSTEIN: // degree n
    case vtkFFDBuildLattice::TRILINEAR: // the voxels' corners
      return n + 1;
    case vtkFFDBuildLattice::TRIQUADRATIC_BEZIER: // 3 per voxel, faces shared
      return 2 * n + 1;
    case vtkFFDBuildLattice::TRICUBIC_BEZIER: // 4 per voxel, faces shared
      return 3 * n + 1;
    default: // CUBIC_BSPLINE: n + 1 knots and one ring beyond the frame
      return n + 3;
  }
}

/// Parameter along an axis of n voxels of control point i at rest.
double ExpectedRestParameter(int basis, int n, int i)
{
  switch (basis)
  {
    case vtkFFDBuildLattice::BERNSTEIN:
    case vtkFFDBuildLattice::TRILINEAR:
      return static_cast<double>(i) / n;
    case vtkFFDBuildLattice::TRIQUADRATIC_BEZIER:
      return static_cast<double>(i) / (2 * n);
    case vtkFFDBuildLattice::TRICUBIC_BEZIER:
      return static_cast<double>(i) / (3 * n);
    default: // CUBIC_BSPLINE: the outer ring lies one spacing outside the frame
      return static_cast<double>(i - 1) / n;
  }
}

/// Whether voxel v of an axis lies in the support of control point a of that axis.
bool VoxelTouchesPoint(int basis, int v, int a)
{
  switch (basis)
  {
    case vtkFFDBuildLattice::BERNSTEIN: // global: every point influences every voxel
      return true;
    case vtkFFDBuildLattice::TRILINEAR: // Bezier degree 1: points v, v + 1
      return v <= a && a <= v + 1;
    case vtkFFDBuildLattice::TRIQUADRATIC_BEZIER: // degree 2: points 2v .. 2v + 2
      return 2 * v <= a && a <= 2 * v + 2;
    case vtkFFDBuildLattice::TRICUBIC_BEZIER: // degree 3: points 3v .. 3v + 3
      return 3 * v <= a && a <= 3 * v + 3;
    default: // CUBIC_BSPLINE: points v .. v + 3
      return v <= a && a <= v + 3;
  }
}

/**
 * Checks `Active`, the point ghost array and GetNumberOfActiveControlPoints() of `lattice` (built by `build`
 * with `basis` over `voxels`, a voxel grid whose cell ghost array marks inactive voxels) against a brute
 * force: a control point is active when any active voxel lies in its support along all three axes.
 */
void ExpectActiveFromSupports(
  int basis, vtkStructuredGrid* voxels, vtkFFDBuildLattice* build, vtkStructuredGrid* lattice)
{
  int vd[3], pd[3];
  voxels->GetDimensions(vd);
  lattice->GetDimensions(pd);
  const int n[3] = { vd[0] - 1, vd[1] - 1, vd[2] - 1 };
  std::vector<std::array<int, 3>> activeVoxels;
  vtkUnsignedCharArray* cellGhosts = voxels->GetCellGhostArray();
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i)
      {
        const vtkIdType id = i + n[0] * (j + n[1] * k);
        if (!cellGhosts || !(cellGhosts->GetValue(id) & vtkDataSetAttributes::HIDDENCELL))
        {
          activeVoxels.push_back({ i, j, k });
        }
      }
  vtkUnsignedCharArray* active = ActiveArray(lattice);
  ASSERT_NE(active, nullptr);
  ASSERT_EQ(active->GetNumberOfValues(), lattice->GetNumberOfPoints());
  vtkUnsignedCharArray* ghosts =
    vtkUnsignedCharArray::SafeDownCast(lattice->GetPointData()->GetArray(vtkDataSetAttributes::GhostArrayName()));
  vtkIdType expectedActive = 0;
  for (int c = 0; c < pd[2]; ++c)
    for (int b = 0; b < pd[1]; ++b)
      for (int a = 0; a < pd[0]; ++a)
      {
        bool influences = false;
        for (const std::array<int, 3>& v : activeVoxels)
        {
          influences = influences ||
            (VoxelTouchesPoint(basis, v[0], a) && VoxelTouchesPoint(basis, v[1], b) &&
              VoxelTouchesPoint(basis, v[2], c));
        }
        const vtkIdType id = a + pd[0] * (b + static_cast<vtkIdType>(pd[1]) * c);
        ASSERT_EQ(active->GetValue(id), influences ? 1 : 0) << "control point " << a << " " << b << " " << c;
        if (ghosts)
        {
          ASSERT_EQ((ghosts->GetValue(id) & vtkDataSetAttributes::HIDDENPOINT) != 0, !influences) << id;
        }
        expectedActive += influences;
      }
  EXPECT_EQ(build->GetNumberOfActiveControlPoints(), expectedActive);
  // The ghost array exists exactly when some control point is culled.
  EXPECT_EQ(ghosts != nullptr, expectedActive < lattice->GetNumberOfPoints());
}

/// A vtkFFDBuildLattice whose basis can be set to a value outside the enum, as a subclass could.
class UnknownBasisBuildLattice : public vtkFFDBuildLattice
{
public:
  static UnknownBasisBuildLattice* New();
  vtkTypeMacro(UnknownBasisBuildLattice, vtkFFDBuildLattice);
  void ForceBasis(int basis)
  {
    this->Basis = basis;
    this->Modified();
  }
};
vtkStandardNewMacro(UnknownBasisBuildLattice);
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
      double x[3], r[3];
      lattice->GetPoint(id, x);
      rest->GetTuple(id, r);
      ASSERT_TRUE(ffdtest::VectorNear(x, expected[id], 1e-15 * scale)) << id;
      ASSERT_TRUE(ffdtest::VectorEqual(r, x, "rest position component")) << id;
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
  EXPECT_STREQ(build->GetBasisAsString(), "Bernstein");
  EXPECT_STREQ(vtkFFDBuildLattice::GetBasisAsString(vtkFFDBuildLattice::CUBIC_BSPLINE), "CubicBSpline");
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
  for (int basis : AllBases)
  {
    SCOPED_TRACE(vtkFFDBuildLattice::GetBasisAsString(basis));
    vtkNew<vtkFFDBuildLattice> build;
    build->SetBasis(basis);
    vtkStructuredGrid* lattice = Build(build, MakeVoxelGrid(SkewedFrame, n, [](int, int, int) { return true; }));
    EXPECT_EQ(build->GetNumberOfActiveControlPoints(), 0);
    vtkUnsignedCharArray* active = ActiveArray(lattice);
    vtkUnsignedCharArray* ghosts =
      vtkUnsignedCharArray::SafeDownCast(lattice->GetPointData()->GetArray(vtkDataSetAttributes::GhostArrayName()));
    ASSERT_NE(active, nullptr);
    ASSERT_NE(ghosts, nullptr);
    ASSERT_EQ(lattice->GetNumberOfPoints(),
      static_cast<vtkIdType>(ExpectedPointsAlongAxis(basis, n[0])) * ExpectedPointsAlongAxis(basis, n[1]) *
        ExpectedPointsAlongAxis(basis, n[2]));
    for (vtkIdType id = 0; id < lattice->GetNumberOfPoints(); ++id)
    {
      EXPECT_EQ(active->GetValue(id), 0);
      EXPECT_TRUE(ghosts->GetValue(id) & vtkDataSetAttributes::HIDDENPOINT);
    }
  }
}

TEST(vtkFFDBuildLattice, EveryBasisHasItsDimensionsAndRestPositions)
{
  for (int basis : AllBases)
  {
    for (const std::vector<int>& n : { std::vector<int>{ 1, 1, 1 }, { 2, 3, 4 }, { 5, 1, 3 } })
    {
      SCOPED_TRACE(std::string(vtkFFDBuildLattice::GetBasisAsString(basis)) + " " + std::to_string(n[0]) + "x" +
        std::to_string(n[1]) + "x" + std::to_string(n[2]));
      vtkNew<vtkFFDBuildLattice> build;
      build->SetBasis(basis);
      vtkStructuredGrid* lattice = Build(build, MakeVoxelGrid(SkewedFrame, n.data()));
      const int expected[3] = { ExpectedPointsAlongAxis(basis, n[0]), ExpectedPointsAlongAxis(basis, n[1]),
        ExpectedPointsAlongAxis(basis, n[2]) };
      int dims[3];
      lattice->GetDimensions(dims);
      ASSERT_EQ(std::vector<int>(dims, dims + 3), std::vector<int>(expected, expected + 3));
      int whole[6];
      build->GetOutputInformation(0)->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), whole);
      EXPECT_EQ(std::vector<int>(whole, whole + 6),
        (std::vector<int>{ 0, expected[0] - 1, 0, expected[1] - 1, 0, expected[2] - 1 }));
      int storedBasis = -1;
      ASSERT_TRUE(vtkFFDDataContract::GetBasis(lattice, storedBasis));
      EXPECT_EQ(storedBasis, basis);
      vtkDoubleArray* rest = vtkDoubleArray::SafeDownCast(
        lattice->GetPointData()->GetAbstractArray(vtkFFDDataContract::RestPositionArrayName()));
      ASSERT_NE(rest, nullptr);
      // Both sides compute X0 + aS + bT + cU in double with |parameters| <= 2 and coordinates below 10: a few
      // roundings apart, far below 1e-14, while a wrong parameter is off by a spacing (> 0.05 here).
      for (int k = 0; k < expected[2]; ++k)
        for (int j = 0; j < expected[1]; ++j)
          for (int i = 0; i < expected[0]; ++i)
          {
            const vtkIdType id = i + expected[0] * (j + static_cast<vtkIdType>(expected[1]) * k);
            const double a = ExpectedRestParameter(basis, n[0], i), b = ExpectedRestParameter(basis, n[1], j),
                         c = ExpectedRestParameter(basis, n[2], k);
            double x[3], r[3], want[3];
            lattice->GetPoint(id, x);
            rest->GetTuple(id, r);
            for (int d = 0; d < 3; ++d)
            {
              want[d] = SkewedFrame[d] + a * SkewedFrame[3 + d] + b * SkewedFrame[6 + d] + c * SkewedFrame[9 + d];
            }
            ASSERT_TRUE(ffdtest::VectorNear(x, want, 1e-14)) << i << " " << j << " " << k;
            ASSERT_TRUE(ffdtest::VectorEqual(r, x, "rest position component")) << id;
          }
    }
  }
}

TEST(vtkFFDBuildLattice, ActiveIsTheUnionOfTheActiveVoxelsSupports)
{
  // Random sparse patterns (fixed seeds) and the single-voxel cases at a corner and inside, every basis.
  const int n[3] = { 6, 5, 4 };
  std::mt19937 random(20240613);
  // Each pattern with whether it is sparse enough that every local basis must cull some control point.
  std::vector<std::pair<std::function<bool(int, int, int)>, bool>> patterns;
  for (double density : { 0.1, 0.4, 0.8 })
  {
    std::vector<bool> hidden(n[0] * n[1] * n[2]);
    std::bernoulli_distribution isHidden(1.0 - density);
    for (size_t v = 0; v < hidden.size(); ++v)
    {
      hidden[v] = isHidden(random);
    }
    patterns.emplace_back(
      [hidden, n](int i, int j, int k) { return hidden[i + n[0] * (j + n[1] * k)]; }, density < 0.2);
  }
  patterns.emplace_back([](int i, int j, int k) { return i + j + k != 0; }, true);
  patterns.emplace_back([](int i, int j, int k) { return !(i == 3 && j == 2 && k == 1); }, true);
  for (int basis : AllBases)
  {
    for (size_t p = 0; p < patterns.size(); ++p)
    {
      SCOPED_TRACE(std::string(vtkFFDBuildLattice::GetBasisAsString(basis)) + " pattern " + std::to_string(p));
      vtkSmartPointer<vtkStructuredGrid> grid = MakeVoxelGrid(SkewedFrame, n, patterns[p].first);
      vtkNew<vtkFFDBuildLattice> build;
      build->SetBasis(basis);
      vtkStructuredGrid* lattice = Build(build, grid);
      ExpectActiveFromSupports(basis, grid, build, lattice);
      if (basis != vtkFFDBuildLattice::BERNSTEIN && patterns[p].second)
      {
        // A local basis must cull something of a sparse grid.
        EXPECT_LT(build->GetNumberOfActiveControlPoints(), lattice->GetNumberOfPoints());
      }
    }
  }
}

TEST(vtkFFDBuildLattice, CullingOnRealMeshes)
{
  struct Case
  {
    const char* Mesh;
    int Basis;
    int Divisions[3];
  };
  const Case cases[] = { { "bear", vtkFFDBuildLattice::TRILINEAR, { 5, 5, 5 } },
    { "elephant", vtkFFDBuildLattice::TRIQUADRATIC_BEZIER, { 6, 5, 4 } },
    { "elephant", vtkFFDBuildLattice::TRICUBIC_BEZIER, { 5, 6, 7 } },
    { "elephant", vtkFFDBuildLattice::CUBIC_BSPLINE, { 7, 6, 5 } },
    { "elephant", vtkFFDBuildLattice::TRILINEAR, { 8, 8, 8 } } };
  for (const Case& c : cases)
  {
    SCOPED_TRACE(std::string(c.Mesh) + " " + vtkFFDBuildLattice::GetBasisAsString(c.Basis));
    vtkNew<vtkFFDVoxelize> voxelize;
    voxelize->SetInputData(ReadTestMesh(c.Mesh));
    voxelize->SetDivisions(c.Divisions[0], c.Divisions[1], c.Divisions[2]);
    vtkNew<vtkFFDBuildLattice> build;
    build->SetBasis(c.Basis);
    build->SetInputConnection(voxelize->GetOutputPort());
    vtkNew<FFDTestErrorObserver> observer;
    observer->Watch(voxelize->GetExecutive()); // the extent the lattice asks of the voxel grid
    ASSERT_EQ(RunPipeline(build, observer), 1) << observer->Errors;
    EXPECT_EQ(observer->Errors, "");
    vtkStructuredGrid* voxels = voxelize->GetOutput();
    vtkStructuredGrid* lattice = build->GetOutput();
    // A surface mesh leaves voxels empty, so these are real tests of the culling.
    ASSERT_GT(voxelize->GetNumberOfActiveVoxels(), 0);
    ASSERT_LT(voxelize->GetNumberOfActiveVoxels(), c.Divisions[0] * c.Divisions[1] * c.Divisions[2]);
    ExpectActiveFromSupports(c.Basis, voxels, build, lattice);
  }
}

TEST(vtkFFDBuildLattice, FigureCaptionStatisticsOfTheBear)
{
  // The paper's Figure 1: a trilinear (2x2x2 per voxel) lattice of 6x6x6 = 216 control points over 5x5x5 voxels,
  // "85 voxels active or 168 control points". Our bear mesh is not the paper's, so our numbers differ; they
  // must agree with each other: the trilinear active control points are exactly the distinct corners of the
  // active voxels.
  vtkSmartPointer<vtkPolyData> bear = ReadTestMesh("bear");
  vtkNew<vtkFFDVoxelize> voxelize;
  voxelize->SetInputData(bear);
  voxelize->SetDivisions(5, 5, 5);
  for (int basis : AllBases)
  {
    SCOPED_TRACE(vtkFFDBuildLattice::GetBasisAsString(basis));
    vtkNew<vtkFFDBuildLattice> build;
    build->SetBasis(basis);
    build->SetInputConnection(voxelize->GetOutputPort());
    vtkNew<FFDTestErrorObserver> observer;
    observer->Watch(voxelize->GetExecutive());
    ASSERT_EQ(RunPipeline(build, observer), 1) << observer->Errors;
    EXPECT_EQ(observer->Errors, "");
    vtkStructuredGrid* lattice = build->GetOutput();
    int dims[3];
    lattice->GetDimensions(dims);
    std::cout << "bear " << vtkFFDBuildLattice::GetBasisAsString(basis)
              << " 5x5x5 voxels: " << bear->GetNumberOfPoints() << " vertices, " << lattice->GetNumberOfPoints()
              << " control points (" << dims[0] << "x" << dims[1] << "x" << dims[2] << "), "
              << voxelize->GetNumberOfActiveVoxels() << " active voxels, " << build->GetNumberOfActiveControlPoints()
              << " active control points\n";
    if (basis != vtkFFDBuildLattice::TRILINEAR)
    {
      continue;
    }
    EXPECT_EQ(lattice->GetNumberOfPoints(), 216);
    vtkUnsignedCharArray* cellGhosts = voxelize->GetOutput()->GetCellGhostArray();
    ASSERT_NE(cellGhosts, nullptr);
    std::set<std::array<int, 3>> corners;
    vtkIdType activeVoxels = 0;
    for (int k = 0; k < 5; ++k)
      for (int j = 0; j < 5; ++j)
        for (int i = 0; i < 5; ++i)
        {
          if (cellGhosts->GetValue(i + 5 * (j + 5 * k)) & vtkDataSetAttributes::HIDDENCELL)
          {
            continue;
          }
          ++activeVoxels;
          for (int corner = 0; corner < 8; ++corner)
          {
            corners.insert({ i + (corner & 1), j + ((corner >> 1) & 1), k + ((corner >> 2) & 1) });
          }
        }
    EXPECT_EQ(activeVoxels, voxelize->GetNumberOfActiveVoxels());
    EXPECT_EQ(build->GetNumberOfActiveControlPoints(), static_cast<vtkIdType>(corners.size()));
    EXPECT_LT(build->GetNumberOfActiveControlPoints(), 216); // the bear does not fill its box
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

TEST(vtkFFDBuildLattice, UnknownBasisIsAnError)
{
  const int n[3] = { 2, 2, 2 };
  vtkNew<UnknownBasisBuildLattice> build;
  build->ForceBasis(7);
  ExpectFailure(build, MakeVoxelGrid(SkewedFrame, n), { "unknown basis 7", "BERNSTEIN", "CUBIC_BSPLINE" });
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

  // The limit is the global basis's: a local basis takes any number of divisions.
  vtkNew<vtkFFDBuildLattice> local;
  local->SetBasisToCubicBSpline();
  EXPECT_EQ(
    Build(local, MakeVoxelGrid(SkewedFrame, tooMany))->GetNumberOfPoints(), 4 * (ffd::MaxBernsteinDegree + 4) * 4);
}
