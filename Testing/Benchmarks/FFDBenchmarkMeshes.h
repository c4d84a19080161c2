// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDBenchmarkMeshes.h
 * @brief The shaded test mesh of the interaction benchmark and the soak (Testing/Benchmarks).
 */
#ifndef FFDBenchmarkMeshes_h
#define FFDBenchmarkMeshes_h

#include "vtkLinearSubdivisionFilter.h"
#include "vtkNew.h"
#include "vtkPolyData.h"
#include "vtkPolyDataNormals.h"
#include "vtkSmartPointer.h"
#include "vtkXMLPolyDataReader.h"

#include <string>

/**
 * The mesh of `path` subdivided `levels` times (vtkLinearSubdivisionFilter; none for 0), with point normals as
 * a shaded mesh has them (vtkPolyDataNormals without splitting, so the points stay the same). Empty when the
 * file could not be read.
 */
inline vtkSmartPointer<vtkPolyData> ShadedSubdividedMesh(const std::string& path, int levels)
{
  vtkNew<vtkXMLPolyDataReader> reader;
  reader->SetFileName(path.c_str());
  vtkNew<vtkLinearSubdivisionFilter> subdivide;
  subdivide->SetInputConnection(reader->GetOutputPort());
  subdivide->SetNumberOfSubdivisions(levels);
  vtkNew<vtkPolyDataNormals> normals;
  normals->SetInputConnection(levels > 0 ? subdivide->GetOutputPort() : reader->GetOutputPort());
  normals->SplittingOff();
  normals->Update();
  auto mesh = vtkSmartPointer<vtkPolyData>::New();
  mesh->ShallowCopy(normals->GetOutput());
  return mesh;
}

#endif
