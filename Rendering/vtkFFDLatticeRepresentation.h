// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkFFDLatticeRepresentation
 * @brief   the geometry of vtkFFDLatticeWidget: a lattice, its selected control points, picking and dragging
 *
 * The representation of an interactive control lattice. It draws the lattice with a vtkFFDLatticeActor
 * (GetLatticeActor() for its parts' properties) and the selected control points as larger yellow spheres
 * around them (GetSelectedPointProperty()), and it edits the lattice in place:
 * - SetLattice() names the lattice data object whose points are moved: the same object that vtkFFDDeform
 *   reads (vtkFFDDeform::SetLatticeData), a copy of vtkFFDBuildLattice's output. Moving its points and marking
 *   them modified is all it takes: vtkFFDDeform re-executes at the next render and, since neither the mesh
 *   nor the lattice's rest frame changed, re-uses its cached binding (only the evaluation runs).
 * - Picking is done in display coordinates: the control point nearest to the cursor within Tolerance pixels,
 *   the one nearest to the camera when several are as near. No hardware or cell picker is involved, so
 *   control points hidden inside the mesh can be picked, and a lattice of thousands of points costs a few
 *   hundred microseconds a pick. Culled control points (`Active` 0) are not pickable by default: moving them
 *   changes nothing (PickCulledPoints).
 * - A drag moves every selected control point by the cursor's motion on the plane through the picked control
 *   point parallel to the view plane (as vtkPointHandleRepresentation moves its focal point).
 * - ResetLatticeToRest() puts every point back at its `RestPosition`.
 * - Direct manipulation (ManipulationMode MESH_POINTS, with SetMesh() the mesh at rest that the lattice
 *   deforms): the point of the deformed mesh nearest the cursor is picked (as control points are), and a drag
 *   moves the control points by the smallest displacement that keeps it under the cursor
 *   (vtkFFDDirectManipulation), solved at every move from the lattice as it was when the drag began, with the
 *   cursor's whole motion: nothing drifts however long the drag. MoveMeshPoint() does one such move without
 *   events.
 *
 * The selection API (SelectControlPoint() and the rest) and MoveSelectedControlPoints() let an application
 * or a test edit the lattice without events. A lattice without an `Active` array has every point pickable; one
 * without `RestPosition` can be dragged but not reset (ResetLatticeToRest() reports the error and returns
 * false). Without a lattice or a renderer nothing is picked and nothing moves.
 *
 * @sa vtkFFDLatticeWidget vtkFFDLatticeActor vtkFFDDeform vtkPointCloudRepresentation
 */
#ifndef vtkFFDLatticeRepresentation_h
#define vtkFFDLatticeRepresentation_h

#include "vtkFFDRenderingModule.h" // For export macro
#include "vtkWidgetRepresentation.h"

#include <memory> // For std::unique_ptr

class vtkFFDLatticeActor;
class vtkIdList;
class vtkPointSet;
class vtkProperty;

class VTKFFDRENDERING_EXPORT vtkFFDLatticeRepresentation : public vtkWidgetRepresentation
{
public:
  static vtkFFDLatticeRepresentation* New();
  vtkTypeMacro(vtkFFDLatticeRepresentation, vtkWidgetRepresentation);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// The lattice whose points are moved in place (vtkFFDBuildLattice's dense or sparse form, or any
  /// vtkPointSet that keeps the data contract). Setting one clears the selection.
  void SetLattice(vtkPointSet* lattice);
  vtkGetObjectMacro(Lattice, vtkPointSet);
  ///@}

  /// The actor that draws the lattice: its parts' properties, point radius, colouring, voxel grid.
  vtkFFDLatticeActor* GetLatticeActor();

  /// Property of the spheres around the selected control points (default yellow).
  vtkProperty* GetSelectedPointProperty();

  ///@{
  /// Largest distance, in pixels, between the cursor and a control point's projection for a pick (default 10).
  vtkSetClampMacro(Tolerance, int, 1, 100);
  vtkGetMacro(Tolerance, int);
  ///@}

  ///@{
  /// Whether culled control points (`Active` 0) can be picked and selected (default off).
  vtkSetMacro(PickCulledPoints, bool);
  vtkGetMacro(PickCulledPoints, bool);
  vtkBooleanMacro(PickCulledPoints, bool);
  ///@}

  enum InteractionStates
  {
    Outside = 0,      ///< nothing pickable under the cursor
    OverControlPoint, ///< a control point within Tolerance of the cursor (GetHoveredControlPoint())
    Moving,           ///< dragging the selected control points, or a mesh point
    OverMeshPoint     ///< MESH_POINTS: a deformed mesh point within Tolerance (GetHoveredMeshPoint())
  };
  vtkSetClampMacro(InteractionState, int, Outside, OverMeshPoint);

  /// The control point found by the last ComputeInteractionState(), -1 when none.
  vtkGetMacro(HoveredControlPoint, vtkIdType);

  /// What picking and dragging act on.
  enum ManipulationModes
  {
    CONTROL_POINTS = 0, ///< control points, selected and dragged (the default)
    MESH_POINTS = 1     ///< points of the deformed mesh, dragged by direct manipulation (needs SetMesh())
  };

  ///@{
  /// What picking and dragging act on (default CONTROL_POINTS); the widget's key `m` switches.
  vtkSetClampMacro(ManipulationMode, int, CONTROL_POINTS, MESH_POINTS);
  vtkGetMacro(ManipulationMode, int);
  void SetManipulationModeToControlPoints() { this->SetManipulationMode(CONTROL_POINTS); }
  void SetManipulationModeToMeshPoints() { this->SetManipulationMode(MESH_POINTS); }
  ///@}

  ///@{
  /// The mesh at rest that the lattice deforms (vtkFFDDeform's input 0), for MESH_POINTS.
  void SetMesh(vtkPointSet* mesh);
  vtkGetObjectMacro(Mesh, vtkPointSet);
  ///@}

  /// The mesh point found by the last ComputeInteractionState() in MESH_POINTS mode, -1 when none.
  vtkGetMacro(HoveredMeshPoint, vtkIdType);

  /**
   * Moves the control points by the smallest displacement that takes mesh point `id`, once deformed, to
   * `target` (world coordinates; vtkFFDDirectManipulation) and marks the lattice's points modified. False, with
   * an error, without a lattice or a mesh, for an id out of range, or where the solve fails.
   */
  bool MoveMeshPoint(vtkIdType id, const double target[3]);

  ///@{
  /**
   * The selection: the control points that a drag moves. SelectControlPoint() refuses (returns false) an id
   * out of range, or a culled control point unless PickCulledPoints is on. The selection is dropped once the
   * lattice's number of points changes (re-executed upstream, or its points replaced): its ids would name
   * other points, or none.
   */
  bool SelectControlPoint(vtkIdType id);
  void DeselectControlPoint(vtkIdType id);
  bool ToggleControlPoint(vtkIdType id);
  void ClearSelection();
  bool IsControlPointSelected(vtkIdType id) const;
  vtkIdType GetNumberOfSelectedControlPoints() const;
  void GetSelectedControlPoints(vtkIdList* ids) const;
  ///@}

  /// Moves every selected control point by `delta` (world units) and marks the lattice's points modified;
  /// false when there is no lattice or nothing is selected.
  bool MoveSelectedControlPoints(const double delta[3]);

  /// Puts every control point back at its `RestPosition`; false, with an error, when the lattice has no
  /// `RestPosition` array of three components per point.
  bool ResetLatticeToRest();

  ///@{
  /// The widget representation's interface (see vtkWidgetRepresentation).
  void BuildRepresentation() override;
  int ComputeInteractionState(int X, int Y, int modify = 0) override;
  void StartWidgetInteraction(double eventPosition[2]) override;
  void WidgetInteraction(double eventPosition[2]) override;
  void EndWidgetInteraction(double eventPosition[2]) override;
  double* GetBounds() VTK_SIZEHINT(6) override;
  void GetActors(vtkPropCollection* actors) override;
  void ReleaseGraphicsResources(vtkWindow* window) override;
  int RenderOpaqueGeometry(vtkViewport* viewport) override;
  int RenderTranslucentPolygonalGeometry(vtkViewport* viewport) override;
  vtkTypeBool HasTranslucentPolygonalGeometry() override;
  ///@}

protected:
  vtkFFDLatticeRepresentation();
  ~vtkFFDLatticeRepresentation() override;

  /// Whether control point `id` may be picked or selected.
  bool IsPickable(vtkIdType id);

  /// The lattice moved so that mesh point `id` goes to `target`, solved from `from` (the lattice or a copy).
  bool SolveMeshPoint(vtkPointSet* from, vtkIdType id, const double target[3]);
  /// The mesh deformed by the lattice as it is (null without both).
  vtkPointSet* GetDeformedMesh();

  vtkPointSet* Lattice = nullptr;
  vtkPointSet* Mesh = nullptr;
  int ManipulationMode = CONTROL_POINTS;
  vtkIdType HoveredMeshPoint = -1;
  int Tolerance = 10;
  bool PickCulledPoints = false;
  vtkIdType HoveredControlPoint = -1;

  // The drag: display depth of the picked control point and the world position of the last event on the
  // plane through it parallel to the view plane.
  double InteractionDepth = 0.0;
  double LastWorldPosition[3] = { 0.0, 0.0, 0.0 };

private:
  vtkFFDLatticeRepresentation(const vtkFFDLatticeRepresentation&) = delete;
  void operator=(const vtkFFDLatticeRepresentation&) = delete;

  struct vtkInternals;
  std::unique_ptr<vtkInternals> Internals;
};

#endif
