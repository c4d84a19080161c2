// SPDX-License-Identifier: BSD-3-Clause
// vtkFFDBuildLattice: the Bernstein rest lattice against equation 1 (ffdref::RestLattice), every basis's
// dimensions and rest positions against the formulas of the paper, culling by support against a brute force
// on hand-made grids and real meshes, the figure-caption statistics, the data contract, and every bad input;
// the sparse form against the dense one (bit for bit) and the supports written from their definitions, its cells
// as VTK evaluates and draws them, its independence of the number of threads, its cost at 1024^3 voxels, and the
// two forms deforming a mesh alike.
#include "vtkFFDBuildLattice.h"

#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkCellType.h"
#include "vtkDataSetAttributes.h"
#include "vtkDataSetSurfaceFilter.h"
#include "vtkDoubleArray.h"
#include "vtkExecutive.h"
#include "vtkFFDDataContract.h"
#include "vtkFFDDeform.h"
#include "vtkFFDVoxelize.h"
#include "vtkFieldData.h"
#include "vtkGenericCell.h"
#include "vtkHigherOrderHexahedron.h"
#include "vtkIdList.h"
#include "vtkInformation.h"
#include "vtkIntArray.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSMPTools.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkStructuredGrid.h"
#include "vtkUnsignedCharArray.h"
#include "vtkUnstructuredGrid.h"

#include "FFDBernstein.h"
#include "FFDReference.h"
#include "FFDTestComparisons.h"
#include "FFDTestErrorObserver.h"
#include "FFDTestMeshes.h"
#include "FFDTestStatistics.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
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
using Index = std::array<int, 3>;

// A skewed parallelepiped away from the origin.
const double SkewedFrame[12] = { -1.5, 2.0, 0.25, 3.0, 0.4, -0.1, 0.5, 2.0, 0.3, -0.2, 0.6, 1.5 };

/// A voxel grid as vtkFFDVoxelize makes it, built by hand: every corner as a point, one hexahedron with its
/// VoxelIndex per voxel for which `hidden(i, j, k)` does not hold (every voxel when `hidden` is empty), in
/// increasing order, or in the order `shuffle` gives them, and the field arrays.
vtkSmartPointer<vtkUnstructuredGrid> MakeVoxelGrid(const double frame[12], const int n[3],
  const std::function<bool(int, int, int)>& hidden = {}, std::mt19937* shuffle = nullptr)
{
  auto grid = vtkSmartPointer<vtkUnstructuredGrid>::New();
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
  std::vector<Index> voxels;
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i)
      {
        if (!hidden || !hidden(i, j, k))
        {
          voxels.push_back({ i, j, k });
        }
      }
  if (shuffle)
  {
    std::shuffle(voxels.begin(), voxels.end(), *shuffle);
  }
  vtkNew<vtkIntArray> index;
  index->SetName(vtkFFDDataContract::VoxelIndexArrayName());
  index->SetNumberOfComponents(3);
  grid->Allocate(static_cast<vtkIdType>(voxels.size()));
  for (const Index& v : voxels)
  {
    const auto corner = [&](int a, int b, int c) -> vtkIdType
    { return v[0] + a + (n[0] + 1) * (v[1] + b + (n[1] + 1) * vtkIdType(v[2] + c)); };
    const vtkIdType ids[8] = { corner(0, 0, 0), corner(1, 0, 0), corner(1, 1, 0), corner(0, 1, 0), corner(0, 0, 1),
      corner(1, 0, 1), corner(1, 1, 1), corner(0, 1, 1) };
    grid->InsertNextCell(VTK_HEXAHEDRON, 8, ids);
    index->InsertNextTypedTuple(v.data());
  }
  grid->GetCellData()->AddArray(index);
  vtkFFDDataContract::SetFrame(grid, frame);
  vtkFFDDataContract::SetDivisions(grid, n);
  return grid;
}

/// The VoxelIndex of every cell of a voxel grid or sparse lattice, in cell order.
std::vector<Index> VoxelsOf(vtkDataSet* grid)
{
  vtkIntArray* index =
    vtkIntArray::SafeDownCast(grid->GetCellData()->GetAbstractArray(vtkFFDDataContract::VoxelIndexArrayName()));
  EXPECT_NE(index, nullptr);
  std::vector<Index> voxels;
  for (vtkIdType c = 0; index && c < index->GetNumberOfTuples(); ++c)
  {
    voxels.push_back({ index->GetValue(3 * c), index->GetValue(3 * c + 1), index->GetValue(3 * c + 2) });
  }
  return voxels;
}

int RunPipeline(vtkFFDBuildLattice* filter, FFDTestErrorObserver* observer)
{
  observer->WatchWithExecutive(filter);
  return filter->GetExecutive()->Update();
}

/// Builds the lattice of `grid` and expects success without any error.
vtkPointSet* Build(vtkFFDBuildLattice* filter, vtkDataObject* grid)
{
  vtkNew<FFDTestErrorObserver> observer;
  filter->SetInputData(grid);
  observer->WatchWithExecutive(filter->GetInputAlgorithm());
  EXPECT_EQ(RunPipeline(filter, observer), 1) << observer->Errors;
  EXPECT_EQ(observer->Errors, "");
  return filter->GetOutput();
}

/// Build() in the dense form: a vtkStructuredGrid.
vtkStructuredGrid* BuildDense(vtkFFDBuildLattice* filter, vtkDataObject* grid)
{
  filter->SetLatticeFormToDense();
  vtkStructuredGrid* lattice = vtkStructuredGrid::SafeDownCast(Build(filter, grid));
  EXPECT_NE(lattice, nullptr);
  return lattice;
}

/// Build() in the sparse form: a vtkUnstructuredGrid.
vtkUnstructuredGrid* BuildSparse(vtkFFDBuildLattice* filter, vtkDataObject* grid)
{
  filter->SetLatticeFormToSparse();
  vtkUnstructuredGrid* lattice = vtkUnstructuredGrid::SafeDownCast(Build(filter, grid));
  EXPECT_NE(lattice, nullptr);
  return lattice;
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

vtkUnsignedCharArray* ActiveArray(vtkPointSet* lattice)
{
  return vtkUnsignedCharArray::SafeDownCast(
    lattice->GetPointData()->GetAbstractArray(vtkFFDDataContract::ActiveArrayName()));
}

const int AllBases[] = { vtkFFDBuildLattice::BERNSTEIN, vtkFFDBuildLattice::TRILINEAR,
  vtkFFDBuildLattice::TRIQUADRATIC_BEZIER, vtkFFDBuildLattice::TRICUBIC_BEZIER, vtkFFDBuildLattice::CUBIC_BSPLINE };
const int LocalBases[] = { vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::TRIQUADRATIC_BEZIER,
  vtkFFDBuildLattice::TRICUBIC_BEZIER, vtkFFDBuildLattice::CUBIC_BSPLINE };

// The formulas below are written out from the issue and the paper (Listings 1 and 2, equation 4, the uniform
// cubic B-spline), independently of Evaluation/Kernels/FFDGridBasis.h.

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
 * with `basis` over `voxels`, a voxel grid of the active voxels) against a brute
 * force: a control point is active when any active voxel lies in its support along all three axes.
 */
void ExpectActiveFromSupports(int basis, vtkDataSet* voxels, vtkFFDBuildLattice* build, vtkStructuredGrid* lattice)
{
  int pd[3];
  lattice->GetDimensions(pd);
  const std::vector<Index> activeVoxels = VoxelsOf(voxels);
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
        for (const Index& v : activeVoxels)
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
  ExpectRecordedCount(lattice, "NumberOfActiveControlPoints", expectedActive);
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
    vtkStructuredGrid* lattice = BuildDense(build, MakeVoxelGrid(SkewedFrame, n.data()));
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
  vtkStructuredGrid* lattice = BuildDense(build, MakeVoxelGrid(SkewedFrame, n));

  int dims[3];
  lattice->GetDimensions(dims);
  EXPECT_EQ(dims[0], 4);
  EXPECT_EQ(dims[1], 5);
  EXPECT_EQ(dims[2], 3);
  // The extent comes with the voxel grid's data (its FFDDivisions): the pipeline announces none before.
  int whole[6];
  build->GetOutputInformation(0)->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), whole);
  EXPECT_EQ(std::vector<int>(whole, whole + 6), (std::vector<int>{ 0, -1, 0, -1, 0, -1 }));
  EXPECT_EQ(std::vector<int>(lattice->GetExtent(), lattice->GetExtent() + 6), (std::vector<int>{ 0, 3, 0, 4, 0, 2 }));
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
    vtkSmartPointer<vtkUnstructuredGrid> grid = oneVoxel
      ? MakeVoxelGrid(SkewedFrame, n, [](int i, int j, int k) { return i + j + k != 0; })
      : MakeVoxelGrid(SkewedFrame, n);
    vtkNew<vtkFFDBuildLattice> build;
    vtkPointSet* lattice = Build(build, grid); // dense: AUTOMATIC's form of the global basis
    ASSERT_TRUE(lattice->IsA("vtkStructuredGrid"));
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
    vtkSmartPointer<vtkUnstructuredGrid> grid = MakeVoxelGrid(SkewedFrame, n, [](int, int, int) { return true; });
    if (basis != vtkFFDBuildLattice::BERNSTEIN)
    {
      // The sparse lattice of no voxel is empty, with the lattice's field arrays.
      vtkUnstructuredGrid* sparse = BuildSparse(build, grid);
      EXPECT_EQ(sparse->GetNumberOfPoints(), 0);
      EXPECT_EQ(sparse->GetNumberOfCells(), 0);
      EXPECT_EQ(build->GetNumberOfActiveControlPoints(), 0);
      int stored = -1;
      EXPECT_TRUE(vtkFFDDataContract::GetBasis(sparse, stored));
    }
    vtkStructuredGrid* lattice = BuildDense(build, grid);
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
      vtkStructuredGrid* lattice = BuildDense(build, MakeVoxelGrid(SkewedFrame, n.data()));
      const int expected[3] = { ExpectedPointsAlongAxis(basis, n[0]), ExpectedPointsAlongAxis(basis, n[1]),
        ExpectedPointsAlongAxis(basis, n[2]) };
      int dims[3];
      lattice->GetDimensions(dims);
      ASSERT_EQ(std::vector<int>(dims, dims + 3), std::vector<int>(expected, expected + 3));
      EXPECT_EQ(std::vector<int>(lattice->GetExtent(), lattice->GetExtent() + 6),
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
      vtkSmartPointer<vtkUnstructuredGrid> grid = MakeVoxelGrid(SkewedFrame, n, patterns[p].first);
      vtkNew<vtkFFDBuildLattice> build;
      build->SetBasis(basis);
      vtkStructuredGrid* lattice = BuildDense(build, grid);
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
    build->SetLatticeFormToDense();
    build->SetInputConnection(voxelize->GetOutputPort());
    vtkNew<FFDTestErrorObserver> observer;
    observer->Watch(voxelize->GetExecutive()); // the request the lattice makes of the voxel grid
    ASSERT_EQ(RunPipeline(build, observer), 1) << observer->Errors;
    EXPECT_EQ(observer->Errors, "");
    vtkUnstructuredGrid* voxels = voxelize->GetOutput();
    vtkStructuredGrid* lattice = build->GetStructuredGridOutput();
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
    build->SetLatticeFormToDense();
    build->SetInputConnection(voxelize->GetOutputPort());
    vtkNew<FFDTestErrorObserver> observer;
    observer->Watch(voxelize->GetExecutive());
    ASSERT_EQ(RunPipeline(build, observer), 1) << observer->Errors;
    EXPECT_EQ(observer->Errors, "");
    vtkStructuredGrid* lattice = build->GetStructuredGridOutput();
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
    std::set<Index> corners;
    const std::vector<Index> voxels = VoxelsOf(voxelize->GetOutput());
    for (const Index& v : voxels)
    {
      for (int corner = 0; corner < 8; ++corner)
      {
        corners.insert({ v[0] + (corner & 1), v[1] + ((corner >> 1) & 1), v[2] + ((corner >> 2) & 1) });
      }
    }
    EXPECT_EQ(static_cast<vtkIdType>(voxels.size()), voxelize->GetNumberOfActiveVoxels());
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

  for (int form : { vtkFFDBuildLattice::DENSE, vtkFFDBuildLattice::SPARSE })
  {
    vtkNew<vtkFFDBuildLattice> direct;
    direct->SetBasisToTrilinear();
    direct->SetLatticeForm(form);
    EXPECT_EQ(Build(direct, vtkSmartPointer<vtkUnstructuredGrid>::New())->GetNumberOfPoints(), 0);
  }
}

TEST(vtkFFDBuildLattice, MissingOrBadContractArraysAreAnError)
{
  const int n[3] = { 2, 2, 2 };
  for (int form : { vtkFFDBuildLattice::DENSE, vtkFFDBuildLattice::SPARSE })
  {
    SCOPED_TRACE(form);
    const auto expectFailure = [form](vtkDataObject* grid, const std::vector<std::string>& messages)
    {
      vtkNew<vtkFFDBuildLattice> build;
      build->SetBasisToTriquadraticBezier();
      build->SetLatticeForm(form);
      ExpectFailure(build, grid, messages);
    };
    {
      vtkSmartPointer<vtkUnstructuredGrid> grid = MakeVoxelGrid(SkewedFrame, n);
      grid->GetFieldData()->RemoveArray(vtkFFDDataContract::FrameArrayName());
      expectFailure(grid, { "FFDFrame", "connect the output of vtkFFDVoxelize" });
    }
    {
      vtkSmartPointer<vtkUnstructuredGrid> grid = MakeVoxelGrid(SkewedFrame, n);
      grid->GetFieldData()->RemoveArray(vtkFFDDataContract::DivisionsArrayName());
      expectFailure(grid, { "FFDDivisions", "connect the output of vtkFFDVoxelize" });
    }
    {
      double nonFinite[12];
      std::copy(SkewedFrame, SkewedFrame + 12, nonFinite);
      nonFinite[7] = std::numeric_limits<double>::quiet_NaN();
      expectFailure(MakeVoxelGrid(nonFinite, n), { "FFDFrame" });
    }
    {
      double flat[12] = { 0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0 };
      vtkSmartPointer<vtkUnstructuredGrid> grid = MakeVoxelGrid(SkewedFrame, n);
      vtkFFDDataContract::SetFrame(grid, flat);
      expectFailure(grid, { "zero volume" });
    }
  }
}

TEST(vtkFFDBuildLattice, MalformedVoxelIndexIsAnError)
{
  const int n[3] = { 3, 2, 4 };
  for (int form : { vtkFFDBuildLattice::DENSE, vtkFFDBuildLattice::SPARSE })
  {
    SCOPED_TRACE(form);
    const auto expectFailure = [form](vtkDataObject* grid, const std::vector<std::string>& messages)
    {
      vtkNew<vtkFFDBuildLattice> build;
      build->SetBasisToCubicBSpline();
      build->SetLatticeForm(form);
      ExpectFailure(build, grid, messages);
    };
    const auto voxelIndex = [](vtkDataSet* grid)
    { return vtkIntArray::SafeDownCast(grid->GetCellData()->GetAbstractArray("VoxelIndex")); };
    {
      vtkSmartPointer<vtkUnstructuredGrid> grid = MakeVoxelGrid(SkewedFrame, n);
      grid->GetCellData()->RemoveArray("VoxelIndex");
      expectFailure(grid, { "no VoxelIndex cell array", "connect the output of vtkFFDVoxelize" });
    }
    {
      // Another type than int, as numpy's default int64 would give.
      vtkSmartPointer<vtkUnstructuredGrid> grid = MakeVoxelGrid(SkewedFrame, n);
      vtkNew<vtkDoubleArray> asDouble;
      asDouble->DeepCopy(voxelIndex(grid));
      asDouble->SetName("VoxelIndex");
      grid->GetCellData()->AddArray(asDouble);
      expectFailure(grid, { "VoxelIndex", "vtkIntArray" });
    }
    {
      // Two components, and one tuple short of the cells.
      vtkSmartPointer<vtkUnstructuredGrid> grid = MakeVoxelGrid(SkewedFrame, n);
      voxelIndex(grid)->SetNumberOfComponents(2);
      expectFailure(grid, { "VoxelIndex", "3 ints" });
      vtkSmartPointer<vtkUnstructuredGrid> shorter = MakeVoxelGrid(SkewedFrame, n);
      voxelIndex(shorter)->SetNumberOfTuples(shorter->GetNumberOfCells() - 1);
      expectFailure(shorter, { "VoxelIndex", "per cell" });
    }
    for (const Index& outside : { Index{ 3, 0, 0 }, Index{ 0, -1, 0 }, Index{ 1, 1, 4 } })
    {
      vtkSmartPointer<vtkUnstructuredGrid> grid = MakeVoxelGrid(SkewedFrame, n);
      voxelIndex(grid)->SetTypedTuple(5, outside.data());
      expectFailure(grid, { "VoxelIndex of cell 5", "lies outside", "(3, 2, 4)" });
    }
    {
      vtkSmartPointer<vtkUnstructuredGrid> grid = MakeVoxelGrid(SkewedFrame, n);
      const Index twice = { 1, 1, 2 };
      voxelIndex(grid)->SetTypedTuple(0, twice.data());
      expectFailure(grid, { "24 cells name only 23 distinct voxels", "one cell" });
    }
  }
}

TEST(vtkFFDBuildLattice, LatticeFormChoosesTheOutput)
{
  vtkNew<vtkFFDBuildLattice> build;
  EXPECT_EQ(build->GetLatticeForm(), vtkFFDBuildLattice::AUTOMATIC);
  EXPECT_STREQ(build->GetLatticeFormAsString(), "Automatic");
  build->SetLatticeFormToDense();
  EXPECT_STREQ(build->GetLatticeFormAsString(), "Dense");
  build->SetLatticeFormToSparse();
  EXPECT_STREQ(build->GetLatticeFormAsString(), "Sparse");
  build->SetLatticeForm(7);
  EXPECT_EQ(build->GetLatticeForm(), vtkFFDBuildLattice::SPARSE);
  build->SetLatticeForm(-1);
  EXPECT_EQ(build->GetLatticeForm(), vtkFFDBuildLattice::AUTOMATIC);

  // AUTOMATIC: sparse for the local bases, dense for the global one; the output object follows the setting.
  const int n[3] = { 2, 3, 2 };
  vtkSmartPointer<vtkUnstructuredGrid> grid = MakeVoxelGrid(SkewedFrame, n);
  for (int basis : AllBases)
  {
    SCOPED_TRACE(vtkFFDBuildLattice::GetBasisAsString(basis));
    build->SetBasis(basis);
    build->SetLatticeFormToAutomatic();
    vtkPointSet* lattice = Build(build, grid);
    EXPECT_STREQ(
      lattice->GetClassName(), basis == vtkFFDBuildLattice::BERNSTEIN ? "vtkStructuredGrid" : "vtkUnstructuredGrid");
    EXPECT_STREQ(BuildDense(build, grid)->GetClassName(), "vtkStructuredGrid");
  }
  // Every control point of the global basis influences every voxel: no sparse form.
  build->SetBasisToBernstein();
  build->SetLatticeFormToSparse();
  ExpectFailure(build, grid, { "SPARSE lattice of the global BERNSTEIN basis", "SetLatticeFormToDense()" });
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
    BuildDense(local, MakeVoxelGrid(SkewedFrame, tooMany))->GetNumberOfPoints(), 4 * (ffd::MaxBernsteinDegree + 4) * 4);
}

//------------------------------------------------------------------------------------------------------------
// The sparse form.
namespace
{
/// The first control point, along an axis, of the support of voxel v, and the support's size: written from the
/// definitions (Bezier of degree p: points p v .. p v + p; cubic B-spline: points v .. v + 3).
int SupportFirst(int basis, int v)
{
  switch (basis)
  {
    case vtkFFDBuildLattice::TRILINEAR:
      return v;
    case vtkFFDBuildLattice::TRIQUADRATIC_BEZIER:
      return 2 * v;
    case vtkFFDBuildLattice::TRICUBIC_BEZIER:
      return 3 * v;
    default: // CUBIC_BSPLINE
      return v;
  }
}

int SupportSize(int basis)
{
  return basis == vtkFFDBuildLattice::TRILINEAR ? 2 : (basis == vtkFFDBuildLattice::TRIQUADRATIC_BEZIER ? 3 : 4);
}

/// VTK_HEXAHEDRON's corners in its order: (0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), then the same at k + 1.
const Index HexCorners[8] = { { 0, 0, 0 }, { 1, 0, 0 }, { 1, 1, 0 }, { 0, 1, 0 }, { 0, 0, 1 }, { 1, 0, 1 }, { 1, 1, 1 },
  { 0, 1, 1 } };

/// The offset (a, b, d) within the support of the point at `place` in a cell of `basis`: VTK's hexahedron order
/// (TRILINEAR), VTK's Bezier hexahedron order (vtkHigherOrderHexahedron::PointIndexFromIJK), tensor order with a
/// fastest (CUBIC_BSPLINE).
Index SupportOffsetAt(int basis, int place)
{
  const int c = SupportSize(basis);
  for (int d = 0; d < c; ++d)
    for (int b = 0; b < c; ++b)
      for (int a = 0; a < c; ++a)
      {
        const int order[3] = { c - 1, c - 1, c - 1 };
        const int at = basis == vtkFFDBuildLattice::TRILINEAR
          ? int(std::find(HexCorners, HexCorners + 8, Index{ a, b, d }) - HexCorners)
          : basis == vtkFFDBuildLattice::CUBIC_BSPLINE ? a + c * (b + c * d)
                                                       : vtkHigherOrderHexahedron::PointIndexFromIJK(a, b, d, order);
        if (at == place)
        {
          return { a, b, d };
        }
      }
  return { -1, -1, -1 };
}

int ExpectedCellType(int basis)
{
  return basis == vtkFFDBuildLattice::TRILINEAR
    ? VTK_HEXAHEDRON
    : (basis == vtkFFDBuildLattice::CUBIC_BSPLINE ? VTK_POLY_VERTEX : VTK_BEZIER_HEXAHEDRON);
}

vtkIntArray* LatticeIndexOf(vtkPointSet* lattice)
{
  return vtkIntArray::SafeDownCast(
    lattice->GetPointData()->GetAbstractArray(vtkFFDDataContract::LatticeIndexArrayName()));
}

/**
 * The sparse lattice against the dense one of the same basis and voxel grid: its points and RestPosition are the
 * dense lattice's active points, bit for bit, in the dense order (increasing i + nI (j + nJ k)), its LatticeIndex
 * their (i, j, k), Active 1 for all; the same field arrays.
 */
void ExpectSparseIsDenseActive(vtkUnstructuredGrid* sparse, vtkStructuredGrid* dense)
{
  int dims[3];
  dense->GetDimensions(dims);
  vtkUnsignedCharArray* denseActive = ActiveArray(dense);
  vtkUnsignedCharArray* sparseActive = ActiveArray(sparse);
  vtkIntArray* index = LatticeIndexOf(sparse);
  vtkDataArray* denseRest = dense->GetPointData()->GetArray(vtkFFDDataContract::RestPositionArrayName());
  vtkDoubleArray* sparseRest =
    vtkDoubleArray::SafeDownCast(sparse->GetPointData()->GetAbstractArray(vtkFFDDataContract::RestPositionArrayName()));
  ASSERT_TRUE(denseActive && sparseActive && index && denseRest && sparseRest);
  ASSERT_EQ(index->GetNumberOfComponents(), 3);
  ASSERT_EQ(sparseRest->GetNumberOfComponents(), 3);
  EXPECT_EQ(sparse->GetPoints()->GetDataType(), VTK_DOUBLE);
  vtkIdType p = 0;
  for (vtkIdType id = 0; id < dense->GetNumberOfPoints(); ++id)
  {
    if (!denseActive->GetValue(id))
    {
      continue;
    }
    ASSERT_LT(p, sparse->GetNumberOfPoints());
    const Index ijk = { int(id % dims[0]), int(id / dims[0] % dims[1]), int(id / dims[0] / dims[1]) };
    const Index got = { index->GetValue(3 * p), index->GetValue(3 * p + 1), index->GetValue(3 * p + 2) };
    ASSERT_EQ(got, ijk) << "point " << p;
    double x[3], y[3], r[3], s[3];
    dense->GetPoint(id, x);
    sparse->GetPoint(p, y);
    denseRest->GetTuple(id, r);
    sparseRest->GetTuple(p, s);
    ASSERT_TRUE(ffdtest::VectorEqual(y, x, "point")) << p;
    ASSERT_TRUE(ffdtest::VectorEqual(s, r, "rest position")) << p;
    ASSERT_EQ(sparseActive->GetValue(p), 1) << p;
    ++p;
  }
  EXPECT_EQ(p, sparse->GetNumberOfPoints());
  double a[12], b[12];
  int na[3], nb[3], ba = -1, bb = -2;
  ASSERT_TRUE(vtkFFDDataContract::GetFrame(sparse, a) && vtkFFDDataContract::GetFrame(dense, b));
  ASSERT_TRUE(vtkFFDDataContract::GetDivisions(sparse, na) && vtkFFDDataContract::GetDivisions(dense, nb));
  ASSERT_TRUE(vtkFFDDataContract::GetBasis(sparse, ba) && vtkFFDDataContract::GetBasis(dense, bb));
  EXPECT_EQ(std::vector<double>(a, a + 12), std::vector<double>(b, b + 12));
  EXPECT_EQ(std::vector<int>(na, na + 3), std::vector<int>(nb, nb + 3));
  EXPECT_EQ(ba, bb);
}

/// Every cell of the sparse lattice is its voxel's (the voxel grid's cell of the same number, its VoxelIndex), of
/// the basis's type and size, and lists exactly the voxel's support, each point at its place in the cell type's
/// order, found through the points' LatticeIndex.
void ExpectCellsListTheirSupports(int basis, vtkDataSet* voxelGrid, vtkUnstructuredGrid* sparse)
{
  const std::vector<Index> voxels = VoxelsOf(voxelGrid);
  EXPECT_EQ(VoxelsOf(sparse), voxels);
  ASSERT_EQ(sparse->GetNumberOfCells(), static_cast<vtkIdType>(voxels.size()));
  vtkIntArray* index = LatticeIndexOf(sparse);
  ASSERT_NE(index, nullptr);
  const int c = SupportSize(basis);
  std::vector<Index> offsets(c * c * c);
  for (int place = 0; place < c * c * c; ++place)
  {
    offsets[place] = SupportOffsetAt(basis, place);
  }
  vtkNew<vtkIdList> ids;
  for (vtkIdType cell = 0; cell < sparse->GetNumberOfCells(); ++cell)
  {
    ASSERT_EQ(sparse->GetCellType(cell), ExpectedCellType(basis)) << cell;
    sparse->GetCellPoints(cell, ids);
    ASSERT_EQ(ids->GetNumberOfIds(), c * c * c) << cell;
    for (int place = 0; place < c * c * c; ++place)
    {
      const vtkIdType id = ids->GetId(place);
      ASSERT_TRUE(id >= 0 && id < sparse->GetNumberOfPoints()) << cell;
      const Index got = { index->GetValue(3 * id), index->GetValue(3 * id + 1), index->GetValue(3 * id + 2) };
      Index want;
      for (int a = 0; a < 3; ++a)
      {
        want[a] = SupportFirst(basis, voxels[cell][a]) + offsets[place][a];
      }
      ASSERT_EQ(got, want) << "cell " << cell << " place " << place;
    }
  }
}

/// The voxel grid of `mesh` at `n` divisions, from vtkFFDVoxelize.
vtkSmartPointer<vtkUnstructuredGrid> Voxelize(vtkPolyData* mesh, const int n[3])
{
  vtkNew<vtkFFDVoxelize> voxelize;
  voxelize->SetInputData(mesh);
  voxelize->SetDivisions(n[0], n[1], n[2]);
  voxelize->Update();
  return voxelize->GetOutput();
}
} // namespace

TEST(vtkFFDBuildLattice, SparseLatticeIsTheDenseLatticesActivePoints)
{
  // Hand-made grids (random patterns, fixed seed, and a shuffled cell order) and the bear's voxel grid.
  const int n[3] = { 6, 5, 4 };
  std::mt19937 random(20240919);
  std::vector<vtkSmartPointer<vtkUnstructuredGrid>> grids;
  for (double density : { 0.05, 0.3, 0.9 })
  {
    std::bernoulli_distribution isHidden(1.0 - density);
    std::vector<bool> hidden(n[0] * n[1] * n[2]);
    for (size_t v = 0; v < hidden.size(); ++v)
    {
      hidden[v] = isHidden(random);
    }
    grids.push_back(MakeVoxelGrid(
      SkewedFrame, n, [&](int i, int j, int k) { return hidden[i + n[0] * (j + n[1] * k)]; },
      density > 0.5 ? &random : nullptr));
  }
  const int bearDivisions[3] = { 13, 11, 17 };
  grids.push_back(Voxelize(ReadTestMesh("bear"), bearDivisions));
  for (int basis : LocalBases)
  {
    for (size_t g = 0; g < grids.size(); ++g)
    {
      SCOPED_TRACE(std::string(vtkFFDBuildLattice::GetBasisAsString(basis)) + " grid " + std::to_string(g));
      vtkNew<vtkFFDBuildLattice> dense, sparse;
      dense->SetBasis(basis);
      sparse->SetBasis(basis);
      vtkStructuredGrid* d = BuildDense(dense, grids[g]);
      vtkUnstructuredGrid* s = BuildSparse(sparse, grids[g]);
      ExpectSparseIsDenseActive(s, d);
      EXPECT_EQ(sparse->GetNumberOfActiveControlPoints(), dense->GetNumberOfActiveControlPoints());
      EXPECT_EQ(sparse->GetNumberOfActiveControlPoints(), s->GetNumberOfPoints());
      ExpectCellsListTheirSupports(basis, grids[g], s);
    }
  }
}

TEST(vtkFFDBuildLattice, SparseCellsAreTheSubRegionsVTKEvaluatesAndDraws)
{
  // At rest every lattice is the identity map: VTK's own evaluation of a Bezier or trilinear cell at parametric
  // coordinates r must give the frame's point at ((v + r) / n), which only the right point order does. And
  // vtkDataSetSurfaceFilter, which VTK's mappers use to draw nonlinear cells, draws the active voxels' boxes.
  const int n[3] = { 4, 3, 5 };
  vtkSmartPointer<vtkUnstructuredGrid> grid =
    MakeVoxelGrid(SkewedFrame, n, [](int i, int j, int k) { return (i + 2 * j + 3 * k) % 4 != 0; });
  const std::vector<Index> voxels = VoxelsOf(grid);
  const double rs[][3] = { { 0.25, 0.5, 0.75 }, { 0.9, 0.1, 0.3 }, { 0.0, 1.0, 0.5 } };
  for (int basis :
    { vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::TRIQUADRATIC_BEZIER, vtkFFDBuildLattice::TRICUBIC_BEZIER })
  {
    SCOPED_TRACE(vtkFFDBuildLattice::GetBasisAsString(basis));
    vtkNew<vtkFFDBuildLattice> build;
    build->SetBasis(basis);
    vtkUnstructuredGrid* lattice = BuildSparse(build, grid);
    vtkNew<vtkGenericCell> cell;
    for (vtkIdType c = 0; c < lattice->GetNumberOfCells(); ++c)
    {
      lattice->GetCell(c, cell);
      for (const double* r : rs)
      {
        double pcoords[3] = { r[0], r[1], r[2] }, x[3], weights[64];
        int subId = 0;
        cell->EvaluateLocation(subId, pcoords, x, weights);
        const double a = (voxels[c][0] + r[0]) / n[0], b = (voxels[c][1] + r[1]) / n[1],
                     e = (voxels[c][2] + r[2]) / n[2];
        double expected[3];
        for (int d = 0; d < 3; ++d)
        {
          expected[d] = SkewedFrame[d] + a * SkewedFrame[3 + d] + b * SkewedFrame[6 + d] + e * SkewedFrame[9 + d];
        }
        // A few roundings of coordinates below 10 (the weights sum to 1 within 1e-15).
        ASSERT_TRUE(ffdtest::VectorNear(x, expected, 1e-13)) << "cell " << c;
      }
    }
    vtkNew<vtkDataSetSurfaceFilter> surface;
    surface->SetInputData(lattice);
    surface->SetNonlinearSubdivisionLevel(2);
    surface->Update();
    vtkPolyData* drawn = surface->GetOutput();
    ASSERT_GT(drawn->GetNumberOfPolys(), 0);
    // The boxes of the active voxels, whose corners are among the lattice's points and hold all the others. The
    // surface's points are floats: coordinates below 10 within 1e-5.
    double got[6], want[6];
    drawn->GetBounds(got);
    lattice->GetPoints()->GetBounds(want);
    for (int b = 0; b < 6; ++b)
    {
      EXPECT_NEAR(got[b], want[b], 1e-5) << b;
    }
  }
}

TEST(vtkFFDBuildLattice, SameSparseLatticeWhateverTheNumberOfThreads)
{
  const int n[3] = { 40, 37, 45 };
  vtkSmartPointer<vtkUnstructuredGrid> grid = Voxelize(ReadTestMesh("bear"), n);
  for (int basis : LocalBases)
  {
    SCOPED_TRACE(vtkFFDBuildLattice::GetBasisAsString(basis));
    std::vector<vtkSmartPointer<vtkUnstructuredGrid>> lattices;
    for (int threads : { 1, 2 })
    {
      vtkSMPTools::Initialize(threads);
      vtkNew<vtkFFDBuildLattice> build;
      build->SetBasis(basis);
      lattices.push_back(BuildSparse(build, grid));
    }
    vtkSMPTools::Initialize(); // back to the default
    for (size_t l = 1; l < lattices.size(); ++l)
    {
      vtkUnstructuredGrid* a = lattices[0];
      vtkUnstructuredGrid* b = lattices[l];
      ASSERT_EQ(b->GetNumberOfPoints(), a->GetNumberOfPoints());
      ASSERT_EQ(b->GetNumberOfCells(), a->GetNumberOfCells());
      for (vtkIdType id = 0; id < a->GetNumberOfPoints(); ++id)
      {
        double x[3], y[3];
        a->GetPoint(id, x);
        b->GetPoint(id, y);
        ASSERT_TRUE(ffdtest::VectorEqual(y, x, "point")) << id;
      }
      vtkNew<vtkIdList> ia, ib;
      for (vtkIdType c = 0; c < a->GetNumberOfCells(); ++c)
      {
        a->GetCellPoints(c, ia);
        b->GetCellPoints(c, ib);
        ASSERT_EQ(ib->GetNumberOfIds(), ia->GetNumberOfIds());
        for (vtkIdType k = 0; k < ia->GetNumberOfIds(); ++k)
        {
          ASSERT_EQ(ib->GetId(k), ia->GetId(k)) << "cell " << c;
        }
      }
    }
  }
}

TEST(vtkFFDBuildLattice, SparseLatticesAt1024CubedCostWhatTheirPointsCost)
{
  // Dense, these lattices would have 1025^3 to 3073^3 control points (50 GB to 1.5 TB); sparse, they hold the
  // supports of the bear's voxels. Checked against the supports written here, and timed.
  const int n[3] = { 1024, 1024, 1024 };
  const auto begin = std::chrono::steady_clock::now();
  vtkSmartPointer<vtkUnstructuredGrid> grid = Voxelize(ReadTestMesh("bear"), n);
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  const vtkIdType voxels = grid->GetNumberOfCells();
  std::cout << "bear at 1024^3: voxelize " << voxels << " active voxels in " << seconds << " s\n";
  ASSERT_GT(voxels, 10000);
  for (int basis : LocalBases)
  {
    SCOPED_TRACE(vtkFFDBuildLattice::GetBasisAsString(basis));
    vtkNew<vtkFFDBuildLattice> build;
    build->SetBasis(basis);
    const auto start = std::chrono::steady_clock::now();
    vtkUnstructuredGrid* lattice = BuildSparse(build, grid);
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    seconds += elapsed;
    const double points = double(lattice->GetNumberOfPoints()), perCell = std::pow(SupportSize(basis), 3);
    const double bytes = 1024.0 * double(lattice->GetActualMemorySize());
    std::cout << "  " << build->GetBasisAsString() << ": " << points << " control points, " << bytes / 1e6 << " MB, "
              << elapsed << " s\n";
    // Per point its position, RestPosition, LatticeIndex and Active (61 bytes); per cell its point ids (32 bits),
    // offset and type, and VoxelIndex (shared with the voxel grid); 64 KB for the fixed parts.
    EXPECT_LE(bytes, 64.0 * points + (4.0 * perCell + 24.0) * double(voxels) + 65536.0);
    EXPECT_LE(points, perCell * double(voxels));
    ExpectCellsListTheirSupports(basis, grid, lattice);
  }
  EXPECT_LT(seconds, 5.0);
}

TEST(vtkFFDBuildLattice, PipelineExecutesOnlyWhenSomethingChanged)
{
  // The dense form announces no extent before it executes: the pipeline must still execute it once per change,
  // and not again, in either form.
  vtkNew<vtkFFDVoxelize> voxelize;
  voxelize->SetInputData(ReadTestMesh("bear"));
  voxelize->SetDivisions(4, 5, 6);
  vtkNew<vtkFFDBuildLattice> build;
  build->SetInputConnection(voxelize->GetOutputPort());
  build->SetBasisToTrilinear();
  for (int form : { vtkFFDBuildLattice::DENSE, vtkFFDBuildLattice::SPARSE, vtkFFDBuildLattice::DENSE })
  {
    SCOPED_TRACE(form);
    build->SetLatticeForm(form);
    vtkNew<FFDTestErrorObserver> observer;
    ASSERT_EQ(RunPipeline(build, observer), 1) << observer->Errors;
    EXPECT_EQ(observer->Errors, "");
    vtkPointSet* first = build->GetOutput();
    EXPECT_STREQ(
      first->GetClassName(), form == vtkFFDBuildLattice::DENSE ? "vtkStructuredGrid" : "vtkUnstructuredGrid");
    const vtkMTimeType executed = first->GetMTime();
    ASSERT_EQ(RunPipeline(build, observer), 1);
    EXPECT_EQ(build->GetOutput()->GetMTime(), executed); // not executed again
    voxelize->SetDivisions(5, 5, 6);
    ASSERT_EQ(RunPipeline(build, observer), 1);
    EXPECT_GT(build->GetOutput()->GetMTime(), executed);
    int divisions[3];
    ASSERT_TRUE(vtkFFDDataContract::GetDivisions(build->GetOutput(), divisions));
    EXPECT_EQ(divisions[0], 5);
    EXPECT_EQ(build->GetOutput()->GetNumberOfPoints() > 0, true);
    voxelize->SetDivisions(4, 5, 6);
  }
}

TEST(vtkFFDBuildLattice, SparseAndDenseLatticesDeformAlike)
{
  // The whole pipeline in either form: both lattices moved by the same function of their rest positions,
  // vtkFFDDeform gives the mesh the same coordinates, bit for bit, from the sparse lattice as from the dense one.
  vtkSmartPointer<vtkPolyData> bear = ReadTestMesh("bear");
  vtkNew<vtkFFDVoxelize> voxelize;
  voxelize->SetInputData(bear);
  voxelize->SetDivisions(6, 5, 7);
  for (int basis : LocalBases)
  {
    SCOPED_TRACE(vtkFFDBuildLattice::GetBasisAsString(basis));
    std::vector<vtkSmartPointer<vtkPointSet>> deformed;
    for (int form : { vtkFFDBuildLattice::DENSE, vtkFFDBuildLattice::SPARSE })
    {
      vtkNew<vtkFFDBuildLattice> build;
      build->SetInputConnection(voxelize->GetOutputPort());
      build->SetBasis(basis);
      build->SetLatticeForm(form);
      build->Update();
      vtkSmartPointer<vtkPointSet> lattice = vtk::TakeSmartPointer(build->GetOutput()->NewInstance());
      lattice->DeepCopy(build->GetOutput());
      vtkDataArray* rest = lattice->GetPointData()->GetArray(vtkFFDDataContract::RestPositionArrayName());
      ASSERT_NE(rest, nullptr);
      for (vtkIdType id = 0; id < lattice->GetNumberOfPoints(); ++id)
      {
        double r[3];
        rest->GetTuple(id, r);
        lattice->GetPoints()->SetPoint(id, r[0] + 0.02 * std::sin(7.0 * r[1]), r[1] + 0.03 * std::cos(5.0 * r[2]),
          r[2] + 0.02 * std::sin(3.0 * r[0]));
      }
      vtkNew<vtkFFDDeform> deform;
      deform->SetInputData(bear);
      deform->SetLatticeData(lattice);
      vtkNew<FFDTestErrorObserver> observer;
      observer->WatchWithExecutive(deform);
      ASSERT_EQ(deform->GetExecutive()->Update(), 1) << observer->Errors;
      deformed.push_back(vtkPointSet::SafeDownCast(deform->GetOutputDataObject(0)));
    }
    ASSERT_EQ(deformed[1]->GetNumberOfPoints(), bear->GetNumberOfPoints());
    double moved = 0.0;
    for (vtkIdType id = 0; id < bear->GetNumberOfPoints(); ++id)
    {
      double x[3], y[3], z[3];
      deformed[0]->GetPoint(id, x);
      deformed[1]->GetPoint(id, y);
      bear->GetPoint(id, z);
      ASSERT_TRUE(ffdtest::VectorEqual(y, x, "deformed point")) << id;
      moved = std::max({ moved, std::fabs(x[0] - z[0]), std::fabs(x[1] - z[1]), std::fabs(x[2] - z[2]) });
    }
    EXPECT_GT(moved, 1e-3); // the lattices really moved the mesh
  }
}
