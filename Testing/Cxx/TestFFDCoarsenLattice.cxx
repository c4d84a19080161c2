// SPDX-License-Identifier: BSD-3-Clause
// vtkFFDCoarsenLattice: a coarsening of an exact refinement returns the original control points; on a real mesh
// the result satisfies the normal equations of the least-squares problem, computed here from the float64
// reference's bases; the reported residual is the distance between the two deformations.

#include "FFDTestErrorObserver.h"
#include "FFDTestInputChecks.h"
#include "FFDTestLattices.h"
#include "FFDTestMeshes.h"

#include "vtkFFDBuildTetrahedralLattice.h"
#include "vtkFFDCoarsenLattice.h"
#include "vtkFFDRefineLattice.h"
#include "vtkMath.h"
#include "vtkUnstructuredGrid.h"

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>

namespace
{
using ffdtest::MovedLattice;
using ffdtest::Vec;
constexpr double Eps = std::numeric_limits<double>::epsilon();

const int Bases[] = { vtkFFDBuildLattice::BERNSTEIN, vtkFFDBuildLattice::TRILINEAR,
  vtkFFDBuildLattice::TRIQUADRATIC_BEZIER, vtkFFDBuildLattice::TRICUBIC_BEZIER, vtkFFDBuildLattice::CUBIC_BSPLINE };

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

/// R: the sum over the active control points b with both neighbours a, c along an axis active too of
/// (x_a - 2 x_b + x_c)^2, as a matrix (`active` empty: every control point active).
Eigen::MatrixXd SmoothnessOf(const ffdtest::Reference& lattice, const std::vector<bool>& active = {})
{
  auto on = [&](Eigen::Index p) { return active.empty() || active[std::size_t(p)]; };
  const int dims[3] = { ffdref::PointsAlongAxis(lattice.Basis, lattice.N[0]),
    ffdref::PointsAlongAxis(lattice.Basis, lattice.N[1]), ffdref::PointsAlongAxis(lattice.Basis, lattice.N[2]) };
  const Eigen::Index n = Eigen::Index(lattice.P.size());
  Eigen::MatrixXd r = Eigen::MatrixXd::Zero(n, n);
  for (int k = 0; k < dims[2]; ++k)
  {
    for (int j = 0; j < dims[1]; ++j)
    {
      for (int i = 0; i < dims[0]; ++i)
      {
        const int p[3] = { i, j, k };
        for (int axis = 0; axis < 3; ++axis)
        {
          if (p[axis] == 0 || p[axis] == dims[axis] - 1)
          {
            continue;
          }
          const Eigen::Index stride = axis == 0 ? 1 : (axis == 1 ? dims[0] : dims[0] * dims[1]);
          const Eigen::Index centre = i + dims[0] * (j + Eigen::Index(dims[1]) * k);
          if (!on(centre - stride) || !on(centre) || !on(centre + stride))
          {
            continue;
          }
          const Eigen::Index at[3] = { centre - stride, centre, centre + stride };
          const double coefficient[3] = { 1, -2, 1 };
          for (int u = 0; u < 3; ++u)
          {
            for (int v = 0; v < 3; ++v)
            {
              r(at[u], at[v]) += coefficient[u] * coefficient[v];
            }
          }
        }
      }
    }
  }
  return r;
}

std::vector<bool> ActiveOf(vtkPointSet* lattice)
{
  vtkDataArray* active = lattice->GetPointData()->GetArray("Active");
  std::vector<bool> on(std::size_t(lattice->GetNumberOfPoints()));
  for (vtkIdType p = 0; p < lattice->GetNumberOfPoints(); ++p)
  {
    on[std::size_t(p)] = active->GetComponent(p, 0) != 0;
  }
  return on;
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
    coarsen->SetRegularization(1e-12);
    vtkSmartPointer<vtkPointSet> coarse = Coarsen(refine->GetOutput(), box, coarsen);
    ASSERT_EQ(coarse->GetNumberOfPoints(), original->GetNumberOfPoints());

    // The bound (docs/level-of-detail.md; Filters/LevelOfDetail/FFDLeastSquares.h): the solver takes eight steps of
    // iterated Tikhonov with M = A + lambda R', A = W^T W (here from the reference's weights), R' the control
    // net's squared second differences plus 1e-6 I, lambda = Regularization mean(diag A). In the generalised
    // eigenvectors A v = mu R' v (R'-orthonormal) each step leaves lambda / (mu + lambda) of a component's error,
    // so |x - x*|_R' <= q^8 |x*|_R' with q = lambda / (mu_min + lambda), and in Euclidean norms
    // |x - x*| <= sqrt(cond(R')) q^8 |x*|. Rounding adds kappa (1000 eps) |x*| (kappa = cond(S A S), S the solver's
    // Jacobi scaling; a row of A sums at most 343 products of 3 factors).
    const ffdtest::Reference want = ffdtest::ReferenceOf(original);
    const Eigen::MatrixXd w = ReferenceWeights(want, box);
    const Eigen::MatrixXd a = w.transpose() * w;
    const Eigen::MatrixXd r = SmoothnessOf(want) + 1e-6 * Eigen::MatrixXd::Identity(a.rows(), a.cols());
    const double lambda = coarsen->GetRegularization() * a.trace() / double(a.rows());
    const Eigen::VectorXd mu = Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd>(a, r).eigenvalues();
    const Eigen::VectorXd rho = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(r).eigenvalues();
    const Eigen::VectorXd s = (a + lambda * r).diagonal().cwiseSqrt().cwiseInverse();
    const Eigen::VectorXd sigma2 =
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(s.asDiagonal() * a * s.asDiagonal()).eigenvalues();
    const double kappa = sigma2.maxCoeff() / sigma2.minCoeff();
    const double q = lambda / (mu.minCoeff() + lambda);
    const Eigen::MatrixXd expected = Displacements(want), got = Displacements(ffdtest::ReferenceOf(coarse));
    const double bound =
      (std::sqrt(rho.maxCoeff() / rho.minCoeff()) * std::pow(q, 8) + kappa * 1000 * Eps) * expected.norm();
    EXPECT_LE((got - expected).cwiseAbs().maxCoeff(), bound)
      << vtkFFDBuildLattice::GetBasisAsString(basis) << ": kappa " << kappa << ", q " << q;
    // A meaningful bound: the B-spline's outer ring, whose weights inside the frame are small and alike, makes its
    // kappa the largest (about 1e7 here).
    EXPECT_LT(bound, 1e-5 * expected.norm()) << "kappa " << kappa << ", q " << q;
    // The residual of an exact fit: |W (x - x*)| <= |x - x*| |W|, |W| <= sqrt(max diag A) sqrt(unknowns).
    EXPECT_LE(coarsen->GetMaximumResidual(), bound * std::sqrt(a.diagonal().maxCoeff() * double(a.rows())));
  }
}

TEST(vtkFFDCoarsenLattice, FitOnTheCowIsTheLeastSquaresFitAndRegularizationTradesItForSmoothness)
{
  vtkSmartPointer<vtkPolyData> cow = ReadTestMesh("cow");
  std::mt19937 rng(2611);
  for (int basis : { vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::TRIQUADRATIC_BEZIER,
         vtkFFDBuildLattice::TRICUBIC_BEZIER, vtkFFDBuildLattice::CUBIC_BSPLINE })
  {
    const int n[3] = { 6, 6, 6 };
    vtkSmartPointer<vtkPointSet> fine = MovedLattice(cow, basis, n, vtkFFDBuildLattice::DENSE, rng, 0.02);
    vtkNew<vtkFFDCoarsenLattice> coarsen;
    coarsen->SetDivisions(3, 3, 3);
    // The higher degrees' least-squares fits on the cow's surface are wild (control points the surface barely
    // touches take values of 1e6 and more: |x*|_R'^2 is 6e12 to 1e15 here), so the bound below says little for
    // them (it still holds); they are what Regularization is for. The trilinear fit is tame.
    const bool tame = basis == vtkFFDBuildLattice::TRILINEAR;
    coarsen->SetRegularization(1e-12);
    vtkSmartPointer<vtkPointSet> coarse = Coarsen(fine, cow, coarsen);
    ASSERT_GT(coarse->GetNumberOfPoints(), 0);

    // The least-squares fit x* (minimum norm) by the reference: W from its bases, d from its deformation by the
    // fine lattice, Eigen's complete orthogonal decomposition. With the bound of the round-trip test above, the
    // filter's sum of squares exceeds the least one, f(x) - f(x*) = (x - x*)^T A (x - x*), by at most
    // max_mu mu (lambda / (mu + lambda))^16 |x*|_R'^2 <= lambda max_t t / (1 + t)^16 |x*|_R'^2 = 0.0231 lambda
    // |x*|_R'^2, plus the rounding of the two sums (1e-12 of them).
    const ffdtest::Reference c = ffdtest::ReferenceOf(coarse), f = ffdtest::ReferenceOf(fine);
    const Eigen::MatrixXd w = ReferenceWeights(c, cow);
    Eigen::MatrixXd d(cow->GetNumberOfPoints(), 3);
    for (vtkIdType p = 0; p < cow->GetNumberOfPoints(); ++p)
    {
      ffdtest::Vec x;
      cow->GetPoint(p, x.data());
      const ffdtest::Vec y = f.Deform(x);
      for (int a = 0; a < 3; ++a)
      {
        d(p, a) = y[a] - x[a];
      }
    }
    const Eigen::MatrixXd best = Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd>(w).solve(d);
    const Eigen::MatrixXd x = Displacements(c);
    const Eigen::MatrixXd a = w.transpose() * w;
    Eigen::MatrixXd r = 1e-6 * Eigen::MatrixXd::Identity(a.rows(), a.cols());
    r += SmoothnessOf(c, ActiveOf(coarse));
    const double lambda = coarsen->GetRegularization() * a.trace() / double(a.rows());
    const double least = (w * best - d).squaredNorm(), got = (w * x - d).squaredNorm();
    const double allowed = 0.0231 * lambda * (best.transpose() * r * best).trace() + 1e-12 * least;
    EXPECT_GE(got, least * (1 - 1e-12)) << vtkFFDBuildLattice::GetBasisAsString(basis);
    EXPECT_LE(got - least, allowed) << vtkFFDBuildLattice::GetBasisAsString(basis);
    if (tame)
    {
      EXPECT_LT(allowed, 1e-6 * least) << "a meaningful bound";
    }

    // The reported residual is the distance between the two lattices' deformations of the cow.
    const Eigen::MatrixXd e = w * x - d;
    double worst = 0;
    for (Eigen::Index p = 0; p < e.rows(); ++p)
    {
      worst = std::max(worst, e.row(p).norm());
    }
    const double size = ffdtest::Diagonal(c.F);
    EXPECT_NEAR(coarsen->GetResidualRMS(), std::sqrt(got / double(e.rows())), 1e-12 * size);
    EXPECT_NEAR(coarsen->GetMaximumResidual(), worst, 1e-12 * size);
    EXPECT_GT(worst, 1e-4 * size) << "a random 6^3 deformation is not a 3^3 one";

    // A larger Regularization gives a smoother control net (smaller x^T R x) for a larger residual.
    coarsen->SetRegularization(1e-4);
    const Eigen::MatrixXd smooth = Displacements(ffdtest::ReferenceOf(Coarsen(fine, cow, coarsen)));
    EXPECT_LT((smooth.transpose() * r * smooth).trace(), (x.transpose() * r * x).trace());
    EXPECT_GT((w * smooth - d).squaredNorm(), got);
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
  const int eight[3] = { 8, 8, 8 };
  vtkSmartPointer<vtkPointSet> bspline =
    MovedLattice(cow, vtkFFDBuildLattice::CUBIC_BSPLINE, eight, vtkFFDBuildLattice::DENSE, rng);
  vtkNew<vtkFFDBuildTetrahedralLattice> tetrahedra;
  tetrahedra->SetInputData(cow);
  tetrahedra->Update();
  struct Case
  {
    vtkPointSet* Lattice;
    vtkPointSet* Mesh;
    int Basis;
    const char* Says;
    double Regularization = 1e-6;
  };
  vtkNew<vtkPolyData> empty;
  const Case cases[] = {
    { sparse, empty, -1, "SetMeshConnection" },
    { tetrahedra->GetOutput(), cow, -1, "tetrahedral" },
    { sparse, cow, vtkFFDBuildLattice::BERNSTEIN, "BERNSTEIN" },
    { cow, cow, -1, "Cannot coarsen the input" },
    // A 4^3 cubic B-spline lattice has control points that no point of the cow weighs, or not enough to
    // determine: without regularisation there is no unique fit.
    { bspline, cow, -1, "undetermined", 0.0 },
    // Issue 30, item 1: a NaN passed the setter's clamp and failed the solve with the message above.
    { sparse, cow, -1, "give SetRegularization() a number from 0 to 1", std::numeric_limits<double>::quiet_NaN() },
  };
  for (const Case& c : cases)
  {
    vtkNew<vtkFFDCoarsenLattice> coarsen;
    vtkNew<FFDTestErrorObserver> errors;
    errors->WatchWithExecutive(coarsen);
    coarsen->SetBasis(c.Basis);
    coarsen->SetRegularization(c.Regularization);
    Coarsen(c.Lattice, c.Mesh, coarsen);
    EXPECT_NE(errors->Errors.find(c.Says), std::string::npos) << errors->Errors;
    EXPECT_EQ(coarsen->GetOutput()->GetNumberOfPoints(), 0);
  }
}

TEST(vtkFFDCoarsenLattice, FitsADeformedMeshAsTheLatticeThatDeformedIt)
{
  // Input 2 given: the fit reproduces its points, here those of the lattice on input 0 (deformed in float64,
  // as the filter deforms it itself), so both fits are the same, bit for bit.
  vtkSmartPointer<vtkPolyData> cow = ReadTestMesh("cow");
  std::mt19937 rng(13);
  const int n[3] = { 6, 4, 4 };
  vtkSmartPointer<vtkPointSet> fine =
    MovedLattice(cow, vtkFFDBuildLattice::CUBIC_BSPLINE, n, vtkFFDBuildLattice::SPARSE, rng);
  vtkNew<vtkFFDDeform> deform;
  deform->SetInputData(cow);
  deform->SetLatticeData(fine);
  deform->SetTransformNormals(false);
  deform->SetOutputPointsPrecision(vtkAlgorithm::DOUBLE_PRECISION);
  deform->Update();
  vtkNew<vtkFFDCoarsenLattice> fromLattice, fromMesh;
  vtkSmartPointer<vtkPointSet> a = Coarsen(fine, cow, fromLattice);
  fromMesh->SetDeformedMeshData(deform->GetOutputDataObject(0));
  vtkSmartPointer<vtkPointSet> b = Coarsen(fine, cow, fromMesh);
  ASSERT_EQ(a->GetNumberOfPoints(), b->GetNumberOfPoints());
  ASSERT_GT(a->GetNumberOfPoints(), 0);
  vtkIdType different = 0;
  for (vtkIdType p = 0; p < a->GetNumberOfPoints(); ++p)
  {
    double x[3], y[3];
    a->GetPoint(p, x);
    b->GetPoint(p, y);
    different += x[0] != y[0] || x[1] != y[1] || x[2] != y[2];
  }
  EXPECT_EQ(different, 0);

  // A deformed mesh of another point count is refused.
  vtkSmartPointer<vtkPolyData> bear = ReadTestMesh("bear");
  vtkNew<vtkFFDCoarsenLattice> mismatched;
  vtkNew<FFDTestErrorObserver> errors;
  errors->WatchWithExecutive(mismatched);
  mismatched->SetDeformedMeshData(bear);
  Coarsen(fine, cow, mismatched);
  EXPECT_NE(errors->Errors.find("same points"), std::string::npos) << errors->Errors;
}

// Issue 30, item 17: a missing or wrong-typed input failed with only the executive's "returned failure".
TEST(vtkFFDCoarsenLattice, SaysWhichInputIsMissingOrWrong)
{
  vtkSmartPointer<vtkPolyData> cow = ReadTestMesh("cow");
  std::mt19937 rng(31);
  const int n[3] = { 4, 4, 4 };
  vtkNew<vtkFFDCoarsenLattice> coarsen;
  coarsen->SetInputData(MovedLattice(cow, vtkFFDBuildLattice::TRILINEAR, n, vtkFFDBuildLattice::DENSE, rng, 0.01));
  coarsen->SetMeshData(cow);
  ffdtest::ExpectClearInputErrors(coarsen, 0, "the lattice", "SetInputConnection() to a grid lattice");
  ffdtest::ExpectClearInputErrors(coarsen, 1, "the mesh", "SetMeshConnection()");
  ffdtest::ExpectClearInputErrors(coarsen, 2, "the deformed mesh", "SetDeformedMeshConnection()", true);
}

// Issue 30, item 16: a mesh point with a NaN coordinate made the residuals NaN and the fit reported success; one
// deformed to NaN (input 2) failed the solve with a message about Regularization. Such points are left out of the
// fit and of the residuals, with a warning: the fit is the one without them, bit for bit, and its residuals too.
TEST(vtkFFDCoarsenLattice, LeavesNonFinitePointsOutAndSaysSo)
{
  vtkSmartPointer<vtkPolyData> cow = ReadTestMesh("cow");
  std::mt19937 rng(35);
  const int n[3] = { 4, 4, 4 };
  vtkSmartPointer<vtkPointSet> fine =
    MovedLattice(cow, vtkFFDBuildLattice::TRIQUADRATIC_BEZIER, n, vtkFFDBuildLattice::DENSE, rng, 0.02);
  vtkNew<vtkFFDCoarsenLattice> clean;
  vtkSmartPointer<vtkPointSet> want = Coarsen(fine, cow, clean);
  ASSERT_GT(want->GetNumberOfPoints(), 0);

  // The cow and two more points, after its own (so that the rows of the fit are the same), NaN and infinite.
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  const vtkIdType count = cow->GetNumberOfPoints();
  vtkNew<vtkPolyData> broken;
  broken->DeepCopy(cow);
  broken->GetPoints()->InsertNextPoint(nan, 0, 0);
  broken->GetPoints()->InsertNextPoint(0, 0, -inf);
  vtkNew<vtkFFDCoarsenLattice> coarsen;
  vtkNew<FFDTestErrorObserver> errors;
  errors->WatchWithExecutive(coarsen);
  vtkSmartPointer<vtkPointSet> got = Coarsen(fine, broken, coarsen);
  EXPECT_EQ(errors->Errors, "");
  const std::string said = "2 of the mesh's " + std::to_string(count + 2) + " points (the first: point " +
    std::to_string(count) + ") have a NaN or infinite coordinate";
  EXPECT_NE(errors->Warnings.find(said), std::string::npos) << errors->Warnings;
  ASSERT_EQ(got->GetNumberOfPoints(), want->GetNumberOfPoints());
  EXPECT_TRUE(ffdtest::SamePoints(got, want));
  EXPECT_EQ(coarsen->GetResidualRMS(), clean->GetResidualRMS());
  EXPECT_EQ(coarsen->GetMaximumResidual(), clean->GetMaximumResidual());

  // A point deformed to NaN (input 2): left out, the fit and residuals finite.
  vtkNew<vtkFFDDeform> deform;
  deform->SetInputData(cow);
  deform->SetLatticeData(fine);
  deform->SetOutputPointsPrecision(vtkAlgorithm::DOUBLE_PRECISION);
  deform->Update();
  vtkNew<vtkPolyData> deformed;
  deformed->DeepCopy(deform->GetOutputDataObject(0));
  deformed->GetPoints()->SetPoint(5, nan, nan, nan);
  vtkNew<vtkFFDCoarsenLattice> fromMesh;
  vtkNew<FFDTestErrorObserver> meshErrors;
  meshErrors->WatchWithExecutive(fromMesh);
  fromMesh->SetDeformedMeshData(deformed);
  got = Coarsen(fine, cow, fromMesh);
  EXPECT_EQ(meshErrors->Errors, "");
  EXPECT_NE(meshErrors->Warnings.find("(the first: point 5)"), std::string::npos) << meshErrors->Warnings;
  EXPECT_EQ(got->GetNumberOfPoints(), want->GetNumberOfPoints());
  EXPECT_TRUE(std::isfinite(fromMesh->GetResidualRMS()) && std::isfinite(fromMesh->GetMaximumResidual()));

  // No finite point at all: an error.
  vtkNew<vtkPolyData> none;
  none->DeepCopy(broken);
  for (vtkIdType p = 0; p < none->GetNumberOfPoints(); ++p)
  {
    none->GetPoints()->SetPoint(p, nan, nan, nan);
  }
  vtkNew<vtkFFDCoarsenLattice> nothing;
  vtkNew<FFDTestErrorObserver> nothingErrors;
  nothingErrors->WatchWithExecutive(nothing);
  Coarsen(fine, none, nothing);
  EXPECT_NE(nothingErrors->Errors.find("has a finite position"), std::string::npos) << nothingErrors->Errors;
  EXPECT_EQ(nothing->GetOutput()->GetNumberOfPoints(), 0);
}

// A sibling of issue 30, item 7: a mesh wholly outside the lattice's frame gave, dense, "Could not build the
// coarse lattice (see the error above)" with no error above, and, sparse, a lattice fitted to nothing. Both say
// that no point lies in the frame.
TEST(vtkFFDCoarsenLattice, RefusesAMeshOutsideTheLatticesFrame)
{
  vtkSmartPointer<vtkPolyData> cow = ReadTestMesh("cow");
  std::mt19937 rng(37);
  const int n[3] = { 4, 4, 4 };
  for (int form : { vtkFFDBuildLattice::DENSE, vtkFFDBuildLattice::SPARSE })
  {
    vtkSmartPointer<vtkPointSet> fine = MovedLattice(cow, vtkFFDBuildLattice::CUBIC_BSPLINE, n, form, rng, 0.02);
    const double size = ffdtest::Diagonal(ffdtest::FrameOf(fine));
    vtkNew<vtkPolyData> far;
    far->DeepCopy(cow);
    for (vtkIdType p = 0; p < far->GetNumberOfPoints(); ++p)
    {
      double x[3];
      far->GetPoint(p, x);
      far->GetPoints()->SetPoint(p, x[0] + 10 * size, x[1], x[2]);
    }
    vtkNew<vtkFFDCoarsenLattice> coarsen;
    vtkNew<FFDTestErrorObserver> errors;
    errors->WatchWithExecutive(coarsen);
    Coarsen(fine, far, coarsen);
    EXPECT_NE(errors->Errors.find("lies in the lattice's frame: there is nothing to fit"), std::string::npos)
      << errors->Errors;
    EXPECT_EQ(coarsen->GetOutput()->GetNumberOfPoints(), 0);
  }
}
