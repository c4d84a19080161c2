# SPDX-License-Identifier: BSD-3-Clause
"""The README's demo in ParaView: the bear deformed by a global Bernstein lattice of 3x4x5 control points,
scripted with paraview.simple and the VoxelFFD plugin.

The same set-up as Examples/Python/deform_mesh.py (the paper's Figure 12): FFDVoxelize divides the bear's frame
into 2x3x4 voxels, FFDBuildLattice builds the Bernstein lattice of degree (2, 3, 4), a Programmable Filter moves
its control points (Examples/Python/twist_lattice.py: the top layer pulled up and twisted, the middle layers
bulged out) and FFDDeform deforms the bear. Two screenshots are written, the bear with its rest lattice and the
deformed bear with the moved lattice, and the figure-style caption is printed.

Run it with pvbatch (or pvpython) from Debian's paraview package, ParaView's Python modules on PYTHONPATH (as
Utilities/setup.sh test unpacks them) and an X display (Debian's ParaView renders through GLX; Xvfb will do):
    PYTHONPATH=build/paraview-prefix/usr/lib/python3/dist-packages \\
      Utilities/with-display.sh pvbatch Examples/ParaView/deform_mesh.py
Under MPI (`mpirun -np 2 pvbatch ...`) every process deforms its piece of the bear with the same lattice.
"""
import argparse
import sys
from pathlib import Path

import numpy as np
from paraview import servermanager
from paraview.simple import (
    ExtractEdges,
    GenerateSurfaceNormals,
    LoadPlugin,
    ProgrammableFilter,
    Render,
    SaveScreenshot,
    Show,
    CreateView,
    _DisableFirstRenderCameraReset,
    XMLPolyDataReader,
)

REPOSITORY = Path(__file__).resolve().parents[2]
PLUGIN = REPOSITORY / "build" / "paraview" / "lib" / "paraview-5.11" / "plugins" / "VoxelFFD" / "VoxelFFD.so"
DIVISIONS = (2, 3, 4)  # voxels per axis; the Bernstein degree per axis, so 3x4x5 control points
# The Programmable Filter's script: a copy of the lattice, moved by the Python demo's own function. It runs where
# the data is (every process under MPI), in pvbatch's Python.
MOVE_SCRIPT = """
import sys
sys.path.insert(0, {folder!r})
from twist_lattice import twist_lattice
lattice = self.GetOutputDataObject(0)
lattice.DeepCopy(self.GetInputDataObject(0, 0))
twist_lattice(lattice)
"""
# A Programmable Filter announces no extent of a structured output by itself: the lattice's, as ParaView's
# displays ask for pieces of it.
EXTENT_SCRIPT = """
executive = self.GetExecutive()
extent = executive.GetInputInformation(0, 0).Get(executive.WHOLE_EXTENT())
executive.GetOutputInformation(0).Set(executive.WHOLE_EXTENT(), extent, 6)
"""


def parse_arguments(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("mesh", nargs="?", default="bear",
                        help="a .vtp file, or the name of a mesh in Testing/Data/Meshes (default: bear)")
    parser.add_argument("--output-dir", type=Path, default=REPOSITORY / "build" / "demo" / "paraview",
                        help="folder for the screenshots (default: build/demo/paraview in the repository)")
    parser.add_argument("--size", type=int, nargs=2, default=(800, 800), metavar=("WIDTH", "HEIGHT"),
                        help="screenshot size in pixels (default: 800 800)")
    parser.add_argument("--plugin", type=Path, default=PLUGIN,
                        help="the VoxelFFD plugin (default: the one Utilities/setup.sh test builds)")
    return parser.parse_args(argv)


def mesh_path(name):
    path = Path(name)
    if path.suffix != ".vtp":
        path = REPOSITORY / "Testing" / "Data" / "Meshes" / f"{name}.vtp"
    if not path.is_file():
        sys.exit(f"{path} is missing: pass a .vtp file, or run Utilities/setup.sh to fetch the meshes")
    return path


def load_plugin(path):
    """Loads the VoxelFFD plugin into paraview.simple (FFDVoxelize, FFDBuildLattice, FFDDeform, ...)."""
    if not path.is_file():
        sys.exit(f"{path} is missing: build the plugin with Utilities/setup.sh test, or pass --plugin")
    LoadPlugin(str(path), ns=globals())


def build_pipeline(path):
    """The demo's pipeline; returns its proxies by name."""
    reader = XMLPolyDataReader(registrationName=path.stem, FileName=[str(path)])
    # Point normals give smooth shading; FFDDeform transforms them with the deformation.
    mesh = GenerateSurfaceNormals(registrationName="Normals", Input=reader, Splitting=0)
    voxels = FFDVoxelize(registrationName="Voxels", Input=mesh, Divisions=list(DIVISIONS))  # noqa: F821
    # Dense: a structured grid of 3x4x5 points, as twist_lattice reshapes it.
    lattice = FFDBuildLattice(registrationName="Lattice", Input=voxels, Basis="Bernstein",  # noqa: F821
                              LatticeForm="Dense")
    moved = ProgrammableFilter(registrationName="MovedLattice", Input=lattice,
                               Script=MOVE_SCRIPT.format(folder=str(REPOSITORY / "Examples" / "Python")),
                               RequestInformationScript=EXTENT_SCRIPT)
    deformed = FFDDeform(registrationName="Deformed", Input=mesh, Lattice=moved)  # noqa: F821
    return {"mesh": mesh, "voxels": voxels, "lattice": lattice, "moved": moved, "deformed": deformed}


def show_scene(view, mesh, lattice):
    """Shows a mesh (ivory) and a lattice (red control points, dark grey edges) in `view`; returns the displays."""
    mesh_display = solid(Show(mesh, view), [0.93, 0.90, 0.82])
    mesh_display.Representation = "Surface"
    mesh_display.Specular = 0.2
    mesh_display.SpecularPower = 20.0
    edge_display = solid(Show(ExtractEdges(Input=lattice), view), [0.25, 0.25, 0.25])
    edge_display.LineWidth = 2.0
    point_display = solid(Show(lattice, view), [0.85, 0.1, 0.1])
    point_display.Representation = "Points"
    point_display.RenderPointsAsSpheres = 1
    point_display.PointSize = 14.0
    return [mesh_display, edge_display, point_display]


def solid(display, colour):
    """`display` in one colour, not coloured by an array; returns it."""
    display.ColorArrayName = ["POINTS", ""]
    display.AmbientColor = display.DiffuseColor = colour
    return display


def frame_camera(view, bounds):
    """The Python demo's camera: looking along -Z, turned 30 degrees about Y and raised 15, fitted to bounds."""
    camera = view.GetActiveCamera()
    camera.SetFocalPoint(0.0, 0.0, 0.0)
    camera.SetPosition(0.0, 0.0, 1.0)
    camera.SetViewUp(0.0, 1.0, 0.0)
    camera.Azimuth(30.0)
    camera.Elevation(15.0)
    view.ResetCamera(*bounds)  # the same framing before and after
    camera.Zoom(1.25)
    _DisableFirstRenderCameraReset()  # else the first Render() frames the visible data itself


def statistic(proxy, name):
    """A statistic of a VoxelFFD filter's last update, a field array of its output: a number or a word."""
    array = proxy.FieldData[name]
    return array.GetStringValue(0) if array.GetNumberOfStringValues() else array.GetRange()[0]


def union_bounds(*proxies):
    # numpy's min and max: in pvbatch's single process a Programmable Filter's script runs in the namespace of
    # __main__, this module, and imports ParaView's array algorithms of those names into it.
    bounds = np.array([proxy.GetDataInformation().GetBounds() for proxy in proxies])
    return [float(v) for pair in zip(bounds[:, 0::2].min(axis=0), bounds[:, 1::2].max(axis=0)) for v in pair]


def new_view(size):
    view = CreateView("RenderView")
    view.ViewSize = list(size)
    view.OrientationAxesVisibility = 0
    view.UseColorPaletteForBackground = 0
    view.BackgroundColorMode = "Gradient"
    view.Background2 = [0.72, 0.76, 0.82]  # bottom: Background2 is ParaView's lower gradient colour
    view.Background = [0.98, 0.98, 0.99]
    return view


def main(argv):
    arguments = parse_arguments(argv)
    path = mesh_path(arguments.mesh)
    load_plugin(arguments.plugin)
    pipeline = build_pipeline(path)
    pipeline["deformed"].UpdatePipeline()

    arguments.output_dir.mkdir(parents=True, exist_ok=True)
    before_png = arguments.output_dir / f"{path.stem}_before.png"
    after_png = arguments.output_dir / f"{path.stem}_after.png"
    view = new_view(arguments.size)
    bounds = union_bounds(pipeline["mesh"], pipeline["lattice"], pipeline["deformed"], pipeline["moved"])
    displays = show_scene(view, pipeline["mesh"], pipeline["lattice"])
    frame_camera(view, bounds)
    Render(view)
    SaveScreenshot(str(before_png), view, ImageResolution=list(arguments.size))
    for display in displays:
        display.Visibility = 0
    show_scene(view, pipeline["deformed"], pipeline["moved"])
    Render(view)
    SaveScreenshot(str(after_png), view, ImageResolution=list(arguments.size))

    # The lattice is the same on every process: its counts are those of the first one's copy.
    lattice = servermanager.Fetch(pipeline["moved"], 0)
    dimensions = [0, 0, 0]
    lattice.GetDimensions(dimensions)
    n_i, n_j, n_k = dimensions
    mesh_points = pipeline["mesh"].GetDataInformation().GetNumberOfPoints()
    print(f"{path.stem}: {mesh_points} vertices, {lattice.GetNumberOfPoints()} control points "
          f"({n_i}x{n_j}x{n_k}), {statistic(pipeline['voxels'], 'NumberOfActiveVoxels'):.0f} active voxels, "
          f"{statistic(pipeline['lattice'], 'NumberOfActiveControlPoints'):.0f} active control points "
          f"(deformed on the {statistic(pipeline['deformed'], 'LastBackendUsed')})")
    print(f"wrote {before_png} and {after_png}")


if __name__ == "__main__":
    main(sys.argv[1:])
