// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDTestMeshes.h
 * @brief Reads the real meshes (bear, elephant, armadillo, ...) that Utilities/setup.sh fetches from
 * Debian's libcgal-demo package into VOXELFFD_MESH_DIR as VTK XML PolyData.
 */
#ifndef FFDTestMeshes_h
#define FFDTestMeshes_h

#include "vtkNew.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSmartPointer.h"
#include "vtkXMLPolyDataReader.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <iostream>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

/// The largest distance between the same points of two point sets (over a's points).
inline double LargestDistance(vtkPointSet* a, vtkPointSet* b)
{
  double largest = 0.0;
  for (vtkIdType p = 0; p < a->GetNumberOfPoints(); ++p)
  {
    double x[3], y[3];
    a->GetPoint(p, x);
    b->GetPoint(p, y);
    largest = std::max(largest, std::hypot(x[0] - y[0], x[1] - y[1], x[2] - y[2]));
  }
  return largest;
}

/// The mesh `name` (e.g. "bear"); throws with a hint when the set-up has not fetched it.
inline vtkSmartPointer<vtkPolyData> ReadTestMesh(const std::string& name)
{
  const std::string path = std::string(VOXELFFD_MESH_DIR) + "/" + name + ".vtp";
  if (!std::ifstream(path).good())
  {
    throw std::runtime_error(path + " is missing: run Utilities/setup.sh, which fetches the meshes");
  }
  vtkNew<vtkXMLPolyDataReader> reader;
  reader->SetFileName(path.c_str());
  reader->Update();
  vtkSmartPointer<vtkPolyData> mesh = reader->GetOutput();
  if (mesh->GetNumberOfPoints() == 0)
  {
    throw std::runtime_error(path + " holds no points");
  }
  return mesh;
}

/// ReadTestMesh() for VTK-style tests, which report failure by their return value: the mesh, or nullptr after
/// printing why on stderr.
inline vtkSmartPointer<vtkPolyData> ReadTestMeshOrReport(const std::string& name)
{
  try
  {
    return ReadTestMesh(name);
  }
  catch (const std::exception& e)
  {
    std::cerr << e.what() << "\n";
    return nullptr;
  }
}

/// The mesh's points in float64 and `outside` more, uniform in a box 60 % larger than its bounds (30 % beyond
/// each side): a cloud with points inside and outside a lattice over the mesh.
inline vtkSmartPointer<vtkPolyData> PointsAround(vtkPolyData* mesh, int outside, std::mt19937& rng)
{
  double b[6];
  mesh->GetBounds(b);
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  for (vtkIdType p = 0; p < mesh->GetNumberOfPoints(); ++p)
  {
    points->InsertNextPoint(mesh->GetPoint(p));
  }
  std::uniform_real_distribution<double> unit(-0.3, 1.3);
  for (int p = 0; p < outside; ++p)
  {
    points->InsertNextPoint(
      b[0] + unit(rng) * (b[1] - b[0]), b[2] + unit(rng) * (b[3] - b[2]), b[4] + unit(rng) * (b[5] - b[4]));
  }
  auto cloud = vtkSmartPointer<vtkPolyData>::New();
  cloud->SetPoints(points);
  return cloud;
}

/// A point set of the given points (double precision), without cells.
inline vtkSmartPointer<vtkPolyData> PointCloud(const std::vector<std::array<double, 3>>& xs)
{
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  for (const std::array<double, 3>& x : xs)
  {
    points->InsertNextPoint(x.data());
  }
  auto cloud = vtkSmartPointer<vtkPolyData>::New();
  cloud->SetPoints(points);
  return cloud;
}

/// A copy of `mesh` (cells and arrays shared) whose points are stored as float: the float path of the filters.
inline vtkSmartPointer<vtkPolyData> WithFloatPoints(vtkPolyData* mesh)
{
  vtkNew<vtkPoints> floatPoints;
  floatPoints->SetDataTypeToFloat();
  floatPoints->DeepCopy(mesh->GetPoints()); // keeps the float type: DeepCopy converts the values
  auto floatMesh = vtkSmartPointer<vtkPolyData>::New();
  floatMesh->ShallowCopy(mesh);
  floatMesh->SetPoints(floatPoints);
  return floatMesh;
}

#endif
