// SPDX-License-Identifier: BSD-3-Clause
// vtkFFDCoarsenLattice: a coarsening of an exact refinement returns the original control points; on a real mesh
// the result satisfies the normal equations of the least-squares problem, computed here from the float64
// reference's bases; the reported residual is the distance between the two deformations.

#include "FFDTestErrorObserver.h"
#include "FFDTestLattices.h"
#include "FFDTestMeshes.h"

#include "vtkFFDBuildTetrahedralLattice.h"
#include "vtkFFDCoarsenLattice.h"
#include "vtkFFDRefineLattice.h"
#include "vtkMath.h"
#include "vtkUnstructuredGrid.h"

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include <limits>
#include <random>

namespace
{
using ffdtest::Vec;
constexpr double Eps = std::numeric_limits<double>::epsilon();

const int Bases[] = { vtkFFDBuildLattice::BERNSTEIN, vtkFFDBuildLattice::TRILINEAR,
  vtkFFDBuildLattice::TRIQUADRATIC_BEZIER, vtkFFDBuildLattice::TRICUBIC_BEZIER, vtkFFDBuildLattice::CUBIC_BSPLINE };

vtkSmartPointer<vtkPointSet> MovedLattice(
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

/// W: the reference's weight of every control point of a dense lattice at every point of `mesh` inside it.
Eigen::MatrixXd ReferenceWeights(const ffdtest::Reference& lattice, vtkPointSet* mesh)
{
  Eigen::MatrixXd w = Eigen::MatrixXd::Zero(mesh->GetNumberOfPoints(), Eigen::Index(lattice.P.size()));
  const int nI = ffdref::PointsAlongAxis(lattice.Basis, lattice.N[0]);
  const int nJ = ffdref::PointsAlongAxis(lattice.Basis, lattice.N[1]);
  for (vtkIdType p = 0; p < mesh->GetNumberOfPoints(); ++p)
  {
    Vec x;
    mesh->GetPoint(p, x.data());
    if (!lattice.Inside(x))
    {
      continue;
    }
    Vec stu = ffdref::Parameters(lattice.F, x);
    std::vector<double> axes[3];
    for (int a = 0; a < 3; ++a)
    {
      axes[a] = ffdref::AxisWeights(lattice.Basis, lattice.N[a], std::clamp(stu[a], 0.0, 1.0));
    }
    for (std::size_t k = 0; k < axes[2].size(); ++k)
    {
      for (std::size_t j = 0; j < axes[1].size(); ++j)
      {
        for (std::size_t i = 0; i < axes[0].size(); ++i)
        {
          w(p, Eigen::Index(i + nI * (j + nJ * k))) = axes[0][i] * axes[1][j] * axes[2][k];
        }
      }
    }
  }
  return w;
}

/// The displacements (points minus rest) of a dense lattice, one row per control point.
Eigen::MatrixXd Displacements(const ffdtest::Reference& lattice)
{
  Eigen::MatrixXd x(Eigen::Index(lattice.P.size()), 3);
  for (std::size_t i = 0; i < lattice.P.size(); ++i)
  {
    for (int c = 0; c < 3; ++c)
    {
      x(Eigen::Index(i), c) = lattice.P[i][c] - lattice.Rest[i][c];
    }
  }
  return x;
}

vtkSmartPointer<vtkPointSet> Coarsen(vtkPointSet* lattice, vtkPointSet* mesh, vtkFFDCoarsenLattice* coarsen)
{
  coarsen->SetInputData(lattice);
  coarsen->SetMeshData(mesh);
  coarsen->Update();
  return coarsen->GetOutput();
}
} // namespace

TEST(vtkFFDCoarsenLattice, CoarseningARefinedLatticeReturnsTheOriginalControlPoints)
{
  // Random points filling a box: every voxel holds points, so every control point is determined.
  std::mt19937 rng(112601);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<std::array<double, 3>> xs(6000);
  for (auto& x : xs)
  {
    x = { u(rng), 0.7 * u(rng), 0.5 * u(rng) };
  }
  vtkSmartPointer<vtkPolyData> box = PointCloud(xs);
  for (int basis : Bases)
  {
    const int n[3] = { 2, 3, 2 };
    vtkSmartPointer<vtkPointSet> original = MovedLattice(box, basis, n, vtkFFDBuildLattice::DENSE, rng);
    vtkNew<vtkFFDRefineLattice> refine;
    refine->SetInputData(original);
    refine->Update();
    vtkNew<vtkFFDCoarsenLattice> coarsen;
    vtkSmartPointer<vtkPointSet> coarse = Coarsen(refine->GetOutput(), box, coarsen);
    ASSERT_EQ(coarse->GetNumberOfPoints(), original->GetNumberOfPoints());

    // The bound, in the solver's scaled unknowns y = D^(1/2) x (D = diag W^T W, from the reference's weights):
    // rounding leaves |y - y*| <= kappa (1000 eps) |y*| (kappa = cond(D^(-1/2) W^T W D^(-1/2)); a row of the
    // normal matrix sums at most 343 products of 3 factors), and four Tikhonov solves leave at most
    // (lambda / sigma_min^2)^4 |y*| of the regularisation.
    const ffdtest::Reference want = ffdtest::ReferenceOf(original);
    const Eigen::MatrixXd w = ReferenceWeights(want, box);
    const Eigen::MatrixXd a = w.transpose() * w;
    const Eigen::VectorXd s = a.diagonal().cwiseSqrt().cwiseInverse();
    const Eigen::VectorXd sigma2 =
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(s.asDiagonal() * a * s.asDiagonal()).eigenvalues();
    const double kappa = sigma2.maxCoeff() / sigma2.minCoeff();
    const Eigen::MatrixXd expected = Displacements(want), got = Displacements(ffdtest::ReferenceOf(coarse));
    const Eigen::MatrixXd scaledExpected = s.cwiseInverse().asDiagonal() * expected;
    const double bound =
      (kappa * 1000 * Eps + std::pow(coarsen->GetRegularization() / sigma2.minCoeff(), 4)) * scaledExpected.norm();
    EXPECT_LE((s.cwiseInverse().asDiagonal() * (got - expected)).cwiseAbs().maxCoeff(), bound)
      << vtkFFDBuildLattice::GetBasisAsString(basis) << ": kappa " << kappa;
    // A meaningful bound: the B-spline's outer ring, whose weights inside the frame are small and alike, makes its
    // kappa the largest (about 1e7 here).
    EXPECT_LT(bound, 1e-5 * scaledExpected.norm()) << "kappa " << kappa;
    // The residual of an exact fit is rounding only: |W (x - x*)| <= |y - y*| (W D^(-1/2) has columns of norm 1)
    // times sqrt(unknowns).
    EXPECT_LE(coarsen->GetMaximumResidual(), bound * std::sqrt(double(s.size())));
  }
}

TEST(vtkFFDCoarsenLattice, FitOnTheBearSatisfiesTheNormalEquations)
{
  vtkSmartPointer<vtkPolyData> bear = ReadTestMesh("bear");
  std::mt19937 rng(2611);
  for (int basis :
    { vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::TRICUBIC_BEZIER, vtkFFDBuildLattice::CUBIC_BSPLINE })
  {
    const int n[3] = { 6, 6, 6 };
    vtkSmartPointer<vtkPointSet> fine = MovedLattice(bear, basis, n, vtkFFDBuildLattice::DENSE, rng, 0.02);
    vtkNew<vtkFFDCoarsenLattice> coarsen;
    coarsen->SetDivisions(3, 3, 3);
    vtkSmartPointer<vtkPointSet> coarse = Coarsen(fine, bear, coarsen);
    ASSERT_GT(coarse->GetNumberOfPoints(), 0);

    // g = W^T (W X - d) + lambda X with the reference's weights and deformation (d from the fine lattice).
    const ffdtest::Reference c = ffdtest::ReferenceOf(coarse), f = ffdtest::ReferenceOf(fine);
    const Eigen::MatrixXd w = ReferenceWeights(c, bear);
    Eigen::MatrixXd d(bear->GetNumberOfPoints(), 3);
    for (vtkIdType p = 0; p < bear->GetNumberOfPoints(); ++p)
    {
      Vec x;
      bear->GetPoint(p, x.data());
      const Vec y = f.Deform(x);
      for (int a = 0; a < 3; ++a)
      {
        d(p, a) = y[a] - x[a];
      }
    }
    const Eigen::MatrixXd x = Displacements(c);
    const Eigen::MatrixXd wtw = w.transpose() * w;
    Eigen::VectorXd s = wtw.diagonal();
    for (Eigen::Index i = 0; i < s.size(); ++i)
    {
      s[i] = s[i] > 0 ? 1 / std::sqrt(s[i]) : 0.0; // culled control points: no row, no equation
    }
    const Eigen::MatrixXd g = s.asDiagonal() * (w.transpose() * d - wtw * x);
    const Eigen::MatrixXd y = s.cwiseInverse().cwiseMin(1e300).asDiagonal() * x;
    // Iterated Tikhonov leaves the scaled residual at lambda times its last correction, which is no larger than
    // the solution: |g| <= Regularization |y|. Recomputing it here adds the rounding of both sides' sums: at most
    // 2 (64 + 3) eps |W|^T (|d| + |W x|) + |A| |x| per entry (64 weights a point, 3 products), scaled.
    const Eigen::MatrixXd rounding = 2 * 67 * Eps * s.asDiagonal() *
      (w.cwiseAbs().transpose() * (d.cwiseAbs() + (w * x).cwiseAbs()) + wtw.cwiseAbs() * x.cwiseAbs());
    for (int a = 0; a < 3; ++a)
    {
      const double allowed = coarsen->GetRegularization() * y.col(a).norm() + rounding.col(a).norm();
      EXPECT_LE(g.col(a).norm(), allowed) << vtkFFDBuildLattice::GetBasisAsString(basis) << " axis " << a;
      EXPECT_LT(allowed, 1e-6 * (s.asDiagonal() * w.transpose() * d).col(a).norm()) << "a meaningful bound";
    }

    // The reported residual is the distance between the two lattices' deformations of the bear.
    double sum = 0, worst = 0;
    const Eigen::MatrixXd e = w * x - d;
    for (Eigen::Index p = 0; p < e.rows(); ++p)
    {
      sum += e.row(p).squaredNorm();
      worst = std::max(worst, e.row(p).norm());
    }
    const double size = ffdtest::Diagonal(c.F);
    EXPECT_NEAR(coarsen->GetResidualRMS(), std::sqrt(sum / double(e.rows())), 1e-12 * size);
    EXPECT_NEAR(coarsen->GetMaximumResidual(), worst, 1e-12 * size);
    EXPECT_GT(worst, 1e-4 * size) << "a random 6^3 deformation is not a 3^3 one";
  }
}

TEST(vtkFFDCoarsenLattice, SparseLatticesCoarsenAsTheirDenseCounterparts)
{
  vtkSmartPointer<vtkPolyData> cow = ReadTestMesh("cow");
  std::mt19937 rng(9);
  const int n[3] = { 8, 6, 4 };
  vtkSmartPointer<vtkPointSet> sparse =
    MovedLattice(cow, vtkFFDBuildLattice::CUBIC_BSPLINE, n, vtkFFDBuildLattice::SPARSE, rng);
  vtkNew<vtkFFDCoarsenLattice> coarsen;
  vtkSmartPointer<vtkPointSet> coarse = Coarsen(sparse, cow, coarsen);
  EXPECT_TRUE(coarse->IsA("vtkUnstructuredGrid"));
  int divisions[3];
  ASSERT_TRUE(vtkFFDDataContract::GetDivisions(coarse, divisions));
  EXPECT_EQ(divisions[0], 4);
  EXPECT_EQ(divisions[2], 2);
  // Its deformation of the cow is within the reported residual of the sparse input's.
  vtkNew<vtkFFDDeform> a, b;
  a->SetInputData(cow);
  a->SetLatticeData(sparse);
  b->SetInputData(cow);
  b->SetLatticeData(coarse);
  a->SetOutputPointsPrecision(vtkAlgorithm::DOUBLE_PRECISION);
  b->SetOutputPointsPrecision(vtkAlgorithm::DOUBLE_PRECISION);
  a->Update();
  b->Update();
  double worst = 0;
  for (vtkIdType p = 0; p < cow->GetNumberOfPoints(); ++p)
  {
    double x[3], y[3];
    vtkPointSet::SafeDownCast(a->GetOutputDataObject(0))->GetPoint(p, x);
    vtkPointSet::SafeDownCast(b->GetOutputDataObject(0))->GetPoint(p, y);
    worst = std::max(worst, std::sqrt(vtkMath::Distance2BetweenPoints(x, y)));
  }
  EXPECT_NEAR(worst, coarsen->GetMaximumResidual(), 1e-12 * ffdtest::Diagonal(ffdtest::FrameOf(coarse)));
}

TEST(vtkFFDCoarsenLattice, RefusesWhatItCannotCoarsen)
{
  vtkSmartPointer<vtkPolyData> cow = ReadTestMesh("cow");
  std::mt19937 rng(5);
  const int n[3] = { 4, 4, 4 };
  vtkSmartPointer<vtkPointSet> sparse =
    MovedLattice(cow, vtkFFDBuildLattice::TRILINEAR, n, vtkFFDBuildLattice::SPARSE, rng);
  vtkNew<vtkFFDBuildTetrahedralLattice> tetrahedra;
  tetrahedra->SetInputData(cow);
  tetrahedra->Update();
  struct Case
  {
    vtkPointSet* Lattice;
    vtkPointSet* Mesh;
    int Basis;
    const char* Says;
  };
  vtkNew<vtkPolyData> empty;
  const Case cases[] = {
    { sparse, empty, -1, "SetMeshConnection" },
    { tetrahedra->GetOutput(), cow, -1, "tetrahedral" },
    { sparse, cow, vtkFFDBuildLattice::BERNSTEIN, "BERNSTEIN" },
    { cow, cow, -1, "Cannot coarsen the input" },
  };
  for (const Case& c : cases)
  {
    vtkNew<vtkFFDCoarsenLattice> coarsen;
    vtkNew<FFDTestErrorObserver> errors;
    errors->WatchWithExecutive(coarsen);
    coarsen->SetBasis(c.Basis);
    Coarsen(c.Lattice, c.Mesh, coarsen);
    EXPECT_NE(errors->Errors.find(c.Says), std::string::npos) << errors->Errors;
    EXPECT_EQ(coarsen->GetOutput()->GetNumberOfPoints(), 0);
  }
}
