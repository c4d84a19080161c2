// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkFFDDeviceOutput
 * @brief   vtkFFDDeform's deformed points left on the CUDA device for a renderer (private to the VoxelFFD modules)
 *
 * GPU–graphics interop (docs/rendering.md, "GPU–GL interop"). When a consumer of vtkFFDDeform asks for its
 * output on the device (the request key vtkFFDDeform::KEEP_OUTPUT_ON_DEVICE(), which vtkFFDInteropPolyDataMapper
 * sets around its own updates) and the CUDA backend deforms, the deformed points and normals stay on the device:
 * the output data object carries this handle under vtkFFDDeform::DEVICE_OUTPUT(), with the deformed points'
 * bounds (reduced on the device), and WriteToGLBuffers() converts them into the renderer's vertex buffers there.
 * The handle shares the ownership of the device's state, so it stays valid for as long as the output holds it.
 *
 * vtkFFDGLRegistrations keeps CUDA's registrations of a renderer's OpenGL buffers across frames; its owner
 * releases them while their context is current, before the buffers are deleted.
 *
 * In a build without CUDA there is never such an output, and IsGLContextOnDevice() says why.
 */
#ifndef vtkFFDDeviceOutput_h
#define vtkFFDDeviceOutput_h

#include "vtkFFDFiltersCoreModule.h" // For export macro
#include "vtkObject.h"

#include <memory> // For std::shared_ptr
#include <string> // For std::string

namespace ffd
{
namespace cuda
{
class ResidentPoints;
}
}

class VTKFFDFILTERSCORE_EXPORT vtkFFDGLRegistrations
{
public:
  vtkFFDGLRegistrations();
  ~vtkFFDGLRegistrations();
  vtkFFDGLRegistrations(const vtkFFDGLRegistrations&) = delete;
  vtkFFDGLRegistrations& operator=(const vtkFFDGLRegistrations&) = delete;

  /// Unregisters every buffer (with their OpenGL context current).
  void Release();

private:
  friend class vtkFFDDeviceOutput;
  struct vtkInternals;
  std::unique_ptr<vtkInternals> Internals;
};

class VTKFFDFILTERSCORE_EXPORT vtkFFDDeviceOutput : public vtkObject
{
public:
  static vtkFFDDeviceOutput* New();
  vtkTypeMacro(vtkFFDDeviceOutput, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// True when the OpenGL context current on this thread runs on the CUDA device that deforms; otherwise false
  /// and why not (no CUDA in this build, no device, or a context on another device or driver, e.g. Mesa).
  static bool IsGLContextOnDevice(std::string& why);

  vtkIdType GetNumberOfPoints() const { return this->NumberOfPoints; }
  bool GetHasNormals() const { return this->HasNormals; }
  /// The deformed points' bounds (non-finite coordinates skipped).
  const double* GetBounds() const { return this->Bounds; }

  /// An OpenGL vertex buffer of `Tuples` float triples, each value (v - Shift) * Scale (vtkOpenGLVertexBufferObject).
  struct GLBuffer
  {
    unsigned int Name = 0;
    vtkIdType Tuples = 0;
    double Shift[3] = { 0, 0, 0 };
    double Scale[3] = { 1, 1, 1 };
  };

  /**
   * Writes the deformed points into `points` and, when not null, the transformed normals into `normals`
   * (buffers of the OpenGL context current on this thread, registered with CUDA through `registrations`, again
   * when `reregister`: their storage was re-specified). Nothing crosses the bus. False, and why, on any failure
   * (the registrations are then released).
   */
  bool WriteToGLBuffers(vtkFFDGLRegistrations& registrations, const GLBuffer& points, const GLBuffer* normals,
    bool reregister, std::string& why) const;

  /// Set by the CUDA backend: the device state that holds the last evaluation, and what it holds.
  void SetDevice(
    std::shared_ptr<ffd::cuda::ResidentPoints> device, vtkIdType points, bool normals, const double bounds[6]);

protected:
  vtkFFDDeviceOutput() = default;
  ~vtkFFDDeviceOutput() override = default;

private:
  vtkFFDDeviceOutput(const vtkFFDDeviceOutput&) = delete;
  void operator=(const vtkFFDDeviceOutput&) = delete;

  std::shared_ptr<ffd::cuda::ResidentPoints> Device;
  vtkIdType NumberOfPoints = 0;
  bool HasNormals = false;
  double Bounds[6] = { 1, -1, 1, -1, 1, -1 };
};

#endif
