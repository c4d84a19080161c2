// SPDX-License-Identifier: BSD-3-Clause
// Image regression test of a frame of the magnetic-sphere scene (the paper's Figure 1, issue 18): the bear in a
// 5 x 5 x 5-voxel TRILINEAR lattice whose active control points are simulated by vtkFFDLatticeDynamics (masses
// from the bear's points, springs, rigid core; the bottom layer pinned, as the bear sits) while a
// vtkFFDMagneticSphere circles the bear, as Examples/Python/magnetic_sphere.py does; after 1.5 s of
// simulated time (90 steps), the lattice, the sphere at its place then, and the bear deformed by the lattice,
// coloured by how far its points moved. Besides the picture: the simulation stays finite, the control points
// nearest the sphere moved toward it, and vtkFFDDeform kept its binding through the steps.
// Compared with Testing/Data/Baseline/TestFFDMagneticSphereImage.png.
#include "FFDImageTestScene.h"
#include "FFDTestMeshes.h"

#include "vtkFFDLatticeDynamics.h"
#include "vtkFFDMagneticSphere.h"
#include "vtkMath.h"
#include "vtkRenderWindow.h"

#include <cmath>
#include <cstdlib>
#include <iostream>

int TestFFDMagneticSphereImage(int argc, char* argv[])
{
  const int divisions[3] = { 5, 5, 5 };
  const int dims[3] = { 6, 6, 6 };
  vtkSmartPointer<vtkPolyData> bear;
  FFDTestLattice lattice;
  if (!ReadMeshAndBuildTestLattice("bear", divisions, vtkFFDBuildLattice::TRILINEAR, dims, bear, lattice))
  {
    return EXIT_FAILURE;
  }
  // The sphere's orbit: a circle around the bear in the horizontal plane through its middle (it stands along +Y),
  // 0.6 of its largest side from its axis, once every 4 s; it pulls what is within 0.6 of that side.
  double bounds[6];
  bear->GetBounds(bounds);
  const double size = std::max({ bounds[1] - bounds[0], bounds[3] - bounds[2], bounds[5] - bounds[4] });
  vtkNew<vtkPoints> path;
  for (int i = 0; i < 16; ++i)
  {
    const double angle = 2 * vtkMath::Pi() * i / 16;
    path->InsertNextPoint(0.5 * (bounds[0] + bounds[1]) + 0.6 * size * std::cos(angle), 0.5 * (bounds[2] + bounds[3]),
      0.5 * (bounds[4] + bounds[5]) + 0.6 * size * std::sin(angle));
  }
  vtkNew<vtkFFDMagneticSphere> sphere;
  sphere->SetPath(path);
  sphere->SetPeriod(4.0);
  sphere->SetRadius(0.1 * size);
  sphere->SetStrength(50.0);
  sphere->SetRange(0.6 * size);

  vtkNew<vtkFFDLatticeDynamics> dynamics;
  dynamics->SetLattice(lattice.Grid);
  dynamics->SetMesh(bear);
  dynamics->AddMagneticSphere(sphere);
  for (int k = 0; k < dims[2]; ++k) // the bottom layer (j = 0) stays where it rests
  {
    for (int i = 0; i < dims[0]; ++i)
    {
      const vtkIdType id = lattice.Id(i, 0, k);
      if (lattice.Grid->GetPointData()->GetArray("Active")->GetComponent(id, 0) != 0)
      {
        dynamics->PinPoint(id, lattice.Grid->GetPoint(id));
      }
    }
  }
  vtkNew<vtkFFDDeform> deform;
  deform->SetInputData(bear);
  deform->SetLatticeData(lattice.Grid);
  deform->Update();
  for (int frame = 0; frame < 45; ++frame) // 30 frames a second, 2 steps a frame
  {
    if (!dynamics->Step(2))
    {
      std::cerr << "vtkFFDLatticeDynamics::Step failed\n";
      return EXIT_FAILURE;
    }
    deform->Update();
  }
  double centre[3];
  sphere->GetCenterAt(dynamics->GetTime(), centre);
  std::cout << "t = " << dynamics->GetTime() << " s: " << dynamics->GetNumberOfSimulatedPoints()
            << " simulated control points, " << dynamics->GetNumberOfSprings() << " springs, kinetic energy "
            << dynamics->GetKineticEnergy() << "\n";
  if (deform->GetNumberOfBindings() != 1 || !std::isfinite(dynamics->GetKineticEnergy()))
  {
    std::cerr << "Expected one binding and a finite simulation\n";
    return EXIT_FAILURE;
  }
  // The simulated control point nearest the sphere moved toward it.
  vtkDataArray* rest = lattice.Grid->GetPointData()->GetArray("RestPosition");
  vtkIdType nearest = -1;
  double nearestDistance = VTK_DOUBLE_MAX;
  for (vtkIdType id = 0; id < lattice.Grid->GetNumberOfPoints(); ++id)
  {
    const double d = std::sqrt(vtkMath::Distance2BetweenPoints(lattice.Grid->GetPoint(id), centre));
    if (dynamics->GetMass(id) > 0 && d < nearestDistance)
    {
      nearest = id;
      nearestDistance = d;
    }
  }
  double x[3], x0[3], toward[3], moved[3];
  lattice.Grid->GetPoint(nearest, x);
  rest->GetTuple(nearest, x0);
  vtkMath::Subtract(x, x0, moved);
  vtkMath::Subtract(centre, x0, toward);
  if (vtkMath::Dot(moved, toward) <= 0)
  {
    std::cerr << "Expected control point " << nearest << ", the nearest to the sphere, to move toward it\n";
    return EXIT_FAILURE;
  }

  vtkSmartPointer<vtkPolyData> deformed = DeformWithDisplacement(bear, lattice.Grid);
  if (!deformed)
  {
    std::cerr << "vtkFFDDeform failed\n";
    return EXIT_FAILURE;
  }
  vtkNew<vtkRenderer> renderer;
  vtkFFDLatticeActor* latticeActor =
    AddDeformedScene(renderer, deformed, lattice.Grid, deformed->GetPointData()->GetScalars()->GetRange()[1]);
  latticeActor->GetEdgeProperty()->SetColor(0.55, 0.55, 0.55);
  latticeActor->GetEdgeProperty()->SetLineWidth(1.0);

  AddMagnetSphere(renderer, centre, sphere->GetRadius());

  vtkSmartPointer<vtkRenderWindow> window = NewTestRenderWindow(500, 500);
  window->AddRenderer(renderer);
  double view[6];
  for (int a = 0; a < 3; ++a)
  {
    const double middle = 0.5 * (bounds[2 * a] + bounds[2 * a + 1]);
    const double half = a == 1 ? 0.5 * (bounds[3] - bounds[2]) : 0.8 * size;
    view[2 * a] = middle - half;
    view[2 * a + 1] = middle + half;
  }
  ViewFromFront(renderer, 25.0, 20.0, view, 1.4);
  window->Render();
  // Threshold 0.05 as the other image tests.
  return CompareWithBaseline(argc, argv, window, 0.05);
}
