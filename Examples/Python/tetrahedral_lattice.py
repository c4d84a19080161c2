#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""Deforms a real mesh with a tetrahedral control mesh (the paper's section III.E and Figure 9): raises the cow's head.

vtkFFDBuildTetrahedralLattice joins the convex hull of the cow's points to their centroid, one tetrahedron per hull
triangle, and subdivides it once for finer control; the nodes in the front of the head move forward and up, the more
the further forward; vtkFFDDeform moves every point by the barycentric weights of its tetrahedron (equation 5).
Points in tetrahedra without a moved node stay exactly where they are. Two PNGs are written, the mesh in its rest
control mesh and the deformed one, and the figure-style caption (vertices, hull triangles, tetrahedra, nodes, active
nodes) and the number of points that moved are printed.

Run it with Debian's /usr/bin/python3, the built package on PYTHONPATH and an X server (Xvfb will do):
    PYTHONPATH=build/lib/python3/dist-packages Utilities/with-display.sh /usr/bin/python3 Examples/Python/tetrahedral_lattice.py
"""
import argparse
import sys
from pathlib import Path

import numpy as np
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy
from vtkmodules.vtkCommonDataModel import vtkUnstructuredGrid

# The mesh reading and the rendering of the demo (this folder is on sys.path when run as a script).
from deform_mesh import REPOSITORY, read_mesh, render, union_bounds, vtkffd

HEAD = 0.15  # the front fraction of the cow's length (+X) whose nodes move
LIFT = (0.25, 0.35, 0.0)  # how far the foremost node moves (x, y, z), in the mesh's units


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--output-dir", type=Path, default=REPOSITORY / "build" / "demo",
                        help="folder for the PNGs (default: build/demo in the repository)")
    parser.add_argument("--levels", type=int, default=1, help="subdivision levels of the control mesh (default: 1)")
    parser.add_argument("--size", type=int, nargs=2, default=(800, 600), metavar=("WIDTH", "HEIGHT"))
    arguments = parser.parse_args()

    name, mesh = read_mesh("cow")
    build = vtkffd.vtkFFDBuildTetrahedralLattice()
    build.SetInputData(mesh)
    build.SetSubdivisionLevels(arguments.levels)
    build.Update()
    rest_lattice = build.GetOutput()
    if rest_lattice.GetNumberOfCells() == 0:
        sys.exit("the control mesh could not be built (see the errors above)")

    lattice = vtkUnstructuredGrid()  # our own copy to move
    lattice.DeepCopy(rest_lattice)
    nodes = vtk_to_numpy(lattice.GetPoints().GetData()).copy()
    x_min, x_max = mesh.GetBounds()[0:2]
    front = x_max - HEAD * (x_max - x_min)
    reach = np.clip((nodes[:, 0] - front) / (x_max - front), 0.0, None)  # 0 behind the head, 1 at the nose
    nodes += reach[:, None] * np.array(LIFT)
    lattice.GetPoints().SetData(numpy_to_vtk(nodes, deep=True))

    deform = vtkffd.vtkFFDDeform()
    deform.SetInputData(mesh)
    deform.SetLatticeData(lattice)
    deform.Update()
    deformed = deform.GetOutput()
    if deformed.GetNumberOfPoints() != mesh.GetNumberOfPoints():
        sys.exit("vtkFFDDeform failed (see the errors above)")

    before = vtk_to_numpy(mesh.GetPoints().GetData())
    after = vtk_to_numpy(deformed.GetPoints().GetData())
    moved = int(np.count_nonzero(np.any(after != before, axis=1)))
    total = mesh.GetNumberOfPoints()

    arguments.output_dir.mkdir(parents=True, exist_ok=True)
    before_png = arguments.output_dir / f"{name}_tetrahedral_before.png"
    after_png = arguments.output_dir / f"{name}_tetrahedral_after.png"
    camera_bounds = union_bounds(mesh, rest_lattice, deformed, lattice)
    radius = 0.004 * np.linalg.norm(np.subtract(camera_bounds[1::2], camera_bounds[0::2]))
    render(before_png, arguments.size, mesh, rest_lattice, camera_bounds, radius)
    render(after_png, arguments.size, deformed, lattice, camera_bounds, radius)

    print(f"{name}: {total} vertices; control mesh of {build.GetNumberOfHullFaces()} hull triangles and the centroid, "
          f"subdivided {arguments.levels} time(s): {lattice.GetNumberOfCells()} tetrahedra, "
          f"{lattice.GetNumberOfPoints()} nodes, {build.GetNumberOfActiveNodes()} active")
    print(f"raised the head: {int(np.count_nonzero(reach))} nodes moved; mesh points: {moved} moved "
          f"({100.0 * moved / total:.1f} %), {total - moved} stayed; {deform.GetLastBackendUsed()} backend")
    print(f"wrote {before_png} and {after_png}")
    if moved == 0 or moved == total:
        sys.exit(f"expected a local deformation, but {moved} of {total} points moved")


if __name__ == "__main__":
    main()
