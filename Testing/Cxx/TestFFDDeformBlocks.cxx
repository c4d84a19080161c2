// SPDX-License-Identifier: BSD-3-Clause
// vtkFFDDeformBlocks: the car-crash case (four blocks along the cow, one corner dented: every point outside that
// block bit for bit unchanged, every point inside it as vtkFFDDeform moves it), overlapping blocks (a partition of
// unity that reproduces a shared affine map, continuous across a frame's face), added levels, and hierarchical FFD
// (vtkFFDDeform applied to a lattice).

#include "FFDTestErrorObserver.h"
#include "FFDTestInputChecks.h"
#include "FFDTestLattices.h"
#include "FFDTestMeshes.h"

#include "vtkDoubleArray.h"
#include "vtkFFDBuildTetrahedralLattice.h"
#include "vtkFFDDeformBlocks.h"
#include "vtkFFDRefineLattice.h"
#include "vtkMath.h"
#include "vtkPointData.h"
#include "vtkUnstructuredGrid.h"

#include <gtest/gtest.h>

#include <random>

namespace
{
/// A lattice of `basis` at rest over the points of `mesh` in the frame X0 + sS + tT + uU (axis-aligned edges).
vtkSmartPointer<vtkPointSet> BlockLattice(
  vtkPointSet* mesh, const double x0[3], const double size[3], int basis, int divisions, int form)
{
  const double s[3] = { size[0], 0, 0 }, t[3] = { 0, size[1], 0 }, u[3] = { 0, 0, size[2] };
  vtkNew<vtkFFDVoxelize> voxelize;
  voxelize->SetInputData(mesh);
  voxelize->SetFrame(x0, s, t, u);
  voxelize->SetDivisions(divisions, divisions, divisions);
  vtkNew<vtkFFDBuildLattice> build;
  build->SetInputConnection(voxelize->GetOutputPort());
  build->SetBasis(basis);
  build->SetLatticeForm(form);
  build->Update();
  vtkSmartPointer<vtkPointSet> lattice = vtkSmartPointer<vtkPointSet>::Take(build->GetOutput()->NewInstance());
  lattice->DeepCopy(build->GetOutput());
  return lattice;
}

/// The four blocks along the cow's length, each a quarter of its padded bounds.
std::vector<vtkSmartPointer<vtkPointSet>> CarBlocks(vtkPointSet* cow, int basis)
{
  double b[6];
  cow->GetBounds(b);
  const double pad = 0.01 * (b[1] - b[0]);
  const double length = (b[1] - b[0] + 2 * pad) / 4;
  std::vector<vtkSmartPointer<vtkPointSet>> blocks;
  for (int i = 0; i < 4; ++i)
  {
    const double x0[3] = { b[0] - pad + i * length, b[2] - pad, b[4] - pad };
    const double size[3] = { length, b[3] - b[2] + 2 * pad, b[5] - b[4] + 2 * pad };
    blocks.push_back(BlockLattice(cow, x0, size, basis, 3, vtkFFDBuildLattice::AUTOMATIC));
  }
  return blocks;
}

/// Dents the block's upper front corner: its control points with s < 0.5, t > 0.5, u > 0.5 pushed in along -t
/// and -u by up to `depth` of the block's height.
void Dent(vtkPointSet* lattice, double depth)
{
  const ffdref::Frame f = ffdtest::FrameOf(lattice);
  vtkDataArray* rest = lattice->GetPointData()->GetArray("RestPosition");
  for (vtkIdType p = 0; p < lattice->GetNumberOfPoints(); ++p)
  {
    ffdtest::Vec x;
    rest->GetTuple(p, x.data());
    const ffdtest::Vec stu = ffdref::Parameters(f, x);
    if (stu[0] < 0.5 && stu[1] > 0.5 && stu[2] > 0.5)
    {
      const double amount = depth * (0.5 - stu[0]) * (stu[1] - 0.5) * (stu[2] - 0.5) * 16;
      lattice->GetPoints()->SetPoint(p, x[0], x[1] - amount * f.T[1], x[2] - amount * f.U[2]);
    }
  }
  lattice->GetPoints()->Modified();
}

bool Same(const double a[3], const double b[3])
{
  return a[0] == b[0] && a[1] == b[1] && a[2] == b[2];
}
} // namespace

TEST(vtkFFDDeformBlocks, CarCrashDentsOneCornerAndLeavesEveryOtherPointBitForBit)
{
  vtkSmartPointer<vtkPolyData> cow = ffdtest::WithPointNormals(ReadTestMesh("cow"));
  for (int basis : { vtkFFDBuildLattice::TRICUBIC_BEZIER, vtkFFDBuildLattice::CUBIC_BSPLINE })
  {
    std::vector<vtkSmartPointer<vtkPointSet>> blocks = CarBlocks(cow, basis);
    Dent(blocks[0], 0.3);
    vtkNew<vtkFFDDeformBlocks> crash;
    crash->SetInputData(cow);
    for (vtkPointSet* block : blocks)
    {
      crash->AddLatticeData(block);
    }
    crash->Update();
    vtkPointSet* crashed = vtkPointSet::SafeDownCast(crash->GetOutputDataObject(0));
    ASSERT_EQ(crashed->GetNumberOfPoints(), cow->GetNumberOfPoints());

    vtkNew<vtkFFDDeform> alone;
    alone->SetInputData(cow);
    alone->SetLatticeData(blocks[0]);
    alone->Update();
    vtkPointSet* dented = vtkPointSet::SafeDownCast(alone->GetOutputDataObject(0));
    const ffdref::Frame f = ffdtest::FrameOf(blocks[0]);
    vtkIdType outside = 0, inside = 0, wrongOutside = 0, wrongInside = 0, moved = 0;
    for (vtkIdType p = 0; p < cow->GetNumberOfPoints(); ++p)
    {
      double x[3], y[3], z[3];
      cow->GetPoint(p, x);
      crashed->GetPoint(p, y);
      dented->GetPoint(p, z);
      const double s = ffdref::Parameters(f, { x[0], x[1], x[2] })[0];
      if (s > 1)
      {
        ++outside;
        wrongOutside += !Same(x, y);
      }
      else if (s < 1)
      {
        ++inside;
        wrongInside += !Same(y, z);
        moved += !Same(x, y);
      }
    }
    EXPECT_GT(outside, cow->GetNumberOfPoints() / 2);
    EXPECT_GT(moved, 10) << "the dent moved points";
    EXPECT_EQ(wrongOutside, 0) << "of " << outside << " points outside the dented block";
    EXPECT_EQ(wrongInside, 0) << "of " << inside << " points inside it";
  }
}

TEST(vtkFFDDeformBlocks, OverlappingBlocksArePartitionOfUnityAndContinuous)
{
  vtkSmartPointer<vtkPolyData> bear = ReadTestMesh("bear");
  double b[6];
  bear->GetBounds(b);
  const double size[3] = { 0.7 * (b[1] - b[0]), 1.1 * (b[3] - b[2]), 1.1 * (b[5] - b[4]) };
  const double left[3] = { b[0] - 0.05 * size[0], b[2] - 0.05 * (b[3] - b[2]), b[4] - 0.05 * (b[5] - b[4]) };
  const double right[3] = { b[1] + 0.05 * size[0] - size[0], left[1], left[2] };
  vtkSmartPointer<vtkPointSet> one =
    BlockLattice(bear, left, size, vtkFFDBuildLattice::CUBIC_BSPLINE, 4, vtkFFDBuildLattice::SPARSE);
  vtkSmartPointer<vtkPointSet> two =
    BlockLattice(bear, right, size, vtkFFDBuildLattice::TRICUBIC_BEZIER, 3, vtkFFDBuildLattice::DENSE);

  // The same affine map on both: the blend reproduces it (the weights sum to 1).
  const double a[3][3] = { { 1.1, 0.1, 0.0 }, { -0.05, 0.95, 0.2 }, { 0.0, 0.1, 1.05 } },
               shift[3] = { 0.1, -0.2, 0.05 };
  auto affine = [&](const double x[3], double y[3])
  {
    for (int r = 0; r < 3; ++r)
    {
      y[r] = shift[r] + a[r][0] * x[0] + a[r][1] * x[1] + a[r][2] * x[2];
    }
  };
  for (vtkPointSet* lattice : { one.Get(), two.Get() })
  {
    vtkDataArray* rest = lattice->GetPointData()->GetArray("RestPosition");
    for (vtkIdType p = 0; p < lattice->GetNumberOfPoints(); ++p)
    {
      double x[3], y[3];
      rest->GetTuple(p, x);
      affine(x, y);
      lattice->GetPoints()->SetPoint(p, y);
    }
  }
  vtkNew<vtkFFDDeformBlocks> blend;
  blend->SetInputData(bear);
  blend->AddLatticeData(one);
  blend->AddLatticeData(two);
  blend->Update();
  const double diagonal = std::hypot(b[1] - b[0], b[3] - b[2], b[5] - b[4]);
  double worst = 0;
  for (vtkIdType p = 0; p < bear->GetNumberOfPoints(); ++p)
  {
    double x[3], y[3], want[3];
    bear->GetPoint(p, x);
    vtkPointSet::SafeDownCast(blend->GetOutputDataObject(0))->GetPoint(p, y);
    affine(x, want);
    worst = std::max(worst, std::sqrt(vtkMath::Distance2BetweenPoints(y, want)));
  }
  // The points are float: each deformation is within a float's rounding of the map (2^-24 of the coordinates'
  // size, here below the diagonal) and the blend averages them.
  EXPECT_LE(worst, 4 * 0x1p-24 * diagonal);

  // Continuity: lattice two moved at random, lattice one at rest. On lattice two's left face (inside lattice one)
  // its weight is 0, so the blend moves nothing there; a millionth inside, it moves by at most phi ~ 4e-6 of
  // lattice two's displacement (every displacement here is below 0.05 of the diagonal).
  std::mt19937 rng(11);
  ffdtest::Perturb(two, rng, 0.05 * diagonal / std::sqrt(3.0));
  for (vtkPointSet* lattice : { one.Get() })
  {
    vtkDataArray* rest = lattice->GetPointData()->GetArray("RestPosition");
    for (vtkIdType p = 0; p < lattice->GetNumberOfPoints(); ++p)
    {
      lattice->GetPoints()->SetPoint(p, rest->GetTuple3(p));
    }
    lattice->GetPoints()->Modified();
  }
  // The blend there, from the class's formula: lattice two's weight phi_2 / (phi_1 + phi_2) times its own
  // displacement (vtkFFDDeform's), within the rounding of forming it (1e-15 of the diagonal).
  const ffdref::Frame f = ffdtest::FrameOf(two), g = ffdtest::FrameOf(one);
  auto phi = [](const ffdtest::Vec& stu)
  { return 64 * stu[0] * (1 - stu[0]) * stu[1] * (1 - stu[1]) * stu[2] * (1 - stu[2]); };
  std::uniform_real_distribution<double> u(0.2, 0.8);
  for (double s : { 0.0, 1e-6 })
  {
    std::vector<std::array<double, 3>> xs;
    for (int i = 0; i < 200; ++i)
    {
      const double t = u(rng), w = u(rng);
      xs.push_back(ffdtest::At(f, s, t, w));
    }
    vtkSmartPointer<vtkPolyData> cloud = PointCloud(xs);
    blend->SetInputData(cloud);
    blend->Update();
    vtkNew<vtkFFDDeform> alone;
    alone->SetInputData(cloud);
    alone->SetLatticeData(two);
    alone->Update();
    double largest = 0, error = 0;
    for (vtkIdType p = 0; p < cloud->GetNumberOfPoints(); ++p)
    {
      double x[3], y[3], z[3];
      cloud->GetPoint(p, x);
      vtkPointSet::SafeDownCast(blend->GetOutputDataObject(0))->GetPoint(p, y);
      vtkPointSet::SafeDownCast(alone->GetOutputDataObject(0))->GetPoint(p, z);
      const double p2 = phi(ffdref::Parameters(f, { x[0], x[1], x[2] }));
      const double p1 = phi(ffdref::Parameters(g, { x[0], x[1], x[2] }));
      ASSERT_GT(p1, 0.1) << "inside lattice one";
      for (int c = 0; c < 3; ++c)
      {
        error = std::max(error, std::abs(y[c] - (x[c] + p2 / (p1 + p2) * (z[c] - x[c]))));
      }
      largest = std::max(largest, std::sqrt(vtkMath::Distance2BetweenPoints(x, y)));
    }
    EXPECT_LE(error, 1e-15 * diagonal);
    if (s == 0)
    {
      EXPECT_EQ(largest, 0.0) << "lattice two's weight is 0 on its face: the blend is continuous there";
    }
    else
    {
      EXPECT_GT(largest, 0.0) << "a millionth inside, lattice two begins to move points";
      EXPECT_LE(largest, 1e-4 * 0.05 * diagonal) << "by a millionth-order share of its displacement";
    }
  }
}

TEST(vtkFFDDeformBlocks, AddedLevelsSumTheirDisplacements)
{
  vtkSmartPointer<vtkPolyData> cow = ReadTestMesh("cow");
  double b[6];
  cow->GetBounds(b);
  const double x0[3] = { b[0], b[2], b[4] }, size[3] = { b[1] - b[0], b[3] - b[2], b[5] - b[4] };
  vtkSmartPointer<vtkPointSet> base =
    BlockLattice(cow, x0, size, vtkFFDBuildLattice::CUBIC_BSPLINE, 3, vtkFFDBuildLattice::SPARSE);
  vtkSmartPointer<vtkPointSet> detail =
    BlockLattice(cow, x0, size, vtkFFDBuildLattice::CUBIC_BSPLINE, 6, vtkFFDBuildLattice::SPARSE);
  vtkNew<vtkFFDBuildTetrahedralLattice> tetrahedra;
  tetrahedra->SetInputData(cow);
  tetrahedra->Update();
  vtkNew<vtkUnstructuredGrid> tetrahedral;
  tetrahedral->DeepCopy(tetrahedra->GetOutput());
  std::mt19937 rng(4);
  ffdtest::Perturb(base, rng, 0.03 * size[0]);
  ffdtest::Perturb(detail, rng, 0.01 * size[0]);
  ffdtest::Perturb(tetrahedral, rng, 0.01 * size[0]);

  vtkNew<vtkFFDDeformBlocks> add;
  add->SetCompositionToAdd();
  add->SetInputData(cow);
  std::vector<vtkPointSet*> levels = { base, detail, tetrahedral };
  std::vector<vtkSmartPointer<vtkPointSet>> each;
  for (vtkPointSet* level : levels)
  {
    add->AddLatticeData(level);
    vtkNew<vtkFFDDeform> deform;
    deform->SetInputData(cow);
    deform->SetLatticeData(level);
    deform->Update();
    each.push_back(vtkPointSet::SafeDownCast(deform->GetOutputDataObject(0)));
  }
  add->Update();
  // Float points: the sum is formed in double from the float results and rounded once to float, within half a
  // float ulp of the sum formed here in another order.
  double worst = 0;
  for (vtkIdType p = 0; p < cow->GetNumberOfPoints(); ++p)
  {
    double x[3], y[3], want[3];
    cow->GetPoint(p, x);
    std::copy(x, x + 3, want);
    for (vtkPointSet* moved : each)
    {
      double z[3];
      moved->GetPoint(p, z);
      for (int c = 0; c < 3; ++c)
      {
        want[c] += z[c] - x[c];
      }
    }
    vtkPointSet::SafeDownCast(add->GetOutputDataObject(0))->GetPoint(p, y);
    for (int c = 0; c < 3; ++c)
    {
      worst = std::max(worst, std::abs(y[c] - want[c]) - 0x1p-24 * std::abs(want[c]));
    }
  }
  EXPECT_LE(worst, 0.0);

  // BLEND refuses a tetrahedral lattice.
  vtkNew<FFDTestErrorObserver> errors;
  errors->WatchWithExecutive(add);
  add->SetCompositionToBlend();
  add->Update();
  EXPECT_NE(errors->Errors.find("SetCompositionToAdd"), std::string::npos) << errors->Errors;
}

TEST(vtkFFDDeformBlocks, HierarchicalFFDDeformsAFineLatticeByACoarseOne)
{
  // vtkFFDDeform with a lattice as its input 0: the fine trilinear lattice's nodes moved by the coarse trilinear
  // lattice are the coarse one's exact refinement, so the mesh deforms alike through either (1e-12 of the
  // diagonal: two float64 evaluations of 8 terms each), and the moved lattice keeps the data contract.
  vtkSmartPointer<vtkPolyData> elephant = ReadTestMesh("elephant");
  double b[6];
  elephant->GetBounds(b);
  const double x0[3] = { b[0], b[2], b[4] }, size[3] = { b[1] - b[0], b[3] - b[2], b[5] - b[4] };
  vtkSmartPointer<vtkPointSet> coarse =
    BlockLattice(elephant, x0, size, vtkFFDBuildLattice::TRILINEAR, 3, vtkFFDBuildLattice::DENSE);
  vtkSmartPointer<vtkPointSet> fine =
    BlockLattice(elephant, x0, size, vtkFFDBuildLattice::TRILINEAR, 6, vtkFFDBuildLattice::SPARSE);
  std::mt19937 rng(8);
  ffdtest::Perturb(coarse, rng, 0.05 * size[0]);

  vtkNew<vtkFFDDeform> moveLattice;
  moveLattice->SetInputData(fine);
  moveLattice->SetLatticeData(coarse);
  moveLattice->SetOutputPointsPrecision(vtkAlgorithm::DOUBLE_PRECISION);
  moveLattice->Update();
  vtkPointSet* moved = vtkPointSet::SafeDownCast(moveLattice->GetOutputDataObject(0));
  ASSERT_TRUE(moved->IsA("vtkUnstructuredGrid"));
  EXPECT_EQ(moved->GetNumberOfCells(), fine->GetNumberOfCells());
  for (const char* name : { "RestPosition", "Active", "LatticeIndex" })
  {
    EXPECT_NE(moved->GetPointData()->GetArray(name), nullptr) << name;
  }
  int divisions[3];
  EXPECT_TRUE(vtkFFDDataContract::GetDivisions(moved, divisions));

  double worst = 0;
  vtkNew<vtkFFDDeform> throughCoarse, throughFine;
  throughCoarse->SetInputData(elephant);
  throughCoarse->SetLatticeData(coarse);
  throughFine->SetInputData(elephant);
  throughFine->SetLatticeData(moved);
  for (vtkFFDDeform* deform : { throughCoarse.Get(), throughFine.Get() })
  {
    deform->SetOutputPointsPrecision(vtkAlgorithm::DOUBLE_PRECISION);
    deform->Update();
  }
  for (vtkIdType p = 0; p < elephant->GetNumberOfPoints(); ++p)
  {
    double y[3], z[3];
    vtkPointSet::SafeDownCast(throughCoarse->GetOutputDataObject(0))->GetPoint(p, y);
    vtkPointSet::SafeDownCast(throughFine->GetOutputDataObject(0))->GetPoint(p, z);
    worst = std::max(worst, std::sqrt(vtkMath::Distance2BetweenPoints(y, z)));
  }
  EXPECT_LE(worst, 1e-12 * std::hypot(size[0], size[1], size[2]));
}

// Issue 30, item 17: a missing or wrong-typed input failed with only the executive's "returned failure".
TEST(vtkFFDDeformBlocks, SaysWhichInputIsMissingOrWrong)
{
  vtkSmartPointer<vtkPolyData> cow = ReadTestMesh("cow");
  std::mt19937 rng(33);
  const int n[3] = { 2, 2, 2 };
  vtkNew<vtkFFDDeformBlocks> blocks;
  blocks->SetInputData(cow);
  blocks->AddLatticeData(
    ffdtest::MovedLattice(cow, vtkFFDBuildLattice::TRILINEAR, n, vtkFFDBuildLattice::DENSE, rng, 0.01));
  ffdtest::ExpectClearInputErrors(blocks, 0, "the mesh", "SetInputConnection() to the mesh to deform");
  ffdtest::ExpectClearInputErrors(blocks, 1, "the lattices", "AddLatticeConnection()");
}

// Issue 30, siblings of item 6: point normals with fewer tuples than the mesh has points were read past their
// end for every point (and written out as the point count's worth of transformed normals). They are passed on
// as they are, untransformed, as vtkFFDDeform passes them; the points are deformed as without normals.
TEST(vtkFFDDeformBlocks, NormalsOfAnotherSizeArePassedOnUntransformed)
{
  vtkSmartPointer<vtkPolyData> cow = ReadTestMesh("cow");
  std::mt19937 rng(36);
  const int n[3] = { 2, 2, 2 };
  vtkSmartPointer<vtkPointSet> lattice =
    ffdtest::MovedLattice(cow, vtkFFDBuildLattice::TRILINEAR, n, vtkFFDBuildLattice::DENSE, rng, 0.05);
  vtkNew<vtkFFDDeformBlocks> plain;
  plain->SetInputData(cow);
  plain->AddLatticeData(lattice);
  plain->Update();

  vtkNew<vtkPolyData> shortNormals;
  shortNormals->ShallowCopy(cow);
  vtkNew<vtkDoubleArray> normals;
  normals->SetName("Normals");
  normals->SetNumberOfComponents(3);
  normals->SetNumberOfTuples(10);
  normals->FillValue(0.0);
  shortNormals->GetPointData()->SetNormals(normals);
  for (int composition : { vtkFFDDeformBlocks::BLEND, vtkFFDDeformBlocks::ADD })
  {
    vtkNew<vtkFFDDeformBlocks> blocks;
    blocks->SetComposition(composition);
    blocks->SetInputData(shortNormals);
    blocks->AddLatticeData(lattice);
    blocks->Update();
    vtkPointSet* output = blocks->GetOutput();
    ASSERT_EQ(output->GetNumberOfPoints(), cow->GetNumberOfPoints());
    EXPECT_TRUE(ffdtest::SamePoints(output, plain->GetOutput()));
    ASSERT_NE(output->GetPointData()->GetNormals(), nullptr);
    EXPECT_EQ(output->GetPointData()->GetNormals()->GetNumberOfTuples(), 10);
  }
}
