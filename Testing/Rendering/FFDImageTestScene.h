// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDImageTestScene.h
 * @brief Set-up shared by the image regression tests of local and global lattices: a lattice of a basis over
 * a real mesh, control points moved in frame units, and a viewport that shows the deformed mesh coloured by
 * how far each point moved, with the lattice drawn by vtkFFDLatticeActor; the off-screen window, the camera
 * and the comparison with the baseline image that every image test uses.
 */
#ifndef FFDImageTestScene_h
#define FFDImageTestScene_h

#include "FFDTestMeshes.h"

#include "vtkActor.h"
#include "vtkCamera.h"
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
#include "vtkRegressionTestImage.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSmartPointer.h"
#include "vtkSphereSource.h"
#include "vtkStructuredGrid.h"
#include "vtkTesting.h"
#include "vtkUnstructuredGrid.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iostream>

/// A lattice whose points the test moves (a copy of vtkFFDBuildLattice's output), with what it was built from.
struct FFDTestLattice
{
  vtkSmartPointer<vtkStructuredGrid> Grid;
  vtkSmartPointer<vtkUnstructuredGrid> VoxelGrid; ///< vtkFFDVoxelize's output: the active voxels
  double Frame[12];                               ///< X0, S, T, U
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
  build->SetLatticeFormToDense(); // indexed as a grid (Id()); vtkFFDLatticeActor draws the dense form
  build->Update();
  lattice.Grid = vtkSmartPointer<vtkStructuredGrid>::New();
  lattice.Grid->DeepCopy(build->GetOutput());
  lattice.Grid->GetDimensions(lattice.Dims);
  lattice.VoxelGrid = vtkSmartPointer<vtkUnstructuredGrid>::New();
  lattice.VoxelGrid->DeepCopy(voxelize->GetOutput());
  std::copy(divisions, divisions + 3, lattice.Divisions);
  lattice.ActiveVoxels = voxelize->GetNumberOfActiveVoxels();
  lattice.ActiveControlPoints = build->GetNumberOfActiveControlPoints();
  if (!vtkFFDDataContract::GetFrame(lattice.Grid, lattice.Frame) || lattice.Dims[0] != expectedDims[0] ||
    lattice.Dims[1] != expectedDims[1] || lattice.Dims[2] != expectedDims[2])
  {
    std::cerr << "Expected a " << vtkFFDBuildLattice::GetBasisAsString(basis) << " lattice of " << expectedDims[0]
              << " x " << expectedDims[1] << " x " << expectedDims[2] << " control points with an FFDFrame, got "
              << lattice.Dims[0] << " x " << lattice.Dims[1] << " x " << lattice.Dims[2] << "\n";
    return false;
  }
  return true;
}

/// ReadTestMeshOrReport(name) into `mesh`, then BuildTestLattice() over it: false (and why on stderr) when
/// either fails.
inline bool ReadMeshAndBuildTestLattice(const char* name, const int divisions[3], int basis, const int expectedDims[3],
  vtkSmartPointer<vtkPolyData>& mesh, FFDTestLattice& lattice)
{
  mesh = ReadTestMeshOrReport(name);
  return mesh && BuildTestLattice(mesh, divisions, basis, expectedDims, lattice);
}

/// A copy of `deformed` (a deformation of `mesh`) with a `Displacement` point array: the distance each point moved.
inline vtkSmartPointer<vtkPolyData> WithDisplacement(vtkPolyData* mesh, vtkPolyData* deformed)
{
  if (!deformed || deformed->GetNumberOfPoints() != mesh->GetNumberOfPoints())
  {
    return nullptr;
  }
  auto copy = vtkSmartPointer<vtkPolyData>::New();
  copy->ShallowCopy(deformed);
  vtkNew<vtkFloatArray> distance;
  distance->SetName("Displacement");
  distance->SetNumberOfTuples(mesh->GetNumberOfPoints());
  for (vtkIdType p = 0; p < mesh->GetNumberOfPoints(); ++p)
  {
    double x[3], y[3];
    mesh->GetPoint(p, x);
    copy->GetPoint(p, y);
    distance->SetValue(p,
      float(std::sqrt((y[0] - x[0]) * (y[0] - x[0]) + (y[1] - x[1]) * (y[1] - x[1]) + (y[2] - x[2]) * (y[2] - x[2]))));
  }
  copy->GetPointData()->SetScalars(distance);
  return copy;
}

/// `mesh` deformed by `lattice`, with a `Displacement` point array: the distance each point moved.
inline vtkSmartPointer<vtkPolyData> DeformWithDisplacement(vtkPolyData* mesh, vtkPointSet* lattice)
{
  vtkNew<vtkFFDDeform> deform;
  deform->SetInputData(mesh);
  deform->SetLatticeData(lattice);
  deform->Update();
  return WithDisplacement(mesh, vtkPolyData::SafeDownCast(deform->GetOutputDataObject(0)));
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
inline vtkFFDLatticeActor* AddDeformedScene(
  vtkRenderer* renderer, vtkPolyData* deformed, vtkPointSet* lattice, double maxDisplacement, double pointRadius = 0.0)
{
  vtkNew<vtkLookupTable> colours;
  colours->SetTableRange(0.0, maxDisplacement);
  colours->SetHueRange(0.12, 0.0);       // ivory-yellow to red
  colours->SetSaturationRange(0.1, 0.9); // points that stay are nearly white
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

/// The magnetic sphere of the Figure 1 scenes: a blue sphere of `radius` at `centre`, added to `renderer`.
inline void AddMagnetSphere(vtkRenderer* renderer, const double centre[3], double radius)
{
  vtkNew<vtkSphereSource> sphere;
  sphere->SetCenter(centre[0], centre[1], centre[2]);
  sphere->SetRadius(radius);
  sphere->SetThetaResolution(32);
  sphere->SetPhiResolution(24);
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputConnection(sphere->GetOutputPort());
  vtkNew<vtkActor> actor;
  actor->SetMapper(mapper);
  actor->GetProperty()->SetColor(0.2, 0.3, 0.6);
  actor->GetProperty()->SetSpecular(0.5);
  renderer->AddActor(actor);
}

/// The image tests' window: off-screen, `width` x `height` pixels, without multisampling (it differs between GL
/// drivers; the comparison is about geometry).
inline vtkSmartPointer<vtkRenderWindow> NewTestRenderWindow(int width, int height)
{
  auto window = vtkSmartPointer<vtkRenderWindow>::New();
  window->SetOffScreenRendering(1);
  window->SetMultiSamples(0);
  window->SetSize(width, height);
  return window;
}

/**
 * Points the renderer's camera at a model standing along +Y and facing +Z (CGAL's bear and cow): from the front
 * (+Z, up +Y), turned by `azimuth` and `elevation` degrees, then fitted to `bounds` and zoomed by `zoom` (1: not
 * zoomed; ResetCamera fits the bounding sphere, leaving wide margins).
 */
inline void ViewFromFront(vtkRenderer* renderer, double azimuth, double elevation, const double bounds[6], double zoom)
{
  vtkCamera* camera = renderer->GetActiveCamera();
  camera->SetPosition(0.0, 0.0, 1.0);
  camera->SetFocalPoint(0.0, 0.0, 0.0);
  camera->SetViewUp(0.0, 1.0, 0.0);
  camera->Azimuth(azimuth);
  camera->Elevation(elevation);
  renderer->ResetCamera(bounds);
  if (zoom != 1.0)
  {
    camera->Zoom(zoom);
  }
}

/**
 * The test's result: EXIT_SUCCESS only when the window's image matches the baseline given by -V within
 * `threshold` (vtkTesting's image-difference error). vtkTesting::Test answers NOT_RUN without a -V baseline
 * argument: only a comparison that ran and matched passes.
 */
inline int CompareWithBaseline(int argc, char* argv[], vtkRenderWindow* window, double threshold)
{
  const int result = vtkRegressionTestImageThreshold(window, threshold);
  return result == vtkTesting::PASSED ? EXIT_SUCCESS : EXIT_FAILURE;
}

#endif
