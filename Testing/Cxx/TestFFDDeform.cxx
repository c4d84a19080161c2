// SPDX-License-Identifier: BSD-3-Clause
// Tests of vtkFFDDeform against the independent float64 reference of equations 1-3 (FFDReference.h), on real
// meshes and on hand-built lattices; the binding cache; normals and Jacobian determinants; bad input.
#include "FFDTestErrorObserver.h"
#include "FFDTestInputChecks.h"
#include "FFDTestLattices.h"
#include "FFDTestMeshes.h"

#include "vtkFFDBuildLattice.h"
#include "vtkFFDDataContract.h"
#include "vtkFFDDeform.h"
#include "vtkFFDVoxelize.h"

#include "vtkCallbackCommand.h"
#include "vtkCellData.h"
#include "vtkDoubleArray.h"
#include "vtkExecutive.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkIntArray.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkStructuredGrid.h"
#include "vtkTransform.h"
#include "vtkUnsignedCharArray.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <random>

namespace
{
using namespace ffdtest;

// A global Bernstein lattice of degree (l, m, n), built by hand (FFDTestLattices.h).
vtkSmartPointer<vtkStructuredGrid> MakeLattice(const ffdref::Frame& f, int l, int m, int n)
{
  const int degrees[3] = { l, m, n };
  return ffdtest::MakeLattice(f, vtkFFDBuildLattice::BERNSTEIN, degrees);
}

// The lattice's control points (absolute positions) in VTK order.
std::vector<Vec> ControlPoints(vtkPointSet* lattice)
{
  std::vector<Vec> p(lattice->GetNumberOfPoints());
  for (vtkIdType i = 0; i < lattice->GetNumberOfPoints(); ++i)
  {
    lattice->GetPoint(i, p[i].data());
  }
  return p;
}

// Reference deformation of one point: equation 2, then equation 3 inside the frame (with the filter's
// documented tolerance of 1e-10 in parameter units at the faces), the point itself outside.
Vec ReferenceDeform(const ffdref::Frame& f, const std::vector<Vec>& p, const int deg[3], const Vec& x)
{
  const Vec stu = ffdref::Parameters(f, x);
  for (double v : stu)
  {
    if (!(v >= -1e-10 && v <= 1 + 1e-10))
    {
      return x;
    }
  }
  return ffdref::Evaluate(p, deg[0], deg[1], deg[2],
    { std::clamp(stu[0], 0.0, 1.0), std::clamp(stu[1], 0.0, 1.0), std::clamp(stu[2], 0.0, 1.0) });
}

// Largest distance between the deformed points and the reference, over the frame's diagonal.
double MaxRelativeError(vtkPointSet* input, vtkPointSet* output, vtkPointSet* lattice)
{
  const ffdref::Frame f = FrameOf(lattice);
  int deg[3];
  EXPECT_TRUE(vtkFFDDataContract::GetDivisions(lattice, deg));
  const std::vector<Vec> p = ControlPoints(lattice);
  EXPECT_EQ(input->GetNumberOfPoints(), output->GetNumberOfPoints());
  return MaxScaledDistance(
    input, output, [&](const Vec& x) { return ReferenceDeform(f, p, deg, x); }, Diagonal(f));
}

} // namespace

// Real meshes through the whole pipeline, random lattices: within 1e-12 of the float64 reference, relative to
// the frame's diagonal, for double points (rounding of a few dozen operations on numbers of order 1).
TEST(vtkFFDDeform, MatchesReferenceOnRealMeshes)
{
  std::mt19937 rng(20261121);
  for (const char* name : { "bear", "elephant" })
  {
    for (const std::array<int, 3>& div : { std::array<int, 3>{ 2, 3, 4 }, std::array<int, 3>{ 5, 5, 5 } })
    {
      vtkSmartPointer<vtkPolyData> mesh = ReadTestMesh(name);
      Pipeline pipeline(mesh, vtkFFDBuildLattice::BERNSTEIN, div[0], div[1], div[2]);
      Perturb(pipeline.Lattice, rng, 0.2 * Diagonal(FrameOf(pipeline.Lattice)));
      pipeline.Deform->Update();
      vtkPointSet* output = pipeline.Output();
      EXPECT_EQ(output->GetPoints()->GetDataType(), VTK_DOUBLE);
      EXPECT_EQ(output->GetNumberOfCells(), mesh->GetNumberOfCells());
      EXPECT_LE(MaxRelativeError(mesh, output, pipeline.Lattice), 1e-12) << name;
    }
  }
}

// Float points are evaluated in float: within 1e-6 of the reference relative to the diagonal (a few float
// epsilons, 6e-8 each, on sums of up to 125 terms bounded by the displacement).
TEST(vtkFFDDeform, FloatPointsStayFloatWithinSinglePrecision)
{
  std::mt19937 rng(7);
  vtkSmartPointer<vtkPolyData> floatMesh = WithFloatPoints(ReadTestMesh("bear"));
  ASSERT_EQ(floatMesh->GetPoints()->GetDataType(), VTK_FLOAT);

  Pipeline pipeline(floatMesh, vtkFFDBuildLattice::BERNSTEIN, 4, 4, 4);
  Perturb(pipeline.Lattice, rng, 0.2 * Diagonal(FrameOf(pipeline.Lattice)));
  pipeline.Deform->Update();
  EXPECT_EQ(pipeline.Output()->GetPoints()->GetDataType(), VTK_FLOAT);
  EXPECT_LE(MaxRelativeError(floatMesh, pipeline.Output(), pipeline.Lattice), 1e-6);

  pipeline.Deform->SetOutputPointsPrecision(vtkAlgorithm::DOUBLE_PRECISION);
  pipeline.Deform->Update();
  EXPECT_EQ(pipeline.Output()->GetPoints()->GetDataType(), VTK_DOUBLE);
  EXPECT_LE(MaxRelativeError(floatMesh, pipeline.Output(), pipeline.Lattice), 1e-12);
}

// Any VTK filter that moves the lattice's points deforms the mesh: an affine motion of the lattice applied by
// vtkTransformFilter moves the mesh by the same affine map (linear precision), to 1e-12 of the diagonal.
TEST(vtkFFDDeform, AffineLatticeMotionIsReproduced)
{
  vtkSmartPointer<vtkPolyData> mesh = ReadTestMesh("elephant");
  Pipeline pipeline(mesh, vtkFFDBuildLattice::BERNSTEIN, 3, 2, 4);
  vtkNew<vtkTransform> affine;
  affine->Translate(0.3, -0.2, 0.1);
  affine->RotateWXYZ(35, 1, 2, 3);
  affine->Scale(1.2, 0.8, 1.1);
  EXPECT_LE(MaxRelativeErrorOfMovedLattice(pipeline, mesh, affine), 1e-12);
}

TEST(vtkFFDDeform, RestLatticeIsTheIdentity)
{
  vtkSmartPointer<vtkPolyData> mesh = ReadTestMesh("elephant");
  Pipeline pipeline(mesh, vtkFFDBuildLattice::BERNSTEIN, 4, 3, 2);
  pipeline.Deform->Update();
  ASSERT_TRUE(SamePoints(pipeline.Output(), mesh));
}

// The binding is computed once and reused while only lattice points move; it is recomputed when the input's
// points, the lattice's frame or its divisions change, and kept for a rebuilt lattice with the same rest frame.
TEST(vtkFFDDeform, BindingIsCachedUntilPointsOrRestFrameChange)
{
  std::mt19937 rng(3);
  vtkSmartPointer<vtkPolyData> mesh = ReadTestMesh("elephant");
  const ffdref::Frame f = { { -0.5, -0.6, -0.4 }, { 1.0, 0.0, 0.0 }, { 0.0, 1.2, 0.0 }, { 0.0, 0.0, 0.8 } };
  vtkSmartPointer<vtkStructuredGrid> lattice = MakeLattice(f, 3, 3, 3);
  vtkNew<vtkFFDDeform> deform;
  deform->SetInputData(mesh);
  deform->SetLatticeData(lattice);
  deform->Update();
  EXPECT_EQ(deform->GetNumberOfBindings(), 1);

  Perturb(lattice, rng, 0.05); // lattice points only: evaluation only, and the output follows
  deform->Update();
  EXPECT_EQ(deform->GetNumberOfBindings(), 1);
  EXPECT_LE(MaxRelativeError(mesh, deform->GetOutput(), lattice), 1e-12);

  vtkSmartPointer<vtkStructuredGrid> rebuilt = MakeLattice(f, 3, 3, 3); // new object, same rest frame
  deform->SetLatticeData(rebuilt);
  deform->Update();
  EXPECT_EQ(deform->GetNumberOfBindings(), 1);

  mesh->GetPoints()->Modified(); // the mesh's points changed
  deform->Update();
  EXPECT_EQ(deform->GetNumberOfBindings(), 2);

  ffdref::Frame g = f;
  g.X0[0] -= 0.01; // another rest frame
  deform->SetLatticeData(MakeLattice(g, 3, 3, 3));
  deform->Update();
  EXPECT_EQ(deform->GetNumberOfBindings(), 3);

  vtkSmartPointer<vtkStructuredGrid> reshaped = MakeLattice(g, 2, 3, 3); // another shape
  Perturb(reshaped, rng, 0.05);
  deform->SetLatticeData(reshaped);
  deform->Update();
  EXPECT_EQ(deform->GetNumberOfBindings(), 4);
  EXPECT_LE(MaxRelativeError(mesh, deform->GetOutput(), reshaped), 1e-12);
}

namespace
{
/// A TRILINEAR lattice over 3x3x3 voxels in the frame that vtkFFDVoxelize gives the mesh.
vtkSmartPointer<vtkStructuredGrid> TrilinearLatticeAround(vtkPolyData* mesh)
{
  const ffdref::Frame f = FrameOf(Pipeline(mesh, vtkFFDBuildLattice::TRILINEAR, 3, 3, 3).Lattice);
  const int divisions[3] = { 3, 3, 3 };
  return ffdtest::MakeLattice(f, vtkFFDBuildLattice::TRILINEAR, divisions);
}
}

TEST(vtkFFDDeform, OutputArraysAreReusedOnlyWhenNobodyElseHoldsThem)
{
  // An update writes into the last output's arrays when nothing else holds them (to spare the allocation);
  // arrays that a caller kept must keep the values of their own update.
  std::mt19937 rng(11);
  vtkSmartPointer<vtkPolyData> mesh = ReadTestMesh("bear");
  vtkSmartPointer<vtkPolyData> withNormals = WithPointNormals(mesh);
  vtkSmartPointer<vtkStructuredGrid> lattice = TrilinearLatticeAround(mesh);
  vtkNew<vtkFFDDeform> deform;
  deform->SetInputData(withNormals);
  deform->SetLatticeData(lattice);
  deform->ComputeJacobianDeterminantOn();
  Perturb(lattice, rng, 0.05);
  deform->Update();

  vtkSmartPointer<vtkDataArray> keptPoints = deform->GetOutput()->GetPoints()->GetData();
  vtkSmartPointer<vtkDataArray> keptNormals = deform->GetOutput()->GetPointData()->GetNormals();
  vtkSmartPointer<vtkDataArray> keptDeterminants =
    deform->GetOutput()->GetPointData()->GetArray(vtkFFDDeform::JacobianDeterminantArrayName());
  ASSERT_TRUE(keptPoints && keptNormals && keptDeterminants);
  std::vector<vtkSmartPointer<vtkDataArray>> copies;
  for (vtkDataArray* kept : { keptPoints.Get(), keptNormals.Get(), keptDeterminants.Get() })
  {
    copies.push_back(vtk::TakeSmartPointer(kept->NewInstance()));
    copies.back()->DeepCopy(kept);
  }
  auto unchanged = [&](vtkDataArray* kept, vtkDataArray* copy)
  {
    for (vtkIdType v = 0; v < kept->GetNumberOfValues(); ++v)
    {
      if (kept->GetComponent(v / kept->GetNumberOfComponents(), v % kept->GetNumberOfComponents()) !=
        copy->GetComponent(v / copy->GetNumberOfComponents(), v % copy->GetNumberOfComponents()))
      {
        return false;
      }
    }
    return true;
  };

  Perturb(lattice, rng, 0.05);
  deform->Update();
  vtkPointSet* out = deform->GetOutput();
  EXPECT_NE(out->GetPoints()->GetData(), keptPoints.Get());
  EXPECT_NE(out->GetPointData()->GetNormals(), keptNormals.Get());
  EXPECT_TRUE(unchanged(keptPoints, copies[0]));
  EXPECT_TRUE(unchanged(keptNormals, copies[1]));
  EXPECT_TRUE(unchanged(keptDeterminants, copies[2]));
  EXPECT_LE(MaxRelativeError(mesh, out, ReferenceOf(lattice)), 1e-12);

  // Nobody holds this update's arrays: the next one writes into them, and its result is still exact.
  vtkDataArray* owned = out->GetPoints()->GetData();
  Perturb(lattice, rng, 0.05);
  deform->Update();
  EXPECT_EQ(deform->GetOutput()->GetPoints()->GetData(), owned);
  EXPECT_LE(MaxRelativeError(mesh, deform->GetOutput(), ReferenceOf(lattice)), 1e-12);
  EXPECT_EQ(deform->GetNumberOfBindings(), 1);
}

TEST(vtkFFDDeform, AViewTakenAtEveryUpdateAlternatesBetweenTwoArrays)
{
  // A caller that holds a view of each output until the next update's (a numpy view taken at every update)
  // keeps the last arrays from reuse; the update before's are free again, and an update writes into them
  // rather than allocating: from the third update on, the outputs alternate between two arrays per role, each
  // exact, and the held view keeps the values of its own update.
  std::mt19937 rng(12);
  vtkSmartPointer<vtkPolyData> mesh = ReadTestMesh("bear");
  vtkSmartPointer<vtkPolyData> withNormals = WithPointNormals(mesh);
  vtkSmartPointer<vtkStructuredGrid> lattice = TrilinearLatticeAround(mesh);
  vtkNew<vtkFFDDeform> deform;
  deform->SetInputData(withNormals);
  deform->SetLatticeData(lattice);
  std::vector<vtkDataArray*> points, normalArrays; // each update's arrays (compared as addresses only)
  vtkSmartPointer<vtkDataArray> viewPoints, viewNormals;
  std::vector<double> viewed;
  for (int update = 0; update < 6; ++update)
  {
    Perturb(lattice, rng, 0.05);
    deform->Update();
    vtkPointSet* out = deform->GetOutput();
    if (viewPoints) // the view of the last update still has its values
    {
      for (vtkIdType v = 0; v < viewPoints->GetNumberOfValues(); v += 997)
      {
        ASSERT_EQ(viewPoints->GetComponent(v / 3, v % 3), viewed[std::size_t(v)]) << "update " << update;
      }
    }
    EXPECT_LE(MaxRelativeError(mesh, out, ReferenceOf(lattice)), 1e-12) << "update " << update;
    points.push_back(out->GetPoints()->GetData());
    normalArrays.push_back(out->GetPointData()->GetNormals());
    viewPoints = out->GetPoints()->GetData(); // the new view; the last one is let go
    viewNormals = out->GetPointData()->GetNormals();
    viewed.resize(std::size_t(viewPoints->GetNumberOfValues()));
    for (vtkIdType v = 0; v < viewPoints->GetNumberOfValues(); ++v)
    {
      viewed[std::size_t(v)] = viewPoints->GetComponent(v / 3, v % 3);
    }
  }
  for (std::size_t u = 2; u < points.size(); ++u)
  {
    EXPECT_EQ(points[u], points[u - 2]) << "update " << u;
    EXPECT_NE(points[u], points[u - 1]) << "update " << u;
    EXPECT_EQ(normalArrays[u], normalArrays[u - 2]) << "update " << u;
  }
}

namespace
{
// dX_ffd/dX of the reference by central differences (step h), as J[r][c] = d y_r / d x_c.
std::array<std::array<double, 3>, 3> ReferenceJacobian(
  const ffdref::Frame& f, const std::vector<Vec>& p, const int deg[3], const Vec& x, double h)
{
  std::array<std::array<double, 3>, 3> j{};
  for (int c = 0; c < 3; ++c)
  {
    Vec xp = x, xm = x;
    xp[c] += h;
    xm[c] -= h;
    const Vec yp = ffdref::Deform(f, p, deg[0], deg[1], deg[2], xp);
    const Vec ym = ffdref::Deform(f, p, deg[0], deg[1], deg[2], xm);
    for (int r = 0; r < 3; ++r)
    {
      j[r][c] = (yp[r] - ym[r]) / (2 * h);
    }
  }
  return j;
}
} // namespace

// Normals follow the inverse transpose of the Jacobian and det(J) is reported: both against central differences
// of the reference (h = 1e-6 of the diagonal; truncation and rounding errors stay below 1e-6 relative).
TEST(vtkFFDDeform, NormalsAndJacobianDeterminantMatchFiniteDifferences)
{
  std::mt19937 rng(11);
  vtkSmartPointer<vtkPolyData> mesh = ReadTestMesh("elephant");
  vtkSmartPointer<vtkPolyData> withNormals = WithPointNormals(mesh);

  Pipeline pipeline(withNormals, vtkFFDBuildLattice::BERNSTEIN, 3, 3, 3);
  Perturb(pipeline.Lattice, rng, 0.1 * Diagonal(FrameOf(pipeline.Lattice)));
  pipeline.Deform->ComputeJacobianDeterminantOn();
  pipeline.Deform->Update();
  vtkPointSet* output = pipeline.Output();
  vtkDataArray* outNormals = output->GetPointData()->GetNormals();
  vtkDataArray* det = output->GetPointData()->GetArray(vtkFFDDeform::JacobianDeterminantArrayName());
  ASSERT_NE(outNormals, nullptr);
  ASSERT_NE(det, nullptr);
  ASSERT_NE(outNormals, withNormals->GetPointData()->GetNormals());

  const ffdref::Frame f = FrameOf(pipeline.Lattice);
  int deg[3];
  vtkFFDDataContract::GetDivisions(pipeline.Lattice, deg);
  const std::vector<Vec> p = ControlPoints(pipeline.Lattice);
  const double h = 1e-6 * Diagonal(f);
  double worstNormal = 0.0, worstDet = 0.0;
  for (vtkIdType i = 0; i < withNormals->GetNumberOfPoints(); i += 7)
  {
    Vec x, n, m;
    withNormals->GetPoint(i, x.data());
    withNormals->GetPointData()->GetNormals()->GetTuple(i, n.data());
    outNormals->GetTuple(i, m.data());
    const auto j = ReferenceJacobian(f, p, deg, x, h);
    const double d = Det(j);
    const Vec expected = TransformedNormal(j, n);
    worstNormal = std::max(worstNormal, Length(ffdref::Sub(m, expected)));
    worstDet = std::max(worstDet, std::fabs(det->GetTuple1(i) - d) / std::fabs(d));
  }
  EXPECT_LE(worstNormal, 1e-5); // normals are stored as float
  EXPECT_LE(worstDet, 1e-6);
}

// Points outside the frame keep their position (det = 1, normal unchanged); points exactly on faces and corners
// deform: a corner goes exactly to its corner control point, since Bernstein lattices interpolate corners.
TEST(vtkFFDDeform, OutsidePointsStayAndBoundaryPointsDeform)
{
  std::mt19937 rng(5);
  const ffdref::Frame f = { { 1.0, 2.0, 3.0 }, { 2.0, 0.5, 0.0 }, { -0.3, 1.5, 0.2 }, { 0.1, 0.2, 1.7 } };
  vtkSmartPointer<vtkStructuredGrid> lattice = MakeLattice(f, 2, 3, 2);
  Perturb(lattice, rng, 0.3);
  const std::vector<Vec> p = ControlPoints(lattice);

  auto at = [&](double s, double t, double u)
  {
    return Vec{ f.X0[0] + s * f.S[0] + t * f.T[0] + u * f.U[0], f.X0[1] + s * f.S[1] + t * f.T[1] + u * f.U[1],
      f.X0[2] + s * f.S[2] + t * f.T[2] + u * f.U[2] };
  };
  const std::vector<Vec> inputs = { at(0, 0, 0), at(1, 1, 1), at(1, 0, 1), at(0.5, 1, 0.3), at(0.2, 0.7, 0),
    at(-0.01, 0.5, 0.5), at(0.5, 1.02, 0.5), at(3, 3, 3) };
  vtkSmartPointer<vtkPolyData> mesh = PointCloud(inputs);

  vtkNew<vtkFFDDeform> deform;
  deform->SetInputData(mesh);
  deform->SetLatticeData(lattice);
  deform->ComputeJacobianDeterminantOn();
  deform->Update();
  vtkPointSet* out = deform->GetOutput();
  vtkDataArray* det = out->GetPointData()->GetArray(vtkFFDDeform::JacobianDeterminantArrayName());

  const Vec corner0 = p[0], corner1 = p.back(), cornerSU = p[2 + 3 * (0 + 4 * 2)];
  const std::vector<Vec> cornerTargets = { corner0, corner1, cornerSU };
  for (int i = 0; i < 3; ++i)
  {
    Vec y;
    out->GetPoint(i, y.data());
    EXPECT_LE(Length(ffdref::Sub(y, cornerTargets[i])), 1e-12) << "corner " << i;
  }
  const int deg[3] = { 2, 3, 2 };
  for (int i = 3; i < 5; ++i) // on faces
  {
    Vec y;
    out->GetPoint(i, y.data());
    EXPECT_LE(Length(ffdref::Sub(y, ffdref::Deform(f, p, deg[0], deg[1], deg[2], inputs[i]))), 1e-12);
    EXPECT_GT(Length(ffdref::Sub(y, inputs[i])), 1e-3) << "a point on a face must deform";
  }
  for (int i = 5; i < 8; ++i) // outside
  {
    Vec y;
    out->GetPoint(i, y.data());
    EXPECT_EQ(y, inputs[i]);
    EXPECT_EQ(det->GetTuple1(i), 1.0);
  }
}

TEST(vtkFFDDeform, NonFiniteInputPointsPassThroughAndOthersAreUnaffected)
{
  std::mt19937 rng(13);
  vtkSmartPointer<vtkPolyData> mesh = ReadTestMesh("elephant");
  Pipeline pipeline(mesh, vtkFFDBuildLattice::BERNSTEIN, 3, 3, 3);
  Perturb(pipeline.Lattice, rng, 0.1);
  pipeline.Deform->Update();
  vtkNew<vtkPoints> clean;
  clean->SetDataTypeToDouble(); // DeepCopy keeps the destination's type
  clean->DeepCopy(pipeline.Output()->GetPoints());

  vtkNew<vtkPolyData> dirty;
  dirty->DeepCopy(mesh);
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  dirty->GetPoints()->SetPoint(10, nan, 0.0, 0.0);
  dirty->GetPoints()->SetPoint(20, 0.0, inf, 0.0);
  dirty->GetPoints()->SetPoint(30, 0.0, 0.0, -inf);
  pipeline.Deform->SetInputData(dirty);
  vtkNew<FFDTestErrorObserver> observer;
  observer->Watch(pipeline.Deform);
  pipeline.Deform->Update();
  EXPECT_TRUE(observer->Errors.empty()) << observer->Errors;
  vtkPointSet* out = pipeline.Output();
  ASSERT_EQ(out->GetNumberOfPoints(), mesh->GetNumberOfPoints());
  for (vtkIdType i = 0; i < out->GetNumberOfPoints(); ++i)
  {
    double y[3], expected[3];
    out->GetPoint(i, y);
    if (i == 10 || i == 20 || i == 30)
    {
      dirty->GetPoint(i, expected);
      for (int c = 0; c < 3; ++c)
      {
        EXPECT_TRUE(y[c] == expected[c] || (std::isnan(y[c]) && std::isnan(expected[c])));
      }
    }
    else
    {
      clean->GetPoint(i, expected);
      ASSERT_TRUE(VectorEqual(y, expected)) << "point " << i;
    }
  }
}

TEST(vtkFFDDeform, EmptyInputGivesEmptyOutputWithoutError)
{
  const ffdref::Frame f = { { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 } };
  vtkNew<vtkPolyData> empty;
  vtkNew<vtkFFDDeform> deform;
  deform->SetInputData(empty);
  deform->SetLatticeData(MakeLattice(f, 1, 1, 1));
  vtkNew<FFDTestErrorObserver> observer;
  observer->Watch(deform);
  deform->Update();
  EXPECT_TRUE(observer->Errors.empty()) << observer->Errors;
  EXPECT_EQ(deform->GetOutput()->GetNumberOfPoints(), 0);
}

// Each broken lattice is refused with a message naming the problem, and the output is empty.
TEST(vtkFFDDeform, BadLatticesAreRefusedWithAClearError)
{
  const ffdref::Frame f = { { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 } };
  struct Case
  {
    const char* Name;
    std::function<void(vtkStructuredGrid*)> Break;
    const char* Expected;
  };
  const double flat[12] = { 0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0 };
  const double nonFinite[12] = { 0, 0, std::nan(""), 1, 0, 0, 0, 1, 0, 0, 0, 1 };
  const int zero[3] = { 0, 2, 2 };
  const std::vector<Case> cases = {
    { "no frame", [](vtkStructuredGrid* l) { l->GetFieldData()->RemoveArray("FFDFrame"); }, "FFDFrame" },
    { "flat frame", [&](vtkStructuredGrid* l) { vtkFFDDataContract::SetFrame(l, flat); }, "(nearly) zero volume" },
    { "non-finite frame", [&](vtkStructuredGrid* l) { vtkFFDDataContract::SetFrame(l, nonFinite); }, "FFDFrame" },
    { "no divisions", [](vtkStructuredGrid* l) { l->GetFieldData()->RemoveArray("FFDDivisions"); }, "FFDDivisions" },
    { "zero divisions", [&](vtkStructuredGrid* l) { vtkFFDDataContract::SetDivisions(l, zero); }, "FFDDivisions" },
    { "no basis", [](vtkStructuredGrid* l) { l->GetFieldData()->RemoveArray("FFDBasis"); }, "FFDBasis" },
    { "unknown basis", [](vtkStructuredGrid* l) { vtkFFDDataContract::SetBasis(l, 7); }, "not a known basis" },
    { "point count of another basis",
      [](vtkStructuredGrid* l) { vtkFFDDataContract::SetBasis(l, vtkFFDBuildLattice::CUBIC_BSPLINE); }, "need 125" },
    { "wrong point count",
      [](vtkStructuredGrid* l)
      {
        const int more[3] = { 2, 2, 3 };
        vtkFFDDataContract::SetDivisions(l, more);
      },
      "need 36" },
    // The same count of points in another shape: the grid's consumers would index it otherwise than the deformation.
    { "dimensions of another shape", [](vtkStructuredGrid* l) { l->SetDimensions(9, 3, 1); },
      "The lattice's dimensions 9x3x1 are not the 3x3x3 control points" },
    { "no rest position", [](vtkStructuredGrid* l) { l->GetPointData()->RemoveArray("RestPosition"); },
      "RestPosition" },
    { "rest position of 2 components",
      [](vtkStructuredGrid* l)
      {
        vtkNew<vtkDoubleArray> rest;
        rest->SetName("RestPosition");
        rest->SetNumberOfComponents(2);
        rest->SetNumberOfTuples(l->GetNumberOfPoints());
        rest->Fill(0.0);
        l->GetPointData()->AddArray(rest);
      },
      "RestPosition" },
    { "non-finite control point", [](vtkStructuredGrid* l) { l->GetPoints()->SetPoint(5, 0.0, std::nan(""), 0.0); },
      "not finite" },
    // Beyond +-1e100 the products of an evaluation overflow: before, the mesh came out as inf and NaN.
    { "control point at 1e308", [](vtkStructuredGrid* l) { l->GetPoints()->SetPoint(5, 1e308, 0.0, 0.0); },
      "Lattice point 5 or its RestPosition is not finite or lies beyond +-1e+100" },
    { "rest position at -1e101",
      [](vtkStructuredGrid* l) { l->GetPointData()->GetArray("RestPosition")->SetComponent(5, 2, -1e101); },
      "Lattice point 5 or its RestPosition is not finite or lies beyond" },
    // The contract's types: an integer RestPosition moved the mesh by its truncation, silently.
    { "integer rest position",
      [](vtkStructuredGrid* l)
      {
        vtkNew<vtkIntArray> rest;
        rest->DeepCopy(l->GetPointData()->GetArray("RestPosition"));
        rest->SetName("RestPosition");
        l->GetPointData()->AddArray(rest);
      },
      "RestPosition array holds int values; the data contract asks for doubles" },
    { "float rest position",
      [](vtkStructuredGrid* l)
      {
        vtkNew<vtkFloatArray> rest;
        rest->DeepCopy(l->GetPointData()->GetArray("RestPosition"));
        rest->SetName("RestPosition");
        l->GetPointData()->AddArray(rest);
      },
      "RestPosition array holds float values" },
    { "float points",
      [](vtkStructuredGrid* l)
      {
        vtkNew<vtkPoints> points;
        points->SetDataTypeToFloat();
        points->DeepCopy(l->GetPoints());
        l->SetPoints(points);
      },
      "The lattice's points are float; the data contract asks for doubles" },
    // Read by the filters that take a lattice's covered voxels (refine, coarsen, detail) at every control point.
    { "Active of fewer values",
      [](vtkStructuredGrid* l)
      {
        vtkNew<vtkUnsignedCharArray> active;
        active->SetName("Active");
        active->SetNumberOfTuples(3);
        active->Fill(1);
        l->GetPointData()->AddArray(active);
      },
      "Active point array does not have one value per point: it has 3 tuples of 1 components" },
    // A rest position the frame does not give (a transform of RestPosition as a vector, or an edit).
    { "rest position off the frame",
      [](vtkStructuredGrid* l) { l->GetPointData()->GetArray("RestPosition")->SetComponent(7, 0, 0.51); },
      "The RestPosition of lattice point 7, (0.51, 1, 0), is not the rest position (0.5, 1, 0)" },
    // Divisions whose counts wrap in 32 or 64 bits (a product that wrapped to 0 once passed the point count).
    { "divisions beyond an int",
      [](vtkStructuredGrid* l)
      {
        const int huge[3] = { 1431655765, 1, 1 };
        vtkFFDDataContract::SetBasis(l, vtkFFDBuildLattice::TRICUBIC_BEZIER);
        vtkFFDDataContract::SetDivisions(l, huge);
      },
      "is too large" },
    { "a product that wraps",
      [](vtkStructuredGrid* l)
      {
        const int wrapping[3] = { 4194303, 2097151, 2097151 };
        vtkFFDDataContract::SetBasis(l, vtkFFDBuildLattice::TRILINEAR);
        vtkFFDDataContract::SetDivisions(l, wrapping);
      },
      "more than 2^31 - 1 control points" },
  };
  vtkSmartPointer<vtkPolyData> mesh = ReadTestMesh("elephant");
  for (const Case& c : cases)
  {
    vtkSmartPointer<vtkStructuredGrid> lattice = MakeLattice(f, 2, 2, 2);
    c.Break(lattice);
    vtkNew<vtkFFDDeform> deform;
    deform->SetInputData(mesh);
    deform->SetLatticeData(lattice);
    const std::string errors = ffdtest::UpdateErrors(deform);
    EXPECT_NE(errors.find(c.Expected), std::string::npos) << c.Name << ": got \"" << errors << "\"";
    EXPECT_EQ(deform->GetOutput()->GetNumberOfPoints(), 0) << c.Name;
  }
}

TEST(vtkFFDDeform, NormalsOfAnotherLengthAreWarnedAboutAndNotTransformed)
{
  // Point normals with one tuple for the whole mesh (read past their end before): a warning, the normals are
  // passed through untransformed, the points are deformed as without normals.
  vtkSmartPointer<vtkPolyData> mesh = ReadTestMesh("bear");
  vtkNew<vtkPolyData> withShortNormals;
  withShortNormals->ShallowCopy(mesh);
  vtkNew<vtkFloatArray> normals;
  normals->SetNumberOfComponents(3);
  normals->InsertNextTuple3(0.0, 0.0, 1.0);
  withShortNormals->GetPointData()->SetNormals(normals);
  Pipeline pipeline(mesh, vtkFFDBuildLattice::TRILINEAR, 2, 2, 2);
  std::mt19937 rng(13);
  Perturb(pipeline.Lattice, rng, 0.05);
  vtkNew<vtkFFDDeform> deform;
  vtkNew<FFDTestErrorObserver> observer;
  observer->Watch(deform);
  deform->SetInputData(withShortNormals);
  deform->SetLatticeData(pipeline.Lattice);
  deform->Update();
  EXPECT_NE(observer->Warnings.find("1 tuples of 3 components"), std::string::npos) << observer->Warnings;
  EXPECT_TRUE(observer->Errors.empty()) << observer->Errors;
  EXPECT_LE(MaxRelativeError(mesh, deform->GetOutput(), ReferenceOf(pipeline.Lattice)), 1e-12);
}

TEST(vtkFFDDeform, ReportsProgress)
{
  vtkSmartPointer<vtkPolyData> mesh = ReadTestMesh("bear");
  Pipeline pipeline(mesh, vtkFFDBuildLattice::BERNSTEIN, 2, 2, 2);
  std::vector<double> progress;
  vtkNew<vtkCallbackCommand> onProgress;
  onProgress->SetClientData(&progress);
  onProgress->SetCallback([](vtkObject* caller, unsigned long, void* data, void*)
    { static_cast<std::vector<double>*>(data)->push_back(static_cast<vtkAlgorithm*>(caller)->GetProgress()); });
  pipeline.Deform->AddObserver(vtkCommand::ProgressEvent, onProgress);
  pipeline.Deform->Update();
  ASSERT_GE(progress.size(), 2u);
  EXPECT_TRUE(std::is_sorted(progress.begin(), progress.end()));
  EXPECT_EQ(progress.back(), 1.0);
}

// Backends: AUTOMATIC picks CUDA only where a device is present; CUDA asked for where it cannot run falls back to
// the CPU with a warning and the same output; GetLastBackendUsed() names what ran. Where a device is present
// (never on the CPU-only machines these tests run on in CI) the CUDA result must match the CPU's within 1e-5 of
// the diagonal (float32 evaluation).
TEST(vtkFFDDeform, BackendChoiceAndCpuFallback)
{
  std::mt19937 rng(17);
  vtkSmartPointer<vtkPolyData> mesh = ReadTestMesh("elephant");
  Pipeline pipeline(mesh, vtkFFDBuildLattice::BERNSTEIN, 3, 3, 3);
  Perturb(pipeline.Lattice, rng, 0.1);
  EXPECT_STREQ(pipeline.Deform->GetLastBackendUsed(), "None");

  pipeline.Deform->SetBackendToCPU();
  pipeline.Deform->Update();
  EXPECT_STREQ(pipeline.Deform->GetLastBackendUsed(), "CPU");
  vtkNew<vtkPoints> cpu;
  cpu->SetDataTypeToDouble();
  cpu->DeepCopy(pipeline.Output()->GetPoints());

  for (int backend : { vtkFFDDeform::AUTOMATIC, vtkFFDDeform::CUDA })
  {
    pipeline.Deform->SetBackend(backend);
    vtkNew<FFDTestErrorObserver> observer;
    observer->Watch(pipeline.Deform);
    pipeline.Deform->Update();
    EXPECT_TRUE(observer->Errors.empty()) << observer->Errors;
    const std::string used = pipeline.Deform->GetLastBackendUsed();
    double worst = 0.0;
    for (vtkIdType i = 0; i < mesh->GetNumberOfPoints(); ++i)
    {
      double a[3], b[3];
      cpu->GetPoint(i, a);
      pipeline.Output()->GetPoint(i, b);
      worst = std::max(worst, std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]));
    }
    if (used == "CUDA")
    {
      EXPECT_LE(worst / Diagonal(FrameOf(pipeline.Lattice)), 1e-5);
    }
    else
    {
      EXPECT_EQ(used, "CPU");
      EXPECT_EQ(worst, 0.0); // the very same CPU computation
      if (backend == vtkFFDDeform::CUDA)
      {
        EXPECT_NE(observer->Warnings.find("CUDA backend cannot run"), std::string::npos) << observer->Warnings;
      }
      else
      {
        EXPECT_TRUE(observer->Warnings.empty()) << observer->Warnings; // AUTOMATIC falls back silently
      }
    }
  }
}
