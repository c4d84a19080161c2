// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDDeviceOutput.h"

#include "vtkObjectFactory.h"

#ifdef VOXELFFD_HAS_CUDA
#include "FFDCudaGLBuffers.h"
#endif

#include <algorithm>
#include <utility>

vtkStandardNewMacro(vtkFFDDeviceOutput);

#ifdef VOXELFFD_HAS_CUDA
struct vtkFFDGLRegistrations::vtkInternals
{
  ffd::cuda::GLBuffers Buffers;
};
#else
struct vtkFFDGLRegistrations::vtkInternals
{
};
#endif

vtkFFDGLRegistrations::vtkFFDGLRegistrations()
  : Internals(new vtkInternals)
{
}

vtkFFDGLRegistrations::~vtkFFDGLRegistrations() = default;

//------------------------------------------------------------------------------------------------------------
void vtkFFDDeviceOutput::SetDevice(
  std::shared_ptr<ffd::cuda::ResidentPoints> device, vtkIdType points, bool normals, const double bounds[6])
{
  this->Device = std::move(device);
  this->NumberOfPoints = points;
  this->HasNormals = normals;
  std::copy(bounds, bounds + 6, this->Bounds);
  this->Modified();
}

#ifdef VOXELFFD_HAS_CUDA
void vtkFFDGLRegistrations::Release()
{
  this->Internals->Buffers.Release();
}

bool vtkFFDDeviceOutput::IsGLContextOnDevice(std::string& why)
{
  return ffd::cuda::GLContextOnDevice(&why);
}

bool vtkFFDDeviceOutput::WriteToGLBuffers(vtkFFDGLRegistrations& registrations, const GLBuffer& points,
  const GLBuffer* normals, bool reregister, std::string& why) const
{
  if (!this->Device || (normals && !this->HasNormals))
  {
    why = "the device holds no such output";
    return false;
  }
  auto target = [](const GLBuffer& buffer)
  {
    ffd::cuda::GLVertexBuffer b;
    b.Name = buffer.Name;
    b.Tuples = buffer.Tuples;
    std::copy(buffer.Shift, buffer.Shift + 3, b.Shift);
    std::copy(buffer.Scale, buffer.Scale + 3, b.Scale);
    return b;
  };
  const ffd::cuda::GLVertexBuffer pointsBuffer = target(points);
  const ffd::cuda::GLVertexBuffer normalsBuffer = normals ? target(*normals) : ffd::cuda::GLVertexBuffer();
  ffd::cuda::GLBuffers& buffers = registrations.Internals->Buffers;
  if (!buffers.Write(*this->Device, pointsBuffer, normals ? &normalsBuffer : nullptr, reregister))
  {
    why = buffers.GetLastError();
    return false;
  }
  return true;
}
#else
// Built without CUDA: there is no device output to write.
void vtkFFDGLRegistrations::Release() {}

bool vtkFFDDeviceOutput::IsGLContextOnDevice(std::string& why)
{
  why = "VoxelFFD was built without CUDA";
  return false;
}

bool vtkFFDDeviceOutput::WriteToGLBuffers(
  vtkFFDGLRegistrations&, const GLBuffer&, const GLBuffer*, bool, std::string& why) const
{
  return vtkFFDDeviceOutput::IsGLContextOnDevice(why);
}
#endif

//------------------------------------------------------------------------------------------------------------
void vtkFFDDeviceOutput::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "NumberOfPoints: " << this->NumberOfPoints << "\n";
  os << indent << "HasNormals: " << (this->HasNormals ? "On" : "Off") << "\n";
  os << indent << "Bounds: " << this->Bounds[0] << " " << this->Bounds[1] << " " << this->Bounds[2] << " "
     << this->Bounds[3] << " " << this->Bounds[4] << " " << this->Bounds[5] << "\n";
}
