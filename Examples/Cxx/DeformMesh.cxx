// SPDX-License-Identifier: BSD-3-Clause
/**
 * DeformMesh: deforms a real mesh with a global Bernstein (Sederberg-Parry) lattice of 3x4x5 control points,
 * or another basis.
 *
 * The set-up of the paper's Figure 12, as in Examples/Python/deform_mesh.py: the mesh is voxelized into 2x3x4
 * voxels, giving a Bernstein lattice of degree (2, 3, 4), i.e. 3x4x5 = 60 control points; the top layer of the
 * lattice is pulled up and twisted and the middle layers bulge out; the mesh is deformed; two PNGs are written
 * (the mesh with its rest lattice, the deformed mesh with the moved lattice); a figure-style caption (vertices,
 * control points, active voxels, active control points, as in the paper's figures) and the time of the
 * deformation are printed.
 *
 * Usage: DeformMesh [--basis bernstein|trilinear|quadratic|cubic|bspline] [--divisions NX NY NZ]
 *                   [MESH.vtp [OUTPUT_FOLDER]]
 * (defaults: bernstein, 2 3 4, Testing/Data/Meshes/bear.vtp, build/demo); e.g. the paper's Figure 1 is
 * `--basis trilinear --divisions 5 5 5`.
 * It renders offscreen through GLX: run it under `xvfb-run -a` where there is no display.
 */
#include "vtkFFDBuildLattice.h"
#include "vtkFFDDataContract.h"
#include "vtkFFDDeform.h"
#include "vtkFFDLatticeActor.h"
#include "vtkFFDVoxelize.h"

#include "vtkActor.h"
#include "vtkCamera.h"
#include "vtkDataArray.h"
#include "vtkMath.h"
#include "vtkNew.h"
#include "vtkPNGWriter.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkPolyDataMapper.h"
#include "vtkPolyDataNormals.h"
#include "vtkProperty.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkStructuredGrid.h"
#include "vtkWindowToImageFilter.h"
#include "vtkXMLPolyDataReader.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <map>
#include <string>
#include <vector>

namespace
{
constexpr int DefaultDivisions[3] = { 2, 3, 4 }; // voxels per axis = Bernstein degree per axis: 3x4x5 points
const std::map<std::string, int> Bases = { { "bernstein", vtkFFDBuildLattice::BERNSTEIN },
  { "trilinear", vtkFFDBuildLattice::TRILINEAR }, { "quadratic", vtkFFDBuildLattice::TRIQUADRATIC_BEZIER },
  { "cubic", vtkFFDBuildLattice::TRICUBIC_BEZIER }, { "bspline", vtkFFDBuildLattice::CUBIC_BSPLINE } };
// CGAL's meshes stand along +Y, the frame's T axis: "up" below is T, and the camera looks along -Z.
constexpr double TwistDegrees = 40.0; // rotation of the top layer about the vertical axis (zero at the bottom)
constexpr double Bulge = 0.35;        // outward push of the middle layers, fraction of their distance to the axis
constexpr double Stretch = 0.25;      // lift of the top layer, fraction of the frame's height
constexpr int EvaluationRuns = 5;
constexpr int ImageSize = 800;

/// Moves the lattice's points: twist and lift the upper layers, bulge the middle ones (as the Python example).
bool DeformLattice(vtkStructuredGrid* lattice)
{
  double frame[12];
  vtkDataArray* rest = lattice->GetPointData()->GetArray(vtkFFDDataContract::RestPositionArrayName());
  if (!vtkFFDDataContract::GetFrame(lattice, frame) || !rest)
  {
    std::cerr << "the lattice lacks its FFDFrame or RestPosition array\n";
    return false;
  }
  const double* origin = frame;
  const double* s = frame + 3;
  const double* t = frame + 6;
  const double* u = frame + 9;
  double axis[3] = { t[0], t[1], t[2] };
  vtkMath::Normalize(axis);
  // Rows of the inverse of [S T U] give a point's frame parameters; a B-spline lattice's outer layers lie
  // outside the frame, at t < 0 and t > 1.
  const double edges[3][3] = { { s[0], t[0], u[0] }, { s[1], t[1], u[1] }, { s[2], t[2], u[2] } };
  double toParameters[3][3];
  vtkMath::Invert3x3(edges, toParameters);

  vtkPoints* points = lattice->GetPoints();
  for (vtkIdType id = 0; id < lattice->GetNumberOfPoints(); ++id)
  {
    double restPoint[3];
    rest->GetTuple(id, restPoint);
    // The layer's parameter t along T.
    const double relative[3] = { restPoint[0] - origin[0], restPoint[1] - origin[1], restPoint[2] - origin[2] };
    const double height = vtkMath::Dot(toParameters[1], relative);
    const double angle = vtkMath::RadiansFromDegrees(TwistDegrees) * height;
    const double scale = 1.0 + Bulge * std::sin(vtkMath::Pi() * height);

    double centre[3], along[3], across[3], turned[3], moved[3];
    for (int c = 0; c < 3; ++c)
    {
      centre[c] = origin[c] + 0.5 * s[c] + 0.5 * u[c] + height * t[c]; // on the frame's vertical axis
      across[c] = restPoint[c] - centre[c];
    }
    const double alongLength = vtkMath::Dot(across, axis);
    for (int c = 0; c < 3; ++c)
    {
      along[c] = alongLength * axis[c];
      across[c] -= along[c];
    }
    // Rotate the part across the axis (Rodrigues' formula; it has no along-axis term), then scale it.
    vtkMath::Cross(axis, across, turned);
    for (int c = 0; c < 3; ++c)
    {
      const double rotated = across[c] * std::cos(angle) + turned[c] * std::sin(angle);
      moved[c] = centre[c] + along[c] + scale * rotated + Stretch * height * height * t[c];
    }
    points->SetPoint(id, moved);
  }
  points->Modified();
  return true;
}

/// Renders the mesh and a lattice offscreen into a PNG, framing `bounds` from the same view every time.
void Render(const std::string& path, vtkPolyData* mesh, vtkStructuredGrid* lattice, const double bounds[6])
{
  vtkNew<vtkPolyDataMapper> meshMapper;
  meshMapper->SetInputData(mesh);
  vtkNew<vtkActor> meshActor;
  meshActor->SetMapper(meshMapper);
  meshActor->GetProperty()->SetColor(0.93, 0.90, 0.82); // ivory
  meshActor->GetProperty()->SetSpecular(0.2);
  meshActor->GetProperty()->SetSpecularPower(20);

  vtkNew<vtkFFDLatticeActor> latticeActor; // red control points, dark grey edges
  latticeActor->SetInputData(lattice);

  vtkNew<vtkRenderer> renderer;
  renderer->AddActor(meshActor);
  renderer->AddActor(latticeActor);
  renderer->GradientBackgroundOn();
  renderer->SetBackground(0.72, 0.76, 0.82);
  renderer->SetBackground2(0.98, 0.98, 0.99);
  vtkCamera* camera = renderer->GetActiveCamera();
  camera->SetFocalPoint(0.0, 0.0, 0.0);
  camera->SetPosition(0.0, 0.0, 1.0);
  camera->SetViewUp(0.0, 1.0, 0.0);
  camera->Azimuth(30.0);
  camera->Elevation(15.0);
  renderer->ResetCamera(bounds);
  camera->Zoom(1.25); // ResetCamera fits the bounding sphere, which leaves wide margins around a box

  vtkNew<vtkRenderWindow> window;
  window->SetOffScreenRendering(1);
  window->SetSize(ImageSize, ImageSize);
  window->AddRenderer(renderer);
  window->Render();
  vtkNew<vtkWindowToImageFilter> grabber;
  grabber->SetInput(window);
  vtkNew<vtkPNGWriter> writer;
  writer->SetInputConnection(grabber->GetOutputPort());
  writer->SetFileName(path.c_str());
  writer->Write();
}

double Milliseconds(std::chrono::steady_clock::duration duration)
{
  return std::chrono::duration<double, std::milli>(duration).count();
}
}

int main(int argc, char* argv[])
{
  const std::string usage = std::string("usage: ") + argv[0] +
    " [--basis bernstein|trilinear|quadratic|cubic|bspline] [--divisions NX NY NZ] [MESH.vtp [OUTPUT_FOLDER]]\n";
  int basis = vtkFFDBuildLattice::BERNSTEIN;
  int divisions[3] = { DefaultDivisions[0], DefaultDivisions[1], DefaultDivisions[2] };
  std::vector<std::string> positional;
  for (int a = 1; a < argc; ++a)
  {
    const std::string argument = argv[a];
    if (argument == "--basis" && a + 1 < argc && Bases.count(argv[a + 1]))
    {
      basis = Bases.at(argv[++a]);
    }
    else if (argument == "--divisions" && a + 3 < argc)
    {
      for (int axis = 0; axis < 3; ++axis)
      {
        divisions[axis] = std::atoi(argv[++a]);
      }
      if (std::min({ divisions[0], divisions[1], divisions[2] }) < 1)
      {
        std::cerr << "--divisions needs at least one voxel per axis\n" << usage;
        return EXIT_FAILURE;
      }
    }
    else if (argument.rfind("--", 0) == 0 || positional.size() == 2)
    {
      std::cerr << usage;
      return EXIT_FAILURE;
    }
    else
    {
      positional.push_back(argument);
    }
  }
  const std::filesystem::path meshPath = positional.size() > 0 ? positional[0] : DEFORMMESH_DEFAULT_MESH;
  const std::filesystem::path outputDir = positional.size() > 1 ? positional[1] : DEFORMMESH_DEFAULT_OUTPUT;
  if (!std::filesystem::is_regular_file(meshPath))
  {
    std::cerr << meshPath.string() << " is missing: pass a .vtp file, or run Utilities/setup.sh to fetch the meshes\n";
    return EXIT_FAILURE;
  }
  const std::string name = meshPath.stem().string();

  vtkNew<vtkXMLPolyDataReader> reader;
  reader->SetFileName(meshPath.string().c_str());
  // Point normals give smooth shading; vtkFFDDeform transforms them with the deformation.
  vtkNew<vtkPolyDataNormals> normals;
  normals->SetInputConnection(reader->GetOutputPort());
  normals->SplittingOff();
  normals->Update();
  vtkPolyData* mesh = normals->GetOutput();
  if (mesh->GetNumberOfPoints() == 0)
  {
    std::cerr << meshPath.string() << " holds no points\n";
    return EXIT_FAILURE;
  }

  vtkNew<vtkFFDVoxelize> voxelize;
  voxelize->SetInputData(mesh);
  voxelize->SetDivisions(divisions);
  vtkNew<vtkFFDBuildLattice> build;
  build->SetInputConnection(voxelize->GetOutputPort());
  build->SetBasis(basis);
  build->SetLatticeFormToDense(); // the form vtkFFDLatticeActor draws
  build->Update();
  vtkStructuredGrid* restLattice = build->GetStructuredGridOutput();
  if (restLattice->GetNumberOfPoints() == 0)
  {
    std::cerr << "the lattice could not be built (see the errors above)\n";
    return EXIT_FAILURE;
  }

  // Our own copy to move, so that a re-execution of vtkFFDBuildLattice cannot undo the moves.
  vtkNew<vtkStructuredGrid> lattice;
  lattice->DeepCopy(restLattice);
  if (!DeformLattice(lattice))
  {
    return EXIT_FAILURE;
  }

  vtkNew<vtkFFDDeform> deform;
  deform->SetInputData(mesh);
  deform->SetLatticeData(lattice);
  using Clock = std::chrono::steady_clock;
  auto start = Clock::now();
  deform->Update(); // the first run binds every point to the lattice, then evaluates
  const double firstRun = Milliseconds(Clock::now() - start);
  std::vector<double> evaluationRuns;
  for (int run = 0; run < EvaluationRuns; ++run)
  {
    lattice->GetPoints()->Modified(); // as after moving control points: the binding is reused
    start = Clock::now();
    deform->Update();
    evaluationRuns.push_back(Milliseconds(Clock::now() - start));
  }
  vtkPolyData* deformed = vtkPolyData::SafeDownCast(deform->GetOutput());
  if (!deformed || deformed->GetNumberOfPoints() != mesh->GetNumberOfPoints())
  {
    std::cerr << "the deformation failed (see the errors above)\n";
    return EXIT_FAILURE;
  }
  if (deform->GetNumberOfBindings() != 1)
  {
    std::cerr << "expected one binding, got " << deform->GetNumberOfBindings() << ": the binding cache did not hold\n";
    return EXIT_FAILURE;
  }
  std::nth_element(evaluationRuns.begin(), evaluationRuns.begin() + EvaluationRuns / 2, evaluationRuns.end());

  // One framing for both images, so that they compare: the union of everything drawn.
  double bounds[6];
  mesh->GetBounds(bounds);
  for (vtkDataSet* data : { static_cast<vtkDataSet*>(restLattice), static_cast<vtkDataSet*>(deformed),
         static_cast<vtkDataSet*>(lattice.Get()) })
  {
    const double* more = data->GetBounds();
    for (int axis = 0; axis < 3; ++axis)
    {
      bounds[2 * axis] = std::min(bounds[2 * axis], more[2 * axis]);
      bounds[2 * axis + 1] = std::max(bounds[2 * axis + 1], more[2 * axis + 1]);
    }
  }
  std::filesystem::create_directories(outputDir);
  const std::string beforePng = (outputDir / (name + "_before.png")).string();
  const std::string afterPng = (outputDir / (name + "_after.png")).string();
  Render(beforePng, mesh, restLattice, bounds);
  Render(afterPng, deformed, lattice, bounds);

  int dims[3];
  lattice->GetDimensions(dims);
  std::cout << name << ": " << mesh->GetNumberOfPoints() << " vertices, " << lattice->GetNumberOfPoints()
            << " control points (" << dims[0] << "x" << dims[1] << "x" << dims[2] << "), "
            << voxelize->GetNumberOfActiveVoxels() << " active voxels, " << build->GetNumberOfActiveControlPoints()
            << " active control points\n"
            << std::fixed << std::setprecision(2) << "deformation: " << firstRun << " ms binding + evaluation, "
            << evaluationRuns[EvaluationRuns / 2] << " ms evaluation only (median of " << EvaluationRuns << ")\n"
            << "wrote " << beforePng << " and " << afterPng << "\n";
  return EXIT_SUCCESS;
}
