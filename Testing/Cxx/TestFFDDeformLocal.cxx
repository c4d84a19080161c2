// SPDX-License-Identifier: BSD-3-Clause
// Tests of vtkFFDDeform with the local bases (trilinear, triquadratic and tricubic Bezier sub-regions, uniform
// cubic B-spline) next to the global Bernstein basis: the independent float64 reference of FFDReference.h and
// VTK's own vtkBSplineTransform as a peer, on real meshes and hand-built lattices; identity and affine
// reproduction, locality, the outside policies, normals and Jacobian determinants, and bad lattices.
#include "FFDTestErrorObserver.h"
#include "FFDTestInputChecks.h"
#include "FFDTestLattices.h"
#include "FFDTestMeshes.h"

#include "vtkFFDBuildLattice.h"
#include "vtkFFDDataContract.h"
#include "vtkFFDDeform.h"
#include "vtkFFDVoxelize.h"

#include "vtkBSplineTransform.h"
#include "vtkDoubleArray.h"
#include "vtkExecutive.h"
#include "vtkImageData.h"
#include "vtkMath.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkStructuredGrid.h"
#include "vtkTransform.h"
#include "vtkTransformFilter.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <string>
#include <vector>

namespace
{
using namespace ffdtest;

const int AllBases[] = { vtkFFDBuildLattice::BERNSTEIN, vtkFFDBuildLattice::TRILINEAR,
  vtkFFDBuildLattice::TRIQUADRATIC_BEZIER, vtkFFDBuildLattice::TRICUBIC_BEZIER, vtkFFDBuildLattice::CUBIC_BSPLINE };
const int LocalBases[] = { vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::TRIQUADRATIC_BEZIER,
  vtkFFDBuildLattice::TRICUBIC_BEZIER, vtkFFDBuildLattice::CUBIC_BSPLINE };

// The float64 reference is ffdref's (FFDReference.h: binomials times powers of the local coordinate for the
// Bezier sub-regions, the Cox-de Boor recursion for the B-spline, sums over the whole lattice in the absolute
// form sum w P). The supports below are written here from the definitions, for the locality test.

// The voxel of parameter s in [0, 1] along an axis of n voxels; s = 1 belongs to the last voxel.
int VoxelOf(double s, int n)
{
  return std::clamp(int(std::floor(s * n)), 0, n - 1);
}

// The control points [first, first + count) along an axis that influence voxel c: p c .. p c + p for a Bezier
// basis of degree p (neighbours share face points), c .. c + 3 for the B-spline (point i centred on voxel
// boundary i - 1, reaching two voxels on each side).
void VoxelSupport(int basis, int c, int& first, int& count)
{
  const bool bspline = basis == vtkFFDBuildLattice::CUBIC_BSPLINE;
  const int p = ffdref::Degree(RefBasis(basis), 0);
  first = bspline ? c : p * c;
  count = bspline ? 4 : p + 1;
}

// Whether control point i of an axis influences voxel c of that axis.
bool InSupport(int basis, int i, int c)
{
  int first, count;
  VoxelSupport(basis, c, first, count);
  return i >= first && i < first + count;
}

std::string BasisName(int basis)
{
  return vtkFFDBuildLattice::GetBasisAsString(basis);
}
} // namespace

//------------------------------------------------------------------------------------------------------------
// Real meshes through the whole pipeline with every basis and random lattices: within 1e-12 of the float64
// reference, relative to the frame's diagonal, for double points (both sides in double: rounding of sums of
// a few hundred terms on coordinates of the order of the diagonal, a few 1e-16 relative). The lattice has the
// control points the basis needs per axis.
TEST(vtkFFDDeformLocal, EveryBasisMatchesReferenceOnRealMeshes)
{
  std::mt19937 rng(20261122);
  for (const char* name : { "bear", "elephant" })
  {
    vtkSmartPointer<vtkPolyData> mesh = ReadTestMesh(name);
    for (int basis : AllBases)
    {
      Pipeline pipeline(mesh, basis, 3, 4, 5);
      int dims[3];
      pipeline.Lattice->GetDimensions(dims);
      EXPECT_EQ(dims[0], PointsAlongAxis(basis, 3)) << BasisName(basis);
      EXPECT_EQ(dims[1], PointsAlongAxis(basis, 4)) << BasisName(basis);
      EXPECT_EQ(dims[2], PointsAlongAxis(basis, 5)) << BasisName(basis);
      Perturb(pipeline.Lattice, rng, 0.05 * pipeline.Diagonal());
      pipeline.Deform->Update();
      vtkPointSet* output = pipeline.Output();
      ASSERT_EQ(output->GetPoints()->GetDataType(), VTK_DOUBLE);
      const Reference ref = ReferenceOf(pipeline.Lattice);
      EXPECT_LE(MaxRelativeError(mesh, output, ref), 1e-12) << name << " " << BasisName(basis);
      EXPECT_GT(MaxRelativeMotion(mesh, output, ref.F), 1e-3) << name << " " << BasisName(basis);
    }
  }
}

// Float points are evaluated in float: within 1e-6 of the reference relative to the diagonal (a few float
// epsilons, 6e-8 each, on sums of up to 64 local terms or 6^3 global ones, bounded by the displacement).
TEST(vtkFFDDeformLocal, FloatPointsMatchReferenceInSinglePrecision)
{
  std::mt19937 rng(77);
  vtkSmartPointer<vtkPolyData> floatMesh = WithFloatPoints(ReadTestMesh("bear"));
  for (int basis : AllBases)
  {
    Pipeline pipeline(floatMesh, basis, 4, 3, 5);
    Perturb(pipeline.Lattice, rng, 0.05 * pipeline.Diagonal());
    pipeline.Deform->Update();
    ASSERT_EQ(pipeline.Output()->GetPoints()->GetDataType(), VTK_FLOAT);
    const Reference ref = ReferenceOf(pipeline.Lattice);
    EXPECT_LE(MaxRelativeError(floatMesh, pipeline.Output(), ref), 1e-6) << BasisName(basis);
  }
}

// A mesh in random vertex order, float32 points (what the SIMD lanes take): every block is gathered, read
// from a copy of the points in the binding's order, and trilinear, triquadratic and B-spline cells are evaluated
// from their power form (the bear has 13 826 points, over 2^3 voxels more than any basis's threshold of points a
// voxel). Within 1e-6 of the reference relative to the diagonal (as the float test above); the same mesh in its
// own order (blocks in place) gives the same points bit for bit, each point's result depending on it alone;
// after the lattice moves (the copy is reused) and after the input's points are replaced (a new binding and a
// new copy: a stale copy would give the old points' deformation), still within 1e-6.
TEST(vtkFFDDeformLocal, RandomVertexOrderIsGatheredFromACopy)
{
  std::mt19937 rng(4242);
  vtkSmartPointer<vtkPolyData> mesh = ReadTestMesh("bear");
  const vtkIdType n = mesh->GetNumberOfPoints();
  std::vector<vtkIdType> order(static_cast<std::size_t>(n));
  for (vtkIdType i = 0; i < n; ++i)
  {
    order[static_cast<std::size_t>(i)] = i;
  }
  std::shuffle(order.begin(), order.end(), rng);
  auto pointsOnly = [&](bool shuffled, double shift)
  {
    vtkNew<vtkPoints> points;
    points->SetDataTypeToFloat();
    points->SetNumberOfPoints(n);
    for (vtkIdType i = 0; i < n; ++i)
    {
      double x[3];
      mesh->GetPoint(shuffled ? order[static_cast<std::size_t>(i)] : i, x);
      points->SetPoint(i, x[0] + shift, x[1], x[2]);
    }
    vtkNew<vtkPolyData> cloud;
    cloud->SetPoints(points);
    return vtkSmartPointer<vtkPolyData>(cloud);
  };
  const vtkSmartPointer<vtkPolyData> ordered = pointsOnly(false, 0.0), shuffled = pointsOnly(true, 0.0);
  for (int basis : LocalBases)
  {
    Pipeline inOrder(ordered, basis, 2, 2, 2);
    Pipeline random(shuffled, basis, 2, 2, 2);
    Perturb(inOrder.Lattice, rng, 0.05 * inOrder.Diagonal());
    random.Lattice->DeepCopy(inOrder.Lattice);
    random.Deform->SetLatticeData(random.Lattice);
    inOrder.Deform->Update();
    random.Deform->Update();
    ASSERT_EQ(random.Output()->GetPoints()->GetDataType(), VTK_FLOAT);
    EXPECT_LE(MaxRelativeError(shuffled, random.Output(), ReferenceOf(random.Lattice)), 1e-6) << BasisName(basis);
    for (vtkIdType i = 0; i < n; ++i)
    {
      double a[3], b[3];
      random.Output()->GetPoint(i, a);
      inOrder.Output()->GetPoint(order[static_cast<std::size_t>(i)], b);
      ASSERT_TRUE(a[0] == b[0] && a[1] == b[1] && a[2] == b[2]) << BasisName(basis) << " point " << i;
    }

    Perturb(random.Lattice, rng, 0.05 * random.Diagonal());
    random.Lattice->Modified();
    random.Deform->Update();
    EXPECT_LE(MaxRelativeError(shuffled, random.Output(), ReferenceOf(random.Lattice)), 1e-6) << BasisName(basis);

    const vtkSmartPointer<vtkPolyData> moved = pointsOnly(true, 0.01 * random.Diagonal());
    random.Deform->SetInputData(moved);
    random.Deform->Update();
    EXPECT_EQ(random.Deform->GetNumberOfBindings(), 2) << BasisName(basis);
    EXPECT_LE(MaxRelativeError(moved, random.Output(), ReferenceOf(random.Lattice)), 1e-6) << BasisName(basis);
    EXPECT_GT(MaxRelativeMotion(shuffled, random.Output(), FrameOf(random.Lattice)), 1e-3) << BasisName(basis);
  }
}

// The rest lattice is the identity for every basis: its control points lie at the rest parameters of the
// definitions (Greville abscissae for the B-spline; 1e-12 of the diagonal), and the mesh comes back bit for
// bit.
TEST(vtkFFDDeformLocal, RestLatticeIsTheIdentityForEveryBasis)
{
  vtkSmartPointer<vtkPolyData> mesh = ReadTestMesh("elephant");
  for (int basis : AllBases)
  {
    Pipeline pipeline(mesh, basis, 4, 3, 2);
    const Reference ref = ReferenceOf(pipeline.Lattice);
    double worstRest = 0.0;
    for (size_t i = 0; i < ref.P.size(); ++i)
    {
      worstRest = std::max(worstRest, Length(ffdref::Sub(ref.P[i], ref.Rest[i])));
    }
    EXPECT_LE(worstRest / Diagonal(ref.F), 1e-12) << BasisName(basis);
    pipeline.Deform->Update();
    ASSERT_TRUE(SamePoints(pipeline.Output(), mesh)) << BasisName(basis);
  }
}

// Linear precision: an affine motion of the whole lattice, applied by vtkTransformFilter, moves the mesh by the
// same affine map for every basis (1e-12 of the diagonal: rounding of sums of at most 216 terms).
TEST(vtkFFDDeformLocal, AffineLatticeMotionIsReproducedForEveryBasis)
{
  vtkSmartPointer<vtkPolyData> mesh = ReadTestMesh("elephant");
  vtkNew<vtkTransform> affine;
  affine->Translate(0.3, -0.2, 0.1);
  affine->RotateWXYZ(35, 1, 2, 3);
  affine->Scale(1.2, 0.8, 1.1);
  for (int basis : AllBases)
  {
    Pipeline pipeline(mesh, basis, 3, 2, 4);
    EXPECT_LE(MaxRelativeErrorOfMovedLattice(pipeline, mesh, affine), 1e-12) << BasisName(basis);
  }
}

// vtkTransformFilter with TransformAllInputVectors on (ParaView's Transform's default) rotates or scales RestPosition
// with the points: the lattice would deform nothing. Vtkffd says so, for every basis, rotation and scaling alike.
// With the option off only the points move: a rigid rotation of the lattice about a point rotates the mesh, by
// partition of unity and linear precision, within 1e-12 of the diagonal of the float64 rotation of each input
// point (Rodrigues' formula, written in the test: rounding of sums of at most 216 terms of the diagonal's size).
TEST(vtkFFDDeformLocal, LatticesTransformedWithTheirVectorsAreRefusedForEveryBasis)
{
  vtkSmartPointer<vtkPolyData> mesh = ReadTestMesh("elephant");
  const Vec centre = { 0.2, -0.1, 0.3 }, axis = { 1.0, 2.0, 3.0 };
  vtkNew<vtkTransform> rotation;
  rotation->Translate(centre.data());
  rotation->RotateWXYZ(35, axis.data());
  rotation->Translate(-centre[0], -centre[1], -centre[2]);
  vtkNew<vtkTransform> scaling;
  scaling->Scale(1.2, 0.8, 1.1);
  for (int basis : AllBases)
  {
    Pipeline pipeline(mesh, basis, 3, 2, 4);
    for (vtkAbstractTransform* transform :
      { static_cast<vtkAbstractTransform*>(rotation.Get()), static_cast<vtkAbstractTransform*>(scaling.Get()) })
    {
      pipeline.Deform->SetLatticeData(TransformedLattice(pipeline.Lattice, transform, true));
      vtkNew<FFDTestErrorObserver> observer;
      observer->WatchWithExecutive(pipeline.Deform);
      pipeline.Deform->Update();
      EXPECT_NE(observer->Errors.find("RestPosition/VoxelIndex no longer match its FFDFrame"), std::string::npos)
        << BasisName(basis) << ": " << observer->Errors;
      EXPECT_NE(observer->Errors.find("with TransformAllInputVectors on); transform the lattice with that option off"),
        std::string::npos)
        << BasisName(basis);
      EXPECT_EQ(pipeline.Output()->GetNumberOfPoints(), 0) << BasisName(basis);
    }
    pipeline.Deform->SetLatticeData(TransformedLattice(pipeline.Lattice, rotation, false));
    pipeline.Deform->Update();
    const double error = MaxScaledDistance(
      mesh, pipeline.Output(), [&](const Vec& x) { return RotatedAbout(x, centre, axis, 35); }, pipeline.Diagonal());
    EXPECT_LE(error, 1e-12) << BasisName(basis);
  }
}

//------------------------------------------------------------------------------------------------------------
// Peer check: CUBIC_BSPLINE equals VTK's own vtkBSplineTransform (border mode Edge) on real meshes, to 1e-12 of
// the diagonal in double for points inside the domain, and so does det(J) against its analytic derivative
// (1e-10 relative: both analytic, in double).
//
// VTK's convention (Filters/Hybrid/vtkBSplineTransform.cxx, v9.1.0): a point maps to the continuous grid index
// p = (x - origin) / spacing; with idx = floor(p) and f = p - idx, coefficients idx - 1 .. idx + 2 get the
// uniform cubic weights (1-f)^3/6 .. f^3/6, i.e. coefficient g is the B-spline centred on grid node g, and the
// point moves by the sum of weights times coefficients (times DisplacementScale, 1 by default). Our control
// point g rests at parameter (g - 1)/n, the centre of its B-spline. So the coefficient image is the lattice's
// displacements in the same (i fastest) order, with origin at the rest position of control point (0, 0, 0),
// X0 - S/n (per axis of an axis-aligned frame), and spacing |S|/n, |T|/n, |U|/n: then p = s n + 1,
// idx - 1 = floor(s n) = our voxel and f = our local coordinate. No index shift beyond that origin is needed.
// Edge mode only matters for points outside the frame, which are not compared (outside, VTK extends the edge
// coefficients while keeping the unclamped weights; our CLAMP_TO_EDGE clamps the parameters instead).
TEST(vtkFFDDeformLocal, CubicBSplineEqualsVTKBSplineTransform)
{
  std::mt19937 rng(9001);
  for (const char* name : { "bear", "elephant" })
  {
    vtkSmartPointer<vtkPolyData> mesh = ReadTestMesh(name);
    const int n[3] = { 4, 5, 6 };
    Pipeline pipeline(mesh, vtkFFDBuildLattice::CUBIC_BSPLINE, n[0], n[1], n[2]);
    pipeline.Deform->SetOutputPointsPrecision(vtkAlgorithm::DOUBLE_PRECISION);
    pipeline.Deform->ComputeJacobianDeterminantOn();
    const ffdref::Frame f = FrameOf(pipeline.Lattice);
    const double diagonal = Diagonal(f);
    // vtkBSplineTransform has no orientation: the frame must be axis-aligned (vtkFFDVoxelize's default).
    ASSERT_EQ(f.S[1], 0.0);
    ASSERT_EQ(f.S[2], 0.0);
    ASSERT_EQ(f.T[0], 0.0);
    ASSERT_EQ(f.T[2], 0.0);
    ASSERT_EQ(f.U[0], 0.0);
    ASSERT_EQ(f.U[1], 0.0);

    vtkDataArray* rest = pipeline.Lattice->GetPointData()->GetArray(vtkFFDDataContract::RestPositionArrayName());
    ASSERT_NE(rest, nullptr);
    double origin[3];
    rest->GetTuple(0, origin);
    const double spacing[3] = { f.S[0] / n[0], f.T[1] / n[1], f.U[2] / n[2] };
    for (int a = 0; a < 3; ++a)
    {
      EXPECT_NEAR(origin[a], f.X0[a] - spacing[a], 1e-12 * diagonal);
    }
    vtkNew<vtkImageData> coefficients;
    coefficients->SetDimensions(n[0] + 3, n[1] + 3, n[2] + 3);
    coefficients->SetOrigin(origin);
    coefficients->SetSpacing(spacing);
    vtkNew<vtkDoubleArray> displacements;
    displacements->SetName("Displacement");
    displacements->SetNumberOfComponents(3);
    displacements->SetNumberOfTuples(pipeline.Lattice->GetNumberOfPoints());
    coefficients->GetPointData()->SetScalars(displacements);

    vtkNew<vtkBSplineTransform> bspline;
    bspline->SetBorderModeToEdge();
    bspline->SetCoefficientData(coefficients);
    vtkNew<vtkTransformFilter> peer;
    peer->SetInputData(mesh);
    peer->SetTransform(bspline);
    peer->SetOutputPointsPrecision(vtkAlgorithm::DOUBLE_PRECISION);

    // Twice: the second time only the lattice's points move (the filter keeps its binding).
    for (int round = 0; round < 2; ++round)
    {
      Perturb(pipeline.Lattice, rng, 0.05 * diagonal);
      for (vtkIdType p = 0; p < pipeline.Lattice->GetNumberOfPoints(); ++p)
      {
        double x[3], x0[3];
        pipeline.Lattice->GetPoint(p, x);
        rest->GetTuple(p, x0);
        displacements->SetTuple3(p, x[0] - x0[0], x[1] - x0[1], x[2] - x0[2]);
      }
      displacements->Modified();
      coefficients->Modified();
      bspline->Modified();
      pipeline.Deform->Update();
      peer->Update();
      bspline->Update();
      vtkPointSet* ours = pipeline.Output();
      vtkPointSet* theirs = peer->GetOutput();
      vtkDataArray* det = ours->GetPointData()->GetArray(vtkFFDDeform::JacobianDeterminantArrayName());
      ASSERT_NE(det, nullptr);
      const Reference ref = ReferenceOf(pipeline.Lattice);
      double worst = 0.0, worstDet = 0.0;
      vtkIdType compared = 0;
      for (vtkIdType i = 0; i < mesh->GetNumberOfPoints(); ++i)
      {
        Vec x, y, z;
        mesh->GetPoint(i, x.data());
        if (!ref.Inside(x))
        {
          continue;
        }
        ++compared;
        ours->GetPoint(i, y.data());
        theirs->GetPoint(i, z.data());
        worst = std::max(worst, Length(ffdref::Sub(y, z)));
        double out[3], derivative[3][3];
        bspline->InternalTransformDerivative(x.data(), out, derivative);
        const double d = vtkMath::Determinant3x3(derivative);
        worstDet = std::max(worstDet, std::fabs(det->GetTuple1(i) - d) / std::fabs(d));
      }
      EXPECT_EQ(compared, mesh->GetNumberOfPoints()) << name << ": the voxelizer's frame holds the mesh";
      EXPECT_LE(worst / diagonal, 1e-12) << name << " round " << round;
      EXPECT_LE(worstDet, 1e-10) << name << " round " << round;
      EXPECT_GT(MaxRelativeMotion(mesh, ours, f), 1e-3) << name;
    }
    EXPECT_EQ(pipeline.Deform->GetNumberOfBindings(), 1);
  }
}

//------------------------------------------------------------------------------------------------------------
// Locality: moving one control point of a local lattice changes only points whose voxel lies in that control
// point's support (computed here from the definitions), exactly (the other points get a sum of zero
// displacements), and it does change some: the control point is drawn from the support of a random mesh
// point's voxel. The moved points match the reference (1e-12 of the diagonal).
TEST(vtkFFDDeformLocal, MovingOneControlPointChangesOnlyItsSupport)
{
  std::mt19937 rng(4242);
  vtkSmartPointer<vtkPolyData> mesh = ReadTestMesh("elephant");
  const int n[3] = { 4, 5, 3 };
  for (int basis : LocalBases)
  {
    Pipeline pipeline(mesh, basis, n[0], n[1], n[2]);
    const ffdref::Frame f = FrameOf(pipeline.Lattice);
    auto voxelOf = [&](const Vec& x)
    {
      const Vec stu = ffdref::Parameters(f, x);
      return std::array<int, 3>{ VoxelOf(stu[0], n[0]), VoxelOf(stu[1], n[1]), VoxelOf(stu[2], n[2]) };
    };
    Vec seed;
    mesh->GetPoint(std::uniform_int_distribution<vtkIdType>(0, mesh->GetNumberOfPoints() - 1)(rng), seed.data());
    const std::array<int, 3> seedVoxel = voxelOf(seed);
    std::array<int, 3> moved;
    for (int a = 0; a < 3; ++a)
    {
      int first, count;
      VoxelSupport(basis, seedVoxel[a], first, count);
      moved[a] = first + std::uniform_int_distribution<int>(0, count - 1)(rng);
      ASSERT_TRUE(InSupport(basis, moved[a], seedVoxel[a]));
    }
    int dims[3];
    pipeline.Lattice->GetDimensions(dims);
    const vtkIdType id = moved[0] + dims[0] * (moved[1] + vtkIdType(dims[1]) * moved[2]);
    double p[3];
    pipeline.Lattice->GetPoint(id, p);
    const double step = 0.1 * pipeline.Diagonal();
    pipeline.Lattice->GetPoints()->SetPoint(id, p[0] + step, p[1] - 0.5 * step, p[2] + 0.7 * step);
    pipeline.Lattice->GetPoints()->Modified();
    pipeline.Deform->Update();

    vtkIdType changed = 0, changedOutside = 0, inSupport = 0;
    for (vtkIdType i = 0; i < mesh->GetNumberOfPoints(); ++i)
    {
      Vec x, y;
      mesh->GetPoint(i, x.data());
      pipeline.Output()->GetPoint(i, y.data());
      const std::array<int, 3> v = voxelOf(x);
      const bool supported =
        InSupport(basis, moved[0], v[0]) && InSupport(basis, moved[1], v[1]) && InSupport(basis, moved[2], v[2]);
      inSupport += supported;
      if (y != x)
      {
        ++changed;
        changedOutside += !supported;
      }
    }
    EXPECT_EQ(changedOutside, 0) << BasisName(basis);
    EXPECT_GT(changed, 0) << BasisName(basis);
    EXPECT_LT(inSupport, mesh->GetNumberOfPoints()) << BasisName(basis) << ": the support must not hold all";
    EXPECT_LE(MaxRelativeError(mesh, pipeline.Output(), ReferenceOf(pipeline.Lattice)), 1e-12);
  }
}

//------------------------------------------------------------------------------------------------------------
// The outside policy, for every basis, on hand-built lattices in a skewed frame with random control points:
// - KEEP_POSITION: points outside keep their position exactly (det J = 1); points exactly on the frame's
//   corners, edges and faces, and on inner voxel faces, deform (they move, and match the reference to 1e-12
//   of the diagonal);
// - CLAMP_TO_EDGE: every point moves to X + D(clamp(s, t, u)) (reference, 1e-12), and det J of outside points
//   matches central differences of that clamped reference (1e-6: steps of 1e-6 of the diagonal);
// - changing the policy rebinds (GetNumberOfBindings increments); moving only lattice points does not.
TEST(vtkFFDDeformLocal, OutsidePolicyForEveryBasis)
{
  std::mt19937 rng(5150);
  const ffdref::Frame f = { { 1.0, 2.0, 3.0 }, { 2.0, 0.5, 0.0 }, { -0.3, 1.5, 0.2 }, { 0.1, 0.2, 1.7 } };
  const int n[3] = { 3, 2, 4 };
  const double h = 1e-6 * Diagonal(f);
  const std::vector<Vec> boundary = { At(f, 0, 0, 0), At(f, 1, 1, 1), At(f, 1, 0, 1), At(f, 0, 1, 0),
    At(f, 0.5, 1, 0.3), At(f, 0.2, 0.7, 0), At(f, 1, 0.4, 0.6), At(f, 0, 0.25, 1), At(f, 1, 1, 0.35),
    At(f, 1.0 / 3, 0.5, 0.25), At(f, 2.0 / 3, 0.61, 0.75) };
  const std::vector<Vec> inside = { At(f, 0.41, 0.27, 0.83), At(f, 0.93, 0.05, 0.12) };
  // Outside points stay off inner voxel faces in their unclamped directions: the Bezier bases are only C0
  // there, and central differences would average the two sides.
  const std::vector<Vec> outside = { At(f, -0.01, 0.3, 0.55), At(f, 0.55, 1.02, 0.3), At(f, 1.3, -0.2, 0.6),
    At(f, 0.7, 0.4, -0.6), At(f, 3, 3, 3), At(f, -1, -1, -1) };
  std::vector<Vec> all = boundary;
  all.insert(all.end(), inside.begin(), inside.end());
  all.insert(all.end(), outside.begin(), outside.end());
  const size_t firstOutside = boundary.size() + inside.size();
  vtkSmartPointer<vtkPolyData> mesh = PointCloud(all);

  for (int basis : AllBases)
  {
    const std::string name = BasisName(basis);
    vtkSmartPointer<vtkStructuredGrid> lattice = MakeLattice(f, basis, n);
    Perturb(lattice, rng, 0.2);
    vtkNew<vtkFFDDeform> deform;
    deform->SetInputData(mesh);
    deform->SetLatticeData(lattice);
    deform->ComputeJacobianDeterminantOn();
    deform->Update();
    EXPECT_EQ(deform->GetNumberOfBindings(), 1);
    Reference ref = ReferenceOf(lattice);
    vtkPointSet* out = deform->GetOutput();
    vtkDataArray* det = out->GetPointData()->GetArray(vtkFFDDeform::JacobianDeterminantArrayName());
    ASSERT_NE(det, nullptr);
    for (size_t i = 0; i < all.size(); ++i)
    {
      Vec y;
      out->GetPoint(vtkIdType(i), y.data());
      if (i < firstOutside)
      {
        EXPECT_LE(Length(ffdref::Sub(y, ref.Deform(all[i]))) / Diagonal(f), 1e-12) << name << " point " << i;
        EXPECT_GT(Length(ffdref::Sub(y, all[i])), 1e-3) << name << " point " << i << " must deform";
      }
      else
      {
        EXPECT_EQ(y, all[i]) << name << " outside point " << i;
        EXPECT_EQ(det->GetTuple1(vtkIdType(i)), 1.0) << name << " outside point " << i;
      }
    }

    deform->SetOutsidePolicyToClampToEdge();
    deform->Update();
    EXPECT_EQ(deform->GetNumberOfBindings(), 2) << name;
    for (int round = 0; round < 2; ++round)
    {
      out = deform->GetOutput();
      det = out->GetPointData()->GetArray(vtkFFDDeform::JacobianDeterminantArrayName());
      ASSERT_NE(det, nullptr);
      EXPECT_LE(MaxRelativeError(mesh, out, ref, true), 1e-12) << name << " round " << round;
      for (size_t i = firstOutside; i < all.size(); ++i)
      {
        Vec y;
        out->GetPoint(vtkIdType(i), y.data());
        EXPECT_GT(Length(ffdref::Sub(y, all[i])), 1e-3) << name << " clamped point " << i << " must deform";
        const double d = Det(ref.Jacobian(all[i], h, true));
        EXPECT_NEAR(det->GetTuple1(vtkIdType(i)), d, 1e-6 * std::max(1.0, std::fabs(d)))
          << name << " clamped point " << i;
      }
      // Only the lattice's points move: evaluation only.
      Perturb(lattice, rng, 0.05);
      deform->Update();
      ref = ReferenceOf(lattice);
      EXPECT_EQ(deform->GetNumberOfBindings(), 2) << name;
    }

    deform->SetOutsidePolicyToKeepPosition();
    deform->Update();
    EXPECT_EQ(deform->GetNumberOfBindings(), 3) << name;
    EXPECT_LE(MaxRelativeError(mesh, deform->GetOutput(), ref), 1e-12) << name;
  }
}

//------------------------------------------------------------------------------------------------------------
// Normals and det J for the local bases against central differences of the reference (step 1e-6 of the
// diagonal; truncation and rounding stay below 1e-6 relative), at points away from voxel faces (local
// coordinates in [1e-3, 1 - 1e-3]: the Bezier bases are only C0 across them). Normals are stored as float:
// 1e-5.
TEST(vtkFFDDeformLocal, NormalsAndJacobianDeterminantMatchFiniteDifferences)
{
  std::mt19937 rng(31337);
  vtkSmartPointer<vtkPolyData> mesh = ReadTestMesh("elephant");
  vtkSmartPointer<vtkPolyData> withNormals = WithPointNormals(mesh);
  vtkDataArray* inNormals = withNormals->GetPointData()->GetNormals();
  ASSERT_NE(inNormals, nullptr);
  const int n[3] = { 3, 4, 3 };

  for (int basis : LocalBases)
  {
    const std::string name = BasisName(basis);
    Pipeline pipeline(withNormals, basis, n[0], n[1], n[2]);
    Perturb(pipeline.Lattice, rng, 0.02 * pipeline.Diagonal());
    pipeline.Deform->ComputeJacobianDeterminantOn();
    pipeline.Deform->Update();
    vtkPointSet* output = pipeline.Output();
    vtkDataArray* outNormals = output->GetPointData()->GetNormals();
    vtkDataArray* det = output->GetPointData()->GetArray(vtkFFDDeform::JacobianDeterminantArrayName());
    ASSERT_NE(outNormals, nullptr);
    ASSERT_NE(det, nullptr);

    const Reference ref = ReferenceOf(pipeline.Lattice);
    const double h = 1e-6 * Diagonal(ref.F);
    double worstNormal = 0.0, worstDet = 0.0;
    int compared = 0;
    for (vtkIdType i = 0; i < withNormals->GetNumberOfPoints(); i += 5)
    {
      Vec x, nIn, nOut;
      withNormals->GetPoint(i, x.data());
      const Vec stu = ffdref::Parameters(ref.F, x);
      bool awayFromFaces = true;
      for (int a = 0; a < 3; ++a)
      {
        const double r = stu[a] * n[a] - VoxelOf(stu[a], n[a]);
        awayFromFaces = awayFromFaces && r > 1e-3 && r < 1 - 1e-3;
      }
      if (!awayFromFaces)
      {
        continue;
      }
      ++compared;
      inNormals->GetTuple(i, nIn.data());
      outNormals->GetTuple(i, nOut.data());
      const Matrix j = ref.Jacobian(x, h);
      const double d = Det(j);
      const Vec expected = TransformedNormal(j, nIn);
      worstNormal = std::max(worstNormal, Length(ffdref::Sub(nOut, expected)));
      worstDet = std::max(worstDet, std::fabs(det->GetTuple1(i) - d) / std::max(1.0, std::fabs(d)));
    }
    EXPECT_GT(compared, withNormals->GetNumberOfPoints() / 10) << name;
    EXPECT_LE(worstNormal, 1e-5) << name;
    EXPECT_LE(worstDet, 1e-6) << name;
  }
}

//------------------------------------------------------------------------------------------------------------
// A lattice whose point count does not match its basis (FFDBasis names a basis the points were not built for)
// is refused with a message giving the count the basis needs, and the output is empty.
TEST(vtkFFDDeformLocal, LatticeSizedForAnotherBasisIsRefused)
{
  const ffdref::Frame f = { { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 } };
  const int n[3] = { 2, 3, 4 };
  vtkSmartPointer<vtkPolyData> mesh = ReadTestMesh("elephant");
  const std::array<int, 2> cases[] = { { vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::CUBIC_BSPLINE },
    { vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::TRICUBIC_BEZIER },
    { vtkFFDBuildLattice::CUBIC_BSPLINE, vtkFFDBuildLattice::TRILINEAR },
    { vtkFFDBuildLattice::TRICUBIC_BEZIER, vtkFFDBuildLattice::TRIQUADRATIC_BEZIER },
    { vtkFFDBuildLattice::TRIQUADRATIC_BEZIER, vtkFFDBuildLattice::BERNSTEIN } };
  for (const std::array<int, 2>& c : cases)
  {
    const std::string name = BasisName(c[0]) + " lattice labelled " + BasisName(c[1]);
    vtkSmartPointer<vtkStructuredGrid> lattice = MakeLattice(f, c[0], n);
    vtkFFDDataContract::SetBasis(lattice, c[1]);
    vtkNew<vtkFFDDeform> deform;
    deform->SetInputData(mesh);
    deform->SetLatticeData(lattice);
    const std::string errors = ffdtest::UpdateErrors(deform);
    const long need = long(PointsAlongAxis(c[1], n[0])) * PointsAlongAxis(c[1], n[1]) * PointsAlongAxis(c[1], n[2]);
    EXPECT_NE(errors.find("need " + std::to_string(need)), std::string::npos) << name << ": got \"" << errors << "\"";
    EXPECT_NE(errors.find(BasisName(c[1])), std::string::npos) << name;
    EXPECT_EQ(deform->GetOutput()->GetNumberOfPoints(), 0) << name;
  }
}
