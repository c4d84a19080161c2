// SPDX-License-Identifier: BSD-3-Clause
// vtkFFDLatticeDynamics: the time of a step against the number of simulated control points, and the frame of
// the paper's sizes: a step plus the deformation of the armadillo subdivided twice (416,002 points) on the
// threads vtkSMPTools has (issue 18's 60 Hz goal: 16 ms on 2 cores). Prints tables (BENCHMARKS.md); asserts
// nothing.

#include "FFDBenchmarkMeshes.h"
#include "FFDBenchmarkUtilities.h"

#include "vtkFFDBuildLattice.h"
#include "vtkFFDDeform.h"
#include "vtkFFDLatticeDynamics.h"
#include "vtkFFDMagneticSphere.h"
#include "vtkFFDVoxelize.h"
#include "vtkSMPTools.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace
{
/// The mesh's sparse lattice of `basis` over `divisions` voxels per axis.
vtkSmartPointer<vtkPointSet> Lattice(vtkPolyData* mesh, int divisions, int basis)
{
  vtkNew<vtkFFDVoxelize> voxelize;
  voxelize->SetInputData(mesh);
  voxelize->SetDivisions(divisions, divisions, divisions);
  vtkNew<vtkFFDBuildLattice> build;
  build->SetInputConnection(voxelize->GetOutputPort());
  build->SetBasis(basis);
  build->SetLatticeFormToSparse();
  build->Update();
  vtkSmartPointer<vtkPointSet> lattice;
  lattice.TakeReference(vtkPointSet::SafeDownCast(build->GetOutput()->NewInstance()));
  lattice->DeepCopy(build->GetOutput());
  return lattice;
}

/// A magnetic sphere beside the lattice, circling it once a second, so that every step moves the body.
void AddOrbitingSphere(vtkFFDLatticeDynamics* dynamics, vtkPointSet* lattice)
{
  double b[6];
  lattice->GetBounds(b);
  const double size = std::max({ b[1] - b[0], b[3] - b[2], b[5] - b[4] });
  vtkNew<vtkPoints> path;
  for (int i = 0; i < 16; ++i)
  {
    const double angle = 2 * 3.141592653589793 * i / 16;
    path->InsertNextPoint(0.5 * (b[0] + b[1]) + 0.6 * size * std::cos(angle),
      0.5 * (b[2] + b[3]) + 0.6 * size * std::sin(angle), 0.5 * (b[4] + b[5]));
  }
  vtkNew<vtkFFDMagneticSphere> sphere;
  sphere->SetPath(path);
  sphere->SetPeriod(1.0);
  sphere->SetRadius(0.15 * size);
  sphere->SetStrength(20.0);
  dynamics->AddMagneticSphere(sphere);
}

/// Time a step: the first (which factors the matrix) and the median of the next `steps`.
void TimeSteps(vtkFFDLatticeDynamics* dynamics, int steps, double& first, double& median)
{
  auto start = Clock::now();
  dynamics->Step();
  first = Seconds(start);
  std::vector<double> times;
  for (int s = 0; s < steps; ++s)
  {
    start = Clock::now();
    dynamics->Step();
    times.push_back(Seconds(start));
  }
  median = Median(times);
}
} // namespace

int main(int argc, char* argv[])
{
  bool quick = false;
  std::string meshDir = VOXELFFD_MESH_DIR;
  int status = 0;
  if (!ParseArguments(
        argc, argv, { { "--quick", &quick }, { "--mesh-dir", &meshDir } }, "[--quick] [--mesh-dir dir]", status))
  {
    return status;
  }
  const vtkSmartPointer<vtkPolyData> armadillo = ShadedSubdividedMesh(meshDir + "/armadillo.vtp", 0);
  if (armadillo->GetNumberOfPoints() == 0)
  {
    std::printf("cannot read %s/armadillo.vtp: run Utilities/setup.sh, which fetches the meshes\n", meshDir.c_str());
    return 1;
  }
  std::printf("vtkSMPTools backend %s, %d threads; default settings (10 iterations a step, springs to all 26 "
              "neighbours, core on)\n",
    vtkSMPTools::GetBackend(), vtkSMPTools::GetEstimatedNumberOfThreads());

  std::printf("\nStep time against simulated control points (armadillo, sparse trilinear lattices)\n\n");
  std::printf("| divisions | simulated points | springs | initialize s | first step s (factors) | step ms | "
              "us per point |\n|---:|---:|---:|---:|---:|---:|---:|\n");
  std::vector<int> divisionsList = { 3, 6, 12, 24, 48, 96, 175 };
  if (quick)
  {
    divisionsList = { 3, 6, 12 };
  }
  for (const int divisions : divisionsList)
  {
    const vtkSmartPointer<vtkPointSet> lattice = Lattice(armadillo, divisions, vtkFFDBuildLattice::TRILINEAR);
    vtkNew<vtkFFDLatticeDynamics> dynamics;
    dynamics->SetLattice(lattice);
    dynamics->SetMesh(armadillo);
    AddOrbitingSphere(dynamics, lattice);
    auto start = Clock::now();
    if (!dynamics->Initialize())
    {
      return 1;
    }
    const double initialize = Seconds(start);
    double first = 0, step = 0;
    const vtkIdType points = dynamics->GetNumberOfSimulatedPoints();
    TimeSteps(dynamics, points > 50000 ? 5 : 30, first, step);
    std::printf("| %d | %lld | %lld | %.3f | %.3f | %.2f | %.2f |\n", divisions, static_cast<long long>(points),
      static_cast<long long>(dynamics->GetNumberOfSprings()), initialize, first, 1e3 * step,
      1e6 * step / double(points));
    std::fflush(stdout);
  }

  std::printf("\nA 60 Hz frame: a step, then the armadillo deformed (positions; vtkFFDDeform on the CPU)\n\n");
  const vtkSmartPointer<vtkPolyData> mesh = quick ? armadillo : ShadedSubdividedMesh(meshDir + "/armadillo.vtp", 2);
  std::printf("| mesh points | basis | divisions | simulated points | step ms | deform ms | frame ms | fits 16 ms |\n"
              "|---:|---|---:|---:|---:|---:|---:|---|\n");
  for (const int basis : { vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::CUBIC_BSPLINE })
  {
    for (const int divisions :
      basis == vtkFFDBuildLattice::TRILINEAR ? std::vector<int>{ 5, 10, 16, 20 } : std::vector<int>{ 5, 10, 13 })
    {
      const vtkSmartPointer<vtkPointSet> lattice = Lattice(mesh, divisions, basis);
      vtkNew<vtkFFDLatticeDynamics> dynamics;
      dynamics->SetLattice(lattice);
      dynamics->SetMesh(mesh);
      AddOrbitingSphere(dynamics, lattice);
      vtkNew<vtkFFDDeform> deform;
      deform->SetInputData(mesh);
      deform->SetLatticeData(lattice);
      deform->SetBackendToCPU();
      deform->TransformNormalsOff();
      dynamics->Step(); // factors
      deform->Update(); // binds
      std::vector<double> steps, deforms;
      for (int frame = 0; frame < 60; ++frame)
      {
        auto start = Clock::now();
        dynamics->Step();
        steps.push_back(Seconds(start));
        start = Clock::now();
        deform->Update();
        deforms.push_back(Seconds(start));
      }
      const double step = Median(steps), evaluate = Median(deforms);
      std::printf("| %lld | %s | %d | %lld | %.2f | %.2f | %.2f | %s |\n",
        static_cast<long long>(mesh->GetNumberOfPoints()), vtkFFDBuildLattice::GetBasisAsString(basis), divisions,
        static_cast<long long>(dynamics->GetNumberOfSimulatedPoints()), 1e3 * step, 1e3 * evaluate,
        1e3 * (step + evaluate), step + evaluate <= 1.0 / 60.0 ? "yes" : "no");
      std::fflush(stdout);
    }
  }
  return 0;
}
