// SPDX-License-Identifier: BSD-3-Clause
// Image regression test of a sparse lattice and a sparse voxel grid (docs/pipeline-and-data-contract.md,
// "Data contract"): the bear voxelized with 8 x 10 x 5 voxels and a sparse TRIQUADRATIC_BEZIER lattice over its active
// voxels only. The control points around the right ear (the viewer's left) are selected by their LatticeIndex and
// dragged up and out through vtkFFDLatticeRepresentation (the widget's geometry), as a drag would move them; the mesh
// follows through vtkFFDDeform without a new binding, and equals a fresh vtkFFDDeform of the moved lattice. Drawn with
// vtkFFDLatticeActor: the control net between existing control points only, and the active voxels' boxes only.
// Compared with Testing/Data/Baseline/TestFFDSparseLatticeImage.png.
#include "FFDImageTestScene.h"
#include "FFDTestMeshes.h"

#include "vtkFFDLatticeRepresentation.h"
#include "vtkIntArray.h"
#include "vtkRegressionTestImage.h"
#include "vtkRenderWindow.h"
#include "vtkTesting.h"

#include <cstdlib>
#include <cstring>
#include <iostream>

int TestFFDSparseLatticeImage(int argc, char* argv[])
{
  vtkSmartPointer<vtkPolyData> bear = ReadTestMeshOrReport("bear");
  if (!bear)
  {
    return EXIT_FAILURE;
  }
  vtkNew<vtkFFDVoxelize> voxelize;
  voxelize->SetInputData(bear);
  voxelize->SetDivisions(8, 10, 5);
  vtkNew<vtkFFDBuildLattice> build;
  build->SetInputConnection(voxelize->GetOutputPort());
  build->SetBasisToTriquadraticBezier(); // sparse: the default form of a local basis
  build->Update();
  auto lattice = vtkSmartPointer<vtkUnstructuredGrid>::New();
  lattice->DeepCopy(build->GetOutputDataObject(0));
  const vtkIdType dense = 17 * 21 * 11;
  std::cout << "bear: " << bear->GetNumberOfPoints() << " vertices, " << voxelize->GetNumberOfActiveVoxels()
            << " active voxels of 400, " << lattice->GetNumberOfPoints() << " control points of the dense " << dense
            << "\n";
  if (lattice->GetNumberOfPoints() == 0 || lattice->GetNumberOfPoints() >= dense)
  {
    std::cerr << "Expected a sparse lattice, smaller than the dense one\n";
    return EXIT_FAILURE;
  }

  vtkNew<vtkFFDDeform> deform;
  deform->SetInputData(bear);
  deform->SetLatticeData(lattice);
  deform->Update();

  // The ear: control points i 3-5, j 16-19 (the top of the head, the viewer's left), every k; dragged by
  // -0.05 S + 0.05 T: out and up.
  vtkNew<vtkFFDLatticeRepresentation> representation;
  representation->SetLattice(lattice);
  auto* index = vtkIntArray::SafeDownCast(lattice->GetPointData()->GetArray("LatticeIndex"));
  double frame[12];
  vtkFFDDataContract::GetFrame(lattice, frame);
  for (vtkIdType p = 0; p < lattice->GetNumberOfPoints(); ++p)
  {
    const int i = index->GetTypedComponent(p, 0), j = index->GetTypedComponent(p, 1);
    if (i >= 3 && i <= 5 && j >= 16 && j <= 19)
    {
      representation->SelectControlPoint(p);
    }
  }
  const vtkIdType selected = representation->GetNumberOfSelectedControlPoints();
  double delta[3];
  for (int c = 0; c < 3; ++c)
  {
    delta[c] = -0.05 * frame[3 + c] + 0.05 * frame[6 + c];
  }
  vtkNew<vtkUnstructuredGrid> before;
  before->DeepCopy(lattice);
  if (selected < 10 || !representation->MoveSelectedControlPoints(delta))
  {
    std::cerr << "Expected to select and move the ear's control points, selected " << selected << "\n";
    return EXIT_FAILURE;
  }
  for (vtkIdType p = 0; p < lattice->GetNumberOfPoints(); ++p)
  {
    double was[3], now[3];
    before->GetPoint(p, was);
    lattice->GetPoint(p, now);
    const bool moved = representation->IsControlPointSelected(p);
    for (int c = 0; c < 3; ++c)
    {
      if (now[c] != (moved ? was[c] + delta[c] : was[c]))
      {
        std::cerr << "Control point " << p << " is not where the drag puts it\n";
        return EXIT_FAILURE;
      }
    }
  }
  deform->Update();
  vtkSmartPointer<vtkPolyData> fresh = DeformWithDisplacement(bear, lattice);
  vtkPointSet* followed = vtkPointSet::SafeDownCast(deform->GetOutputDataObject(0));
  if (deform->GetNumberOfBindings() != 1 || !fresh ||
    std::memcmp(followed->GetPoints()->GetVoidPointer(0), fresh->GetPoints()->GetVoidPointer(0),
      followed->GetPoints()->GetData()->GetDataSize() * followed->GetPoints()->GetData()->GetDataTypeSize()) != 0)
  {
    std::cerr << "The mesh did not follow the sparse lattice without a new binding\n";
    return EXIT_FAILURE;
  }
  std::cout << selected << " control points dragged, " << CountMovedPoints(fresh, 1e-9) << " mesh points moved\n";

  vtkNew<vtkRenderer> renderer;
  vtkFFDLatticeActor* latticeActor = AddDeformedScene(
    renderer, fresh, lattice, fresh->GetPointData()->GetScalars()->GetRange()[1], 0.004 * lattice->GetLength());
  latticeActor->SetVoxelGridConnection(voxelize->GetOutputPort());
  vtkSmartPointer<vtkRenderWindow> window = NewTestRenderWindow(600, 600);
  window->AddRenderer(renderer);
  ViewFromFront(renderer, -35.0, 15.0, lattice->GetBounds(), 1.1);
  window->Render();
  // Threshold 0.05, as the other image tests: renders under Xvfb/llvmpipe are byte-identical across runs.
  return CompareWithBaseline(argc, argv, window, 0.05);
}
