// SPDX-License-Identifier: BSD-3-Clause
// vtkFFDDirectManipulation (issue 21, direct manipulation): targets met where they can be, for every grid basis
// (dense and sparse) and tetrahedral lattices on the bear; the move is the minimum-norm one (in the row space of
// the float64 reference's weights); only control points whose support holds a target move; one point asked to two
// places goes half way (the least-squares optimum); regularisation moves less and misses; bad input.
//
// Tolerances: a target's deformed point is the float64 sum of at most 64 weighted displacements, and the solve's
// residual is rounding of a k x m system (k <= 8 targets, m <= 512 columns) of condition number kappa: 1e-10 of
// the frame's diagonal bounds both for the well-separated targets used here (kappa < 1e3 measured).

#include "FFDTestErrorObserver.h"
#include "FFDTestInputChecks.h"
#include "FFDTestLattices.h"
#include "FFDTestMeshes.h"

#include "vtkFFDBuildTetrahedralLattice.h"
#include "vtkFFDDirectManipulation.h"
#include "vtkIdTypeArray.h"
#include "vtkMath.h"
#include "vtkUnstructuredGrid.h"

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include <limits>
#include <random>
#include <set>
#include <vector>

namespace
{
using ffdtest::Vec;

struct Targets
{
  vtkNew<vtkIdTypeArray> Ids;
  vtkNew<vtkPoints> Positions;
  Targets() { this->Positions->SetDataTypeToDouble(); }
};

/// `count` mesh points spread over the mesh (every count-th of a shuffled order, taking the farthest from those
/// chosen), each asked to move by a random vector of up to `reach` from where `lattice` takes it.
void ChooseTargets(vtkPointSet* mesh, vtkPointSet* lattice, int count, double reach, std::mt19937& rng, Targets& out)
{
  std::vector<vtkIdType> chosen = { vtkIdType(rng() % mesh->GetNumberOfPoints()) };
  while (int(chosen.size()) < count)
  {
    vtkIdType best = 0;
    double farthest = -1;
    for (vtkIdType p = 0; p < mesh->GetNumberOfPoints(); p += 7)
    {
      double nearest = VTK_DOUBLE_MAX, x[3], y[3];
      mesh->GetPoint(p, x);
      for (vtkIdType c : chosen)
      {
        mesh->GetPoint(c, y); // not GetPoint(c): it returns one buffer for every call
        nearest = std::min(nearest, vtkMath::Distance2BetweenPoints(x, y));
      }
      if (nearest > farthest)
      {
        farthest = nearest;
        best = p;
      }
    }
    chosen.push_back(best);
  }
  vtkNew<vtkFFDDeform> deform;
  deform->SetInputData(mesh);
  deform->SetLatticeData(lattice);
  deform->SetOutputPointsPrecision(vtkAlgorithm::DOUBLE_PRECISION);
  deform->Update();
  std::uniform_real_distribution<double> d(-reach, reach);
  for (vtkIdType id : chosen)
  {
    double y[3];
    vtkPointSet::SafeDownCast(deform->GetOutputDataObject(0))->GetPoint(id, y);
    out.Ids->InsertNextValue(id);
    out.Positions->InsertNextPoint(y[0] + d(rng), y[1] + d(rng), y[2] + d(rng));
  }
}

vtkSmartPointer<vtkPointSet> Manipulate(
  vtkPointSet* lattice, vtkPointSet* mesh, Targets& targets, vtkFFDDirectManipulation* filter)
{
  filter->SetInputData(lattice);
  filter->SetMeshData(mesh);
  filter->SetTargetPointIds(targets.Ids);
  filter->SetTargetPositions(targets.Positions);
  filter->Update();
  return filter->GetOutput();
}

/// The largest distance between a target and where `lattice` takes its mesh point.
double Missed(vtkPointSet* mesh, vtkPointSet* lattice, Targets& targets)
{
  vtkNew<vtkFFDDeform> deform;
  deform->SetInputData(mesh);
  deform->SetLatticeData(lattice);
  deform->SetOutputPointsPrecision(vtkAlgorithm::DOUBLE_PRECISION);
  deform->Update();
  double worst = 0;
  for (vtkIdType t = 0; t < targets.Ids->GetNumberOfValues(); ++t)
  {
    double y[3], want[3];
    vtkPointSet::SafeDownCast(deform->GetOutputDataObject(0))->GetPoint(targets.Ids->GetValue(t), y);
    targets.Positions->GetPoint(t, want);
    worst = std::max(worst, std::sqrt(vtkMath::Distance2BetweenPoints(y, want)));
  }
  return worst;
}

/// The float64 reference's weights of the targets' mesh points (rows) on every control point of `rest`'s dense
/// lattice (columns, i fastest).
Eigen::MatrixXd ReferenceWeights(vtkPointSet* mesh, Targets& targets, const ffdtest::Reference& rest)
{
  const int* n = rest.N;
  const int dims[3] = { ffdref::PointsAlongAxis(rest.Basis, n[0]), ffdref::PointsAlongAxis(rest.Basis, n[1]),
    ffdref::PointsAlongAxis(rest.Basis, n[2]) };
  Eigen::MatrixXd w = Eigen::MatrixXd::Zero(targets.Ids->GetNumberOfValues(), Eigen::Index(rest.P.size()));
  for (Eigen::Index t = 0; t < w.rows(); ++t)
  {
    Vec x;
    mesh->GetPoint(targets.Ids->GetValue(t), x.data());
    const Vec stu = ffdref::Parameters(rest.F, x);
    std::vector<double> axes[3];
    for (int a = 0; a < 3; ++a)
    {
      axes[a] = ffdref::AxisWeights(rest.Basis, n[a], stu[a]);
    }
    for (int c = 0; c < dims[2]; ++c)
    {
      for (int b = 0; b < dims[1]; ++b)
      {
        for (int a = 0; a < dims[0]; ++a)
        {
          w(t, a + dims[0] * (b + Eigen::Index(dims[1]) * c)) = axes[0][a] * axes[1][b] * axes[2][c];
        }
      }
    }
  }
  return w;
}

const int Bases[] = { vtkFFDBuildLattice::BERNSTEIN, vtkFFDBuildLattice::TRILINEAR,
  vtkFFDBuildLattice::TRIQUADRATIC_BEZIER, vtkFFDBuildLattice::TRICUBIC_BEZIER, vtkFFDBuildLattice::CUBIC_BSPLINE };
} // namespace

TEST(vtkFFDDirectManipulation, MeetsTargetsWithTheMinimumNormMoveForEveryGridBasis)
{
  vtkSmartPointer<vtkPolyData> bear = ReadTestMesh("bear");
  std::mt19937 rng(21);
  for (int basis : Bases)
  {
    for (int form : { vtkFFDBuildLattice::DENSE, vtkFFDBuildLattice::SPARSE })
    {
      if (basis == vtkFFDBuildLattice::BERNSTEIN && form == vtkFFDBuildLattice::SPARSE)
      {
        continue;
      }
      const int n[3] = { 4, 5, 4 };
      vtkSmartPointer<vtkPointSet> lattice = ffdtest::MovedLattice(bear, basis, n, form, rng, 0.02);
      const double size = ffdtest::Diagonal(ffdtest::FrameOf(lattice));
      Targets targets;
      ChooseTargets(bear, lattice, 4, 0.03 * size, rng, targets);
      vtkNew<vtkFFDDirectManipulation> manipulate;
      vtkSmartPointer<vtkPointSet> moved = Manipulate(lattice, bear, targets, manipulate);
      const std::string what = std::string(vtkFFDBuildLattice::GetBasisAsString(basis)) +
        (form == vtkFFDBuildLattice::SPARSE ? " sparse" : " dense");
      EXPECT_LE(Missed(bear, moved, targets), 1e-10 * size) << what;
      EXPECT_LE(manipulate->GetMaximumTargetDistance(), 1e-10 * size) << what;
      EXPECT_GT(Missed(bear, lattice, targets), 1e-3 * size) << "the targets were away from their points";

      // Only control points with a target in their support moved: each moved one has a weight at some target
      // (the reference's weights of the dense lattice, or, sparse, of the dense lattice of the same indices).
      const ffdtest::Reference rest =
        ffdtest::ReferenceOf(ffdtest::MovedLattice(bear, basis, n, vtkFFDBuildLattice::DENSE, rng, 0.0));
      const int dims[3] = { ffdref::PointsAlongAxis(rest.Basis, n[0]), ffdref::PointsAlongAxis(rest.Basis, n[1]),
        ffdref::PointsAlongAxis(rest.Basis, n[2]) };
      const Eigen::MatrixXd w = ReferenceWeights(bear, targets, rest);
      const Eigen::Index m = w.cols();
      Eigen::MatrixXd move = Eigen::MatrixXd::Zero(m, 3);
      vtkDataArray* index = moved->GetPointData()->GetArray("LatticeIndex");
      vtkIdType movedOutside = 0;
      for (vtkIdType p = 0; p < moved->GetNumberOfPoints(); ++p)
      {
        double a[3], b[3];
        lattice->GetPoint(p, a);
        moved->GetPoint(p, b);
        const Eigen::Index q = index ? Eigen::Index(index->GetComponent(p, 0)) +
            dims[0] * (Eigen::Index(index->GetComponent(p, 1)) + dims[1] * Eigen::Index(index->GetComponent(p, 2)))
                                     : Eigen::Index(p);
        for (int c = 0; c < 3; ++c)
        {
          move(q, c) = b[c] - a[c];
        }
        movedOutside += move.row(q).squaredNorm() > 0 && w.col(q).cwiseAbs().maxCoeff() == 0;
      }
      EXPECT_EQ(movedOutside, 0) << what;
      EXPECT_GT(manipulate->GetNumberOfMovedControlPoints(), 0);
      // The minimum-norm move lies in the row space of W: move = W^T y with y = (W W^T)^-1 W move (the reference's
      // W of 4 well-separated targets has full rank); the remainder is rounding.
      const Eigen::MatrixXd y = (w * w.transpose()).ldlt().solve(w * move);
      EXPECT_LE((w.transpose() * y - move).cwiseAbs().maxCoeff(), 1e-10 * move.cwiseAbs().maxCoeff()) << what;
    }
  }
}

TEST(vtkFFDDirectManipulation, MeetsTargetsOnTetrahedralLattices)
{
  vtkSmartPointer<vtkPolyData> bear = ReadTestMesh("bear");
  vtkNew<vtkFFDBuildTetrahedralLattice> build;
  build->SetInputData(bear);
  build->SetSubdivisionLevels(2);
  build->Update();
  vtkNew<vtkUnstructuredGrid> lattice;
  lattice->DeepCopy(build->GetOutput());
  std::mt19937 rng(22);
  double b[6];
  bear->GetBounds(b);
  const double size = std::hypot(b[1] - b[0], b[3] - b[2], b[5] - b[4]);
  Targets targets;
  ChooseTargets(bear, lattice, 3, 0.03 * size, rng, targets);
  vtkNew<vtkFFDDirectManipulation> manipulate;
  vtkSmartPointer<vtkPointSet> moved = Manipulate(lattice, bear, targets, manipulate);
  EXPECT_LE(Missed(bear, moved, targets), 1e-10 * size);
  // Each target moves by its tetrahedron's 4 nodes: at most 12 nodes move.
  EXPECT_GT(manipulate->GetNumberOfMovedControlPoints(), 0);
  EXPECT_LE(manipulate->GetNumberOfMovedControlPoints(), 12);
}

TEST(vtkFFDDirectManipulation, OnePointAskedToTwoPlacesGoesHalfWay)
{
  // The least-squares optimum of |F(x) - T1|^2 + |F(x) - T2|^2 is F(x) = (T1 + T2) / 2, which the lattice can give.
  vtkSmartPointer<vtkPolyData> cow = ReadTestMesh("cow");
  std::mt19937 rng(23);
  const int n[3] = { 3, 3, 3 };
  vtkSmartPointer<vtkPointSet> lattice =
    ffdtest::MovedLattice(cow, vtkFFDBuildLattice::CUBIC_BSPLINE, n, vtkFFDBuildLattice::SPARSE, rng, 0.0);
  const double size = ffdtest::Diagonal(ffdtest::FrameOf(lattice));
  Targets targets;
  const vtkIdType id = 100;
  double x[3];
  cow->GetPoint(id, x);
  targets.Ids->InsertNextValue(id);
  targets.Ids->InsertNextValue(id);
  targets.Positions->InsertNextPoint(x[0] + 0.05 * size, x[1], x[2]);
  targets.Positions->InsertNextPoint(x[0], x[1] + 0.05 * size, x[2]);
  vtkNew<vtkFFDDirectManipulation> manipulate;
  vtkSmartPointer<vtkPointSet> moved = Manipulate(lattice, cow, targets, manipulate);
  vtkNew<vtkFFDDeform> deform;
  deform->SetInputData(cow);
  deform->SetLatticeData(moved);
  deform->SetOutputPointsPrecision(vtkAlgorithm::DOUBLE_PRECISION);
  deform->Update();
  double y[3];
  vtkPointSet::SafeDownCast(deform->GetOutputDataObject(0))->GetPoint(id, y);
  const double half[3] = { x[0] + 0.025 * size, x[1] + 0.025 * size, x[2] };
  EXPECT_LE(std::sqrt(vtkMath::Distance2BetweenPoints(y, half)), 1e-10 * size);
  EXPECT_NEAR(manipulate->GetMaximumTargetDistance(), 0.025 * std::sqrt(2.0) * size, 1e-10 * size);

  // Regularised: the move is smaller and the targets farther.
  vtkNew<vtkFFDDirectManipulation> regularised;
  regularised->SetRegularization(0.5);
  vtkSmartPointer<vtkPointSet> gentle = Manipulate(lattice, cow, targets, regularised);
  double full = 0, less = 0;
  for (vtkIdType p = 0; p < lattice->GetNumberOfPoints(); ++p)
  {
    double a[3], b[3], c[3];
    lattice->GetPoint(p, a);
    moved->GetPoint(p, b);
    gentle->GetPoint(p, c);
    full += vtkMath::Distance2BetweenPoints(a, b);
    less += vtkMath::Distance2BetweenPoints(a, c);
  }
  EXPECT_LT(less, full);
  EXPECT_GT(regularised->GetMaximumTargetDistance(), manipulate->GetMaximumTargetDistance());
}

// More targets than the lattice can meet (40 points on a 2 x 2 x 2 trilinear lattice: 27 control points per
// coordinate): the result satisfies the least-squares optimality condition W^T (T - F(x)) = 0 for the reference's
// W. The move is computed by a backward-stable decomposition, so W^T r is rounding of the size
// eps |W| |r| cond(W); 1e-9 |W| |r| leaves room for cond(W) < 1e6 (these points are well spread: far less).
TEST(vtkFFDDirectManipulation, OverdeterminedTargetsMeetTheLeastSquaresCondition)
{
  vtkSmartPointer<vtkPolyData> bear = ReadTestMesh("bear");
  std::mt19937 rng(24);
  const int n[3] = { 2, 2, 2 };
  vtkSmartPointer<vtkPointSet> lattice =
    ffdtest::MovedLattice(bear, vtkFFDBuildLattice::TRILINEAR, n, vtkFFDBuildLattice::DENSE, rng, 0.02);
  const double size = ffdtest::Diagonal(ffdtest::FrameOf(lattice));
  Targets targets;
  ChooseTargets(bear, lattice, 40, 0.03 * size, rng, targets);
  vtkNew<vtkFFDDirectManipulation> manipulate;
  vtkSmartPointer<vtkPointSet> moved = Manipulate(lattice, bear, targets, manipulate);
  EXPECT_GT(Missed(bear, moved, targets), 1e-3 * size) << "the targets could all be met";

  const Eigen::MatrixXd w = ReferenceWeights(bear, targets, ffdtest::ReferenceOf(lattice));
  vtkNew<vtkFFDDeform> deform;
  deform->SetInputData(bear);
  deform->SetLatticeData(moved);
  deform->SetOutputPointsPrecision(vtkAlgorithm::DOUBLE_PRECISION);
  deform->Update();
  Eigen::MatrixXd r(w.rows(), 3);
  for (Eigen::Index t = 0; t < w.rows(); ++t)
  {
    double y[3], want[3];
    vtkPointSet::SafeDownCast(deform->GetOutputDataObject(0))->GetPoint(targets.Ids->GetValue(t), y);
    targets.Positions->GetPoint(t, want);
    for (int c = 0; c < 3; ++c)
    {
      r(t, c) = want[c] - y[c];
    }
  }
  EXPECT_LE((w.transpose() * r).norm(), 1e-9 * w.norm() * r.norm());
}

TEST(vtkFFDDirectManipulation, RefusesBadTargets)
{
  vtkSmartPointer<vtkPolyData> cow = ReadTestMesh("cow");
  std::mt19937 rng(24);
  const int n[3] = { 3, 3, 3 };
  vtkSmartPointer<vtkPointSet> lattice =
    ffdtest::MovedLattice(cow, vtkFFDBuildLattice::TRILINEAR, n, vtkFFDBuildLattice::SPARSE, rng, 0.0);
  struct Case
  {
    vtkIdType Id;
    int Positions;
    const char* Says;
  };
  for (const Case& c : { Case{ cow->GetNumberOfPoints(), 1, "names mesh point" }, Case{ -1, 1, "names mesh point" },
         Case{ 3, 2, "one position per id" } })
  {
    Targets targets;
    targets.Ids->InsertNextValue(c.Id);
    for (int i = 0; i < c.Positions; ++i)
    {
      targets.Positions->InsertNextPoint(0, 0, 0);
    }
    vtkNew<vtkFFDDirectManipulation> manipulate;
    vtkNew<FFDTestErrorObserver> errors;
    errors->WatchWithExecutive(manipulate);
    Manipulate(lattice, cow, targets, manipulate);
    EXPECT_NE(errors->Errors.find(c.Says), std::string::npos) << errors->Errors;
    EXPECT_EQ(manipulate->GetOutput()->GetNumberOfPoints(), 0);
  }
  // No mesh.
  Targets targets;
  targets.Ids->InsertNextValue(0);
  targets.Positions->InsertNextPoint(0, 0, 0);
  vtkNew<vtkFFDDirectManipulation> manipulate;
  vtkNew<FFDTestErrorObserver> errors;
  errors->WatchWithExecutive(manipulate);
  manipulate->SetInputData(lattice);
  manipulate->SetTargetPointIds(targets.Ids);
  manipulate->SetTargetPositions(targets.Positions);
  manipulate->Update();
  EXPECT_NE(errors->Errors.find("SetMeshConnection"), std::string::npos) << errors->Errors;
}

// Issue 30, item 7: targets whose mesh points are all outside the lattice left W without a column, and Eigen's
// decomposition of a count x 0 matrix crashed. Now nothing moves (the lattice as it is, bit for bit), a warning
// says why, and the distance reported is each target's from its point, which keeps its place outside.
TEST(vtkFFDDirectManipulation, TargetsAllOutsideTheLatticeMoveNothing)
{
  vtkSmartPointer<vtkPolyData> cow = ReadTestMesh("cow");
  std::mt19937 rng(25);
  const int n[3] = { 3, 3, 3 };
  for (int form : { vtkFFDBuildLattice::DENSE, vtkFFDBuildLattice::SPARSE })
  {
    vtkSmartPointer<vtkPointSet> lattice =
      ffdtest::MovedLattice(cow, vtkFFDBuildLattice::TRILINEAR, n, form, rng, 0.02);
    const double size = ffdtest::Diagonal(ffdtest::FrameOf(lattice));
    vtkSmartPointer<vtkPolyData> far = PointCloud({ { 10 * size, 0, 0 }, { 0, -10 * size, 3 * size } });
    Targets targets;
    for (vtkIdType id : { 0, 1 })
    {
      double x[3];
      far->GetPoint(id, x);
      targets.Ids->InsertNextValue(id);
      targets.Positions->InsertNextPoint(x[0] + 0.1 * size * (id + 1), x[1], x[2]); // 0.1 and 0.2 size away
    }
    vtkNew<vtkFFDDirectManipulation> manipulate;
    vtkNew<FFDTestErrorObserver> errors;
    errors->WatchWithExecutive(manipulate);
    vtkSmartPointer<vtkPointSet> moved = Manipulate(lattice, far, targets, manipulate);
    EXPECT_EQ(errors->Errors, "");
    EXPECT_NE(errors->Warnings.find("2 of the 2 targets lie outside the lattice"), std::string::npos)
      << errors->Warnings;
    ASSERT_EQ(moved->GetNumberOfPoints(), lattice->GetNumberOfPoints());
    EXPECT_TRUE(ffdtest::SamePoints(moved, lattice));
    EXPECT_EQ(manipulate->GetNumberOfMovedControlPoints(), 0);
    EXPECT_NEAR(manipulate->GetMaximumTargetDistance(), 0.2 * size, 1e-14 * size);
  }
}

// Issue 30, item 7: a target naming a mesh point with a non-finite coordinate crashed the solve (every target
// such a point: W without a column). A non-finite target position, or a NaN Regularization, went on to a
// non-finite solve. Each is an error that names the target or setting, with an empty output.
TEST(vtkFFDDirectManipulation, RefusesNonFiniteTargetsAndSettings)
{
  vtkSmartPointer<vtkPolyData> cow = ReadTestMesh("cow");
  std::mt19937 rng(26);
  const int n[3] = { 3, 3, 3 };
  vtkSmartPointer<vtkPointSet> lattice =
    ffdtest::MovedLattice(cow, vtkFFDBuildLattice::TRILINEAR, n, vtkFFDBuildLattice::DENSE, rng, 0.0);
  vtkNew<vtkPolyData> broken;
  broken->DeepCopy(cow);
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  broken->GetPoints()->SetPoint(7, nan, 0, 0);
  broken->GetPoints()->SetPoint(8, 0, inf, 0);
  struct Case
  {
    std::vector<vtkIdType> Ids;
    double Position;
    double Regularization;
    const char* Says;
  };
  for (const Case& c : { Case{ { 7 }, 0.0, 0.0, "names mesh point 7, whose coordinates" },
         Case{ { 8, 7 }, 0.0, 0.0, "names mesh point 8, whose coordinates" },
         Case{ { 9, 7 }, 0.0, 0.0, "Target 1 names mesh point 7" }, Case{ { 9 }, nan, 0.0, "Target position 0" },
         Case{ { 9 }, -inf, 0.0, "Target position 0" }, Case{ { 9 }, 0.0, nan, "SetRegularization()" } })
  {
    Targets targets;
    for (vtkIdType id : c.Ids)
    {
      targets.Ids->InsertNextValue(id);
      targets.Positions->InsertNextPoint(c.Position, 0, 0);
    }
    vtkNew<vtkFFDDirectManipulation> manipulate;
    manipulate->SetRegularization(c.Regularization);
    vtkNew<FFDTestErrorObserver> errors;
    errors->WatchWithExecutive(manipulate);
    Manipulate(lattice, broken, targets, manipulate);
    EXPECT_NE(errors->Errors.find(c.Says), std::string::npos) << errors->Errors;
    EXPECT_EQ(manipulate->GetOutput()->GetNumberOfPoints(), 0) << c.Says;
  }
}

// Issue 30, item 17: a missing or wrong-typed input failed with only the executive's "returned failure".
TEST(vtkFFDDirectManipulation, SaysWhichInputIsMissingOrWrong)
{
  vtkSmartPointer<vtkPolyData> cow = ReadTestMesh("cow");
  std::mt19937 rng(27);
  const int n[3] = { 2, 2, 2 };
  vtkNew<vtkFFDDirectManipulation> manipulate;
  manipulate->SetInputData(
    ffdtest::MovedLattice(cow, vtkFFDBuildLattice::TRILINEAR, n, vtkFFDBuildLattice::DENSE, rng, 0.0));
  manipulate->SetMeshData(cow);
  ffdtest::ExpectClearInputErrors(manipulate, 0, "the lattice", "SetInputConnection() to the lattice to move");
  ffdtest::ExpectClearInputErrors(manipulate, 1, "the mesh", "SetMeshConnection()", true);
}
