// SPDX-License-Identifier: BSD-3-Clause
#include "FFDCudaGLBuffers.h"

#include "FFDCudaDevice.cuh"

#include <GL/gl.h> // cuda_gl_interop.h's types
#include <cuda_gl_interop.h>

#include <map>
#include <utility>

namespace ffd
{
namespace cuda
{
using detail::Check;
using detail::CudaError;

namespace
{
// VTK's vertex buffer layout: 3 floats a tuple, each value (v - shift) * scale computed in double and rounded
// to float, as vtkOpenGLVertexBufferObject does on the host, so that both paths draw the same bits.
struct ShiftScale
{
  double Shift[3], Scale[3];
};

template <typename Real>
__global__ void __launch_bounds__(detail::ThreadsPerBlock)
  WriteVertexBufferKernel(const Real* __restrict__ values, std::int64_t count, ShiftScale map, float* out)
{
  const std::int64_t i = blockIdx.x * std::int64_t(detail::ThreadsPerBlock) + threadIdx.x;
  if (i < 3 * count)
  {
    const int c = int(i % 3);
    out[i] = float((double(values[i]) - map.Shift[c]) * map.Scale[c]);
  }
}

ShiftScale ShiftScaleOf(const GLVertexBuffer& buffer)
{
  ShiftScale map;
  for (int c = 0; c < 3; ++c)
  {
    map.Shift[c] = buffer.Shift[c];
    map.Scale[c] = buffer.Scale[c];
  }
  return map;
}
} // namespace

//------------------------------------------------------------------------------------------------------------
bool GLContextOnDevice(std::string* why)
{
  auto fail = [&](const std::string& reason)
  {
    if (why)
    {
      *why = reason;
    }
    cudaGetLastError(); // clear a non-sticky error
    return false;
  };
  if (!DeviceAvailable(why))
  {
    return false;
  }
  unsigned int count = 0;
  int devices[4] = { -1, -1, -1, -1 };
  const cudaError_t code = cudaGLGetDevices(&count, devices, 4, cudaGLDeviceListAll);
  if (code != cudaSuccess || count == 0)
  {
    return fail(std::string("the OpenGL context is not on a CUDA device (") +
      (code != cudaSuccess ? cudaGetErrorString(code) : "no device") + ")");
  }
  int current = 0;
  if (cudaGetDevice(&current) != cudaSuccess)
  {
    return fail("no current CUDA device");
  }
  for (unsigned int d = 0; d < count && d < 4; ++d)
  {
    if (devices[d] == current)
    {
      return true;
    }
  }
  return fail("the OpenGL context is on CUDA device " + std::to_string(devices[0]) + ", the deformation on device " +
    std::to_string(current));
}

//------------------------------------------------------------------------------------------------------------
struct GLBuffers::Impl
{
  std::map<unsigned int, cudaGraphicsResource_t> Registered; // by buffer name
  std::string LastError;

  cudaGraphicsResource_t Registration(unsigned int name, bool reregister)
  {
    auto found = this->Registered.find(name);
    if (found != this->Registered.end() && reregister)
    {
      cudaGraphicsUnregisterResource(found->second);
      this->Registered.erase(found);
      found = this->Registered.end();
    }
    if (found != this->Registered.end())
    {
      return found->second;
    }
    cudaGraphicsResource_t resource = nullptr;
    Check(cudaGraphicsGLRegisterBuffer(&resource, name, cudaGraphicsRegisterFlagsWriteDiscard),
      "registering an OpenGL buffer");
    this->Registered.emplace(name, resource);
    return resource;
  }

  // Maps the buffer, checks that it holds `buffer.Tuples` float triples, writes `values` into it and unmaps it.
  template <typename Real>
  void Fill(const Real* values, std::int64_t count, const GLVertexBuffer& buffer, bool reregister, cudaStream_t stream)
  {
    if (buffer.Tuples != count)
    {
      throw CudaError{ cudaErrorInvalidValue, "writing an OpenGL buffer: it has another number of points" };
    }
    cudaGraphicsResource_t resource = this->Registration(buffer.Name, reregister);
    Check(cudaGraphicsMapResources(1, &resource, stream), "mapping an OpenGL buffer");
    void* data = nullptr;
    std::size_t bytes = 0;
    const cudaError_t mapped = cudaGraphicsResourceGetMappedPointer(&data, &bytes, resource);
    if (mapped == cudaSuccess && bytes >= std::size_t(count) * 3 * sizeof(float))
    {
      WriteVertexBufferKernel<Real><<<detail::BlocksFor(3 * count), detail::ThreadsPerBlock, 0, stream>>>(
        values, count, ShiftScaleOf(buffer), static_cast<float*>(data));
    }
    const cudaError_t launched = cudaGetLastError();
    Check(cudaGraphicsUnmapResources(1, &resource, stream), "unmapping an OpenGL buffer");
    Check(mapped, "mapping an OpenGL buffer");
    if (bytes < std::size_t(count) * 3 * sizeof(float))
    {
      throw CudaError{ cudaErrorInvalidValue, "writing an OpenGL buffer: it is smaller than the points" };
    }
    Check(launched, "writing an OpenGL buffer");
  }

  void Release()
  {
    for (auto& registered : this->Registered)
    {
      cudaGraphicsUnregisterResource(registered.second);
    }
    this->Registered.clear();
  }
};

GLBuffers::GLBuffers()
  : I(new Impl)
{
}

GLBuffers::~GLBuffers()
{
  this->I->Release();
}

bool GLBuffers::Write(
  const ResidentPoints& source, const GLVertexBuffer& points, const GLVertexBuffer* normals, bool reregister)
{
  const ResidentPoints::State& s = *source.S;
  try
  {
    if (!s.Evaluated || (normals && !s.EvaluatedNormals))
    {
      throw CudaError{ cudaErrorInvalidValue, "writing OpenGL buffers: nothing of that was evaluated" };
    }
    auto fill = [&](const detail::Buffer& values, const GLVertexBuffer& buffer)
    {
      if (s.IsDouble)
      {
        this->I->Fill(values.As<double>(), s.Count, buffer, reregister, s.Stream);
      }
      else
      {
        this->I->Fill(values.As<float>(), s.Count, buffer, reregister, s.Stream);
      }
    };
    fill(s.OutPoints, points);
    if (normals)
    {
      fill(s.OutNormals, *normals);
    }
    return true;
  }
  catch (const CudaError& e)
  {
    this->I->LastError = std::string("CUDA failed while ") + e.What + ": " + cudaGetErrorString(e.Code);
    cudaGetLastError();
    this->I->Release();
    return false;
  }
}

void GLBuffers::Release()
{
  this->I->Release();
}

const std::string& GLBuffers::GetLastError() const
{
  return this->I->LastError;
}

} // namespace cuda
} // namespace ffd
