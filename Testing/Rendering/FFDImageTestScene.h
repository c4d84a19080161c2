// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDImageTestScene.h
 * @brief Set-up shared by the image regression tests of local and global lattices: a lattice of a basis over
 * a real mesh, control points moved in frame units, and a viewport that shows the deformed mesh coloured by
 * how far each point moved, with the lattice drawn by vtkFFDLatticeActor.
 */
#ifndef FFDImageTestScene_h
#define FFDImageTestScene_h

#include "vtkActor.h"
#include "vtkFFDBuildLattice.h"
#include "vtkFFDDataContract.h"
#include "vtkFFDDeform.h"
#include "vtkFFDLatticeActor.h"
#include "vtkFFDVoxelize.h"
#include "vtkFloatArray.h"
#include "vtkLookupTable.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkPolyDataMapper.h"
#include "vtkProperty.h"
#include "vtkRenderer.h"
#include "vtkSmartPointer.h"
#include "vtkStructuredGrid.h"

#include <algorithm>
#include <cmath>
#include <iostream>

/// A lattice whose points the test moves (a copy of vtkFFDBuildLattice's output), with what it was built from.
struct FFDTestLattice
{
  vtkSmartPointer<vtkStructuredGrid> Grid;
  vtkSmartPointer<vtkStructuredGrid> VoxelGrid; ///< vtkFFDVoxelize's output: inactive voxels hidden
  double Frame[12]; ///< X0, S, T, U
  int Divisions[3];
  int Dims[3]; ///< control points per axis
  vtkIdType ActiveVoxels = 0;
  vtkIdType ActiveControlPoints = 0;

  /// Id of control point (i, j, k).
  vtkIdType Id(int i, int j, int k) const { return i + this->Dims[0] * (j + vtkIdType(this->Dims[1]) * k); }

  /// Moves control point (i, j, k) by (ds, dt, du) in frame units: ds S + dt T + du U.
  void Move(int i, int j, int k, double ds, double dt, double du)
  {
    const vtkIdType id = this->Id(i, j, k);
    double p[3];
    this->Grid->GetPoint(id, p);
    for (int c = 0; c < 3; ++c)
    {
      p[c] += ds * this->Frame[3 + c] + dt * this->Frame[6 + c] + du * this->Frame[9 + c];
    }
    this->Grid->GetPoints()->SetPoint(id, p);
    this->Grid->GetPoints()->Modified();
  }
};

/// Voxelizes `mesh` into `divisions` voxels and builds the rest lattice of `basis`; false (and why on
/// stderr) when the pipeline fails or the lattice is not of `expectedDims` control points.
inline bool BuildTestLattice(
  vtkPolyData* mesh, const int divisions[3], int basis, const int expectedDims[3], FFDTestLattice& lattice)
{
  vtkNew<vtkFFDVoxelize> voxelize;
  voxelize->SetInputData(mesh);
  voxelize->SetDivisions(divisions[0], divisions[1], divisions[2]);
  vtkNew<vtkFFDBuildLattice> build;
  build->SetInputConnection(voxelize->GetOutputPort());
  build->SetBasis(basis);
  build->Update();
  lattice.Grid = vtkSmartPointer<vtkStructuredGrid>::New();
  lattice.Grid->DeepCopy(build->GetOutput());
  lattice.Grid->GetDimensions(lattice.Dims);
  lattice.VoxelGrid = vtkSmartPointer<vtkStructuredGrid>::New();
  lattice.VoxelGrid->DeepCopy(voxelize->GetOutput());
  std::copy(divisions, divisions + 3, lattice.Divisions);
  lattice.ActiveVoxels = voxelize->GetNumberOfActiveVoxels();
  lattice.ActiveControlPoints = build->GetNumberOfActiveControlPoints();
  if (!vtkFFDDataContract::GetFrame(lattice.Grid, lattice.Frame) || lattice.Dims[0] != expectedDims[0] ||
    lattice.Dims[1] != expectedDims[1] || lattice.Dims[2] != expectedDims[2])
  {
    std::cerr << "Expected a " << vtkFFDBuildLattice::GetBasisAsString(basis) << " lattice of "
              << expectedDims[0] << " x " << expectedDims[1] << " x " << expectedDims[2]
              << " control points with an FFDFrame, got " << lattice.Dims[0] << " x " << lattice.Dims[1] << " x "
              << lattice.Dims[2] << "\n";
    return false;
  }
  return true;
}

/// `mesh` deformed by `lattice`, with a `Displacement` point array: the distance each point moved.
inline vtkSmartPointer<vtkPolyData> DeformWithDisplacement(vtkPolyData* mesh, vtkPointSet* lattice)
{
  vtkNew<vtkFFDDeform> deform;
  deform->SetInputData(mesh);
  deform->SetLatticeData(lattice);
  deform->Update();
  auto deformed = vtkSmartPointer<vtkPolyData>::New();
  deformed->ShallowCopy(deform->GetOutput());
  if (deformed->GetNumberOfPoints() != mesh->GetNumberOfPoints())
  {
    return nullptr;
  }
  vtkNew<vtkFloatArray> distance;
  distance->SetName("Displacement");
  distance->SetNumberOfTuples(mesh->GetNumberOfPoints());
  for (vtkIdType p = 0; p < mesh->GetNumberOfPoints(); ++p)
  {
    double x[3], y[3];
    mesh->GetPoint(p, x);
    deformed->GetPoint(p, y);
    distance->SetValue(p, float(std::sqrt((y[0] - x[0]) * (y[0] - x[0]) + (y[1] - x[1]) * (y[1] - x[1]) +
                            (y[2] - x[2]) * (y[2] - x[2]))));
  }
  deformed->GetPointData()->SetScalars(distance);
  return deformed;
}

/// Points of a DeformWithDisplacement() result that moved by more than `tolerance`.
inline vtkIdType CountMovedPoints(vtkPolyData* deformed, double tolerance)
{
  vtkDataArray* distance = deformed->GetPointData()->GetArray("Displacement");
  vtkIdType moved = 0;
  for (vtkIdType p = 0; p < distance->GetNumberOfTuples(); ++p)
  {
    moved += distance->GetTuple1(p) > tolerance ? 1 : 0;
  }
  return moved;
}

/**
 * Adds the deformed mesh, coloured by its `Displacement` from ivory (did not move) to red (moved
 * `maxDisplacement` or more), and the lattice to `renderer`, on a white background. A dense lattice is drawn
 * with small spheres (`pointRadius` in world units, 0 for vtkFFDLatticeActor's automatic size) and thin,
 * light edges, so that the mesh stays visible through it. Returns the lattice's actor, for more settings.
 */
inline vtkFFDLatticeActor* AddDeformedScene(vtkRenderer* renderer, vtkPolyData* deformed, vtkPointSet* lattice,
  double maxDisplacement, double pointRadius = 0.0)
{
  vtkNew<vtkLookupTable> colours;
  colours->SetTableRange(0.0, maxDisplacement);
  colours->SetHueRange(0.12, 0.0);        // ivory-yellow to red
  colours->SetSaturationRange(0.1, 0.9);  // points that stay are nearly white
  colours->SetValueRange(0.95, 0.7);
  colours->Build();
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputData(deformed);
  mapper->SetLookupTable(colours);
  mapper->SetScalarRange(0.0, maxDisplacement);
  mapper->SetScalarModeToUsePointData();
  vtkNew<vtkActor> actor;
  actor->SetMapper(mapper);

  vtkNew<vtkFFDLatticeActor> latticeActor;
  latticeActor->SetInputData(lattice);
  if (pointRadius > 0.0)
  {
    latticeActor->SetPointRadius(pointRadius);
    latticeActor->GetEdgeProperty()->SetLineWidth(1.0);
    latticeActor->GetEdgeProperty()->SetColor(0.6, 0.6, 0.6);
  }

  renderer->AddActor(actor);
  renderer->AddActor(latticeActor);
  renderer->SetBackground(1.0, 1.0, 1.0);
  return latticeActor; // the renderer holds it
}

#endif
