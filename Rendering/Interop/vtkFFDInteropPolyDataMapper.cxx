// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDInteropPolyDataMapper.h"

#include "vtkFFDDeform.h"
#include "vtkFFDDeviceOutput.h"

#include "vtkActor.h"
#include "vtkAlgorithm.h"
#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkInformation.h"
#include "vtkInformationIntegerKey.h"
#include "vtkInformationObjectBaseKey.h"
#include "vtkLogger.h"
#include "vtkMath.h"
#include "vtkObjectFactory.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLVertexBufferObject.h"
#include "vtkOpenGLVertexBufferObjectGroup.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkProperty.h"
#include "vtkRenderer.h"
#include "vtkSelection.h"
#include "vtkTexture.h"
#include "vtkWeakPointer.h"
#include "vtk_glew.h"

#include <algorithm>
#include <cstdint>
#include <vector>

vtkStandardNewMacro(vtkFFDInteropPolyDataMapper);

namespace
{
enum class Decision
{
  Undecided,
  On,
  Off
};

// What the vertex buffers last received from the device: which output, into which buffers, after which of their
// uploads by vtkOpenGLPolyDataMapper (an upload overwrites them with the input's copies, and may re-specify their
// storage, which CUDA must then register again).
struct Written
{
  const vtkFFDDeviceOutput* Output = nullptr;
  vtkMTimeType OutputTime = 0;
  int Points = 0, Normals = 0;
  vtkMTimeType PointsUpload = 0, NormalsUpload = 0;

  bool SameBuffers(const Written& other) const
  {
    return this->Points == other.Points && this->Normals == other.Normals && this->PointsUpload == other.PointsUpload &&
      this->NormalsUpload == other.NormalsUpload;
  }
  bool operator==(const Written& other) const
  {
    return this->Output == other.Output && this->OutputTime == other.OutputTime && this->SameBuffers(other);
  }
};

// vtkFFDDeform::KEEP_OUTPUT_ON_DEVICE() on the mapper's input information while it lives: the requests of the
// mapper's own updates, and of no one else's.
class KeepOnDeviceRequest
{
public:
  KeepOnDeviceRequest(vtkAlgorithm* mapper, bool active)
    : Information(active && mapper->GetNumberOfInputConnections(0) > 0 ? mapper->GetInputInformation() : nullptr)
  {
    if (this->Information)
    {
      this->Information->Set(vtkFFDDeform::KEEP_OUTPUT_ON_DEVICE(), 1);
    }
  }
  ~KeepOnDeviceRequest()
  {
    if (this->Information)
    {
      this->Information->Remove(vtkFFDDeform::KEEP_OUTPUT_ON_DEVICE());
    }
  }
  KeepOnDeviceRequest(const KeepOnDeviceRequest&) = delete;
  KeepOnDeviceRequest& operator=(const KeepOnDeviceRequest&) = delete;

private:
  vtkInformation* Information;
};

// What the buffers other than the points' and normals' are built from: the cells, the point and cell arrays (the
// normals among them: vtkFFDDeform's copy of the input's), the actor's property and texture, this mapper (its
// lookup table included) and its selection. While it stays the same, a new deformation kept on the device changes
// nothing but the points and normals, which the device writes: vtkOpenGLPolyDataMapper's rebuild, which VTK 9.1
// runs whenever the input's modification time changes (index buffers included: about 70 ms per million points),
// is skipped.
std::vector<vtkMTimeType> StructureOf(vtkPolyData* input, vtkOpenGLPolyDataMapper* mapper, vtkActor* actor)
{
  std::vector<vtkMTimeType> key{ mapper->GetMTime(), actor->GetProperty()->GetMTime(),
    actor->GetTexture() ? actor->GetTexture()->GetMTime() : 0,
    mapper->GetSelection() ? mapper->GetSelection()->GetMTime() : 0 };
  auto add = [&key](vtkObject* object)
  {
    key.push_back(static_cast<vtkMTimeType>(reinterpret_cast<std::uintptr_t>(object)));
    key.push_back(object ? object->GetMTime() : 0);
  };
  add(input->GetPoints()->GetData());
  for (vtkCellArray* cells : { input->GetVerts(), input->GetLines(), input->GetPolys(), input->GetStrips() })
  {
    add(cells);
  }
  for (vtkFieldData* data :
    { static_cast<vtkFieldData*>(input->GetPointData()), static_cast<vtkFieldData*>(input->GetCellData()) })
  {
    for (int a = 0; a < data->GetNumberOfArrays(); ++a)
    {
      add(data->GetAbstractArray(a));
    }
  }
  return key;
}

bool ScalarModeUsesFieldData(int mode) // field data is not in StructureOf()
{
  return mode == VTK_SCALAR_MODE_USE_FIELD_DATA || mode == VTK_SCALAR_MODE_USE_CELL_FIELD_DATA ||
    mode == VTK_SCALAR_MODE_USE_POINT_FIELD_DATA;
}

vtkFFDDeviceOutput* DeviceOutputOf(vtkPolyData* input)
{
  return input ? vtkFFDDeviceOutput::SafeDownCast(input->GetInformation()->Get(vtkFFDDeform::DEVICE_OUTPUT()))
               : nullptr;
}

// A vertex buffer as the device writes it: float triples, one per point, with the buffer's shift and scale.
bool AsDeviceTarget(vtkOpenGLVertexBufferObject* vbo, vtkIdType points, vtkFFDDeviceOutput::GLBuffer& target)
{
  if (!vbo || vbo->GetDataType() != VTK_FLOAT || vbo->GetNumberOfComponents() != 3 ||
    vbo->GetStride() != 3 * sizeof(float) || vtkIdType(vbo->GetNumberOfTuples()) != points)
  {
    return false;
  }
  target.Name = static_cast<unsigned int>(vbo->GetHandle());
  target.Tuples = points;
  if (vbo->GetCoordShiftAndScaleEnabled())
  {
    const std::vector<double>& shift = vbo->GetShift();
    const std::vector<double>& scale = vbo->GetScale();
    std::copy_n(shift.begin(), 3, target.Shift);
    std::copy_n(scale.begin(), 3, target.Scale);
  }
  return true;
}
} // namespace

struct vtkFFDInteropPolyDataMapper::vtkInternals
{
  Decision State = Decision::Undecided;
  vtkFFDGLRegistrations Registrations;
  Written Last;
  std::vector<vtkMTimeType> BuiltStructure; // StructureOf() the input when the buffers were last built
  vtkRenderer* Renderer = nullptr;          // of the render under way: a failure draws that frame from the host
  vtkActor* Actor = nullptr;
  vtkWeakPointer<vtkOpenGLRenderWindow> Window; // whose context the registered buffers belong to
};

//------------------------------------------------------------------------------------------------------------
vtkFFDInteropPolyDataMapper::vtkFFDInteropPolyDataMapper()
  : Interop(true)
  , LastFrameFromDevice(false)
  , NumberOfDeviceWrites(0)
  , Internals(new vtkInternals)
{
}

vtkFFDInteropPolyDataMapper::~vtkFFDInteropPolyDataMapper()
{
  // Before the superclass's destructor deletes the buffers: CUDA's registrations go first, in their context. (A
  // window that went first has released them through ReleaseGraphicsResources().)
  if (vtkOpenGLRenderWindow* window = this->Internals->Window)
  {
    window->PushContext();
    this->Internals->Registrations.Release();
    window->PopContext();
  }
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDInteropPolyDataMapper::RenderPiece(vtkRenderer* ren, vtkActor* act)
{
  this->DecideInterop();
  this->LastFrameFromDevice = false;
  this->Internals->Renderer = ren;
  this->Internals->Actor = act;
  this->Internals->Window = vtkOpenGLRenderWindow::SafeDownCast(ren->GetRenderWindow());
  {
    const KeepOnDeviceRequest request(this, this->Interop && this->Internals->State == Decision::On);
    this->Superclass::RenderPiece(ren, act);
  }
  this->Internals->Renderer = nullptr;
  this->Internals->Actor = nullptr;
}

double* vtkFFDInteropPolyDataMapper::GetBounds()
{
  const KeepOnDeviceRequest request(this, this->Interop && this->Internals->State == Decision::On);
  return this->Superclass::GetBounds();
}

void vtkFFDInteropPolyDataMapper::ComputeBounds()
{
  vtkFFDDeviceOutput* device = DeviceOutputOf(this->GetInput());
  if (!device)
  {
    this->Superclass::ComputeBounds();
    return;
  }
  std::copy_n(device->GetBounds(), 6, this->Bounds);
  if (this->Bounds[0] > this->Bounds[1])
  {
    vtkMath::UninitializeBounds(this->Bounds);
  }
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDInteropPolyDataMapper::DecideInterop()
{
  if (!this->Interop || this->Internals->State != Decision::Undecided)
  {
    return;
  }
  std::string why;
  if (vtkFFDDeviceOutput::IsGLContextOnDevice(why))
  {
    this->Internals->State = Decision::On;
    this->InteropStatus.clear();
    const char* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    vtkLogF(INFO, "GPU-GL interop on: the CUDA device writes vtkFFDDeform's points into the vertex buffers of %s",
      renderer ? renderer : "this OpenGL context");
    return;
  }
  this->Internals->State = Decision::Off;
  this->InteropStatus = why;
  vtkLogF(INFO, "GPU-GL interop off (%s): the deformed points are drawn from the host", why.c_str());
}

void vtkFFDInteropPolyDataMapper::TurnInteropOff(const std::string& why)
{
  vtkWarningMacro("GPU-GL interop turned off (" << why << "); the deformed points are drawn from the host.");
  vtkInternals& internals = *this->Internals;
  internals.State = Decision::Off;
  this->InteropStatus = why;
  internals.Registrations.Release();
  internals.Last = Written();
  internals.BuiltStructure.clear();
  // This frame too: the input executes again without the request, downloads, and the buffers are rebuilt.
  this->GetInputInformation()->Remove(vtkFFDDeform::KEEP_OUTPUT_ON_DEVICE());
  this->GetInputAlgorithm()->Update();
  this->CurrentInput = this->GetInput();
  if (internals.Renderer && internals.Actor)
  {
    this->Superclass::UpdateBufferObjects(internals.Renderer, internals.Actor);
  }
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDInteropPolyDataMapper::UpdateBufferObjects(vtkRenderer* ren, vtkActor* act)
{
  vtkInternals& internals = *this->Internals;
  const bool onDevice = DeviceOutputOf(this->CurrentInput) != nullptr;
  std::vector<vtkMTimeType> structure;
  if (onDevice)
  {
    structure = StructureOf(this->CurrentInput, this, act);
  }
  const bool pointsOnly = onDevice && structure == internals.BuiltStructure && this->VBOs->GetVBO("vertexMC");
  if (!pointsOnly || ScalarModeUsesFieldData(this->GetScalarMode()))
  {
    this->Superclass::UpdateBufferObjects(ren, act);
    internals.BuiltStructure = structure; // empty for host points: the next output kept on the device rebuilds
  }
  this->LastFrameFromDevice = this->WriteDeviceOutput();
}

bool vtkFFDInteropPolyDataMapper::WriteDeviceOutput()
{
  vtkFFDDeviceOutput* device = DeviceOutputOf(this->CurrentInput);
  if (!device)
  {
    return false; // host points: vtkOpenGLPolyDataMapper uploaded them
  }
  vtkInternals& internals = *this->Internals;
  vtkOpenGLVertexBufferObject* pointsVBO = this->VBOs->GetVBO("vertexMC");
  vtkOpenGLVertexBufferObject* normalsVBO = this->VBOs->GetVBO("normalMC");
  vtkFFDDeviceOutput::GLBuffer points, normals;
  const vtkIdType count = device->GetNumberOfPoints();
  if (!AsDeviceTarget(pointsVBO, count, points) ||
    (normalsVBO && !(device->GetHasNormals() && AsDeviceTarget(normalsVBO, count, normals))))
  {
    this->TurnInteropOff("the vertex buffers are not the float triples, one per point, that the device writes");
    return false;
  }
  Written now;
  now.Output = device;
  now.OutputTime = device->GetMTime();
  now.Points = pointsVBO->GetHandle();
  now.PointsUpload = pointsVBO->GetUploadTime();
  now.Normals = normalsVBO ? normalsVBO->GetHandle() : 0;
  now.NormalsUpload = normalsVBO ? normalsVBO->GetUploadTime().GetMTime() : 0;
  if (now == internals.Last)
  {
    return true; // a frame of the same output (the camera moved): the buffers hold it
  }
  std::string why;
  if (!device->WriteToGLBuffers(
        internals.Registrations, points, normalsVBO ? &normals : nullptr, !now.SameBuffers(internals.Last), why))
  {
    this->TurnInteropOff(why);
    return false;
  }
  internals.Last = now;
  ++this->NumberOfDeviceWrites;
  return true;
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDInteropPolyDataMapper::ReleaseGraphicsResources(vtkWindow* window)
{
  this->Internals->Registrations.Release(); // before the buffers go
  this->Internals->Last = Written();
  this->Internals->BuiltStructure.clear();
  this->Superclass::ReleaseGraphicsResources(window);
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDInteropPolyDataMapper::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Interop: " << (this->Interop ? "On" : "Off") << "\n";
  os << indent << "InteropStatus: " << (this->InteropStatus.empty() ? "(none)" : this->InteropStatus) << "\n";
  os << indent << "LastFrameFromDevice: " << (this->LastFrameFromDevice ? "On" : "Off") << "\n";
  os << indent << "NumberOfDeviceWrites: " << this->NumberOfDeviceWrites << "\n";
}
