// SPDX-License-Identifier: BSD-3-Clause
// vtkFFDLatticeActor's ColorByFoldCertificate, checked on its parts rather than on an image: a dense trilinear
// lattice of 3^3 voxels with one control point pushed through its neighbour, certified by vtkFFDFoldCertificate;
// the actor's folded part draws, in red, exactly the edges of the cells the array marks folded (found here from
// the lattice's own cells, by their end points' positions), and nothing when the option is off or the lattice has
// no such array. The scene is rendered once, to show that the parts draw.
#include "vtkActor.h"
#include "vtkAssembly.h"
#include "vtkCell.h"
#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkFFDBuildLattice.h"
#include "vtkFFDFoldCertificate.h"
#include "vtkFFDLatticeActor.h"
#include "vtkFFDVoxelize.h"
#include "vtkMapper.h"
#include "vtkNew.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkProp3DCollection.h"
#include "vtkProperty.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkStructuredGrid.h"
#include "vtkUnsignedCharArray.h"

#include <array>
#include <cstdlib>
#include <iostream>
#include <set>
#include <utility>

namespace
{
using Point = std::array<double, 3>;
using Edge = std::pair<Point, Point>;

Edge MakeEdge(const Point& a, const Point& b)
{
  return a < b ? Edge{ a, b } : Edge{ b, a };
}

/// The edges of the lattice's cells whose FoldCertificate is `state`, by their end points.
std::set<Edge> CellEdges(vtkDataSet* lattice, int state)
{
  vtkUnsignedCharArray* states = vtkUnsignedCharArray::SafeDownCast(
    lattice->GetCellData()->GetArray(vtkFFDFoldCertificate::GetFoldCertificateArrayName()));
  std::set<Edge> edges;
  for (vtkIdType c = 0; c < lattice->GetNumberOfCells(); ++c)
  {
    if (states->GetValue(c) != state)
    {
      continue;
    }
    vtkCell* cell = lattice->GetCell(c);
    for (int e = 0; e < cell->GetNumberOfEdges(); ++e)
    {
      Point a, b;
      lattice->GetPoint(cell->GetEdge(e)->GetPointId(0), a.data());
      lattice->GetPoint(cell->GetEdge(e)->GetPointId(1), b.data());
      edges.insert(MakeEdge(a, b));
    }
  }
  return edges;
}

/// The lines the actor's part drawn with `property` shows (none where the part is hidden).
std::set<Edge> DrawnEdges(vtkFFDLatticeActor* actor, vtkProperty* property)
{
  actor->GetBounds(); // brings the parts up to date
  std::set<Edge> edges;
  vtkProp3DCollection* parts = actor->GetParts();
  parts->InitTraversal();
  while (vtkProp3D* prop = parts->GetNextProp3D())
  {
    vtkActor* part = vtkActor::SafeDownCast(prop);
    if (!part || part->GetProperty() != property || !part->GetVisibility())
    {
      continue;
    }
    part->GetMapper()->Update();
    vtkPolyData* lines = vtkPolyData::SafeDownCast(part->GetMapper()->GetInputDataObject(0, 0));
    vtkNew<vtkIdList> ids;
    for (lines->GetLines()->InitTraversal(); lines->GetLines()->GetNextCell(ids);)
    {
      Point a, b;
      lines->GetPoint(ids->GetId(0), a.data());
      lines->GetPoint(ids->GetId(1), b.data());
      edges.insert(MakeEdge(a, b));
    }
  }
  return edges;
}
} // namespace

int TestFFDFoldCertificateColors(int, char*[])
{
  // One point at each voxel's centre of the unit box split 3^3: every voxel active, a dense trilinear lattice.
  vtkNew<vtkPoints> centres;
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i)
        centres->InsertNextPoint((i + 0.5) / 3, (j + 0.5) / 3, (k + 0.5) / 3);
  vtkNew<vtkPolyData> cloud;
  cloud->SetPoints(centres);
  vtkNew<vtkFFDVoxelize> voxelize;
  voxelize->SetInputData(cloud);
  const double origin[3] = { 0, 0, 0 }, s[3] = { 1, 0, 0 }, t[3] = { 0, 1, 0 }, u[3] = { 0, 0, 1 };
  voxelize->SetFrame(origin, s, t, u);
  voxelize->SetDivisions(3, 3, 3);
  vtkNew<vtkFFDBuildLattice> build;
  build->SetInputConnection(voxelize->GetOutputPort());
  build->SetBasisToTrilinear();
  build->SetLatticeFormToDense();
  build->Update();
  vtkNew<vtkStructuredGrid> lattice;
  lattice->DeepCopy(build->GetOutputDataObject(0));
  const vtkIdType pushed = 1 + 4 * (1 + 4 * 1); // lattice index (1, 1, 1), 1/3 from its neighbour along x
  double x[3];
  lattice->GetPoint(pushed, x);
  lattice->GetPoints()->SetPoint(pushed, x[0] + 0.6, x[1], x[2]);

  vtkNew<vtkFFDFoldCertificate> certificate;
  certificate->SetInputData(lattice);
  certificate->Update();
  vtkDataSet* certified = vtkDataSet::SafeDownCast(certificate->GetOutputDataObject(0));
  const std::set<Edge> folded = CellEdges(certified, vtkFFDFoldCertificate::FOLDED);
  const std::set<Edge> undecided = CellEdges(certified, vtkFFDFoldCertificate::UNDECIDED);
  std::cout << certificate->GetNumberOfFoldedCells() << " folded cells (" << folded.size() << " edges), "
            << certificate->GetNumberOfUndecidedCells() << " undecided (" << undecided.size() << " edges)\n";

  vtkNew<vtkFFDLatticeActor> actor;
  actor->SetInputConnection(certificate->GetOutputPort());
  int failures = 0;
  auto expect = [&failures](bool ok, const char* what)
  {
    if (!ok)
    {
      std::cerr << "FAILED: " << what << "\n";
      ++failures;
    }
  };
  expect(DrawnEdges(actor, actor->GetFoldedCellProperty()).empty(), "nothing coloured while the option is off");
  actor->ColorByFoldCertificateOn();
  expect(!folded.empty(), "the pushed point folds some cells");
  expect(DrawnEdges(actor, actor->GetFoldedCellProperty()) == folded, "the folded cells' edges, exactly");
  expect(DrawnEdges(actor, actor->GetUndecidedCellProperty()) == undecided, "the undecided cells' edges, exactly");
  double red[3], orange[3];
  actor->GetFoldedCellProperty()->GetColor(red);
  actor->GetUndecidedCellProperty()->GetColor(orange);
  expect(red[0] > 0.8 && red[1] < 0.1 && red[2] < 0.1, "folded cells in red");
  expect(orange[0] > 0.9 && orange[1] > 0.4 && orange[1] < 0.8 && orange[2] < 0.1, "undecided cells in orange");

  vtkNew<vtkRenderer> renderer;
  renderer->AddActor(actor);
  vtkNew<vtkRenderWindow> window;
  window->SetOffScreenRendering(1);
  window->SetSize(200, 200);
  window->AddRenderer(renderer);
  window->Render();

  actor->SetInputData(lattice); // the same lattice without the array
  expect(DrawnEdges(actor, actor->GetFoldedCellProperty()).empty(), "nothing coloured without the array");
  window->Render();
  return failures == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
}
