// SPDX-License-Identifier: BSD-3-Clause
// Image regression test of GPU–GL interop: the bear with point normals in a cubic B-spline lattice (left) and in
// its tetrahedral control mesh (right), each drawn by vtkFFDInteropPolyDataMapper after three moves of its
// lattice. The last frame must match the same scene drawn from the host (Interop off: vtkOpenGLPolyDataMapper's
// path) within the baseline threshold of the other image tests, and match the baseline
// Testing/Data/Baseline/TestFFDInteropImage.png. On the GPU machine (VOXELFFD_EXPECT_INTEROP=1) the device must
// have written every moved frame, and no mesh-sized download happened (at most the bounds, 48 bytes a frame);
// elsewhere the host draws, and the frames are the same by construction.
#include "FFDImageTestScene.h"
#include "FFDInteropTestScene.h"

#include "vtkImageData.h"
#include "vtkImageDifference.h"
#include "vtkProperty.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkWindowToImageFilter.h"

#include <cmath>
#include <cstdlib>
#include <iostream>

namespace
{
vtkSmartPointer<vtkImageData> Capture(vtkRenderWindow* window)
{
  vtkNew<vtkWindowToImageFilter> capture;
  capture->SetInput(window);
  capture->ReadFrontBufferOff();
  capture->Update();
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->DeepCopy(capture->GetOutput());
  return image;
}

vtkSmartPointer<vtkRenderer> AddViewport(vtkRenderWindow* window, InteropPipeline& scene, double left, double right,
  const double bounds[6], const double colour[3])
{
  auto renderer = vtkSmartPointer<vtkRenderer>::New();
  renderer->SetViewport(left, 0.0, right, 1.0);
  renderer->SetBackground(1.0, 1.0, 1.0);
  scene.Actor->GetProperty()->SetColor(colour[0], colour[1], colour[2]);
  scene.Actor->GetProperty()->SetSpecular(0.3);
  renderer->AddActor(scene.Actor);
  ViewFromFront(renderer, 30.0, 10.0, bounds, 1.3);
  window->AddRenderer(renderer);
  return renderer;
}
} // namespace

int TestFFDInteropImage(int argc, char* argv[])
{
  vtkSmartPointer<vtkPolyData> bear = BearWithNormals();
  const int divisions[3] = { 4, 4, 4 }, dims[3] = { 7, 7, 7 };
  FFDTestLattice grid;
  if (!bear || !BuildTestLattice(bear, divisions, vtkFFDBuildLattice::CUBIC_BSPLINE, dims, grid))
  {
    return EXIT_FAILURE;
  }
  vtkSmartPointer<vtkUnstructuredGrid> tetrahedra = TetrahedralLatticeOf(bear);
  double bounds[6];
  bear->GetBounds(bounds);
  const double size = std::hypot(bounds[1] - bounds[0], bounds[3] - bounds[2], bounds[5] - bounds[4]);

  InteropPipeline onGrid(bear, grid.Grid), onTetrahedra(bear, tetrahedra);
  vtkSmartPointer<vtkRenderWindow> window = NewTestRenderWindow(600, 300);
  const double ivory[3] = { 0.93, 0.9, 0.8 }, sand[3] = { 0.85, 0.75, 0.6 };
  AddViewport(window, onGrid, 0.0, 0.5, bounds, ivory);
  AddViewport(window, onTetrahedra, 0.5, 1.0, bounds, sand);
  window->Render();

  // Three moves: the head leans to the right, by the grid's two upper layers of control points, and by the
  // tetrahedra's nodes, each by the square of its height over the bear's (a smooth bend).
  const bool device = ExpectInterop();
  int failures = 0;
  for (int move = 1; move <= 3; ++move)
  {
    for (int i = 0; i < dims[0]; ++i)
    {
      for (int k = 0; k < dims[2]; ++k)
      {
        grid.Move(i, 5, k, 0.06, 0.0, 0.0);
        grid.Move(i, 4, k, 0.03, 0.0, 0.0);
      }
    }
    for (vtkIdType id = 0; id < tetrahedra->GetNumberOfPoints(); ++id)
    {
      double p[3];
      tetrahedra->GetPoint(id, p);
      const double height = (p[1] - bounds[2]) / (bounds[3] - bounds[2]);
      tetrahedra->GetPoints()->SetPoint(id, p[0] + 0.05 * size * height * height, p[1], p[2]);
    }
    tetrahedra->GetPoints()->Modified();
    const vtkTypeUInt64 before = onGrid.Deform->GetBytesDownloaded() + onTetrahedra.Deform->GetBytesDownloaded();
    window->Render();
    const vtkTypeUInt64 downloaded =
      onGrid.Deform->GetBytesDownloaded() + onTetrahedra.Deform->GetBytesDownloaded() - before;
    const bool fromDevice = onGrid.Mapper->GetLastFrameFromDevice() && onTetrahedra.Mapper->GetLastFrameFromDevice();
    std::cout << "move " << move << ": " << (fromDevice ? "written by the device" : "uploaded from the host") << ", "
              << downloaded << " bytes downloaded\n";
    if (fromDevice != device || (device && downloaded > 2 * 48))
    {
      std::cerr << "move " << move << ": expected the frame "
                << (device ? "written by the device, the bounds alone downloaded" : "uploaded from the host") << "\n";
      ++failures;
    }
  }
  vtkSmartPointer<vtkImageData> interop = Capture(window);

  onGrid.Mapper->InteropOff();
  onTetrahedra.Mapper->InteropOff();
  window->Render();
  vtkSmartPointer<vtkImageData> host = Capture(window);
  vtkNew<vtkImageDifference> difference;
  difference->SetInputData(interop);
  difference->SetImageData(host);
  difference->Update();
  std::cout << "interop frame against the host frame: error " << difference->GetThresholdedError() << "\n";
  if (!(difference->GetThresholdedError() <= 0.05) || onGrid.Mapper->GetLastFrameFromDevice())
  {
    std::cerr << "Expected the interop frame to match the host frame within 0.05\n";
    ++failures;
  }
  onGrid.Mapper->InteropOn();
  onTetrahedra.Mapper->InteropOn();
  window->Render();
  const int baseline = CompareWithBaseline(argc, argv, window, 0.05);
  return failures == 0 ? baseline : EXIT_FAILURE;
}
