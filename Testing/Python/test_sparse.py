#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""The sparse voxel grid and sparse lattices from Python, as numpy sees them, against numpy references written
here from the data contract: the active voxels are the voxels of the points (equation 2), a sparse lattice's
points are the union of the active voxels' supports in increasing lattice order, at the rest position of their
LatticeIndex, a writable numpy view, and each cell lists its voxel's support; the dense form's reshape(nK, nJ, nI,
3) holds the same points bit for bit.

Run with Debian's /usr/bin/python3, PYTHONPATH=<build>/lib/python3/dist-packages and VOXELFFD_MESH_DIR set to the
folder of the meshes (ctest does both). Exits non-zero when a test fails.
"""
import unittest

import numpy as np
from vtkmodules.util.numpy_support import vtk_to_numpy

import vtkffd
from ffdtesting import bbox_diagonal, catch_errors, points_of, read_mesh  # the same folder

Build = vtkffd.vtkFFDBuildLattice
DIVISIONS = (37, 41, 29)

# Per local basis: the support of voxel v along an axis is first(v) .. first(v) + size - 1, and control point i
# rests at parameter rest(i, n) (n voxels along the axis).
SUPPORTS = {
    Build.TRILINEAR: (lambda v: v, 2, lambda i, n: i / n),
    Build.TRIQUADRATIC_BEZIER: (lambda v: 2 * v, 3, lambda i, n: i / (2 * n)),
    Build.TRICUBIC_BEZIER: (lambda v: 3 * v, 4, lambda i, n: i / (3 * n)),
    Build.CUBIC_BSPLINE: (lambda v: v, 4, lambda i, n: (i - 1) / n),
}
POINTS_PER_AXIS = {Build.TRILINEAR: lambda n: n + 1, Build.TRIQUADRATIC_BEZIER: lambda n: 2 * n + 1,
                   Build.TRICUBIC_BEZIER: lambda n: 3 * n + 1, Build.CUBIC_BSPLINE: lambda n: n + 3}


def frame_of(data):
    return vtk_to_numpy(data.GetFieldData().GetArray("FFDFrame")).astype(np.float64).reshape(4, 3)


def at(frame, stu):
    """X0 + s S + t T + u U for (N, 3) parameters."""
    return frame[0] + stu @ frame[1:]


def linear(index, dims):
    """i + n0 (j + n1 k) of (N, 3) indices, as int64."""
    index = index.astype(np.int64)
    return index[:, 0] + dims[0] * (index[:, 1] + dims[1] * index[:, 2])


class TestSparse(unittest.TestCase):
    def setUp(self):
        self.mesh = read_mesh("bear")
        self.voxelize = vtkffd.vtkFFDVoxelize()
        self.voxelize.SetInputData(self.mesh)
        self.voxelize.SetDivisions(*DIVISIONS)
        self.voxelize.Update()
        self.grid = self.voxelize.GetOutput()
        self.voxels = vtk_to_numpy(self.grid.GetCellData().GetArray("VoxelIndex"))
        self.frame = frame_of(self.grid)
        self.diagonal = bbox_diagonal(points_of(self.mesh))

    def test_voxel_grid_holds_the_voxels_of_the_points(self):
        # Equation 2 by solving [S T U] stu = X - X0; every bear point lies inside the padded frame.
        stu = np.linalg.solve(self.frame[1:].T, (points_of(self.mesh) - self.frame[0]).T).T
        expected = np.unique(linear(np.minimum((stu * DIVISIONS).astype(int), np.array(DIVISIONS) - 1), DIVISIONS))
        # The cells in increasing voxel order, each voxel once.
        np.testing.assert_array_equal(linear(self.voxels, DIVISIONS), expected)
        self.assertEqual(self.voxelize.GetNumberOfActiveVoxels(), len(expected))
        # Each cell's 8 corners, in VTK's hexahedron order, at X0 + (i/nx) S + (j/ny) T + (k/nz) U.
        cells = vtk_to_numpy(self.grid.GetCells().GetConnectivityArray()).reshape(-1, 8)
        hexahedron = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]])
        corners = (self.voxels[:, None, :] + hexahedron[None, :, :]) / DIVISIONS
        np.testing.assert_allclose(vtk_to_numpy(self.grid.GetPoints().GetData())[cells], at(self.frame, corners),
                                   rtol=0, atol=1e-14 * self.diagonal)
        self.assertEqual(self.grid.GetNumberOfPoints(), len(np.unique(cells)))  # each corner once

    def test_sparse_lattices_are_numpy_views_of_the_active_control_points(self):
        for basis, (first, size, rest) in SUPPORTS.items():
            with self.subTest(basis=Build.GetBasisAsString(basis)):
                build = Build()
                build.SetInputConnection(self.voxelize.GetOutputPort())
                build.SetBasis(basis)  # the default form, AUTOMATIC, is sparse for a local basis
                build.Update()
                lattice = build.GetOutput()
                self.assertEqual(lattice.GetClassName(), "vtkUnstructuredGrid")
                dims = [POINTS_PER_AXIS[basis](n) for n in DIVISIONS]
                index = vtk_to_numpy(lattice.GetPointData().GetArray("LatticeIndex"))

                # The points: the union of the supports, in increasing lattice order.
                offsets = np.stack(np.meshgrid(*[np.arange(size)] * 3, indexing="ij"), axis=-1).reshape(-1, 3)
                supports = first(self.voxels)[:, None, :] + offsets[None, :, :]
                np.testing.assert_array_equal(linear(index, dims), np.unique(linear(supports.reshape(-1, 3), dims)))
                self.assertEqual(build.GetNumberOfActiveControlPoints(), len(index))

                # At the rest position of their LatticeIndex; RestPosition the same.
                points = vtk_to_numpy(lattice.GetPoints().GetData())
                expected = at(self.frame, np.stack([rest(index[:, a], DIVISIONS[a]) for a in range(3)], axis=1))
                np.testing.assert_allclose(points, expected, rtol=0, atol=1e-14 * self.diagonal)
                np.testing.assert_array_equal(vtk_to_numpy(lattice.GetPointData().GetArray("RestPosition")), points)

                # Each cell is its voxel's support (as a set: the point order is the cell type's).
                cells = vtk_to_numpy(lattice.GetCells().GetConnectivityArray()).reshape(-1, size**3)
                got = np.sort(linear(index[cells.ravel()], dims).reshape(-1, size**3), axis=1)
                np.testing.assert_array_equal(got, np.sort(linear(supports.reshape(-1, 3), dims).reshape(-1, size**3),
                                                           axis=1))

                # The dense form's grid holds the same points, bit for bit.
                build.SetLatticeFormToDense()
                build.Update()
                dense = vtk_to_numpy(build.GetOutput().GetPoints().GetData()).reshape(dims[2], dims[1], dims[0], 3)
                np.testing.assert_array_equal(dense[index[:, 2], index[:, 1], index[:, 0]], points)

                # The points are a writable view: numpy moves them.
                moved = points[0] + (0.0, 0.1, 0.0)
                points[0] = moved
                lattice.GetPoints().Modified()
                self.assertEqual(lattice.GetPoint(0), tuple(moved))

    def test_sparse_bernstein_is_an_error(self):
        build = Build()
        build.SetInputData(self.grid)
        build.SetBasisToBernstein()
        build.SetLatticeFormToSparse()
        errors = catch_errors(build, executive=True)
        self.assertEqual(build.GetExecutive().Update(), 0)
        self.assertTrue(any("SPARSE lattice of the global BERNSTEIN basis" in m for m in errors.messages),
                        errors.messages)


    def test_control_net_joins_only_index_neighbours(self):
        # vtkFFDCellEdges joins two points of a sparse lattice where their LatticeIndex differ by one along one
        # axis. A flat key i + nI (j + nJ k) over the indices' range aliased (-1, 1, 0) with (2, 0, 0), the
        # neighbour of (1, 0, 0): an edge between points that are not neighbours. Only (0, 0, 0)-(1, 0, 0) is one.
        from vtkmodules.util.numpy_support import numpy_to_vtk
        from vtkmodules.vtkCommonCore import vtkPoints
        from vtkmodules.vtkCommonDataModel import vtkUnstructuredGrid
        from vtkmodules.util.vtkConstants import VTK_INT
        indices = np.array([[0, 0, 0], [1, 0, 0], [-1, 1, 0]], dtype=np.int32)
        points = vtkPoints()
        points.SetData(numpy_to_vtk(indices.astype(np.float64), deep=True))
        net = vtkUnstructuredGrid()
        net.SetPoints(points)
        index = numpy_to_vtk(indices, deep=True, array_type=VTK_INT)
        index.SetName("LatticeIndex")
        net.GetPointData().AddArray(index)
        edges = vtkffd.vtkFFDCellEdges()
        edges.SetInputData(net)
        edges.Update()
        lines = edges.GetOutput().GetLines()
        pairs = vtk_to_numpy(lines.GetConnectivityArray()).reshape(-1, 2).tolist()
        self.assertEqual(pairs, [[0, 1]])


if __name__ == "__main__":
    unittest.main()
