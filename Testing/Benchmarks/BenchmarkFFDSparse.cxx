// SPDX-License-Identifier: BSD-3-Clause
/**
 * BenchmarkFFDSparse: how voxel grids and lattices scale with their divisions, sparse and dense. Not a test: it
 * prints tables and asserts nothing about time. Results and how to read them: BENCHMARKS.md.
 *
 * Each row runs in a process of its own (this program started again with --row), so that its peak resident
 * memory (/proc/self/status VmHWM, reset once the mesh is read) is its own: the mesh is read (and subdivided),
 * then vtkFFDVoxelize, vtkFFDBuildLattice in the sparse or the dense form and the first vtkFFDDeform update (the
 * binding and an evaluation), the peak being taken there; then re-updates of a copy of the lattice whose points move
 * (the median of several: the evaluation alone, of the points without their normals). Columns: active voxels, active
 * control points, the peak memory up to the binding and the part of it above the mesh's, the lattice's and the voxel
 * grid's bytes (GetActualMemorySize()) per active control point and per active voxel beyond their points (24 bytes
 * each), the times of voxelize, build, bind (the first update less a re-update) and re-update, and the re-update's
 * points per second.
 *
 * Usage: BenchmarkFFDSparse [--quick] [--table scaling|throughput|all] [--mesh-dir dir] [--backend cpu|auto]
 *   scaling     bear, armadillo subdivided twice (0.4 M points) and 4 times (6.7 M points); trilinear and cubic
 *               B-spline; divisions 64^3 to 1024^3; the dense form up to 256^3 (beyond, it needs GBs).
 *   throughput  re-update of the armadillo subdivided twice, sparse against dense, 16^3 to 64^3, every local basis.
 *   --quick     the bear only, up to 256^3: a smoke check (seconds).
 *   --backend   vtkFFDDeform's backend (default cpu; auto takes CUDA where a device is).
 * One row alone, as each table row runs it: BenchmarkFFDSparse --row mesh.vtp levels divisions basis sparse|dense
 * cpu|auto (basis as vtkFFDBuildLattice::Bases: 1 TRILINEAR, 4 CUBIC_BSPLINE); it prints "row" and the columns' raw
 * values: points, active voxels, active control points, peak MB, above mesh MB, B/point, B/voxel, voxelize s,
 * build s, bind s, re-update s, M points/s, backend.
 */

#include "vtkFFDBuildLattice.h"
#include "vtkFFDDeform.h"
#include "vtkFFDVoxelize.h"

#include "FFDBenchmarkMeshes.h"
#include "FFDBenchmarkUtilities.h"

#include "vtkDataSet.h"
#include "vtkNew.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSmartPointer.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

namespace
{
/// One row, measured in this process: the line the parent prints, or an error.
int RunRow(const std::string& meshPath, int levels, int divisions, int basis, bool sparse, int backend)
{
  const vtkSmartPointer<vtkPolyData> mesh = ShadedSubdividedMesh(meshPath, levels);
  if (mesh->GetNumberOfPoints() == 0)
  {
    std::printf("error: cannot read %s\n", meshPath.c_str());
    return 1;
  }
  const double meshMegabytes = ResidentMegabytes("VmRSS");
  ResetPeakResidentMemory();

  auto start = Clock::now();
  vtkNew<vtkFFDVoxelize> voxelize;
  voxelize->SetInputData(mesh);
  voxelize->SetDivisions(divisions, divisions, divisions);
  voxelize->Update();
  const double voxelizeSeconds = Seconds(start);

  start = Clock::now();
  vtkNew<vtkFFDBuildLattice> build;
  build->SetInputConnection(voxelize->GetOutputPort());
  build->SetBasis(basis);
  build->SetLatticeForm(sparse ? vtkFFDBuildLattice::SPARSE : vtkFFDBuildLattice::DENSE);
  build->Update();
  const double buildSeconds = Seconds(start);
  vtkPointSet* built = vtkPointSet::SafeDownCast(build->GetOutputDataObject(0));
  if (!built || built->GetNumberOfPoints() == 0)
  {
    std::printf("error: no lattice\n");
    return 1;
  }
  vtkNew<vtkFFDDeform> deform;
  deform->SetInputData(mesh);
  deform->SetLatticeConnection(build->GetOutputPort());
  deform->SetBackend(backend);
  deform->TransformNormalsOff(); // the points alone, as BenchmarkFFDDeform times them
  start = Clock::now();
  deform->Update();
  const double firstSeconds = Seconds(start);
  const double peakToBind = ResidentMegabytes("VmHWM");

  // The lattice a user moves: the built one's structure and arrays, its own points. Its rest state and cells
  // are the built one's, so the binding is kept.
  vtkSmartPointer<vtkPointSet> lattice = vtkSmartPointer<vtkPointSet>::Take(built->NewInstance());
  lattice->ShallowCopy(built);
  vtkNew<vtkPoints> moving;
  moving->SetDataType(built->GetPoints()->GetDataType()); // DeepCopy() keeps the receiver's type: double
  moving->DeepCopy(built->GetPoints());
  lattice->SetPoints(moving);
  deform->SetLatticeData(lattice);

  // Re-updates: every control point moved a little, the binding kept.
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> jitter(-1e-4, 1e-4);
  std::vector<double> updates;
  vtkPoints* points = lattice->GetPoints();
  for (int r = 0; r < 7; ++r)
  {
    for (vtkIdType p = 0; p < points->GetNumberOfPoints(); ++p)
    {
      double x[3];
      points->GetPoint(p, x);
      points->SetPoint(p, x[0] + jitter(rng), x[1] + jitter(rng), x[2] + jitter(rng));
    }
    points->Modified();
    start = Clock::now();
    deform->Update();
    updates.push_back(Seconds(start));
  }
  const double update = Median(updates);
  if (deform->GetNumberOfBindings() != 1 || deform->GetOutputDataObject(0)->GetMTime() < points->GetMTime())
  {
    std::printf("error: the binding was recomputed, or the update did not run\n");
    return 1;
  }
  const double activeVoxels = double(voxelize->GetNumberOfActiveVoxels());
  const double activePoints = double(build->GetNumberOfActiveControlPoints());
  // Beyond the points themselves (24 bytes each), as the goals count them.
  vtkDataSet* voxels = vtkDataSet::SafeDownCast(voxelize->GetOutputDataObject(0));
  const double voxelBytes = 1024.0 * double(voxels->GetActualMemorySize()) - 24.0 * double(voxels->GetNumberOfPoints());
  const double latticeBytes = 1024.0 * double(built->GetActualMemorySize()) - 24.0 * double(built->GetNumberOfPoints());
  std::printf("row %lld %.0f %.0f %.0f %.0f %.1f %.1f %.3f %.3f %.3f %.9f %.1f %s\n",
    static_cast<long long>(mesh->GetNumberOfPoints()), activeVoxels, activePoints, peakToBind,
    peakToBind - meshMegabytes, latticeBytes / std::max(activePoints, 1.0), voxelBytes / std::max(activeVoxels, 1.0),
    voxelizeSeconds, buildSeconds, std::max(0.0, firstSeconds - update), update,
    double(mesh->GetNumberOfPoints()) / update * 1e-6, deform->GetLastBackendUsed());
  return 0;
}

struct MeshChoice
{
  const char* Name;
  const char* File;
  int Levels;
};

/// Runs one row in a new process and prints it as a table line; `self` is this program's path. Returns the
/// re-update's seconds, or -1 where the row failed.
double Row(const std::string& self, const std::string& meshDir, const MeshChoice& mesh, int divisions, int basis,
  bool sparse, const std::string& backend)
{
  const std::string command = "'" + self + "' --row '" + meshDir + "/" + mesh.File + "' " +
    std::to_string(mesh.Levels) + " " + std::to_string(divisions) + " " + std::to_string(basis) + " " +
    (sparse ? "sparse" : "dense") + " " + backend + " 2>&1";
  std::string output;
  if (FILE* pipe = popen(command.c_str(), "r"))
  {
    char buffer[4096];
    while (std::fgets(buffer, sizeof(buffer), pipe))
    {
      output += buffer;
    }
    pclose(pipe);
  }
  long long points = 0;
  double activeVoxels, activePoints, peak, aboveMesh, perPoint, perVoxel, tv, tb, tbind, tu, rate;
  char ran[16] = "";
  const std::size_t at = output.find("row ");
  const char* basisName = vtkFFDBuildLattice::GetBasisAsString(basis);
  if (at == std::string::npos ||
    std::sscanf(output.c_str() + at, "row %lld %lf %lf %lf %lf %lf %lf %lf %lf %lf %lf %lf %15s", &points,
      &activeVoxels, &activePoints, &peak, &aboveMesh, &perPoint, &perVoxel, &tv, &tb, &tbind, &tu, &rate, ran) != 13)
  {
    std::string reason = output.substr(0, output.find('\n'));
    std::printf("| %s | %lld | %d^3 | %s | %s | failed: %s |\n", mesh.Name, points, divisions, basisName,
      sparse ? "sparse" : "dense", reason.c_str());
    std::fflush(stdout);
    return -1.0;
  }
  std::printf("| %s | %lld | %d^3 | %s | %s | %.0f | %.0f | %.0f | %.0f | %.1f | %.1f | %.3f | %.3f | %.3f | %.2f | "
              "%.1f | %s |\n",
    mesh.Name, points, divisions, basisName, sparse ? "sparse" : "dense", activeVoxels, activePoints, peak, aboveMesh,
    perPoint, perVoxel, tv, tb, tbind, 1e3 * tu, rate, ran);
  std::fflush(stdout);
  return tu;
}

void Header()
{
  std::printf("| mesh | points | divisions | basis | form | active voxels | active control points | peak MB to bind | "
              "above mesh MB | lattice B/point | voxel grid B/voxel | voxelize s | build s | bind s | re-update ms "
              "| M points/s | backend |\n");
  std::printf("|---|---:|---:|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|\n");
}
} // namespace

int main(int argc, char* argv[])
{
  if (argc == 8 && std::strcmp(argv[1], "--row") == 0)
  {
    const int backend = std::strcmp(argv[7], "auto") == 0 ? vtkFFDDeform::AUTOMATIC : vtkFFDDeform::CPU;
    return RunRow(argv[2], std::atoi(argv[3]), std::atoi(argv[4]), std::atoi(argv[5]),
      std::strcmp(argv[6], "sparse") == 0, backend);
  }
  bool quick = false;
  std::string table = "all", meshDir = VOXELFFD_MESH_DIR, backend = "cpu";
  int status = 0;
  if (!ParseArguments(argc, argv,
        { { "--quick", &quick }, { "--table", &table, "scaling|throughput|all" }, { "--mesh-dir", &meshDir },
          { "--backend", &backend, "cpu|auto" } },
        "[--quick] [--table scaling|throughput|all] [--mesh-dir dir] [--backend cpu|auto]", status))
  {
    return status;
  }
  const std::string self = argv[0];
  const MeshChoice bear = { "bear", "bear.vtp", 0 };
  const MeshChoice armadillo = { "armadillo x2", "armadillo.vtp", 2 };
  const MeshChoice large = { "armadillo x4", "armadillo.vtp", 4 };
  const int bases[] = { vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::CUBIC_BSPLINE };
  if (table == "scaling" || table == "all")
  {
    std::printf("\nScaling: memory and time against the divisions (each row a process of its own)\n\n");
    Header();
    std::vector<MeshChoice> meshes = { bear };
    if (!quick)
    {
      meshes.push_back(armadillo);
      meshes.push_back(large);
    }
    for (const MeshChoice& mesh : meshes)
    {
      for (int basis : bases)
      {
        for (int divisions : { 64, 128, 256, 512, 1024 })
        {
          if (quick && divisions > 256)
          {
            continue;
          }
          Row(self, meshDir, mesh, divisions, basis, true, backend);
          if (divisions <= 256)
          {
            Row(self, meshDir, mesh, divisions, basis, false, backend);
          }
        }
      }
    }
  }
  if (table == "throughput" || table == "all")
  {
    std::printf("\nRe-update throughput, sparse against dense\n\n");
    Header();
    const MeshChoice mesh = quick ? bear : armadillo;
    std::string ratios = "| basis | divisions | sparse / dense re-update time |\n|---|---:|---:|\n";
    for (int basis : { vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::TRIQUADRATIC_BEZIER,
           vtkFFDBuildLattice::TRICUBIC_BEZIER, vtkFFDBuildLattice::CUBIC_BSPLINE })
    {
      for (int divisions : { 16, 32, 64 })
      {
        const double dense = Row(self, meshDir, mesh, divisions, basis, false, backend);
        const double sparse = Row(self, meshDir, mesh, divisions, basis, true, backend);
        char line[128];
        std::snprintf(line, sizeof(line), "| %s | %d^3 | %.2f |\n", vtkFFDBuildLattice::GetBasisAsString(basis),
          divisions, dense > 0 && sparse > 0 ? sparse / dense : -1.0);
        ratios += line;
      }
    }
    std::printf("\n%s", ratios.c_str());
  }
  return 0;
}
