#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""Deforms one corner of a real mesh locally: raises the bear's left arm with a cubic B-spline lattice.

A local basis (CUBIC_BSPLINE by default, or TRILINEAR and the Bezier sub-regions with --basis) over 10x10x4 voxels:
the control points around the bear's left arm (the viewer's right) are rotated about the shoulder, up to
ARM_DEGREES at the arm's tip, and every other control point stays where it is. The arm rises; the head, the other
arm and the legs do not move at all, which a global (Bernstein) lattice cannot do: there every control point moves
every point of the mesh. Two PNGs are written, the mesh with its rest lattice and the deformed mesh with the moved
lattice, and the paper's figure-style caption (vertices, control points, active voxels, active control points) and
the number of mesh points that moved and stayed are printed.

Run it with Debian's /usr/bin/python3, the built package on PYTHONPATH and an X server (Xvfb will do):
    PYTHONPATH=build/lib/python3/dist-packages Utilities/with-display.sh /usr/bin/python3 Examples/Python/deform_corner.py
"""
import argparse
import sys
from pathlib import Path

import numpy as np
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkCommonDataModel import vtkStructuredGrid
from vtkmodules.vtkFiltersExtraction import vtkExtractGrid

# The mesh reading, the bases' names and the rendering of the demo (this folder is on sys.path when run as a script).
from deform_mesh import BASES, REPOSITORY, read_mesh, render, union_bounds, vtkffd

DIVISIONS = (10, 10, 4)  # voxels along S (x), T (y, up) and U (z)
# Where the arm is, in frame parameters (s, t) of the bear's frame: the shoulder's pivot, and the band of heights
# around the arm whose control points move (fully inside INNER, fading to zero at OUTER).
SHOULDER = (0.75, 0.55)
ARM_HEIGHT_INNER = (0.45, 0.65)
ARM_HEIGHT_OUTER = (0.38, 0.70)
ARM_DEGREES = 40.0  # rotation of the arm's tip about the frame's U axis (counterclockwise seen from +U: upwards)


def parse_arguments():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--basis", choices=[name for name in BASES if name != "bernstein"], default="bspline",
                        help="the local basis (default: bspline, the uniform cubic B-spline)")
    parser.add_argument("--output-dir", type=Path, default=REPOSITORY / "build" / "demo",
                        help="folder for the PNGs (default: build/demo in the repository)")
    parser.add_argument("--size", type=int, nargs=2, default=(800, 800), metavar=("WIDTH", "HEIGHT"),
                        help="image size in pixels (default: 800 800)")
    return parser.parse_args()


def smoothstep(x, begin, end):
    """0 below begin, 1 above end, a C1 ramp between."""
    r = np.clip((x - begin) / (end - begin), 0.0, 1.0)
    return r * r * (3.0 - 2.0 * r)


def raise_arm(lattice):
    """Rotates the control points around the arm about the shoulder, in place; returns the VOI (VTK's
    imin, imax, jmin, jmax, kmin, kmax) of the moved control points and how many moved."""
    n_i, n_j, n_k = lattice.GetDimensions()
    origin, s_axis, t_axis, u_axis = vtk_to_numpy(lattice.GetFieldData().GetArray("FFDFrame")).reshape(4, 3)
    rest = vtk_to_numpy(lattice.GetPointData().GetArray("RestPosition")).reshape(n_k, n_j, n_i, 3)
    points = vtk_to_numpy(lattice.GetPoints().GetData()).reshape(n_k, n_j, n_i, 3)  # a view, VTK order

    # Frame parameters (s, t, u) of every control point's rest position (outside [0, 1] for a B-spline's ring).
    frame = np.column_stack((s_axis, t_axis, u_axis))
    stu = np.linalg.solve(frame, (rest - origin).reshape(-1, 3).T).T.reshape(rest.shape)
    s, t = stu[..., 0], stu[..., 1]
    # Weight 1 at the arm's tip and beyond, 0 at the shoulder and away from the arm's height band.
    weight = smoothstep(s, SHOULDER[0], 1.0) * smoothstep(t, ARM_HEIGHT_OUTER[0], ARM_HEIGHT_INNER[0]) \
        * (1.0 - smoothstep(t, ARM_HEIGHT_INNER[1], ARM_HEIGHT_OUTER[1]))
    angle = np.radians(ARM_DEGREES) * weight

    # Rotate about the axis through the shoulder along U, in the (S, T) plane of world coordinates.
    pivot = origin + SHOULDER[0] * s_axis + SHOULDER[1] * t_axis + 0.5 * u_axis
    axis = u_axis / np.linalg.norm(u_axis)
    offset = rest - pivot
    along = (offset @ axis)[..., None] * axis
    across = offset - along
    cos, sin = np.cos(angle)[..., None], np.sin(angle)[..., None]
    points[...] = pivot + along + across * cos + np.cross(axis, across) * sin
    lattice.GetPoints().Modified()  # numpy wrote behind VTK's back: tell the pipeline
    moved = np.nonzero(weight)  # k, j, i indices
    voi = [int(bound) for axis in (2, 1, 0) for bound in (moved[axis].min(), moved[axis].max())]
    return voi, len(moved[0])


def corner(lattice, voi):
    """The control points in the VOI: the corner being deformed, drawn without the rest of the dense lattice,
    which would hide the mesh."""
    extract = vtkExtractGrid()
    extract.SetInputData(lattice)
    extract.SetVOI(*voi)
    extract.Update()
    return extract.GetOutput()


def main():
    arguments = parse_arguments()
    name, mesh = read_mesh("bear")

    voxelize = vtkffd.vtkFFDVoxelize()
    voxelize.SetInputData(mesh)
    voxelize.SetDivisions(*DIVISIONS)
    build = vtkffd.vtkFFDBuildLattice()
    build.SetInputConnection(voxelize.GetOutputPort())
    getattr(build, BASES[arguments.basis])()
    build.SetLatticeFormToDense()  # a grid: raise_arm() reshapes it
    build.Update()
    rest_lattice = build.GetOutput()
    if rest_lattice.GetNumberOfPoints() == 0:
        sys.exit("the lattice could not be built (see the errors above)")

    lattice = vtkStructuredGrid()  # our own copy to move
    lattice.DeepCopy(rest_lattice)
    voi, moved_control_points = raise_arm(lattice)

    deform = vtkffd.vtkFFDDeform()
    deform.SetInputData(mesh)
    deform.SetLatticeData(lattice)
    deform.Update()
    deformed = deform.GetOutput()
    if deformed.GetNumberOfPoints() != mesh.GetNumberOfPoints():
        sys.exit("vtkFFDDeform failed (see the errors above)")

    before = vtk_to_numpy(mesh.GetPoints().GetData())
    after = vtk_to_numpy(deformed.GetPoints().GetData())
    # Points outside the moved control points' support keep their coordinates exactly (their displacement is a
    # sum of zeros), so "moved" needs no tolerance.
    moved = int(np.count_nonzero(np.any(after != before, axis=1)))
    total = mesh.GetNumberOfPoints()

    arguments.output_dir.mkdir(parents=True, exist_ok=True)
    before_png = arguments.output_dir / f"{name}_corner_before.png"
    after_png = arguments.output_dir / f"{name}_corner_after.png"
    shown_rest, shown = corner(rest_lattice, voi), corner(lattice, voi)
    camera_bounds = union_bounds(mesh, shown_rest, deformed, shown)
    render(before_png, arguments.size, mesh, shown_rest, camera_bounds)
    render(after_png, arguments.size, deformed, shown, camera_bounds)

    n_i, n_j, n_k = lattice.GetDimensions()
    print(f"{name}, {build.GetBasisAsString()} over {DIVISIONS[0]}x{DIVISIONS[1]}x{DIVISIONS[2]} voxels: "
          f"{total} vertices, {lattice.GetNumberOfPoints()} control points ({n_i}x{n_j}x{n_k}), "
          f"{voxelize.GetNumberOfActiveVoxels()} active voxels, "
          f"{build.GetNumberOfActiveControlPoints()} active control points")
    print(f"raised the left arm: {moved_control_points} control points moved; mesh points: {moved} moved "
          f"({100.0 * moved / total:.1f} %), {total - moved} stayed")
    print(f"wrote {before_png} and {after_png}")
    # A local deformation of one corner moves some points and leaves the rest exactly in place.
    if moved == 0 or moved == total:
        sys.exit(f"expected a local deformation, but {moved} of {total} points moved")


if __name__ == "__main__":
    main()
