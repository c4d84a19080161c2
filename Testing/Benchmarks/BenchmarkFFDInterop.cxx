// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file BenchmarkFFDInterop.cxx
 * @brief GPU–GL interop against the host path: time from a control-point move to a finished frame.
 *
 * A wavy sheet of 1 M, 10 M and 50 M points (float32, triangles, with or without point normals) in a lattice
 * over 16 x 16 x 2 voxels (TRILINEAR and CUBIC_BSPLINE), deformed by vtkFFDDeform on CUDA and drawn by
 * vtkFFDInteropPolyDataMapper in a 1024 x 1024 offscreen window. Each timed frame moves one control point,
 * renders and waits for the GPU (vtkRenderWindow::WaitForCompletion(): glFinish). The host path (Interop off:
 * the deformed points and normals are downloaded into the output arrays, then uploaded again into the vertex
 * buffers) and the interop path (the device writes the vertex buffers) take turns in blocks of frames on the
 * same scene, so that their ratio is measured side by side. Bytes over the bus per frame: the lattice's
 * displacements up and what vtkFFDDeform downloaded (vtkFFDDeform's counters), plus, on the host path, the
 * vertex buffers uploaded (points and normals, 12 bytes each a point). Each frame is split into its pipeline
 * part (vtkFFDDeform's update, which the mapper's bounds trigger, as the renderer's first request does) and the
 * rest (buffers and draw). It also times an unchanged frame (the draw alone). It prints a table and asserts nothing
 * about time; BENCHMARKS.md holds the results.
 *
 * On the GPU machine (no X display): bash Utilities/gpu-rendering.sh --benchmark (vtkFFDEGLRenderWindow through
 * VOXELFFD_RENDER_WINDOW=egl). Here, in an X display with small sizes:
 *   Utilities/with-display.sh build/bin/BenchmarkFFDInterop --points 0.1 --frames 4
 * Usage: BenchmarkFFDInterop [--points M[,M...]] [--frames N]   (M: millions of points)
 */
#include "FFDBenchmarkUtilities.h"
#include "FFDSelectRenderWindow.h"

#include "vtkActor.h"
#include "vtkCamera.h"
#include "vtkCellArray.h"
#include "vtkFFDBuildLattice.h"
#include "vtkFFDDeform.h"
#include "vtkFFDInteropPolyDataMapper.h"
#include "vtkFFDVoxelize.h"
#include "vtkFloatArray.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkProperty.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSMPTools.h"
#include "vtkStructuredGrid.h"
#include "vtkTypeInt32Array.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

namespace
{
/// A sheet of about `millions` M points over [0, 2] x [0, 1], z a few waves high, in triangles, with its
/// exact unit normals when `withNormals`.
vtkSmartPointer<vtkPolyData> WavySheet(double millions, bool withNormals)
{
  const vtkIdType nx = std::max<vtkIdType>(2, vtkIdType(std::sqrt(2.0 * millions * 1e6)));
  const vtkIdType ny = std::max<vtkIdType>(2, vtkIdType(millions * 1e6) / nx);
  vtkNew<vtkFloatArray> xyz, normals;
  xyz->SetNumberOfComponents(3);
  xyz->SetNumberOfTuples(nx * ny);
  normals->SetName("Normals");
  normals->SetNumberOfComponents(3);
  normals->SetNumberOfTuples(withNormals ? nx * ny : 0);
  vtkSMPTools::For(0, ny,
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType j = begin; j < end; ++j)
      {
        for (vtkIdType i = 0; i < nx; ++i)
        {
          const double x = 2.0 * i / (nx - 1), y = double(j) / (ny - 1);
          const double z = 0.05 * std::sin(6.0 * x) * std::cos(5.0 * y);
          const double zx = 0.3 * std::cos(6.0 * x) * std::cos(5.0 * y),
                       zy = -0.25 * std::sin(6.0 * x) * std::sin(5.0 * y);
          const vtkIdType p = j * nx + i;
          xyz->SetTypedTuple(p, std::array<float, 3>{ float(x), float(y), float(z) }.data());
          if (withNormals)
          {
            const double length = std::sqrt(zx * zx + zy * zy + 1.0);
            normals->SetTypedTuple(
              p, std::array<float, 3>{ float(-zx / length), float(-zy / length), float(1.0 / length) }.data());
          }
        }
      }
    });
  const vtkIdType quads = (nx - 1) * (ny - 1);
  vtkNew<vtkTypeInt32Array> offsets, connectivity;
  offsets->SetNumberOfTuples(2 * quads + 1);
  connectivity->SetNumberOfTuples(6 * quads);
  vtkSMPTools::For(0, ny - 1,
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType j = begin; j < end; ++j)
      {
        for (vtkIdType i = 0; i < nx - 1; ++i)
        {
          const vtkIdType q = j * (nx - 1) + i, a = j * nx + i;
          const vtkTypeInt32 corners[6] = { vtkTypeInt32(a), vtkTypeInt32(a + 1), vtkTypeInt32(a + nx + 1),
            vtkTypeInt32(a), vtkTypeInt32(a + nx + 1), vtkTypeInt32(a + nx) };
          for (int c = 0; c < 6; ++c)
          {
            connectivity->SetValue(6 * q + c, corners[c]);
          }
          offsets->SetValue(2 * q, vtkTypeInt32(6 * q));
          offsets->SetValue(2 * q + 1, vtkTypeInt32(6 * q + 3));
        }
      }
    });
  offsets->SetValue(2 * quads, vtkTypeInt32(6 * quads));
  vtkNew<vtkCellArray> triangles;
  triangles->SetData(offsets, connectivity);
  vtkNew<vtkPoints> points;
  points->SetData(xyz);
  auto sheet = vtkSmartPointer<vtkPolyData>::New();
  sheet->SetPoints(points);
  sheet->SetPolys(triangles);
  if (withNormals)
  {
    sheet->GetPointData()->SetNormals(normals);
  }
  return sheet;
}

/// The rest lattice of `basis` over `sheet`'s 16 x 16 x 2 voxels, as a grid the benchmark moves.
vtkSmartPointer<vtkStructuredGrid> LatticeOver(vtkPolyData* sheet, int basis)
{
  vtkNew<vtkFFDVoxelize> voxelize;
  voxelize->SetInputData(sheet);
  voxelize->SetDivisions(16, 16, 2);
  vtkNew<vtkFFDBuildLattice> build;
  build->SetInputConnection(voxelize->GetOutputPort());
  build->SetBasis(basis);
  build->SetLatticeFormToDense();
  build->Update();
  auto lattice = vtkSmartPointer<vtkStructuredGrid>::New();
  lattice->DeepCopy(build->GetOutput());
  return lattice;
}

struct PathTimes
{
  std::vector<double> Frames;    ///< seconds from a move to the finished frame
  std::vector<double> Pipelines; ///< of which the update of vtkFFDDeform (through the mapper's bounds)
  double LatticeBytes = 0, DownloadedBytes = 0, BufferBytes = 0; ///< a frame's, on average, of the last block
  int DeviceFrames = 0;
};

struct Scene
{
  vtkNew<vtkFFDDeform> Deform;
  vtkNew<vtkFFDInteropPolyDataMapper> Mapper;
  vtkNew<vtkActor> Actor;
  vtkNew<vtkRenderer> Renderer;
  vtkSmartPointer<vtkRenderWindow> Window = vtkSmartPointer<vtkRenderWindow>::New();
  vtkSmartPointer<vtkStructuredGrid> Lattice;
  int Moves = 0;

  Scene(vtkPolyData* sheet, vtkStructuredGrid* lattice)
    : Lattice(lattice)
  {
    this->Deform->SetInputData(sheet);
    this->Deform->SetLatticeData(lattice);
    this->Mapper->SetInputConnection(this->Deform->GetOutputPort());
    this->Actor->SetMapper(this->Mapper);
    this->Actor->GetProperty()->SetColor(0.93, 0.9, 0.8);
    this->Renderer->AddActor(this->Actor);
    this->Renderer->SetBackground(1.0, 1.0, 1.0);
    this->Window->SetOffScreenRendering(1);
    this->Window->SetMultiSamples(0);
    this->Window->SetSize(1024, 1024);
    this->Window->AddRenderer(this->Renderer);
    this->Renderer->GetActiveCamera()->Elevation(-50.0);
    this->Renderer->ResetCamera();
  }

  /// Moves a control point in the middle of the lattice up and down by turns.
  void Move()
  {
    int dims[3];
    this->Lattice->GetDimensions(dims);
    const vtkIdType id = dims[0] / 2 + dims[0] * (dims[1] / 2 + vtkIdType(dims[1]) * (dims[2] / 2));
    double p[3];
    this->Lattice->GetPoint(id, p);
    p[2] += (this->Moves++ % 2 ? -0.05 : 0.05);
    this->Lattice->GetPoints()->SetPoint(id, p);
    this->Lattice->GetPoints()->Modified();
  }

  /// `frames` timed frames on one path, after one untimed frame that switches to it.
  void Frames(bool interop, int frames, PathTimes& times)
  {
    this->Mapper->SetInterop(interop);
    this->Move();
    this->Window->Render();
    this->Window->WaitForCompletion();
    const vtkTypeUInt64 up = this->Deform->GetLatticeBytesUploaded(), down = this->Deform->GetBytesDownloaded();
    int hostFrames = 0;
    for (int f = 0; f < frames; ++f)
    {
      this->Move();
      const Clock::time_point start = Clock::now();
      this->Mapper->GetBounds(); // what the renderer asks first: vtkFFDDeform executes
      times.Pipelines.push_back(Seconds(start));
      this->Window->Render();
      this->Window->WaitForCompletion();
      times.Frames.push_back(Seconds(start));
      hostFrames += this->Mapper->GetLastFrameFromDevice() ? 0 : 1;
    }
    times.DeviceFrames += frames - hostFrames;
    times.LatticeBytes = double(this->Deform->GetLatticeBytesUploaded() - up) / frames;
    times.DownloadedBytes = double(this->Deform->GetBytesDownloaded() - down) / frames;
    vtkPolyData* input = vtkPolyData::SafeDownCast(this->Deform->GetInputDataObject(0, 0));
    const bool normals = input->GetPointData()->GetNormals() != nullptr;
    times.BufferBytes = 12.0 * (normals ? 2 : 1) * double(input->GetNumberOfPoints()) * hostFrames / frames;
  }

  /// The median time of rendering the unchanged frame again (the draw alone).
  double UnchangedFrame(int frames)
  {
    std::vector<double> times;
    for (int f = 0; f < frames; ++f)
    {
      const Clock::time_point start = Clock::now();
      this->Renderer->GetActiveCamera()->Azimuth(f % 2 ? -0.5 : 0.5);
      this->Window->Render();
      this->Window->WaitForCompletion();
      times.push_back(Seconds(start));
    }
    return Median(times);
  }
};

std::string Megabytes(double bytes)
{
  char text[32];
  std::snprintf(text, sizeof text, bytes < 1e5 ? "%.0f B" : "%.1f MB", bytes < 1e5 ? bytes : bytes / 1e6);
  return text;
}
} // namespace

int main(int argc, char* argv[])
{
  std::string sizes = "1,10,50";
  int frames = 8;
  int status = 0;
  if (!ParseArguments(
        argc, argv, { { "--points", &sizes }, { "--frames", &frames } }, "[--points M[,M...]] [--frames N]", status))
  {
    return status;
  }
  FFDSelectRenderWindow(&argc, &argv);
  frames = std::max(2, frames);
  std::printf(
    "%d frames a path in two blocks, each frame: move one control point, Render(), glFinish; ms\n\n", 2 * frames);
  std::printf("| points | basis | normals | host frame (pipeline) | interop frame (pipeline) | interop / host | "
              "interop fps | unchanged frame | bus per frame, host | bus per frame, interop | device-written frames "
              "|\n|---:|---|---|---:|---:|---:|---:|---:|---|---|---|\n");
  std::stringstream list(sizes);
  for (std::string size; std::getline(list, size, ',');)
  {
    const double millions = std::atof(size.c_str());
    for (bool withNormals : { true, false })
    {
      vtkSmartPointer<vtkPolyData> sheet = WavySheet(millions, withNormals);
      for (int basis : { vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::CUBIC_BSPLINE })
      {
        Scene scene(sheet, LatticeOver(sheet, basis));
        scene.Window->Render(); // binds, uploads the cells once
        PathTimes host, interop;
        for (int block = 0; block < 2; ++block)
        {
          scene.Frames(false, frames / 2 + frames % 2 * block, host);
          scene.Frames(true, frames / 2 + frames % 2 * block, interop);
        }
        const double unchanged = scene.UnchangedFrame(frames);
        const double h = Median(host.Frames), i = Median(interop.Frames);
        std::printf(
          "| %.2f M | %s | %s | %.2f (%.2f) | %.2f (%.2f) | %.3f | %.0f | %.2f | %s up, %s down, %s to GL | %s up, %s "
          "down, %s to GL | %d of %zu |\n",
          sheet->GetNumberOfPoints() / 1e6, vtkFFDBuildLattice::GetBasisAsString(basis), withNormals ? "yes" : "no",
          1e3 * h, 1e3 * Median(host.Pipelines), 1e3 * i, 1e3 * Median(interop.Pipelines), i / h, 1.0 / i,
          1e3 * unchanged, Megabytes(host.LatticeBytes).c_str(), Megabytes(host.DownloadedBytes).c_str(),
          Megabytes(host.BufferBytes).c_str(), Megabytes(interop.LatticeBytes).c_str(),
          Megabytes(interop.DownloadedBytes).c_str(), Megabytes(interop.BufferBytes).c_str(), interop.DeviceFrames,
          interop.Frames.size());
        std::fflush(stdout);
      }
    }
  }
  return EXIT_SUCCESS;
}
