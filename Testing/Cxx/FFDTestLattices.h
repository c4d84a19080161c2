// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDTestLattices.h
 * @brief Test helpers shared by the vtkFFDDeform tests: lattices built by hand from the data contract, the
 * float64 reference (FFDReference.h) applied to a lattice, random perturbations, the whole pipeline.
 */
#ifndef FFDTestLattices_h
#define FFDTestLattices_h

#include "FFDReference.h"
#include "FFDTestComparisons.h"

#include "vtkAbstractTransform.h"
#include "vtkDoubleArray.h"
#include "vtkFFDBuildLattice.h"
#include "vtkFFDDataContract.h"
#include "vtkFFDDeform.h"
#include "vtkFFDVoxelize.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkPolyDataNormals.h"
#include "vtkSmartPointer.h"
#include "vtkStructuredGrid.h"
#include "vtkTransformFilter.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <vector>

namespace ffdtest
{
using ffdref::Vec;
using Matrix = std::array<std::array<double, 3>, 3>;

static_assert(int(ffdref::Basis::Bernstein) == vtkFFDBuildLattice::BERNSTEIN &&
    int(ffdref::Basis::Trilinear) == vtkFFDBuildLattice::TRILINEAR &&
    int(ffdref::Basis::TriquadraticBezier) == vtkFFDBuildLattice::TRIQUADRATIC_BEZIER &&
    int(ffdref::Basis::TricubicBezier) == vtkFFDBuildLattice::TRICUBIC_BEZIER &&
    int(ffdref::Basis::CubicBSpline) == vtkFFDBuildLattice::CUBIC_BSPLINE,
  "the reference numbers the bases as the FFDBasis field array");

inline ffdref::Basis RefBasis(int basis)
{
  return static_cast<ffdref::Basis>(basis);
}

inline int PointsAlongAxis(int basis, int n)
{
  return ffdref::PointsAlongAxis(RefBasis(basis), n);
}

inline Vec At(const ffdref::Frame& f, double s, double t, double u)
{
  return { f.X0[0] + s * f.S[0] + t * f.T[0] + u * f.U[0], f.X0[1] + s * f.S[1] + t * f.T[1] + u * f.U[1],
    f.X0[2] + s * f.S[2] + t * f.T[2] + u * f.U[2] };
}

inline double Length(const Vec& v)
{
  return std::sqrt(ffdref::Dot(v, v));
}

inline double Diagonal(const ffdref::Frame& f)
{
  return Length(ffdref::Sub(At(f, 1, 1, 1), f.X0));
}

// A lattice as the reference sees it: frame, basis, divisions, control points and the rest lattice of the
// definitions (not the lattice's RestPosition array).
struct Reference
{
  ffdref::Frame F;
  ffdref::Basis Basis;
  int N[3];
  std::vector<Vec> P;
  std::vector<Vec> Rest;

  // Whether x lies in the frame, within the filter's documented band of 1e-10 in parameter units.
  bool Inside(const Vec& x) const
  {
    const Vec stu = ffdref::Parameters(this->F, x);
    return std::all_of(stu.begin(), stu.end(), [](double v) { return v >= -1e-10 && v <= 1 + 1e-10; });
  }

  // The deformed point: sum w P inside the frame; outside, X (kept) or X + D(clamp(s, t, u)) (clamped), where
  // D = sum w P - sum w P_rest.
  Vec Deform(const Vec& x, bool clampOutside = false) const
  {
    if (this->Inside(x))
    {
      return ffdref::DeformLocal(this->Basis, this->F, this->N, this->P, x);
    }
    if (!clampOutside)
    {
      return x;
    }
    Vec stu = ffdref::Parameters(this->F, x);
    for (double& v : stu)
    {
      v = std::clamp(v, 0.0, 1.0);
    }
    const Vec moved = ffdref::EvaluateLocal(this->Basis, this->N, this->P, stu);
    const Vec rest = ffdref::EvaluateLocal(this->Basis, this->N, this->Rest, stu);
    return { x[0] + moved[0] - rest[0], x[1] + moved[1] - rest[1], x[2] + moved[2] - rest[2] };
  }

  // dX_ffd/dX by central differences of Deform() with step h: J[r][c] = d y_r / d x_c.
  Matrix Jacobian(const Vec& x, double h, bool clampOutside = false) const
  {
    Matrix j{};
    for (int c = 0; c < 3; ++c)
    {
      Vec xp = x, xm = x;
      xp[c] += h;
      xm[c] -= h;
      const Vec yp = this->Deform(xp, clampOutside), ym = this->Deform(xm, clampOutside);
      for (int r = 0; r < 3; ++r)
      {
        j[r][c] = (yp[r] - ym[r]) / (2 * h);
      }
    }
    return j;
  }
};

inline ffdref::Frame FrameOf(vtkDataObject* data)
{
  double f[12];
  EXPECT_TRUE(vtkFFDDataContract::GetFrame(data, f));
  return { { f[0], f[1], f[2] }, { f[3], f[4], f[5] }, { f[6], f[7], f[8] }, { f[9], f[10], f[11] } };
}

// Reads a lattice through the data contract's field arrays and its points.
inline Reference ReferenceOf(vtkPointSet* lattice)
{
  Reference ref;
  ref.F = FrameOf(lattice);
  int basis = -1;
  EXPECT_TRUE(vtkFFDDataContract::GetBasis(lattice, basis));
  ref.Basis = RefBasis(basis);
  EXPECT_TRUE(vtkFFDDataContract::GetDivisions(lattice, ref.N));
  ref.Rest = ffdref::RestLattice(ref.Basis, ref.F, ref.N);
  EXPECT_EQ(size_t(lattice->GetNumberOfPoints()), ref.Rest.size());
  ref.P.resize(lattice->GetNumberOfPoints());
  for (vtkIdType i = 0; i < lattice->GetNumberOfPoints(); ++i)
  {
    lattice->GetPoint(i, ref.P[i].data());
  }
  return ref;
}

// A lattice of `basis` at rest, built by hand from the reference's rest lattice and the data contract, so that
// the tests of vtkFFDDeform on it do not depend on vtkFFDBuildLattice.
inline vtkSmartPointer<vtkStructuredGrid> MakeLattice(const ffdref::Frame& f, int basis, const int n[3])
{
  auto lattice = vtkSmartPointer<vtkStructuredGrid>::New();
  lattice->SetDimensions(PointsAlongAxis(basis, n[0]), PointsAlongAxis(basis, n[1]), PointsAlongAxis(basis, n[2]));
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  vtkNew<vtkDoubleArray> rest;
  rest->SetName(vtkFFDDataContract::RestPositionArrayName());
  rest->SetNumberOfComponents(3);
  for (const Vec& p : ffdref::RestLattice(RefBasis(basis), f, n))
  {
    points->InsertNextPoint(p.data());
    rest->InsertNextTuple(p.data());
  }
  lattice->SetPoints(points);
  lattice->GetPointData()->AddArray(rest);
  const double frame[12] = { f.X0[0], f.X0[1], f.X0[2], f.S[0], f.S[1], f.S[2], f.T[0], f.T[1], f.T[2], f.U[0], f.U[1],
    f.U[2] };
  vtkFFDDataContract::SetFrame(lattice, frame);
  vtkFFDDataContract::SetDivisions(lattice, n);
  vtkFFDDataContract::SetBasis(lattice, basis);
  return lattice;
}

/// A lattice of `basis` over `mesh` (vtkFFDVoxelize, axis-aligned frame) in `form`, its active control points
/// moved at random by up to `amplitude` of the frame's diagonal per component.
inline vtkSmartPointer<vtkPointSet> MovedLattice(
  vtkPointSet* mesh, int basis, const int n[3], int form, std::mt19937& rng, double amplitude = 0.05)
{
  vtkNew<vtkFFDVoxelize> voxelize;
  voxelize->SetInputData(mesh);
  voxelize->SetDivisions(n[0], n[1], n[2]);
  vtkNew<vtkFFDBuildLattice> build;
  build->SetInputConnection(voxelize->GetOutputPort());
  build->SetBasis(basis);
  build->SetLatticeForm(form);
  build->Update();
  vtkSmartPointer<vtkPointSet> lattice = vtkSmartPointer<vtkPointSet>::Take(build->GetOutput()->NewInstance());
  lattice->DeepCopy(build->GetOutput());
  const double size = ffdtest::Diagonal(ffdtest::FrameOf(lattice));
  std::uniform_real_distribution<double> move(-amplitude * size, amplitude * size);
  vtkDataArray* active = lattice->GetPointData()->GetArray("Active");
  for (vtkIdType p = 0; p < lattice->GetNumberOfPoints(); ++p)
  {
    if (active->GetComponent(p, 0) != 0)
    {
      double x[3];
      lattice->GetPoint(p, x);
      lattice->GetPoints()->SetPoint(p, x[0] + move(rng), x[1] + move(rng), x[2] + move(rng));
    }
  }
  return lattice;
}

// Moves every lattice point by a random vector of up to `amplitude` per component.
inline void Perturb(vtkPointSet* lattice, std::mt19937& rng, double amplitude)
{
  std::uniform_real_distribution<double> d(-amplitude, amplitude);
  vtkPoints* points = lattice->GetPoints();
  for (vtkIdType p = 0; p < points->GetNumberOfPoints(); ++p)
  {
    double x[3];
    points->GetPoint(p, x);
    points->SetPoint(p, x[0] + d(rng), x[1] + d(rng), x[2] + d(rng));
  }
  points->Modified();
}

/// The mesh with point normals (vtkPolyDataNormals without splitting: the same points).
inline vtkSmartPointer<vtkPolyData> WithPointNormals(vtkPolyData* mesh)
{
  vtkNew<vtkPolyDataNormals> normals;
  normals->SetInputData(mesh);
  normals->SplittingOff();
  normals->Update();
  return normals->GetOutput();
}

// Every point of `got` equal to the same point of `want`, coordinate for coordinate (==, as ASSERT_EQ compares),
// over want's points; fails at the first point that is not, naming it and its coordinates.
inline ::testing::AssertionResult SamePoints(vtkPointSet* got, vtkPointSet* want)
{
  for (vtkIdType i = 0; i < want->GetNumberOfPoints(); ++i)
  {
    double x[3], y[3];
    got->GetPoint(i, x);
    want->GetPoint(i, y);
    const ::testing::AssertionResult same = VectorEqual(x, y, "coordinate");
    if (!same)
    {
      return ::testing::AssertionFailure() << "point " << i << ": " << same.message();
    }
  }
  return ::testing::AssertionSuccess();
}

// Largest distance between each output point and expected(x) of its input point x, over `scale`.
template <typename Expected>
double MaxScaledDistance(vtkPointSet* input, vtkPointSet* output, const Expected& expected, double scale)
{
  double worst = 0.0;
  for (vtkIdType i = 0; i < input->GetNumberOfPoints(); ++i)
  {
    Vec x, y;
    input->GetPoint(i, x.data());
    output->GetPoint(i, y.data());
    worst = std::max(worst, Length(ffdref::Sub(y, expected(x))));
  }
  return worst / scale;
}

// Largest distance between the output points and the reference, over the frame's diagonal.
inline double MaxRelativeError(vtkPointSet* input, vtkPointSet* output, const Reference& ref, bool clamp = false)
{
  EXPECT_EQ(input->GetNumberOfPoints(), output->GetNumberOfPoints());
  return MaxScaledDistance(
    input, output, [&](const Vec& x) { return ref.Deform(x, clamp); }, Diagonal(ref.F));
}

// Largest distance any point moved, over the frame's diagonal: shows that a comparison could fail.
inline double MaxRelativeMotion(vtkPointSet* input, vtkPointSet* output, const ffdref::Frame& f)
{
  return MaxScaledDistance(
    input, output, [](const Vec& x) { return x; }, Diagonal(f));
}

inline double Det(const Matrix& a)
{
  return ffdref::Dot(
    { a[0][0], a[0][1], a[0][2] }, ffdref::Cross({ a[1][0], a[1][1], a[1][2] }, { a[2][0], a[2][1], a[2][2] }));
}

/// The unit normal J^-T n of a Jacobian J: the cofactor matrix (its columns cross products of J's columns)
/// times n over det J, normalized.
inline Vec TransformedNormal(const Matrix& j, const Vec& n)
{
  const Vec c0 = ffdref::Cross({ j[0][1], j[1][1], j[2][1] }, { j[0][2], j[1][2], j[2][2] });
  const Vec c1 = ffdref::Cross({ j[0][2], j[1][2], j[2][2] }, { j[0][0], j[1][0], j[2][0] });
  const Vec c2 = ffdref::Cross({ j[0][0], j[1][0], j[2][0] }, { j[0][1], j[1][1], j[2][1] });
  const double d = Det(j);
  Vec expected;
  for (int r = 0; r < 3; ++r)
  {
    expected[r] = (c0[r] * n[0] + c1[r] * n[1] + c2[r] * n[2]) / d;
  }
  const double length = Length(expected);
  for (double& e : expected)
  {
    e /= length;
  }
  return expected;
}

// The whole pipeline: vtkFFDVoxelize (axis-aligned frame) -> vtkFFDBuildLattice(basis) -> a deep copy of the
// lattice, which the test moves -> vtkFFDDeform.
struct Pipeline
{
  vtkNew<vtkFFDVoxelize> Voxelize;
  vtkNew<vtkFFDBuildLattice> Build;
  vtkNew<vtkFFDDeform> Deform;
  vtkSmartPointer<vtkStructuredGrid> Lattice = vtkSmartPointer<vtkStructuredGrid>::New();

  Pipeline(vtkPointSet* mesh, int basis, int nx, int ny, int nz)
  {
    this->Voxelize->SetInputData(mesh);
    this->Voxelize->SetDivisions(nx, ny, nz);
    this->Build->SetInputConnection(this->Voxelize->GetOutputPort());
    this->Build->SetBasis(basis);
    this->Build->SetLatticeFormToDense();
    this->Build->Update();
    this->Lattice->DeepCopy(this->Build->GetOutput());
    this->Deform->SetInputData(mesh);
    this->Deform->SetLatticeData(this->Lattice);
  }

  vtkPointSet* Output() { return vtkPointSet::SafeDownCast(this->Deform->GetOutputDataObject(0)); }
  double Diagonal() { return ffdtest::Diagonal(FrameOf(this->Lattice)); }
};

// Moves the pipeline's lattice by `transform` through vtkTransformFilter (as any VTK filter could move it),
// updates the deformation of `mesh` (the pipeline's input) and returns the largest distance between a deformed
// point and the transform of its input point, over the frame's diagonal.
inline double MaxRelativeErrorOfMovedLattice(Pipeline& pipeline, vtkPointSet* mesh, vtkAbstractTransform* transform)
{
  vtkNew<vtkTransformFilter> move;
  move->SetInputData(pipeline.Lattice);
  move->SetTransform(transform);
  pipeline.Deform->SetLatticeConnection(move->GetOutputPort());
  pipeline.Deform->Update();
  double worst = 0.0;
  for (vtkIdType i = 0; i < mesh->GetNumberOfPoints(); ++i)
  {
    double x[3], expected[3], y[3];
    mesh->GetPoint(i, x);
    transform->TransformPoint(x, expected);
    pipeline.Output()->GetPoint(i, y);
    worst = std::max(worst, std::hypot(y[0] - expected[0], y[1] - expected[1], y[2] - expected[2]));
  }
  return worst / pipeline.Diagonal();
}

/// `x` rotated by `degrees` about the axis through `centre` along `axis`, in float64 by Rodrigues' formula
/// x' = c + v cos a + (k x v) sin a + k (k . v)(1 - cos a), v = x - c, k the unit axis (independent of VTK's).
inline Vec RotatedAbout(const Vec& x, const Vec& centre, const Vec& axis, double degrees)
{
  const double a = degrees * 3.14159265358979323846 / 180.0;
  const double length = Length(axis);
  const Vec k = { axis[0] / length, axis[1] / length, axis[2] / length };
  const Vec v = ffdref::Sub(x, centre);
  const Vec kv = ffdref::Cross(k, v);
  const double kDotV = ffdref::Dot(k, v);
  Vec y;
  for (int c = 0; c < 3; ++c)
  {
    y[c] = centre[c] + v[c] * std::cos(a) + kv[c] * std::sin(a) + k[c] * kDotV * (1.0 - std::cos(a));
  }
  return y;
}

/// `lattice` moved by vtkTransformFilter with `transform`, every 3-component array transformed as a vector too
/// where `allInputVectors` is on (ParaView's Transform's default), and a copy of the output.
inline vtkSmartPointer<vtkPointSet> TransformedLattice(
  vtkPointSet* lattice, vtkAbstractTransform* transform, bool allInputVectors)
{
  vtkNew<vtkTransformFilter> move;
  move->SetInputData(lattice);
  move->SetTransform(transform);
  move->SetTransformAllInputVectors(allInputVectors);
  move->Update();
  auto moved = vtkSmartPointer<vtkPointSet>::Take(lattice->NewInstance());
  moved->DeepCopy(move->GetOutput());
  return moved;
}

} // namespace ffdtest

#endif
