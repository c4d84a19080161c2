// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDLatticeActor.h"

#include "vtkActor.h"
#include "vtkAlgorithmOutput.h"
#include "vtkCellData.h"
#include "vtkDataArray.h"
#include "vtkDataSet.h"
#include "vtkFFDCellEdges.h"
#include "vtkFFDControlPoints.h"
#include "vtkGlyph3DMapper.h"
#include "vtkLookupTable.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkPolyDataMapper.h"
#include "vtkProperty.h"
#include "vtkSphereSource.h"
#include "vtkThreshold.h"

vtkStandardNewMacro(vtkFFDLatticeActor);

namespace
{
/// A glyph part: one sphere per control point of a vtkFFDControlPoints output.
struct PointPart
{
  vtkNew<vtkFFDControlPoints> Points;
  vtkNew<vtkGlyph3DMapper> Mapper;
  vtkNew<vtkActor> Actor;

  void Initialize(vtkSphereSource* sphere, int selection, double r, double g, double b)
  {
    this->Points->SetSelection(selection);
    this->Mapper->SetInputConnection(this->Points->GetOutputPort());
    this->Mapper->SetSourceConnection(sphere->GetOutputPort());
    // The sphere's own radius sets the glyph size: no scaling or orientation from point arrays.
    this->Mapper->ScalingOff();
    this->Mapper->OrientOff();
    this->Mapper->ScalarVisibilityOff();
    this->Actor->SetMapper(this->Mapper);
    this->Actor->GetProperty()->SetColor(r, g, b);
  }
};

/// A line part: the edges of the visible cells of a data set.
struct EdgePart
{
  vtkNew<vtkFFDCellEdges> Edges;
  vtkNew<vtkPolyDataMapper> Mapper;
  vtkNew<vtkActor> Actor;

  void Initialize(double r, double g, double b, double width)
  {
    this->Mapper->SetInputConnection(this->Edges->GetOutputPort());
    this->Mapper->ScalarVisibilityOff();
    this->Actor->SetMapper(this->Mapper);
    this->Actor->GetProperty()->SetColor(r, g, b);
    this->Actor->GetProperty()->SetLineWidth(width);
    // Lines get no shading; without this they would darken with their angle to the light.
    this->Actor->GetProperty()->LightingOff();
  }
};

/// The lattice's cell array that vtkFFDFoldCertificate (Filters/Quality, which this module does not link) adds.
const char* const FoldCertificateName = "FoldCertificate";

/// A line part of the lattice's cells whose `FoldCertificate` is `state`.
struct FoldPart
{
  vtkNew<vtkThreshold> Select;
  EdgePart Lines;

  void Initialize(int state, double r, double g, double b)
  {
    this->Select->SetInputArrayToProcess(0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_CELLS, FoldCertificateName);
    this->Select->SetLowerThreshold(state);
    this->Select->SetUpperThreshold(state);
    this->Select->SetThresholdFunction(vtkThreshold::THRESHOLD_BETWEEN);
    this->Lines.Edges->SetInputConnection(this->Select->GetOutputPort());
    this->Lines.Initialize(r, g, b, 4.0);
  }
};
}

struct vtkFFDLatticeActor::vtkInternals
{
  vtkNew<vtkSphereSource> Sphere; // shared by both point parts: culled and active spheres have one size
  PointPart ActivePoints;
  PointPart CulledPoints;
  EdgePart LatticeEdges;
  EdgePart Voxels;
  FoldPart Folded, Undecided;
  vtkNew<vtkLookupTable> DisplacementColors;
  bool HasLattice = false;
  bool HasVoxelGrid = false;
};

//------------------------------------------------------------------------------
vtkFFDLatticeActor::vtkFFDLatticeActor()
  : Internals(new vtkInternals)
{
  vtkInternals& in = *this->Internals;
  in.Sphere->SetThetaResolution(16);
  in.Sphere->SetPhiResolution(12);
  in.ActivePoints.Initialize(in.Sphere, vtkFFDControlPoints::ACTIVE, 0.9, 0.1, 0.1);
  in.CulledPoints.Initialize(in.Sphere, vtkFFDControlPoints::CULLED, 0.75, 0.75, 0.75);
  in.LatticeEdges.Initialize(0.25, 0.25, 0.25, 2.0);
  in.Voxels.Initialize(0.27, 0.51, 0.71, 1.0);
  in.Folded.Initialize(1, 0.9, 0.0, 0.0);
  in.Undecided.Initialize(2, 1.0, 0.6, 0.0);

  // Blue (not moved) to red (moved the most), the usual reading of a magnitude.
  in.DisplacementColors->SetHueRange(0.667, 0.0);
  in.DisplacementColors->Build();
  in.ActivePoints.Mapper->SetLookupTable(in.DisplacementColors);
  in.ActivePoints.Mapper->UseLookupTableScalarRangeOff();
  // The parts join the assembly once there is an input (ShowLatticeParts, SetVoxelGridData).
}

//------------------------------------------------------------------------------
vtkFFDLatticeActor::~vtkFFDLatticeActor() = default;

//------------------------------------------------------------------------------
void vtkFFDLatticeActor::SetInputConnection(vtkAlgorithmOutput* output)
{
  vtkInternals& in = *this->Internals;
  in.ActivePoints.Points->SetInputConnection(output);
  in.CulledPoints.Points->SetInputConnection(output);
  in.LatticeEdges.Edges->SetInputConnection(output);
  in.Folded.Select->SetInputConnection(output);
  in.Undecided.Select->SetInputConnection(output);
  this->ShowLatticeParts(output != nullptr);
  this->Modified();
}

//------------------------------------------------------------------------------
void vtkFFDLatticeActor::SetInputData(vtkDataSet* lattice)
{
  vtkInternals& in = *this->Internals;
  in.ActivePoints.Points->SetInputData(lattice);
  in.CulledPoints.Points->SetInputData(lattice);
  in.LatticeEdges.Edges->SetInputData(lattice);
  in.Folded.Select->SetInputData(lattice);
  in.Undecided.Select->SetInputData(lattice);
  this->ShowLatticeParts(lattice != nullptr);
  this->Modified();
}

//------------------------------------------------------------------------------
void vtkFFDLatticeActor::ShowLatticeParts(bool hasInput)
{
  // Without an input the parts stay out of the assembly: updating an unconnected filter (for bounds, for a
  // render or for PrintSelf) is a pipeline error.
  vtkInternals& in = *this->Internals;
  in.HasLattice = hasInput;
  vtkActor* parts[5] = { in.LatticeEdges.Actor, in.CulledPoints.Actor, in.ActivePoints.Actor, in.Folded.Lines.Actor,
    in.Undecided.Lines.Actor };
  for (vtkActor* part : parts)
  {
    if (hasInput)
    {
      this->AddPart(part);
    }
    else
    {
      this->RemovePart(part);
    }
  }
}

//------------------------------------------------------------------------------
void vtkFFDLatticeActor::SetVoxelGridConnection(vtkAlgorithmOutput* output)
{
  vtkInternals& in = *this->Internals;
  in.Voxels.Edges->SetInputConnection(output);
  in.HasVoxelGrid = output != nullptr;
  in.HasVoxelGrid ? this->AddPart(in.Voxels.Actor) : this->RemovePart(in.Voxels.Actor);
  this->Modified();
}

//------------------------------------------------------------------------------
void vtkFFDLatticeActor::SetVoxelGridData(vtkDataSet* voxelGrid)
{
  vtkInternals& in = *this->Internals;
  in.Voxels.Edges->SetInputData(voxelGrid);
  in.HasVoxelGrid = voxelGrid != nullptr;
  in.HasVoxelGrid ? this->AddPart(in.Voxels.Actor) : this->RemovePart(in.Voxels.Actor);
  this->Modified();
}

//------------------------------------------------------------------------------
vtkProperty* vtkFFDLatticeActor::GetPointProperty()
{
  return this->Internals->ActivePoints.Actor->GetProperty();
}

//------------------------------------------------------------------------------
vtkProperty* vtkFFDLatticeActor::GetCulledPointProperty()
{
  return this->Internals->CulledPoints.Actor->GetProperty();
}

//------------------------------------------------------------------------------
vtkProperty* vtkFFDLatticeActor::GetEdgeProperty()
{
  return this->Internals->LatticeEdges.Actor->GetProperty();
}

//------------------------------------------------------------------------------
vtkProperty* vtkFFDLatticeActor::GetVoxelProperty()
{
  return this->Internals->Voxels.Actor->GetProperty();
}

//------------------------------------------------------------------------------
vtkProperty* vtkFFDLatticeActor::GetFoldedCellProperty()
{
  return this->Internals->Folded.Lines.Actor->GetProperty();
}

//------------------------------------------------------------------------------
vtkProperty* vtkFFDLatticeActor::GetUndecidedCellProperty()
{
  return this->Internals->Undecided.Lines.Actor->GetProperty();
}

//------------------------------------------------------------------------------
vtkLookupTable* vtkFFDLatticeActor::GetDisplacementLookupTable()
{
  return this->Internals->DisplacementColors;
}

//------------------------------------------------------------------------------
double vtkFFDLatticeActor::GetRenderedPointRadius()
{
  return this->Internals->Sphere->GetRadius();
}

//------------------------------------------------------------------------------
void vtkFFDLatticeActor::UpdateParts()
{
  vtkInternals& in = *this->Internals;
  in.LatticeEdges.Actor->SetVisibility(in.HasLattice && this->ShowEdges);
  if (!in.HasLattice)
  {
    return;
  }
  // The lattice may have moved since the last render: bring the point parts up to date before measuring.
  in.ActivePoints.Points->Update();
  vtkPolyData* active = in.ActivePoints.Points->GetOutput();
  // A part with no point would report uninitialized bounds; it is hidden instead.
  in.ActivePoints.Actor->SetVisibility(active->GetNumberOfPoints() > 0);
  bool showCulled = false;
  if (this->ShowCulledPoints)
  {
    in.CulledPoints.Points->Update();
    showCulled = in.CulledPoints.Points->GetOutput()->GetNumberOfPoints() > 0;
  }
  in.CulledPoints.Actor->SetVisibility(showCulled);
  this->UpdateFoldParts();

  if (this->PointRadius > 0.0)
  {
    in.Sphere->SetRadius(this->PointRadius);
  }
  else
  {
    vtkDataSet* lattice = vtkDataSet::SafeDownCast(in.ActivePoints.Points->GetInputDataObject(0, 0));
    // A lattice of a single point (or none) has no size to scale with: the last radius stays.
    const double diagonal = (lattice && lattice->GetNumberOfPoints() > 0) ? lattice->GetLength() : 0.0;
    if (diagonal > 0.0)
    {
      in.Sphere->SetRadius(GetAutomaticRadiusFraction() * diagonal);
    }
  }

  in.ActivePoints.Mapper->SetScalarVisibility(this->ColorByDisplacement);
  if (this->ColorByDisplacement)
  {
    double range[2] = { this->DisplacementRange[0], this->DisplacementRange[1] };
    if (range[1] <= range[0])
    {
      vtkDataArray* lengths = active->GetPointData()->GetScalars();
      range[0] = 0.0;
      range[1] = lengths && lengths->GetNumberOfTuples() > 0 ? lengths->GetRange(0)[1] : 0.0;
      if (range[1] <= 0.0)
      {
        range[1] = 1.0; // nothing moved: every point gets the colour of 0
      }
    }
    in.ActivePoints.Mapper->SetScalarRange(range);
  }
}

//------------------------------------------------------------------------------
void vtkFFDLatticeActor::UpdateFoldParts()
{
  // Shown only where the lattice has the array (vtkThreshold would complain of one it lacks) and the cells of
  // their state exist (a part without points would report uninitialized bounds).
  vtkInternals& in = *this->Internals;
  vtkDataSet* lattice = vtkDataSet::SafeDownCast(in.ActivePoints.Points->GetInputDataObject(0, 0));
  const bool colour = this->ColorByFoldCertificate && lattice && lattice->GetCellData()->GetArray(FoldCertificateName);
  for (FoldPart* part : { &in.Folded, &in.Undecided })
  {
    bool show = false;
    if (colour)
    {
      part->Lines.Edges->Update();
      show = part->Lines.Edges->GetOutput()->GetNumberOfLines() > 0;
    }
    part->Lines.Actor->SetVisibility(show);
  }
}

//------------------------------------------------------------------------------
int vtkFFDLatticeActor::RenderOpaqueGeometry(vtkViewport* viewport)
{
  this->UpdateParts();
  // vtkGlyph3DMapper brings its sphere source up to date in GetBounds(), which the renderer calls on its own
  // props only: inside a widget representation nobody else would, and a new radius would not show.
  this->Superclass::GetBounds();
  return this->Superclass::RenderOpaqueGeometry(viewport);
}

//------------------------------------------------------------------------------
double* vtkFFDLatticeActor::GetBounds()
{
  this->UpdateParts();
  return this->Superclass::GetBounds();
}

//------------------------------------------------------------------------------
void vtkFFDLatticeActor::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  vtkInternals& in = *this->Internals;
  os << indent << "Lattice: " << (in.HasLattice ? "set" : "(none)") << "\n";
  os << indent << "VoxelGrid: " << (in.HasVoxelGrid ? "set" : "(none)") << "\n";
  os << indent << "PointRadius: " << this->PointRadius << (this->PointRadius > 0.0 ? "" : " (automatic)") << "\n";
  os << indent << "RenderedPointRadius: " << in.Sphere->GetRadius() << "\n";
  os << indent << "ShowCulledPoints: " << (this->ShowCulledPoints ? "On" : "Off") << "\n";
  os << indent << "ShowEdges: " << (this->ShowEdges ? "On" : "Off") << "\n";
  os << indent << "ColorByDisplacement: " << (this->ColorByDisplacement ? "On" : "Off") << "\n";
  os << indent << "ColorByFoldCertificate: " << (this->ColorByFoldCertificate ? "On" : "Off") << "\n";
  os << indent << "DisplacementRange: " << this->DisplacementRange[0] << " " << this->DisplacementRange[1]
     << (this->DisplacementRange[1] > this->DisplacementRange[0] ? "" : " (automatic)") << "\n";
  os << indent << "PointProperty:\n";
  this->GetPointProperty()->PrintSelf(os, indent.GetNextIndent());
  os << indent << "CulledPointProperty:\n";
  this->GetCulledPointProperty()->PrintSelf(os, indent.GetNextIndent());
  os << indent << "EdgeProperty:\n";
  this->GetEdgeProperty()->PrintSelf(os, indent.GetNextIndent());
  os << indent << "VoxelProperty:\n";
  this->GetVoxelProperty()->PrintSelf(os, indent.GetNextIndent());
}
