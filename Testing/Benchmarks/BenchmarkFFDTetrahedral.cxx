// SPDX-License-Identifier: BSD-3-Clause
// Benchmark of the tetrahedral FFD (issue 5): binding and evaluation throughput of vtkFFDDeform with
// tetrahedral lattices of about 100, 10 k and 100 k tetrahedra on a ~0.4 M-point mesh, next to the trilinear
// grid evaluation of the same mesh and to VTK's vtkDeformPointSet (mean value coordinates over a control
// mesh's surface) as the peer, all in one run. Prints tables; asserts nothing (not a test). BENCHMARKS.md says
// how to run it and records the results.
#include "FFDBenchmarkUtilities.h"
#include "FFDTestTetrahedra.h"

#include "vtkFFDBuildLattice.h"
#include "vtkFFDBuildTetrahedralLattice.h"
#include "vtkFFDDeform.h"
#include "vtkFFDVoxelize.h"

#include "vtkDataSetSurfaceFilter.h"
#include "vtkDeformPointSet.h"
#include "vtkLinearSubdivisionFilter.h"
#include "vtkPolyData.h"
#include "vtkSMPTools.h"
#include "vtkStructuredGrid.h"
#include "vtkXMLPolyDataReader.h"

#include <cstdio>
#include <random>
#include <string>
#include <vector>

namespace
{
/// Moves every point of a lattice by up to `amplitude`, a new random displacement each call.
void Move(vtkPointSet* lattice, vtkDataArray* rest, double amplitude, std::mt19937& rng)
{
  std::uniform_real_distribution<double> move(-amplitude, amplitude);
  vtkPoints* points = lattice->GetPoints();
  for (vtkIdType p = 0; p < points->GetNumberOfPoints(); ++p)
  {
    double x[3];
    rest->GetTuple(p, x);
    points->SetPoint(p, x[0] + move(rng), x[1] + move(rng), x[2] + move(rng));
  }
  points->Modified();
}

struct Row
{
  std::string Lattice;
  vtkIdType Tetrahedra = 0;
  int Threads = 0;
  double Bind = 0.0, Evaluate = 0.0;
};

/// Binding (the first Update() minus an evaluation) and evaluation (the median Update() after moving the
/// lattice) of vtkFFDDeform on the CPU.
Row Measure(const std::string& name, vtkPolyData* mesh, vtkPointSet* lattice, int threads, double amplitude)
{
  vtkSMPTools::Initialize(threads);
  vtkDataArray* rest = lattice->GetPointData()->GetArray("RestPosition");
  std::mt19937 rng(7);
  Row row{ name, lattice->GetNumberOfCells(), threads };
  vtkNew<vtkFFDDeform> deform;
  deform->SetInputData(mesh);
  deform->SetLatticeData(lattice);
  deform->SetBackendToCPU();
  deform->SetOutsidePolicyToClampToEdge();
  Move(lattice, rest, amplitude, rng);
  const Clock::time_point begin = Clock::now();
  deform->Update();
  const double first = Seconds(begin);
  const auto moveAndUpdate = [&]()
  {
    Move(lattice, rest, amplitude, rng);
    const Clock::time_point start = Clock::now();
    deform->Update();
    return Seconds(start);
  };
  row.Evaluate = Repeat(moveAndUpdate, 9).Median;
  row.Bind = first - row.Evaluate;
  if (deform->GetNumberOfBindings() != 1)
  {
    std::fprintf(stderr, "unexpected re-binding: %lld bindings\n", (long long)deform->GetNumberOfBindings());
  }
  return row;
}
} // namespace

int main(int argc, char* argv[])
{
  std::string meshPath = std::string(VOXELFFD_MESH_DIR) + "/armadillo.vtp";
  bool quick = false, noPeer = false;
  int status = 0;
  if (!ParseArguments(argc, argv, { { "--mesh", &meshPath }, { "--quick", &quick }, { "--no-peer", &noPeer } },
        "[--mesh file.vtp] [--quick] [--no-peer]", status))
  {
    return status;
  }
  const int levels = quick ? 0 : 2; // armadillo: 26 k points, 416 k after two subdivisions
  const bool peer = !noPeer;
  vtkNew<vtkXMLPolyDataReader> reader;
  reader->SetFileName(meshPath.c_str());
  vtkNew<vtkLinearSubdivisionFilter> subdivide;
  subdivide->SetInputConnection(reader->GetOutputPort());
  subdivide->SetNumberOfSubdivisions(levels);
  subdivide->Update();
  vtkNew<vtkPolyData> mesh;
  mesh->ShallowCopy(levels > 0 ? subdivide->GetOutput() : reader->GetOutput());
  const vtkIdType n = mesh->GetNumberOfPoints();
  if (n == 0)
  {
    std::fprintf(stderr, "cannot read %s\n", meshPath.c_str());
    return 1;
  }
  double bounds[6];
  mesh->GetBounds(bounds);
  const double diagonal = std::sqrt((bounds[1] - bounds[0]) * (bounds[1] - bounds[0]) +
    (bounds[3] - bounds[2]) * (bounds[3] - bounds[2]) + (bounds[5] - bounds[4]) * (bounds[5] - bounds[4]));
  const double amplitude = 0.02 * diagonal;
  double padded[6];
  for (int a = 0; a < 3; ++a)
  {
    const double pad = 0.05 * (bounds[2 * a + 1] - bounds[2 * a]);
    padded[2 * a] = bounds[2 * a] - pad;
    padded[2 * a + 1] = bounds[2 * a + 1] + pad;
  }
  std::printf("Mesh %s subdivided %d times: %lld points (%s)\n", meshPath.c_str(), levels, (long long)n,
    mesh->GetPoints()->GetDataType() == VTK_DOUBLE ? "float64" : "float32");
  std::printf("vtkSMPTools backend: %s; threads 1 and 2\n\n", vtkSMPTools::GetBackend());

  // The lattices: Kuhn triangulations of the padded bounding box (user-supplied lattices of controlled size)
  // and vtkFFDBuildTetrahedralLattice's hull + centroid with 0, 1 and 2 levels of subdivision.
  struct Lattice
  {
    std::string Name;
    vtkSmartPointer<vtkUnstructuredGrid> Grid;
    double BuildSeconds = 0.0;
  };
  std::vector<Lattice> lattices;
  for (const int cells : { 3, 12, 26 })
  {
    const Clock::time_point begin = Clock::now();
    auto grid = ffdtest::KuhnBoxLattice(cells, padded, 0.2);
    lattices.push_back({ "box " + std::to_string(cells) + "^3 x 6", grid, Seconds(begin) });
  }
  for (const int level : { 0, 1, 2 })
  {
    vtkNew<vtkFFDBuildTetrahedralLattice> build;
    build->SetInputData(mesh);
    build->SetSubdivisionLevels(level);
    const Clock::time_point begin = Clock::now();
    build->Update();
    auto grid = vtkSmartPointer<vtkUnstructuredGrid>::New();
    grid->DeepCopy(build->GetOutput());
    lattices.push_back({ "hull, level " + std::to_string(level), grid, Seconds(begin) });
  }

  // The trilinear grid evaluation of the same mesh, for the goal "within 2x of trilinear".
  vtkNew<vtkFFDVoxelize> voxelize;
  voxelize->SetInputData(mesh);
  voxelize->SetDivisions(10, 10, 10);
  vtkNew<vtkFFDBuildLattice> buildGrid;
  buildGrid->SetInputConnection(voxelize->GetOutputPort());
  buildGrid->SetBasisToTrilinear();
  buildGrid->SetLatticeFormToDense();
  buildGrid->Update();
  vtkNew<vtkStructuredGrid> grid;
  grid->DeepCopy(buildGrid->GetOutput());

  std::printf("Binding: the first Update() minus one evaluation; evaluation: median of 9 Update()s after moving\n"
              "every node (binding cached; outside policy CLAMP_TO_EDGE); Mpts/s = points / time.\n\n");
  std::printf("| lattice              | tetrahedra | build (s) | th | bind (s) | bind Mpts/s | eval (s) | eval Mpts/s |"
              " eval / trilinear |\n");
  std::printf("|----------------------|-----------:|----------:|---:|---------:|------------:|---------:|------------:|"
              "-----------------:|\n");
  for (const int threads : { 1, 2 })
  {
    const Row trilinear = Measure("trilinear 10^3", mesh, grid, threads, amplitude);
    std::printf("| %-20s | %10s | %9s | %2d | %8.4f | %11.2f | %8.4f | %11.2f | %16s |\n", "grid TRILINEAR 10^3", "-",
      "-", threads, trilinear.Bind, n / trilinear.Bind * 1e-6, trilinear.Evaluate, n / trilinear.Evaluate * 1e-6,
      "1.00");
    for (const Lattice& lattice : lattices)
    {
      const Row row = Measure(lattice.Name, mesh, lattice.Grid, threads, amplitude);
      std::printf("| %-20s | %10lld | %9.3f | %2d | %8.4f | %11.2f | %8.4f | %11.2f | %16.2f |\n", lattice.Name.c_str(),
        (long long)row.Tetrahedra, lattice.BuildSeconds, threads, row.Bind, n / row.Bind * 1e-6, row.Evaluate,
        n / row.Evaluate * 1e-6, row.Evaluate / trilinear.Evaluate);
    }
  }

  if (peer)
  {
    // VTK's vtkDeformPointSet: mean value coordinates of every point over a closed control mesh (the surface
    // of our control mesh), computed once (its "binding"), then a weighted sum per update. Its cost grows with
    // points x control-mesh triangles, so only the smaller control meshes are timed.
    std::printf("\nPeer: VTK's vtkDeformPointSet with the surface of the same control mesh (its nodes moved the same\n"
                "way), %d threads (it is serial where it is not SMP):\n\n",
      vtkSMPTools::GetEstimatedNumberOfThreads());
    std::printf(
      "| control mesh         | triangles | init (s) | init Mpts/s | eval (s) | eval Mpts/s | ours eval (s) |\n");
    std::printf(
      "|----------------------|----------:|---------:|------------:|---------:|------------:|--------------:|\n");
    vtkSMPTools::Initialize(0);
    for (const Lattice& lattice : lattices)
    {
      vtkNew<vtkDataSetSurfaceFilter> surface;
      surface->SetInputData(lattice.Grid);
      surface->Update();
      vtkPolyData* control = surface->GetOutput();
      if (control->GetNumberOfCells() > 3000)
      {
        continue;
      }
      vtkNew<vtkPolyData> moving;
      moving->DeepCopy(control);
      vtkNew<vtkDeformPointSet> deform;
      deform->SetInputData(mesh);
      deform->SetControlMeshData(moving);
      std::mt19937 rng(7);
      Move(moving, control->GetPointData()->GetArray("RestPosition"), amplitude, rng);
      const Clock::time_point begin = Clock::now();
      deform->Update();
      const double first = Seconds(begin);
      const auto moveAndUpdate = [&]()
      {
        Move(moving, control->GetPointData()->GetArray("RestPosition"), amplitude, rng);
        moving->Modified();
        const Clock::time_point start = Clock::now();
        deform->Update();
        return Seconds(start);
      };
      const double evaluate = Repeat(moveAndUpdate, 5).Median;
      const Row ours = Measure(lattice.Name, mesh, lattice.Grid, vtkSMPTools::GetEstimatedNumberOfThreads(), amplitude);
      std::printf("| %-20s | %9lld | %8.3f | %11.3f | %8.4f | %11.2f | %13.4f |\n", lattice.Name.c_str(),
        (long long)control->GetNumberOfCells(), first - evaluate, n / (first - evaluate) * 1e-6, evaluate,
        n / evaluate * 1e-6, ours.Evaluate);
    }
  }
  return 0;
}
