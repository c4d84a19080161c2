// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkFFDInteropPolyDataMapper
 * @brief   draws vtkFFDDeform's output from the CUDA device: the deformed points go straight into its vertex buffers
 *
 * GPU–graphics interop, the paper's third contribution (docs/rendering.md, "GPU–GL interop"). A
 * vtkOpenGLPolyDataMapper which, when its OpenGL context runs on the CUDA device, asks the vtkFFDDeform that
 * feeds it to keep its output there (vtkFFDDeform::KEEP_OUTPUT_ON_DEVICE(), around the mapper's own updates) and
 * has the device write the deformed points, and the transformed normals, into the vertex buffer objects it draws
 * (registered with CUDA), in the layout and with the coordinate shift and scale that vtkOpenGLPolyDataMapper gives
 * them. Per frame only the lattice's displacements cross the bus. The rest is vtkOpenGLPolyDataMapper's: cells,
 * colours and texture coordinates are uploaded by it, once while they do not change; the bounds are those of the
 * deformed points, reduced on the device.
 *
 * Where interop cannot run (a build without CUDA, no device, a context on another driver such as Mesa's
 * llvmpipe, or on another GPU), or with Interop off, or when the input is not kept on the device (the CPU
 * deforms, ComputeJacobianDeterminant is on, another filter comes in between), it draws as
 * vtkOpenGLPolyDataMapper does, from the host's points. The first render logs one line (vtkLogger, INFO) that
 * says which path it takes and why ("GPU-GL interop on: ..." or "GPU-GL interop off: ..."); a failure of the
 * device later turns interop off with a warning, and that frame is drawn from downloaded points.
 *
 * One render window per mapper (CUDA's registrations of its buffers belong to that window's context).
 *
 * @sa vtkFFDDeform vtkOpenGLPolyDataMapper
 */
#ifndef vtkFFDInteropPolyDataMapper_h
#define vtkFFDInteropPolyDataMapper_h

#include "vtkFFDRenderingInteropModule.h" // For export macro
#include "vtkOpenGLPolyDataMapper.h"

#include <memory> // For std::unique_ptr
#include <string> // For std::string

class VTKFFDRENDERINGINTEROP_EXPORT vtkFFDInteropPolyDataMapper : public vtkOpenGLPolyDataMapper
{
public:
  static vtkFFDInteropPolyDataMapper* New();
  vtkTypeMacro(vtkFFDInteropPolyDataMapper, vtkOpenGLPolyDataMapper);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// Draw from the CUDA device where possible (default on); off: vtkOpenGLPolyDataMapper's host path.
  vtkSetMacro(Interop, bool);
  vtkGetMacro(Interop, bool);
  vtkBooleanMacro(Interop, bool);
  ///@}

  /// Whether the last frame's points were written by the device.
  vtkGetMacro(LastFrameFromDevice, bool);

  /// Times the device wrote the vertex buffers (once per new deformation drawn), since this mapper was made.
  vtkGetMacro(NumberOfDeviceWrites, vtkIdType);

  /// Why interop is off ("" while it is on or before the first render).
  const char* GetInteropStatus() const { return this->InteropStatus.c_str(); }

  void RenderPiece(vtkRenderer* ren, vtkActor* act) override;
  using Superclass::GetBounds;
  double* GetBounds() override;
  void ReleaseGraphicsResources(vtkWindow* window) override;

protected:
  vtkFFDInteropPolyDataMapper();
  ~vtkFFDInteropPolyDataMapper() override;

  void ComputeBounds() override;
  void UpdateBufferObjects(vtkRenderer* ren, vtkActor* act) override;

  bool Interop;
  bool LastFrameFromDevice;
  vtkIdType NumberOfDeviceWrites;
  std::string InteropStatus;

private:
  vtkFFDInteropPolyDataMapper(const vtkFFDInteropPolyDataMapper&) = delete;
  void operator=(const vtkFFDInteropPolyDataMapper&) = delete;

  // The steps of RenderPiece() and UpdateBufferObjects().
  void DecideInterop(); // once, at the first render, with the context current
  bool WriteDeviceOutput();
  void TurnInteropOff(const std::string& why);

  struct vtkInternals;
  std::unique_ptr<vtkInternals> Internals;
};

#endif
