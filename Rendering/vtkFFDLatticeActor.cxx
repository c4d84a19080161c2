// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDLatticeActor.h"

#include "vtkActor.h"
#include "vtkAlgorithmOutput.h"
#include "vtkDataSet.h"
#include "vtkExtractEdges.h"
#include "vtkGlyph3DMapper.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPolyDataMapper.h"
#include "vtkProperty.h"
#include "vtkSphereSource.h"

vtkStandardNewMacro(vtkFFDLatticeActor);

struct vtkFFDLatticeActor::vtkInternals
{
  // Control points: one sphere glyph per lattice point.
  vtkNew<vtkSphereSource> Sphere;
  vtkNew<vtkGlyph3DMapper> PointMapper;
  vtkNew<vtkActor> PointActor;

  // Lattice edges: the cells' edges, which for a structured lattice are the grid lines.
  vtkNew<vtkExtractEdges> Edges;
  vtkNew<vtkPolyDataMapper> EdgeMapper;
  vtkNew<vtkActor> EdgeActor;
};

//------------------------------------------------------------------------------
vtkFFDLatticeActor::vtkFFDLatticeActor()
  : PointRadius(0.0)
  , Internals(new vtkInternals)
{
  vtkInternals& in = *this->Internals;

  in.Sphere->SetThetaResolution(16);
  in.Sphere->SetPhiResolution(12);
  in.PointMapper->SetSourceConnection(in.Sphere->GetOutputPort());
  // The sphere's own radius sets the glyph size: no scaling or orientation from the lattice's arrays
  // (a lattice carries RestPosition vectors that would otherwise orient or scale the glyphs).
  in.PointMapper->ScalingOff();
  in.PointMapper->OrientOff();
  // Colours come from the properties, not from point arrays such as `Active`.
  in.PointMapper->ScalarVisibilityOff();
  in.PointActor->SetMapper(in.PointMapper);
  in.PointActor->GetProperty()->SetColor(0.9, 0.1, 0.1);

  // Keep the lattice's points as they are (no merging locator): edge i-j then joins lattice points i and j.
  in.Edges->UseAllPointsOn();
  in.EdgeMapper->SetInputConnection(in.Edges->GetOutputPort());
  in.EdgeMapper->ScalarVisibilityOff();
  in.EdgeActor->SetMapper(in.EdgeMapper);
  in.EdgeActor->GetProperty()->SetColor(0.25, 0.25, 0.25);
  in.EdgeActor->GetProperty()->SetLineWidth(2.0);
  // Lines get no shading; without this they would darken with their angle to the light.
  in.EdgeActor->GetProperty()->LightingOff();
  // The parts join the assembly once there is an input (ShowParts).
}

//------------------------------------------------------------------------------
vtkFFDLatticeActor::~vtkFFDLatticeActor() = default;

//------------------------------------------------------------------------------
void vtkFFDLatticeActor::SetInputConnection(vtkAlgorithmOutput* output)
{
  this->Internals->PointMapper->SetInputConnection(output);
  this->Internals->Edges->SetInputConnection(output);
  this->ShowParts(output != nullptr);
  this->Modified();
}

//------------------------------------------------------------------------------
void vtkFFDLatticeActor::SetInputData(vtkDataSet* lattice)
{
  this->Internals->PointMapper->SetInputData(lattice);
  this->Internals->Edges->SetInputData(lattice);
  this->ShowParts(lattice != nullptr);
  this->Modified();
}

//------------------------------------------------------------------------------
void vtkFFDLatticeActor::ShowParts(bool hasInput)
{
  // Without an input the parts stay out of the assembly: asking an unconnected vtkExtractEdges for its
  // output (for bounds, for a render or for PrintSelf) is a pipeline error.
  vtkInternals& in = *this->Internals;
  if (hasInput)
  {
    this->AddPart(in.EdgeActor);
    this->AddPart(in.PointActor);
  }
  else
  {
    this->RemovePart(in.EdgeActor);
    this->RemovePart(in.PointActor);
  }
}

//------------------------------------------------------------------------------
vtkProperty* vtkFFDLatticeActor::GetPointProperty()
{
  return this->Internals->PointActor->GetProperty();
}

//------------------------------------------------------------------------------
vtkProperty* vtkFFDLatticeActor::GetEdgeProperty()
{
  return this->Internals->EdgeActor->GetProperty();
}

//------------------------------------------------------------------------------
double vtkFFDLatticeActor::GetRenderedPointRadius()
{
  return this->Internals->Sphere->GetRadius();
}

//------------------------------------------------------------------------------
void vtkFFDLatticeActor::UpdatePointRadius()
{
  vtkInternals& in = *this->Internals;
  if (this->PointRadius > 0.0)
  {
    in.Sphere->SetRadius(this->PointRadius);
    return;
  }
  vtkAlgorithmOutput* input = in.PointMapper->GetInputConnection(0, 0);
  if (!input)
  {
    return;
  }
  // The lattice may have moved since the last render: bring the input up to date before measuring it.
  input->GetProducer()->Update(input->GetIndex());
  vtkDataSet* lattice = in.PointMapper->GetInput();
  // A lattice of a single point (or none) has no size to scale with: the last radius stays.
  const double diagonal = (lattice && lattice->GetNumberOfPoints() > 0) ? lattice->GetLength() : 0.0;
  if (diagonal > 0.0)
  {
    in.Sphere->SetRadius(GetAutomaticRadiusFraction() * diagonal);
  }
}

//------------------------------------------------------------------------------
int vtkFFDLatticeActor::RenderOpaqueGeometry(vtkViewport* viewport)
{
  this->UpdatePointRadius();
  return this->Superclass::RenderOpaqueGeometry(viewport);
}

//------------------------------------------------------------------------------
double* vtkFFDLatticeActor::GetBounds()
{
  this->UpdatePointRadius();
  return this->Superclass::GetBounds();
}

//------------------------------------------------------------------------------
void vtkFFDLatticeActor::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "PointRadius: " << this->PointRadius
     << (this->PointRadius > 0.0 ? "" : " (automatic)") << "\n";
  os << indent << "RenderedPointRadius: " << this->Internals->Sphere->GetRadius() << "\n";
  os << indent << "PointProperty:\n";
  this->GetPointProperty()->PrintSelf(os, indent.GetNextIndent());
  os << indent << "EdgeProperty:\n";
  this->GetEdgeProperty()->PrintSelf(os, indent.GetNextIndent());
}
