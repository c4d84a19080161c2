// SPDX-License-Identifier: BSD-3-Clause
// vtkFFDVoxelize: the frame of each mode, the active voxels against an independent brute-force count written
// from the paper's equation 2 (ffdref::Parameters), the sparse output's data contract (cells, corners, order),
// its independence of the number of threads, its cost at 1024^3 divisions, and every bad input.
#include "vtkFFDVoxelize.h"

#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkCellType.h"
#include "vtkDoubleArray.h"
#include "vtkExecutive.h"
#include "vtkFFDDataContract.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkIdList.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkIntArray.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSMPTools.h"
#include "vtkUnstructuredGrid.h"

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
#include <iostream>
#include <limits>
#include <random>
#include <set>
#include <tuple>

namespace
{
using Voxel = std::array<int, 3>;
using ffdref::Vec;

std::vector<Vec> PointsOf(vtkPointSet* data)
{
  std::vector<Vec> xs(data->GetNumberOfPoints());
  for (vtkIdType id = 0; id < data->GetNumberOfPoints(); ++id)
  {
    data->GetPoint(id, xs[id].data());
  }
  return xs;
}

ffdref::Frame FrameOf(vtkDataObject* data)
{
  double f[12];
  EXPECT_TRUE(vtkFFDDataContract::GetFrame(data, f));
  return { { f[0], f[1], f[2] }, { f[3], f[4], f[5] }, { f[6], f[7], f[8] }, { f[9], f[10], f[11] } };
}

/// The voxels holding points, computed independently of the filter from equation 2. The filter's documented
/// rules: a point within 1e-10 (parameter units) of the frame is inside, clamped onto it; a point on a face
/// between two voxels belongs to the higher one, and the upper faces (s = 1) to the last voxel.
std::set<Voxel> BruteForceActiveVoxels(const std::vector<Vec>& xs, const ffdref::Frame& f, const int n[3])
{
  const double tol = 1e-10;
  std::set<Voxel> active;
  for (const Vec& x : xs)
  {
    const Vec p = ffdref::Parameters(f, x);
    Voxel v;
    bool inside = true;
    for (int a = 0; a < 3; ++a)
    {
      inside = inside && p[a] >= -tol && p[a] <= 1 + tol; // false for NaN too
      const double s = std::min(std::max(p[a], 0.0), 1.0);
      v[a] = std::min(static_cast<int>(std::floor(s * n[a])), n[a] - 1);
    }
    if (inside)
    {
      active.insert(v);
    }
  }
  return active;
}

/// The output's voxels, from its VoxelIndex cell array, in cell order.
std::vector<Voxel> VoxelsOf(vtkUnstructuredGrid* grid)
{
  vtkIntArray* index =
    vtkIntArray::SafeDownCast(grid->GetCellData()->GetAbstractArray(vtkFFDDataContract::VoxelIndexArrayName()));
  EXPECT_NE(index, nullptr);
  std::vector<Voxel> voxels;
  if (!index)
  {
    return voxels;
  }
  EXPECT_EQ(index->GetNumberOfComponents(), 3);
  EXPECT_EQ(index->GetNumberOfTuples(), grid->GetNumberOfCells());
  for (vtkIdType c = 0; c < index->GetNumberOfTuples(); ++c)
  {
    voxels.push_back({ index->GetValue(3 * c), index->GetValue(3 * c + 1), index->GetValue(3 * c + 2) });
  }
  return voxels;
}

double Norm(const Vec& v)
{
  return std::sqrt(ffdref::Dot(v, v));
}

/// Whether a comes before b in increasing grid order (i fastest, then j, then k).
bool Before(const Voxel& a, const Voxel& b)
{
  return std::make_tuple(a[2], a[1], a[0]) < std::make_tuple(b[2], b[1], b[0]);
}

/// The output's voxels as a set, after checking that they come in increasing order, which also means each once.
std::set<Voxel> ActiveVoxels(vtkUnstructuredGrid* grid)
{
  const std::vector<Voxel> voxels = VoxelsOf(grid);
  for (size_t c = 1; c < voxels.size(); ++c)
  {
    EXPECT_TRUE(Before(voxels[c - 1], voxels[c])) << "cell " << c;
  }
  return std::set<Voxel>(voxels.begin(), voxels.end());
}

/// VTK_HEXAHEDRON's corners in its order: (0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), then the same at k + 1.
const int HexCorners[8][3] = { { 0, 0, 0 }, { 1, 0, 0 }, { 1, 1, 0 }, { 0, 1, 0 }, { 0, 0, 1 }, { 1, 0, 1 },
  { 1, 1, 1 }, { 0, 1, 1 } };

/**
 * Checks the voxel grid's cells and points against the data contract, from its definitions: every cell a
 * VTK_HEXAHEDRON whose m-th point is its voxel's corner HexCorners[m]; every point the corner of some cell and
 * of one only, at X0 + (i/nx) S + (j/ny) T + (k/nz) U; the points in increasing corner order (so no corner twice);
 * as many points as the active voxels have distinct corners.
 */
void ExpectCellsOnTheirCorners(vtkUnstructuredGrid* out, const int n[3])
{
  const std::vector<Voxel> voxels = VoxelsOf(out);
  const vtkIdType numPoints = out->GetNumberOfPoints();
  ASSERT_EQ(out->GetPoints()->GetDataType(), VTK_DOUBLE);
  std::vector<Voxel> cornerOfPoint(numPoints, Voxel{ -1, -1, -1 });
  std::set<Voxel> corners;
  vtkNew<vtkIdList> ids;
  for (vtkIdType c = 0; c < out->GetNumberOfCells(); ++c)
  {
    ASSERT_EQ(out->GetCellType(c), VTK_HEXAHEDRON) << c;
    out->GetCellPoints(c, ids);
    ASSERT_EQ(ids->GetNumberOfIds(), 8) << c;
    for (int m = 0; m < 8; ++m)
    {
      const Voxel corner = { voxels[c][0] + HexCorners[m][0], voxels[c][1] + HexCorners[m][1],
        voxels[c][2] + HexCorners[m][2] };
      corners.insert(corner);
      const vtkIdType id = ids->GetId(m);
      ASSERT_TRUE(id >= 0 && id < numPoints) << "cell " << c << " names point " << id;
      if (cornerOfPoint[id][0] < 0)
      {
        cornerOfPoint[id] = corner;
      }
      ASSERT_EQ(cornerOfPoint[id], corner) << "point " << id << " is two corners";
    }
  }
  EXPECT_EQ(static_cast<vtkIdType>(corners.size()), numPoints);
  // A few roundings apart: X0 + aS + bT + cU from the same doubles.
  const ffdref::Frame f = FrameOf(out);
  const double scale = Norm(f.X0) + Norm(f.S) + Norm(f.T) + Norm(f.U);
  for (vtkIdType id = 0; id < numPoints; ++id)
  {
    const Voxel& c = cornerOfPoint[id];
    ASSERT_GE(c[0], 0) << "point " << id << " is no cell's corner";
    if (id > 0)
    {
      ASSERT_TRUE(Before(cornerOfPoint[id - 1], c)) << "points " << id - 1 << " and " << id;
    }
    const double a = double(c[0]) / n[0], b = double(c[1]) / n[1], d = double(c[2]) / n[2];
    const Vec expected = { f.X0[0] + a * f.S[0] + b * f.T[0] + d * f.U[0],
      f.X0[1] + a * f.S[1] + b * f.T[1] + d * f.U[1], f.X0[2] + a * f.S[2] + b * f.T[2] + d * f.U[2] };
    double x[3];
    out->GetPoint(id, x);
    ASSERT_TRUE(ffdtest::VectorNear(x, expected, 1e-15 * scale)) << id;
  }
}

/// Runs the filter's pipeline; returns the executive's result with errors captured in `observer`.
int RunPipeline(vtkFFDVoxelize* filter, FFDTestErrorObserver* observer)
{
  observer->WatchWithExecutive(filter);
  return filter->GetExecutive()->Update();
}

/// Voxelizes `input` and checks the active voxels against the brute force on the output's own frame.
void ExpectActiveVoxelsMatchBruteForce(vtkPointSet* input, vtkFFDVoxelize* filter)
{
  vtkNew<FFDTestErrorObserver> observer;
  filter->SetInputData(input);
  ASSERT_EQ(RunPipeline(filter, observer), 1) << observer->Errors;
  EXPECT_EQ(observer->Errors, "");
  vtkUnstructuredGrid* out = filter->GetOutput();
  const int* n = filter->GetDivisions();
  const std::set<Voxel> expected = BruteForceActiveVoxels(PointsOf(input), FrameOf(out), n);
  EXPECT_FALSE(expected.empty());
  EXPECT_EQ(ActiveVoxels(out), expected);
  EXPECT_EQ(filter->GetNumberOfActiveVoxels(), static_cast<vtkIdType>(expected.size()));
  ExpectRecordedCount(out, "NumberOfActiveVoxels", static_cast<vtkIdType>(expected.size()));
  ExpectCellsOnTheirCorners(out, n);
}

/// Rotation R = Rz(c) Ry(b) Rx(a), columns = images of the unit axes.
std::array<Vec, 3> Rotation(double a, double b, double c)
{
  const double ca = std::cos(a), sa = std::sin(a), cb = std::cos(b), sb = std::sin(b), cc = std::cos(c),
               sc = std::sin(c);
  const double m[3][3] = { { cc * cb, cc * sb * sa - sc * ca, cc * sb * ca + sc * sa },
    { sc * cb, sc * sb * sa + cc * ca, sc * sb * ca - cc * sa }, { -sb, cb * sa, cb * ca } };
  return { Vec{ m[0][0], m[1][0], m[2][0] }, Vec{ m[0][1], m[1][1], m[2][1] }, Vec{ m[0][2], m[1][2], m[2][2] } };
}
} // namespace

TEST(vtkFFDVoxelize, ActiveVoxelsOfRealMeshesMatchBruteForce)
{
  for (const char* name : { "bear", "elephant" })
  {
    SCOPED_TRACE(name);
    vtkSmartPointer<vtkPolyData> mesh = ReadTestMesh(name);
    for (int mode : { vtkFFDVoxelize::AXIS_ALIGNED, vtkFFDVoxelize::PRINCIPAL_AXES })
    {
      SCOPED_TRACE(mode);
      for (const Voxel& n : { Voxel{ 4, 4, 4 }, Voxel{ 7, 11, 5 }, Voxel{ 40, 33, 29 } })
      {
        vtkNew<vtkFFDVoxelize> voxelize;
        voxelize->SetFrameMode(mode);
        voxelize->SetDivisions(n[0], n[1], n[2]);
        ExpectActiveVoxelsMatchBruteForce(mesh, voxelize);
      }
    }
  }
}

TEST(vtkFFDVoxelize, FloatAndDoublePointsGiveTheSameVoxels)
{
  vtkSmartPointer<vtkPolyData> mesh = ReadTestMesh("elephant");
  vtkNew<vtkPolyData> asFloat, asDouble;
  for (auto [copy, type] : { std::make_pair(asFloat.Get(), VTK_FLOAT), std::make_pair(asDouble.Get(), VTK_DOUBLE) })
  {
    vtkNew<vtkPoints> points;
    points->SetDataType(type);
    points->DeepCopy(mesh->GetPoints()); // keeps `type`: DeepCopy converts the values
    copy->SetPoints(points);
  }
  ASSERT_EQ(asFloat->GetPoints()->GetDataType(), VTK_FLOAT);
  ASSERT_EQ(asDouble->GetPoints()->GetDataType(), VTK_DOUBLE);
  vtkNew<vtkFFDVoxelize> a, b;
  a->SetDivisions(9, 8, 7);
  b->SetDivisions(9, 8, 7);
  ExpectActiveVoxelsMatchBruteForce(asFloat, a);
  ExpectActiveVoxelsMatchBruteForce(asDouble, b);
  EXPECT_EQ(ActiveVoxels(a->GetOutput()), ActiveVoxels(b->GetOutput()));
}

TEST(vtkFFDVoxelize, AxisAlignedFrameIsThePaddedBounds)
{
  vtkSmartPointer<vtkPolyData> mesh = ReadTestMesh("bear");
  const std::vector<Vec> xs = PointsOf(mesh);
  Vec lo = xs[0], hi = xs[0];
  for (const Vec& x : xs)
    for (int c = 0; c < 3; ++c)
    {
      lo[c] = std::min(lo[c], x[c]);
      hi[c] = std::max(hi[c], x[c]);
    }
  const double largest = std::max({ hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2] });

  for (double padding : { 0.0, 0.05, 0.3 })
  {
    SCOPED_TRACE(padding);
    vtkNew<vtkFFDVoxelize> voxelize;
    voxelize->SetInputData(mesh);
    voxelize->SetPadding(padding);
    voxelize->Update();
    const ffdref::Frame f = FrameOf(voxelize->GetOutput());
    const double pad = padding * largest;
    // The frame is a few additions away from the bounds: 1e-12 of the mesh size is far above rounding.
    const double tol = 1e-12 * largest;
    const Vec size = { hi[0] - lo[0] + 2 * pad, hi[1] - lo[1] + 2 * pad, hi[2] - lo[2] + 2 * pad };
    const ffdref::Frame box = { { lo[0] - pad, lo[1] - pad, lo[2] - pad }, { size[0], 0.0, 0.0 }, { 0.0, size[1], 0.0 },
      { 0.0, 0.0, size[2] } };
    EXPECT_TRUE(ffdtest::FramesNear(f, box, tol));
    for (const Vec& x : xs)
    {
      const Vec p = ffdref::Parameters(f, x);
      for (int a = 0; a < 3; ++a)
      {
        ASSERT_GE(p[a], 0.0 - 1e-12);
        ASSERT_LE(p[a], 1.0 + 1e-12);
      }
    }
  }
}

TEST(vtkFFDVoxelize, PrincipalAxesFollowARotatedElongatedCloud)
{
  // A box-shaped cloud with half-extents 10 : 3 : 1, rotated by a known rotation and moved.
  std::mt19937 rng(20240501);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const std::array<Vec, 3> r = Rotation(0.7, -0.4, 1.1);
  const Vec center = { 5.0, -2.0, 3.0 };
  const double half[3] = { 10.0, 3.0, 1.0 };
  std::vector<Vec> xs(5000);
  for (Vec& x : xs)
  {
    x = center;
    for (int a = 0; a < 3; ++a)
    {
      const double w = half[a] * unit(rng);
      for (int c = 0; c < 3; ++c)
      {
        x[c] += w * r[a][c];
      }
    }
  }
  vtkSmartPointer<vtkPolyData> cloud = PointCloud(xs);

  for (double padding : { 0.0, 0.1 })
  {
    SCOPED_TRACE(padding);
    vtkNew<vtkFFDVoxelize> voxelize;
    voxelize->SetInputData(cloud);
    voxelize->SetFrameModeToPrincipalAxes();
    voxelize->SetPadding(padding);
    voxelize->SetDivisions(6, 5, 3);
    ExpectActiveVoxelsMatchBruteForce(cloud, voxelize);
    const ffdref::Frame f = FrameOf(voxelize->GetOutput());
    const Vec* edges[3] = { &f.S, &f.T, &f.U };

    // Orthogonal and right-handed.
    EXPECT_NEAR(ffdref::Dot(f.S, f.T), 0.0, 1e-12 * Norm(f.S) * Norm(f.T));
    EXPECT_NEAR(ffdref::Dot(f.S, f.U), 0.0, 1e-12 * Norm(f.S) * Norm(f.U));
    EXPECT_NEAR(ffdref::Dot(f.T, f.U), 0.0, 1e-12 * Norm(f.T) * Norm(f.U));
    EXPECT_GT(ffdref::Dot(ffdref::Cross(f.S, f.T), f.U), 0.0);
    // S along the long direction, T the middle one. 5000 samples estimate the axes to well within 1 degree.
    for (int a = 0; a < 3; ++a)
    {
      EXPECT_GT(std::fabs(ffdref::Dot(*edges[a], r[a])) / Norm(*edges[a]), std::cos(M_PI / 180.0)) << a;
    }
    EXPECT_GT(Norm(f.S), Norm(f.T));
    EXPECT_GT(Norm(f.T), Norm(f.U));

    // Every point inside; without padding the box is tight (a point within 1e-3 of each face), with padding
    // every point is at least pad / (extent + 2 pad) from each face.
    Vec lo = { 1, 1, 1 }, hi = { 0, 0, 0 };
    for (const Vec& x : xs)
    {
      const Vec p = ffdref::Parameters(f, x);
      for (int a = 0; a < 3; ++a)
      {
        lo[a] = std::min(lo[a], p[a]);
        hi[a] = std::max(hi[a], p[a]);
      }
    }
    const double largest = Norm(f.S) / (1.0 + 2.0 * padding); // S is the longest edge of the tight box
    for (int a = 0; a < 3; ++a)
    {
      const double margin = padding * largest / Norm(*edges[a]);
      EXPECT_NEAR(lo[a], margin, 1e-12) << a;
      EXPECT_NEAR(hi[a], 1.0 - margin, 1e-12) << a;
    }
  }
}

TEST(vtkFFDVoxelize, ExplicitFrameIgnoresPointsOutside)
{
  // A skewed parallelepiped and random points around it, many of them outside.
  const double origin[3] = { -1.0, 0.5, 2.0 }, s[3] = { 3.0, 0.4, 0.0 }, t[3] = { 0.5, 2.0, 0.3 },
               u[3] = { -0.2, 0.6, 1.5 };
  const ffdref::Frame f = { { origin[0], origin[1], origin[2] }, { s[0], s[1], s[2] }, { t[0], t[1], t[2] },
    { u[0], u[1], u[2] } };
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> param(-0.3, 1.3);
  std::vector<Vec> xs(4000);
  size_t outside = 0;
  for (Vec& x : xs)
  {
    const double a = param(rng), b = param(rng), c = param(rng);
    for (int k = 0; k < 3; ++k)
    {
      x[k] = origin[k] + a * s[k] + b * t[k] + c * u[k];
    }
    outside += (a < 0 || a > 1 || b < 0 || b > 1 || c < 0 || c > 1) ? 1 : 0;
  }
  ASSERT_GT(outside, xs.size() / 4);
  vtkSmartPointer<vtkPolyData> cloud = PointCloud(xs);
  vtkNew<vtkFFDVoxelize> voxelize;
  voxelize->SetFrameModeToExplicit();
  voxelize->SetFrame(origin, s, t, u);
  voxelize->SetDivisions(5, 3, 4);
  ExpectActiveVoxelsMatchBruteForce(cloud, voxelize);
  EXPECT_TRUE(ffdtest::FramesEqual(FrameOf(voxelize->GetOutput()), f));
}

TEST(vtkFFDVoxelize, SetFrameSelectsTheExplicitMode)
{
  // SetFrame() alone gives that frame (it was ignored until SetFrameModeToExplicit()); the part setters only
  // store their vectors, and the automatic mode chosen after them is used.
  vtkSmartPointer<vtkPolyData> cloud = PointCloud({ { 0, 0, 0 }, { 1, 1, 1 } });
  const double origin[3] = { -1.0, 0.5, 2.0 }, s[3] = { 3.0, 0.4, 0.0 }, t[3] = { 0.5, 2.0, 0.3 },
               u[3] = { -0.2, 0.6, 1.5 };
  vtkNew<vtkFFDVoxelize> voxelize;
  voxelize->SetInputData(cloud);
  voxelize->SetFrame(origin, s, t, u);
  EXPECT_EQ(voxelize->GetFrameMode(), vtkFFDVoxelize::EXPLICIT);
  voxelize->Update();
  const ffdref::Frame f = { { origin[0], origin[1], origin[2] }, { s[0], s[1], s[2] }, { t[0], t[1], t[2] },
    { u[0], u[1], u[2] } };
  EXPECT_TRUE(ffdtest::FramesEqual(FrameOf(voxelize->GetOutput()), f));
  voxelize->SetFrameModeToAxisAligned();
  voxelize->SetFrameOrigin(5.0, 5.0, 5.0);
  EXPECT_EQ(voxelize->GetFrameMode(), vtkFFDVoxelize::AXIS_ALIGNED);
  voxelize->Update();
  EXPECT_LT(FrameOf(voxelize->GetOutput()).X0[0], 0.0); // the padded bounds of the cloud
}

TEST(vtkFFDVoxelize, PointsOnFacesGoToTheHigherVoxel)
{
  const double origin[3] = { 0, 0, 0 }, s[3] = { 2, 0, 0 }, t[3] = { 0, 2, 0 }, u[3] = { 0, 0, 2 };
  // On the upper corner, on the interior face s = 1/2, on the origin, and two points just outside.
  vtkSmartPointer<vtkPolyData> cloud =
    PointCloud({ { 2, 2, 2 }, { 1, 0, 0 }, { 0, 0, 0 }, { 2.5, 1, 1 }, { 1, -0.1, 1 } });
  vtkNew<vtkFFDVoxelize> voxelize;
  voxelize->SetFrameModeToExplicit();
  voxelize->SetFrame(origin, s, t, u);
  voxelize->SetDivisions(2, 2, 2);
  ExpectActiveVoxelsMatchBruteForce(cloud, voxelize);
  EXPECT_EQ(ActiveVoxels(voxelize->GetOutput()), (std::set<Voxel>{ { 1, 1, 1 }, { 1, 0, 0 }, { 0, 0, 0 } }));
}

TEST(vtkFFDVoxelize, OutputFollowsTheDataContract)
{
  vtkSmartPointer<vtkPolyData> mesh = ReadTestMesh("elephant");
  vtkNew<vtkFFDVoxelize> voxelize;
  voxelize->SetInputData(mesh);
  voxelize->SetFrameModeToPrincipalAxes();
  voxelize->SetDivisions(3, 5, 2);
  voxelize->Update();
  vtkUnstructuredGrid* out = voxelize->GetOutput();

  EXPECT_GT(out->GetNumberOfCells(), 0);
  EXPECT_LT(out->GetNumberOfCells(), 30); // the elephant leaves voxels empty
  EXPECT_EQ(out->GetNumberOfCells(), voxelize->GetNumberOfActiveVoxels());
  EXPECT_NE(vtkIntArray::SafeDownCast(out->GetCellData()->GetAbstractArray(vtkFFDDataContract::VoxelIndexArrayName())),
    nullptr);
  EXPECT_FALSE(out->GetCells()->IsStorage64Bit()); // ids that fit 32 bits are stored in 32 bits
  vtkIntArray* divisions =
    vtkIntArray::SafeDownCast(out->GetFieldData()->GetAbstractArray(vtkFFDDataContract::DivisionsArrayName()));
  ASSERT_NE(divisions, nullptr);
  ASSERT_EQ(divisions->GetNumberOfValues(), 3);
  EXPECT_EQ(divisions->GetValue(0), 3);
  EXPECT_EQ(divisions->GetValue(1), 5);
  EXPECT_EQ(divisions->GetValue(2), 2);
  vtkDoubleArray* frame =
    vtkDoubleArray::SafeDownCast(out->GetFieldData()->GetAbstractArray(vtkFFDDataContract::FrameArrayName()));
  ASSERT_NE(frame, nullptr);
  ASSERT_EQ(frame->GetNumberOfValues(), 12);
  ExpectCellsOnTheirCorners(out, voxelize->GetDivisions());
}

TEST(vtkFFDVoxelize, RandomPointsAtFineDivisionsMatchBruteForce)
{
  // Points spread over a skewed frame and around it, at divisions where most voxels hold one point or none.
  const double origin[3] = { 0.5, -1.0, 2.0 }, s[3] = { 2.0, 0.3, -0.1 }, t[3] = { -0.4, 1.5, 0.2 },
               u[3] = { 0.1, 0.5, 1.2 };
  std::mt19937 rng(20240917);
  std::uniform_real_distribution<double> param(-0.05, 1.05);
  std::vector<Vec> xs(20000);
  for (Vec& x : xs)
  {
    const double a = param(rng), b = param(rng), c = param(rng);
    for (int k = 0; k < 3; ++k)
    {
      x[k] = origin[k] + a * s[k] + b * t[k] + c * u[k];
    }
  }
  vtkSmartPointer<vtkPolyData> cloud = PointCloud(xs);
  vtkNew<vtkFFDVoxelize> voxelize;
  voxelize->SetFrame(origin, s, t, u);
  voxelize->SetDivisions(300, 170, 233);
  ExpectActiveVoxelsMatchBruteForce(cloud, voxelize);
  EXPECT_GT(voxelize->GetNumberOfActiveVoxels(), 15000); // few points share a voxel: a real test of the order
}

TEST(vtkFFDVoxelize, SameOutputWhateverTheNumberOfThreads)
{
  // The bear at fine divisions and a random cloud: the active sets are merged from per-thread grids, the corners
  // and cells found by sorting and searching; the output must not depend on how the points were shared out.
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Vec> xs(30000);
  for (Vec& x : xs)
  {
    x = { unit(rng), unit(rng), unit(rng) };
  }
  for (vtkSmartPointer<vtkPolyData> input : { ReadTestMesh("bear"), PointCloud(xs) })
  {
    std::vector<vtkSmartPointer<vtkUnstructuredGrid>> outputs;
    for (int threads : { 1, 2 })
    {
      vtkSMPTools::Initialize(threads);
      vtkNew<vtkFFDVoxelize> voxelize;
      voxelize->SetInputData(input);
      voxelize->SetDivisions(97, 89, 101);
      voxelize->Update();
      outputs.push_back(voxelize->GetOutput());
    }
    vtkSMPTools::Initialize(); // back to the default
    vtkUnstructuredGrid* one = outputs[0];
    ASSERT_GT(one->GetNumberOfCells(), 1000);
    for (size_t o = 1; o < outputs.size(); ++o)
    {
      vtkUnstructuredGrid* other = outputs[o];
      ASSERT_EQ(other->GetNumberOfPoints(), one->GetNumberOfPoints());
      ASSERT_EQ(other->GetNumberOfCells(), one->GetNumberOfCells());
      EXPECT_EQ(VoxelsOf(other), VoxelsOf(one));
      for (vtkIdType id = 0; id < one->GetNumberOfPoints(); ++id)
      {
        double a[3], b[3];
        one->GetPoint(id, a);
        other->GetPoint(id, b);
        ASSERT_TRUE(ffdtest::VectorEqual(b, a, "corner")) << id;
      }
      vtkNew<vtkIdList> a, b;
      for (vtkIdType c = 0; c < one->GetNumberOfCells(); ++c)
      {
        one->GetCellPoints(c, a);
        other->GetCellPoints(c, b);
        for (vtkIdType k = 0; k < 8; ++k)
        {
          ASSERT_EQ(b->GetId(k), a->GetId(k)) << "cell " << c;
        }
      }
    }
  }
}

TEST(vtkFFDVoxelize, DivisionsOf1024CubedCostWhatTheActiveVoxelsCost)
{
  // A dense grid of 1024^3 voxels would need 1025^3 corners, 25 GB; the sparse one holds the bear's voxels.
  vtkSmartPointer<vtkPolyData> bear = ReadTestMesh("bear");
  vtkNew<vtkFFDVoxelize> voxelize;
  voxelize->SetDivisions(1024, 1024, 1024);
  const auto begin = std::chrono::steady_clock::now();
  ExpectActiveVoxelsMatchBruteForce(bear, voxelize);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  vtkUnstructuredGrid* out = voxelize->GetOutput();
  const double voxels = double(out->GetNumberOfCells()), corners = double(out->GetNumberOfPoints());
  const double bytes = 1024.0 * double(out->GetActualMemorySize());
  std::cout << "bear at 1024^3: " << voxels << " active voxels, " << corners << " corners, " << bytes / 1e6 << " MB, "
            << seconds << " s with the brute-force check\n";
  // Per voxel its VoxelIndex (12 bytes), 8 point ids, an offset and a type (37 in 32 bits); 24 bytes a corner;
  // at most 8 corners a voxel. 64 KB for the arrays' and the field data's fixed parts.
  EXPECT_LE(corners, 8.0 * voxels);
  EXPECT_LE(bytes, 64.0 * voxels + 32.0 * corners + 65536.0);
  EXPECT_LT(seconds, 5.0);
}

TEST(vtkFFDVoxelize, NoActiveVoxelGivesAGridWithItsFrameOnly)
{
  // Every point outside the explicit frame: no cell, no point, but the frame and divisions for the lattice.
  vtkSmartPointer<vtkPolyData> cloud = PointCloud({ { 5, 5, 5 }, { 6, 6, 6 } });
  const double o[3] = { 0, 0, 0 }, s[3] = { 1, 0, 0 }, t[3] = { 0, 1, 0 }, u[3] = { 0, 0, 1 };
  vtkNew<vtkFFDVoxelize> voxelize;
  voxelize->SetInputData(cloud);
  voxelize->SetFrame(o, s, t, u);
  vtkNew<FFDTestErrorObserver> observer;
  EXPECT_EQ(RunPipeline(voxelize, observer), 1);
  EXPECT_EQ(observer->Errors, "");
  vtkUnstructuredGrid* out = voxelize->GetOutput();
  EXPECT_EQ(out->GetNumberOfCells(), 0);
  EXPECT_EQ(out->GetNumberOfPoints(), 0);
  EXPECT_EQ(voxelize->GetNumberOfActiveVoxels(), 0);
  int divisions[3];
  EXPECT_TRUE(vtkFFDDataContract::GetDivisions(out, divisions));
  const ffdref::Frame unit = { { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 } };
  EXPECT_TRUE(ffdtest::FramesEqual(FrameOf(out), unit));
}

TEST(vtkFFDVoxelize, NonFinitePointsAreIgnored)
{
  vtkSmartPointer<vtkPolyData> mesh = ReadTestMesh("elephant");
  std::vector<Vec> xs = PointsOf(mesh);
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  std::vector<Vec> polluted = xs;
  polluted.insert(polluted.begin() + 100, { nan, 0.0, 0.0 });
  polluted.push_back({ inf, -inf, 1.0 });
  polluted.push_back({ 0.0, 0.0, -inf });

  for (int mode : { vtkFFDVoxelize::AXIS_ALIGNED, vtkFFDVoxelize::PRINCIPAL_AXES })
  {
    SCOPED_TRACE(mode);
    vtkNew<vtkFFDVoxelize> clean, dirty;
    clean->SetFrameMode(mode);
    dirty->SetFrameMode(mode);
    clean->SetDivisions(8, 6, 7);
    dirty->SetDivisions(8, 6, 7);
    vtkSmartPointer<vtkPolyData> cleanCloud = PointCloud(xs), dirtyCloud = PointCloud(polluted);
    ExpectActiveVoxelsMatchBruteForce(cleanCloud, clean);
    ExpectActiveVoxelsMatchBruteForce(dirtyCloud, dirty);
    // Same frame (the same finite points in the same order give the same sums), same voxels.
    double a[12], b[12];
    ASSERT_TRUE(vtkFFDDataContract::GetFrame(clean->GetOutput(), a));
    ASSERT_TRUE(vtkFFDDataContract::GetFrame(dirty->GetOutput(), b));
    EXPECT_EQ(std::vector<double>(a, a + 12), std::vector<double>(b, b + 12));
    EXPECT_EQ(clean->GetNumberOfActiveVoxels(), dirty->GetNumberOfActiveVoxels());
  }
}

TEST(vtkFFDVoxelize, EmptyInputGivesEmptyOutput)
{
  vtkNew<vtkPolyData> empty;
  vtkNew<vtkFFDVoxelize> voxelize;
  voxelize->SetInputData(empty);
  vtkNew<FFDTestErrorObserver> observer;
  EXPECT_EQ(RunPipeline(voxelize, observer), 1);
  EXPECT_EQ(observer->Errors, "");
  EXPECT_EQ(voxelize->GetOutput()->GetNumberOfPoints(), 0);
  EXPECT_EQ(voxelize->GetNumberOfActiveVoxels(), 0);
}

namespace
{
/// Expects the filter to fail on `input` with an error containing `message`.
void ExpectFailure(vtkFFDVoxelize* voxelize, vtkPointSet* input, const std::string& message)
{
  vtkNew<FFDTestErrorObserver> observer;
  voxelize->SetInputData(input);
  EXPECT_EQ(RunPipeline(voxelize, observer), 0);
  EXPECT_NE(observer->Errors.find(message), std::string::npos) << observer->Errors;
  EXPECT_EQ(voxelize->GetNumberOfActiveVoxels(), 0);
}
} // namespace

TEST(vtkFFDVoxelize, DivisionsBelowOneAreAnError)
{
  vtkSmartPointer<vtkPolyData> cloud = PointCloud({ { 0, 0, 0 }, { 1, 1, 1 } });
  for (const Voxel& n : { Voxel{ 0, 4, 4 }, Voxel{ 4, -1, 4 }, Voxel{ 4, 4, 0 } })
  {
    vtkNew<vtkFFDVoxelize> voxelize;
    voxelize->SetDivisions(n[0], n[1], n[2]);
    ExpectFailure(voxelize, cloud, "must be at least 1");
  }
}

namespace
{
/// vtkFFDVoxelize with RequestData callable alone: ParaView's executive still calls RequestData after
/// RequestInformation failed, so RequestData must check the settings it computes with.
class VoxelizeRequestDataOnly : public vtkFFDVoxelize
{
public:
  static VoxelizeRequestDataOnly* New();
  vtkTypeMacro(VoxelizeRequestDataOnly, vtkFFDVoxelize);

  int Run(vtkPointSet* input, vtkUnstructuredGrid* output)
  {
    vtkNew<vtkInformation> inputInfo, outputInfo;
    inputInfo->Set(vtkDataObject::DATA_OBJECT(), input);
    outputInfo->Set(vtkDataObject::DATA_OBJECT(), output);
    vtkNew<vtkInformationVector> inputs, outputs;
    inputs->Append(inputInfo);
    outputs->Append(outputInfo);
    vtkInformationVector* inputPorts[1] = { inputs };
    return this->RequestData(nullptr, inputPorts, outputs);
  }
};
vtkStandardNewMacro(VoxelizeRequestDataOnly);
} // namespace

TEST(vtkFFDVoxelize, RequestDataAloneRefusesBadDivisions)
{
  vtkSmartPointer<vtkPolyData> cloud = PointCloud({ { 0, 0, 0 }, { 1, 1, 1 } });
  for (const Voxel& n : { Voxel{ 0, 4, 4 }, Voxel{ 4, -1, 4 }, Voxel{ 4, 4, 0 }, Voxel{ VTK_INT_MAX, VTK_INT_MAX, 2 } })
  {
    vtkNew<VoxelizeRequestDataOnly> voxelize;
    vtkNew<FFDTestErrorObserver> observer;
    voxelize->AddObserver(vtkCommand::ErrorEvent, observer);
    voxelize->SetDivisions(n[0], n[1], n[2]);
    vtkNew<vtkUnstructuredGrid> output;
    EXPECT_EQ(voxelize->Run(cloud, output), 0); // before the check there: SIGFPE in the voxel index
    EXPECT_NE(observer->Errors.find("Divisions ("), std::string::npos) << observer->Errors;
    EXPECT_EQ(output->GetNumberOfCells(), 0);
  }
}

TEST(vtkFFDVoxelize, DivisionsBeyondA64BitIndexAreAnError)
{
  // Voxels and corners are found by their linear index, an int64: (2^31)^2 * 3 corners overflow it.
  vtkSmartPointer<vtkPolyData> cloud = PointCloud({ { 0, 0, 0 }, { 1, 1, 1 } });
  vtkNew<vtkFFDVoxelize> voxelize;
  voxelize->SetDivisions(VTK_INT_MAX, VTK_INT_MAX, 2);
  ExpectFailure(voxelize, cloud, "64-bit index");
}

TEST(vtkFFDVoxelize, BadExplicitFramesAreAnError)
{
  vtkSmartPointer<vtkPolyData> cloud = PointCloud({ { 0, 0, 0 }, { 1, 1, 1 } });
  const double o[3] = { 0, 0, 0 }, s[3] = { 1, 0, 0 }, t[3] = { 0, 1, 0 }, flat[3] = { 1, 1, 0 };
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  {
    vtkNew<vtkFFDVoxelize> voxelize;
    voxelize->SetFrameModeToExplicit();
    voxelize->SetFrame(o, s, t, flat); // U in the plane of S and T
    ExpectFailure(voxelize, cloud, "zero volume");
  }
  {
    vtkNew<vtkFFDVoxelize> voxelize;
    voxelize->SetFrameModeToExplicit();
    voxelize->SetFrame(o, s, t, o); // U = 0
    ExpectFailure(voxelize, cloud, "zero volume");
  }
  for (double bad : { nan, inf })
  {
    const double u[3] = { 0, bad, 1 };
    vtkNew<vtkFFDVoxelize> voxelize;
    voxelize->SetFrameModeToExplicit();
    voxelize->SetFrame(o, s, t, u);
    ExpectFailure(voxelize, cloud, "NaN or infinite");
  }
  // Finite numbers whose volume overflows double precision were reported as a flat frame.
  const double huge[3][3] = { { 1e308, 0, 0 }, { 0, 1e308, 0 }, { 0, 0, 1e308 } };
  {
    vtkNew<vtkFFDVoxelize> voxelize;
    voxelize->SetFrameModeToExplicit();
    voxelize->SetFrame(o, huge[0], huge[1], huge[2]);
    ExpectFailure(voxelize, cloud, "overflows or underflows");
  }
}

TEST(vtkFFDVoxelize, PaddingThatOverflowsTheFrameIsAnError)
{
  // SetPadding(inf) clamps to the largest double, whose frame overflows: the error names Padding, not flatness.
  vtkSmartPointer<vtkPolyData> cloud = PointCloud({ { 0, 0, 0 }, { 1, 1, 1 } });
  for (double padding : { std::numeric_limits<double>::infinity(), std::numeric_limits<double>::quiet_NaN(), 1e308 })
  {
    for (int mode : { vtkFFDVoxelize::AXIS_ALIGNED, vtkFFDVoxelize::PRINCIPAL_AXES })
    {
      SCOPED_TRACE(padding);
      vtkNew<vtkFFDVoxelize> voxelize;
      voxelize->SetFrameMode(mode);
      voxelize->SetPadding(padding);
      ExpectFailure(voxelize, cloud, "set Padding (SetPadding()) to a finite fraction");
    }
  }
}

TEST(vtkFFDVoxelize, DegenerateInputsOfAutomaticFramesAreAnError)
{
  const double nan = std::numeric_limits<double>::quiet_NaN();
  vtkSmartPointer<vtkPolyData> identical = PointCloud({ { 1, 2, 3 }, { 1, 2, 3 }, { 1, 2, 3 } });
  vtkSmartPointer<vtkPolyData> noFinite = PointCloud({ { nan, 0, 0 }, { 0, nan, 0 } });
  vtkSmartPointer<vtkPolyData> flat = PointCloud({ { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 } });
  for (int mode : { vtkFFDVoxelize::AXIS_ALIGNED, vtkFFDVoxelize::PRINCIPAL_AXES })
  {
    SCOPED_TRACE(mode);
    vtkNew<vtkFFDVoxelize> a, b, c;
    a->SetFrameMode(mode);
    b->SetFrameMode(mode);
    c->SetFrameMode(mode);
    ExpectFailure(a, identical, "identical");
    ExpectFailure(b, noFinite, "finite");
    c->SetPadding(0.0); // a flat input only has a volume through the padding
    ExpectFailure(c, flat, "zero volume");
  }
}

TEST(vtkFFDVoxelize, DenselyFilledFrameHasEveryVoxelActive)
{
  // Two points per voxel of a 24 x 17 x 9 grid: whole OpenVDB leaf nodes (8^3) fill up.
  const int n[3] = { 24, 17, 9 };
  std::vector<Vec> xs;
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i)
      {
        xs.push_back({ (i + 0.25) / n[0], (j + 0.5) / n[1], (k + 0.75) / n[2] });
        xs.push_back({ (i + 0.75) / n[0], (j + 0.25) / n[1], (k + 0.5) / n[2] });
      }
  vtkSmartPointer<vtkPolyData> cloud = PointCloud(xs);
  vtkNew<vtkFFDVoxelize> voxelize;
  const double o[3] = { 0, 0, 0 }, s[3] = { 1, 0, 0 }, t[3] = { 0, 1, 0 }, u[3] = { 0, 0, 1 };
  voxelize->SetFrameModeToExplicit();
  voxelize->SetFrame(o, s, t, u);
  voxelize->SetDivisions(n[0], n[1], n[2]);
  ExpectActiveVoxelsMatchBruteForce(cloud, voxelize);
  EXPECT_EQ(voxelize->GetNumberOfActiveVoxels(), n[0] * n[1] * n[2]);
}
