#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""The command line `python3 -m vtkffd` (docs/interchange-and-files.md, "Command line"), run as a user runs it, in a
subprocess on the bear written to .off, .vtp and .ply files: `build` writes the lattice of the same voxelize -> build
pipeline run in-process, and `deform` of it, or of a lattice moved in-process and saved, gives the points of the
in-process vtkFFDDeform. Both sides run the same filters on the same inputs (the files keep float64 exactly), so the
tolerance is 0: bit for bit. Also: `info`'s counts, `convert` round trips, vtkffd.meshio's OFF files (read back bit
for bit, comments, colours, malformed files), --help, bad input (one line naming the problem, no traceback: files
cut short or garbled, numbers out of range), writes that fail part-way (the file that was there is kept), and
--quiet (nothing on stderr).

Run with Debian's /usr/bin/python3, PYTHONPATH=<build>/lib/python3/dist-packages and VOXELFFD_MESH_DIR set to the
folder of the meshes (ctest does both). Exits non-zero when a test fails.
"""
import os
import re
import resource
import subprocess
import sys
import tempfile
import unittest

import numpy as np
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy
from vtkmodules.vtkCommonCore import vtkPoints
from vtkmodules.vtkCommonDataModel import vtkPolyData

import vtkffd
from vtkffd import interchange, meshio
from ffdtesting import points_of, read_mesh  # the same folder

# The folder that holds the package under test, for the subprocesses (which run in a temporary folder).
PACKAGE_PARENT = os.path.dirname(os.path.dirname(os.path.abspath(vtkffd.__file__)))


def contents(data):
    """What two identical point sets share, bit for bit: points, an unstructured grid's cells, point, cell and field
    arrays, as {name: numpy array}."""
    parts = {"points": vtk_to_numpy(data.GetPoints().GetData())}
    if data.IsA("vtkUnstructuredGrid"):  # a sparse lattice's supports, a tetrahedral lattice's tetrahedra
        parts.update({"cell types": vtk_to_numpy(data.GetCellTypesArray()),
                      "offsets": vtk_to_numpy(data.GetCells().GetOffsetsArray()),
                      "connectivity": vtk_to_numpy(data.GetCells().GetConnectivityArray())})
    for where, attributes in (("point", data.GetPointData()), ("cell", data.GetCellData()),
                              ("field", data.GetFieldData())):
        parts.update({f"{where} {attributes.GetArrayName(a)}": as_numpy(attributes.GetAbstractArray(a))
                      for a in range(attributes.GetNumberOfArrays())})
    return parts


def as_numpy(array):
    """A VTK array's values as a numpy array: numbers as they are stored, strings (a statistic such as
    LastBackendUsed) as numpy strings."""
    if array.IsA("vtkDataArray"):
        return vtk_to_numpy(array)
    return np.array([array.GetValue(i) for i in range(array.GetNumberOfValues())])


def build_in_process(mesh, basis, divisions, form=vtkffd.vtkFFDBuildLattice.AUTOMATIC):
    """The voxelize -> build pipeline's builder, updated, over `mesh`."""
    voxelize = vtkffd.vtkFFDVoxelize()
    voxelize.SetInputData(mesh)
    voxelize.SetDivisions(*divisions)
    build = vtkffd.vtkFFDBuildLattice()
    build.SetInputConnection(voxelize.GetOutputPort())
    build.SetBasis(basis)
    build.SetLatticeForm(form)
    build.Update()
    return build


def lower_half(mesh):
    """The points of `mesh` below its median height (y) as a point set: a lattice built over them leaves the upper
    half of the mesh outside, where --outside matters."""
    points = vtk_to_numpy(mesh.GetPoints().GetData())
    vtk_points = vtkPoints()
    vtk_points.SetData(numpy_to_vtk(points[points[:, 1] < np.median(points[:, 1])], deep=True))
    half = vtkPolyData()
    half.SetPoints(vtk_points)
    return half


def own_copy(lattice):
    copy = type(lattice)()
    copy.DeepCopy(lattice)
    return copy


def deform_in_process(mesh, lattice, outside=vtkffd.vtkFFDDeform.KEEP_POSITION, double=False):
    deform = vtkffd.vtkFFDDeform()
    deform.SetInputData(mesh)
    deform.SetLatticeData(lattice)
    deform.SetOutsidePolicy(outside)
    if double:
        deform.SetOutputPointsPrecision(1)  # vtkAlgorithm.DOUBLE_PRECISION
    deform.Update()
    return deform.GetOutput()


def move(lattice, scale, seed):
    """Moves the lattice's points at random by up to `scale` per coordinate; returns the lattice."""
    points = vtk_to_numpy(lattice.GetPoints().GetData())  # a view
    points += np.random.default_rng(seed).uniform(-scale, scale, points.shape)
    lattice.GetPoints().Modified()
    return lattice


class TestCommandLine(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.mesh = read_mesh("bear")  # float64 points
        cls.folder = tempfile.TemporaryDirectory()
        for name in ("bear.off", "bear.vtp", "bear.ply"):  # .ply keeps float32 points: --double matters
            meshio.write_mesh(cls.mesh, cls.path(name))

    @classmethod
    def tearDownClass(cls):
        cls.folder.cleanup()

    @classmethod
    def path(cls, name):
        return os.path.join(cls.folder.name, name)

    def run_command(self, *arguments, file_size_limit=None):
        """Runs `python3 -m vtkffd ARGUMENTS` in the test folder; returns (exit status, stdout, stderr). With
        `file_size_limit`, writes past that many bytes of a file fail (RLIMIT_FSIZE; Python ignores SIGXFSZ), as
        on a disk that fills up part-way, for root too."""
        limit = None if file_size_limit is None else (
            lambda: resource.setrlimit(resource.RLIMIT_FSIZE, (file_size_limit, file_size_limit)))
        result = subprocess.run([sys.executable, "-m", "vtkffd", *arguments], cwd=self.folder.name,
                                env=dict(os.environ, PYTHONPATH=PACKAGE_PARENT), capture_output=True, text=True,
                                timeout=120, preexec_fn=limit)
        return result.returncode, result.stdout, result.stderr

    def expect_one_line_errors(self, cases, no_file_named=None):
        """Runs each case (arguments, exit status, what its message names): exit status 1 and one line on stderr,
        or 2 and argparse's usage above the line; no traceback; with `no_file_named`, no file of that prefix left."""
        for arguments, status, problem in cases:
            with self.subTest(arguments=" ".join(arguments)):
                got, out, err = self.run_command(*arguments, "-q")
                self.assertEqual(got, status, err)
                self.assertNotIn("Traceback", err)
                lines = err.splitlines()
                if status == 2:  # a usage error shows the usage above its line, as argparse does
                    self.assertTrue(lines[0].startswith("usage: "), err)
                else:
                    self.assertEqual(len(lines), 1, err)
                self.assertIn(problem, lines[-1])
                if no_file_named:
                    self.assertFalse([name for name in os.listdir(self.folder.name) if name.startswith(no_file_named)])

    def succeed(self, *arguments):
        """Runs the command, which must succeed; returns its stdout."""
        status, out, err = self.run_command(*arguments)
        self.assertEqual(status, 0, err)
        return out

    def assertBitForBit(self, got, want):
        got, want = contents(got), contents(want)
        self.assertEqual(sorted(got), sorted(want))
        for name in want:
            with self.subTest(part=name):
                self.assertEqual(got[name].dtype, want[name].dtype)
                self.assertEqual(got[name].tobytes(), want[name].tobytes())

    def test_build_then_deform_equal_the_pipeline(self):
        Build = vtkffd.vtkFFDBuildLattice
        for basis, name, divisions, lattice_file in ((Build.BERNSTEIN, "bernstein", (2, 3, 4), "bernstein.vts"),
                                                     (Build.CUBIC_BSPLINE, "bspline", (6, 6, 6), "bspline.vtu")):
            with self.subTest(basis=name):
                self.succeed("build", "bear.off", "-o", lattice_file, "--basis", name,
                             "--divisions", *map(str, divisions), "-q")
                want = build_in_process(self.mesh, basis, divisions).GetOutput()
                self.assertBitForBit(interchange.read_lattice(self.path(lattice_file)), want)
                self.succeed("deform", "bear.off", lattice_file, "-o", name + "_deformed.vtp", "-q")
                self.assertBitForBit(meshio.read_mesh(self.path(name + "_deformed.vtp")),
                                     deform_in_process(self.mesh, want))

    def test_deform_by_a_moved_lattice_equals_the_pipeline(self):
        Build, Deform = vtkffd.vtkFFDBuildLattice, vtkffd.vtkFFDDeform
        ply_mesh = meshio.read_mesh(self.path("bear.ply"))  # as the command reads it: float32 points
        half = lower_half(self.mesh)
        tetrahedra = vtkffd.vtkFFDBuildTetrahedralLattice()
        tetrahedra.SetInputData(half)
        tetrahedra.Update()
        cases = (  # lattice, its file, the mesh file and mesh, options, the in-process deformation's settings
            (build_in_process(self.mesh, Build.BERNSTEIN, (2, 3, 4)).GetOutput(), "moved.vts", "bear.off",
             self.mesh, [], {}),
            (build_in_process(half, Build.TRICUBIC_BEZIER, (3, 3, 3), Build.DENSE).GetOutput(), "moved_half.vts",
             "bear.vtp", self.mesh, ["--outside", "clamp"], {"outside": Deform.CLAMP_TO_EDGE}),
            (build_in_process(self.mesh, Build.TRILINEAR, (5, 5, 5)).GetOutput(), "moved_sparse.vtu", "bear.ply",
             ply_mesh, ["--double"], {"double": True}),
            (tetrahedra.GetOutput(), "moved_half_tetrahedra.vtu", "bear.off", self.mesh, [], {}))
        for seed, (rest, lattice_file, mesh_file, mesh, options, settings) in enumerate(cases):
            with self.subTest(lattice=lattice_file, mesh=mesh_file):
                lattice = move(own_copy(rest), 0.05, seed)  # the bear is about 2 long: up to 2.5 %
                interchange.write_lattice(lattice, self.path(lattice_file))
                self.succeed("deform", mesh_file, lattice_file, "-o", "deformed.vtp", "--backend", "cpu", "-q",
                             *options)
                want = deform_in_process(mesh, lattice, **settings)
                self.assertBitForBit(meshio.read_mesh(self.path("deformed.vtp")), want)
                # The options matter: the mesh moved, and --outside moved points outside the half lattice.
                points = vtk_to_numpy(want.GetPoints().GetData())
                self.assertFalse(np.array_equal(points, vtk_to_numpy(mesh.GetPoints().GetData())))
                if "outside" in settings:
                    self.assertFalse(np.array_equal(points, vtk_to_numpy(
                        deform_in_process(mesh, lattice).GetPoints().GetData())))

    def info(self, lattice_file):
        """`info`'s table as {name: value}."""
        return dict(re.split(r"\s{2,}", line, maxsplit=1) for line in self.succeed("info", lattice_file).splitlines())

    def test_info_counts(self):
        Build = vtkffd.vtkFFDBuildLattice
        lattice = own_copy(build_in_process(self.mesh, Build.BERNSTEIN, (2, 3, 4)).GetOutput())
        points = vtk_to_numpy(lattice.GetPoints().GetData())
        moved = [3, 17, 59]
        points[moved] += [[0.1, 0.0, 0.0], [0.0, -0.25, 0.0], [0.0, 0.0, 0.2]]
        lattice.GetPoints().Modified()
        interchange.write_lattice(lattice, self.path("info.vts"))
        rows = self.info("info.vts")
        self.assertTrue(rows["kind"].startswith("grid, dense"), rows["kind"])
        self.assertEqual((rows["basis"], rows["divisions"]), ("bernstein", "2 x 3 x 4"))
        self.assertEqual((rows["control points"], rows["active"], rows["moved"]), ("60", "60", "3"))
        self.assertEqual(rows["largest displacement"], f"{0.25:.6g} (control point 17)")

        # A dense trilinear lattice culls control points; a sparse one holds the active ones only.
        for form, name in ((Build.DENSE, "culled.vts"), (Build.SPARSE, "sparse.vtu")):
            build = build_in_process(self.mesh, Build.TRILINEAR, (6, 6, 6), form)
            interchange.write_lattice(build.GetOutput(), self.path(name))
            rows = self.info(name)
            total = 7 ** 3 if form == Build.DENSE else build.GetNumberOfActiveControlPoints()
            self.assertEqual((rows["control points"], rows["active"], rows["moved"]),
                             (str(total), str(build.GetNumberOfActiveControlPoints()), "0"))
            self.assertLess(build.GetNumberOfActiveControlPoints(), 7 ** 3)

        tetrahedra = vtkffd.vtkFFDBuildTetrahedralLattice()
        tetrahedra.SetInputData(self.mesh)
        tetrahedra.Update()
        interchange.write_lattice(tetrahedra.GetOutput(), self.path("tetrahedra.vtu"))
        rows = self.info("tetrahedra.vtu")
        self.assertTrue(rows["kind"].startswith("tetrahedral"), rows["kind"])
        self.assertEqual((rows["control points"], rows["active"]),
                         (str(tetrahedra.GetOutput().GetNumberOfPoints()), str(tetrahedra.GetNumberOfActiveNodes())))

    def test_convert_round_trip(self):
        Build = vtkffd.vtkFFDBuildLattice
        dense = move(own_copy(build_in_process(self.mesh, Build.BERNSTEIN, (2, 3, 4)).GetOutput()), 0.05, 7)
        sparse = move(own_copy(build_in_process(self.mesh, Build.CUBIC_BSPLINE, (6, 6, 6)).GetOutput()), 0.05, 8)
        for lattice, first, other in ((dense, "convert.vts", "convert_dense.vtk"),
                                      (sparse, "convert.vtu", "convert_sparse.vdb")):
            with self.subTest(format=other):
                interchange.write_lattice(lattice, self.path(first))
                self.succeed("convert", first, "-o", other, "-q")
                self.succeed("convert", other, "-o", "back_" + first, "-q")
                self.assertBitForBit(interchange.read_lattice(self.path("back_" + first)), lattice)

    def test_off_round_trip_is_bit_for_bit(self):
        meshio.write_off(self.mesh, self.path("round_trip.off"))
        read = meshio.read_mesh(self.path("round_trip.off"))
        self.assertBitForBit(read, self.mesh)
        got, want = read.GetPolys(), self.mesh.GetPolys()
        for got_array, want_array in ((got.GetOffsetsArray(), want.GetOffsetsArray()),
                                      (got.GetConnectivityArray(), want.GetConnectivityArray())):
            self.assertEqual(vtk_to_numpy(got_array).tolist(), vtk_to_numpy(want_array).tolist())

    def test_off_comments_counts_and_colours(self):
        with open(self.path("square.off"), "w") as stream:
            stream.write("OFF # a unit square and a triangle\n\n# counts on their own line\n5 2 0\n0 0 0\n1 0 0\n"
                         "1 1 0\n0 1 0  # a comment after a vertex\n0.5 0.5 1\n4 0 1 2 3 255 0 0\n3 0 1 4\n")
        mesh = meshio.read_mesh(self.path("square.off"))
        self.assertEqual(vtk_to_numpy(mesh.GetPoints().GetData()).tolist(),
                         [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0.5, 0.5, 1]])
        self.assertEqual(vtk_to_numpy(mesh.GetPolys().GetOffsetsArray()).tolist(), [0, 4, 7])
        self.assertEqual(vtk_to_numpy(mesh.GetPolys().GetConnectivityArray()).tolist(), [0, 1, 2, 3, 0, 1, 4])
        for text, problem in (("COFF\n", "only plain OFF"), ("OFF\n3\n", "line 2"), ("OFF 3 1\n0 0 0\n", "fewer"),
                              ("OFF 1 0\n0 zero 0\n", "line 2: expected the x y z"),
                              ("OFF 1 1\n0 0 0\n3 0 0\n", "line 3: expected a face"),
                              ("OFF 1 1\n0 0 0\n1 1\n", "below 1")):
            with self.subTest(text=text):
                with open(self.path("bad.off"), "w") as stream:
                    stream.write(text)
                with self.assertRaisesRegex(ValueError, problem):
                    meshio.read_mesh(self.path("bad.off"))

    def test_invert_takes_the_deformed_mesh_back(self):
        """`deform` then `invert` by the same moved lattice: the bear back at rest within 1e-10 of its size (Newton
        stops at 1e-12 of the frame's diagonal; det J stays near 1 for these small moves), and the output's
        InverseStatus says every point was found; in-process vtkFFDInverseDeform gives the same points bit for
        bit."""
        lattice = build_in_process(self.mesh, vtkffd.vtkFFDBuildLattice.CUBIC_BSPLINE, (3, 3, 3)).GetOutput()
        moved = vtk_to_numpy(lattice.GetPoints().GetData())
        moved += np.random.default_rng(5).uniform(-0.005, 0.005, moved.shape)
        interchange.write_lattice(lattice, self.path("inv.vtu"))
        self.succeed("deform", "bear.vtp", "inv.vtu", "-o", "deformed.vtp", "--double")
        self.succeed("invert", "deformed.vtp", "inv.vtu", "-o", "back.vtp", "--double")
        back = meshio.read_mesh(self.path("back.vtp"))
        points = points_of(self.mesh)
        size = float(np.linalg.norm(points.max(axis=0) - points.min(axis=0)))
        self.assertLess(np.abs(points_of(back) - points).max(), 1e-10 * size)
        self.assertEqual(int(vtk_to_numpy(back.GetPointData().GetArray("InverseStatus")).max()), 0)
        inverse = vtkffd.vtkFFDInverseDeform()
        inverse.SetInputData(meshio.read_mesh(self.path("deformed.vtp")))
        inverse.SetLatticeData(interchange.read_lattice(self.path("inv.vtu")))
        inverse.SetOutputPointsPrecision(1)  # vtkAlgorithm.DOUBLE_PRECISION
        inverse.Update()
        np.testing.assert_array_equal(points_of(back), points_of(inverse.GetOutput()))

    def test_help_names_every_command(self):
        out = self.succeed("--help")
        for command in ("build", "deform", "invert", "info", "convert"):
            self.assertIn(command, out)
            self.assertIn("examples:", self.succeed(command, "--help"))

    def test_bad_input_is_one_line_without_traceback(self):
        interchange.write_lattice(build_in_process(self.mesh, vtkffd.vtkFFDBuildLattice.BERNSTEIN, (1, 1, 1))
                                  .GetOutput(), self.path("bad_input.vts"))
        with open(self.path("malformed.off"), "w") as stream:
            stream.write("OFF\n1 0 0\n0 0\n")
        cases = (  # arguments, exit status, what the message names
            (("deform", "missing.off", "bad_input.vts", "-o", "out.vtp"), 1, "missing.off"),
            (("deform", "bear.off", "missing.vts", "-o", "out.vtp"), 1, "missing.vts"),
            (("build", "bear.xyz", "-o", "out.vts"), 1, ".xyz"),
            (("deform", "bear.off", "bad_input.vts", "-o", "out.xyz"), 1, ".xyz"),
            (("deform", "malformed.off", "bad_input.vts", "-o", "out.vtp"), 1, "malformed.off, line 3"),
            (("build", "bear.off", "-o", "out.vtu", "--form", "sparse"), 1, "SPARSE lattice of the global BERNSTEIN"),
            (("build", "bear.off", "-o", "out.vts", "--divisions", "0"), 2, "--divisions"),
            (("build", "bear.off", "-o", "out.vts", "--divisions", "2", "3"), 2, "--divisions"))
        self.expect_one_line_errors(cases)

    def test_files_cut_short_or_garbled_and_numbers_out_of_range(self):
        """One line and exit status 1 (2 for a usage error), no traceback, no output file: random bytes in a mesh's
        name (STL, OBJ: VTK passes its message as None), files cut short (a binary PLY crashes VTK's reader, a
        legacy VTK file gives a warning only, or crashes VTK's reader when cut in an array's header, PyGeM's lines
        left out read as zeros), sizes beyond memory or VTK's int, padding and frames that overflow, a lattice
        that is not finite written where no reader takes it back."""
        Build = vtkffd.vtkFFDBuildLattice
        random = np.random.default_rng(30).integers(0, 256, 20000, dtype=np.uint8).tobytes()
        files = {"random.stl": random, "random.obj": random}
        for name in ("bear.ply", "bear.vtp"):
            meshio.write_mesh(self.mesh, self.path("whole" + name[-4:]), name[-4:])
        meshio.write_mesh(self.mesh, self.path("whole.vtk"))
        with open(self.path("whole.ply"), "rb") as stream:
            files["cut.ply"] = stream.read()[:5000]
        with open(self.path("whole.vtk"), "rb") as stream:
            files["cut_mesh.vtk"] = stream.read()[:-1000]
        dense = own_copy(build_in_process(self.mesh, Build.BERNSTEIN, (2, 2, 2)).GetOutput())
        interchange.write_lattice(dense, self.path("dense.vtk"))
        with open(self.path("dense.vtk"), "rb") as stream:
            whole = stream.read()
        files["cut_in_field_data.vtk"] = whole[:whole.index(b"FIELD FieldData") + 7]
        interchange.write_lattice(dense, self.path("dense.prm"))
        with open(self.path("dense.prm"), "rb") as stream:
            whole = stream.read()
        files["cut.prm"] = whole[:whole.index(b"\n", whole.index(b"parameter z")) + 1]
        files["huge.prm"] = whole.replace(b"n control points x: 3", b"n control points x: 2147483647")
        files["huge.off"] = b"OFF\n3 1 0\n-1e308 0 0\n1e308 0 0\n0 1 0\n3 0 1 2\n"
        for name, data in files.items():
            with open(self.path(name), "wb") as stream:
                stream.write(data)
        vtk_to_numpy(dense.GetPoints().GetData())[4] = np.nan
        bspline = own_copy(build_in_process(self.mesh, Build.CUBIC_BSPLINE, (2, 2, 2), Build.DENSE).GetOutput())
        vtk_to_numpy(bspline.GetPoints().GetData())[4] = np.inf
        meshio.write_mesh(dense, self.path("nan.vts"))  # as a user would, past write_lattice's check
        meshio.write_mesh(bspline, self.path("inf.vts"))
        cases = (  # arguments, exit status, what the message names
            (("build", "random.stl", "-o", "bad_out.vts"), 1, "random.stl: not an STL file"),
            (("build", "random.obj", "-o", "bad_out.vts"), 1, "random.obj"),
            (("build", "cut.ply", "-o", "bad_out.vts"), 1, "cut.ply: cut short"),
            (("build", "cut_mesh.vtk", "-o", "bad_out.vts"), 1, "cut_mesh.vtk: Error reading binary data"),
            (("deform", "bear.off", "cut_in_field_data.vtk", "-o", "bad_out.vtp"), 1, "crashes"),
            (("info", "cut.prm"), 1, "'parameter z' lists 1 of the 27 control points"),
            (("info", "huge.prm"), 1, "GB needed"),
            (("convert", "nan.vts", "-o", "bad_out.prm"), 1, "control point 4 is not finite"),
            (("convert", "inf.vts", "-o", "bad_out.tfm"), 1, "control point 4 is not finite"),
            (("build", "bear.off", "-o", "bad_out.vts", "--divisions", "4294967296"), 2, "at most 2147483647"),
            (("build", "bear.off", "-o", "bad_out.vts", "--padding", "inf"), 2, "--padding: inf: a finite number"),
            (("build", "bear.off", "-o", "bad_out.vts", "--padding", "1e308"), 1, "--padding 1e+308"),
            (("build", "huge.off", "-o", "bad_out.vts"), 1, "huge.off: its points span"))
        self.expect_one_line_errors(cases, no_file_named="bad_out")

    def test_a_failed_write_leaves_the_file_that_was_there(self):
        """Every output format, written by a command whose writes of a file fail past 2,000 bytes (a disk that
        fills up): exit status 1, one line naming the output, the file that was there unchanged, nothing left
        beside it. Each output is larger than that when the write succeeds."""
        Build = vtkffd.vtkFFDBuildLattice
        for name, lattice in (("dense.vts", build_in_process(self.mesh, Build.BERNSTEIN, (2, 3, 4))),
                              ("bspline.vts", build_in_process(self.mesh, Build.CUBIC_BSPLINE, (5, 5, 5), Build.DENSE)),
                              ("sparse.vtu", build_in_process(self.mesh, Build.TRILINEAR, (6, 6, 6)))):
            interchange.write_lattice(lattice.GetOutput(), self.path(name))
        limit = 2000
        commands = [("deform", "bear.off", "dense.vts", "-o", "full_disk" + extension)
                    for extension in (".vtp", ".vtk", ".stl", ".ply", ".obj", ".off")]
        commands += [("convert", "dense.vts", "-o", "full_disk.prm"), ("convert", "bspline.vts", "-o", "full_disk.tfm"),
                     ("convert", "sparse.vtu", "-o", "full_disk.vdb"), ("convert", "sparse.vtu", "-o", "full_disk.vtu"),
                     ("convert", "dense.vts", "-o", "full_disk.vts"),
                     ("convert", "sparse.vtu", "-o", "full_disk_lattice.vtk")]
        for arguments in commands:
            output = self.path(arguments[-1])
            with self.subTest(arguments=" ".join(arguments)):
                self.succeed(*arguments, "-q")
                self.assertGreater(os.path.getsize(output), limit)
                with open(output, "wb") as stream:
                    stream.write(b"the file that was there\n")
                files = sorted(os.listdir(self.folder.name))
                status, out, err = self.run_command(*arguments, "-q", file_size_limit=limit)
                self.assertEqual(status, 1, err)
                self.assertEqual(len(err.splitlines()), 1, err)
                self.assertIn(arguments[-1], err)
                with open(output, "rb") as stream:
                    self.assertEqual(stream.read(), b"the file that was there\n")
                self.assertEqual(sorted(os.listdir(self.folder.name)), files)

    def test_quiet_says_nothing(self):
        for quiet in (True, False):
            with self.subTest(quiet=quiet):
                option = ["-q"] if quiet else []
                for arguments in (("build", "bear.off", "-o", "quiet.vtu", "--basis", "trilinear", *option),
                                  ("deform", "bear.off", "quiet.vtu", "-o", "quiet.vtp", *option)):
                    status, out, err = self.run_command(*arguments)
                    self.assertEqual((status, out), (0, ""), err)
                    if quiet:
                        self.assertEqual(err, "")
                    else:  # not a terminal: a few plain lines of progress, and a summary
                        self.assertIn("100%\n", err)
                        self.assertNotIn("\r", err)
                        output = arguments[arguments.index("-o") + 1]
                        self.assertTrue(err.splitlines()[-1].startswith(output + ": "), err)


if __name__ == "__main__":
    unittest.main()
