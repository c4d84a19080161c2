// SPDX-License-Identifier: BSD-3-Clause
/**
 * BenchmarkFFDFoldCertificate: vtkFFDFoldCertificate over every voxel of an N^3 cubic B-spline lattice (issue 33's
 * goal: 1 M active cells decided in under 1 s on 2 CPU threads). Not a test: it prints a table and asserts nothing
 * about time. Results: BENCHMARKS.md.
 *
 * The lattice: the unit box split into N^3 voxels, one point at each voxel's centre, so that every voxel is active;
 * vtkFFDBuildLattice's CUBIC_BSPLINE lattice, sparse and dense. Its points are moved by a mild deformation: a
 * smooth bend of 0.3 control-point spacings plus a random move of up to `--noise` spacings per component (default
 * 0.1, fixed seed). Each row times a new filter's first update (reading and checking the lattice, deciding every
 * voxel, the cell array), then the median of 3 re-updates after the lattice's points were marked modified (what
 * a drag does: the filter keeps what it read of the rest state), on 1 and 2 threads, at MaxSubdivisionDepth 3.
 *
 * A second table times vtkFFDMeshInversion on a tetrahedral volume mesh (the Kuhn triangulation of a box, 6 M^3
 * tetrahedra, M = 55: 1.0 M tetrahedra) deformed by the same kind of lattice, against vtkMeshQuality's
 * TetScaledJacobian over the same cells (it gives the scaled Jacobian only, not the comparison with the rest mesh).
 *
 * Usage: BenchmarkFFDFoldCertificate [--quick] [--divisions N] [--noise PERCENT]
 *   --quick      N = 30 (27,000 voxels), M = 15: a check of the program (a second).
 *   --divisions  N (default 100: 1 M voxels).
 *   --noise      the random move in % of a spacing (default 10).
 */

#include "vtkFFDBuildLattice.h"
#include "vtkFFDDeform.h"
#include "vtkFFDFoldCertificate.h"
#include "vtkFFDMeshInversion.h"
#include "vtkFFDVoxelize.h"

#include "FFDBenchmarkUtilities.h"
#include "FFDTestTetrahedra.h"

#include "vtkCellData.h"
#include "vtkDataArray.h"
#include "vtkFFDDataContract.h"
#include "vtkMeshQuality.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSMPTools.h"
#include "vtkSmartPointer.h"
#include "vtkUnstructuredGrid.h"

#include <cmath>
#include <cstdio>
#include <random>

namespace
{
/// The moved CUBIC_BSPLINE lattice over the unit box split in n^3 voxels, every voxel active, in `form`.
vtkSmartPointer<vtkPointSet> MovedLattice(int n, int form, double noise)
{
  vtkNew<vtkPoints> centres;
  centres->SetDataTypeToDouble();
  centres->SetNumberOfPoints(vtkIdType(n) * n * n);
  for (int k = 0, p = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i, ++p)
      {
        centres->SetPoint(p, (i + 0.5) / n, (j + 0.5) / n, (k + 0.5) / n);
      }
  vtkNew<vtkPolyData> cloud;
  cloud->SetPoints(centres);
  vtkNew<vtkFFDVoxelize> voxelize;
  voxelize->SetInputData(cloud);
  const double origin[3] = { 0, 0, 0 }, s[3] = { 1, 0, 0 }, t[3] = { 0, 1, 0 }, u[3] = { 0, 0, 1 };
  voxelize->SetFrame(origin, s, t, u);
  voxelize->SetDivisions(n, n, n);
  vtkNew<vtkFFDBuildLattice> build;
  build->SetInputConnection(voxelize->GetOutputPort());
  build->SetBasisToCubicBSpline();
  build->SetLatticeForm(form);
  build->Update();
  auto lattice = vtkSmartPointer<vtkPointSet>::Take(build->GetOutput()->NewInstance());
  lattice->DeepCopy(build->GetOutput());
  const double h = 1.0 / n; // the control-point spacing
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> move(-noise * h, noise * h);
  vtkDataArray* rest = lattice->GetPointData()->GetArray(vtkFFDDataContract::RestPositionArrayName());
  for (vtkIdType p = 0; p < lattice->GetNumberOfPoints(); ++p)
  {
    double x[3];
    rest->GetTuple(p, x);
    const double bend = 0.3 * h * std::sin(6.283 * (x[0] + 2 * x[1] + 3 * x[2]));
    lattice->GetPoints()->SetPoint(p, x[0] + bend + move(rng), x[1] + move(rng), x[2] - bend + move(rng));
  }
  return lattice;
}

/// vtkFFDMeshInversion against vtkMeshQuality on 6 m^3 tetrahedra deformed by a 10^3 cubic B-spline lattice.
void MeshInversionTable(int m)
{
  const double bounds[6] = { 0, 1, 0, 1, 0, 1 };
  vtkSmartPointer<vtkUnstructuredGrid> mesh = ffdtest::KuhnBoxLattice(m, bounds, 0.2);
  mesh->GetPointData()->Initialize(); // a mesh, not a lattice: no RestPosition
  vtkNew<vtkFFDDeform> deform;
  deform->SetInputData(mesh);
  deform->SetLatticeData(MovedLattice(10, vtkFFDBuildLattice::DENSE, 0.3));
  deform->Update();
  std::printf("\nvtkFFDMeshInversion, %lld tetrahedra deformed by a 10^3 cubic B-spline lattice; median of 3\n\n",
    static_cast<long long>(mesh->GetNumberOfCells()));
  std::printf("| threads | inverted | min scaled Jacobian | vtkFFDMeshInversion s | vtkMeshQuality s |\n");
  std::printf("|---:|---:|---:|---:|---:|\n");
  for (int threads : { 1, 2 })
  {
    vtkSMPTools::Initialize(threads);
    vtkNew<vtkFFDMeshInversion> inversion;
    inversion->SetInputConnection(deform->GetOutputPort());
    inversion->SetRestMeshData(mesh);
    const double ours = MedianSeconds(3,
      [&]
      {
        inversion->Modified();
        inversion->Update();
      });
    vtkNew<vtkMeshQuality> quality;
    quality->SetInputConnection(deform->GetOutputPort());
    quality->SetTetQualityMeasureToScaledJacobian();
    const double theirs = MedianSeconds(3,
      [&]
      {
        quality->Modified();
        quality->Update();
      });
    std::printf("| %d | %lld | %.4f | %.3f | %.3f |\n", threads,
      static_cast<long long>(inversion->GetNumberOfInvertedCells()), inversion->GetMinimumScaledJacobian(), ours,
      theirs);
  }
}
} // namespace

int main(int argc, char* argv[])
{
  bool quick = false;
  int divisions = 100, noisePercent = 10, status = 0;
  if (!ParseArguments(argc, argv,
        { { "--quick", &quick }, { "--divisions", &divisions }, { "--noise", &noisePercent } },
        "[--quick] [--divisions N] [--noise PERCENT]", status))
  {
    return status;
  }
  divisions = quick ? 30 : divisions;
  std::printf(
    "CUBIC_BSPLINE, %d^3 voxels (all active), noise %d %% of a spacing, depth 3\n\n", divisions, noisePercent);
  std::printf("| form | threads | voxels | certified | folded | undecided | first update s | M voxels/s | "
              "re-update s |\n");
  std::printf("|---|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  for (int form : { vtkFFDBuildLattice::SPARSE, vtkFFDBuildLattice::DENSE })
  {
    const vtkSmartPointer<vtkPointSet> lattice = MovedLattice(divisions, form, noisePercent / 100.0);
    for (int threads : { 1, 2 })
    {
      vtkSMPTools::Initialize(threads);
      vtkNew<vtkFFDFoldCertificate> certificate;
      certificate->SetInputData(lattice);
      // A new filter reads and checks the whole lattice; then only its points move (as a drag moves them), and
      // the filter keeps what it read of the rest (median of 3).
      const Clock::time_point start = Clock::now();
      certificate->Update();
      const double first = Seconds(start);
      const double again = MedianSeconds(3,
        [&]
        {
          lattice->GetPoints()->Modified();
          certificate->Update();
        });
      const vtkIdType voxels = certificate->GetNumberOfCertifiedCells() + certificate->GetNumberOfFoldedCells() +
        certificate->GetNumberOfUndecidedCells();
      std::printf("| %s | %d | %lld | %lld | %lld | %lld | %.3f | %.2f | %.3f |\n",
        form == vtkFFDBuildLattice::SPARSE ? "sparse" : "dense", threads, static_cast<long long>(voxels),
        static_cast<long long>(certificate->GetNumberOfCertifiedCells()),
        static_cast<long long>(certificate->GetNumberOfFoldedCells()),
        static_cast<long long>(certificate->GetNumberOfUndecidedCells()), first, voxels / first * 1e-6, again);
    }
  }
  MeshInversionTable(quick ? 15 : 55);
  return 0;
}
