// SPDX-License-Identifier: BSD-3-Clause
// vtkFFDRefineLattice: a refined lattice deforms as the lattice it came from, for every basis and form.
//
// Tolerance: the coarse and the refined deformations are float64 sums of at most (n+1)^3 <= 35 937 products of
// weights (a partition of unity) and displacements |d| <= the perturbation; each refined displacement is itself
// such a sum with dyadic (or once-rounded) weights. Each side is within (terms + 3) eps |d| of the exact value and
// terms <= 64 for the local bases, (2n+1)^3 for Bernstein: 1e-12 of the frame's diagonal bounds it with room
// (the requirement), the perturbation being 5% of the diagonal.

#include "FFDTestErrorObserver.h"
#include "FFDTestInputChecks.h"
#include "FFDTestLattices.h"
#include "FFDTestMeshes.h"
#include "FFDTestTetrahedra.h"

#include "vtkFFDBuildTetrahedralLattice.h"
#include "vtkFFDRefineLattice.h"
#include "vtkMath.h"
#include "vtkUnsignedCharArray.h"
#include "vtkUnstructuredGrid.h"

#include <gtest/gtest.h>

#include <random>

namespace
{
using ffdtest::MovedLattice;
using ffdtest::Vec;

const int Bases[] = { vtkFFDBuildLattice::BERNSTEIN, vtkFFDBuildLattice::TRILINEAR,
  vtkFFDBuildLattice::TRIQUADRATIC_BEZIER, vtkFFDBuildLattice::TRICUBIC_BEZIER, vtkFFDBuildLattice::CUBIC_BSPLINE };

vtkSmartPointer<vtkPointSet> Refine(vtkPointSet* lattice, int levels = 1)
{
  vtkNew<vtkFFDRefineLattice> refine;
  refine->SetInputData(lattice);
  refine->SetLevels(levels);
  refine->Update();
  return refine->GetOutput();
}

vtkSmartPointer<vtkPointSet> Deformed(vtkPointSet* mesh, vtkPointSet* lattice)
{
  vtkNew<vtkFFDDeform> deform;
  deform->SetInputData(mesh);
  deform->SetLatticeData(lattice);
  deform->SetOutputPointsPrecision(vtkAlgorithm::DOUBLE_PRECISION);
  deform->Update();
  return vtkPointSet::SafeDownCast(deform->GetOutputDataObject(0));
}

/// Random points filling the box [0, 1] x [0, 0.6] x [0, 0.4]: every voxel of a few divisions holds some.
vtkSmartPointer<vtkPolyData> FilledBox(std::mt19937& rng, int count)
{
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<std::array<double, 3>> xs(count);
  for (auto& x : xs)
  {
    x = { u(rng), 0.6 * u(rng), 0.4 * u(rng) };
  }
  return PointCloud(xs);
}
} // namespace

TEST(vtkFFDRefineLattice, DeformsTheBearAsTheCoarseLatticeForEveryBasisAndForm)
{
  vtkSmartPointer<vtkPolyData> bear = ReadTestMesh("bear");
  std::mt19937 rng(1126);
  for (int basis : Bases)
  {
    for (int form : { vtkFFDBuildLattice::DENSE, vtkFFDBuildLattice::SPARSE })
    {
      if (basis == vtkFFDBuildLattice::BERNSTEIN && form == vtkFFDBuildLattice::SPARSE)
      {
        continue;
      }
      const int n[3] = { 3, 4, 5 };
      vtkSmartPointer<vtkPointSet> coarse = MovedLattice(bear, basis, n, form, rng);
      vtkSmartPointer<vtkPointSet> fine = Refine(coarse);
      int fineDivisions[3];
      ASSERT_TRUE(vtkFFDDataContract::GetDivisions(fine, fineDivisions));
      EXPECT_EQ(fineDivisions[0], 6);
      EXPECT_EQ(fineDivisions[2], 10);
      EXPECT_EQ(fine->GetDataObjectType(), coarse->GetDataObjectType());
      const double size = ffdtest::Diagonal(ffdtest::FrameOf(coarse));
      vtkSmartPointer<vtkPointSet> expected = Deformed(bear, coarse);
      EXPECT_LE(LargestDistance(Deformed(bear, fine), expected), 1e-12 * size)
        << vtkFFDBuildLattice::GetBasisAsString(basis) << (form == vtkFFDBuildLattice::SPARSE ? " sparse" : " dense");
      // The deformation moved the bear (the comparison is not between two identities).
      EXPECT_GT(LargestDistance(expected, bear), 0.01 * size);
      // Twice refined (n -> 4n) too.
      EXPECT_LE(LargestDistance(Deformed(bear, Refine(coarse, 2)), expected), 1e-12 * size)
        << vtkFFDBuildLattice::GetBasisAsString(basis) << " refined twice";
    }
  }
}

TEST(vtkFFDRefineLattice, RefinedLatticeEqualsTheCoarseFunctionEverywhereInTheFrame)
{
  // Every voxel active, so the dense lattices' functions can be compared at any parameter by the reference.
  std::mt19937 rng(2611);
  vtkSmartPointer<vtkPolyData> box = FilledBox(rng, 20000);
  std::uniform_real_distribution<double> u(0, 1);
  for (int basis : Bases)
  {
    const int n[3] = { 2, 3, 2 };
    vtkSmartPointer<vtkPointSet> coarse = MovedLattice(box, basis, n, vtkFFDBuildLattice::DENSE, rng);
    vtkSmartPointer<vtkPointSet> fine = Refine(coarse);
    ASSERT_EQ(fine->GetPointData()->GetArray("Active")->GetRange()[0], 1.0) << "every control point stays active";
    const ffdtest::Reference c = ffdtest::ReferenceOf(coarse), f = ffdtest::ReferenceOf(fine);
    const double size = ffdtest::Diagonal(c.F);
    for (int sample = 0; sample < 500; ++sample)
    {
      const Vec stu = { u(rng), u(rng), u(rng) };
      const Vec a = ffdref::EvaluateLocal(c.Basis, c.N, c.P, stu), b = ffdref::EvaluateLocal(f.Basis, f.N, f.P, stu);
      for (int axis = 0; axis < 3; ++axis)
      {
        EXPECT_NEAR(a[axis], b[axis], 1e-12 * size) << vtkFFDBuildLattice::GetBasisAsString(basis);
      }
    }
    // The rest positions are those of the finer lattice by definition.
    const std::vector<Vec> rest = ffdref::RestLattice(f.Basis, f.F, f.N);
    vtkDataArray* restArray = fine->GetPointData()->GetArray("RestPosition");
    for (vtkIdType p = 0; p < fine->GetNumberOfPoints(); p += 7)
    {
      for (int axis = 0; axis < 3; ++axis)
      {
        EXPECT_NEAR(restArray->GetComponent(p, axis), rest[p][axis], 1e-15 * size);
      }
    }
  }
}

TEST(vtkFFDRefineLattice, SparseRefinementIsTheDenseOnesActivePartBitForBit)
{
  vtkSmartPointer<vtkPolyData> elephant = ReadTestMesh("elephant");
  for (int basis :
    { vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::TRICUBIC_BEZIER, vtkFFDBuildLattice::CUBIC_BSPLINE })
  {
    const int n[3] = { 5, 4, 6 };
    std::mt19937 denseRng(7), sparseRng(7);
    vtkSmartPointer<vtkPointSet> dense = MovedLattice(elephant, basis, n, vtkFFDBuildLattice::DENSE, denseRng);
    // The same displacements on the sparse lattice's points (each a dense point by its LatticeIndex).
    vtkSmartPointer<vtkPointSet> sparse = MovedLattice(elephant, basis, n, vtkFFDBuildLattice::SPARSE, sparseRng);
    int dims[3];
    vtkStructuredGrid::SafeDownCast(dense)->GetDimensions(dims);
    vtkDataArray* index = sparse->GetPointData()->GetArray("LatticeIndex");
    for (vtkIdType p = 0; p < sparse->GetNumberOfPoints(); ++p)
    {
      const vtkIdType q = vtkIdType(index->GetComponent(p, 0)) +
        dims[0] * (vtkIdType(index->GetComponent(p, 1)) + dims[1] * vtkIdType(index->GetComponent(p, 2)));
      sparse->GetPoints()->SetPoint(p, dense->GetPoint(q));
    }
    vtkSmartPointer<vtkPointSet> fineDense = Refine(dense), fineSparse = Refine(sparse);
    vtkStructuredGrid::SafeDownCast(fineDense)->GetDimensions(dims);
    index = fineSparse->GetPointData()->GetArray("LatticeIndex");
    vtkDataArray* active = fineDense->GetPointData()->GetArray("Active");
    vtkIdType mismatches = 0, activeDense = 0;
    for (vtkIdType q = 0; q < fineDense->GetNumberOfPoints(); ++q)
    {
      activeDense += active->GetComponent(q, 0) != 0;
    }
    // A dense lattice's active region is the voxels whose support is active: those with points and maybe more.
    EXPECT_LE(fineSparse->GetNumberOfPoints(), activeDense);
    for (vtkIdType p = 0; p < fineSparse->GetNumberOfPoints(); ++p)
    {
      const vtkIdType q = vtkIdType(index->GetComponent(p, 0)) +
        dims[0] * (vtkIdType(index->GetComponent(p, 1)) + dims[1] * vtkIdType(index->GetComponent(p, 2)));
      double a[3], b[3];
      fineSparse->GetPoint(p, a);
      fineDense->GetPoint(q, b);
      mismatches += active->GetComponent(q, 0) == 0 || a[0] != b[0] || a[1] != b[1] || a[2] != b[2];
    }
    EXPECT_EQ(mismatches, 0) << vtkFFDBuildLattice::GetBasisAsString(basis);
  }
}

TEST(vtkFFDRefineLattice, ALatticeAtRestRefinesToTheFinerLatticeAtRest)
{
  vtkSmartPointer<vtkPolyData> cow = ReadTestMesh("cow");
  std::mt19937 rng(3);
  for (int basis : Bases)
  {
    const int n[3] = { 4, 3, 2 }, twice[3] = { 8, 6, 4 };
    vtkSmartPointer<vtkPointSet> coarse = MovedLattice(cow, basis, n, vtkFFDBuildLattice::AUTOMATIC, rng, 0.0);
    vtkSmartPointer<vtkPointSet> fine = Refine(coarse);
    vtkNew<vtkFFDVoxelize> voxelize;
    voxelize->SetInputData(cow);
    voxelize->SetDivisions(8, 6, 4);
    vtkNew<vtkFFDBuildLattice> build;
    build->SetInputConnection(voxelize->GetOutputPort());
    build->SetBasis(basis);
    build->Update();
    vtkPointSet* direct = vtkPointSet::SafeDownCast(build->GetOutputDataObject(0));
    int divisions[3];
    vtkFFDDataContract::GetDivisions(fine, divisions);
    EXPECT_TRUE(std::equal(divisions, divisions + 3, twice));
    // Built over the cow's own voxels at 2n, the finer lattice is a subset of the refined one (the halves of the
    // coarse voxels hold voxels without points); every one of its points is there at the same place, bit for bit.
    EXPECT_LE(direct->GetNumberOfPoints(), fine->GetNumberOfPoints());
    vtkIdType different = 0;
    if (basis == vtkFFDBuildLattice::BERNSTEIN)
    {
      ASSERT_EQ(direct->GetNumberOfPoints(), fine->GetNumberOfPoints());
      for (vtkIdType p = 0; p < fine->GetNumberOfPoints(); ++p)
      {
        double a[3], b[3];
        fine->GetPoint(p, a);
        direct->GetPoint(p, b);
        different += a[0] != b[0] || a[1] != b[1] || a[2] != b[2];
      }
    }
    else
    {
      std::map<std::array<int, 3>, vtkIdType> ids;
      vtkDataArray* index = fine->GetPointData()->GetArray("LatticeIndex");
      for (vtkIdType p = 0; p < fine->GetNumberOfPoints(); ++p)
      {
        ids[{ int(index->GetComponent(p, 0)), int(index->GetComponent(p, 1)), int(index->GetComponent(p, 2)) }] = p;
      }
      vtkDataArray* directIndex = direct->GetPointData()->GetArray("LatticeIndex");
      for (vtkIdType p = 0; p < direct->GetNumberOfPoints(); ++p)
      {
        auto it = ids.find({ int(directIndex->GetComponent(p, 0)), int(directIndex->GetComponent(p, 1)),
          int(directIndex->GetComponent(p, 2)) });
        if (it == ids.end())
        {
          ++different;
          continue;
        }
        double a[3], b[3];
        fine->GetPoint(it->second, a);
        direct->GetPoint(p, b);
        different += a[0] != b[0] || a[1] != b[1] || a[2] != b[2];
      }
    }
    EXPECT_EQ(different, 0) << vtkFFDBuildLattice::GetBasisAsString(basis);
  }
}

TEST(vtkFFDRefineLattice, RefusesWhatItCannotRefine)
{
  vtkSmartPointer<vtkPolyData> cow = ReadTestMesh("cow");
  std::mt19937 rng(5);
  struct Case
  {
    vtkSmartPointer<vtkPointSet> Input;
    const char* Says;
  };
  vtkNew<vtkFFDBuildTetrahedralLattice> tetrahedra;
  tetrahedra->SetInputData(cow);
  tetrahedra->Update();
  const int degree17[3] = { 17, 2, 2 };
  const Case cases[] = {
    { tetrahedra->GetOutput(), "SubdivisionLevels" },
    { MovedLattice(cow, vtkFFDBuildLattice::BERNSTEIN, degree17, vtkFFDBuildLattice::DENSE, rng), "degree 34" },
    { cow, "Cannot refine the input" },
  };
  for (const Case& c : cases)
  {
    vtkNew<vtkFFDRefineLattice> refine;
    vtkNew<FFDTestErrorObserver> errors;
    errors->WatchWithExecutive(refine);
    refine->SetInputData(c.Input);
    refine->Update();
    EXPECT_NE(errors->Errors.find(c.Says), std::string::npos) << errors->Errors;
    EXPECT_EQ(refine->GetOutput()->GetNumberOfPoints(), 0);
  }
  // Levels 0 passes the lattice through.
  vtkSmartPointer<vtkPointSet> lattice =
    MovedLattice(cow, vtkFFDBuildLattice::TRILINEAR, degree17, vtkFFDBuildLattice::SPARSE, rng);
  EXPECT_EQ(LargestDistance(Refine(lattice, 0), lattice), 0.0);
}

// Issue 30, item 17: a missing or wrong-typed input failed with only the executive's "returned failure".
TEST(vtkFFDRefineLattice, SaysWhichInputIsMissingOrWrong)
{
  vtkSmartPointer<vtkPolyData> cow = ReadTestMesh("cow");
  std::mt19937 rng(30);
  const int n[3] = { 2, 2, 2 };
  vtkNew<vtkFFDRefineLattice> refine;
  refine->SetInputData(
    ffdtest::MovedLattice(cow, vtkFFDBuildLattice::TRILINEAR, n, vtkFFDBuildLattice::DENSE, rng, 0.01));
  ffdtest::ExpectClearInputErrors(refine, 0, "the lattice", "SetInputConnection() to a grid lattice");
}

// Issue 30, item 10: Levels 16 on a 4 x 4 x 4 lattice (1.8e16 voxels at the last level) refined level after level
// until the memory ran out (12 GB in 40 s and on). The last level's size is checked before the first is refined:
// an error with the sizes and the Levels that fit, at once, with an empty output.
TEST(vtkFFDRefineLattice, RefusesLevelsWhoseLatticeCannotFitBeforeRefining)
{
  vtkSmartPointer<vtkPolyData> cow = ReadTestMesh("cow");
  std::mt19937 rng(34);
  const int n[3] = { 4, 4, 4 };
  for (int basis : { vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::CUBIC_BSPLINE })
  {
    for (int form : { vtkFFDBuildLattice::DENSE, vtkFFDBuildLattice::SPARSE })
    {
      vtkNew<vtkFFDRefineLattice> refine;
      refine->SetInputData(MovedLattice(cow, basis, n, form, rng, 0.01));
      refine->SetLevels(16);
      const std::string errors = ffdtest::UpdateErrors(refine);
      const std::string said = std::string("Levels 16 refine the 4x4x4 ") +
        vtkFFDBuildLattice::GetBasisAsString(basis) + " lattice to 262144x262144x262144 divisions";
      EXPECT_NE(errors.find(said), std::string::npos) << errors;
      EXPECT_NE(errors.find("set fewer Levels (SetLevels(); at most "), std::string::npos) << errors;
      EXPECT_EQ(refine->GetOutput()->GetNumberOfPoints(), 0);
    }
  }
}
