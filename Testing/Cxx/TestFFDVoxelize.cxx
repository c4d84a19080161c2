// SPDX-License-Identifier: BSD-3-Clause
// vtkFFDVoxelize: the frame of each mode, the active voxels against an independent brute-force count written
// from the paper's equation 2 (ffdref::Parameters), the output's data contract, and every bad input.
#include "vtkFFDVoxelize.h"

#include "vtkCellData.h"
#include "vtkDataSetAttributes.h"
#include "vtkDoubleArray.h"
#include "vtkExecutive.h"
#include "vtkFFDDataContract.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkInformation.h"
#include "vtkIntArray.h"
#include "vtkNew.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkStructuredGrid.h"
#include "vtkUnsignedCharArray.h"

#include "FFDReference.h"
#include "FFDTestComparisons.h"
#include "FFDTestErrorObserver.h"
#include "FFDTestMeshes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <set>

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

/// The voxels the output shows (no HIDDENCELL bit).
std::set<Voxel> ShownVoxels(vtkStructuredGrid* grid, const int n[3])
{
  std::set<Voxel> shown;
  vtkUnsignedCharArray* ghosts =
    vtkUnsignedCharArray::SafeDownCast(grid->GetCellData()->GetArray(vtkDataSetAttributes::GhostArrayName()));
  EXPECT_NE(ghosts, nullptr);
  if (!ghosts)
  {
    return shown;
  }
  EXPECT_EQ(ghosts->GetNumberOfValues(), static_cast<vtkIdType>(n[0]) * n[1] * n[2]);
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i)
      {
        if (!(ghosts->GetValue(i + n[0] * (j + n[1] * k)) & vtkDataSetAttributes::HIDDENCELL))
        {
          shown.insert({ i, j, k });
        }
      }
  return shown;
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
  vtkStructuredGrid* out = filter->GetOutput();
  const int* n = filter->GetDivisions();
  const std::set<Voxel> expected = BruteForceActiveVoxels(PointsOf(input), FrameOf(out), n);
  EXPECT_FALSE(expected.empty());
  EXPECT_EQ(ShownVoxels(out, n), expected);
  EXPECT_EQ(filter->GetNumberOfActiveVoxels(), static_cast<vtkIdType>(expected.size()));
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

double Norm(const Vec& v)
{
  return std::sqrt(ffdref::Dot(v, v));
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
  EXPECT_EQ(ShownVoxels(a->GetOutput(), a->GetDivisions()), ShownVoxels(b->GetOutput(), b->GetDivisions()));
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
  const int n[3] = { 2, 2, 2 };
  EXPECT_EQ(ShownVoxels(voxelize->GetOutput(), n), (std::set<Voxel>{ { 1, 1, 1 }, { 1, 0, 0 }, { 0, 0, 0 } }));
}

TEST(vtkFFDVoxelize, OutputFollowsTheDataContract)
{
  vtkSmartPointer<vtkPolyData> mesh = ReadTestMesh("elephant");
  vtkNew<vtkFFDVoxelize> voxelize;
  voxelize->SetInputData(mesh);
  voxelize->SetFrameModeToPrincipalAxes();
  voxelize->SetDivisions(3, 5, 2);
  voxelize->Update();
  vtkStructuredGrid* out = voxelize->GetOutput();

  int dims[3];
  out->GetDimensions(dims);
  EXPECT_EQ(dims[0], 4);
  EXPECT_EQ(dims[1], 6);
  EXPECT_EQ(dims[2], 3);
  EXPECT_EQ(out->GetNumberOfCells(), 30);
  EXPECT_EQ(out->GetPoints()->GetDataType(), VTK_DOUBLE);
  int whole[6];
  voxelize->GetOutputInformation(0)->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), whole);
  EXPECT_EQ(std::vector<int>(whole, whole + 6), (std::vector<int>{ 0, 3, 0, 5, 0, 2 }));

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

  // Corner (i, j, k) at X0 + (i/nx) S + (j/ny) T + (k/nz) U (equation 1), in VTK order; a few roundings apart.
  const ffdref::Frame f = FrameOf(out);
  const std::vector<Vec> expected = ffdref::RestLattice(f, 3, 5, 2);
  const double scale = Norm(f.X0) + Norm(f.S) + Norm(f.T) + Norm(f.U);
  ASSERT_EQ(out->GetNumberOfPoints(), static_cast<vtkIdType>(expected.size()));
  for (vtkIdType id = 0; id < out->GetNumberOfPoints(); ++id)
  {
    double x[3];
    out->GetPoint(id, x);
    ASSERT_TRUE(ffdtest::VectorNear(x, expected[id], 1e-15 * scale)) << id;
  }
  EXPECT_EQ(vtkUnsignedCharArray::SafeDownCast(out->GetCellData()->GetArray(vtkDataSetAttributes::GhostArrayName()))
              ->GetNumberOfValues(),
    30);
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
