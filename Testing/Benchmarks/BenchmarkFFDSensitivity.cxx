// SPDX-License-Identifier: BSD-3-Clause
// CPU benchmark of the adjoint (vtkFFDSensitivity, W^T g) beside the forward deformation (vtkFFDDeform) of the same
// basis, points and lattice, in one run, on vtkSMPTools' threads (--threads N; default: the backend's): each
// update after a moved lattice (forward) or a changed gradient (adjoint), the binding made once before, median of
// --repeats (default 5). Points: float32, uniform in a box, in voxel order (consecutive points in the same or
// neighbouring voxels of a 32^3 grid, as a mesh's vertices), --points N (default 2^20). The CUDA adjoint is
// measured by BenchmarkFFDCuda --adjoint. It prints a table and asserts nothing.
#include "FFDBenchmarkUtilities.h"

#include "vtkDoubleArray.h"
#include "vtkFFDBuildLattice.h"
#include "vtkFFDDeform.h"
#include "vtkFFDSensitivity.h"
#include "vtkFFDVoxelize.h"
#include "vtkFloatArray.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSMPTools.h"
#include "vtkSmartPointer.h"
#include "vtkStructuredGrid.h"

#include <cstdio>
#include <random>
#include <string>

namespace
{
// n float32 points in [0, 1]^3 in voxel order, with a gradient array "g" of components in [-1, 1].
vtkSmartPointer<vtkPolyData> Cloud(vtkIdType n, std::mt19937& rng)
{
  std::uniform_real_distribution<double> u(0.0, 1.0), unit(-1.0, 1.0);
  vtkNew<vtkPoints> points;
  points->SetDataTypeToFloat();
  points->SetNumberOfPoints(n);
  vtkNew<vtkDoubleArray> g;
  g->SetName("g");
  g->SetNumberOfComponents(3);
  g->SetNumberOfTuples(n);
  const vtkIdType cells = 32 * 32 * 32;
  for (vtkIdType i = 0; i < n; ++i)
  {
    const vtkIdType c = i * cells / n;
    points->SetPoint(
      i, (double(c % 32) + u(rng)) / 32, (double((c / 32) % 32) + u(rng)) / 32, (double(c / 1024) + u(rng)) / 32);
    g->SetTuple3(i, unit(rng), unit(rng), unit(rng));
  }
  auto cloud = vtkSmartPointer<vtkPolyData>::New();
  cloud->SetPoints(points);
  cloud->GetPointData()->AddArray(g);
  return cloud;
}

// The lattice of `basis` over `divisions`^3 voxels of the cloud, its control points moved at random.
vtkSmartPointer<vtkStructuredGrid> Lattice(vtkPolyData* cloud, int basis, int divisions, std::mt19937& rng)
{
  vtkNew<vtkFFDVoxelize> voxelize;
  voxelize->SetInputData(cloud);
  voxelize->SetDivisions(divisions, divisions, divisions);
  vtkNew<vtkFFDBuildLattice> build;
  build->SetInputConnection(voxelize->GetOutputPort());
  build->SetBasis(basis);
  build->SetLatticeFormToDense();
  build->Update();
  auto lattice = vtkSmartPointer<vtkStructuredGrid>::New();
  lattice->DeepCopy(build->GetOutputDataObject(0));
  std::uniform_real_distribution<double> move(-0.01, 0.01);
  for (vtkIdType p = 0; p < lattice->GetNumberOfPoints(); ++p)
  {
    double x[3];
    lattice->GetPoint(p, x);
    lattice->GetPoints()->SetPoint(p, x[0] + move(rng), x[1] + move(rng), x[2] + move(rng));
  }
  return lattice;
}
} // namespace

int main(int argc, char* argv[])
{
  int points = 1 << 20, repeats = 5, threads = 0;
  int status = 0;
  if (!ParseArguments(argc, argv, { { "--points", &points }, { "--repeats", &repeats }, { "--threads", &threads } },
        "[--points N] [--repeats N] [--threads N]", status))
  {
    return status;
  }
  if (threads > 0)
  {
    vtkSMPTools::Initialize(int(threads));
  }
  std::mt19937 rng(2026);
  vtkSmartPointer<vtkPolyData> cloud = Cloud(points, rng);
  std::printf("CPU: %s backend, %d threads; %d float32 points in voxel order, median of %d updates\n",
    vtkSMPTools::GetBackend(), vtkSMPTools::GetEstimatedNumberOfThreads(), points, repeats);
  std::printf("| basis | voxels | forward ms | forward M points/s | adjoint ms | adjoint M points/s | "
              "adjoint / forward |\n|---|---:|---:|---:|---:|---:|---:|\n");
  const std::pair<int, int> cases[] = { { vtkFFDBuildLattice::BERNSTEIN, 4 }, { vtkFFDBuildLattice::TRILINEAR, 32 },
    { vtkFFDBuildLattice::TRIQUADRATIC_BEZIER, 32 }, { vtkFFDBuildLattice::TRICUBIC_BEZIER, 32 },
    { vtkFFDBuildLattice::CUBIC_BSPLINE, 32 } };
  for (const auto& [basis, divisions] : cases)
  {
    vtkSmartPointer<vtkStructuredGrid> lattice = Lattice(cloud, basis, divisions, rng);
    vtkNew<vtkFFDDeform> deform;
    deform->SetBackendToCPU();
    deform->SetInputData(cloud);
    deform->SetLatticeData(lattice);
    deform->Update(); // binds
    const double forward = MedianSeconds(repeats,
      [&]
      {
        lattice->GetPoints()->Modified();
        deform->Update();
      });
    vtkNew<vtkFFDSensitivity> sensitivity;
    sensitivity->SetInputData(cloud);
    sensitivity->SetLatticeData(lattice);
    sensitivity->SetInputArrayToProcess(0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, "g");
    sensitivity->SetDeform(deform);
    sensitivity->Update();
    const double adjoint = MedianSeconds(repeats,
      [&]
      {
        cloud->GetPointData()->GetArray("g")->Modified();
        sensitivity->Update();
      });
    std::printf("| %s | %d^3 | %.1f | %.1f | %.1f | %.1f | %.2f |\n", vtkFFDBuildLattice::GetBasisAsString(basis),
      divisions, forward * 1e3, double(points) / forward * 1e-6, adjoint * 1e3, double(points) / adjoint * 1e-6,
      forward / adjoint);
  }
  return 0;
}
