// SPDX-License-Identifier: BSD-3-Clause
// Image regression test in the spirit of the paper's Figure 9 ("Simple Object Tetrahedron Decomposition"): the
// cow inside its tetrahedral control mesh, the convex hull of its points joined to their centroid
// (vtkFFDBuildTetrahedralLattice, subdivided once), with the nodes around its head pulled forward and up. The cow is
// coloured by how far its points moved; the control mesh is drawn by vtkFFDLatticeActor (active nodes red,
// culled grey). Besides the picture, locality is checked in numbers: a point moves only if it lies in a
// tetrahedron with a moved node. Compared with Testing/Data/Baseline/TestFFDTetrahedralImage.png.
#include "FFDImageTestScene.h"
#include "FFDTestMeshes.h"

#include "vtkCamera.h"
#include "vtkDataArray.h"
#include "vtkFFDBuildTetrahedralLattice.h"
#include "vtkGenericCell.h"
#include "vtkIdList.h"
#include "vtkRegressionTestImage.h"
#include "vtkRenderWindow.h"
#include "vtkStaticCellLocator.h"
#include "vtkTesting.h"
#include "vtkUnstructuredGrid.h"

#include <cstdlib>
#include <iostream>
#include <set>

int TestFFDTetrahedralImage(int argc, char* argv[])
{
  vtkSmartPointer<vtkPolyData> cow = ReadTestMeshOrReport("cow");
  if (!cow)
  {
    return EXIT_FAILURE;
  }
  vtkNew<vtkFFDBuildTetrahedralLattice> build;
  build->SetInputData(cow);
  build->SetSubdivisionLevels(1); // the hull's fan alone reaches from the nose to the centroid
  build->Update();
  vtkNew<vtkUnstructuredGrid> lattice;
  lattice->DeepCopy(build->GetOutput());
  std::cout << "cow: " << cow->GetNumberOfPoints() << " points; control mesh: " << build->GetNumberOfHullFaces()
            << " hull triangles, " << lattice->GetNumberOfCells() << " tetrahedra, " << lattice->GetNumberOfPoints()
            << " nodes, " << build->GetNumberOfActiveNodes() << " active\n";

  // The head: CGAL's cow looks along +X. Nodes in the front 15 % of its length move forward and up, the more
  // the further forward.
  double bounds[6];
  cow->GetBounds(bounds);
  const double front = bounds[1] - 0.15 * (bounds[1] - bounds[0]);
  std::set<vtkIdType> moved;
  for (vtkIdType id = 0; id < lattice->GetNumberOfPoints(); ++id)
  {
    double p[3];
    lattice->GetPoint(id, p);
    if (p[0] > front)
    {
      const double f = (p[0] - front) / (bounds[1] - front);
      p[0] += 0.25 * f;
      p[1] += 0.35 * f;
      lattice->GetPoints()->SetPoint(id, p);
      moved.insert(id);
    }
  }
  lattice->GetPoints()->Modified();
  std::cout << "moved " << moved.size() << " nodes\n";
  if (moved.empty())
  {
    std::cerr << "Expected some hull nodes at the head\n";
    return EXIT_FAILURE;
  }

  vtkSmartPointer<vtkPolyData> deformed = DeformWithDisplacement(cow, lattice);
  if (!deformed)
  {
    std::cerr << "vtkFFDDeform failed\n";
    return EXIT_FAILURE;
  }
  // Locality: a point whose rest tetrahedron (found by VTK's locator over the rest control mesh) has no moved
  // node keeps its position exactly. Points on faces between tetrahedra may belong to either: skipped.
  vtkNew<vtkUnstructuredGrid> rest;
  rest->DeepCopy(build->GetOutput());
  vtkNew<vtkStaticCellLocator> locator;
  locator->SetDataSet(rest);
  locator->BuildLocator();
  vtkDataArray* distance = deformed->GetPointData()->GetArray("Displacement");
  vtkIdType movedPoints = 0, checked = 0;
  for (vtkIdType p = 0; p < cow->GetNumberOfPoints(); ++p)
  {
    double x[3], pcoords[3], weights[4];
    cow->GetPoint(p, x);
    vtkNew<vtkGenericCell> cell;
    const vtkIdType tetrahedron = locator->FindCell(x, 0.0, cell, pcoords, weights);
    if (tetrahedron < 0 || *std::min_element(weights, weights + 4) < 1e-3)
    {
      continue;
    }
    ++checked;
    vtkNew<vtkIdList> nodes;
    rest->GetCellPoints(tetrahedron, nodes);
    bool hasMovedNode = false;
    for (vtkIdType k = 0; k < 4; ++k)
    {
      hasMovedNode = hasMovedNode || moved.count(nodes->GetId(k));
    }
    const bool pointMoved = distance->GetTuple1(p) > 0.0;
    movedPoints += pointMoved ? 1 : 0;
    if (pointMoved && !hasMovedNode)
    {
      std::cerr << "Point " << p << " moved although no node of its tetrahedron " << tetrahedron << " did\n";
      return EXIT_FAILURE;
    }
  }
  std::cout << "mesh points: " << movedPoints << " of " << checked << " checked moved\n";
  if (movedPoints == 0 || movedPoints > checked / 2)
  {
    std::cerr << "Expected the head to move, not most of the cow\n";
    return EXIT_FAILURE;
  }

  vtkNew<vtkRenderer> renderer;
  vtkFFDLatticeActor* latticeActor =
    AddDeformedScene(renderer, deformed, lattice, deformed->GetPointData()->GetScalars()->GetRange()[1], 0.006);
  latticeActor->GetEdgeProperty()->SetColor(0.62, 0.7, 0.88);
  latticeActor->GetEdgeProperty()->SetOpacity(0.6);

  vtkSmartPointer<vtkRenderWindow> window = NewTestRenderWindow(560, 420);
  window->AddRenderer(renderer);
  // CGAL's cow: length along X, up along +Y; seen from its side, a little from the front and above.
  ViewFromFront(renderer, -20.0, 12.0, lattice->GetBounds(), 1.3);
  window->Render();

  // Threshold 0.05 (vtkTesting's image-difference error), as the other image tests.
  return CompareWithBaseline(argc, argv, window, 0.05);
}
