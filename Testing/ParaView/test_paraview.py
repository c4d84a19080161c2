#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""The ParaView plugin in ParaView's own programs, against this build's vtkffd (Debian's VTK 9.1).

- pvbatch runs the pipeline of paraview_pipeline.py (voxelize with principal axes, a sparse cubic B-spline lattice
  moved by a Programmable Filter, deform; a subdivided tetrahedral lattice, moved, deform with Extrapolate) on
  the bear, and every output equals, bit for bit, the same pipeline built here with vtkffd: the plugin compiles
  the same sources against ParaView's VTK 9.2, and nothing in them depends on the VTK or the thread count.
- mpirun -np 2 and 3 pvbatch: the mesh split among the processes by RedistributeDataSet, the points that pieces
  share marked by GenerateGlobalIds; the voxel grid and the lattices that the first process holds, and the
  deformed pieces of every process (each point found by its id), equal pvbatch's single-process outputs bit for
  bit. The ParaView demo on 2 processes reads and deforms the bear once.
- pvbatch plays simulation_pipeline.py: FFDDeform under FFD Simulate Lattice follows the simulated lattice at each
  time, asked by UpdatePipeline(time) and by the animation scene; every output equals vtkffd's, bit for bit.
- pvpython loads the plugin and runs a filter; the GUI (paraview --plugins) loads it and builds the pipeline
  from a script, in an X display.

ctest passes the programs and paths in the environment (Testing/ParaView/CMakeLists.txt); run one part with -k.
"""
import json
import os
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

import numpy as np
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkCommonDataModel import vtkPlane, vtkUnstructuredGrid
from vtkmodules.vtkIOXML import vtkXMLGenericDataObjectReader

import vtkffd

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from lattice_moves import move_control_points  # noqa: E402  (the same folder)

PLUGIN = os.environ.get("VOXELFFD_PARAVIEW_PLUGIN", "")
PVBATCH = os.environ.get("VOXELFFD_PVBATCH", "pvbatch")
PVPYTHON = os.environ.get("VOXELFFD_PVPYTHON", "pvpython")
PARAVIEW = os.environ.get("VOXELFFD_PARAVIEW_GUI", "paraview")
MESH = Path(os.environ.get("VOXELFFD_MESH_DIR", HERE.parents[1] / "Testing" / "Data" / "Meshes")) / "bear.vtp"
TIMEOUT = 300  # seconds a ParaView program may take here (a few seconds each when all is well)


def paraview_environment():
    """ParaView's Python modules instead of Debian's VTK ones, whose libraries a ParaView process must not load.
    pvpython looks for its modules beside the libraries it loaded: ParaView's prefix's, on LD_LIBRARY_PATH."""
    environment = dict(os.environ)
    environment["PYTHONPATH"] = os.environ["VOXELFFD_PARAVIEW_PYTHONPATH"]
    environment["LD_LIBRARY_PATH"] = os.environ["VOXELFFD_PARAVIEW_LIBRARY_PATH"]
    environment.pop("LD_PRELOAD", None)
    # Open MPI as root in a container: allowed, and several processes on fewer cores.
    environment.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
                       OMPI_MCA_rmaps_base_oversubscribe="1", OMPI_MCA_btl_vader_single_copy_mechanism="none")
    return environment


def run(command, expected_errors=(), **kwargs):
    """Runs a ParaView program; fails on its exit status and on any error it reports that does not name one of
    `expected_errors` (ParaView reports a failing filter, proxy or property on stderr and goes on)."""
    result = subprocess.run([str(part) for part in command], env=paraview_environment(), capture_output=True,
                            text=True, timeout=TIMEOUT, **kwargs)
    output = result.stdout + result.stderr
    if result.returncode != 0:
        raise AssertionError(f"{command[0]} failed ({result.returncode}):\n{output}")
    for line in output.splitlines():
        # vtkLogger's form ("ERR|") and vtkOutputWindow's ("ERROR:"), and the executive's echo of a failed request.
        error = "ERROR" in line or " ERR| " in line or "Traceback" in line
        if error and not any(expected in line for expected in expected_errors + ("returned failure for request",)):
            raise AssertionError(f"{command[0]} reported an error:\n{output}")
    return output


def read(path):
    reader = vtkXMLGenericDataObjectReader()
    reader.SetFileName(str(path))
    reader.Update()
    return reader.GetOutput()


def points(data):
    return vtk_to_numpy(data.GetPoints().GetData())


def array(data, name, where="point"):
    attributes = {"point": data.GetPointData, "field": data.GetFieldData, "cell": data.GetCellData}[where]()
    found = attributes.GetArray(name)
    if found is None:
        raise AssertionError(f"no {where} array {name}")
    return vtk_to_numpy(found)


def cells(data):
    if data.IsA("vtkUnstructuredGrid"):
        return vtk_to_numpy(data.GetCells().GetConnectivityArray()), vtk_to_numpy(data.GetCellTypesArray())
    if data.IsA("vtkPolyData"):
        return vtk_to_numpy(data.GetPolys().GetConnectivityArray()), np.zeros(0)
    return np.array(data.GetDimensions()), np.zeros(0)


def moved_and_deformed(mesh, lattice_filter, extrapolate=False):
    """A copy of `lattice_filter`'s output moved by lattice_moves.py, as pvbatch's Programmable Filter moves it,
    and `mesh` deformed by it (Extrapolate outside where asked)."""
    lattice_filter.Update()
    lattice = vtkUnstructuredGrid()
    lattice.DeepCopy(lattice_filter.GetOutput())
    move_control_points(lattice)
    deform = vtkffd.vtkFFDDeform()
    deform.SetInputData(mesh)
    deform.SetLatticeData(lattice)
    if extrapolate:
        deform.SetOutsidePolicyToExtrapolate()
    deform.Update()
    return lattice, deform.GetOutput()


def run_pipeline(folder, processes=1):
    """paraview_pipeline.py in pvbatch, on `processes` MPI processes; its outputs by name, a distributed one as
    the list of its pieces in process order."""
    command = [PVBATCH, "--dr", HERE / "paraview_pipeline.py", PLUGIN, MESH, folder]
    if processes > 1:
        command = ["mpirun", "-np", processes] + command
    run(command)
    outputs = {}
    for path in sorted(Path(folder).glob("*.vt?"), key=lambda p: (p.stem.rsplit("_", 1)[0], p.stem)):
        name, _, rank = path.stem.rpartition("_")
        if rank.isdigit():
            outputs.setdefault(name, []).append((int(rank), read(path)))
        else:
            outputs[path.stem] = read(path)
    return {name: [piece for _, piece in sorted(value)] if isinstance(value, list) else value
            for name, value in outputs.items()}


class ParaViewTestCase(unittest.TestCase):
    def assertSameDataSet(self, actual, expected, what, arrays=()):
        """Bit for bit: the points, the cells and the named point and field arrays."""
        self.assertEqual(actual.GetClassName(), expected.GetClassName(), what)
        np.testing.assert_array_equal(points(actual), points(expected), err_msg=f"{what}: points")
        for part, (got, want) in zip(("connectivity", "cell types"), zip(cells(actual), cells(expected))):
            np.testing.assert_array_equal(got, want, err_msg=f"{what}: {part}")
        for name, where in arrays:
            np.testing.assert_array_equal(array(actual, name, where), array(expected, name, where),
                                          err_msg=f"{what}: {name}")


LATTICE_ARRAYS = (("FFDFrame", "field"), ("FFDDivisions", "field"), ("FFDBasis", "field"),
                  ("RestPosition", "point"), ("Active", "point"))


class Pipeline(ParaViewTestCase):
    """pvbatch against vtkffd (Debian's VTK): the same sources, compiled against two VTKs, give the same bits."""

    def reference(self):
        mesh = read(MESH)
        voxelize = vtkffd.vtkFFDVoxelize()
        voxelize.SetInputData(mesh)
        voxelize.SetDivisions(5, 6, 4)
        voxelize.SetFrameModeToPrincipalAxes()
        build = vtkffd.vtkFFDBuildLattice()
        build.SetInputConnection(voxelize.GetOutputPort())
        build.SetBasisToCubicBSpline()
        build.SetLatticeFormToSparse()
        tetrahedral = vtkffd.vtkFFDBuildTetrahedralLattice()
        tetrahedral.SetInputData(mesh)
        tetrahedral.SetSubdivisionLevels(1)
        lattice, deformed = moved_and_deformed(mesh, build)
        tetrahedra, tetrahedral_deformed = moved_and_deformed(mesh, tetrahedral, extrapolate=True)
        return {"mesh": mesh, "voxels": voxelize.GetOutput(), "lattice": lattice, "deformed": deformed,
                "tetrahedra": tetrahedra, "tetrahedral_deformed": tetrahedral_deformed}

    def test_pvbatch_equals_vtkffd(self):
        with tempfile.TemporaryDirectory() as folder:
            paraview = run_pipeline(folder)
        expected = self.reference()
        self.assertGreater(paraview["voxels"].GetNumberOfCells(), 20)
        self.assertSameDataSet(paraview["voxels"], expected["voxels"], "voxels",
                               (("FFDFrame", "field"), ("FFDDivisions", "field"), ("VoxelIndex", "cell")))
        self.assertSameDataSet(paraview["lattice"], expected["lattice"], "lattice", LATTICE_ARRAYS)
        self.assertSameDataSet(paraview["tetrahedra"], expected["tetrahedra"], "tetrahedra",
                               (("RestPosition", "point"),))
        for name in ("deformed", "tetrahedral_deformed"):
            (deformed,) = paraview[name]  # one process, one piece
            # The deformation moved the bear: the comparison is not one of two unmoved copies.
            moved = np.linalg.norm(points(deformed) - points(expected["mesh"]), axis=1)
            self.assertGreater(moved.max(), 0.01 * np.ptp(points(expected["mesh"]), axis=0).max(), name)
            np.testing.assert_array_equal(points(deformed), points(expected[name]), err_msg=name)


class Mpi(ParaViewTestCase):
    """mpirun -np 2 and 3 pvbatch: the bear split among the processes gives, once gathered, the serial output."""

    @classmethod
    def setUpClass(cls):
        cls.folder = tempfile.TemporaryDirectory()
        cls.serial = run_pipeline(Path(cls.folder.name) / "serial")

    @classmethod
    def tearDownClass(cls):
        cls.folder.cleanup()

    def check(self, processes):
        parallel = run_pipeline(Path(self.folder.name) / f"np{processes}", processes)
        (serial_mesh,) = self.serial["mesh"]
        mesh_points = serial_mesh.GetNumberOfPoints()
        np.testing.assert_array_equal(array(serial_mesh, "MeshPointId"), np.arange(mesh_points))
        # Every process held a piece, not the whole mesh.
        self.assertEqual(len(parallel["mesh"]), processes)
        for piece in parallel["mesh"]:
            self.assertGreater(piece.GetNumberOfPoints(), 0)
            self.assertLess(piece.GetNumberOfPoints(), mesh_points)
        self.assertSameDataSet(parallel["voxels"], self.serial["voxels"], "voxels",
                               (("FFDFrame", "field"), ("VoxelIndex", "cell")))
        self.assertSameDataSet(parallel["lattice"], self.serial["lattice"], "lattice", LATTICE_ARRAYS)
        self.assertSameDataSet(parallel["tetrahedra"], self.serial["tetrahedra"], "tetrahedra",
                               (("RestPosition", "point"),))
        for name in ("deformed", "tetrahedral_deformed"):
            (serial,) = self.serial[name]
            ids = np.concatenate([array(piece, "MeshPointId") for piece in parallel[name]])
            deformed = np.concatenate([points(piece) for piece in parallel[name]])
            # Points shared by pieces come once from each: every copy must equal the serial point.
            self.assertEqual(set(ids.tolist()), set(range(mesh_points)), name)
            np.testing.assert_array_equal(deformed, points(serial)[ids], err_msg=name)

    def test_two_processes(self):
        self.check(2)

    def test_three_processes(self):
        self.check(3)

    def test_demo_on_two_processes(self):
        # Examples/ParaView/deform_mesh.py as docs/paraview.md runs it under MPI: the reader straight before
        # FFDVoxelize, which asks it for this process's piece, so that the bear is read and deformed once
        # (its vertices counted over the processes), not once a process.
        with tempfile.TemporaryDirectory() as folder:
            output = run(["mpirun", "-np", 2, PVBATCH, "--dr", HERE.parents[1] / "Examples" / "ParaView" /
                          "deform_mesh.py", "--plugin", PLUGIN, "--output-dir", folder, "--size", 200, 200])
            self.assertTrue((Path(folder) / "bear_after.png").is_file())
        (mesh,) = self.serial["mesh"]
        self.assertIn(f"bear: {mesh.GetNumberOfPoints()} vertices, 60 control points (3x4x5)", output)


class Transform(ParaViewTestCase):
    """ParaView's Transform on a lattice (issue 30, item 3). With TransformAllInputVectors on (the GUI's default)
    it rotated a sparse lattice's VoxelIndex as a vector, and a dense lattice's RestPosition, which then deformed
    nothing: FFDDeform now says what the transform did. With it off, the lattice's points alone turn, and the bear
    turns with them: rotating every control point about the origin rotates every point inside, since the weights
    sum to 1. The bear is float32: its points agree to float32 rounding, 1e-6 of its size."""

    SCRIPT = """
import json
from paraview import servermanager
from paraview.simple import *
LoadPlugin({plugin!r}, ns=globals())
mesh = XMLPolyDataReader(FileName=[{mesh!r}])
report = dict()
for form in ("Dense", "Sparse"):
    lattice = FFDBuildLattice(Input=FFDVoxelize(Input=mesh, Divisions=[4, 4, 4]), LatticeForm=form,
                              Basis="Cubic B-Spline")
    for vectors in (1, 0):
        moved = Transform(Input=lattice, TransformAllInputVectors=vectors)
        moved.Transform.Rotate = [0, 0, 30]
        deformed = FFDDeform(Input=mesh, Lattice=moved)
        deformed.UpdatePipeline()
        output = servermanager.Fetch(deformed)
        report[form + str(vectors)] = [list(output.GetPoint(i)) for i in range(output.GetNumberOfPoints())]
open({report!r}, "w").write(json.dumps(report))
"""

    def test_transformed_lattices_turn_the_mesh_or_say_why_not(self):
        with tempfile.TemporaryDirectory() as folder:
            report = Path(folder) / "report.json"
            script = Path(folder) / "script.py"
            script.write_text(self.SCRIPT.format(plugin=PLUGIN, mesh=str(MESH), report=str(report)))
            output = run([PVBATCH, "--dr", script], expected_errors=("no longer match its FFDFrame",))
            result = json.loads(report.read_text())
        self.assertEqual(output.count("no longer match its FFDFrame"), 2, output)  # dense and sparse, vectors on
        bear = points(read(MESH))
        angle = np.radians(30.0)
        rotation = np.array([[np.cos(angle), -np.sin(angle), 0], [np.sin(angle), np.cos(angle), 0], [0, 0, 1]])
        expected = bear @ rotation.T
        size = np.ptp(bear, axis=0).max()
        for form in ("Dense", "Sparse"):
            with self.subTest(form=form):
                self.assertEqual(result[form + "1"], [])  # an error and an empty output
                self.assertLess(np.abs(np.array(result[form + "0"]) - expected).max(), 1e-6 * size)


class Dynamics(ParaViewTestCase):
    """pvbatch plays simulation_pipeline.py: FFDDeform under FFD Simulate Lattice follows the simulation in time."""

    def test_deformed_mesh_follows_the_simulation(self):
        # Issue 30, item 2: the deformed bear's bounds were the same at every time (FFDDeform announced no time
        # range, so no time request re-executed it). Each time's output must be the bear deformed by that time's
        # simulated lattice (vtkffd's vtkFFDDeform on the lattice pvbatch wrote: the same bits, as in Pipeline),
        # and the lattice vtkffd's own simulation at that time (the same sources: the same bits).
        with tempfile.TemporaryDirectory() as folder:
            run([PVBATCH, "--dr", HERE / "simulation_pipeline.py", PLUGIN, MESH, folder])
            report = json.loads((Path(folder) / "report.json").read_text())
            times = report["times"]
            # vtkXMLDataSetWriter names every file .vtk; the reader reads what it holds.
            lattices = [read(Path(folder) / f"lattice_{i}.vtk") for i in range(len(times))]
            deformed = [read(Path(folder) / f"deformed_{i}.vtk") for i in range(len(times))]
        self.assertEqual(report["time_range"], [0.0, 1.0])
        mesh = read(MESH)
        size = np.ptp(points(mesh), axis=0).max()
        lowest = [bounds[4] for bounds in report["updated"]]
        self.assertEqual(lowest[0], mesh.GetBounds()[4])
        self.assertLess(lowest[1], lowest[0] - 0.1 * size)  # the bear fell
        self.assertEqual(report["animated"], report["updated"])  # the animation asks for the same times
        reference = self.simulation(mesh)
        for i, time in enumerate(times):
            reference.UpdateTimeStep(time)
            np.testing.assert_array_equal(points(lattices[i]), points(reference.GetOutput()), err_msg=f"t={time}")
            deform = vtkffd.vtkFFDDeform()
            deform.SetInputData(mesh)
            deform.SetLatticeData(lattices[i])
            deform.Update()
            np.testing.assert_array_equal(points(deformed[i]), points(deform.GetOutput()), err_msg=f"t={time}")

    @staticmethod
    def simulation(mesh):
        """simulation_pipeline.py's simulation, built here with vtkffd."""
        voxelize = vtkffd.vtkFFDVoxelize()
        voxelize.SetInputData(mesh)
        voxelize.SetDivisions(5, 5, 5)
        build = vtkffd.vtkFFDBuildLattice()
        build.SetInputConnection(voxelize.GetOutputPort())
        build.SetBasisToTrilinear()
        build.Update()
        simulate = vtkffd.vtkFFDSimulateLattice()
        simulate.SetInputConnection(build.GetOutputPort())
        simulate.SetMeshData(mesh)
        simulate.SetEndTime(1.0)
        simulate.GetDynamics().SetGravity(0.0, 0.0, -9.81)
        plane = vtkPlane()
        plane.SetOrigin(0.0, 0.0, build.GetOutput().GetBounds()[4] - 0.25)
        plane.SetNormal(0.0, 0.0, 1.0)
        simulate.GetDynamics().AddCollider(plane)
        simulate.plane = plane  # kept with the filter
        return simulate


class Clients(ParaViewTestCase):
    """The plugin loads in pvpython and in the GUI, and its filters run there: their statistics are the output's
    field data, right after the update (information properties read 0 until UpdatePropertyInformation()), a
    dense lattice shows its control points under a spaced label (issue 30 item 4), and Divisions 0 is an error that
    leaves the client running (it died of SIGFPE in RequestData, item 1)."""

    SCRIPT = """
import json
from paraview.simple import *
LoadPlugin({plugin!r}, ns=globals())
mesh = XMLPolyDataReader(FileName=[{mesh!r}])
voxels = FFDVoxelize(Input=mesh, Divisions=[3, 3, 3])
lattice = FFDBuildLattice(Input=voxels, Basis="Cubic B-Spline", LatticeForm="Dense")
deformed = FFDDeform(Input=mesh, Lattice=lattice, Backend="CPU")
deformed.UpdatePipeline()
no_voxels = FFDVoxelize(Input=mesh, Divisions=[0, 4, 4])
no_voxels.UpdatePipeline()
open({report!r}, "w").write(json.dumps(dict(
    active=voxels.FieldData["NumberOfActiveVoxels"].GetRange()[0],
    cells=voxels.GetDataInformation().GetNumberOfCells(),
    backend=deformed.FieldData["LastBackendUsed"].GetStringValue(0),
    cells_of_divisions_0=no_voxels.GetDataInformation().GetNumberOfCells(),
    label=lattice.GetXMLLabel(),
    representation=Show(lattice, CreateView("RenderView")).SMProxy.GetProperty("Representation").GetElement(0))))
"""

    def expected_voxels(self):
        voxelize = vtkffd.vtkFFDVoxelize()
        voxelize.SetInputData(read(MESH))
        voxelize.SetDivisions(3, 3, 3)
        voxelize.Update()
        return voxelize.GetNumberOfActiveVoxels()

    def check_client(self, command_for_script):
        with tempfile.TemporaryDirectory() as folder:
            report = Path(folder) / "report.json"
            script = Path(folder) / "script.py"
            script.write_text(self.SCRIPT.format(plugin=PLUGIN, mesh=str(MESH), report=str(report)))
            run(command_for_script(script), expected_errors=("Divisions (0, 4, 4) must be at least 1",))
            result = json.loads(report.read_text())
        expected = self.expected_voxels()
        self.assertGreater(expected, 1)
        self.assertEqual(result["active"], expected)
        self.assertEqual(result["cells"], expected)
        self.assertEqual(result["backend"], "CPU")
        self.assertEqual(result["cells_of_divisions_0"], 0)
        self.assertEqual(result["label"], "FFD Build Lattice")  # spaced, as ParaView's own labels
        self.assertEqual(result["representation"], "Points")  # a dense lattice's control points, not its outline

    def test_pvpython(self):
        self.check_client(lambda script: [PVPYTHON, "--dr", script])

    def test_gui(self):
        # The GUI runs the script at start-up, then quits (--exit); it needs the X display ctest runs in.
        self.check_client(lambda script: [PARAVIEW, "--dr", f"--plugins={PLUGIN}", f"--script={script}", "--exit"])


if __name__ == "__main__":
    unittest.main()
