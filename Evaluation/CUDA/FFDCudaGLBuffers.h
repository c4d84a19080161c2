// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDCudaGLBuffers.h
 * @brief GPU–graphics interop: the device writes its last evaluation straight into OpenGL vertex buffers.
 *
 * Plain C++ (no CUDA, OpenGL or VTK header); FFDCudaGLBuffers.cu is compiled by nvcc. A renderer that draws the
 * deformed points from vertex buffer objects (VTK's vtkOpenGLPolyDataMapper: one buffer of float x, y, z per
 * point for the positions, one for the normals, each value stored as (v - shift) * scale) gives their names;
 * the device converts its results (float or double) into them on its stream, and nothing crosses the bus. The
 * buffers must belong to the OpenGL context current on the calling thread, and that context must run on the
 * CUDA device (GLContextOnDevice()).
 *
 * Failures return false with the reason in GetLastError(), as ResidentPoints does; the buffers are then
 * unregistered (the caller falls back to uploading host data).
 */
#ifndef FFDCudaGLBuffers_h
#define FFDCudaGLBuffers_h

#include "FFDCudaResidentPoints.h"

#include <cstdint>
#include <memory>
#include <string>

namespace ffd
{
namespace cuda
{

/// True when the OpenGL context current on this thread runs on the current CUDA device; otherwise false, with
/// the reason in `why` when given (no CUDA device, a context of another vendor such as Mesa's llvmpipe, another
/// GPU).
bool GLContextOnDevice(std::string* why = nullptr);

/// One OpenGL vertex buffer to fill: `Tuples` tuples of 3 floats, each value (v - Shift) * Scale.
struct GLVertexBuffer
{
  unsigned int Name = 0;
  std::int64_t Tuples = 0;
  double Shift[3] = { 0, 0, 0 };
  double Scale[3] = { 1, 1, 1 };
};

/// CUDA's registrations of OpenGL buffers, kept across frames by whoever owns the buffers.
class GLBuffers
{
public:
  GLBuffers();
  ~GLBuffers();
  GLBuffers(const GLBuffers&) = delete;
  GLBuffers& operator=(const GLBuffers&) = delete;

  /**
   * Writes `source`'s last evaluation into `points` (and its normals into `normals`, when not null: they must
   * have been evaluated). A buffer is registered with CUDA the first time its name is seen, and again when
   * `reregister` (its storage was re-specified since, as glBufferData does). The write is ordered before the
   * OpenGL commands issued after it returns.
   */
  bool Write(
    const ResidentPoints& source, const GLVertexBuffer& points, const GLVertexBuffer* normals, bool reregister);

  /// Unregisters every buffer; call while their context is current, before they are deleted.
  void Release();

  const std::string& GetLastError() const;

  struct Impl;

private:
  std::unique_ptr<Impl> I;
};

} // namespace cuda
} // namespace ffd

#endif
