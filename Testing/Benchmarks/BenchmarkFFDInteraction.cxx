// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file BenchmarkFFDInteraction.cxx
 * @brief Time from a control-point move to the re-rendered frame, split into pipeline and render.
 *
 * What a user of vtkFFDLatticeWidget waits for on every mouse move: the armadillo of the test data subdivided
 * twice (vtkLinearSubdivisionFilter, ~0.42 M points, with point normals as a shaded mesh has them) in a local
 * lattice over 10 x 10 x 10 voxels, drawn in an offscreen 800 x 800 window with the widget's representation.
 * After a first render (which binds the points), each of the timed moves
 *   1. moves one selected active control point through vtkFFDLatticeRepresentation::MoveSelectedControlPoints
 *      (what a drag does),
 *   2. "pipeline": vtkFFDDeform::Update() (the evaluation with the cached binding, normals included),
 *   3. "render": vtkRenderWindow::Render() and WaitForCompletion() (the mapper uploads the new points and
 *      normals, the lattice actor follows, the frame is drawn: llvmpipe under Xvfb here).
 * It prints a table of medians (and the fastest and slowest move) per basis, with the median time of rendering
 * the same frame again unchanged (drawing without upload), and never asserts times; the
 * binding count must stay 1 through the moves (it prints it). Results: BENCHMARKS.md.
 *
 * Usage: BenchmarkFFDInteraction [--mesh FILE.vtp] [--levels N] [--moves N]   (in an X display:
 * Utilities/with-display.sh build/bin/BenchmarkFFDInteraction)
 */
#include "FFDBenchmarkMeshes.h"
#include "FFDBenchmarkUtilities.h"
#include "vtkActor.h"
#include "vtkFFDBuildLattice.h"
#include "vtkFFDDeform.h"
#include "vtkFFDLatticeActor.h"
#include "vtkFFDLatticeRepresentation.h"
#include "vtkFFDVoxelize.h"
#include "vtkMath.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkPolyDataMapper.h"
#include "vtkProperty.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSMPTools.h"
#include "vtkStructuredGrid.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

int main(int argc, char* argv[])
{
  std::string meshPath = std::string(VOXELFFD_MESH_DIR) + "/armadillo.vtp";
  int levels = 2;
  int moves = 30;
  int status = 0;
  if (!ParseArguments(argc, argv, { { "--mesh", &meshPath }, { "--levels", &levels }, { "--moves", &moves } },
        "[--mesh FILE.vtp] [--levels N] [--moves N]", status))
  {
    return status;
  }
  moves = std::max(1, moves);
  const vtkSmartPointer<vtkPolyData> mesh = ShadedSubdividedMesh(meshPath, levels);
  if (mesh->GetNumberOfPoints() == 0)
  {
    std::fprintf(stderr, "%s: no points (run Utilities/setup.sh to fetch the meshes)\n", meshPath.c_str());
    return EXIT_FAILURE;
  }
  std::printf("mesh: %s subdivided %d times: %lld points, %lld triangles, point normals; %d threads (%s)\n",
    meshPath.c_str(), levels, static_cast<long long>(mesh->GetNumberOfPoints()),
    static_cast<long long>(mesh->GetNumberOfPolys()), vtkSMPTools::GetEstimatedNumberOfThreads(),
    vtkSMPTools::GetBackend());
  std::printf("%d moves of one control point, 10x10x10 voxels, offscreen 800x800 window; times in ms\n\n", moves);
  std::printf("| basis | control points (active) | bindings | pipeline median (min-max) | render median (min-max) "
              "| move to frame median | unchanged frame median |\n|---|---|---|---|---|---|---|\n");

  const int bases[2] = { vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::CUBIC_BSPLINE };
  for (int basis : bases)
  {
    vtkNew<vtkFFDVoxelize> voxelize;
    voxelize->SetInputData(mesh);
    voxelize->SetDivisions(10, 10, 10);
    vtkNew<vtkFFDBuildLattice> build;
    build->SetInputConnection(voxelize->GetOutputPort());
    build->SetBasis(basis);
    build->SetLatticeFormToDense();
    build->Update();
    vtkNew<vtkStructuredGrid> lattice;
    lattice->DeepCopy(build->GetOutput());

    vtkNew<vtkFFDDeform> deform;
    deform->SetInputData(mesh);
    deform->SetLatticeData(lattice);
    vtkNew<vtkPolyDataMapper> mapper;
    mapper->SetInputConnection(deform->GetOutputPort());
    vtkNew<vtkActor> actor;
    actor->SetMapper(mapper);
    vtkNew<vtkFFDLatticeRepresentation> representation;
    representation->SetLattice(lattice);
    // The active control point nearest to the mesh's centre: its move deforms a part of the mesh.
    double centre[3];
    mesh->GetCenter(centre);
    vtkIdType chosen = -1;
    double nearest = VTK_DOUBLE_MAX;
    vtkDataArray* active = lattice->GetPointData()->GetArray("Active");
    for (vtkIdType id = 0; id < lattice->GetNumberOfPoints(); ++id)
    {
      const double d = vtkMath::Distance2BetweenPoints(lattice->GetPoint(id), centre);
      if (active->GetComponent(id, 0) != 0.0 && d < nearest)
      {
        nearest = d;
        chosen = id;
      }
    }
    representation->SelectControlPoint(chosen);

    vtkNew<vtkRenderer> renderer;
    renderer->AddActor(actor);
    renderer->AddViewProp(representation);
    representation->SetRenderer(renderer);
    vtkNew<vtkRenderWindow> window;
    window->SetOffScreenRendering(1);
    window->SetSize(800, 800);
    window->AddRenderer(renderer);
    renderer->ResetCamera();
    window->Render(); // binds the points, uploads everything once

    // The same frame again with nothing changed: the cost of drawing alone (no upload), for comparison.
    std::vector<double> still;
    for (int m = 0; m < 5; ++m)
    {
      const Clock::time_point t0 = Clock::now();
      window->Render();
      window->WaitForCompletion();
      still.push_back(1e3 * Seconds(t0));
    }

    const double step = 0.01 * lattice->GetLength();
    std::vector<double> pipeline, render, total;
    for (int m = 0; m < moves; ++m)
    {
      const double sign = (m % 2) ? -1.0 : 1.0;
      const double delta[3] = { sign * step, 0.5 * sign * step, 0.0 };
      const Clock::time_point t0 = Clock::now();
      representation->MoveSelectedControlPoints(delta);
      deform->Update();
      const Clock::time_point t1 = Clock::now();
      window->Render();
      window->WaitForCompletion();
      const Clock::time_point t2 = Clock::now();
      pipeline.push_back(1e3 * Seconds(t0, t1));
      render.push_back(1e3 * Seconds(t1, t2));
      total.push_back(1e3 * Seconds(t0, t2));
    }
    const Timing p = Summarize(pipeline), r = Summarize(render), t = Summarize(total), u = Summarize(still);
    std::printf("| %s | %lld (%lld) | %lld | %.1f (%.1f-%.1f) | %.1f (%.1f-%.1f) | %.1f | %.1f |\n",
      vtkFFDBuildLattice::GetBasisAsString(basis), static_cast<long long>(lattice->GetNumberOfPoints()),
      static_cast<long long>(build->GetNumberOfActiveControlPoints()),
      static_cast<long long>(deform->GetNumberOfBindings()), p.Median, p.Best, p.Worst, r.Median, r.Best, r.Worst,
      t.Median, u.Median);
  }
  return EXIT_SUCCESS;
}
