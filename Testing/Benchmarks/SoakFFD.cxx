// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file SoakFFD.cxx
 * @brief Many updates with the lattice moving: resident memory must stay flat (not a test: it prints a table).
 *
 * The armadillo of the test data subdivided twice (vtkLinearSubdivisionFilter, ~0.42 M points, with point
 * normals), deformed through each grid basis (10 x 10 x 10 voxels; the global one 3 x 3 x 3) and a tetrahedral
 * lattice (its hull subdivided once), with normals and the Jacobian's determinant. Every update moves the
 * lattice as the widget's drag does (vtkFFDLatticeRepresentation::MoveSelectedControlPoints on a selected
 * control point, back and forth), and every 10th moves all of its points a little, as a script would; a view
 * of each output's points is held until the next update, as a numpy user holds one. The resident set size
 * (/proc/self/status VmRSS) is read after update 1,000 and after the last: the table gives both and their
 * difference. Results: BENCHMARKS.md.
 *
 * Usage: SoakFFD [--mesh FILE.vtp] [--updates N]   (default 10000)
 */
#include "FFDBenchmarkMeshes.h"
#include "FFDBenchmarkUtilities.h"
#include "vtkFFDBuildLattice.h"
#include "vtkFFDBuildTetrahedralLattice.h"
#include "vtkFFDDeform.h"
#include "vtkFFDLatticeRepresentation.h"
#include "vtkFFDVoxelize.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSMPTools.h"
#include "vtkSmartPointer.h"
#include "vtkStructuredGrid.h"
#include "vtkUnstructuredGrid.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>

namespace
{
/// A lattice to deform: built over the mesh by `build` (a vtkFFDBuildLattice or vtkFFDBuildTetrahedralLattice).
template <typename Lattice>
vtkSmartPointer<Lattice> CopyOf(vtkAlgorithm* build)
{
  build->Update();
  auto lattice = vtkSmartPointer<Lattice>::New();
  lattice->DeepCopy(build->GetOutputDataObject(0));
  return lattice;
}
}

int main(int argc, char* argv[])
{
  std::string meshPath = std::string(VOXELFFD_MESH_DIR) + "/armadillo.vtp";
  int updates = 10000;
  int status = 0;
  if (!ParseArguments(
        argc, argv, { { "--mesh", &meshPath }, { "--updates", &updates } }, "[--mesh FILE.vtp] [--updates N]", status))
  {
    return status;
  }
  updates = std::max(1001, updates);
  const vtkSmartPointer<vtkPolyData> mesh = ShadedSubdividedMesh(meshPath, 2);
  if (mesh->GetNumberOfPoints() == 0)
  {
    std::fprintf(stderr, "%s: no points (run Utilities/setup.sh to fetch the meshes)\n", meshPath.c_str());
    return EXIT_FAILURE;
  }
  std::printf("mesh: %s subdivided twice: %lld points, normals; %d threads (%s); %d updates a lattice\n\n",
    meshPath.c_str(), static_cast<long long>(mesh->GetNumberOfPoints()), vtkSMPTools::GetEstimatedNumberOfThreads(),
    vtkSMPTools::GetBackend(), updates);
  std::printf("| lattice | control points | bindings | ms an update | RSS after 1,000 (MB) | RSS after %d (MB) | "
              "change |\n|---|---|---|---|---|---|---|\n",
    updates);

  const int grids[] = { vtkFFDBuildLattice::BERNSTEIN, vtkFFDBuildLattice::TRILINEAR,
    vtkFFDBuildLattice::TRIQUADRATIC_BEZIER, vtkFFDBuildLattice::TRICUBIC_BEZIER, vtkFFDBuildLattice::CUBIC_BSPLINE };
  std::mt19937 rng(20261124);
  for (int row = 0; row <= 5; ++row)
  {
    vtkSmartPointer<vtkPointSet> lattice;
    std::string name;
    if (row < 5)
    {
      vtkNew<vtkFFDVoxelize> voxelize;
      voxelize->SetInputData(mesh);
      const int n = grids[row] == vtkFFDBuildLattice::BERNSTEIN ? 3 : 10;
      voxelize->SetDivisions(n, n, n);
      vtkNew<vtkFFDBuildLattice> build;
      build->SetInputConnection(voxelize->GetOutputPort());
      build->SetBasis(grids[row]);
      build->SetLatticeFormToDense();
      lattice = CopyOf<vtkStructuredGrid>(build);
      name = vtkFFDBuildLattice::GetBasisAsString(grids[row]);
    }
    else
    {
      vtkNew<vtkFFDBuildTetrahedralLattice> build;
      build->SetInputData(mesh);
      build->SetSubdivisionLevels(1);
      lattice = CopyOf<vtkUnstructuredGrid>(build);
      name = "tetrahedral (level 1)";
    }
    vtkNew<vtkFFDDeform> deform;
    deform->SetInputData(mesh);
    deform->SetLatticeData(lattice);
    deform->ComputeJacobianDeterminantOn();
    vtkNew<vtkFFDLatticeRepresentation> representation;
    representation->SetLattice(lattice);
    vtkDataArray* active = lattice->GetPointData()->GetArray("Active");
    for (vtkIdType id = lattice->GetNumberOfPoints() / 2; id < lattice->GetNumberOfPoints(); ++id)
    {
      if (active->GetComponent(id, 0) != 0.0 && representation->SelectControlPoint(id))
      {
        break;
      }
    }
    const double step = 0.002 * lattice->GetLength();
    std::normal_distribution<double> jitter(0.0, 0.0002 * lattice->GetLength());
    vtkSmartPointer<vtkDataArray> view; // the caller's view of the last output's points
    double at1000 = 0.0;
    const Clock::time_point start = Clock::now();
    for (int u = 1; u <= updates; ++u)
    {
      const double sign = (u % 2) ? 1.0 : -1.0;
      const double delta[3] = { sign * step, -0.5 * sign * step, 0.25 * sign * step };
      representation->MoveSelectedControlPoints(delta);
      if (u % 10 == 0)
      {
        vtkPoints* points = lattice->GetPoints();
        for (vtkIdType id = 0; id < points->GetNumberOfPoints(); ++id)
        {
          double x[3];
          points->GetPoint(id, x);
          points->SetPoint(id, x[0] + jitter(rng), x[1] + jitter(rng), x[2] + jitter(rng));
        }
        points->Modified();
      }
      deform->Update();
      view = deform->GetOutput()->GetPoints()->GetData();
      if (u == 1000)
      {
        at1000 = ResidentMegabytes("VmRSS");
      }
    }
    const double seconds = Seconds(start);
    const double atEnd = ResidentMegabytes("VmRSS");
    std::printf("| %s | %lld | %lld | %.2f | %.1f | %.1f | %+.2f %% |\n", name.c_str(),
      static_cast<long long>(lattice->GetNumberOfPoints()), static_cast<long long>(deform->GetNumberOfBindings()),
      1000.0 * seconds / updates, at1000, atEnd, 100.0 * (atEnd - at1000) / at1000);
    std::fflush(stdout);
  }
  return EXIT_SUCCESS;
}
