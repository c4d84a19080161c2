// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkFFDLatticeWidget
 * @brief   pick control points of a free-form deformation lattice and drag them; the mesh follows
 *
 * A VTK widget (with vtkFFDLatticeRepresentation) that edits a control lattice in place. Give the
 * representation the lattice that vtkFFDDeform reads (vtkFFDDeform::SetLatticeData): every drag moves the
 * lattice's points, and the next render re-executes vtkFFDDeform with its cached binding, so the mesh follows
 * the cursor at the cost of one evaluation per frame.
 *
 * Events (the camera gets every event the widget does not use):
 * - left button on a control point: selects it alone (unless it is already selected, so that a selection can
 *   be dragged from any of its points) and drags the selection until release, on the plane through the
 *   picked point parallel to the view plane;
 * - Shift + left button on a control point: adds it to the selection or removes it; when added, the drag
 *   moves the whole selection;
 * - key `x`: resets the whole lattice to its rest position (`RestPosition`);
 * - key Escape: clears the selection;
 * - key `m`: switches between dragging control points and dragging points of the mesh (direct manipulation,
 *   vtkFFDLatticeRepresentation::MESH_POINTS; the representation needs the mesh at rest, SetMesh()). In that
 *   mode the left button on a point of the deformed mesh drags it: the lattice takes the smallest control-point
 *   move that keeps the point under the cursor, and the mesh follows.
 *
 * It invokes StartInteractionEvent, InteractionEvent (after every move, and after a reset) and
 * EndInteractionEvent, so an application can observe the lattice's edits.
 *
 * @sa vtkFFDLatticeRepresentation vtkFFDLatticeActor vtkFFDDeform vtkPointCloudWidget vtkHandleWidget
 */
#ifndef vtkFFDLatticeWidget_h
#define vtkFFDLatticeWidget_h

#include "vtkAbstractWidget.h"
#include "vtkFFDRenderingModule.h" // For export macro

class vtkFFDLatticeRepresentation;

class VTKFFDRENDERING_EXPORT vtkFFDLatticeWidget : public vtkAbstractWidget
{
public:
  static vtkFFDLatticeWidget* New();
  vtkTypeMacro(vtkFFDLatticeWidget, vtkAbstractWidget);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// The representation: holds the lattice, the selection and the drawing.
  void SetRepresentation(vtkFFDLatticeRepresentation* representation);
  vtkFFDLatticeRepresentation* GetLatticeRepresentation();

  /// Creates a vtkFFDLatticeRepresentation when none is set.
  void CreateDefaultRepresentation() override;

  /// The key that resets the lattice to rest (`x`).
  static char GetResetKey() { return 'x'; }

  /// The key that switches between dragging control points and mesh points (`m`).
  static char GetModeKey() { return 'm'; }

  /// Whether a drag is under way.
  bool IsDragging() const { return this->WidgetState == Dragging; }

protected:
  vtkFFDLatticeWidget();
  ~vtkFFDLatticeWidget() override = default;

  enum WidgetStates
  {
    Start = 0,
    Dragging
  };
  int WidgetState = Start;

  static void SelectAction(vtkAbstractWidget* widget);
  static void ToggleSelectAction(vtkAbstractWidget* widget);
  static void MoveAction(vtkAbstractWidget* widget);
  static void EndSelectAction(vtkAbstractWidget* widget);
  static void ResetAction(vtkAbstractWidget* widget);
  static void ClearSelectionAction(vtkAbstractWidget* widget);
  static void SwitchModeAction(vtkAbstractWidget* widget);

  /// Picks the control point (or, in MESH_POINTS mode, the mesh point) under the event position; -1 when there
  /// is none (or no renderer there).
  vtkIdType PickAtEventPosition();
  /// Starts dragging the selection from the picked control point, or the picked mesh point.
  void StartDrag();

private:
  vtkFFDLatticeWidget(const vtkFFDLatticeWidget&) = delete;
  void operator=(const vtkFFDLatticeWidget&) = delete;
};

#endif
