// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDInteropTestScene.h
 * @brief What the GPU–GL interop tests share: whether the device path is expected (VOXELFFD_EXPECT_INTEROP=1, set
 * by Utilities/gpu-rendering.sh on the GPU machine; elsewhere the fallback is), the bear with point normals and
 * its lattices, a deformation drawn by vtkFFDInteropPolyDataMapper, and the read-back of the vertex buffers
 * that mapper draws, compared with an independent float64 deformation on the CPU.
 */
#ifndef FFDInteropTestScene_h
#define FFDInteropTestScene_h

#include "FFDTestMeshes.h"

#include "vtkActor.h"
#include "vtkDataArray.h"
#include "vtkFFDBuildTetrahedralLattice.h"
#include "vtkFFDDeform.h"
#include "vtkFFDInteropPolyDataMapper.h"
#include "vtkNew.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLVertexBufferObject.h"
#include "vtkOpenGLVertexBufferObjectGroup.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkPolyDataNormals.h"
#include "vtkSmartPointer.h"
#include "vtkUnstructuredGrid.h"
#include "vtk_glew.h"

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

/// True on the GPU machine (VOXELFFD_EXPECT_INTEROP=1): the device must draw; elsewhere the host must.
inline bool ExpectInterop()
{
  const char* expect = std::getenv("VOXELFFD_EXPECT_INTEROP");
  return expect && std::strcmp(expect, "1") == 0;
}

/// The bear in float32 with point normals (vtkPolyDataNormals without splitting: the same points).
inline vtkSmartPointer<vtkPolyData> BearWithNormals()
{
  vtkSmartPointer<vtkPolyData> bear = ReadTestMeshOrReport("bear");
  if (!bear)
  {
    return nullptr;
  }
  vtkNew<vtkPolyDataNormals> normals;
  normals->SetInputData(WithFloatPoints(bear));
  normals->SplittingOff();
  normals->Update();
  auto withNormals = vtkSmartPointer<vtkPolyData>::New();
  withNormals->ShallowCopy(normals->GetOutput());
  return withNormals;
}

/// `mesh`'s tetrahedral control mesh (vtkFFDBuildTetrahedralLattice, subdivided once), a copy to move.
inline vtkSmartPointer<vtkUnstructuredGrid> TetrahedralLatticeOf(vtkPolyData* mesh)
{
  vtkNew<vtkFFDBuildTetrahedralLattice> build;
  build->SetInputData(mesh);
  build->SetSubdivisionLevels(1);
  build->Update();
  auto lattice = vtkSmartPointer<vtkUnstructuredGrid>::New();
  lattice->DeepCopy(build->GetOutput());
  return lattice;
}

/// A deformation drawn through vtkFFDInteropPolyDataMapper (the default backend: CUDA where there is a device).
struct InteropPipeline
{
  vtkNew<vtkFFDDeform> Deform;
  vtkNew<vtkFFDInteropPolyDataMapper> Mapper;
  vtkNew<vtkActor> Actor;

  InteropPipeline(vtkPolyData* mesh, vtkPointSet* lattice)
  {
    this->Deform->SetInputData(mesh);
    this->Deform->SetLatticeData(lattice);
    this->Mapper->SetInputConnection(this->Deform->GetOutputPort());
    this->Mapper->ScalarVisibilityOff();
    this->Actor->SetMapper(this->Mapper);
  }
};

/// `mesh` deformed by `lattice` on the CPU in float64: the reference the drawn buffers are compared with.
inline vtkSmartPointer<vtkPolyData> ReferenceDeformation(vtkPolyData* mesh, vtkPointSet* lattice)
{
  vtkNew<vtkFFDDeform> deform;
  deform->SetBackendToCPU();
  deform->SetOutputPointsPrecision(vtkAlgorithm::DOUBLE_PRECISION);
  deform->SetInputData(mesh);
  deform->SetLatticeData(lattice);
  deform->Update();
  auto reference = vtkSmartPointer<vtkPolyData>::New();
  reference->DeepCopy(deform->GetOutput());
  return reference;
}

/**
 * The largest difference between what `mapper`'s vertex buffer `attribute` ("vertexMC" or "normalMC") holds,
 * read back from OpenGL and mapped back through its shift and scale, and `expected` (3 components a point), over
 * every point and component; infinity when the buffer is missing or of another size.
 */
inline double LargestBufferError(
  vtkFFDInteropPolyDataMapper* mapper, vtkRenderWindow* window, const char* attribute, vtkDataArray* expected)
{
  vtkOpenGLVertexBufferObject* vbo = mapper->GetVBOs()->GetVBO(attribute);
  if (!vbo || !expected || vtkIdType(vbo->GetNumberOfTuples()) != expected->GetNumberOfTuples() ||
    vbo->GetStride() != 3 * sizeof(float))
  {
    return INFINITY;
  }
  std::vector<float> values(3 * std::size_t(vbo->GetNumberOfTuples()));
  window->MakeCurrent();
  glBindBuffer(GL_ARRAY_BUFFER, static_cast<GLuint>(vbo->GetHandle()));
  glGetBufferSubData(GL_ARRAY_BUFFER, 0, GLsizeiptr(values.size() * sizeof(float)), values.data());
  glBindBuffer(GL_ARRAY_BUFFER, 0);
  const bool shifted = vbo->GetCoordShiftAndScaleEnabled();
  double largest = 0.0;
  for (vtkIdType p = 0; p < expected->GetNumberOfTuples(); ++p)
  {
    for (int c = 0; c < 3; ++c)
    {
      const double stored = values[3 * p + c];
      const double value = shifted ? stored / vbo->GetScale()[c] + vbo->GetShift()[c] : stored;
      largest = std::max(largest, std::abs(value - expected->GetComponent(p, c)));
    }
  }
  return largest;
}

#endif
