#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""Deforms a real mesh interactively: drag the control points of its lattice with vtkFFDLatticeWidget.

The bear (or --mesh) in a TRILINEAR lattice of 5x5x5 voxels (--basis for another local basis), with the active
voxels drawn as boxes and the culled control points grey. In the window:
    left button on a control point   select it and drag it; the mesh follows (only the evaluation re-runs)
    Shift + left button              add a control point to the selection (or remove it), then drag them all
    x                                reset the lattice to its rest position
    Escape                           clear the selection
    anything else                    the camera (trackball), as in any VTK window

With --offscreen no window opens: the script drags the control point nearest to the mesh's rightmost point by
synthesised mouse events, as a user would, writes a PNG (--output) and prints how far the control point and
the mesh moved. It fails (exit status 1) when the drag moved nothing or re-bound the mesh.

Run it with Debian's /usr/bin/python3, the built package on PYTHONPATH and an X server (Xvfb will do):
    PYTHONPATH=build/lib/python3/dist-packages /usr/bin/python3 Examples/Python/interactive_lattice.py
    PYTHONPATH=build/lib/python3/dist-packages Utilities/with-display.sh \\
        /usr/bin/python3 Examples/Python/interactive_lattice.py --offscreen --output build/demo/interactive.png
"""
import argparse
import sys
from pathlib import Path

import numpy as np
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkCommonCore import vtkCommand
from vtkmodules.vtkCommonDataModel import vtkStructuredGrid
from vtkmodules.vtkInteractionStyle import vtkInteractorStyleTrackballCamera
from vtkmodules.vtkIOImage import vtkPNGWriter
from vtkmodules.vtkRenderingCore import (vtkActor, vtkInteractorObserver, vtkRenderer,
                                         vtkRenderWindow, vtkRenderWindowInteractor, vtkWindowToImageFilter)
import vtkmodules.vtkRenderingOpenGL2  # noqa: F401  (the OpenGL render window)

# The mesh reading and the bases' names of the demo (this folder is on sys.path when run as a script).
from deform_mesh import BASES, read_mesh, vtkffd

DIVISIONS = (5, 5, 5)  # the paper's Figure 1: 6x6x6 = 216 control points around the bear


def parse_arguments():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--mesh", default="bear", help="a mesh name of Testing/Data/Meshes or a .vtp file")
    parser.add_argument("--basis", choices=[name for name in BASES if name != "bernstein"], default="trilinear",
                        help="the local basis (default: trilinear)")
    parser.add_argument("--offscreen", action="store_true",
                        help="no window: perform a scripted drag and write a PNG")
    parser.add_argument("--output", type=Path, default=Path("interactive_lattice.png"),
                        help="the PNG written with --offscreen")
    return parser.parse_args()


def build_scene(mesh, basis):
    voxelize = vtkffd.vtkFFDVoxelize()
    voxelize.SetInputData(mesh)
    voxelize.SetDivisions(*DIVISIONS)
    build = vtkffd.vtkFFDBuildLattice()
    build.SetInputConnection(voxelize.GetOutputPort())
    getattr(build, BASES[basis])()
    build.SetLatticeFormToDense()  # the form the widget draws and drags
    build.Update()
    lattice = vtkStructuredGrid()  # our own copy: the widget moves its points in place
    lattice.DeepCopy(build.GetOutput())

    deform = vtkffd.vtkFFDDeform()
    deform.SetInputData(mesh)
    deform.SetLatticeData(lattice)
    # Draws from the CUDA device where the window's OpenGL context is on it (GPU-GL interop), else from the host.
    mapper = vtkffd.vtkFFDInteropPolyDataMapper()
    mapper.SetInputConnection(deform.GetOutputPort())
    actor = vtkActor()
    actor.SetMapper(mapper)
    actor.GetProperty().SetColor(0.93, 0.9, 0.8)
    print(f"{mesh.GetNumberOfPoints()} vertices, {lattice.GetNumberOfPoints()} control points, "
          f"{voxelize.GetNumberOfActiveVoxels()} active voxels, {build.GetNumberOfActiveControlPoints()} "
          f"active control points ({basis})")
    return voxelize, lattice, deform, actor


def scripted_drag(interactor, renderer, lattice, mesh):
    """Presses on the active control point nearest to the mesh's rightmost point, drags it 80 pixels right
    and 40 up in four moves, releases; returns its id."""
    points = vtk_to_numpy(lattice.GetPoints().GetData())
    active = vtk_to_numpy(lattice.GetPointData().GetArray("Active"))
    target = vtk_to_numpy(mesh.GetPoints().GetData())[:, 0].argmax()
    distance = np.linalg.norm(points - mesh.GetPoint(int(target)), axis=1)
    distance[active == 0] = np.inf
    chosen = int(distance.argmin())
    display = [0.0, 0.0, 0.0]
    vtkInteractorObserver.ComputeWorldToDisplay(renderer, *points[chosen], display)
    x, y = round(display[0]), round(display[1])
    steps = [(x, y, vtkCommand.MouseMoveEvent), (x, y, vtkCommand.LeftButtonPressEvent)]
    steps += [(x + 20 * i, y + 10 * i, vtkCommand.MouseMoveEvent) for i in range(1, 5)]
    steps += [(x + 80, y + 40, vtkCommand.LeftButtonReleaseEvent)]
    for px, py, event in steps:
        interactor.SetEventInformation(px, py, 0, 0)
        interactor.InvokeEvent(event)
    return chosen


def main():
    args = parse_arguments()
    _, mesh = read_mesh(args.mesh)
    voxelize, lattice, deform, mesh_actor = build_scene(mesh, args.basis)

    renderer = vtkRenderer()
    renderer.AddActor(mesh_actor)
    renderer.SetBackground(1.0, 1.0, 1.0)
    window = vtkRenderWindow()
    window.SetSize(700, 700)
    window.SetWindowName("VoxelFFD: drag the control points (x resets, Escape clears the selection)")
    window.AddRenderer(renderer)
    if args.offscreen:
        window.SetOffScreenRendering(1)
        window.SetMultiSamples(0)
    interactor = vtkRenderWindowInteractor()
    interactor.SetRenderWindow(window)
    interactor.SetInteractorStyle(vtkInteractorStyleTrackballCamera())

    widget = vtkffd.vtkFFDLatticeWidget()
    widget.SetInteractor(interactor)
    widget.CreateDefaultRepresentation()
    representation = widget.GetLatticeRepresentation()
    representation.SetLattice(lattice)
    representation.GetLatticeActor().SetVoxelGridConnection(voxelize.GetOutputPort())
    representation.GetLatticeActor().ColorByDisplacementOn()  # dragged points turn from blue to red
    widget.On()

    camera = renderer.GetActiveCamera()
    camera.SetPosition(0.0, 0.0, 1.0)  # CGAL's meshes stand along +Y and face +Z
    camera.SetViewUp(0.0, 1.0, 0.0)
    camera.Azimuth(20.0)
    camera.Elevation(15.0)
    renderer.ResetCamera(lattice.GetBounds())
    window.Render()

    if not args.offscreen:
        interactor.Start()
        return 0

    before = vtk_to_numpy(lattice.GetPoints().GetData()).copy()
    chosen = scripted_drag(interactor, renderer, lattice, mesh)
    window.Render()
    moved = np.linalg.norm(vtk_to_numpy(lattice.GetPoints().GetData()) - before, axis=1)
    deform.Update()
    mesh_motion = np.linalg.norm(vtk_to_numpy(deform.GetOutput().GetPoints().GetData()) -
                                 vtk_to_numpy(mesh.GetPoints().GetData()), axis=1)
    print(f"dragged control point {chosen} by {moved[chosen]:.4g} ({np.count_nonzero(moved)} control point moved); "
          f"mesh points: {np.count_nonzero(mesh_motion)} moved, by up to {mesh_motion.max():.4g}; "
          f"bindings: {deform.GetNumberOfBindings()}")
    args.output.parent.mkdir(parents=True, exist_ok=True)
    image = vtkWindowToImageFilter()
    image.SetInput(window)
    writer = vtkPNGWriter()
    writer.SetFileName(str(args.output))
    writer.SetInputConnection(image.GetOutputPort())
    writer.Write()
    print(f"wrote {args.output}")
    ok = (np.count_nonzero(moved) == 1 and moved[chosen] > 0.0 and 0 < np.count_nonzero(mesh_motion) < len(mesh_motion)
          and deform.GetNumberOfBindings() == 1 and args.output.is_file())
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
