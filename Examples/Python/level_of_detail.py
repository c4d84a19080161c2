#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""Level of detail: a coarse lattice deformed, refined exactly, detail added locally, and coarsened back.

1. The bear in a 3x3x3 cubic B-spline lattice, twisted and lifted as the demo does (twist_lattice.twist_lattice).
2. vtkFFDRefineLattice: the same deformation on a 6x6x6 lattice (the script prints the largest difference over the
   bear's points: rounding only).
3. vtkFFDBuildDetailLattice over the refined lattice's voxels around the head: a 12x12x12 detail lattice, at rest,
   whose movable control points in front of the muzzle are then pulled forward; vtkFFDDeformBlocks adds it to the
   refined lattice's deformation (hierarchical B-splines), so only the head changes.
4. vtkFFDCoarsenLattice: that detailed deformation fitted back onto a 3x3x3 lattice by least squares (the script
   prints the residual: the detail a coarse lattice cannot hold).

Writes a PNG of each step and a contact sheet of the four. Run it with Debian's /usr/bin/python3, the built
package on PYTHONPATH and an X server (Xvfb will do):
    PYTHONPATH=build/lib/python3/dist-packages Utilities/with-display.sh /usr/bin/python3 Examples/Python/level_of_detail.py
"""
import argparse
import sys
from pathlib import Path

import numpy as np
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy
from vtkmodules.util.vtkConstants import VTK_INT
from vtkmodules.vtkCommonDataModel import vtkStructuredGrid, vtkUnstructuredGrid

# The demo's mesh reading, lattice motion and rendering (this folder is on sys.path when run as a script).
from deform_mesh import REPOSITORY, contact_sheet, read_mesh, render, union_bounds, vtkffd
from twist_lattice import twist_lattice

SIZE = (500, 500)
HEAD_RADIUS = 0.15  # of the bounding box's diagonal: the refined voxels whose centre is this near the head
PULL = 0.12  # of the diagonal: how far the detail pulls the muzzle forward
VIEW_AZIMUTH = 70.0  # degrees from +Z: the bear's face in profile


def parse_arguments():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--mesh", default="bear", help="a mesh of Testing/Data/Meshes or a .vtp file (default: bear)")
    parser.add_argument("--output-dir", type=Path, default=REPOSITORY / "build" / "demo" / "level_of_detail",
                        help="folder for the PNGs (default: build/demo/level_of_detail in the repository)")
    return parser.parse_args()


def points_of(data):
    return vtk_to_numpy(data.GetPoints().GetData()).astype(np.float64)


def frame_of(lattice):
    return vtk_to_numpy(lattice.GetFieldData().GetArray("FFDFrame")).reshape(4, 3)


def deformed(mesh, lattice):
    deform = vtkffd.vtkFFDDeform()
    deform.SetInputData(mesh)
    deform.SetLatticeData(lattice)
    deform.Update()
    return deform.GetOutput()


def head_voxels(lattice, mesh):
    """The (i, j, k) of the lattice's voxels whose centre lies within HEAD_RADIUS of the head (the centroid of the
    top 15% of the mesh's points: the bear stands along +Y)."""
    points = points_of(mesh)
    head = points[points[:, 1] >= np.quantile(points[:, 1], 0.85)].mean(axis=0)
    diagonal = np.linalg.norm(points.max(axis=0) - points.min(axis=0))
    origin, s_axis, t_axis, u_axis = frame_of(lattice)
    n = vtk_to_numpy(lattice.GetFieldData().GetArray("FFDDivisions"))
    ijk = np.stack(np.meshgrid(*(np.arange(v) for v in n), indexing="ij"), axis=-1).reshape(-1, 3)
    centres = origin + ((ijk + 0.5) / n) @ np.stack((s_axis, t_axis, u_axis))
    return ijk[np.linalg.norm(centres - head, axis=1) < HEAD_RADIUS * diagonal], head, diagonal


def pull_muzzle(detail, head, diagonal):
    """Moves the detail lattice's movable (Active) control points in front of the head forward (+Z: the bear faces
    +Z), most at the front, through a numpy view of its points."""
    points = vtk_to_numpy(detail.GetPoints().GetData())
    rest = vtk_to_numpy(detail.GetPointData().GetArray("RestPosition"))
    active = vtk_to_numpy(detail.GetPointData().GetArray("Active")) != 0
    ahead = np.clip((rest[:, 2] - head[2]) / (0.2 * diagonal), 0.0, 1.0)
    across = np.exp(-np.sum((rest[:, :2] - head[:2]) ** 2, axis=1) / (0.12 * diagonal) ** 2)
    pull = np.where(active, PULL * diagonal * ahead * across, 0.0)
    points[:, 2] += pull
    detail.GetPoints().Modified()
    return int((pull > 0).sum())


def main():
    args = parse_arguments()
    name, mesh = read_mesh(args.mesh)
    args.output_dir.mkdir(parents=True, exist_ok=True)

    # 1. A coarse lattice, deformed.
    voxelize = vtkffd.vtkFFDVoxelize()
    voxelize.SetInputData(mesh)
    voxelize.SetDivisions(3, 3, 3)
    build = vtkffd.vtkFFDBuildLattice()
    build.SetInputConnection(voxelize.GetOutputPort())
    build.SetBasisToCubicBSpline()
    build.SetLatticeFormToDense()  # twist_lattice reshapes the dense grid
    build.Update()
    coarse = vtkStructuredGrid()
    coarse.DeepCopy(build.GetOutput())
    twist_lattice(coarse)
    coarse_mesh = deformed(mesh, coarse)

    # 2. Refined exactly.
    refine = vtkffd.vtkFFDRefineLattice()
    refine.SetInputData(coarse)
    refine.Update()
    refined = vtkStructuredGrid()
    refined.DeepCopy(refine.GetOutput())
    refined_mesh = deformed(mesh, refined)
    difference = np.abs(points_of(refined_mesh) - points_of(coarse_mesh)).max()

    # 3. Detail over the head, added to the refined lattice.
    voxels, head, diagonal = head_voxels(refined, mesh)
    detail_filter = vtkffd.vtkFFDBuildDetailLattice()
    detail_filter.SetInputData(refined)
    detail_filter.SetSelectedVoxels(numpy_to_vtk(voxels.astype(np.int32), deep=True, array_type=VTK_INT))
    detail_filter.Update()
    detail = vtkUnstructuredGrid()
    detail.DeepCopy(detail_filter.GetOutput())
    pulled = pull_muzzle(detail, head, diagonal)
    levels = vtkffd.vtkFFDDeformBlocks()
    levels.SetCompositionToAdd()
    levels.SetInputData(mesh)
    levels.AddLatticeData(refined)
    levels.AddLatticeData(detail)
    levels.Update()
    detailed_mesh = levels.GetOutput()
    detail_motion = np.linalg.norm(points_of(detailed_mesh) - points_of(refined_mesh), axis=1)
    changed = detail_motion > 0

    # 4. Coarsened back onto 3x3x3, by least squares over the bear's points.
    coarsen = vtkffd.vtkFFDCoarsenLattice()
    coarsen.SetInputData(refined)  # the frame and the basis
    coarsen.SetMeshData(mesh)
    coarsen.SetDeformedMeshData(detailed_mesh)
    coarsen.SetDivisions(3, 3, 3)
    coarsen.Update()
    coarsened = coarsen.GetOutput()
    coarsened_mesh = deformed(mesh, coarsened)

    print(f"{name}: {mesh.GetNumberOfPoints()} vertices")
    print(f"1. coarse 3x3x3 cubic B-spline lattice: {coarse.GetNumberOfPoints()} control points, deformed")
    print(f"2. refined exactly to 6x6x6 ({refined.GetNumberOfPoints()} control points): largest difference "
          f"{difference:.1e} ({difference / diagonal:.1e} of the diagonal)")
    print(f"3. detail lattice over {len(voxels)} voxels near the head: {detail.GetNumberOfPoints()} control points "
          f"({int(vtk_to_numpy(detail.GetPointData().GetArray('Active')).sum())} movable), {pulled} pulled; "
          f"{int(changed.sum())} of {mesh.GetNumberOfPoints()} vertices changed, by up to {detail_motion.max():.3f}")
    print(f"4. coarsened to 3x3x3: residual {coarsen.GetResidualRMS():.2e} RMS, {coarsen.GetMaximumResidual():.2e} "
          f"at most ({coarsen.GetMaximumResidual() / diagonal:.1%} of the diagonal)")

    bounds = union_bounds(coarse_mesh, refined_mesh, detailed_mesh, coarsened_mesh)
    pngs = []
    for step, (shown, lattice) in enumerate(((coarse_mesh, coarse), (refined_mesh, refined), (detailed_mesh, detail),
                                             (coarsened_mesh, coarsened)), start=1):
        png = args.output_dir / f"{name}_level_of_detail_{step}.png"
        render(png, SIZE, shown, lattice, bounds, point_radius=0.004 * diagonal, azimuth=VIEW_AZIMUTH)
        pngs.append(png)
    sheet = args.output_dir / f"{name}_level_of_detail.png"
    contact_sheet(pngs, sheet, 4)
    print(f"wrote {len(pngs)} PNGs and {sheet}")

    if difference > 1e-12 * diagonal:
        sys.exit("the refined lattice should deform the mesh as the coarse one does")
    if not changed.any() or changed.all():
        sys.exit("the detail should change some of the mesh's points, not none and not all")
    if not 0.0 < coarsen.GetMaximumResidual():
        sys.exit("the coarse fit should lose some of the detail, and less than all of it")
    if coarsen.GetMaximumResidual() >= detail_motion.max():
        sys.exit("the coarse fit should keep some of the detail")


if __name__ == "__main__":
    main()
