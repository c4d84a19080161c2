#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""A fine lattice over a real mesh at 512^3 voxels: memory follows the mesh, not the divisions.

The bear is voxelized into 512 x 512 x 512 voxels and a cubic B-spline lattice is built over its active voxels
only: vtkFFDBuildLattice's default form for a local basis is sparse, a vtkUnstructuredGrid of the control points
that influence some active voxel, each with its (i, j, k) in the `LatticeIndex` point array. The dense form would
hold 515^3 = 136.6 million control points (6.8 GB); the sparse one holds under a million. numpy then presses a
small dent into the bear's belly (a Gaussian bump of the control points, selected by their rest positions) and
vtkFFDDeform deforms the mesh. The script prints the sizes, the memory and the times, and writes a PNG of the
deformed bear coloured by how far each point moved.

Run it with Debian's /usr/bin/python3, the built package on PYTHONPATH and an X server (Xvfb will do):
    PYTHONPATH=build/lib/python3/dist-packages Utilities/with-display.sh /usr/bin/python3 Examples/Python/sparse_lattice.py
"""
import argparse
import resource
import sys
import time
from pathlib import Path

import numpy as np
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy
from vtkmodules.vtkCommonCore import vtkLookupTable
from vtkmodules.vtkCommonDataModel import vtkUnstructuredGrid
from vtkmodules.vtkRenderingCore import vtkActor, vtkPolyDataMapper, vtkRenderer

# The mesh reading and PNG writing of the demo (this folder is on sys.path when run as a script).
from deform_mesh import REPOSITORY, read_mesh, vtkffd, write_png


def parse_arguments():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--mesh", default="bear", help="a mesh of Testing/Data/Meshes or a .vtp file (default: bear)")
    parser.add_argument("--divisions", type=int, default=512, help="voxels along each axis (default: 512)")
    parser.add_argument("--output-dir", type=Path, default=REPOSITORY / "build" / "demo",
                        help="folder for the PNG (default: build/demo in the repository)")
    return parser.parse_args()


def peak_megabytes():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0  # kB on Linux


def dent(lattice, centre_stu, radius_stu, depth_stu):
    """Pushes the control points near `centre_stu` (frame parameters) back along -U, by depth_stu U at the centre
    fading as a Gaussian of radius radius_stu; in place, through numpy views of the lattice's points."""
    origin, s_axis, t_axis, u_axis = vtk_to_numpy(lattice.GetFieldData().GetArray("FFDFrame")).reshape(4, 3)
    rest = vtk_to_numpy(lattice.GetPointData().GetArray("RestPosition"))
    points = vtk_to_numpy(lattice.GetPoints().GetData())  # a view: writing it moves the lattice's points
    # The rest positions' frame parameters (s, t, u): solve X0 + s S + t T + u U = x for every control point.
    frame = np.column_stack((s_axis, t_axis, u_axis))
    stu = np.linalg.solve(frame, (rest - origin).T).T
    weight = np.exp(-np.sum((stu - np.asarray(centre_stu)) ** 2, axis=1) / radius_stu ** 2)
    moved = weight > 1e-3
    points[moved] -= np.outer(weight[moved] * depth_stu, u_axis)
    lattice.GetPoints().Modified()  # numpy wrote behind VTK's back
    return int(moved.sum())


def render(output_path, mesh, displacement):
    distance = numpy_to_vtk(displacement, deep=True)
    distance.SetName("Displacement")
    mesh.GetPointData().SetScalars(distance)
    colours = vtkLookupTable()  # ivory (did not move) to red (moved the most)
    colours.SetHueRange(0.12, 0.0)
    colours.SetSaturationRange(0.1, 0.9)
    colours.SetValueRange(0.95, 0.7)
    colours.Build()
    mapper = vtkPolyDataMapper()
    mapper.SetInputData(mesh)
    mapper.SetLookupTable(colours)
    mapper.SetScalarRange(0.0, float(displacement.max()) or 1.0)
    actor = vtkActor()
    actor.SetMapper(mapper)
    renderer = vtkRenderer()
    renderer.AddActor(actor)
    renderer.SetBackground(1.0, 1.0, 1.0)
    camera = renderer.GetActiveCamera()
    camera.SetPosition(0.0, 0.0, 1.0)  # the bear stands along +Y and faces +Z
    camera.SetFocalPoint(0.0, 0.0, 0.0)
    camera.SetViewUp(0.0, 1.0, 0.0)
    camera.Azimuth(-40.0)
    camera.Elevation(10.0)
    renderer.ResetCamera()
    camera.Zoom(1.3)
    write_png(renderer, (600, 600), output_path)


def main():
    args = parse_arguments()
    name, mesh = read_mesh(args.mesh)
    n = args.divisions

    start = time.perf_counter()
    voxelize = vtkffd.vtkFFDVoxelize()
    voxelize.SetInputData(mesh)
    voxelize.SetDivisions(n, n, n)
    build = vtkffd.vtkFFDBuildLattice()
    build.SetInputConnection(voxelize.GetOutputPort())
    build.SetBasisToCubicBSpline()  # LatticeForm AUTOMATIC: sparse for a local basis
    build.Update()
    built = time.perf_counter() - start
    if build.GetOutputDataObject(0).GetNumberOfPoints() == 0:
        sys.exit("the lattice could not be built (see the error above)")
    lattice = vtkUnstructuredGrid()
    lattice.DeepCopy(build.GetOutputDataObject(0))  # the lattice we move; the filter keeps its own output
    dense = (n + 3) ** 3
    print(f"{name}: {mesh.GetNumberOfPoints()} vertices, {n}^3 voxels, {voxelize.GetNumberOfActiveVoxels()} active")
    print(f"sparse cubic B-spline lattice: {lattice.GetNumberOfPoints()} control points of the dense {dense} "
          f"({lattice.GetActualMemorySize() / 1024.0:.0f} MB instead of about {50.0 * dense / 1e9:.1f} GB), "
          f"{lattice.GetNumberOfCells()} cells; voxelize + build {built:.2f} s")

    moved = dent(lattice, centre_stu=(0.5, 0.35, 1.0), radius_stu=0.12, depth_stu=0.06)

    deform = vtkffd.vtkFFDDeform()
    deform.SetInputData(mesh)
    deform.SetLatticeData(lattice)
    start = time.perf_counter()
    deform.Update()
    first = time.perf_counter() - start
    before = vtk_to_numpy(mesh.GetPoints().GetData())
    after = vtk_to_numpy(deform.GetOutput().GetPoints().GetData())
    displacement = np.linalg.norm(after - before, axis=1)
    changed = int((displacement > 0.0).sum())
    print(f"{moved} control points moved; {changed} of {mesh.GetNumberOfPoints()} mesh points moved, "
          f"by up to {displacement.max():.4f}; deform {first * 1e3:.1f} ms (binding and evaluation, "
          f"{deform.GetLastBackendUsed()}); peak memory {peak_megabytes():.0f} MB")
    if changed == 0 or changed == mesh.GetNumberOfPoints():
        sys.exit("the dent should move some of the mesh's points, not none and not all")

    args.output_dir.mkdir(parents=True, exist_ok=True)
    output = args.output_dir / f"{name}_sparse_{n}.png"
    render(output, deform.GetOutput(), displacement)
    print(f"wrote {output}")


if __name__ == "__main__":
    main()
