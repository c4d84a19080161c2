#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""The .vdb files from Python (docs/interchange-and-files.md, ".vdb files"): a sparse cubic B-spline lattice over the
bear, its points moved through numpy, written by vtkFFDVDBWriter and read back by vtkFFDVDBReader bit for bit (points,
every point, cell and field array, the cells), the voxel grid of output port 1 that of vtkFFDVoxelize, the same
deformation; a dense lattice, a missing file and a damaged one are errors with empty outputs; a write that fails
part-way leaves the file that was there as it was.

Run with Debian's /usr/bin/python3, PYTHONPATH=<build>/lib/python3/dist-packages and VOXELFFD_MESH_DIR set to the
folder of the meshes (ctest does both). Exits non-zero when a test fails.
"""
import os
import resource
import signal
import tempfile
import unittest

import numpy as np
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkCommonDataModel import vtkUnstructuredGrid

import vtkffd
from ffdtesting import catch_errors, read_mesh  # the same folder


def arrays(attributes):
    """The arrays of point, cell or field data as {name: numpy array}."""
    return {attributes.GetArrayName(a): vtk_to_numpy(attributes.GetArray(a))
            for a in range(attributes.GetNumberOfArrays())}


def grid_parts(grid):
    """What two identical grids share, bit for bit: points, cells, and every array."""
    parts = {"points": vtk_to_numpy(grid.GetPoints().GetData()),
             "cell types": vtk_to_numpy(grid.GetCellTypesArray()),
             "offsets": vtk_to_numpy(grid.GetCells().GetOffsetsArray()),
             "connectivity": vtk_to_numpy(grid.GetCells().GetConnectivityArray())}
    for where, data in (("point", grid.GetPointData()), ("cell", grid.GetCellData()), ("field", grid.GetFieldData())):
        parts.update({where + " " + name: values for name, values in arrays(data).items()})
    return parts


def deformed_points(mesh, lattice):
    deform = vtkffd.vtkFFDDeform()
    deform.SetInputData(mesh)
    deform.SetLatticeData(lattice)
    deform.Update()
    return vtk_to_numpy(deform.GetOutput().GetPoints().GetData())


class TestVDB(unittest.TestCase):
    def setUp(self):
        self.mesh = read_mesh("bear")
        self.voxelize = vtkffd.vtkFFDVoxelize()
        self.voxelize.SetInputData(self.mesh)
        self.voxelize.SetDivisions(12, 12, 12)
        build = vtkffd.vtkFFDBuildLattice()
        build.SetInputConnection(self.voxelize.GetOutputPort())
        build.SetBasisToCubicBSpline()  # sparse: the default form of a local basis
        build.Update()
        self.lattice = vtkUnstructuredGrid()
        self.lattice.DeepCopy(build.GetOutput())
        points = vtk_to_numpy(self.lattice.GetPoints().GetData())  # a view
        points += np.random.default_rng(2025).uniform(-0.02, 0.02, points.shape)
        self.lattice.GetPoints().Modified()
        self.folder = tempfile.TemporaryDirectory()
        self.path = os.path.join(self.folder.name, "bear.vdb")

    def tearDown(self):
        self.folder.cleanup()

    def write(self, data):
        writer = vtkffd.vtkFFDVDBWriter()
        writer.SetInputData(data)
        writer.SetFileName(self.path)
        errors = catch_errors(writer, executive=True)
        return writer.Write(), errors.messages

    def test_round_trip_is_bit_for_bit(self):
        self.assertEqual(self.write(self.lattice), (1, []))
        reader = vtkffd.vtkFFDVDBReader()
        reader.SetFileName(self.path)
        reader.Update()
        for got, want in ((reader.GetOutput(), self.lattice), (reader.GetOutput(1), self.voxelize.GetOutput())):
            got, want = grid_parts(got), grid_parts(want)
            self.assertEqual(sorted(got), sorted(want))
            for name in want:
                with self.subTest(part=name):
                    self.assertEqual(got[name].dtype, want[name].dtype)
                    self.assertEqual(got[name].tobytes(), want[name].tobytes())
        self.assertEqual(deformed_points(self.mesh, reader.GetOutput()).tobytes(),
                         deformed_points(self.mesh, self.lattice).tobytes())

    def test_dense_lattice_is_an_error(self):
        build = vtkffd.vtkFFDBuildLattice()
        build.SetInputConnection(self.voxelize.GetOutputPort())
        build.SetBasisToTrilinear()
        build.SetLatticeFormToDense()
        build.Update()
        written, errors = self.write(build.GetOutput())
        self.assertEqual(written, 0)
        self.assertTrue(any("SetLatticeFormToSparse()" in m for m in errors), errors)
        self.assertFalse(os.path.exists(self.path))

    def read_with_errors(self):
        reader = vtkffd.vtkFFDVDBReader()
        reader.SetFileName(self.path)
        errors = catch_errors(reader, executive=True)
        return reader, reader.GetExecutive().Update(), errors.messages

    def test_damaged_file_is_an_error(self):
        # A byte flipped in the grids: the checksum's error, before OpenVDB parses the file (it aborted before).
        self.assertEqual(self.write(self.lattice), (1, []))
        with open(self.path, "rb") as f:
            data = bytearray(f.read())
        data[len(data) // 2] ^= 0x10
        with open(self.path, "wb") as f:
            f.write(data)
        reader, read, errors = self.read_with_errors()
        self.assertEqual(read, 0)
        self.assertTrue(any(" is damaged: " in m for m in errors), errors)
        for port in (0, 1):
            self.assertEqual(reader.GetOutput(port).GetNumberOfPoints(), 0)

    def test_failed_write_keeps_the_old_file(self):
        # A file size limit makes the write fail part-way, as a full disk does: an error, the old file unchanged.
        self.assertEqual(self.write(self.lattice), (1, []))
        with open(self.path, "rb") as f:
            before = f.read()
        self.assertGreater(len(before), 8192)
        points = vtk_to_numpy(self.lattice.GetPoints().GetData())
        points += 0.01
        self.lattice.GetPoints().Modified()
        soft, hard = resource.getrlimit(resource.RLIMIT_FSIZE)
        handler = signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a failed write, not a killed process
        resource.setrlimit(resource.RLIMIT_FSIZE, (4096, hard))
        try:
            written, errors = self.write(self.lattice)
        finally:
            resource.setrlimit(resource.RLIMIT_FSIZE, (soft, hard))
            signal.signal(signal.SIGXFSZ, handler)
        self.assertEqual(written, 0)
        self.assertTrue(any("File too large" in m and "left as it was" in m for m in errors), errors)
        with open(self.path, "rb") as f:
            self.assertTrue(f.read() == before, "the file changed")
        self.assertEqual(os.listdir(self.folder.name), ["bear.vdb"])

    def test_missing_file_is_an_error(self):
        reader = vtkffd.vtkFFDVDBReader()
        reader.SetFileName(self.path)
        errors = catch_errors(reader, executive=True)
        self.assertEqual(reader.GetExecutive().Update(), 0)
        self.assertTrue(any("No such file or directory" in m for m in errors.messages), errors.messages)
        for port in (0, 1):
            self.assertEqual(reader.GetOutput(port).GetNumberOfPoints(), 0)


if __name__ == "__main__":
    unittest.main()
