// SPDX-License-Identifier: BSD-3-Clause
/**
 * BenchmarkFFDLevelOfDetail: the time of exact refinement (vtkFFDRefineLattice, n -> 2n) and of coarsening by least
 * squares over a mesh's points (vtkFFDCoarsenLattice, n -> n/2) for lattices of 10^3 to 100^3 divisions over the
 * armadillo. Not a test: it prints a table and asserts nothing about time. Results: BENCHMARKS.md.
 *
 * Each row: a lattice of the basis and form over the mesh, its active control points moved at random (2% of the
 * diagonal); the refinement's time (the median of 3 runs, 1 beyond 10 s) and the refined lattice's control points;
 * the coarsening's time (the same) and the coarse lattice's control points, and the largest distance between the
 * two lattices' deformations over the mesh's points, over the mesh's diagonal (the detail a coarser lattice cannot
 * hold).
 *
 * Usage: BenchmarkFFDLevelOfDetail [--quick] [--mesh name] [--mesh-dir dir]
 *   --quick   the bear and 10^3, 20^3 only: a smoke check (seconds).
 */

#include "vtkFFDBuildLattice.h"
#include "vtkFFDCoarsenLattice.h"
#include "vtkFFDRefineLattice.h"
#include "vtkFFDVoxelize.h"

#include "FFDBenchmarkUtilities.h"

#include "vtkDataArray.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSmartPointer.h"
#include "vtkXMLPolyDataReader.h"

#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

namespace
{
vtkSmartPointer<vtkPointSet> MovedLattice(vtkPolyData* mesh, int basis, int n, int form, double amplitude)
{
  vtkNew<vtkFFDVoxelize> voxelize;
  voxelize->SetInputData(mesh);
  voxelize->SetDivisions(n, n, n);
  vtkNew<vtkFFDBuildLattice> build;
  build->SetInputConnection(voxelize->GetOutputPort());
  build->SetBasis(basis);
  build->SetLatticeForm(form);
  build->Update();
  vtkSmartPointer<vtkPointSet> lattice = vtkSmartPointer<vtkPointSet>::Take(build->GetOutput()->NewInstance());
  lattice->DeepCopy(build->GetOutput());
  std::mt19937 rng(n);
  std::uniform_real_distribution<double> move(-amplitude, amplitude);
  vtkDataArray* active = lattice->GetPointData()->GetArray("Active");
  for (vtkIdType p = 0; p < lattice->GetNumberOfPoints(); ++p)
  {
    if (active->GetComponent(p, 0) != 0)
    {
      double x[3];
      lattice->GetPoint(p, x);
      lattice->GetPoints()->SetPoint(p, x[0] + move(rng), x[1] + move(rng), x[2] + move(rng));
    }
  }
  return lattice;
}
} // namespace

int main(int argc, char* argv[])
{
  bool quick = false;
  std::string meshName, meshDir = VOXELFFD_MESH_DIR;
  int status = 0;
  if (!ParseArguments(argc, argv, { { "--quick", &quick }, { "--mesh", &meshName }, { "--mesh-dir", &meshDir } },
        "[--quick] [--mesh name] [--mesh-dir dir]", status))
  {
    return status;
  }
  if (meshName.empty())
  {
    meshName = quick ? "bear" : "armadillo";
  }
  vtkNew<vtkXMLPolyDataReader> reader;
  reader->SetFileName((meshDir + "/" + meshName + ".vtp").c_str());
  reader->Update();
  vtkPolyData* mesh = reader->GetOutput();
  if (mesh->GetNumberOfPoints() == 0)
  {
    std::fprintf(stderr, "cannot read %s/%s.vtp (run Utilities/setup.sh)\n", meshDir.c_str(), meshName.c_str());
    return 1;
  }
  double bounds[6];
  mesh->GetBounds(bounds);
  const double diagonal = std::hypot(bounds[1] - bounds[0], bounds[3] - bounds[2], bounds[5] - bounds[4]);
  std::printf("%s: %lld points\n\n", meshName.c_str(), static_cast<long long>(mesh->GetNumberOfPoints()));
  std::printf("| basis | form | n | control points | refine n->2n (ms) | refined points | coarsen n->n/2 (ms) | "
              "coarse points | max residual / diagonal |\n|---|---|---|---|---|---|---|---|---|\n");

  const std::vector<int> sizes = quick ? std::vector<int>{ 10, 20 } : std::vector<int>{ 10, 20, 50, 100 };
  for (int basis : { vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::CUBIC_BSPLINE })
  {
    for (int form : { vtkFFDBuildLattice::SPARSE, vtkFFDBuildLattice::DENSE })
    {
      for (int n : sizes)
      {
        if (form == vtkFFDBuildLattice::DENSE && n > 50)
        {
          continue; // a dense 200^3 refinement holds 8 M control points: the sparse form is the one for that
        }
        vtkSmartPointer<vtkPointSet> lattice = MovedLattice(mesh, basis, n, form, 0.02 * diagonal);
        vtkNew<vtkFFDRefineLattice> refine;
        refine->SetInputData(lattice);
        const double refineSeconds = MedianSeconds(
          3,
          [&]
          {
            refine->Modified();
            refine->Update();
          },
          10.0);
        vtkNew<vtkFFDCoarsenLattice> coarsen;
        coarsen->SetInputData(lattice);
        coarsen->SetMeshData(mesh);
        const double coarsenSeconds = MedianSeconds(
          3,
          [&]
          {
            coarsen->Modified();
            coarsen->Update();
          },
          10.0);
        std::printf("| %s | %s | %d^3 | %lld | %.1f | %lld | %.0f | %lld | %.2e |\n",
          vtkFFDBuildLattice::GetBasisAsString(basis), form == vtkFFDBuildLattice::SPARSE ? "sparse" : "dense", n,
          static_cast<long long>(lattice->GetNumberOfPoints()), 1e3 * refineSeconds,
          static_cast<long long>(refine->GetOutput()->GetNumberOfPoints()), 1e3 * coarsenSeconds,
          static_cast<long long>(coarsen->GetOutput()->GetNumberOfPoints()), coarsen->GetMaximumResidual() / diagonal);
        std::fflush(stdout);
      }
    }
  }
  return 0;
}
