#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""A magnetic sphere orbits the bear and pulls its simulated lattice: the paper's Figure 1.

The bear in a 5x5x5-voxel trilinear lattice (216 control points, of which the active ones are simulated by
vtkFFDLatticeDynamics: penalty springs to all 26 neighbours, a rigid core, masses from the mesh's points; the
bottom layer pinned, as the bear sits). A vtkFFDMagneticSphere circles the bear and pulls the control points
near it; every frame advances the simulation by two steps and deforms the mesh. Interactive by default: a window
where the lattice widget drags control points too (pinned while dragged, the simulation pulling the rest after
them; q quits). --offscreen --frames N writes N PNGs and a contact sheet instead. Both print the Figure 1
caption statistics and the time per frame (simulation, deformation, render).

Run it with Debian's /usr/bin/python3 (which has VTK's Python), the built package on PYTHONPATH and an X server
(Xvfb will do), as Utilities/setup.sh does:
    PYTHONPATH=build/lib/python3/dist-packages Utilities/with-display.sh /usr/bin/python3 \\
        Examples/Python/magnetic_sphere.py --offscreen --frames 24
"""
import argparse
import math
import statistics
import sys
import time
from pathlib import Path

from vtkmodules.vtkCommonCore import vtkCommand, vtkIdList, vtkPoints
from vtkmodules.vtkCommonDataModel import vtkStructuredGrid
from vtkmodules.vtkFiltersSources import vtkSphereSource
from vtkmodules.vtkIOImage import vtkPNGWriter
from vtkmodules.vtkInteractionStyle import vtkInteractorStyleTrackballCamera
from vtkmodules.vtkRenderingCore import (
    vtkActor,
    vtkInteractorObserver,
    vtkPolyDataMapper,
    vtkRenderer,
    vtkRenderWindow,
    vtkRenderWindowInteractor,
    vtkWindowToImageFilter,
)
import vtkmodules.vtkRenderingOpenGL2  # noqa: F401  (the OpenGL implementations of the rendering classes)

# The mesh reading of the demo (this folder is on sys.path when run as a script).
from deform_mesh import REPOSITORY, contact_sheet, read_mesh, vtkffd

DIVISIONS = 5  # voxels per axis: 6x6x6 = 216 control points, as in the paper's Figure 1
PERIOD = 4.0  # seconds for one orbit of the sphere
STEPS_PER_FRAME = 2  # simulation steps of 1/60 s per rendered frame (30 frames a second of simulated time)
SHEET_COLUMNS = 4
STRENGTH = 50.0  # the sphere's pull at its surface (an acceleration; the lattice keeps its default springs)


def parse_arguments():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--offscreen", action="store_true", help="render without a window: PNGs and a contact sheet")
    parser.add_argument("--frames", type=int, default=120, help="frames to render (default 120: one orbit)")
    parser.add_argument("--output-dir", type=Path, default=REPOSITORY / "build" / "magnetic_sphere",
                        help="folder of the PNGs with --offscreen (default: build/magnetic_sphere)")
    parser.add_argument("--size", type=int, nargs=2, default=(640, 640), metavar=("WIDTH", "HEIGHT"))
    arguments = parser.parse_args()
    if arguments.frames < 1:
        parser.error("--frames needs at least one frame")
    return arguments


def orbit(bounds, radius_factor=0.6):
    """16 points on a circle around the mesh, in the horizontal plane through its middle (CGAL's meshes stand
    along +Y)."""
    centre = [(bounds[2 * a] + bounds[2 * a + 1]) / 2 for a in range(3)]
    size = max(bounds[1] - bounds[0], bounds[3] - bounds[2], bounds[5] - bounds[4])
    path = vtkPoints()
    for i in range(16):
        angle = 2 * math.pi * i / 16
        path.InsertNextPoint(centre[0] + radius_factor * size * math.cos(angle), centre[1],
                             centre[2] + radius_factor * size * math.sin(angle))
    return path, size


def scripted_drag(interactor, renderer, lattice, dynamics, seated, frame):
    """Drags the top simulated control point nearest the view's centre 60 pixels right in three moves, a frame
    of simulation after each: the point must stay where the widget put it (pinned) while the simulation runs,
    and follow the simulation again once released."""
    candidates = [p for p in range(lattice.GetNumberOfPoints()) if dynamics.GetMass(p) > 0 and p not in seated]
    chosen = max(candidates, key=lambda p: lattice.GetPoint(p)[1])
    display = [0.0, 0.0, 0.0]
    vtkInteractorObserver.ComputeWorldToDisplay(renderer, *lattice.GetPoint(chosen), display)
    x, y = round(display[0]), round(display[1])
    start = lattice.GetPoint(chosen)
    for px, event in ((x, vtkCommand.MouseMoveEvent), (x, vtkCommand.LeftButtonPressEvent)):
        interactor.SetEventInformation(px, y, 0, 0)
        interactor.InvokeEvent(event)
    for move in range(1, 4):
        interactor.SetEventInformation(x + 20 * move, y, 0, 0)
        interactor.InvokeEvent(vtkCommand.MouseMoveEvent)
        put = lattice.GetPoint(chosen)
        frame()
        if math.dist(put, lattice.GetPoint(chosen)) > 1e-12 * (1 + math.dist(put, (0, 0, 0))):
            sys.exit(f"dragged control point {chosen} did not stay where the widget put it")
    interactor.SetEventInformation(x + 60, y, 0, 0)
    interactor.InvokeEvent(vtkCommand.LeftButtonReleaseEvent)
    put = lattice.GetPoint(chosen)
    frame()
    if dynamics.GetNumberOfPinnedPoints() != len(seated) or lattice.GetPoint(chosen) == put:
        sys.exit("the dragged control point stayed pinned after its release")
    print(f"dragged control point {chosen} by {math.dist(start, put):.3g}: pinned while dragged, free after")


def main():
    arguments = parse_arguments()
    _, mesh = read_mesh("bear")  # with point normals for smooth shading; vtkFFDDeform transforms them

    voxelize = vtkffd.vtkFFDVoxelize()
    voxelize.SetInputData(mesh)
    voxelize.SetDivisions(DIVISIONS, DIVISIONS, DIVISIONS)
    build = vtkffd.vtkFFDBuildLattice()
    build.SetInputConnection(voxelize.GetOutputPort())
    build.SetBasisToTrilinear()
    build.SetLatticeFormToDense()  # all 216 control points, culled ones hidden, as in the figure
    build.Update()
    lattice = vtkStructuredGrid()  # our copy, moved by the simulation
    lattice.DeepCopy(build.GetOutput())

    path, size = orbit(mesh.GetBounds())
    sphere = vtkffd.vtkFFDMagneticSphere()
    sphere.SetPath(path)
    sphere.SetPeriod(PERIOD)
    sphere.SetRadius(0.1 * size)
    sphere.SetStrength(STRENGTH)
    sphere.SetFalloff(2.0)
    sphere.SetRange(0.6 * size)  # only the control points near it feel it

    dynamics = vtkffd.vtkFFDLatticeDynamics()
    dynamics.SetLattice(lattice)
    dynamics.SetMesh(mesh)
    dynamics.AddMagneticSphere(sphere)
    if not dynamics.Initialize():
        sys.exit("the lattice could not be simulated (see the errors above)")
    # The bear sits: its lowest layer of control points is pinned where it rests, so the sphere's pull squishes
    # the body instead of carrying it away.
    n_i, n_j, n_k = lattice.GetDimensions()
    seated = {}  # the bottom layer's pins: point id -> target
    for k in range(n_k):
        for i in range(n_i):
            point = i + n_i * n_j * k  # j = 0: the bottom layer (CGAL's meshes stand along +Y)
            if dynamics.GetMass(point) > 0:
                seated[point] = lattice.GetPoint(point)
                dynamics.PinPoint(point, seated[point])

    deform = vtkffd.vtkFFDDeform()
    deform.SetInputData(mesh)
    deform.SetLatticeData(lattice)

    mesh_mapper = vtkPolyDataMapper()
    mesh_mapper.SetInputConnection(deform.GetOutputPort())
    mesh_actor = vtkActor()
    mesh_actor.SetMapper(mesh_mapper)
    mesh_actor.GetProperty().SetColor(0.80, 0.62, 0.42)
    mesh_actor.GetProperty().SetSpecular(0.2)
    mesh_actor.GetProperty().SetSpecularPower(20)
    ball = vtkSphereSource()
    ball.SetRadius(sphere.GetRadius())
    ball.SetThetaResolution(32)
    ball.SetPhiResolution(32)
    ball_mapper = vtkPolyDataMapper()
    ball_mapper.SetInputConnection(ball.GetOutputPort())
    ball_actor = vtkActor()
    ball_actor.SetMapper(ball_mapper)
    ball_actor.GetProperty().SetColor(0.15, 0.35, 0.85)

    renderer = vtkRenderer()
    for actor in (mesh_actor, ball_actor):  # the lattice widget below draws the lattice
        renderer.AddActor(actor)
    renderer.GradientBackgroundOn()
    renderer.SetBackground(0.72, 0.76, 0.82)
    renderer.SetBackground2(0.98, 0.98, 0.99)
    camera = renderer.GetActiveCamera()
    camera.SetPosition(0.0, 0.6, 1.0)
    camera.SetFocalPoint(0.0, 0.0, 0.0)
    camera.SetViewUp(0.0, 1.0, 0.0)
    bounds = list(mesh.GetBounds())
    for a in (0, 2):  # the orbit's extent in X and Z
        middle = (bounds[2 * a] + bounds[2 * a + 1]) / 2
        bounds[2 * a], bounds[2 * a + 1] = middle - 0.7 * size, middle + 0.7 * size
    renderer.ResetCamera(bounds)
    camera.Zoom(1.5)

    window = vtkRenderWindow()
    window.SetSize(*arguments.size)
    window.AddRenderer(renderer)
    window.SetOffScreenRendering(1 if arguments.offscreen else 0)

    times = {"simulation": [], "deformation": [], "render": []}
    before = [lattice.GetPoint(p) for p in range(lattice.GetNumberOfPoints())]

    def frame():
        start = time.perf_counter()
        dynamics.Step(STEPS_PER_FRAME)
        ball.SetCenter(*centre_at(dynamics.GetTime()))
        times["simulation"].append(time.perf_counter() - start)
        start = time.perf_counter()
        deform.Update()
        times["deformation"].append(time.perf_counter() - start)
        start = time.perf_counter()
        window.Render()
        times["render"].append(time.perf_counter() - start)

    def centre_at(t):
        centre = [0.0, 0.0, 0.0]
        sphere.GetCenterAt(t, centre)
        return centre

    ball.SetCenter(*centre_at(0.0))
    print(f"bear: {mesh.GetNumberOfPoints()} graphical vertices, {lattice.GetNumberOfPoints()} control points "
          f"({n_i}x{n_j}x{n_k}) - with {voxelize.GetNumberOfActiveVoxels()} voxels active or "
          f"{build.GetNumberOfActiveControlPoints()} control points; {dynamics.GetNumberOfSimulatedPoints()} "
          f"simulated, {dynamics.GetNumberOfSprings()} springs")

    # The lattice widget drags control points: while dragged they are pinned where the widget puts them, and the
    # simulation pulls the rest of the body after them.
    interactor = vtkRenderWindowInteractor()
    interactor.SetRenderWindow(window)
    interactor.SetInteractorStyle(vtkInteractorStyleTrackballCamera())
    widget = vtkffd.vtkFFDLatticeWidget()
    widget.SetInteractor(interactor)
    widget.CreateDefaultRepresentation()
    representation = widget.GetLatticeRepresentation()
    representation.SetLattice(lattice)
    representation.GetLatticeActor().SetPointRadius(0.012 * size)
    dragged = set()

    def pin_selection(*_):
        release()
        selected = vtkIdList()
        representation.GetSelectedControlPoints(selected)
        for index in range(selected.GetNumberOfIds()):
            point = selected.GetId(index)
            if dynamics.GetMass(point) > 0:
                dynamics.PinPoint(point, lattice.GetPoint(point))
                dragged.add(point)

    def release(*_):
        for point in dragged:
            if point in seated:  # a dragged seated point stays where it was put
                seated[point] = lattice.GetPoint(point)
                dynamics.PinPoint(point, seated[point])
            else:
                dynamics.UnpinPoint(point)
        dragged.clear()

    widget.AddObserver("InteractionEvent", pin_selection)
    widget.AddObserver("EndInteractionEvent", release)
    widget.On()

    if arguments.offscreen:
        arguments.output_dir.mkdir(parents=True, exist_ok=True)
        grabber = vtkWindowToImageFilter()
        grabber.SetInput(window)
        writer = vtkPNGWriter()
        writer.SetInputConnection(grabber.GetOutputPort())
        pngs = []
        for index in range(arguments.frames):
            frame()
            grabber.Modified()
            pngs.append(arguments.output_dir / f"frame_{index:04d}.png")
            writer.SetFileName(str(pngs[-1]))
            writer.Write()
        step = max(1, len(pngs) // 12)
        sheet = arguments.output_dir / "contact_sheet.png"
        contact_sheet(pngs[step - 1::step][:12], sheet, SHEET_COLUMNS)
        print(f"wrote {len(pngs)} frames and {sheet}")
        scripted_drag(interactor, renderer, lattice, dynamics, seated, frame)
    else:
        interactor.Initialize()
        interactor.AddObserver("TimerEvent", lambda *_: frame())
        interactor.CreateRepeatingTimer(1000 // 30)
        window.SetWindowName("VoxelFFD: a magnetic sphere pulls the lattice; drag control points to pin them")
        window.Render()
        interactor.Start()

    moved = max(math.dist(before[p], lattice.GetPoint(p)) for p in range(lattice.GetNumberOfPoints()))
    if times["simulation"]:
        print(f"per frame ({len(times['simulation'])} frames, {STEPS_PER_FRAME} steps of "
              f"{dynamics.GetTimeStep() * 1e3:.1f} ms each), median: "
              + ", ".join(f"{name} {statistics.median(values) * 1e3:.2f} ms" for name, values in times.items()))
        print(f"largest control point motion: {moved / size:.3f} of the mesh's size")
    if arguments.offscreen and not 0.01 * size < moved < size:
        sys.exit(f"the sphere moved the lattice by {moved:.3g}, not a visible but sane amount")


if __name__ == "__main__":
    main()
