// SPDX-License-Identifier: BSD-3-Clause
// Tests of the tetrahedral FFD (paper section III.E): vtkFFDDeform with a tetrahedral lattice and
// vtkFFDBuildTetrahedralLattice, against the float64 reference of FFDReference.h (barycentric weights as
// signed-volume ratios, the absolute form sum w P, found by a brute-force search over every tetrahedron) and,
// for the hull, against VTK's vtkDelaunay3D as a peer.
#include "FFDTestErrorObserver.h"
#include "FFDTestInputChecks.h"
#include "FFDTestMeshes.h"
#include "FFDTestTetrahedra.h"

#include "vtkFFDBuildLattice.h"
#include "vtkFFDBuildTetrahedralLattice.h"
#include "vtkFFDDataContract.h"
#include "vtkFFDDeform.h"
#include "vtkFFDVoxelize.h"

#include "vtkCellArray.h"
#include "vtkDelaunay3D.h"
#include "vtkDoubleArray.h"
#include "vtkExecutive.h"
#include "vtkFloatArray.h"
#include "vtkHexahedron.h"
#include "vtkIdList.h"
#include "vtkIntArray.h"
#include "vtkMath.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkUnsignedCharArray.h"
#include "vtkUnstructuredGrid.h"

#include "FFDReference.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <vector>

namespace
{
using ffdref::Vec;

Vec Point(vtkPoints* points, vtkIdType id)
{
  Vec x;
  points->GetPoint(id, x.data());
  return x;
}

Vec Rest(vtkUnstructuredGrid* lattice, vtkIdType id)
{
  Vec x;
  lattice->GetPointData()->GetArray("RestPosition")->GetTuple(id, x.data());
  return x;
}

std::array<vtkIdType, 4> Nodes(vtkUnstructuredGrid* lattice, vtkIdType cell)
{
  vtkNew<vtkIdList> ids;
  lattice->GetCellPoints(cell, ids);
  return { ids->GetId(0), ids->GetId(1), ids->GetId(2), ids->GetId(3) };
}

/// The reference's tetrahedron holding x at rest: the one whose smallest weight is largest (a point on a face
/// shared by two belongs to both, and both give the same position), or -1 when x is outside by more than
/// `tolerance` in weight units. Tetrahedra without volume are skipped.
vtkIdType ReferenceTetrahedron(vtkUnstructuredGrid* lattice, const Vec& x, double tolerance = 1e-9)
{
  vtkIdType best = -1;
  double bestMargin = -std::numeric_limits<double>::infinity();
  for (vtkIdType c = 0; c < lattice->GetNumberOfCells(); ++c)
  {
    const auto n = Nodes(lattice, c);
    const Vec a = Rest(lattice, n[0]), b = Rest(lattice, n[1]), cc = Rest(lattice, n[2]), d = Rest(lattice, n[3]);
    if (std::fabs(ffdref::SignedVolume(a, b, cc, d)) < 1e-12)
    {
      continue;
    }
    const auto w = ffdref::TetrahedronWeights(a, b, cc, d, x);
    const double margin = std::min({ w[0], w[1], w[2], w[3] });
    if (margin > bestMargin)
    {
      bestMargin = margin;
      best = c;
    }
  }
  return bestMargin >= -tolerance ? best : -1;
}

/// The reference deformation of x by tetrahedron `cell` (its weights extrapolated when x is outside it).
Vec ReferenceDeform(vtkUnstructuredGrid* lattice, vtkIdType cell, const Vec& x)
{
  const auto n = Nodes(lattice, cell);
  std::array<Vec, 4> rest, moved;
  for (int i = 0; i < 4; ++i)
  {
    rest[i] = Rest(lattice, n[i]);
    moved[i] = Point(lattice->GetPoints(), n[i]);
  }
  return ffdref::DeformInTetrahedron(rest, moved, x);
}

/// The Kuhn triangulation of the box [lo, hi]^3 (FFDTestTetrahedra.h).
vtkSmartPointer<vtkUnstructuredGrid> BoxLattice(
  int n, double lo, double hi, double jitter, bool invertSome, unsigned seed = 1)
{
  const double bounds[6] = { lo, hi, lo, hi, lo, hi };
  return ffdtest::KuhnBoxLattice(n, bounds, jitter, invertSome, seed);
}

/// Moves every node of the lattice by a random displacement of up to `amplitude` per coordinate.
void DisplaceNodes(vtkUnstructuredGrid* lattice, double amplitude, unsigned seed)
{
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(-amplitude, amplitude);
  vtkPoints* points = lattice->GetPoints();
  for (vtkIdType p = 0; p < points->GetNumberOfPoints(); ++p)
  {
    const Vec x = Point(points, p);
    points->SetPoint(p, x[0] + unit(rng), x[1] + unit(rng), x[2] + unit(rng));
  }
  points->Modified();
}

vtkSmartPointer<vtkPolyData> RandomPoints(int count, double lo, double hi, int type, unsigned seed)
{
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(lo, hi);
  vtkNew<vtkPoints> points;
  points->SetDataType(type);
  for (int i = 0; i < count; ++i)
  {
    points->InsertNextPoint(unit(rng), unit(rng), unit(rng));
  }
  vtkNew<vtkPolyData> mesh;
  mesh->SetPoints(points);
  return mesh;
}

vtkSmartPointer<vtkPointSet> Deform(vtkPointSet* mesh, vtkDataObject* lattice, int policy = vtkFFDDeform::KEEP_POSITION)
{
  vtkNew<vtkFFDDeform> deform;
  deform->SetInputData(mesh);
  deform->SetLatticeData(lattice);
  deform->SetOutsidePolicy(policy);
  deform->SetBackendToCPU();
  deform->Update();
  return deform->GetOutput();
}

double Distance(const Vec& a, const Vec& b)
{
  return std::sqrt(ffdref::Dot(ffdref::Sub(a, b), ffdref::Sub(a, b)));
}

/// Checks a deformed point set against the reference: points inside the rest lattice moved as the reference
/// moves them (within `tolerance`), points outside left exactly in place. Counts both kinds.
void ExpectReferenceInsideAndKeptOutside(
  vtkPointSet* mesh, vtkPointSet* output, vtkUnstructuredGrid* lattice, double tolerance, int& inside, int& outside)
{
  inside = outside = 0;
  for (vtkIdType i = 0; i < mesh->GetNumberOfPoints(); ++i)
  {
    const Vec x = Point(mesh->GetPoints(), i);
    const Vec y = Point(output->GetPoints(), i);
    const vtkIdType cell = ReferenceTetrahedron(lattice, x);
    if (cell < 0)
    {
      EXPECT_EQ(y, x) << "outside point " << i;
      ++outside;
      continue;
    }
    ++inside;
    EXPECT_LT(Distance(y, ReferenceDeform(lattice, cell, x)), tolerance) << "point " << i;
  }
}

//------------------------------------------------------------------------------------------------------------
// Random points in and around a jittered box lattice whose nodes moved at random, and the lattice's own nodes
// and edge midpoints (on faces and edges): inside, the reference's position within 1e-12 of the lattice size
// in double and 1e-5 relative in float; outside, the input position exactly.
TEST(vtkFFDDeformTetrahedral, MatchesTheReferenceInsideAndKeepsPointsOutside)
{
  for (const int type : { VTK_DOUBLE, VTK_FLOAT })
  {
    auto lattice = BoxLattice(3, -1.0, 1.0, 0.25, false, 7);
    auto mesh = RandomPoints(3000, -1.3, 1.3, type, 11);
    for (vtkIdType p = 0; p < lattice->GetNumberOfPoints(); ++p) // nodes and points on edges
    {
      const Vec a = Rest(lattice, p), b = Rest(lattice, (p * 7 + 3) % lattice->GetNumberOfPoints());
      mesh->GetPoints()->InsertNextPoint(a.data());
      mesh->GetPoints()->InsertNextPoint(0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1]), 0.5 * (a[2] + b[2]));
    }
    DisplaceNodes(lattice, 0.2, 13);
    auto output = Deform(mesh, lattice);
    ASSERT_EQ(output->GetNumberOfPoints(), mesh->GetNumberOfPoints());
    ASSERT_EQ(output->GetPoints()->GetDataType(), type);
    const double tol = type == VTK_DOUBLE ? 1e-12 * 2.0 : 1e-5 * 2.0;
    int inside, outside;
    SCOPED_TRACE(type == VTK_DOUBLE ? "double points" : "float points");
    ExpectReferenceInsideAndKeptOutside(mesh, output, lattice, tol, inside, outside);
    EXPECT_GT(inside, 1000);
  }
}

// A non-convex lattice (a U: the box without the upper middle column of cells), where walks from a seed in
// one arm leave the mesh before reaching a point in the other: VTK's locator places those points.
TEST(vtkFFDDeformTetrahedral, NonConvexLatticesAreLocatedWhereWalksLeaveThem)
{
  auto box = BoxLattice(3, 0.0, 3.0, 0.1, false, 71);
  vtkNew<vtkUnstructuredGrid> lattice;
  lattice->SetPoints(box->GetPoints());
  lattice->GetPointData()->ShallowCopy(box->GetPointData());
  vtkNew<vtkCellArray> cells;
  for (vtkIdType c = 0; c < box->GetNumberOfCells(); ++c)
  {
    const vtkIdType cube = c / 6; // i + 3 (j + 3 k)
    if (cube % 3 == 1 && cube / 9 >= 1)
    {
      continue;
    }
    vtkNew<vtkIdList> ids;
    box->GetCellPoints(c, ids);
    cells->InsertNextCell(ids);
  }
  lattice->SetCells(VTK_TETRA, cells);
  DisplaceNodes(lattice, 0.2, 73);
  auto mesh = RandomPoints(3000, 0.0, 3.0, VTK_DOUBLE, 79);
  auto output = Deform(mesh, lattice);
  int inside, outside;
  ExpectReferenceInsideAndKeptOutside(mesh, output, lattice, 1e-12, inside, outside);
  EXPECT_GT(inside, 1000);
  EXPECT_GT(outside, 500);
}

// The rest lattice built around a real mesh leaves it exactly as it is; an affine motion of every node moves
// it by that motion, normals by its cofactor and det J is its determinant.
TEST(vtkFFDDeformTetrahedral, RestIsTheIdentityAndAffineMotionsAreReproducedOnARealMesh)
{
  auto mesh = ReadTestMesh("cow");
  vtkNew<vtkFFDBuildTetrahedralLattice> build;
  build->SetInputData(mesh);
  build->SetSubdivisionLevels(1);
  build->Update();
  vtkUnstructuredGrid* lattice = build->GetOutput();
  ASSERT_GT(lattice->GetNumberOfCells(), 0);
  auto rest = Deform(mesh, lattice);
  for (vtkIdType i = 0; i < mesh->GetNumberOfPoints(); ++i)
  {
    ASSERT_EQ(Point(rest->GetPoints(), i), Point(mesh->GetPoints(), i));
  }

  const double m[3][3] = { { 1.1, 0.2, -0.1 }, { -0.15, 0.9, 0.05 }, { 0.1, 0.3, 1.2 } };
  const Vec b = { 0.3, -0.2, 0.5 };
  auto affine = [&](const Vec& x)
  {
    Vec y;
    for (int r = 0; r < 3; ++r)
    {
      y[r] = m[r][0] * x[0] + m[r][1] * x[1] + m[r][2] * x[2] + b[r];
    }
    return y;
  };
  vtkNew<vtkUnstructuredGrid> moved;
  moved->DeepCopy(lattice);
  for (vtkIdType p = 0; p < moved->GetNumberOfPoints(); ++p)
  {
    moved->GetPoints()->SetPoint(p, affine(Rest(moved, p)).data());
  }
  vtkNew<vtkPolyData> withNormals;
  withNormals->DeepCopy(mesh);
  vtkNew<vtkDoubleArray> normals;
  normals->SetNumberOfComponents(3);
  normals->SetName("Normals");
  std::mt19937 rng(3);
  std::normal_distribution<double> gauss;
  for (vtkIdType i = 0; i < mesh->GetNumberOfPoints(); ++i)
  {
    double n[3] = { gauss(rng), gauss(rng), gauss(rng) };
    vtkMath::Normalize(n);
    normals->InsertNextTuple(n);
  }
  withNormals->GetPointData()->SetNormals(normals);
  vtkNew<vtkFFDDeform> deform;
  deform->SetInputData(withNormals);
  deform->SetLatticeData(moved);
  deform->ComputeJacobianDeterminantOn();
  deform->Update();
  vtkPointSet* out = deform->GetOutput();
  double bounds[6];
  mesh->GetBounds(bounds);
  const double scale = std::sqrt(vtkMath::Distance2BetweenPoints(bounds, bounds + 3)) + 1.0;
  const double det = vtkMath::Determinant3x3(m[0], m[1], m[2]);
  double cof[3][3];
  for (int r = 0; r < 3; ++r)
  {
    for (int c = 0; c < 3; ++c) // cofactor of m: det * m^-T
    {
      const int r1 = (r + 1) % 3, r2 = (r + 2) % 3, c1 = (c + 1) % 3, c2 = (c + 2) % 3;
      cof[r][c] = m[r1][c1] * m[r2][c2] - m[r1][c2] * m[r2][c1];
    }
  }
  vtkDataArray* outNormals = out->GetPointData()->GetNormals();
  vtkDataArray* dets = out->GetPointData()->GetArray(vtkFFDDeform::JacobianDeterminantArrayName());
  ASSERT_TRUE(outNormals && dets);
  for (vtkIdType i = 0; i < mesh->GetNumberOfPoints(); ++i)
  {
    EXPECT_LT(Distance(Point(out->GetPoints(), i), affine(Point(mesh->GetPoints(), i))), 1e-12 * scale);
    double n[3], expected[3];
    normals->GetTuple(i, n);
    for (int r = 0; r < 3; ++r)
    {
      expected[r] = cof[r][0] * n[0] + cof[r][1] * n[1] + cof[r][2] * n[2];
    }
    vtkMath::Normalize(expected);
    double got[3];
    outNormals->GetTuple(i, got);
    // The maps' gradients come from the tetrahedra's dual vectors, which thin tetrahedra of the hull's fan
    // amplify: 1e-10 is still 10^6 times below any visible error.
    EXPECT_LT(std::sqrt(vtkMath::Distance2BetweenPoints(got, expected)), 1e-10);
    EXPECT_NEAR(dets->GetTuple1(i), det, 1e-10);
  }
}

// Moving one interior node moves exactly the points of its incident tetrahedra: every other point keeps its
// position bit for bit.
TEST(vtkFFDDeformTetrahedral, MovingOneNodeMovesOnlyPointsOfItsTetrahedra)
{
  auto lattice = BoxLattice(3, 0.0, 3.0, 0.2, true, 5);
  auto mesh = RandomPoints(4000, 0.0, 3.0, VTK_DOUBLE, 17);
  const vtkIdType node = 1 + 4 * (1 + 4 * 1); // interior node (1, 1, 1)
  const Vec x0 = Point(lattice->GetPoints(), node);
  lattice->GetPoints()->SetPoint(node, x0[0] + 0.3, x0[1] - 0.2, x0[2] + 0.1);
  auto output = Deform(mesh, lattice);
  int moved = 0;
  for (vtkIdType i = 0; i < mesh->GetNumberOfPoints(); ++i)
  {
    const Vec x = Point(mesh->GetPoints(), i);
    const Vec y = Point(output->GetPoints(), i);
    const vtkIdType cell = ReferenceTetrahedron(lattice, x);
    ASSERT_GE(cell, 0);
    const auto n = Nodes(lattice, cell);
    const bool incident = std::find(n.begin(), n.end(), node) != n.end();
    if (!incident)
    {
      // A point on a face between an incident tetrahedron and another may be bound to either; its weight at
      // the node is then 0 up to rounding.
      EXPECT_LT(Distance(y, x), 1e-13) << "point " << i << " in tetrahedron " << cell;
    }
    else if (Distance(y, x) > 0.0)
    {
      ++moved;
    }
    if (!incident)
    {
      continue;
    }
    EXPECT_LT(Distance(y, ReferenceDeform(lattice, cell, x)), 1e-12);
  }
  EXPECT_GT(moved, 20);
}

// Inverted tetrahedra (negative orientation at rest) deform as the others: the same result as the lattice with
// every tetrahedron positive. A node moved through its opposite face gives det J < 0 there.
TEST(vtkFFDDeformTetrahedral, InvertedTetrahedraAndFolds)
{
  auto positive = BoxLattice(2, 0.0, 1.0, 0.2, false, 9);
  auto inverted = BoxLattice(2, 0.0, 1.0, 0.2, true, 9);
  DisplaceNodes(positive, 0.1, 19);
  DisplaceNodes(inverted, 0.1, 19);
  auto mesh = RandomPoints(2000, 0.0, 1.0, VTK_DOUBLE, 23);
  auto a = Deform(mesh, positive);
  auto b = Deform(mesh, inverted);
  for (vtkIdType i = 0; i < mesh->GetNumberOfPoints(); ++i)
  {
    EXPECT_LT(Distance(Point(a->GetPoints(), i), Point(b->GetPoints(), i)), 1e-13);
  }

  // Fold: the centre node (1, 1, 1) of a 2^3 box moved far beyond the box's corner (0, 0, 0) turns the
  // tetrahedra around it inside out.
  auto fold = BoxLattice(2, 0.0, 1.0, 0.0, true, 9);
  fold->GetPoints()->SetPoint(1 + 3 * (1 + 3 * 1), -1.0, -1.0, -1.0);
  vtkNew<vtkFFDDeform> deform;
  deform->SetInputData(mesh);
  deform->SetLatticeData(fold);
  deform->ComputeJacobianDeterminantOn();
  deform->Update();
  vtkDataArray* dets = deform->GetOutput()->GetPointData()->GetArray("JacobianDeterminant");
  ASSERT_TRUE(dets);
  int folded = 0;
  for (vtkIdType i = 0; i < mesh->GetNumberOfPoints(); ++i)
  {
    const Vec x = Point(mesh->GetPoints(), i);
    const vtkIdType cell = ReferenceTetrahedron(fold, x);
    const auto n = Nodes(fold, cell);
    std::array<Vec, 4> rest, moved;
    for (int k = 0; k < 4; ++k)
    {
      rest[k] = Rest(fold, n[k]);
      moved[k] = Point(fold->GetPoints(), n[k]);
    }
    // det J of an affine map is the ratio of the deformed to the rest signed volume.
    const double expected = ffdref::SignedVolume(moved[0], moved[1], moved[2], moved[3]) /
      ffdref::SignedVolume(rest[0], rest[1], rest[2], rest[3]);
    if (std::min({ ffdref::TetrahedronWeights(rest[0], rest[1], rest[2], rest[3], x)[0],
          ffdref::TetrahedronWeights(rest[0], rest[1], rest[2], rest[3], x)[1],
          ffdref::TetrahedronWeights(rest[0], rest[1], rest[2], rest[3], x)[2],
          ffdref::TetrahedronWeights(rest[0], rest[1], rest[2], rest[3], x)[3] }) < 1e-9)
    {
      continue; // on a face: either neighbour's determinant is right
    }
    EXPECT_NEAR(dets->GetTuple1(i), expected, 1e-12 * std::max(1.0, std::fabs(expected)));
    folded += expected < 0.0 ? 1 : 0;
  }
  EXPECT_GT(folded, 50);
}

// Points outside the unit-cube lattice, just beyond the middle of a boundary triangle: KEEP_POSITION keeps
// them; CLAMP_TO_EDGE moves them by the displacement at their nearest point of the cube (the clamped
// coordinates), with det J of that clamped map by finite differences of the reference; EXTRAPOLATE moves them
// by the affine map of the tetrahedron owning that triangle.
TEST(vtkFFDDeformTetrahedral, OutsidePolicies)
{
  auto lattice = BoxLattice(2, 0.0, 1.0, 0.0, false, 1);
  DisplaceNodes(lattice, 0.15, 29);
  // Outside points: beyond each boundary triangle's centroid along its outward axis; and beyond corners.
  vtkNew<vtkPoints> outside;
  outside->SetDataTypeToDouble();
  std::vector<vtkIdType> owner;
  for (vtkIdType c = 0; c < lattice->GetNumberOfCells(); ++c)
  {
    const auto n = Nodes(lattice, c);
    for (int skip = 0; skip < 4; ++skip)
    {
      Vec centroid = { 0, 0, 0 };
      std::vector<Vec> face;
      for (int k = 0; k < 4; ++k)
      {
        if (k != skip)
        {
          face.push_back(Rest(lattice, n[k]));
        }
      }
      for (int axis = 0; axis < 3; ++axis)
      {
        for (const double side : { 0.0, 1.0 })
        {
          if (std::all_of(face.begin(), face.end(), [&](const Vec& v) { return v[axis] == side; }))
          {
            for (const Vec& v : face)
            {
              for (int k = 0; k < 3; ++k)
              {
                centroid[k] += v[k] / 3.0;
              }
            }
            centroid[axis] += side == 0.0 ? -0.05 : 0.05;
            outside->InsertNextPoint(centroid.data());
            owner.push_back(c);
          }
        }
      }
    }
  }
  ASSERT_EQ(outside->GetNumberOfPoints(), 48); // 6 faces x 4 squares x 2 triangles
  vtkNew<vtkPolyData> mesh;
  mesh->SetPoints(outside);

  auto kept = Deform(mesh, lattice, vtkFFDDeform::KEEP_POSITION);
  auto extrapolated = Deform(mesh, lattice, vtkFFDDeform::EXTRAPOLATE);
  vtkNew<vtkFFDDeform> clamp;
  clamp->SetInputData(mesh);
  clamp->SetLatticeData(lattice);
  clamp->SetOutsidePolicyToClampToEdge();
  clamp->ComputeJacobianDeterminantOn();
  clamp->Update();
  vtkPointSet* clamped = clamp->GetOutput();
  auto clampedReference = [&](const Vec& x)
  {
    Vec c = { std::clamp(x[0], 0.0, 1.0), std::clamp(x[1], 0.0, 1.0), std::clamp(x[2], 0.0, 1.0) };
    const Vec d = ffdref::Sub(ReferenceDeform(lattice, ReferenceTetrahedron(lattice, c), c), c);
    return Vec{ x[0] + d[0], x[1] + d[1], x[2] + d[2] };
  };
  for (vtkIdType i = 0; i < mesh->GetNumberOfPoints(); ++i)
  {
    const Vec x = Point(outside, i);
    EXPECT_EQ(Point(kept->GetPoints(), i), x);
    EXPECT_LT(Distance(Point(extrapolated->GetPoints(), i), ReferenceDeform(lattice, owner[i], x)), 1e-12);
    EXPECT_LT(Distance(Point(clamped->GetPoints(), i), clampedReference(x)), 1e-12);
    // det J by central differences of the reference (the clamped map is affine near x, so they are exact up
    // to rounding).
    const double h = 1e-4;
    double j[3][3];
    for (int c = 0; c < 3; ++c)
    {
      Vec xp = x, xm = x;
      xp[c] += h;
      xm[c] -= h;
      const Vec yp = clampedReference(xp), ym = clampedReference(xm);
      for (int r = 0; r < 3; ++r)
      {
        j[r][c] = (yp[r] - ym[r]) / (2 * h);
      }
    }
    EXPECT_NEAR(
      clamped->GetPointData()->GetArray("JacobianDeterminant")->GetTuple1(i), vtkMath::Determinant3x3(j), 1e-8);
  }
}

// EXTRAPOLATE where several tetrahedra are nearest (beyond a corner of the box, whose every tetrahedron at the
// corner is as near): the lowest id of them, whichever VTK's locator proposes; and a real mesh's outside points
// deform the same at every binding (VTK's locator, built in parallel, orders tied cells differently from one
// build to the next: the bear below differed by 0.012 between bindings before ties were broken by id).
TEST(vtkFFDDeformTetrahedral, ExtrapolateIsTheSameAtEveryBinding)
{
  auto lattice = BoxLattice(2, 0.0, 1.0, 0.0, false, 1);
  DisplaceNodes(lattice, 0.15, 31);
  vtkIdType lowest = -1;
  int atCorner = 0;
  for (vtkIdType c = 0; c < lattice->GetNumberOfCells(); ++c)
  {
    for (const vtkIdType n : Nodes(lattice, c))
    {
      if (Rest(lattice, n) == Vec{ 0.0, 0.0, 0.0 })
      {
        lowest = lowest < 0 ? c : lowest;
        ++atCorner;
      }
    }
  }
  ASSERT_GT(atCorner, 1);
  vtkNew<vtkPoints> corner;
  corner->SetDataTypeToDouble();
  corner->InsertNextPoint(-0.05, -0.03, -0.04);
  vtkNew<vtkPolyData> beyond;
  beyond->SetPoints(corner);
  const Vec x = Point(corner, 0);
  EXPECT_LT(Distance(Point(Deform(beyond, lattice, vtkFFDDeform::EXTRAPOLATE)->GetPoints(), 0),
              ReferenceDeform(lattice, lowest, x)),
    1e-12);

  // Half the bear in its hull, nodes moved; the whole bear deformed by fresh filters (each binds anew).
  vtkSmartPointer<vtkPolyData> bear = ReadTestMesh("bear");
  double bounds[6];
  bear->GetBounds(bounds);
  vtkNew<vtkPoints> half;
  for (vtkIdType p = 0; p < bear->GetNumberOfPoints(); ++p)
  {
    double y[3];
    bear->GetPoint(p, y);
    if (y[1] < 0.5 * (bounds[2] + bounds[3]))
    {
      half->InsertNextPoint(y);
    }
  }
  vtkNew<vtkPolyData> halfBear;
  halfBear->SetPoints(half);
  vtkNew<vtkFFDBuildTetrahedralLattice> build;
  build->SetInputData(halfBear);
  build->Update();
  vtkNew<vtkUnstructuredGrid> hull;
  hull->DeepCopy(build->GetOutput());
  DisplaceNodes(hull, 0.05, 37);
  vtkSmartPointer<vtkPointSet> first = Deform(bear, hull, vtkFFDDeform::EXTRAPOLATE);
  for (int again = 0; again < 5; ++again)
  {
    vtkSmartPointer<vtkPointSet> next = Deform(bear, hull, vtkFFDDeform::EXTRAPOLATE);
    for (vtkIdType p = 0; p < bear->GetNumberOfPoints(); ++p)
    {
      ASSERT_EQ(Point(next->GetPoints(), p), Point(first->GetPoints(), p)) << "point " << p << ", binding " << again;
    }
  }
}

// A tetrahedron without volume is reported at binding and skipped; the points follow its neighbours.
TEST(vtkFFDDeformTetrahedral, DegenerateTetrahedraAreReportedAndSkipped)
{
  auto lattice = BoxLattice(2, 0.0, 1.0, 0.1, false, 31);
  // Two flat tetrahedra: a repeated node, and four nodes on the bottom face.
  const vtkIdType repeated[4] = { 0, 1, 1, 4 };
  const vtkIdType flat[4] = { 0, 1, 3, 4 };
  lattice->InsertNextCell(VTK_TETRA, 4, repeated);
  lattice->InsertNextCell(VTK_TETRA, 4, flat);
  DisplaceNodes(lattice, 0.1, 37);
  auto mesh = RandomPoints(1000, 0.0, 1.0, VTK_DOUBLE, 41);
  vtkNew<FFDTestErrorObserver> observer;
  vtkNew<vtkFFDDeform> deform;
  observer->Watch(deform);
  deform->SetInputData(mesh);
  deform->SetLatticeData(lattice);
  deform->Update();
  EXPECT_NE(observer->Warnings.find("2 of 50 tetrahedra of the lattice have no volume (the first is cell 48)"),
    std::string::npos)
    << observer->Warnings;
  EXPECT_TRUE(observer->Errors.empty()) << observer->Errors;
  for (vtkIdType i = 0; i < mesh->GetNumberOfPoints(); ++i)
  {
    const Vec x = Point(mesh->GetPoints(), i);
    const Vec y = Point(deform->GetOutput()->GetPoints(), i);
    EXPECT_LT(Distance(y, ReferenceDeform(lattice, ReferenceTetrahedron(lattice, x), x)), 1e-12);
  }
  // Moving the lattice again does not re-bind, so it does not warn again.
  observer->Warnings.clear();
  DisplaceNodes(lattice, 0.05, 43);
  deform->Update();
  EXPECT_TRUE(observer->Warnings.empty()) << observer->Warnings;
  EXPECT_EQ(deform->GetNumberOfBindings(), 1);
}

// A lattice whose tetrahedra all lack volume binds no point: under every outside policy each point keeps its
// position, also a non-finite one (VTK's locator finds no nearest tetrahedron: each reports a numerical error).
TEST(vtkFFDDeformTetrahedral, LatticesWithoutVolumeKeepEveryPoint)
{
  auto box = BoxLattice(2, 0.0, 1.0, 0.0, false, 31);
  vtkNew<vtkUnstructuredGrid> lattice;
  lattice->SetPoints(box->GetPoints());
  lattice->GetPointData()->ShallowCopy(box->GetPointData());
  const vtkIdType repeated[4] = { 0, 1, 1, 4 };
  const vtkIdType flat[4] = { 0, 1, 3, 4 };
  lattice->Allocate(2);
  lattice->InsertNextCell(VTK_TETRA, 4, repeated);
  lattice->InsertNextCell(VTK_TETRA, 4, flat);
  DisplaceNodes(lattice, 0.1, 47);
  auto mesh = RandomPoints(200, -0.5, 1.5, VTK_DOUBLE, 53);
  mesh->GetPoints()->InsertNextPoint(std::numeric_limits<double>::quiet_NaN(), 0.5, 0.5);
  for (const int policy : { vtkFFDDeform::KEEP_POSITION, vtkFFDDeform::CLAMP_TO_EDGE, vtkFFDDeform::EXTRAPOLATE })
  {
    SCOPED_TRACE("outside policy " + std::to_string(policy));
    vtkNew<FFDTestErrorObserver> observer;
    vtkNew<vtkFFDDeform> deform;
    observer->Watch(deform);
    deform->SetInputData(mesh);
    deform->SetLatticeData(lattice);
    deform->SetOutsidePolicy(policy);
    deform->SetBackendToCPU();
    deform->Update();
    EXPECT_NE(observer->Warnings.find("2 of 2 tetrahedra of the lattice have no volume"), std::string::npos)
      << observer->Warnings;
    EXPECT_TRUE(observer->Errors.empty()) << observer->Errors;
    vtkPoints* output = deform->GetOutput()->GetPoints();
    ASSERT_EQ(output->GetNumberOfPoints(), mesh->GetNumberOfPoints());
    for (vtkIdType i = 0; i < mesh->GetNumberOfPoints(); ++i)
    {
      const Vec x = Point(mesh->GetPoints(), i), y = Point(output, i);
      for (int c = 0; c < 3; ++c)
      {
        EXPECT_TRUE(y[c] == x[c] || (std::isnan(y[c]) && std::isnan(x[c]))) << "point " << i;
      }
    }
  }
}

// The binding is cached while only node positions change (also through a rebuilt but equal lattice), and
// recomputed when the rest shape, the points or the outside policy change.
TEST(vtkFFDDeformTetrahedral, BindingIsCachedAcrossNodeMoves)
{
  auto lattice = BoxLattice(3, 0.0, 1.0, 0.2, false, 47);
  auto mesh = RandomPoints(2000, -0.1, 1.1, VTK_FLOAT, 53);
  vtkNew<vtkFFDDeform> deform;
  deform->SetInputData(mesh);
  deform->SetLatticeData(lattice);
  const vtkMTimeType restMTime = lattice->GetPointData()->GetArray("RestPosition")->GetMTime();
  deform->Update();
  EXPECT_EQ(lattice->GetPointData()->GetArray("RestPosition")->GetMTime(), restMTime); // the input is not touched
  for (unsigned step = 0; step < 3; ++step)
  {
    DisplaceNodes(lattice, 0.05, 59 + step);
    deform->Update();
    const Vec x = Point(mesh->GetPoints(), 5);
    const vtkIdType cell = ReferenceTetrahedron(lattice, x);
    if (cell >= 0)
    {
      EXPECT_LT(Distance(Point(deform->GetOutput()->GetPoints(), 5), ReferenceDeform(lattice, cell, x)), 1e-5);
    }
  }
  EXPECT_EQ(deform->GetNumberOfBindings(), 1);
  vtkNew<vtkUnstructuredGrid> rebuilt;
  rebuilt->DeepCopy(lattice);
  deform->SetLatticeData(rebuilt);
  deform->Update();
  EXPECT_EQ(deform->GetNumberOfBindings(), 1);
  deform->SetLatticeData(lattice);
  vtkDataArray* rest = lattice->GetPointData()->GetArray("RestPosition");
  rest->SetComponent(30, 0, rest->GetComponent(30, 0) + 1e-3); // another rest shape
  rest->Modified();
  deform->Update();
  EXPECT_EQ(deform->GetNumberOfBindings(), 2);
  deform->SetOutsidePolicyToExtrapolate();
  deform->Update();
  EXPECT_EQ(deform->GetNumberOfBindings(), 3);
  mesh->GetPoints()->Modified();
  deform->Update();
  EXPECT_EQ(deform->GetNumberOfBindings(), 4);
}

// Lattices that are not what they claim: each is an error naming the problem, with an empty output.
TEST(vtkFFDDeformTetrahedral, InconsistentLatticesAreErrors)
{
  auto mesh = RandomPoints(100, 0.0, 1.0, VTK_DOUBLE, 61);
  struct Case
  {
    std::string Name;
    std::string Expected;
    std::function<void(vtkUnstructuredGrid*)> Break;
  };
  const std::vector<Case> cases = {
    { "no RestPosition", "no RestPosition point array",
      [](vtkUnstructuredGrid* g) { g->GetPointData()->RemoveArray("RestPosition"); } },
    { "2 components", "no RestPosition point array",
      [](vtkUnstructuredGrid* g)
      {
        vtkNew<vtkDoubleArray> r;
        r->SetName("RestPosition");
        r->SetNumberOfComponents(2);
        r->SetNumberOfTuples(g->GetNumberOfPoints());
        r->Fill(0.0);
        g->GetPointData()->AddArray(r);
      } },
    { "too few tuples", "no RestPosition point array",
      [](vtkUnstructuredGrid* g) { g->GetPointData()->GetArray("RestPosition")->SetNumberOfTuples(3); } },
    { "a hexahedron", "cell 6 is not a tetrahedron (VTK cell type 12)",
      [](vtkUnstructuredGrid* g)
      {
        const vtkIdType hex[8] = { 0, 1, 4, 3, 9, 10, 13, 12 };
        const vtkIdType keep = g->GetNumberOfCells();
        vtkNew<vtkUnstructuredGrid> copy;
        copy->SetPoints(g->GetPoints());
        copy->GetPointData()->ShallowCopy(g->GetPointData());
        for (vtkIdType c = 0; c < keep; ++c)
        {
          if (c == 6)
          {
            copy->InsertNextCell(VTK_HEXAHEDRON, 8, hex);
          }
          vtkNew<vtkIdList> ids;
          g->GetCellPoints(c, ids);
          copy->InsertNextCell(VTK_TETRA, ids);
        }
        g->ShallowCopy(copy);
      } },
    { "a NaN node", "point 5 or its RestPosition is not finite",
      [](vtkUnstructuredGrid* g) { g->GetPoints()->SetPoint(5, std::nan(""), 0.0, 0.0); } },
    // Beyond +-1e100, a tetrahedron's volume (the cube of its edges) and maps overflow: before, every point came
    // out as NaN or inf without a word.
    { "a node at 1e308", "Tetrahedral lattice point 5 or its RestPosition is not finite or lies beyond +-1e+100",
      [](vtkUnstructuredGrid* g) { g->GetPoints()->SetPoint(5, 1e308, 0.0, 0.0); } },
    { "a rest position at -1e101", "Tetrahedral lattice point 4 or its RestPosition is not finite or lies beyond",
      [](vtkUnstructuredGrid* g) { g->GetPointData()->GetArray("RestPosition")->SetComponent(4, 1, -1e101); } },
    // The contract's types: an integer RestPosition moved the mesh by its truncation, silently.
    { "an integer RestPosition", "RestPosition array holds int values; the data contract asks for doubles",
      [](vtkUnstructuredGrid* g)
      {
        vtkNew<vtkIntArray> rest;
        rest->DeepCopy(g->GetPointData()->GetArray("RestPosition"));
        rest->SetName("RestPosition");
        g->GetPointData()->AddArray(rest);
      } },
    { "a float RestPosition", "RestPosition array holds float values",
      [](vtkUnstructuredGrid* g)
      {
        vtkNew<vtkFloatArray> rest;
        rest->DeepCopy(g->GetPointData()->GetArray("RestPosition"));
        rest->SetName("RestPosition");
        g->GetPointData()->AddArray(rest);
      } },
    { "float nodes", "The tetrahedral lattice's points are float; the data contract asks for doubles",
      [](vtkUnstructuredGrid* g)
      {
        vtkNew<vtkPoints> points;
        points->SetDataTypeToFloat();
        points->DeepCopy(g->GetPoints());
        g->SetPoints(points);
      } },
    { "no cells", "has no cells",
      [](vtkUnstructuredGrid* g)
      {
        vtkNew<vtkCellArray> none;
        g->SetCells(VTK_TETRA, none);
      } },
    // Point ids outside the lattice, checked before any node is read through them (the id 77 of 4
    // points, a negative id, and a tetrahedron of three ids).
    { "id 77", "cell 2 names point 77, but the lattice has",
      [](vtkUnstructuredGrid* g) {
        g->GetCells()->ReplaceCellAtId(2, { 0, 1, 77, 3 });
      } },
    { "id -1", "cell 0 names point -1",
      [](vtkUnstructuredGrid* g) {
        g->GetCells()->ReplaceCellAtId(0, { 0, -1, 2, 3 });
      } },
    { "three ids", "is a tetrahedron of 3 point ids instead of 4",
      [](vtkUnstructuredGrid* g)
      {
        const vtkIdType three[3] = { 0, 1, 2 };
        g->InsertNextCell(VTK_TETRA, 3, three);
      } },
  };
  for (const Case& c : cases)
  {
    auto lattice = BoxLattice(2, 0.0, 1.0, 0.0, false, 1);
    c.Break(lattice);
    vtkNew<vtkFFDDeform> deform;
    deform->SetInputData(mesh);
    deform->SetLatticeData(lattice);
    const std::string errors = ffdtest::UpdateErrors(deform);
    EXPECT_NE(errors.find(c.Expected), std::string::npos) << c.Name << ": " << errors;
    EXPECT_EQ(deform->GetOutput()->GetNumberOfPoints(), 0) << c.Name;
  }
}

// The case: a node of the lattice built around a real mesh moved to 1e308 turned the whole mesh into NaN
// and inf; it is an error naming the node, with an empty output. Up to the bound, a lattice and mesh of 1e99
// deform as one of size 1: a translation of every node moves every point by it, within 1e-12 of the size.
TEST(vtkFFDDeformTetrahedral, NodesBeyondTheBoundAreErrorsAndLatticesUpToItDeform)
{
  vtkSmartPointer<vtkPolyData> mesh = ReadTestMesh("elephant");
  vtkNew<vtkFFDBuildTetrahedralLattice> build;
  build->SetInputData(mesh);
  build->Update();
  auto lattice = vtkSmartPointer<vtkUnstructuredGrid>::New();
  lattice->DeepCopy(build->GetOutput());
  const vtkIdType node = lattice->GetNumberOfPoints() - 1;
  lattice->GetPoints()->SetPoint(node, 1e308, 0.0, 0.0);
  vtkNew<vtkFFDDeform> deform;
  deform->SetInputData(mesh);
  deform->SetLatticeData(lattice);
  const std::string errors = ffdtest::UpdateErrors(deform);
  EXPECT_NE(errors.find("Tetrahedral lattice point " + std::to_string(node) +
              " or its RestPosition is not finite or lies beyond +-1e+100: the point is at (1e+308, 0, 0)"),
    std::string::npos)
    << errors;
  EXPECT_EQ(deform->GetOutput()->GetNumberOfPoints(), 0);

  const double scale = 1e99;
  auto big = BoxLattice(3, 0.0, scale, 0.0, false, 2);
  auto points = RandomPoints(200, 0.1 * scale, 0.9 * scale, VTK_DOUBLE, 62);
  const double shift[3] = { 0.25 * scale, -0.5 * scale, 0.125 * scale };
  for (vtkIdType p = 0; p < big->GetNumberOfPoints(); ++p)
  {
    double x[3];
    big->GetPoint(p, x);
    big->GetPoints()->SetPoint(p, x[0] + shift[0], x[1] + shift[1], x[2] + shift[2]);
  }
  vtkNew<vtkFFDDeform> large;
  large->SetInputData(points);
  large->SetLatticeData(big);
  large->Update();
  vtkPointSet* out = large->GetOutput();
  ASSERT_EQ(out->GetNumberOfPoints(), points->GetNumberOfPoints());
  double worst = 0.0;
  for (vtkIdType p = 0; p < points->GetNumberOfPoints(); ++p)
  {
    double x[3], y[3];
    points->GetPoint(p, x);
    out->GetPoint(p, y);
    for (int c = 0; c < 3; ++c)
    {
      worst = std::max(worst, std::fabs(y[c] - (x[c] + shift[c])) / scale);
    }
  }
  EXPECT_LE(worst, 1e-12);
}

// Ids edited in place after a first update (vtkCellArray's time does not follow its arrays'), and nodes taken
// away under tetrahedra that name them: both are checked again at the next update (one crashed, the other read
// stale memory).
TEST(vtkFFDDeformTetrahedral, IdsChangedAfterAnUpdateAreCheckedAgain)
{
  auto mesh = RandomPoints(100, 0.0, 1.0, VTK_DOUBLE, 62);
  for (bool shrink : { false, true })
  {
    auto lattice = BoxLattice(2, 0.0, 1.0, 0.0, false, 1);
    vtkNew<vtkFFDDeform> deform;
    vtkNew<FFDTestErrorObserver> observer;
    observer->WatchWithExecutive(deform);
    deform->SetInputData(mesh);
    deform->SetLatticeData(lattice);
    deform->Update();
    ASSERT_TRUE(observer->Errors.empty()) << observer->Errors;
    ASSERT_EQ(deform->GetOutput()->GetNumberOfPoints(), 100);
    const vtkIdType nodes = lattice->GetNumberOfPoints();
    if (shrink)
    {
      lattice->GetPoints()->SetNumberOfPoints(4);
      lattice->GetPointData()->GetArray("RestPosition")->SetNumberOfTuples(4);
      lattice->GetPoints()->Modified();
    }
    else
    {
      vtkDataArray* connectivity = lattice->GetCells()->GetConnectivityArray();
      connectivity->SetTuple1(6, double(nodes + 99999));
      connectivity->Modified();
    }
    lattice->Modified();
    deform->Update();
    EXPECT_NE(observer->Errors.find("names point"), std::string::npos) << shrink << ": " << observer->Errors;
    EXPECT_EQ(deform->GetOutput()->GetNumberOfPoints(), 0);
  }
}

// EXTRAPOLATE is a tetrahedral lattice's policy; a grid lattice says so.
TEST(vtkFFDDeformTetrahedral, ExtrapolateNeedsATetrahedralLattice)
{
  auto mesh = ReadTestMesh("cow");
  vtkNew<vtkFFDVoxelize> voxelize;
  voxelize->SetInputData(mesh);
  vtkNew<vtkFFDBuildLattice> build;
  build->SetInputConnection(voxelize->GetOutputPort());
  build->SetBasisToTrilinear();
  vtkNew<vtkFFDDeform> deform;
  deform->SetInputData(mesh);
  deform->SetLatticeConnection(build->GetOutputPort());
  deform->SetOutsidePolicyToExtrapolate();
  const std::string errors = ffdtest::UpdateErrors(deform);
  EXPECT_NE(errors.find("EXTRAPOLATE needs a tetrahedral lattice"), std::string::npos) << errors;
  EXPECT_EQ(deform->GetOutput()->GetNumberOfPoints(), 0);
}

//------------------------------------------------------------------------------------------------------------
// vtkFFDBuildTetrahedralLattice on a real mesh: positive tetrahedra that fill the convex hull (whose volume
// vtkDelaunay3D of the same points gives, as a peer), every mesh point inside, subdivision keeping the volume
// and adding one node per edge, and the nodes with a weight for some point marked active.
double Volume(vtkUnstructuredGrid* grid, vtkIdType cell, bool signedVolume = true)
{
  const auto n = Nodes(grid, cell);
  const double v = ffdref::SignedVolume(Point(grid->GetPoints(), n[0]), Point(grid->GetPoints(), n[1]),
    Point(grid->GetPoints(), n[2]), Point(grid->GetPoints(), n[3]));
  return signedVolume ? v : std::fabs(v);
}

TEST(vtkFFDBuildTetrahedralLattice, FillsTheConvexHullOfARealMesh)
{
  auto mesh = ReadTestMesh("cow");
  vtkNew<vtkFFDBuildTetrahedralLattice> build;
  build->SetInputData(mesh);
  build->SetPadding(0.0);
  build->Update();
  vtkUnstructuredGrid* lattice = build->GetOutput();
  EXPECT_EQ(lattice->GetNumberOfCells(), build->GetNumberOfHullFaces());
  EXPECT_EQ(lattice->GetNumberOfPoints(), build->GetNumberOfHullFaces() / 2 + 2 + 1); // Euler: V = F/2 + 2
  // The definition of the convex hull: every mesh point lies behind the plane of every outer face (the face
  // opposite the centroid, node 0), up to rounding, and the outer nodes are mesh points.
  double bounds[6];
  mesh->GetBounds(bounds);
  const double size = std::sqrt(vtkMath::Distance2BetweenPoints(bounds, bounds + 3));
  const Vec centroid = Point(lattice->GetPoints(), 0);
  double volume = 0.0;
  for (vtkIdType c = 0; c < lattice->GetNumberOfCells(); ++c)
  {
    EXPECT_GT(Volume(lattice, c), 0.0) << "tetrahedron " << c;
    volume += Volume(lattice, c);
    const auto n = Nodes(lattice, c);
    ASSERT_EQ(n[0], 0);
    const Vec a = Point(lattice->GetPoints(), n[1]), b = Point(lattice->GetPoints(), n[2]),
              d = Point(lattice->GetPoints(), n[3]);
    Vec normal = ffdref::Cross(ffdref::Sub(b, a), ffdref::Sub(d, a));
    const double length = std::sqrt(ffdref::Dot(normal, normal));
    const double side = ffdref::Dot(normal, ffdref::Sub(centroid, a)) < 0.0 ? 1.0 : -1.0; // outward
    for (int k = 0; k < 3; ++k)
    {
      normal[k] *= side / length;
    }
    for (vtkIdType i = 0; i < mesh->GetNumberOfPoints(); ++i)
    {
      ASSERT_LE(ffdref::Dot(normal, ffdref::Sub(Point(mesh->GetPoints(), i), a)), 1e-12 * size)
        << "mesh point " << i << " is outside face " << c;
    }
  }
  // vtkDelaunay3D of the same points as a peer for the volume: its tetrahedralization of the hull is not
  // exact at thin boundary slivers (0.14 % short on this mesh with Offset 10), hence 0.5 %.
  vtkNew<vtkDelaunay3D> delaunay;
  delaunay->SetInputData(mesh);
  delaunay->SetOffset(10.0);
  delaunay->Update();
  double hullVolume = 0.0;
  for (vtkIdType c = 0; c < delaunay->GetOutput()->GetNumberOfCells(); ++c)
  {
    hullVolume += Volume(delaunay->GetOutput(), c, false);
  }
  EXPECT_NEAR(volume, hullVolume, 5e-3 * hullVolume);
  ASSERT_TRUE(lattice->GetPointData()->GetArray("RestPosition"));
  EXPECT_EQ(lattice->GetPoints()->GetDataType(), VTK_DOUBLE);

  // With padding every mesh point lies strictly inside; each level multiplies the tetrahedra by 8, keeps the
  // volume (the padded hull's, (1 + padding)^3 times the hull's) and adds one node per edge.
  build->SetPadding(0.05);
  vtkIdType tetrahedra = 0, nodes = 0, coarseEdges = 0;
  for (int level = 0; level <= 2; ++level)
  {
    build->SetSubdivisionLevels(level);
    build->Update();
    double v = 0.0;
    std::set<std::pair<vtkIdType, vtkIdType>> edges;
    for (vtkIdType c = 0; c < lattice->GetNumberOfCells(); ++c)
    {
      ASSERT_GT(Volume(lattice, c), 0.0) << "level " << level << " tetrahedron " << c;
      v += Volume(lattice, c);
      const auto n = Nodes(lattice, c);
      for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j)
          edges.insert({ std::min(n[i], n[j]), std::max(n[i], n[j]) });
    }
    EXPECT_NEAR(v, std::pow(1.05, 3) * volume, 1e-12 * volume) << "level " << level;
    if (level > 0)
    {
      EXPECT_EQ(lattice->GetNumberOfCells(), 8 * tetrahedra);
      EXPECT_EQ(lattice->GetNumberOfPoints(), nodes + coarseEdges);
    }
    else
    {
      for (vtkIdType i = 0; i < mesh->GetNumberOfPoints(); ++i)
      {
        const Vec x = Point(mesh->GetPoints(), i);
        ASSERT_GE(ReferenceTetrahedron(lattice, x, 1e-12), 0) << "mesh point " << i << " is outside";
      }
    }
    tetrahedra = lattice->GetNumberOfCells();
    nodes = lattice->GetNumberOfPoints();
    coarseEdges = static_cast<vtkIdType>(edges.size());
  }
}

TEST(vtkFFDBuildTetrahedralLattice, MarksTheNodesOfTetrahedraHoldingPointsActive)
{
  auto mesh = ReadTestMesh("cow");
  vtkNew<vtkFFDBuildTetrahedralLattice> build;
  build->SetInputData(mesh);
  build->SetSubdivisionLevels(1);
  build->Update();
  vtkUnstructuredGrid* lattice = build->GetOutput();
  std::vector<unsigned char> expected(lattice->GetNumberOfPoints(), 0);
  for (vtkIdType i = 0; i < mesh->GetNumberOfPoints(); ++i)
  {
    const Vec x = Point(mesh->GetPoints(), i);
    const vtkIdType cell = ReferenceTetrahedron(lattice, x);
    ASSERT_GE(cell, 0) << "mesh point " << i << " is outside the control mesh";
    const auto w = [&]
    {
      const auto n = Nodes(lattice, cell);
      return ffdref::TetrahedronWeights(
        Rest(lattice, n[0]), Rest(lattice, n[1]), Rest(lattice, n[2]), Rest(lattice, n[3]), x);
    }();
    const auto n = Nodes(lattice, cell);
    for (int k = 0; k < 4; ++k)
    {
      if (w[k] > 1e-9) // a point on a face does not move the opposite node's weight
      {
        expected[n[k]] = 1;
      }
    }
  }
  auto* active = vtkUnsignedCharArray::SafeDownCast(lattice->GetPointData()->GetArray("Active"));
  ASSERT_TRUE(active);
  vtkUnsignedCharArray* ghosts = lattice->GetPointGhostArray();
  vtkIdType count = 0;
  for (vtkIdType p = 0; p < lattice->GetNumberOfPoints(); ++p)
  {
    EXPECT_EQ(active->GetValue(p), expected[p]) << "node " << p;
    count += expected[p];
    if (ghosts)
    {
      EXPECT_EQ(ghosts->GetValue(p) != 0, expected[p] == 0) << "node " << p;
    }
  }
  EXPECT_EQ(build->GetNumberOfActiveNodes(), count);
  EXPECT_LT(count, lattice->GetNumberOfPoints()); // the inner nodes hold no surface point
  EXPECT_TRUE(ghosts);
}

TEST(vtkFFDBuildTetrahedralLattice, SubdivisionsBeyondWhatALatticeHoldsAreErrors)
{
  // 100 000 points on a sphere: about 200 000 hull faces, times 8^5 tetrahedra at SubdivisionLevels 5, the
  // most it takes: 6.5e9 tetrahedra, more than the binding numbers by int (and some 2 PB at the estimated 300
  // bytes a tetrahedron). Refused before subdividing, with what was asked.
  vtkNew<vtkPoints> points;
  std::mt19937 rng(68);
  std::normal_distribution<double> normal;
  for (int i = 0; i < 100000; ++i)
  {
    double x[3] = { normal(rng), normal(rng), normal(rng) };
    const double r = std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
    points->InsertNextPoint(x[0] / r, x[1] / r, x[2] / r);
  }
  vtkNew<vtkPolyData> mesh;
  mesh->SetPoints(points);
  vtkNew<vtkFFDBuildTetrahedralLattice> build;
  vtkNew<FFDTestErrorObserver> observer;
  observer->WatchWithExecutive(build);
  build->SetInputData(mesh);
  build->SetSubdivisionLevels(12); // clamped to 5
  EXPECT_EQ(build->GetSubdivisionLevels(), 5);
  build->Update();
  EXPECT_NE(observer->Errors.find("SubdivisionLevels 5"), std::string::npos) << observer->Errors;
  EXPECT_NE(observer->Errors.find("tetrahedra a lattice may have"), std::string::npos) << observer->Errors;
  EXPECT_EQ(build->GetOutput()->GetNumberOfCells(), 0);
  EXPECT_GT(build->GetNumberOfHullFaces(), 100000);
}

TEST(vtkFFDBuildTetrahedralLattice, FlatOrTooFewPointsAreErrors)
{
  for (const int count : { 3, 200 })
  {
    vtkNew<vtkPoints> points;
    std::mt19937 rng(67);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (int i = 0; i < count; ++i)
    {
      points->InsertNextPoint(unit(rng), unit(rng), 0.25); // a plane
    }
    vtkNew<vtkPolyData> mesh;
    mesh->SetPoints(points);
    vtkNew<vtkFFDBuildTetrahedralLattice> build;
    vtkNew<FFDTestErrorObserver> observer;
    observer->WatchWithExecutive(build);
    build->SetInputData(mesh);
    build->Update();
    EXPECT_NE(observer->Errors.find(count < 4 ? "needs at least 4" : "coplanar"), std::string::npos)
      << observer->Errors;
    EXPECT_EQ(build->GetOutput()->GetNumberOfCells(), 0);
  }
}
} // namespace
