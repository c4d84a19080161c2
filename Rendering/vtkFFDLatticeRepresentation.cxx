// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDLatticeRepresentation.h"

#include "vtkActor.h"
#include "vtkCellArray.h"
#include "vtkDataArray.h"
#include "vtkFFDDataContract.h"
#include "vtkFFDDeform.h"
#include "vtkFFDDirectManipulation.h"
#include "vtkFFDLatticeActor.h"
#include "vtkGlyph3DMapper.h"
#include "vtkIdList.h"
#include "vtkIdTypeArray.h"
#include "vtkInteractorObserver.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkPropCollection.h"
#include "vtkProperty.h"
#include "vtkRenderer.h"
#include "vtkSphereSource.h"

#include <functional>
#include <set>

vtkStandardNewMacro(vtkFFDLatticeRepresentation);

struct vtkFFDLatticeRepresentation::vtkInternals
{
  vtkNew<vtkFFDLatticeActor> LatticeActor;
  std::set<vtkIdType> Selection;     // ordered: GetSelectedControlPoints() lists ids in increasing order
  vtkIdType SelectionPointCount = 0; // the lattice's number of points when the selection was made

  /// Drops the selection once `lattice`'s number of points is no longer the one it was made on (the lattice
  /// re-executed upstream, or its points replaced): its ids then name other points or none, which a move would
  /// write out of bounds. True when it was dropped.
  bool DropStaleSelection(vtkPointSet* lattice)
  {
    const vtkIdType count = lattice && lattice->GetPoints() ? lattice->GetNumberOfPoints() : 0;
    if (this->Selection.empty() || count == this->SelectionPointCount)
    {
      return false;
    }
    this->Selection.clear();
    return true;
  }

  // The selected control points, drawn as spheres larger than the lattice actor's, around them.
  vtkNew<vtkPolyData> SelectedPoints;
  vtkNew<vtkSphereSource> SelectedSphere;
  vtkNew<vtkGlyph3DMapper> SelectedMapper;
  vtkNew<vtkActor> SelectedActor;

  // Direct manipulation: the mesh deformed (for picking), the solve, and the drag's start: the lattice then,
  // the mesh point and where it was.
  vtkNew<vtkFFDDeform> Deform;
  vtkNew<vtkFFDDirectManipulation> Manipulate;
  vtkSmartPointer<vtkPointSet> DragStartLattice;
  vtkIdType DraggedMeshPoint = -1;
  double DragStartPoint[3] = { 0.0, 0.0, 0.0 };
  double DragStartWorld[3] = { 0.0, 0.0, 0.0 };
};

namespace
{
/**
 * The point of `points` nearest the display position (X, Y) within `tolerance` pixels and inside the clipping
 * range, among those `pickable`; among points within a pixel of each other (a lattice row seen end-on), the
 * nearest to the camera. -1 when none.
 */
vtkIdType NearestOnScreen(
  vtkRenderer* renderer, vtkPoints* points, int X, int Y, int tolerance, const std::function<bool(vtkIdType)>& pickable)
{
  const double tolerance2 = double(tolerance) * tolerance;
  double bestDistance2 = VTK_DOUBLE_MAX;
  double bestDepth = VTK_DOUBLE_MAX;
  vtkIdType best = -1;
  for (vtkIdType id = 0; id < points->GetNumberOfPoints(); ++id)
  {
    if (!pickable(id))
    {
      continue;
    }
    double x[3], display[3];
    points->GetPoint(id, x);
    vtkInteractorObserver::ComputeWorldToDisplay(renderer, x[0], x[1], x[2], display);
    const double dx = display[0] - X;
    const double dy = display[1] - Y;
    const double distance2 = dx * dx + dy * dy;
    if (distance2 > tolerance2 || display[2] < 0.0 || display[2] > 1.0) // beyond the clipping range
    {
      continue;
    }
    const bool nearer = distance2 < bestDistance2 - 1.0;
    const bool asNearAndInFront = distance2 <= bestDistance2 + 1.0 && display[2] < bestDepth;
    if (nearer || asNearAndInFront)
    {
      bestDistance2 = distance2;
      bestDepth = display[2];
      best = id;
    }
  }
  return best;
}
} // namespace

//------------------------------------------------------------------------------
vtkFFDLatticeRepresentation::vtkFFDLatticeRepresentation()
  : Internals(new vtkInternals)
{
  vtkInternals& in = *this->Internals;
  in.SelectedSphere->SetThetaResolution(16);
  in.SelectedSphere->SetPhiResolution(12);
  in.SelectedMapper->SetInputData(in.SelectedPoints);
  in.SelectedMapper->SetSourceConnection(in.SelectedSphere->GetOutputPort());
  in.SelectedMapper->ScalingOff();
  in.SelectedMapper->OrientOff();
  in.SelectedMapper->ScalarVisibilityOff();
  in.SelectedActor->SetMapper(in.SelectedMapper);
  in.SelectedActor->GetProperty()->SetColor(1.0, 0.85, 0.0);
  this->InteractionState = Outside;
}

//------------------------------------------------------------------------------
vtkFFDLatticeRepresentation::~vtkFFDLatticeRepresentation()
{
  this->SetLattice(nullptr);
  this->SetMesh(nullptr);
}

//------------------------------------------------------------------------------
void vtkFFDLatticeRepresentation::SetLattice(vtkPointSet* lattice)
{
  if (this->Lattice == lattice)
  {
    return;
  }
  if (this->Lattice)
  {
    this->Lattice->UnRegister(this);
  }
  this->Lattice = lattice;
  if (this->Lattice)
  {
    this->Lattice->Register(this);
  }
  this->Internals->LatticeActor->SetInputData(lattice);
  this->Internals->Deform->SetLatticeData(lattice);
  this->Internals->Selection.clear();
  this->HoveredControlPoint = -1;
  this->HoveredMeshPoint = -1;
  this->Modified();
}

//------------------------------------------------------------------------------
void vtkFFDLatticeRepresentation::SetMesh(vtkPointSet* mesh)
{
  if (this->Mesh == mesh)
  {
    return;
  }
  if (this->Mesh)
  {
    this->Mesh->UnRegister(this);
  }
  this->Mesh = mesh;
  if (this->Mesh)
  {
    this->Mesh->Register(this);
  }
  this->Internals->Deform->SetInputData(mesh);
  this->HoveredMeshPoint = -1;
  this->Modified();
}

//------------------------------------------------------------------------------
vtkPointSet* vtkFFDLatticeRepresentation::GetDeformedMesh()
{
  if (!this->Lattice || !this->Mesh)
  {
    return nullptr;
  }
  vtkFFDDeform* deform = this->Internals->Deform;
  deform->Update(); // re-executes only when the lattice moved, with its binding kept
  return deform->GetOutput();
}

//------------------------------------------------------------------------------
bool vtkFFDLatticeRepresentation::SolveMeshPoint(vtkPointSet* from, vtkIdType id, const double target[3])
{
  vtkFFDDirectManipulation* manipulate = this->Internals->Manipulate;
  vtkNew<vtkIdTypeArray> ids;
  ids->InsertNextValue(id);
  vtkNew<vtkPoints> targets;
  targets->SetDataTypeToDouble();
  targets->InsertNextPoint(target);
  manipulate->SetInputData(from);
  manipulate->SetMeshData(this->Mesh);
  manipulate->SetTargetPointIds(ids);
  manipulate->SetTargetPositions(targets);
  manipulate->Update();
  vtkPointSet* moved = manipulate->GetOutput();
  if (!moved->GetPoints() || moved->GetNumberOfPoints() != this->Lattice->GetNumberOfPoints())
  {
    return false; // the filter reported why
  }
  this->Lattice->GetPoints()->DeepCopy(moved->GetPoints());
  this->Lattice->GetPoints()->Modified();
  this->Modified();
  return true;
}

//------------------------------------------------------------------------------
bool vtkFFDLatticeRepresentation::MoveMeshPoint(vtkIdType id, const double target[3])
{
  if (!this->Lattice || !this->Lattice->GetPoints() || !this->Mesh)
  {
    vtkErrorMacro("Moving a mesh point needs the lattice (SetLattice()) and the mesh at rest it deforms "
                  "(SetMesh()).");
    return false;
  }
  if (id < 0 || id >= this->Mesh->GetNumberOfPoints())
  {
    vtkErrorMacro(
      "Mesh point " << id << " is not a point of the mesh (" << this->Mesh->GetNumberOfPoints() << " points).");
    return false;
  }
  // The solve reads its input while the lattice is overwritten: it starts from a copy.
  vtkSmartPointer<vtkPointSet> from = vtkSmartPointer<vtkPointSet>::Take(this->Lattice->NewInstance());
  from->DeepCopy(this->Lattice);
  return this->SolveMeshPoint(from, id, target);
}

//------------------------------------------------------------------------------
vtkFFDLatticeActor* vtkFFDLatticeRepresentation::GetLatticeActor()
{
  return this->Internals->LatticeActor;
}

//------------------------------------------------------------------------------
vtkProperty* vtkFFDLatticeRepresentation::GetSelectedPointProperty()
{
  return this->Internals->SelectedActor->GetProperty();
}

//------------------------------------------------------------------------------
bool vtkFFDLatticeRepresentation::IsPickable(vtkIdType id)
{
  if (!this->Lattice || id < 0 || id >= this->Lattice->GetNumberOfPoints())
  {
    return false;
  }
  if (this->PickCulledPoints)
  {
    return true;
  }
  // A lattice without `Active` (or with a malformed one, which vtkFFDControlPoints reports) counts every point
  // as active.
  vtkDataArray* active = this->Lattice->GetPointData()->GetArray(vtkFFDDataContract::ActiveArrayName());
  if (!active || active->GetNumberOfComponents() != 1 ||
    active->GetNumberOfTuples() != this->Lattice->GetNumberOfPoints())
  {
    return true;
  }
  return active->GetComponent(id, 0) != 0.0;
}

//------------------------------------------------------------------------------
bool vtkFFDLatticeRepresentation::SelectControlPoint(vtkIdType id)
{
  if (!this->IsPickable(id))
  {
    return false;
  }
  this->Internals->DropStaleSelection(this->Lattice);
  this->Internals->SelectionPointCount = this->Lattice->GetNumberOfPoints();
  if (this->Internals->Selection.insert(id).second)
  {
    this->Modified();
  }
  return true;
}

//------------------------------------------------------------------------------
void vtkFFDLatticeRepresentation::DeselectControlPoint(vtkIdType id)
{
  if (this->Internals->Selection.erase(id) > 0)
  {
    this->Modified();
  }
}

//------------------------------------------------------------------------------
bool vtkFFDLatticeRepresentation::ToggleControlPoint(vtkIdType id)
{
  if (this->IsControlPointSelected(id))
  {
    this->DeselectControlPoint(id);
    return false;
  }
  return this->SelectControlPoint(id);
}

//------------------------------------------------------------------------------
void vtkFFDLatticeRepresentation::ClearSelection()
{
  if (!this->Internals->Selection.empty())
  {
    this->Internals->Selection.clear();
    this->Modified();
  }
}

//------------------------------------------------------------------------------
bool vtkFFDLatticeRepresentation::IsControlPointSelected(vtkIdType id) const
{
  this->Internals->DropStaleSelection(this->Lattice);
  return this->Internals->Selection.count(id) > 0;
}

//------------------------------------------------------------------------------
vtkIdType vtkFFDLatticeRepresentation::GetNumberOfSelectedControlPoints() const
{
  this->Internals->DropStaleSelection(this->Lattice);
  return static_cast<vtkIdType>(this->Internals->Selection.size());
}

//------------------------------------------------------------------------------
void vtkFFDLatticeRepresentation::GetSelectedControlPoints(vtkIdList* ids) const
{
  if (!ids)
  {
    return;
  }
  ids->Reset();
  this->Internals->DropStaleSelection(this->Lattice);
  for (vtkIdType id : this->Internals->Selection)
  {
    ids->InsertNextId(id);
  }
}

//------------------------------------------------------------------------------
bool vtkFFDLatticeRepresentation::MoveSelectedControlPoints(const double delta[3])
{
  if (this->Internals->DropStaleSelection(this->Lattice))
  {
    this->Modified();
  }
  if (!this->Lattice || !this->Lattice->GetPoints() || this->Internals->Selection.empty())
  {
    return false;
  }
  vtkPoints* points = this->Lattice->GetPoints();
  for (vtkIdType id : this->Internals->Selection)
  {
    double x[3];
    points->GetPoint(id, x);
    points->SetPoint(id, x[0] + delta[0], x[1] + delta[1], x[2] + delta[2]);
  }
  // The points' MTime is what vtkFFDDeform's pipeline sees (the lattice's MTime includes it): the deformation
  // re-executes at the next update, with the cached binding since the rest frame did not change.
  points->Modified();
  this->Modified();
  return true;
}

//------------------------------------------------------------------------------
bool vtkFFDLatticeRepresentation::ResetLatticeToRest()
{
  if (!this->Lattice || !this->Lattice->GetPoints())
  {
    vtkErrorMacro("No lattice to reset: call SetLattice() with the lattice that vtkFFDDeform reads.");
    return false;
  }
  const vtkIdType n = this->Lattice->GetNumberOfPoints();
  vtkDataArray* rest = this->Lattice->GetPointData()->GetArray(vtkFFDDataContract::RestPositionArrayName());
  if (!rest || rest->GetNumberOfComponents() != 3 || rest->GetNumberOfTuples() != n)
  {
    vtkErrorMacro("The lattice has no `" << vtkFFDDataContract::RestPositionArrayName()
                                         << "` point array of 3 components per control point (" << n
                                         << "), so its rest positions are unknown: build it with "
                                         << "vtkFFDBuildLattice or add that array.");
    return false;
  }
  vtkPoints* points = this->Lattice->GetPoints();
  for (vtkIdType id = 0; id < n; ++id)
  {
    points->SetPoint(id, rest->GetTuple3(id));
  }
  points->Modified();
  this->Modified();
  return true;
}

//------------------------------------------------------------------------------
int vtkFFDLatticeRepresentation::ComputeInteractionState(int X, int Y, int)
{
  this->HoveredControlPoint = -1;
  this->HoveredMeshPoint = -1;
  if (this->InteractionState == Moving)
  {
    return this->InteractionState; // a drag keeps its control points until it ends
  }
  this->InteractionState = Outside;
  // vtkAbstractWidget::SetEnabled() asks before the first render, when the renderer may have no camera yet:
  // nothing is on screen to pick then.
  if (!this->Lattice || !this->Lattice->GetPoints() || !this->Renderer || !this->Renderer->IsActiveCameraCreated())
  {
    return this->InteractionState;
  }
  if (this->ManipulationMode == MESH_POINTS)
  {
    vtkPointSet* deformed = this->GetDeformedMesh();
    if (deformed && deformed->GetPoints())
    {
      this->HoveredMeshPoint =
        NearestOnScreen(this->Renderer, deformed->GetPoints(), X, Y, this->Tolerance, [](vtkIdType) { return true; });
    }
    this->InteractionState = this->HoveredMeshPoint >= 0 ? OverMeshPoint : Outside;
    return this->InteractionState;
  }
  this->HoveredControlPoint = NearestOnScreen(this->Renderer, this->Lattice->GetPoints(), X, Y, this->Tolerance,
    [this](vtkIdType id) { return this->IsPickable(id); });
  if (this->HoveredControlPoint >= 0)
  {
    this->InteractionState = OverControlPoint;
  }
  return this->InteractionState;
}

//------------------------------------------------------------------------------
void vtkFFDLatticeRepresentation::StartWidgetInteraction(double eventPosition[2])
{
  vtkInternals& in = *this->Internals;
  const bool meshPoint = this->ManipulationMode == MESH_POINTS;
  vtkPointSet* deformed = meshPoint ? this->GetDeformedMesh() : nullptr;
  if (!this->Lattice || !this->Renderer ||
    (meshPoint ? !deformed || this->HoveredMeshPoint < 0 || this->HoveredMeshPoint >= deformed->GetNumberOfPoints()
               : !this->IsPickable(this->HoveredControlPoint)))
  {
    return;
  }
  // The drag plane goes through the picked point, parallel to the view plane: its display depth.
  double x[3], display[3], world[4];
  if (meshPoint)
  {
    deformed->GetPoint(this->HoveredMeshPoint, x);
    in.DraggedMeshPoint = this->HoveredMeshPoint;
    std::copy_n(x, 3, in.DragStartPoint);
    in.DragStartLattice = vtkSmartPointer<vtkPointSet>::Take(this->Lattice->NewInstance());
    in.DragStartLattice->DeepCopy(this->Lattice);
  }
  else
  {
    this->Lattice->GetPoint(this->HoveredControlPoint, x);
  }
  vtkInteractorObserver::ComputeWorldToDisplay(this->Renderer, x[0], x[1], x[2], display);
  this->InteractionDepth = display[2];
  vtkInteractorObserver::ComputeDisplayToWorld(
    this->Renderer, eventPosition[0], eventPosition[1], this->InteractionDepth, world);
  for (int c = 0; c < 3; ++c)
  {
    this->LastWorldPosition[c] = in.DragStartWorld[c] = world[c];
  }
  this->StartEventPosition[0] = eventPosition[0];
  this->StartEventPosition[1] = eventPosition[1];
  this->StartEventPosition[2] = 0.0;
  this->InteractionState = Moving;
}

//------------------------------------------------------------------------------
void vtkFFDLatticeRepresentation::WidgetInteraction(double eventPosition[2])
{
  if (this->InteractionState != Moving || !this->Renderer)
  {
    return;
  }
  double world[4];
  vtkInteractorObserver::ComputeDisplayToWorld(
    this->Renderer, eventPosition[0], eventPosition[1], this->InteractionDepth, world);
  vtkInternals& in = *this->Internals;
  if (this->ManipulationMode == MESH_POINTS)
  {
    if (in.DragStartLattice && this->Mesh)
    {
      // From the drag's start with the whole motion: each move's solve is exact, so nothing accumulates.
      double target[3];
      for (int c = 0; c < 3; ++c)
      {
        target[c] = in.DragStartPoint[c] + world[c] - in.DragStartWorld[c];
      }
      this->SolveMeshPoint(in.DragStartLattice, in.DraggedMeshPoint, target);
    }
    return;
  }
  const double delta[3] = { world[0] - this->LastWorldPosition[0], world[1] - this->LastWorldPosition[1],
    world[2] - this->LastWorldPosition[2] };
  for (int c = 0; c < 3; ++c)
  {
    this->LastWorldPosition[c] = world[c];
  }
  this->MoveSelectedControlPoints(delta);
}

//------------------------------------------------------------------------------
void vtkFFDLatticeRepresentation::EndWidgetInteraction(double eventPosition[2])
{
  this->WidgetInteraction(eventPosition);
  this->Internals->DragStartLattice = nullptr;
  this->Internals->DraggedMeshPoint = -1;
  this->InteractionState = Outside;
}

//------------------------------------------------------------------------------
void vtkFFDLatticeRepresentation::BuildRepresentation()
{
  vtkInternals& in = *this->Internals;
  const bool stale =
    this->GetMTime() > this->BuildTime || (this->Lattice && this->Lattice->GetMTime() > this->BuildTime);
  if (!stale)
  {
    return;
  }
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  vtkNew<vtkCellArray> vertices;
  in.DropStaleSelection(this->Lattice);
  if (this->Lattice)
  {
    for (vtkIdType id : in.Selection)
    {
      const vtkIdType p = points->InsertNextPoint(this->Lattice->GetPoint(id));
      vertices->InsertNextCell(1, &p);
    }
    // The highlight encloses the control point's sphere, whatever size the lattice actor gives it.
    in.LatticeActor->GetBounds();
    in.SelectedSphere->SetRadius(1.6 * in.LatticeActor->GetRenderedPointRadius());
  }
  in.SelectedPoints->Initialize();
  in.SelectedPoints->SetPoints(points);
  in.SelectedPoints->SetVerts(vertices);
  in.SelectedActor->SetVisibility(points->GetNumberOfPoints() > 0);
  // vtkGlyph3DMapper brings its glyph source up to date when asked for its bounds, which the renderer does
  // only for its own props, never for this actor inside the representation: ask here, or nothing is drawn.
  in.SelectedMapper->Update();
  in.SelectedActor->GetBounds();
  this->BuildTime.Modified();
}

//------------------------------------------------------------------------------
double* vtkFFDLatticeRepresentation::GetBounds()
{
  if (!this->Lattice)
  {
    return nullptr;
  }
  this->BuildRepresentation();
  return this->Internals->LatticeActor->GetBounds();
}

//------------------------------------------------------------------------------
void vtkFFDLatticeRepresentation::GetActors(vtkPropCollection* actors)
{
  this->Internals->LatticeActor->GetActors(actors);
  this->Internals->SelectedActor->GetActors(actors);
}

//------------------------------------------------------------------------------
void vtkFFDLatticeRepresentation::ReleaseGraphicsResources(vtkWindow* window)
{
  this->Internals->LatticeActor->ReleaseGraphicsResources(window);
  this->Internals->SelectedActor->ReleaseGraphicsResources(window);
}

//------------------------------------------------------------------------------
int vtkFFDLatticeRepresentation::RenderOpaqueGeometry(vtkViewport* viewport)
{
  if (!this->Lattice)
  {
    return 0;
  }
  this->BuildRepresentation();
  int count = this->Internals->LatticeActor->RenderOpaqueGeometry(viewport);
  if (this->Internals->SelectedActor->GetVisibility())
  {
    count += this->Internals->SelectedActor->RenderOpaqueGeometry(viewport);
  }
  return count;
}

//------------------------------------------------------------------------------
int vtkFFDLatticeRepresentation::RenderTranslucentPolygonalGeometry(vtkViewport* viewport)
{
  if (!this->Lattice)
  {
    return 0;
  }
  int count = this->Internals->LatticeActor->RenderTranslucentPolygonalGeometry(viewport);
  if (this->Internals->SelectedActor->GetVisibility())
  {
    count += this->Internals->SelectedActor->RenderTranslucentPolygonalGeometry(viewport);
  }
  return count;
}

//------------------------------------------------------------------------------
vtkTypeBool vtkFFDLatticeRepresentation::HasTranslucentPolygonalGeometry()
{
  if (!this->Lattice)
  {
    return 0;
  }
  this->BuildRepresentation();
  return this->Internals->LatticeActor->HasTranslucentPolygonalGeometry() ||
    (this->Internals->SelectedActor->GetVisibility() &&
      this->Internals->SelectedActor->HasTranslucentPolygonalGeometry());
}

//------------------------------------------------------------------------------
void vtkFFDLatticeRepresentation::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Lattice: " << this->Lattice << "\n";
  os << indent << "Tolerance: " << this->Tolerance << " pixels\n";
  os << indent << "PickCulledPoints: " << (this->PickCulledPoints ? "On" : "Off") << "\n";
  os << indent << "HoveredControlPoint: " << this->HoveredControlPoint << "\n";
  os << indent << "ManipulationMode: " << (this->ManipulationMode == MESH_POINTS ? "MESH_POINTS" : "CONTROL_POINTS")
     << "\n";
  os << indent << "Mesh: " << this->Mesh << "\n";
  os << indent << "HoveredMeshPoint: " << this->HoveredMeshPoint << "\n";
  os << indent << "NumberOfSelectedControlPoints: " << this->GetNumberOfSelectedControlPoints() << "\n";
  os << indent << "SelectedPointProperty:\n";
  this->GetSelectedPointProperty()->PrintSelf(os, indent.GetNextIndent());
  os << indent << "LatticeActor:\n";
  this->Internals->LatticeActor->PrintSelf(os, indent.GetNextIndent());
}
