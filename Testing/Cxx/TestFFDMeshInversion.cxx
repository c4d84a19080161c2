// SPDX-License-Identifier: BSD-3-Clause
// vtkFFDMeshInversion: each cell's Inverted flag against an independent computation, the sign of det(dx/dr) from
// VTK's own shape-function derivatives (vtkTetra, vtkHexahedron, vtkVoxel, vtkWedge, vtkPyramid::
// InterpolationDerivs) at the cell's corners (and a hexahedron's centre), rest against deformed; the scaled Jacobian
// against vtkMeshQuality (tetrahedra, hexahedra) and known values (ideal cells of every type); volume meshes deformed
// by vtkFFDDeform; bad input.
#include "FFDTestErrorObserver.h"
#include "FFDTestInputChecks.h"
#include "FFDTestMeshes.h"
#include "FFDTestTetrahedra.h"

#include "vtkCallbackCommand.h"
#include "vtkCellData.h"
#include "vtkCellType.h"
#include "vtkDoubleArray.h"
#include "vtkFFDBuildLattice.h"
#include "vtkFFDDeform.h"
#include "vtkFFDMeshInversion.h"
#include "vtkFFDVoxelize.h"
#include "vtkGenericCell.h"
#include "vtkHexahedron.h"
#include "vtkIdList.h"
#include "vtkMeshQuality.h"
#include "vtkNew.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkPyramid.h"
#include "vtkStructuredGrid.h"
#include "vtkTetra.h"
#include "vtkUnsignedCharArray.h"
#include "vtkUnstructuredGrid.h"
#include "vtkVoxel.h"
#include "vtkWedge.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>
#include <vector>

namespace
{
/// det(dx/d(r, s, t)) of cell c of `mesh` at parametric point `pc`, from VTK's interpolation derivatives.
double VtkJacobian(vtkUnstructuredGrid* mesh, vtkIdType c, const double* pc)
{
  vtkNew<vtkIdList> ids;
  mesh->GetCellPoints(c, ids);
  const int n = static_cast<int>(ids->GetNumberOfIds());
  double d[24];
  switch (mesh->GetCellType(c))
  {
    case VTK_TETRA:
      vtkTetra::InterpolationDerivs(pc, d);
      break;
    case VTK_HEXAHEDRON:
      vtkHexahedron::InterpolationDerivs(pc, d);
      break;
    case VTK_VOXEL:
      vtkVoxel::InterpolationDerivs(pc, d);
      break;
    case VTK_WEDGE:
      vtkWedge::InterpolationDerivs(pc, d);
      break;
    default:
      vtkPyramid::InterpolationDerivs(pc, d);
  }
  double j[3][3] = {};
  for (int a = 0; a < 3; ++a)
    for (int i = 0; i < n; ++i)
    {
      double x[3];
      mesh->GetPoint(ids->GetId(i), x);
      for (int r = 0; r < 3; ++r)
        j[a][r] += d[a * n + i] * x[r];
    }
  return j[0][0] * (j[1][1] * j[2][2] - j[1][2] * j[2][1]) - j[0][1] * (j[1][0] * j[2][2] - j[1][2] * j[2][0]) +
    j[0][2] * (j[1][0] * j[2][1] - j[1][1] * j[2][0]);
}

/// The Jacobian's dets of cell c at its corners (not a pyramid's apex, which VTK's derivatives leave singular) and a
/// hexahedron's centre.
std::vector<double> VtkCornerJacobians(vtkUnstructuredGrid* mesh, vtkIdType c)
{
  vtkNew<vtkGenericCell> cell;
  mesh->GetCell(c, cell);
  const double* pcoords = cell->GetParametricCoords();
  const int type = cell->GetCellType();
  std::vector<double> dets;
  for (int p = 0; p < cell->GetNumberOfPoints() - (type == VTK_PYRAMID ? 1 : 0); ++p)
  {
    dets.push_back(VtkJacobian(mesh, c, pcoords + 3 * p));
  }
  if (type == VTK_HEXAHEDRON || type == VTK_VOXEL)
  {
    const double centre[3] = { 0.5, 0.5, 0.5 };
    dets.push_back(VtkJacobian(mesh, c, centre));
  }
  return dets;
}

/// The expected flag of cell c: all rest dets of one sign, and each deformed one of that sign.
int ExpectedState(vtkUnstructuredGrid* rest, vtkUnstructuredGrid* deformed, vtkIdType c)
{
  const std::vector<double> before = VtkCornerJacobians(rest, c), after = VtkCornerJacobians(deformed, c);
  const bool positive = std::all_of(before.begin(), before.end(), [](double d) { return d > 0; });
  const bool negative = std::all_of(before.begin(), before.end(), [](double d) { return d < 0; });
  if (!positive && !negative)
  {
    return vtkFFDMeshInversion::INVALID_AT_REST;
  }
  const double sign = positive ? 1.0 : -1.0;
  return std::all_of(after.begin(), after.end(), [sign](double d) { return sign * d > 0; })
    ? vtkFFDMeshInversion::VALID
    : vtkFFDMeshInversion::INVERTED;
}

/// One cell of each type, apart: a hexahedron, a voxel, a tetrahedron and its mirror, a wedge and a pyramid, of
/// edge 1, each an ideal cell of its kind (the wedge on an equilateral triangle, the pyramid with equilateral
/// faces), in VTK's node orders.
vtkSmartPointer<vtkUnstructuredGrid> OneOfEach()
{
  const double s3 = std::sqrt(3.0) / 2, h = 1 / std::sqrt(2.0);
  const std::vector<std::pair<int, std::vector<std::array<double, 3>>>> cells = {
    { VTK_HEXAHEDRON,
      { { 0, 0, 0 }, { 1, 0, 0 }, { 1, 1, 0 }, { 0, 1, 0 }, { 0, 0, 1 }, { 1, 0, 1 }, { 1, 1, 1 }, { 0, 1, 1 } } },
    { VTK_VOXEL,
      { { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 }, { 1, 1, 0 }, { 0, 0, 1 }, { 1, 0, 1 }, { 0, 1, 1 }, { 1, 1, 1 } } },
    { VTK_TETRA, { { 0, 0, 0 }, { 1, 0, 0 }, { 0.5, s3, 0 }, { 0.5, s3 / 3, std::sqrt(2.0 / 3) } } },
    { VTK_TETRA, { { 0, 0, 0 }, { 0.5, s3, 0 }, { 1, 0, 0 }, { 0.5, s3 / 3, std::sqrt(2.0 / 3) } } },
    { VTK_WEDGE, { { 0, 0, 0 }, { 0.5, s3, 0 }, { 1, 0, 0 }, { 0, 0, 1 }, { 0.5, s3, 1 }, { 1, 0, 1 } } },
    { VTK_PYRAMID, { { 0, 0, 0 }, { 1, 0, 0 }, { 1, 1, 0 }, { 0, 1, 0 }, { 0.5, 0.5, h } } },
  };
  auto mesh = vtkSmartPointer<vtkUnstructuredGrid>::New();
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  mesh->SetPoints(points);
  double shift = 0;
  for (const auto& cell : cells)
  {
    std::vector<vtkIdType> ids;
    for (const auto& x : cell.second)
    {
      ids.push_back(points->InsertNextPoint(x[0] + shift, x[1], x[2]));
    }
    mesh->InsertNextCell(cell.first, static_cast<vtkIdType>(ids.size()), ids.data());
    shift += 2;
  }
  return mesh;
}

vtkFFDMeshInversion* Inspect(vtkFFDMeshInversion* filter, vtkPointSet* deformed, vtkPointSet* rest)
{
  filter->SetInputData(deformed);
  filter->SetRestMeshData(rest);
  filter->Update();
  return filter;
}

vtkDataArray* CellArray(vtkFFDMeshInversion* filter, const char* name)
{
  return vtkPointSet::SafeDownCast(filter->GetOutputDataObject(0))->GetCellData()->GetArray(name);
}
} // namespace

// Ideal cells score 1 (the scaled Jacobian's normalisation, by type), the mirrored tetrahedron too; nothing inverted.
TEST(vtkFFDMeshInversion, IdealCellsScoreOne)
{
  vtkSmartPointer<vtkUnstructuredGrid> mesh = OneOfEach();
  vtkNew<vtkFFDMeshInversion> inversion;
  Inspect(inversion, mesh, mesh);
  EXPECT_EQ(inversion->GetNumberOfInvertedCells(), 0);
  EXPECT_EQ(inversion->GetNumberOfInvalidRestCells(), 0);
  vtkDataArray* scaled = CellArray(inversion, "ScaledJacobian");
  for (vtkIdType c = 0; c < mesh->GetNumberOfCells(); ++c)
  {
    EXPECT_NEAR(scaled->GetComponent(c, 0), 1.0, 1e-14) << "cell " << c;
  }
  EXPECT_NEAR(inversion->GetMinimumScaledJacobian(), 1.0, 1e-14);
}

// 400 random moves of every node (up to 0.05 to 0.6 of an edge): each cell's flag as VTK's derivatives have it, and
// the scaled Jacobian of the hexahedron and the tetrahedra as vtkMeshQuality has it (times the rest orientation:
// the mirrored tetrahedron's is negated); 1e-12 covers the two orders of operations on values of order 1.
TEST(vtkFFDMeshInversion, AgreesWithVTKsDerivativesAndMeshQuality)
{
  vtkSmartPointer<vtkUnstructuredGrid> rest = OneOfEach();
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  int inverted = 0, valid = 0;
  for (int trial = 0; trial < 400; ++trial)
  {
    const double amplitude = 0.05 + 0.55 * (trial % 8) / 7.0;
    vtkNew<vtkUnstructuredGrid> deformed;
    deformed->DeepCopy(rest);
    for (vtkIdType p = 0; p < deformed->GetNumberOfPoints(); ++p)
    {
      double x[3];
      deformed->GetPoint(p, x);
      deformed->GetPoints()->SetPoint(
        p, x[0] + amplitude * unit(rng), x[1] + amplitude * unit(rng), x[2] + amplitude * unit(rng));
    }
    vtkNew<vtkFFDMeshInversion> inversion;
    Inspect(inversion, deformed, rest);
    vtkDataArray* states = CellArray(inversion, "Inverted");
    vtkDataArray* scaled = CellArray(inversion, "ScaledJacobian");
    vtkIdType count = 0;
    for (vtkIdType c = 0; c < rest->GetNumberOfCells(); ++c)
    {
      const int expected = ExpectedState(rest, deformed, c);
      ASSERT_EQ(states->GetComponent(c, 0), expected) << "trial " << trial << " cell " << c;
      count += expected == vtkFFDMeshInversion::INVERTED;
      inverted += expected == vtkFFDMeshInversion::INVERTED;
      valid += expected == vtkFFDMeshInversion::VALID;
    }
    EXPECT_EQ(inversion->GetNumberOfInvertedCells(), count);
    EXPECT_NEAR(scaled->GetComponent(0, 0), vtkMeshQuality::HexScaledJacobian(deformed->GetCell(0)), 1e-12);
    EXPECT_NEAR(scaled->GetComponent(2, 0), vtkMeshQuality::TetScaledJacobian(deformed->GetCell(2)), 1e-12);
    EXPECT_NEAR(scaled->GetComponent(3, 0), -vtkMeshQuality::TetScaledJacobian(deformed->GetCell(3)), 1e-12);
    // An inverted cell has a scaled Jacobian <= 0, a valid one > 0.
    for (vtkIdType c = 0; c < rest->GetNumberOfCells(); ++c)
    {
      EXPECT_EQ(scaled->GetComponent(c, 0) > 0, states->GetComponent(c, 0) == vtkFFDMeshInversion::VALID) << c;
    }
  }
  EXPECT_GT(inverted, 100);
  EXPECT_GT(valid, 100);
}

// A tetrahedral volume mesh (the Kuhn triangulation of a box, a third of its tetrahedra in mirrored order) deformed by
// vtkFFDDeform with a cubic B-spline lattice: gently, nothing inverts; with one control point pushed through the
// mesh, the cells VTK's derivatives find inverted, and those only.
TEST(vtkFFDMeshInversion, VolumeMeshDeformedByALattice)
{
  const double bounds[6] = { 0, 1, 0, 1, 0, 1 };
  vtkSmartPointer<vtkUnstructuredGrid> mesh = ffdtest::KuhnBoxLattice(6, bounds, 0.2, true);
  vtkNew<vtkFFDVoxelize> voxelize;
  voxelize->SetInputData(mesh);
  voxelize->SetDivisions(3, 3, 3);
  vtkNew<vtkFFDBuildLattice> build;
  build->SetInputConnection(voxelize->GetOutputPort());
  build->SetBasisToCubicBSpline();
  build->SetLatticeFormToDense();
  build->Update();
  vtkNew<vtkStructuredGrid> lattice;
  lattice->DeepCopy(build->GetOutputDataObject(0));
  vtkNew<vtkFFDDeform> deform;
  deform->SetInputData(mesh);
  deform->SetLatticeData(lattice);
  for (double push : { 0.05, 1.5 })
  {
    const vtkIdType point = 3 + 6 * (3 + 6 * 3); // an inner control point of the 6^3 lattice
    double x[3];
    build->GetOutput()->GetPoint(point, x);
    lattice->GetPoints()->SetPoint(point, x[0] + push, x[1] + push / 2, x[2]);
    lattice->GetPoints()->Modified();
    deform->Update();
    vtkUnstructuredGrid* deformed = vtkUnstructuredGrid::SafeDownCast(deform->GetOutput());
    vtkNew<vtkFFDMeshInversion> inversion;
    Inspect(inversion, deformed, mesh);
    vtkDataArray* states = CellArray(inversion, "Inverted");
    vtkIdType expected = 0;
    for (vtkIdType c = 0; c < mesh->GetNumberOfCells(); ++c)
    {
      const int state = ExpectedState(mesh, deformed, c);
      EXPECT_EQ(states->GetComponent(c, 0), state) << c;
      expected += state == vtkFFDMeshInversion::INVERTED;
    }
    EXPECT_EQ(inversion->GetNumberOfInvertedCells(), expected);
    EXPECT_EQ(inversion->GetNumberOfInvalidRestCells(), 0);
    if (push < 1)
    {
      EXPECT_EQ(expected, 0);
      EXPECT_GT(inversion->GetMinimumScaledJacobian(), 0.0);
    }
    else
    {
      EXPECT_GT(expected, 0);
      EXPECT_LE(inversion->GetMinimumScaledJacobian(), 0.0);
    }
  }
}

TEST(vtkFFDMeshInversion, BadInputIsAnErrorAndAnEmptyOutput)
{
  vtkSmartPointer<vtkUnstructuredGrid> mesh = OneOfEach();
  vtkNew<vtkFFDMeshInversion> inversion;
  inversion->SetInputData(mesh);
  inversion->SetRestMeshData(mesh);
  ffdtest::ExpectClearInputErrors(inversion, 0, "the deformed mesh", "SetInputConnection() to the deformed");
  ffdtest::ExpectClearInputErrors(inversion, 1, "the mesh at rest", "SetRestMeshConnection()");

  vtkSmartPointer<vtkPolyData> bear = ReadTestMesh("bear"); // triangles
  vtkNew<vtkUnstructuredGrid> fewer;
  fewer->DeepCopy(mesh);
  fewer->GetPoints()->SetNumberOfPoints(mesh->GetNumberOfPoints() - 1);
  vtkNew<vtkUnstructuredGrid> rewired;
  rewired->DeepCopy(mesh);
  vtkIdType tetra[4] = { 16, 17, 19, 18 }; // the tetrahedron's nodes, two swapped
  rewired->ReplaceCell(2, 4, tetra);
  struct Case
  {
    vtkPointSet* Deformed;
    vtkPointSet* Rest;
    const char* Expected;
  };
  for (const Case& c : { Case{ bear, bear, "not a linear volume cell" }, Case{ mesh, fewer, "must be one mesh" },
         Case{ rewired, mesh, "Cell 2 differs" } })
  {
    vtkNew<vtkFFDMeshInversion> filter;
    vtkNew<FFDTestErrorObserver> errors;
    errors->WatchWithExecutive(filter);
    Inspect(filter, c.Deformed, c.Rest);
    EXPECT_NE(errors->Errors.find(c.Expected), std::string::npos) << errors->Errors;
    EXPECT_EQ(vtkPointSet::SafeDownCast(filter->GetOutputDataObject(0))->GetNumberOfPoints(), 0);
  }
}

// An abort asked for at the start (the executive's progress report of 0) leaves an empty output and no error.
TEST(vtkFFDMeshInversion, Abort)
{
  vtkSmartPointer<vtkUnstructuredGrid> mesh = OneOfEach();
  vtkNew<vtkCallbackCommand> abort;
  abort->SetCallback(
    [](vtkObject* caller, unsigned long, void*, void*) { vtkAlgorithm::SafeDownCast(caller)->SetAbortExecute(1); });
  vtkNew<vtkFFDMeshInversion> inversion;
  inversion->AddObserver(vtkCommand::ProgressEvent, abort);
  vtkNew<FFDTestErrorObserver> errors;
  errors->WatchWithExecutive(inversion);
  Inspect(inversion, mesh, mesh);
  EXPECT_EQ(errors->Errors, "");
  EXPECT_EQ(vtkPointSet::SafeDownCast(inversion->GetOutputDataObject(0))->GetNumberOfPoints(), 0);
}
