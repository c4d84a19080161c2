// SPDX-License-Identifier: BSD-3-Clause
// Interaction test of vtkFFDLatticeWidget, driven by synthesised events (the interactor's event information set
// to display positions computed from the renderer's world-to-display transform, then the VTK events invoked,
// as a recorded vtkInteractorEventRecorder session would): the bear with a 5 x 5 x 5 TRILINEAR lattice
// (4 x 4 x 4 voxels), deformed through vtkFFDDeform whose lattice is the widget's.
// 1. press on control point (4, 2, 2), drag it 60 x 40 pixels in two moves, release: that control point moves by
//    the expected world vector (the cursor's motion on the plane through it parallel to the view plane), no other
//    control point moves, the mesh equals a fresh vtkFFDDeform of the moved lattice, and the binding was not
//    recomputed (vtkFFDDeform::GetNumberOfBindings() stays 1);
// 2. click (4, 3, 2), Shift+press (4, 1, 2) and drag: both move together by the same vector;
// 3. key `x`: every control point is back at RestPosition and the mesh at its input position;
// 4. a last drag, compared with Testing/Data/Baseline/TestFFDLatticeWidget.png (the widget's selection
//    highlight and the deformed arm).
#include "FFDImageTestScene.h"
#include "FFDTestMeshes.h"

#include "vtkCamera.h"
#include "vtkCommand.h"
#include "vtkDataArray.h"
#include "vtkFFDLatticeRepresentation.h"
#include "vtkFFDLatticeWidget.h"
#include "vtkIdList.h"
#include "vtkInteractorObserver.h"
#include "vtkInteractorStyleTrackballCamera.h"
#include "vtkMath.h"
#include "vtkRegressionTestImage.h"
#include "vtkRenderWindow.h"
#include "vtkRenderWindowInteractor.h"
#include "vtkTesting.h"

#include <cmath>
#include <cstdlib>
#include <iostream>
#include <string>

namespace
{
// Control points are moved by the difference of two display-to-world conversions: equal to the expected vector
// up to rounding, far below this fraction of the lattice's diagonal.
constexpr double PointTolerance = 1e-9;

struct Scene
{
  vtkRenderer* Renderer;
  vtkRenderWindowInteractor* Interactor;
};

void DisplayPosition(vtkRenderer* renderer, const double world[3], double display[3])
{
  vtkInteractorObserver::ComputeWorldToDisplay(renderer, world[0], world[1], world[2], display);
}

/// The world vector of a cursor motion from `from` to `to` (display pixels) at display depth `depth`.
void ExpectedMotion(vtkRenderer* renderer, const int from[2], const int to[2], double depth, double motion[3])
{
  double a[4], b[4];
  vtkInteractorObserver::ComputeDisplayToWorld(renderer, from[0], from[1], depth, a);
  vtkInteractorObserver::ComputeDisplayToWorld(renderer, to[0], to[1], depth, b);
  for (int c = 0; c < 3; ++c)
  {
    motion[c] = b[c] - a[c];
  }
}

void Event(vtkRenderWindowInteractor* interactor, unsigned long event, const int position[2], bool shift)
{
  interactor->SetEventInformation(position[0], position[1], 0, shift ? 1 : 0);
  interactor->InvokeEvent(event, nullptr);
}

/// Press at `from`, move in two steps to `to`, release there.
void Drag(vtkRenderWindowInteractor* interactor, const int from[2], const int to[2], bool shift)
{
  Event(interactor, vtkCommand::MouseMoveEvent, from, shift);
  Event(interactor, vtkCommand::LeftButtonPressEvent, from, shift);
  const int middle[2] = { (from[0] + to[0]) / 2, (from[1] + to[1]) / 2 };
  Event(interactor, vtkCommand::MouseMoveEvent, middle, shift);
  Event(interactor, vtkCommand::MouseMoveEvent, to, shift);
  Event(interactor, vtkCommand::LeftButtonReleaseEvent, to, shift);
}

/// Checks every control point against `expected` (a copy of the lattice with the expected moves).
bool CheckLattice(vtkStructuredGrid* lattice, vtkStructuredGrid* expected, double diagonal, const char* step)
{
  const double error = LargestDistance(lattice, expected);
  std::cout << step << ": control points within " << error << " of the expected positions\n";
  if (error > PointTolerance * diagonal)
  {
    std::cerr << step << ": control points off by " << error << ", more than " << PointTolerance
              << " of the lattice's diagonal\n";
    return false;
  }
  return true;
}

/// The mesh as the widget's pipeline left it against a fresh vtkFFDDeform of `expected`.
bool CheckMesh(vtkFFDDeform* deform, vtkPolyData* mesh, vtkStructuredGrid* expected, double diagonal, const char* step,
  double* largestMotion = nullptr)
{
  deform->Update();
  vtkNew<vtkFFDDeform> fresh;
  fresh->SetInputData(mesh);
  fresh->SetLatticeData(expected);
  fresh->Update();
  const double error = LargestDistance(deform->GetOutput(), fresh->GetOutput());
  std::cout << step << ": mesh within " << error << " of a fresh deformation; bindings "
            << deform->GetNumberOfBindings() << "\n";
  if (largestMotion)
  {
    *largestMotion = LargestDistance(deform->GetOutput(), mesh);
  }
  // Both run the same evaluation on the same numbers: any difference beyond the control points' own
  // tolerance means the pipeline did not re-execute.
  if (error > PointTolerance * diagonal || deform->GetNumberOfBindings() != 1)
  {
    std::cerr << step << ": expected the mesh to follow the lattice with the cached binding (1 binding)\n";
    return false;
  }
  return true;
}

void Translate(vtkStructuredGrid* grid, vtkIdType id, const double motion[3])
{
  double p[3];
  grid->GetPoint(id, p);
  grid->GetPoints()->SetPoint(id, p[0] + motion[0], p[1] + motion[1], p[2] + motion[2]);
  grid->GetPoints()->Modified();
}
}

int TestFFDLatticeWidget(int argc, char* argv[])
{
  const int divisions[3] = { 4, 4, 4 };
  const int dims[3] = { 5, 5, 5 };
  vtkSmartPointer<vtkPolyData> bear;
  FFDTestLattice lattice;
  if (!ReadMeshAndBuildTestLattice("bear", divisions, vtkFFDBuildLattice::TRILINEAR, dims, bear, lattice))
  {
    return EXIT_FAILURE;
  }
  vtkStructuredGrid* grid = lattice.Grid;
  const double diagonal = grid->GetLength();
  vtkNew<vtkStructuredGrid> expected; // the lattice as the test expects it after each step
  expected->DeepCopy(grid);

  vtkNew<vtkFFDDeform> deform;
  deform->SetInputData(bear);
  deform->SetLatticeData(grid);
  vtkNew<vtkPolyDataMapper> meshMapper;
  meshMapper->SetInputConnection(deform->GetOutputPort());
  vtkNew<vtkActor> meshActor;
  meshActor->SetMapper(meshMapper);
  meshActor->GetProperty()->SetColor(0.93, 0.9, 0.8);

  vtkNew<vtkRenderer> renderer;
  renderer->AddActor(meshActor);
  renderer->SetBackground(1.0, 1.0, 1.0);
  vtkSmartPointer<vtkRenderWindow> window = NewTestRenderWindow(500, 500);
  window->AddRenderer(renderer);
  vtkNew<vtkRenderWindowInteractor> interactor;
  interactor->SetRenderWindow(window);
  vtkNew<vtkInteractorStyleTrackballCamera> style; // what the widget does not use goes to the camera
  interactor->SetInteractorStyle(style);

  vtkNew<vtkFFDLatticeWidget> widget;
  widget->SetInteractor(interactor);
  widget->CreateDefaultRepresentation();
  vtkFFDLatticeRepresentation* rep = widget->GetLatticeRepresentation();
  rep->SetLattice(grid);
  widget->On();

  ViewFromFront(renderer, 20.0, 15.0, grid->GetBounds(), 1.0);
  window->Render();
  if (deform->GetNumberOfBindings() != 1)
  {
    std::cerr << "Expected the first render to bind the mesh once\n";
    return EXIT_FAILURE;
  }

  // 1. Drag control point (4, 2, 2), on the +S face at the height of the bear's left arm.
  const vtkIdType arm = lattice.Id(4, 2, 2);
  double display[3];
  DisplayPosition(renderer, grid->GetPoint(arm), display);
  const int from[2] = { int(std::lround(display[0])), int(std::lround(display[1])) };
  const int to[2] = { from[0] + 60, from[1] + 40 };
  double motion[3];
  ExpectedMotion(renderer, from, to, display[2], motion);
  Drag(interactor, from, to, false);
  Translate(expected, arm, motion);
  double largestMotion = 0.0;
  if (!CheckLattice(grid, expected, diagonal, "drag") ||
    !CheckMesh(deform, bear, expected, diagonal, "drag", &largestMotion))
  {
    return EXIT_FAILURE;
  }
  // The arm follows the control point: its points move by up to the control point's motion (a point at the
  // control point would move by all of it; the arm's nearest points get most of it).
  const double motionLength = vtkMath::Norm(motion);
  std::cout << "control point moved " << motionLength << ", mesh points by up to " << largestMotion << "\n";
  if (largestMotion < 0.3 * motionLength || largestMotion > motionLength * (1.0 + 1e-9))
  {
    std::cerr << "Expected the mesh to move by 30 % to 100 % of the control point's motion at most\n";
    return EXIT_FAILURE;
  }
  if (rep->GetNumberOfSelectedControlPoints() != 1 || !rep->IsControlPointSelected(arm))
  {
    std::cerr << "Expected the dragged control point to stay selected, alone\n";
    return EXIT_FAILURE;
  }

  // 2. Select (4, 3, 2) by a click, add (4, 1, 2) with Shift and drag it: both move by its drag vector.
  const vtkIdType upper = lattice.Id(4, 3, 2);
  const vtkIdType lower = lattice.Id(4, 1, 2);
  DisplayPosition(renderer, grid->GetPoint(upper), display);
  const int click[2] = { int(std::lround(display[0])), int(std::lround(display[1])) };
  Drag(interactor, click, click, false);
  DisplayPosition(renderer, grid->GetPoint(lower), display);
  const int from2[2] = { int(std::lround(display[0])), int(std::lround(display[1])) };
  const int to2[2] = { from2[0] - 30, from2[1] - 50 };
  ExpectedMotion(renderer, from2, to2, display[2], motion);
  Drag(interactor, from2, to2, true);
  Translate(expected, upper, motion);
  Translate(expected, lower, motion);
  vtkNew<vtkIdList> selected;
  rep->GetSelectedControlPoints(selected);
  if (selected->GetNumberOfIds() != 2 || !rep->IsControlPointSelected(upper) || !rep->IsControlPointSelected(lower))
  {
    std::cerr << "Expected control points " << upper << " and " << lower << " selected, got "
              << selected->GetNumberOfIds() << " points\n";
    return EXIT_FAILURE;
  }
  if (!CheckLattice(grid, expected, diagonal, "group drag") ||
    !CheckMesh(deform, bear, expected, diagonal, "group drag"))
  {
    return EXIT_FAILURE;
  }

  // 3. Key `x`: back to rest.
  interactor->SetKeyEventInformation(0, 0, vtkFFDLatticeWidget::GetResetKey(), 0, "x");
  interactor->InvokeEvent(vtkCommand::KeyPressEvent, nullptr);
  vtkDataArray* rest = grid->GetPointData()->GetArray("RestPosition");
  for (vtkIdType id = 0; id < grid->GetNumberOfPoints(); ++id)
  {
    expected->GetPoints()->SetPoint(id, rest->GetTuple3(id));
  }
  expected->GetPoints()->Modified();
  if (!CheckLattice(grid, expected, 0.0, "reset") || !CheckMesh(deform, bear, expected, diagonal, "reset"))
  {
    return EXIT_FAILURE;
  }
  const double restError = LargestDistance(deform->GetOutput(), bear);
  if (restError > PointTolerance * diagonal)
  {
    std::cerr << "Expected the rest lattice to give back the input mesh, off by " << restError << "\n";
    return EXIT_FAILURE;
  }

  // 4. A last drag of the arm's control point, for the picture.
  DisplayPosition(renderer, grid->GetPoint(arm), display);
  const int from3[2] = { int(std::lround(display[0])), int(std::lround(display[1])) };
  const int to3[2] = { from3[0] + 50, from3[1] + 70 };
  Drag(interactor, from3, to3, false);
  if (deform->GetNumberOfBindings() != 1)
  {
    std::cerr << "Expected no new binding over the whole interaction\n";
    return EXIT_FAILURE;
  }
  window->Render();

  // Threshold 0.05 (vtkTesting's image-difference error), as the other image tests.
  return CompareWithBaseline(argc, argv, window, 0.05);
}
