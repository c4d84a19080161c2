// SPDX-License-Identifier: BSD-3-Clause
// Image regression test of the paper's section III.C ("local crash damage"): the cow, the long mesh of the test
// set, in four blocks along its length, each a 3 x 3 x 3 TRILINEAR lattice of its quarter, deformed together by
// vtkFFDDeformBlocks. The front block's upper corner on the viewer's side (the head) is dented; every point
// outside that block must keep its coordinates bit for bit (checked here too). The cow is coloured by how far its
// points moved; the dented block's lattice is drawn with its points, the others as thin grey edges. Compared with
// Testing/Data/Baseline/TestFFDCarCrashImage.png.
#include "FFDImageTestScene.h"

#include "vtkFFDDeformBlocks.h"

#include <vector>

int TestFFDCarCrashImage(int argc, char* argv[])
{
  vtkSmartPointer<vtkPolyData> cow = ReadTestMeshOrReport("cow");
  if (!cow)
  {
    return EXIT_FAILURE;
  }
  double b[6];
  cow->GetBounds(b);
  const double pad = 0.01 * (b[1] - b[0]);
  const double length = (b[1] - b[0] + 2 * pad) / 4;
  std::vector<vtkSmartPointer<vtkUnstructuredGrid>> blocks;
  vtkNew<vtkFFDDeformBlocks> crash;
  crash->SetInputData(cow);
  for (int i = 0; i < 4; ++i)
  {
    const double x0[3] = { b[0] - pad + i * length, b[2] - pad, b[4] - pad };
    const double s[3] = { length, 0, 0 }, t[3] = { 0, b[3] - b[2] + 2 * pad, 0 },
                 u[3] = { 0, 0, b[5] - b[4] + 2 * pad };
    vtkNew<vtkFFDVoxelize> voxelize;
    voxelize->SetInputData(cow);
    voxelize->SetFrame(x0, s, t, u);
    voxelize->SetDivisions(3, 3, 3);
    vtkNew<vtkFFDBuildLattice> build;
    build->SetInputConnection(voxelize->GetOutputPort());
    build->SetBasisToTrilinear();
    build->Update();
    auto block = vtkSmartPointer<vtkUnstructuredGrid>::New();
    block->DeepCopy(build->GetOutput());
    blocks.push_back(block);
    crash->AddLatticeData(block);
  }

  // The dent: control points of block 3 with s > 0.5, t > 0.5, u > 0.5 (its upper front corner on the +z side)
  // pushed down and in by up to 40% of the block's height and depth, most at the corner.
  const double height = b[3] - b[2] + 2 * pad, depth = b[5] - b[4] + 2 * pad;
  const double front = b[0] - pad + 3 * length;
  vtkUnstructuredGrid* dented = blocks[3];
  vtkDataArray* rest = dented->GetPointData()->GetArray("RestPosition");
  vtkIdType moved = 0;
  for (vtkIdType p = 0; p < dented->GetNumberOfPoints(); ++p)
  {
    double x[3];
    rest->GetTuple(p, x);
    const double stu[3] = { (x[0] - front) / length, (x[1] - (b[2] - pad)) / height, (x[2] - (b[4] - pad)) / depth };
    if (stu[0] > 0.5 && stu[1] > 0.5 && stu[2] > 0.5)
    {
      const double amount = 0.4 * 8 * (stu[0] - 0.5) * (stu[1] - 0.5) * (stu[2] - 0.5);
      dented->GetPoints()->SetPoint(p, x[0], x[1] - amount * height, x[2] - amount * depth);
      ++moved;
    }
  }
  dented->GetPoints()->Modified();
  crash->Update();
  vtkSmartPointer<vtkPolyData> deformed =
    WithDisplacement(cow, vtkPolyData::SafeDownCast(crash->GetOutputDataObject(0)));
  if (!deformed)
  {
    std::cerr << "vtkFFDDeformBlocks failed\n";
    return EXIT_FAILURE;
  }

  // Every point behind block 3 keeps its coordinates bit for bit.
  vtkIdType changedOutside = 0, changedInside = 0;
  for (vtkIdType p = 0; p < cow->GetNumberOfPoints(); ++p)
  {
    double x[3], y[3];
    cow->GetPoint(p, x);
    deformed->GetPoint(p, y);
    const bool changed = x[0] != y[0] || x[1] != y[1] || x[2] != y[2];
    (x[0] < front ? changedOutside : changedInside) += changed;
  }
  std::cout << "cow: " << cow->GetNumberOfPoints() << " points; " << moved << " control points dented; "
            << changedInside << " points moved in the dented block, " << changedOutside << " beyond it\n";
  if (changedOutside != 0 || changedInside == 0)
  {
    std::cerr << "Expected the dent to move points of the front block only\n";
    return EXIT_FAILURE;
  }

  vtkNew<vtkRenderer> renderer;
  vtkFFDLatticeActor* dentedActor =
    AddDeformedScene(renderer, deformed, dented, deformed->GetPointData()->GetScalars()->GetRange()[1]);
  dentedActor->GetEdgeProperty()->SetLineWidth(1.0);
  dentedActor->SetPointRadius(0.008);
  for (int i = 0; i < 3; ++i)
  {
    vtkNew<vtkFFDLatticeActor> latticeActor;
    latticeActor->SetInputData(blocks[i]);
    latticeActor->SetPointRadius(0.003);
    latticeActor->GetEdgeProperty()->SetLineWidth(1.0);
    latticeActor->GetEdgeProperty()->SetColor(0.7, 0.7, 0.7);
    renderer->AddActor(latticeActor);
  }
  vtkSmartPointer<vtkRenderWindow> window = NewTestRenderWindow(640, 400);
  window->AddRenderer(renderer);
  ViewFromFront(renderer, 35.0, 20.0, cow->GetBounds(), 1.25);
  window->Render();
  return CompareWithBaseline(argc, argv, window, 0.05);
}
