# SPDX-License-Identifier: BSD-3-Clause
"""The command line `python3 -m vtkffd`: build a lattice around a mesh, deform a mesh by a lattice (or map it back),
describe or convert a lattice file. main() is its entry point; docs/interchange-and-files.md, "Command line", shows it
at work.

Meshes are read and written by vtkffd.meshio, lattices by vtkffd.interchange, each by its file's extension; a
write that fails leaves the file that was there. A user's mistake (a missing file, an unknown extension, a file
cut short or garbled, options that do not fit, a filter's error, a write that fails) ends in one line on stderr and
exit status 1 (2 for a usage error), never in a traceback.
"""
import argparse
import math
import sys

import numpy as np
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkCommonCore import reference, vtkCommand, vtkLogger, vtkOutputWindow
from vtkmodules.vtkCommonExecutionModel import vtkAlgorithm
from vtkmodules.vtkFiltersGeneral import vtkImageDataToPointSet

import vtkffd
from vtkffd import interchange, meshio

PROG = "python3 -m vtkffd"
Contract = vtkffd.vtkFFDDataContract
Build = vtkffd.vtkFFDBuildLattice
BASES = {  # --basis: the vtkFFDBuildLattice basis
    "bernstein": Build.BERNSTEIN,
    "trilinear": Build.TRILINEAR,
    "triquadratic": Build.TRIQUADRATIC_BEZIER,
    "tricubic": Build.TRICUBIC_BEZIER,
    "bspline": Build.CUBIC_BSPLINE,
}
FORMS = {"auto": Build.AUTOMATIC, "dense": Build.DENSE, "sparse": Build.SPARSE}
FRAMES = {"axis": vtkffd.vtkFFDVoxelize.AXIS_ALIGNED, "principal": vtkffd.vtkFFDVoxelize.PRINCIPAL_AXES}
OUTSIDE = {"keep": vtkffd.vtkFFDDeform.KEEP_POSITION, "clamp": vtkffd.vtkFFDDeform.CLAMP_TO_EDGE,
           "extrapolate": vtkffd.vtkFFDDeform.EXTRAPOLATE}
BACKENDS = {"auto": vtkffd.vtkFFDDeform.AUTOMATIC, "cpu": vtkffd.vtkFFDDeform.CPU, "cuda": vtkffd.vtkFFDDeform.CUDA}
MESH_FORMATS = " ".join(meshio.EXTENSIONS)
LATTICE_FORMATS = " ".join(interchange.LATTICE_EXTENSIONS)

DESCRIPTION = f"""\
Free-form deformation (FFD) bends, twists or dents a mesh by moving a few control points instead of its vertices.
The mesh is enclosed in a lattice of control points over the voxels that hold it; each mesh point is bound to
the lattice once, and moving control points moves the mesh points around them smoothly (every point for the
global Bernstein basis, only those near the moved control points for the local bases and tetrahedral lattices).

The pipeline: `build` writes the lattice around a mesh, at rest; move its points in any tool that edits the file
(ParaView, numpy, Blender through .vdb, PyGeM through .prm, ITK through .tfm); `deform` moves the mesh, or any
other inside the lattice, by it; `invert` takes a deformed mesh back to rest. `info` describes a lattice and
`convert` changes its format.

meshes: {MESH_FORMATS}; lattices: {LATTICE_FORMATS}."""

EXAMPLES = f"""\
examples:
  {PROG} build bear.off -o bear.vts --divisions 2 3 4
  {PROG} info bear.vts
  {PROG} deform bear.off bear_moved.vts -o bear_deformed.vtp
  {PROG} invert bear_deformed.vtp bear_moved.vts -o bear_back.vtp
  {PROG} convert bear_moved.vts -o bear_moved.prm
{PROG} COMMAND --help tells more of each."""


class CommandError(Exception):
    """A failure to report in one line (a VTK filter's error): exit status 1."""


class ProgressBar:
    """One filter's progress on stderr, from its ProgressEvents: a bar redrawn in place on a terminal, else a line
    at each quarter, so that a log gets a few lines rather than one per event."""

    WIDTH = 30

    def __init__(self, stream, label):
        self.stream, self.label = stream, label
        self.terminal = stream.isatty()
        self.quarter = -1

    def progress(self, algorithm, event):
        fraction = algorithm.GetProgress()
        if self.terminal:
            done = round(fraction * self.WIDTH)
            self.stream.write(f"\r{self.label:<14} [{'#' * done}{'.' * (self.WIDTH - done)}] {fraction:4.0%}")
        elif int(4 * fraction) > self.quarter:
            self.quarter = int(4 * fraction)
            self.stream.write(f"{self.label}: {25 * self.quarter}%\n")
        self.stream.flush()

    def end(self, algorithm, event):
        if self.terminal:
            self.stream.write("\n")


class Console:
    """What a command tells its user on stderr: a progress bar per filter and one-line summaries (neither with
    --quiet), VTK's warnings, and VTK's errors raised as one CommandError. VTK's errors and warnings are taken from
    every object of the process through vtkOutputWindow, instead of VTK's log of several lines each."""

    def __init__(self, quiet, stream=sys.stderr):
        self.quiet, self.stream = quiet, stream
        self.errors, self.warnings = meshio.VTKMessages(), meshio.VTKMessages()
        window = vtkOutputWindow.GetInstance()
        window.AddObserver(vtkCommand.ErrorEvent, self.errors)
        window.AddObserver(vtkCommand.WarningEvent, self.warnings)
        vtkLogger.SetStderrVerbosity(vtkLogger.VERBOSITY_OFF)  # else VTK's logger prints each message once more

    def say(self, text):
        if not self.quiet:
            print(text, file=self.stream)

    def check(self):
        """Writes the warnings VTK gave since the last check, and raises its first error."""
        for warning in self.warnings.messages:
            print(f"{PROG}: warning: {warning}", file=self.stream)
        self.warnings.messages.clear()
        if self.errors.first():
            raise CommandError(self.errors.first())

    def update(self, algorithm, label):
        """Updates `algorithm` under a progress bar labelled `label`, then check()s."""
        if not self.quiet:
            bar = ProgressBar(self.stream, label)
            algorithm.AddObserver(vtkCommand.ProgressEvent, bar.progress)
            algorithm.AddObserver(vtkCommand.EndEvent, bar.end)
        algorithm.Update()
        self.check()


def read_point_set(path):
    """The mesh in the file `path` as the vtkPointSet that the filters take: image data (.vti) as the structured
    grid of its points."""
    mesh = meshio.read_mesh(path)
    if not mesh.IsA("vtkImageData"):
        return mesh
    points = vtkImageDataToPointSet()
    points.SetInputData(mesh)
    points.Update()
    return points.GetOutput()


def check_frame(mesh, arguments):
    """Raises CommandError when the frame around the mesh's finite points, grown by the padding, has sides that
    float64 cannot hold (vtkFFDVoxelize would call it flat): the mesh's extent, or its largest side times
    1 + 2 padding (times sqrt(3), the most a principal-axes box can grow over the axis-aligned one)."""
    points = vtk_to_numpy(mesh.GetPoints().GetData()).astype(np.float64)
    points = points[np.all(np.isfinite(points), axis=1)]
    if not len(points):
        return  # vtkFFDVoxelize's error
    with np.errstate(over="ignore"):
        low, high = points.min(axis=0), points.max(axis=0)
        extent = high - low
        side = extent.max() * (1.0 + 2.0 * arguments.padding) * (math.sqrt(3.0) if arguments.frame == "principal"
                                                                 else 1.0)
    if not np.all(np.isfinite(extent)):
        raise CommandError(f"{arguments.mesh}: its points span from {low.tolist()} to {high.tolist()}, farther than "
                           "float64 holds a frame's sides: scale the mesh down")
    if not math.isfinite(side):
        raise CommandError(f"--padding {arguments.padding:g}: the frame's sides, {extent.max():g} grown by twice the "
                           "padding, overflow float64: give a smaller padding")


def build(arguments, console):
    interchange.lattice_extension(arguments.output)  # a lattice file: fail before the work
    mesh = read_point_set(arguments.mesh)
    if arguments.tetrahedral:
        builder = vtkffd.vtkFFDBuildTetrahedralLattice()
        builder.SetInputData(mesh)
        builder.SetPadding(arguments.padding)
        builder.SetSubdivisionLevels(arguments.levels)
        console.update(builder, "tetrahedra")
        lattice = builder.GetOutput()
        summary = (f"{lattice.GetNumberOfCells()} tetrahedra from a hull of {builder.GetNumberOfHullFaces()} "
                   f"triangles, {lattice.GetNumberOfPoints()} nodes ({builder.GetNumberOfActiveNodes()} active)")
    else:
        check_frame(mesh, arguments)
        voxelize = vtkffd.vtkFFDVoxelize()
        voxelize.SetInputData(mesh)
        voxelize.SetDivisions(*arguments.divisions)
        voxelize.SetFrameMode(FRAMES[arguments.frame])
        voxelize.SetPadding(arguments.padding)
        builder = Build()
        builder.SetInputConnection(voxelize.GetOutputPort())
        builder.SetBasis(BASES[arguments.basis])
        builder.SetLatticeForm(FORMS[arguments.form])
        console.update(voxelize, "voxelize")
        console.update(builder, "build lattice")
        lattice = builder.GetOutput()
        summary = (f"{arguments.basis} lattice ({'dense' if lattice.IsA('vtkStructuredGrid') else 'sparse'}), "
                   f"{lattice.GetNumberOfPoints()} control points ({builder.GetNumberOfActiveControlPoints()} "
                   f"active) over {voxelize.GetNumberOfActiveVoxels()} active voxels of "
                   f"{'x'.join(map(str, voxelize.GetDivisions()))}")
    interchange.write_lattice(lattice, arguments.output)
    console.check()
    console.say(f"{arguments.output}: {summary}")


def deform(arguments, console):
    mesh = read_point_set(arguments.mesh)
    meshio.check_format(mesh, arguments.output)  # the output is of the mesh's type: fail before the work
    lattice = interchange.read_lattice(arguments.lattice)
    console.check()
    deformer = vtkffd.vtkFFDDeform()
    deformer.SetInputData(mesh)
    deformer.SetLatticeData(lattice)
    deformer.SetOutsidePolicy(OUTSIDE[arguments.outside])
    deformer.SetBackend(BACKENDS[arguments.backend])
    if arguments.double:
        deformer.SetOutputPointsPrecision(vtkAlgorithm.DOUBLE_PRECISION)
    console.update(deformer, "deform")
    meshio.write_mesh(deformer.GetOutput(), arguments.output)
    console.check()
    console.say(f"{arguments.output}: {mesh.GetNumberOfPoints()} points deformed on the "
                f"{deformer.GetLastBackendUsed()}")


def invert(arguments, console):
    mesh = read_point_set(arguments.mesh)
    meshio.check_format(mesh, arguments.output)
    lattice = interchange.read_lattice(arguments.lattice)
    console.check()
    inverter = vtkffd.vtkFFDInverseDeform()
    inverter.SetInputData(mesh)
    inverter.SetLatticeData(lattice)
    if arguments.double:
        inverter.SetOutputPointsPrecision(vtkAlgorithm.DOUBLE_PRECISION)
    console.update(inverter, "invert")
    meshio.write_mesh(inverter.GetOutput(), arguments.output)
    console.check()
    failed = inverter.GetNumberOfFoldedPoints() + inverter.GetNumberOfUnconvergedPoints()
    console.say(f"{arguments.output}: {mesh.GetNumberOfPoints()} points back at rest"
                + (f", {failed} without a reliable rest position (the InverseStatus point array)" if failed else ""))


def describe(lattice):
    """The rows of `info` for a lattice that read_lattice() accepted: (name, value) pairs."""
    field, point_data = lattice.GetFieldData(), lattice.GetPointData()
    if field.GetArray(Contract.FrameArrayName()) is None:  # the data contract's tetrahedral lattice
        rows = [("kind", f"tetrahedral: a {lattice.GetClassName()} of {lattice.GetNumberOfCells()} tetrahedra")]
    else:
        if lattice.IsA("vtkStructuredGrid"):
            kind = f"grid, dense: a vtkStructuredGrid of {' x '.join(map(str, lattice.GetDimensions()))} points"
        else:
            kind = (f"grid, sparse: a {lattice.GetClassName()} of the active control points and "
                    f"{lattice.GetNumberOfCells()} cells, one per active voxel")
        basis, divisions, frame = reference(0), [0] * 3, [0.0] * 12
        rows = [("kind", kind),
                ("basis", name_of(BASES, int(basis), "malformed") if Contract.GetBasis(lattice, basis)
                 else "missing or malformed"),
                ("divisions", " x ".join(map(str, divisions)) if Contract.GetDivisions(lattice, divisions)
                 else "missing or malformed")]
        if Contract.GetFrame(lattice, frame):
            rows += [(name, " ".join(f"{v:.6g}" for v in vector))
                     for name, vector in zip(("frame origin", "frame S", "frame T", "frame U"), np.reshape(frame, (4, 3)))]
        else:
            rows.append(("frame", "malformed"))
    points = vtk_to_numpy(lattice.GetPoints().GetData()).astype(np.float64)
    displacement = points - vtk_to_numpy(point_data.GetArray(Contract.RestPositionArrayName()))
    lengths = np.linalg.norm(displacement, axis=1)
    active = point_data.GetArray(Contract.ActiveArrayName())
    rows += [("control points", str(len(points))),
             ("active", str(np.count_nonzero(vtk_to_numpy(active)) if active else len(points))),
             ("moved", str(np.count_nonzero(np.any(displacement != 0.0, axis=1)))),
             ("largest displacement", f"{lengths.max():.6g} (control point {lengths.argmax()})" if lengths.any()
              else "0")]
    if len(points):
        rows.append(("bounds", ", ".join(f"{axis} {low:.6g} .. {high:.6g}" for axis, low, high
                                         in zip("xyz", points.min(axis=0), points.max(axis=0)))))
    return rows


def info(arguments, console):
    lattice = interchange.read_lattice(arguments.lattice)
    console.check()
    for name, value in describe(lattice):
        print(f"{name:<22}{value}")


def convert(arguments, console):
    interchange.lattice_extension(arguments.output)  # fail before reading the input
    interchange.write_lattice(interchange.read_lattice(arguments.lattice), arguments.output)
    console.check()
    console.say(f"{arguments.output}: converted from {arguments.lattice}")


def name_of(choices, value, unknown=None):
    """The name of `value` among `choices` ({name: value}), or `unknown`."""
    return next((name for name, v in choices.items() if v == value), unknown)


def build_defaults(tetrahedral):
    """The build options' defaults: the settings of a new vtkFFDVoxelize and vtkFFDBuildLattice, or of a new
    vtkFFDBuildTetrahedralLattice."""
    if tetrahedral:
        tetrahedra = vtkffd.vtkFFDBuildTetrahedralLattice()
        return {"padding": tetrahedra.GetPadding(), "levels": tetrahedra.GetSubdivisionLevels()}
    voxelize, builder = vtkffd.vtkFFDVoxelize(), Build()
    return {"basis": name_of(BASES, builder.GetBasis()), "divisions": list(voxelize.GetDivisions()),
            "form": name_of(FORMS, builder.GetLatticeForm()), "frame": name_of(FRAMES, voxelize.GetFrameMode()),
            "padding": voxelize.GetPadding()}


INT_MAX = 2**31 - 1  # VTK's int settings (vtkFFDVoxelize's Divisions)


def positive_int(text):
    """A whole number, at least 1 and at most VTK's int (an argparse type)."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
    if not 1 <= value <= INT_MAX:
        raise argparse.ArgumentTypeError(f"{value}: at least 1 voxel per axis, at most {INT_MAX}")
    return value


def nonnegative_float(text):
    """A finite number, at least 0 (an argparse type)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not 0.0 <= value < math.inf:
        raise argparse.ArgumentTypeError(f"{value}: a finite number, at least 0")
    return value


def make_parser():
    """The argument parser: one subparser per command, each with its run function as `run`."""
    parser = argparse.ArgumentParser(prog=PROG, description=DESCRIPTION, epilog=EXAMPLES,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    commands = parser.add_subparsers(title="commands", metavar="COMMAND", dest="command", required=True)
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument("-q", "--quiet", action="store_true", help="no progress bar and no summary on stderr")

    def command(name, run, summary, description, examples):
        sub = commands.add_parser(name, help=summary, description=description, parents=[common],
                                  epilog="examples:\n" + "".join(f"  {PROG} {name} {e}\n" for e in examples),
                                  formatter_class=argparse.RawDescriptionHelpFormatter)
        sub.set_defaults(run=run, parser=sub)
        return sub

    grid, tetrahedral = build_defaults(False), build_defaults(True)  # None below: the option was not given
    sub = command("build", build, "write the control lattice around a mesh, at rest", """\
Encloses MESH in a frame divided into voxels, finds the voxels that hold its points and writes the control
lattice of a basis over them, at rest (each control point where it does not move the mesh): move its points,
then `deform`. The frame is a box around the mesh, grown by the padding on every side, along x, y, z or along
the mesh's principal axes. Control points per axis, for n voxels: bernstein n + 1 (the global FFD of Sederberg
and Parry: each control point moves the whole mesh), trilinear n + 1, triquadratic 2n + 1, tricubic 3n + 1
(Bezier patches per voxel), bspline n + 3 (uniform cubic B-spline, smooth to the second derivative); the local
bases move only the mesh points near a control point. A dense lattice (a .vts grid) holds every control point,
a sparse one (.vtu, .vdb) only those that influence a voxel of the mesh. With --tetrahedral, the lattice is
instead a control mesh of tetrahedra: the mesh's convex hull joined to its centroid.""", [
        "bear.off -o bear.vts                    # a global 5x5x5 Bernstein lattice",
        "bear.off -o bear.vtu --basis bspline --divisions 16",
        "cow.vtp -o cow.vtu --tetrahedral --levels 1"])
    sub.add_argument("mesh", metavar="MESH", help=f"the mesh ({MESH_FORMATS})")
    sub.add_argument("-o", "--output", metavar="LATTICE", required=True, help=f"the lattice ({LATTICE_FORMATS})")
    sub.add_argument("--basis", choices=BASES, help=f"the lattice's basis (default: {grid['basis']})")
    sub.add_argument("--divisions", type=positive_int, nargs="+", metavar="N",
                     help="voxels per axis: N for all three or NX NY NZ (default: "
                          f"{' '.join(map(str, grid['divisions']))})")
    sub.add_argument("--form", choices=FORMS, help="dense, sparse, or auto: sparse for the local bases, dense for "
                                                   f"bernstein (default: {grid['form']})")
    sub.add_argument("--frame", choices=FRAMES, help="the frame's axes: x, y, z (axis) or the mesh's principal "
                                                     f"axes (default: {grid['frame']})")
    sub.add_argument("--padding", type=nonnegative_float,
                     help=f"the frame's margin, a fraction of its largest side (default: {grid['padding']:g}); "
                          f"with --tetrahedral, of each hull node's distance to the centroid "
                          f"(default: {tetrahedral['padding']:g})")
    sub.add_argument("--tetrahedral", action="store_true", help="a control mesh of tetrahedra, not a grid")
    levels = vtkffd.vtkFFDBuildTetrahedralLattice()  # the range of its SubdivisionLevels
    sub.add_argument("--levels", type=int, choices=range(levels.GetSubdivisionLevelsMinValue(),
                                                         levels.GetSubdivisionLevelsMaxValue() + 1),
                     help=f"with --tetrahedral: times each tetrahedron is split into 8 "
                          f"(default: {tetrahedral['levels']})")

    sub = command("deform", deform, "deform a mesh by a lattice", """\
Moves each point of MESH by the deformation of LATTICE at it (the lattice's points minus their rest positions,
the point array RestPosition) and writes the result, of MESH's kind with its arrays and its point normals turned
with the deformation, to OUT.""", [
        "bear.off bear_moved.vts -o bear_deformed.vtp",
        "cow.vtp cow_moved.vtu -o cow_deformed.ply --outside extrapolate"])
    sub.add_argument("mesh", metavar="MESH", help=f"the mesh ({MESH_FORMATS})")
    sub.add_argument("lattice", metavar="LATTICE", help=f"the lattice ({LATTICE_FORMATS})")
    sub.add_argument("-o", "--output", metavar="OUT", required=True, help="the deformed mesh")
    sub.add_argument("--outside", choices=OUTSIDE, default="keep",
                     help="points outside the lattice: keep their position (the default), clamp (move as the "
                          "nearest point of the lattice), extrapolate (tetrahedral lattices: move with the nearest "
                          "tetrahedron)")
    sub.add_argument("--backend", choices=BACKENDS, default="auto",
                     help="where to compute: auto (a CUDA GPU where there is one, else the CPU; the default), cpu, "
                          "cuda (the CPU, with a warning, where CUDA cannot run)")
    sub.add_argument("--double", action="store_true", help="float64 points (default: the precision of MESH's)")

    sub = command("invert", invert, "map a deformed mesh back to rest", """\
Moves each point of MESH, a mesh in the deformed space, to the rest position that LATTICE deforms to it (the
inverse of `deform` with points outside the lattice kept): Newton's method on the lattice's own evaluation for
grid lattices, exact for tetrahedral ones. OUT gets an InverseStatus point array: 0 found, 1 where the
deformation folds, 2 not found.""", ["bear_deformed.vtp bear_moved.vts -o bear_back.vtp"])
    sub.add_argument("mesh", metavar="MESH", help=f"the deformed mesh ({MESH_FORMATS})")
    sub.add_argument("lattice", metavar="LATTICE", help=f"the lattice that deformed it ({LATTICE_FORMATS})")
    sub.add_argument("-o", "--output", metavar="OUT", required=True, help="the mesh at rest")
    sub.add_argument("--double", action="store_true", help="float64 points (default: the precision of MESH's)")

    sub = command("info", info, "describe a lattice", """\
Prints what LATTICE is: a grid (dense or sparse) or tetrahedral lattice, its basis, divisions and frame (origin
and edge vectors S, T, U), its control points (all; active: those that influence a voxel of the mesh; moved:
away from their rest positions), the largest displacement of a control point, and the bounds.""", ["bear.vts"])
    sub.add_argument("lattice", metavar="LATTICE", help=f"the lattice ({LATTICE_FORMATS})")

    sub = command("convert", convert, "write a lattice in another format", """\
Writes LATTICE, unchanged, in the format of OUT's extension: e.g. a lattice of this tool for Blender or Houdini
(.vdb), PyGeM (.prm) or ITK (.tfm), or one of theirs for `deform`.""", ["bear.vtu -o bear.vdb"])
    sub.add_argument("lattice", metavar="LATTICE", help=f"the lattice ({LATTICE_FORMATS})")
    sub.add_argument("-o", "--output", metavar="OUT", required=True, help="the converted lattice")
    return parser


def check_build(arguments):
    """Calls the usage error for build options that do not fit together, and fills in the defaults of the others."""
    parser = arguments.parser
    grid = [f"--{name}" for name in ("basis", "divisions", "form", "frame") if getattr(arguments, name) is not None]
    if arguments.tetrahedral and grid:
        parser.error(f"{', '.join(grid)}: for grid lattices, not with --tetrahedral")
    if arguments.tetrahedral and arguments.padding is not None:
        largest = vtkffd.vtkFFDBuildTetrahedralLattice().GetPaddingMaxValue()
        if arguments.padding > largest:
            parser.error(f"--padding: at most {largest:g} with --tetrahedral")
    if not arguments.tetrahedral and arguments.levels is not None:
        parser.error("--levels: for --tetrahedral lattices only")
    if arguments.divisions is not None and len(arguments.divisions) not in (1, 3):
        parser.error(f"--divisions: N or NX NY NZ, not {len(arguments.divisions)} numbers")
    if arguments.divisions is not None and len(arguments.divisions) == 1:
        arguments.divisions *= 3
    for name, value in build_defaults(arguments.tetrahedral).items():
        if getattr(arguments, name) is None:
            setattr(arguments, name, value)


def main(argv=None):
    """Runs the command line on `argv` (default: sys.argv[1:]); returns the exit status: 0, or 1 after an error
    (its message on stderr); a usage error exits with 2, as argparse does. VTK's errors and warnings of the whole
    process go to the command's messages from then on."""
    arguments = make_parser().parse_args(argv)
    if arguments.command == "build":
        check_build(arguments)
    console = Console(arguments.quiet)
    try:
        arguments.run(arguments, console)
    except (CommandError, ValueError) as error:
        print(f"{PROG}: error: {error}", file=sys.stderr)
        return 1
    except OSError as error:  # a file that cannot be opened, read or written
        print(f"{PROG}: error: {error.filename}: {error.strerror}" if error.filename else f"{PROG}: error: {error}",
              file=sys.stderr)
        return 1
    except MemoryError:  # what no size check foresaw
        print(f"{PROG}: error: out of memory running {arguments.command}", file=sys.stderr)
        return 1
    return 0
