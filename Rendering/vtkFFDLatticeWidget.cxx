// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDLatticeWidget.h"

#include "vtkCallbackCommand.h"
#include "vtkCommand.h"
#include "vtkEvent.h"
#include "vtkFFDLatticeRepresentation.h"
#include "vtkObjectFactory.h"
#include "vtkRenderWindow.h" // For VTK_CURSOR_HAND
#include "vtkRenderWindowInteractor.h"
#include "vtkRenderer.h"
#include "vtkWidgetCallbackMapper.h"
#include "vtkWidgetEvent.h"

vtkStandardNewMacro(vtkFFDLatticeWidget);

//------------------------------------------------------------------------------
vtkFFDLatticeWidget::vtkFFDLatticeWidget()
{
  this->ManagesCursor = 1;
  vtkWidgetCallbackMapper* mapper = this->CallbackMapper;
  mapper->SetCallbackMethod(vtkCommand::LeftButtonPressEvent, vtkEvent::NoModifier, 0, 0, nullptr,
    vtkWidgetEvent::Select, this, vtkFFDLatticeWidget::SelectAction);
  mapper->SetCallbackMethod(vtkCommand::LeftButtonPressEvent, vtkEvent::ShiftModifier, 0, 0, nullptr,
    vtkWidgetEvent::AddPoint, this, vtkFFDLatticeWidget::ToggleSelectAction);
  mapper->SetCallbackMethod(vtkCommand::MouseMoveEvent, vtkWidgetEvent::Move, this, vtkFFDLatticeWidget::MoveAction);
  mapper->SetCallbackMethod(vtkCommand::LeftButtonReleaseEvent, vtkEvent::AnyModifier, 0, 0, nullptr,
    vtkWidgetEvent::EndSelect, this, vtkFFDLatticeWidget::EndSelectAction);
  // Key presses, not characters: the interactor style acts on characters (CharEvent), and `x` and Escape are
  // none of its keys, so the two never fight.
  mapper->SetCallbackMethod(vtkCommand::KeyPressEvent, vtkEvent::AnyModifier, GetResetKey(), 0, "x",
    vtkWidgetEvent::Reset, this, vtkFFDLatticeWidget::ResetAction);
  mapper->SetCallbackMethod(vtkCommand::KeyPressEvent, vtkEvent::AnyModifier, 27, 0, "Escape", vtkWidgetEvent::Delete,
    this, vtkFFDLatticeWidget::ClearSelectionAction);
  mapper->SetCallbackMethod(vtkCommand::KeyPressEvent, vtkEvent::AnyModifier, GetModeKey(), 0, "m",
    vtkWidgetEvent::ModifyEvent, this, vtkFFDLatticeWidget::SwitchModeAction);
}

//------------------------------------------------------------------------------
void vtkFFDLatticeWidget::SetRepresentation(vtkFFDLatticeRepresentation* representation)
{
  this->Superclass::SetWidgetRepresentation(representation);
}

//------------------------------------------------------------------------------
vtkFFDLatticeRepresentation* vtkFFDLatticeWidget::GetLatticeRepresentation()
{
  return vtkFFDLatticeRepresentation::SafeDownCast(this->WidgetRep);
}

//------------------------------------------------------------------------------
void vtkFFDLatticeWidget::CreateDefaultRepresentation()
{
  if (!this->WidgetRep)
  {
    this->WidgetRep = vtkFFDLatticeRepresentation::New();
  }
}

//------------------------------------------------------------------------------
vtkIdType vtkFFDLatticeWidget::PickAtEventPosition()
{
  vtkFFDLatticeRepresentation* rep = this->GetLatticeRepresentation();
  if (!rep || !this->Interactor)
  {
    return -1;
  }
  const int* position = this->Interactor->GetEventPosition();
  if (!this->CurrentRenderer || !this->CurrentRenderer->IsInViewport(position[0], position[1]))
  {
    return -1;
  }
  rep->ComputeInteractionState(position[0], position[1]);
  return rep->GetManipulationMode() == vtkFFDLatticeRepresentation::MESH_POINTS ? rep->GetHoveredMeshPoint()
                                                                                : rep->GetHoveredControlPoint();
}

//------------------------------------------------------------------------------
void vtkFFDLatticeWidget::StartDrag()
{
  vtkFFDLatticeRepresentation* rep = this->GetLatticeRepresentation();
  const int* position = this->Interactor->GetEventPosition();
  double eventPosition[2] = { double(position[0]), double(position[1]) };
  rep->StartWidgetInteraction(eventPosition);
  this->WidgetState = Dragging;
  this->GrabFocus(this->EventCallbackCommand);
  this->RequestCursorShape(VTK_CURSOR_HAND);
  this->EventCallbackCommand->SetAbortFlag(1); // the camera does not move with the control points
  this->StartInteraction();
  this->InvokeEvent(vtkCommand::StartInteractionEvent, nullptr);
  this->Render();
}

//------------------------------------------------------------------------------
void vtkFFDLatticeWidget::SelectAction(vtkAbstractWidget* widget)
{
  auto* self = static_cast<vtkFFDLatticeWidget*>(widget);
  const vtkIdType id = self->PickAtEventPosition();
  if (id < 0)
  {
    return; // not on a control point: the event goes on to the camera
  }
  vtkFFDLatticeRepresentation* rep = self->GetLatticeRepresentation();
  if (rep->GetManipulationMode() == vtkFFDLatticeRepresentation::CONTROL_POINTS && !rep->IsControlPointSelected(id))
  {
    rep->ClearSelection();
    rep->SelectControlPoint(id);
  }
  self->StartDrag();
}

//------------------------------------------------------------------------------
void vtkFFDLatticeWidget::ToggleSelectAction(vtkAbstractWidget* widget)
{
  auto* self = static_cast<vtkFFDLatticeWidget*>(widget);
  vtkFFDLatticeRepresentation* rep = self->GetLatticeRepresentation();
  if (rep && rep->GetManipulationMode() == vtkFFDLatticeRepresentation::MESH_POINTS)
  {
    SelectAction(widget); // mesh points have no selection: Shift drags as the plain button does
    return;
  }
  const vtkIdType id = self->PickAtEventPosition();
  if (id < 0)
  {
    return;
  }
  if (rep->ToggleControlPoint(id))
  {
    self->StartDrag(); // added: the drag moves the selection with it
    return;
  }
  // Removed: nothing to drag, but the click was ours.
  self->EventCallbackCommand->SetAbortFlag(1);
  self->Render();
}

//------------------------------------------------------------------------------
void vtkFFDLatticeWidget::MoveAction(vtkAbstractWidget* widget)
{
  auto* self = static_cast<vtkFFDLatticeWidget*>(widget);
  vtkFFDLatticeRepresentation* rep = self->GetLatticeRepresentation();
  if (!rep)
  {
    return;
  }
  if (self->WidgetState != Dragging)
  {
    // Hovering: only the cursor changes; no render, which with a large mesh would cost a frame per move.
    const vtkIdType id = self->PickAtEventPosition();
    self->RequestCursorShape(id >= 0 ? VTK_CURSOR_HAND : VTK_CURSOR_DEFAULT);
    return;
  }
  const int* position = self->Interactor->GetEventPosition();
  double eventPosition[2] = { double(position[0]), double(position[1]) };
  rep->WidgetInteraction(eventPosition);
  self->EventCallbackCommand->SetAbortFlag(1);
  self->InvokeEvent(vtkCommand::InteractionEvent, nullptr);
  self->Render();
}

//------------------------------------------------------------------------------
void vtkFFDLatticeWidget::EndSelectAction(vtkAbstractWidget* widget)
{
  auto* self = static_cast<vtkFFDLatticeWidget*>(widget);
  if (self->WidgetState != Dragging)
  {
    return;
  }
  const int* position = self->Interactor->GetEventPosition();
  double eventPosition[2] = { double(position[0]), double(position[1]) };
  self->GetLatticeRepresentation()->EndWidgetInteraction(eventPosition);
  self->WidgetState = Start;
  self->ReleaseFocus();
  self->EventCallbackCommand->SetAbortFlag(1);
  self->EndInteraction();
  self->InvokeEvent(vtkCommand::EndInteractionEvent, nullptr);
  self->Render();
}

//------------------------------------------------------------------------------
void vtkFFDLatticeWidget::ResetAction(vtkAbstractWidget* widget)
{
  auto* self = static_cast<vtkFFDLatticeWidget*>(widget);
  vtkFFDLatticeRepresentation* rep = self->GetLatticeRepresentation();
  if (!rep || self->WidgetState == Dragging || !rep->GetLattice())
  {
    return;
  }
  self->EventCallbackCommand->SetAbortFlag(1);
  if (rep->ResetLatticeToRest()) // reports its own error when the lattice has no RestPosition
  {
    self->InvokeEvent(vtkCommand::InteractionEvent, nullptr);
    self->Render();
  }
}

//------------------------------------------------------------------------------
void vtkFFDLatticeWidget::ClearSelectionAction(vtkAbstractWidget* widget)
{
  auto* self = static_cast<vtkFFDLatticeWidget*>(widget);
  vtkFFDLatticeRepresentation* rep = self->GetLatticeRepresentation();
  if (!rep || self->WidgetState == Dragging)
  {
    return;
  }
  rep->ClearSelection();
  self->EventCallbackCommand->SetAbortFlag(1);
  self->Render();
}

//------------------------------------------------------------------------------
void vtkFFDLatticeWidget::SwitchModeAction(vtkAbstractWidget* widget)
{
  auto* self = static_cast<vtkFFDLatticeWidget*>(widget);
  vtkFFDLatticeRepresentation* rep = self->GetLatticeRepresentation();
  if (!rep || self->WidgetState == Dragging)
  {
    return;
  }
  rep->SetManipulationMode(rep->GetManipulationMode() == vtkFFDLatticeRepresentation::MESH_POINTS
      ? vtkFFDLatticeRepresentation::CONTROL_POINTS
      : vtkFFDLatticeRepresentation::MESH_POINTS);
  self->EventCallbackCommand->SetAbortFlag(1);
  self->RequestCursorShape(VTK_CURSOR_DEFAULT);
}

//------------------------------------------------------------------------------
void vtkFFDLatticeWidget::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "WidgetState: " << (this->WidgetState == Dragging ? "Dragging" : "Start") << "\n";
}
