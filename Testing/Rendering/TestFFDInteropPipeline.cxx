// SPDX-License-Identifier: BSD-3-Clause
// GPU–GL interop keeps the pipeline honest (vtkFFDDeform drawn by vtkFFDInteropPolyDataMapper). After lattice
// moves, a downstream filter's update, the caller's Update(), a mesh change, det J asked for, a backend change, a
// window resize, a switch to a tetrahedral lattice and a mesh far from the origin (the buffers shifted and
// scaled), the vertex buffers that are drawn, read back from OpenGL,
// hold the points and normals of an independent float64 deformation on the CPU, within 1e-5 of the mesh's size
// (points) and 1e-5 (unit normals): the float32 evaluation's agreement with float64 that the other tests hold it
// to, plus the buffers' float rounding (2^-24 relative). A stale buffer is off by a move, 5-10 % of the size.
// Downstream, host points agree within the same bound. The path is the expected one: on the GPU machine
// (VOXELFFD_EXPECT_INTEROP=1, Utilities/gpu-rendering.sh) the device writes the buffers of every frame after the
// first, downloading only the bounds (at most 48 bytes a frame); elsewhere (Mesa, no GPU) the host draws every
// frame. Either way the mapper logs exactly one line about interop.
#include "FFDImageTestScene.h"
#include "FFDInteropTestScene.h"

#include "vtkElevationFilter.h"
#include "vtkLogger.h"
#include "vtkPoints.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"

#include <array>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <string>

namespace
{
void CountInteropLines(void* count, const vtkLogger::Message& message)
{
  if (std::string(message.message).find("GPU-GL interop") != std::string::npos)
  {
    ++*static_cast<int*>(count);
  }
}

/// Moves the tetrahedral lattice's nodes in the front 20 % of the bear along +x forward and up, by `amount`.
void MoveFront(vtkUnstructuredGrid* lattice, const double bounds[6], double amount)
{
  const double front = bounds[1] - 0.2 * (bounds[1] - bounds[0]);
  for (vtkIdType id = 0; id < lattice->GetNumberOfPoints(); ++id)
  {
    double p[3];
    lattice->GetPoint(id, p);
    if (p[0] > front)
    {
      p[0] += amount;
      p[1] += amount;
      lattice->GetPoints()->SetPoint(id, p);
    }
  }
  lattice->GetPoints()->Modified();
}

/// A copy of `mesh` (cells and normals shared) with its points x -> c + scale (x - c) + offset, c its centre, in
/// double precision: a mesh change.
vtkSmartPointer<vtkPolyData> Moved(vtkPolyData* mesh, double scale, double offset)
{
  double c[3];
  mesh->GetCenter(c);
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(mesh->GetNumberOfPoints());
  for (vtkIdType p = 0; p < points->GetNumberOfPoints(); ++p)
  {
    double x[3];
    mesh->GetPoint(p, x);
    for (int a = 0; a < 3; ++a)
    {
      x[a] = c[a] + scale * (x[a] - c[a]) + offset;
    }
    points->SetPoint(p, x);
  }
  auto moved = vtkSmartPointer<vtkPolyData>::New();
  moved->ShallowCopy(mesh);
  moved->SetPoints(points);
  return moved;
}
} // namespace

int TestFFDInteropPipeline(int, char*[])
{
  int interopLines = 0;
  vtkLogger::AddCallback("interop-lines", CountInteropLines, &interopLines, vtkLogger::VERBOSITY_INFO);
  vtkSmartPointer<vtkPolyData> bear = BearWithNormals();
  const int divisions[3] = { 4, 4, 4 }, dims[3] = { 7, 7, 7 };
  FFDTestLattice lattice;
  if (!bear || !BuildTestLattice(bear, divisions, vtkFFDBuildLattice::CUBIC_BSPLINE, dims, lattice))
  {
    return EXIT_FAILURE;
  }
  const bool device = ExpectInterop();
  double bounds[6];
  bear->GetBounds(bounds);
  const double size = std::hypot(bounds[1] - bounds[0], bounds[3] - bounds[2], bounds[5] - bounds[4]);

  InteropPipeline scene(bear, lattice.Grid);
  vtkNew<vtkRenderer> renderer;
  renderer->AddActor(scene.Actor);
  vtkSmartPointer<vtkRenderWindow> window = NewTestRenderWindow(300, 300);
  window->AddRenderer(renderer);
  ViewFromFront(renderer, 20.0, 10.0, bounds, 1.0);

  int failures = 0;
  vtkPolyData* mesh = bear;
  vtkPointSet* latticeData = lattice.Grid;
  vtkSmartPointer<vtkPolyData> reference;
  // Renders a frame and checks its buffers, its path and what it downloaded.
  auto frame = [&](const char* step, bool fromDevice)
  {
    const vtkTypeUInt64 downloadedBefore = scene.Deform->GetBytesDownloaded();
    window->Render();
    const vtkTypeUInt64 downloaded = scene.Deform->GetBytesDownloaded() - downloadedBefore;
    reference = ReferenceDeformation(mesh, latticeData);
    const double points =
      LargestBufferError(scene.Mapper, window, "vertexMC", reference->GetPoints()->GetData()) / size;
    const double normals =
      LargestBufferError(scene.Mapper, window, "normalMC", reference->GetPointData()->GetNormals());
    const bool drawnFromDevice = scene.Mapper->GetLastFrameFromDevice();
    std::cout << step << ": points within " << points << " of the size, normals within " << normals
              << (drawnFromDevice ? ", written by the device" : ", uploaded from the host") << ", " << downloaded
              << " bytes downloaded\n";
    if (!(points <= 1e-5) || !(normals <= 1e-5) || drawnFromDevice != fromDevice || (fromDevice && downloaded > 48))
    {
      std::cerr << step << ": expected buffers within 1e-5, "
                << (fromDevice ? "written by the device with at most 48 bytes downloaded" : "uploaded from the host")
                << "\n";
      ++failures;
    }
  };
  // A consumer's host points (a downstream filter's output, or the output after the caller's Update()).
  auto hostPoints = [&](const char* step, vtkPointSet* points)
  {
    const double error = LargestDistance(points, reference) / size;
    std::cout << step << ": host points within " << error << " of the size\n";
    if (!(error <= 1e-5))
    {
      std::cerr << step << ": expected the deformed points within 1e-5\n";
      ++failures;
    }
  };

  frame("first frame", false); // the first bounds are asked for before the mapper knows its context
  for (int move = 1; move <= 3; ++move)
  {
    lattice.Move(5, 3 + move % 2, 3, 0.15, 0.1 * move, 0.0);
    frame(("move " + std::to_string(move)).c_str(), device);
  }

  vtkNew<vtkElevationFilter> downstream;
  downstream->SetInputConnection(scene.Deform->GetOutputPort());
  downstream->Update();
  hostPoints("downstream filter", vtkPointSet::SafeDownCast(downstream->GetOutput()));
  lattice.Move(1, 2, 3, -0.2, 0.0, 0.1);
  frame("move after the downstream filter", device);
  scene.Deform->Update();
  hostPoints("the caller's Update()", vtkPointSet::SafeDownCast(scene.Deform->GetOutputDataObject(0)));
  frame("frame after the caller's Update()", false); // the download is drawn
  lattice.Move(2, 2, 2, 0.1, 0.1, 0.1);
  frame("move after the caller's Update()", device);

  vtkSmartPointer<vtkPolyData> shrunk = Moved(bear, 0.9, 0.0);
  mesh = shrunk;
  scene.Deform->SetInputData(shrunk);
  frame("mesh change", device);

  scene.Deform->ComputeJacobianDeterminantOn();
  lattice.Move(5, 5, 5, 0.1, 0.0, -0.1);
  frame("det J asked for", false);
  scene.Deform->ComputeJacobianDeterminantOff();
  scene.Deform->SetBackendToCPU();
  lattice.Move(4, 4, 4, -0.1, 0.1, 0.0);
  frame("CPU backend", false);
  scene.Deform->SetBackendToAutomatic();
  lattice.Move(4, 4, 4, 0.1, -0.1, 0.0);
  frame("automatic backend", device);

  window->SetSize(420, 300);
  lattice.Move(3, 5, 2, 0.0, 0.0, 0.2);
  frame("resized window", device);

  vtkSmartPointer<vtkUnstructuredGrid> tetrahedra = TetrahedralLatticeOf(bear);
  latticeData = tetrahedra;
  scene.Deform->SetLatticeData(tetrahedra);
  MoveFront(tetrahedra, bounds, 0.05 * size);
  frame("tetrahedral lattice", device);
  MoveFront(tetrahedra, bounds, 0.05 * size);
  frame("tetrahedral lattice moved", device);

  // Far from the origin (2000 sizes away, in float64), where vtkOpenGLPolyDataMapper stores the points shifted and
  // scaled (AUTO_SHIFT_SCALE: more than 1000 diagonals away): the device must write them with the same shift and
  // scale. The float64 evaluation and the buffers' shift keep the bound of 1e-5 of the size.
  vtkSmartPointer<vtkPolyData> far = Moved(bear, 1.0, 2000.0 * size);
  FFDTestLattice farLattice;
  if (!BuildTestLattice(
        far, divisions, vtkFFDBuildLattice::TRILINEAR, std::array<int, 3>{ 5, 5, 5 }.data(), farLattice))
  {
    return EXIT_FAILURE;
  }
  mesh = far;
  latticeData = farLattice.Grid;
  scene.Deform->SetInputData(far);
  scene.Deform->SetLatticeData(farLattice.Grid);
  renderer->ResetCamera();
  frame("far from the origin", device); // a new mesh and lattice: bound again, on the device
  farLattice.Move(2, 4, 2, 0.1, 0.1, 0.0);
  frame("far from the origin, moved", device);
  if (!scene.Mapper->GetVBOs()->GetVBO("vertexMC")->GetCoordShiftAndScaleEnabled())
  {
    std::cerr << "Expected the points' buffer shifted and scaled far from the origin\n";
    ++failures;
  }

  const std::string status = scene.Mapper->GetInteropStatus();
  std::cout << "interop lines logged: " << interopLines << "; status: " << (status.empty() ? "on" : status) << "\n";
  if (interopLines != 1 || status.empty() == !device)
  {
    std::cerr << "Expected one line about interop and interop " << (device ? "on" : "off, with the reason") << "\n";
    ++failures;
  }
  vtkLogger::RemoveCallback("interop-lines");
  return failures == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
}
