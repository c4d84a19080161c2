#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""Deforms a real mesh with a global Bernstein (Sederberg-Parry) lattice of 3x4x5 control points, or another basis.

The set-up of the paper's Figure 12: the mesh is voxelized into 2x3x4 voxels, which gives a Bernstein lattice of
degree (2, 3, 4), that is 3x4x5 = 60 control points. The lattice's points are moved through numpy (the top layer
is pulled up and twisted, the middle layers bulge out), the mesh is deformed, and two PNGs are written: the mesh
with its rest lattice, and the deformed mesh with the moved lattice. A figure-style caption (vertices, control
points, active voxels, active control points, as in the paper's figures) and the time of the deformation are
printed. --basis and --divisions choose another lattice: e.g. the paper's Figure 1 is
`--basis trilinear --divisions 5 5 5`.

Run it with Debian's /usr/bin/python3 (which has VTK's Python), the built package on PYTHONPATH and an X server
(Xvfb will do), as Utilities/setup.sh does:
    PYTHONPATH=build/lib/python3/dist-packages Utilities/with-display.sh /usr/bin/python3 Examples/Python/deform_mesh.py
"""
import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np
from vtkmodules.vtkCommonDataModel import vtkStructuredGrid
from vtkmodules.vtkFiltersCore import vtkImageAppend, vtkPolyDataNormals
from vtkmodules.vtkImagingCore import vtkImageResize
from vtkmodules.vtkIOImage import vtkPNGReader, vtkPNGWriter
from vtkmodules.vtkIOXML import vtkXMLPolyDataReader
from vtkmodules.vtkRenderingCore import (
    vtkActor,
    vtkPolyDataMapper,
    vtkRenderer,
    vtkRenderWindow,
    vtkWindowToImageFilter,
)
import vtkmodules.vtkRenderingOpenGL2  # noqa: F401  (the OpenGL implementations of the rendering classes)

from twist_lattice import twist_lattice

try:
    import vtkffd
except ImportError as error:
    sys.exit(f"{error}: put the built package on PYTHONPATH, e.g. PYTHONPATH=build/lib/python3/dist-packages")

REPOSITORY = Path(__file__).resolve().parents[2]
DIVISIONS = (2, 3, 4)  # voxels per axis; the Bernstein degree per axis, so 3x4x5 control points
BASES = {  # --basis name: the vtkFFDBuildLattice setter
    "bernstein": "SetBasisToBernstein",
    "trilinear": "SetBasisToTrilinear",
    "quadratic": "SetBasisToTriquadraticBezier",
    "cubic": "SetBasisToTricubicBezier",
    "bspline": "SetBasisToCubicBSpline",
}
EVALUATION_RUNS = 5


def parse_arguments():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("mesh", nargs="?", default="bear",
                        help="a .vtp file, or the name of a mesh in Testing/Data/Meshes (default: bear)")
    parser.add_argument("--output-dir", type=Path, default=REPOSITORY / "build" / "demo",
                        help="folder for the PNGs (default: build/demo in the repository)")
    parser.add_argument("--size", type=int, nargs=2, default=(800, 800), metavar=("WIDTH", "HEIGHT"),
                        help="image size in pixels (default: 800 800)")
    parser.add_argument("--basis", choices=BASES, default="bernstein",
                        help="the lattice's basis (default: bernstein, the global Sederberg-Parry FFD)")
    parser.add_argument("--divisions", type=int, nargs=3, default=DIVISIONS, metavar=("NX", "NY", "NZ"),
                        help="voxels per axis of the frame (default: 2 3 4)")
    arguments = parser.parse_args()
    if min(arguments.divisions) < 1:
        parser.error("--divisions needs at least one voxel per axis")
    return arguments


def read_mesh(name):
    path = Path(name)
    if path.suffix != ".vtp":
        path = REPOSITORY / "Testing" / "Data" / "Meshes" / f"{name}.vtp"
    if not path.is_file():
        sys.exit(f"{path} is missing: pass a .vtp file, or run Utilities/setup.sh to fetch the meshes")
    reader = vtkXMLPolyDataReader()
    reader.SetFileName(str(path))
    # Point normals give smooth shading; vtkFFDDeform transforms them with the deformation.
    normals = vtkPolyDataNormals()
    normals.SetInputConnection(reader.GetOutputPort())
    normals.SplittingOff()
    normals.Update()
    mesh = normals.GetOutput()
    if mesh.GetNumberOfPoints() == 0:
        sys.exit(f"{path} holds no points")
    return path.stem, mesh


def render(output_path, size, mesh, lattice, camera_bounds, point_radius=None, azimuth=30.0):
    mesh_mapper = vtkPolyDataMapper()
    mesh_mapper.SetInputData(mesh)
    mesh_actor = vtkActor()
    mesh_actor.SetMapper(mesh_mapper)
    mesh_actor.GetProperty().SetColor(0.93, 0.90, 0.82)  # ivory
    mesh_actor.GetProperty().SetSpecular(0.2)
    mesh_actor.GetProperty().SetSpecularPower(20)

    lattice_actor = vtkffd.vtkFFDLatticeActor()  # red control points, dark grey edges
    lattice_actor.SetInputData(lattice)
    if point_radius:  # else a fraction of the lattice's diagonal, too large for a dense control mesh
        lattice_actor.SetPointRadius(point_radius)
        lattice_actor.GetEdgeProperty().SetLineWidth(1.0)

    renderer = vtkRenderer()
    renderer.AddActor(mesh_actor)
    renderer.AddActor(lattice_actor)
    renderer.GradientBackgroundOn()
    renderer.SetBackground(0.72, 0.76, 0.82)
    renderer.SetBackground2(0.98, 0.98, 0.99)
    camera = renderer.GetActiveCamera()
    camera.SetFocalPoint(0.0, 0.0, 0.0)
    camera.SetPosition(0.0, 0.0, 1.0)
    camera.SetViewUp(0.0, 1.0, 0.0)
    camera.Azimuth(azimuth)
    camera.Elevation(15.0)
    renderer.ResetCamera(camera_bounds)  # the same framing before and after
    camera.Zoom(1.25)  # ResetCamera fits the bounding sphere, which leaves wide margins around a box

    write_png(renderer, size, output_path)


def write_png(renderer, size, output_path):
    """Renders `renderer` offscreen into a window of `size` pixels and writes it as a PNG."""
    window = vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetSize(*size)
    window.AddRenderer(renderer)
    window.Render()
    grabber = vtkWindowToImageFilter()
    grabber.SetInput(window)
    writer = vtkPNGWriter()
    writer.SetInputConnection(grabber.GetOutputPort())
    writer.SetFileName(str(output_path))
    writer.Write()


def contact_sheet(pngs, output_path, columns):
    """The PNGs side by side, `columns` a row, each at half its width and height, written as one PNG."""
    rows = []
    for start in range(0, len(pngs), columns):
        row = vtkImageAppend()
        row.SetAppendAxis(0)
        for png in pngs[start:start + columns]:
            reader = vtkPNGReader()
            reader.SetFileName(str(png))
            shrink = vtkImageResize()
            shrink.SetInputConnection(reader.GetOutputPort())
            shrink.SetMagnificationFactors(0.5, 0.5, 1)
            shrink.SetResizeMethodToMagnificationFactors()
            row.AddInputConnection(shrink.GetOutputPort())
        rows.append(row)
    sheet = vtkImageAppend()
    sheet.SetAppendAxis(1)
    sheet.PreserveExtentsOff()
    for row in reversed(rows):  # images grow upwards: the first row on top
        sheet.AddInputConnection(row.GetOutputPort())
    writer = vtkPNGWriter()
    writer.SetInputConnection(sheet.GetOutputPort())
    writer.SetFileName(str(output_path))
    writer.Write()


def union_bounds(*data_sets):
    bounds = np.array([data.GetBounds() for data in data_sets])
    return [float(v) for pair in zip(bounds[:, 0::2].min(axis=0), bounds[:, 1::2].max(axis=0)) for v in pair]


def main():
    arguments = parse_arguments()
    name, mesh = read_mesh(arguments.mesh)

    voxelize = vtkffd.vtkFFDVoxelize()
    voxelize.SetInputData(mesh)
    voxelize.SetDivisions(*arguments.divisions)
    build = vtkffd.vtkFFDBuildLattice()
    build.SetInputConnection(voxelize.GetOutputPort())
    getattr(build, BASES[arguments.basis])()
    build.SetLatticeFormToDense()  # a grid, reshaped below, which vtkFFDLatticeActor draws
    build.Update()
    if build.GetOutput().GetNumberOfPoints() == 0:
        sys.exit("the lattice could not be built (see the errors above)")
    rest_lattice = build.GetOutput()

    # Our own copy to move, so that a re-execution of vtkFFDBuildLattice cannot undo the moves.
    lattice = vtkStructuredGrid()
    lattice.DeepCopy(rest_lattice)
    twist_lattice(lattice)

    deform = vtkffd.vtkFFDDeform()
    deform.SetInputData(mesh)
    deform.SetLatticeData(lattice)
    start = time.perf_counter()
    deform.Update()  # the first run binds every point to the lattice, then evaluates
    first_run = time.perf_counter() - start
    evaluation_runs = []
    for _ in range(EVALUATION_RUNS):
        lattice.GetPoints().Modified()  # as after moving control points: the binding is reused
        start = time.perf_counter()
        deform.Update()
        evaluation_runs.append(time.perf_counter() - start)
    if deform.GetNumberOfBindings() != 1:
        sys.exit(f"expected one binding, got {deform.GetNumberOfBindings()}: the binding cache did not hold")
    deformed = deform.GetOutput()

    arguments.output_dir.mkdir(parents=True, exist_ok=True)
    before_png = arguments.output_dir / f"{name}_before.png"
    after_png = arguments.output_dir / f"{name}_after.png"
    camera_bounds = union_bounds(mesh, rest_lattice, deformed, lattice)
    render(before_png, arguments.size, mesh, rest_lattice, camera_bounds)
    render(after_png, arguments.size, deformed, lattice, camera_bounds)

    n_i, n_j, n_k = lattice.GetDimensions()
    print(f"{name}: {mesh.GetNumberOfPoints()} vertices, {lattice.GetNumberOfPoints()} control points "
          f"({n_i}x{n_j}x{n_k}), {voxelize.GetNumberOfActiveVoxels()} active voxels, "
          f"{build.GetNumberOfActiveControlPoints()} active control points")
    print(f"deformation: {first_run * 1e3:.2f} ms binding + evaluation, "
          f"{statistics.median(evaluation_runs) * 1e3:.2f} ms evaluation only (median of {EVALUATION_RUNS})")
    print(f"wrote {before_png} and {after_png}")


if __name__ == "__main__":
    main()
