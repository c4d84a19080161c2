#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""The Quality module from Python: vtkFFDFoldCertificate on a lattice moved with numpy (its FoldCertificate array
read back as numpy, its counts), and vtkFFDMeshInversion on a tetrahedral mesh whose nodes numpy moves, each
cell's Inverted flag against numpy's signed volumes (rest against deformed) and its ScaledJacobian against a numpy
formula (sqrt(2) det over the largest product of a corner's edge lengths); bad input.

Run with Debian's /usr/bin/python3, PYTHONPATH=<build>/lib/python3/dist-packages (ctest sets it). Exits non-zero
when a test fails.
"""
import unittest

import numpy as np
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy
from vtkmodules.vtkCommonCore import vtkPoints
from vtkmodules.vtkCommonDataModel import VTK_TETRA, vtkPolyData, vtkStructuredGrid, vtkUnstructuredGrid

import vtkffd
from ffdtesting import catch_errors  # the same folder


def box_lattice(n, basis):
    """A dense lattice of `basis` over the unit box split n^3, every voxel active (a point at each centre)."""
    centres = (np.arange(n) + 0.5) / n
    grid = np.stack(np.meshgrid(centres, centres, centres, indexing="ij"), axis=-1).reshape(-1, 3)
    points = vtkPoints()
    points.SetData(numpy_to_vtk(grid, deep=True))
    cloud = vtkPolyData()
    cloud.SetPoints(points)
    voxelize = vtkffd.vtkFFDVoxelize()
    voxelize.SetInputData(cloud)
    voxelize.SetFrame((0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1))
    voxelize.SetDivisions(n, n, n)
    build = vtkffd.vtkFFDBuildLattice()
    build.SetInputConnection(voxelize.GetOutputPort())
    build.SetBasis(basis)
    build.SetLatticeFormToDense()
    build.Update()
    lattice = vtkStructuredGrid()
    lattice.DeepCopy(build.GetOutput())
    return lattice


class FoldCertificateTest(unittest.TestCase):
    def test_rest_certified_and_pushed_point_folds(self):
        lattice = box_lattice(3, vtkffd.vtkFFDBuildLattice.TRILINEAR)
        certificate = vtkffd.vtkFFDFoldCertificate()
        certificate.SetInputData(lattice)
        certificate.Update()
        self.assertEqual(certificate.GetNumberOfCertifiedCells(), 27)
        states = vtk_to_numpy(certificate.GetOutput().GetCellData().GetArray("FoldCertificate"))
        self.assertTrue(np.all(states == vtkffd.vtkFFDFoldCertificate.CERTIFIED))

        points = vtk_to_numpy(lattice.GetPoints().GetData()).reshape(4, 4, 4, 3)  # [k, j, i], a view
        points[1, 1, 1, 0] += 0.6  # beyond its neighbour along x, 1/3 away
        lattice.GetPoints().Modified()
        certificate.Update()
        states = vtk_to_numpy(certificate.GetOutput().GetCellData().GetArray("FoldCertificate")).reshape(3, 3, 3)
        self.assertEqual(states[1, 1, 1], vtkffd.vtkFFDFoldCertificate.FOLDED)  # the voxel on its +x side
        self.assertEqual(certificate.GetNumberOfFoldedCells(), int(np.sum(states == 1)))
        self.assertEqual(certificate.GetNumberOfCertifiedCells() + certificate.GetNumberOfFoldedCells()
                         + certificate.GetNumberOfUndecidedCells(), 27)

    def test_bad_lattice_is_an_error(self):
        lattice = box_lattice(2, vtkffd.vtkFFDBuildLattice.CUBIC_BSPLINE)
        lattice.GetPointData().RemoveArray("RestPosition")
        certificate = vtkffd.vtkFFDFoldCertificate()
        certificate.SetInputData(lattice)
        errors = catch_errors(certificate, executive=True)
        certificate.Update()
        self.assertTrue(any("RestPosition" in m for m in errors.messages), errors.messages)
        self.assertEqual(certificate.GetOutput().GetNumberOfPoints(), 0)


def tetrahedral_mesh(rng):
    """Five cubes' worth of Kuhn tetrahedra in a row: 6 a cube, every node jittered by up to 0.1."""
    nodes = np.array([[i, j, k] for k in (0, 1) for j in (0, 1) for i in range(6)], dtype=float)
    nodes += rng.uniform(-0.1, 0.1, nodes.shape)
    index = {tuple(int(round(v)) for v in np.round(p)): n for n, p in enumerate(nodes)}
    tetrahedra = []
    for c in range(5):
        for order in ((0, 1, 2), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0)):
            corner = [c, 0, 0]
            tetrahedron = [index[tuple(corner)]]
            for axis in order:
                corner[axis] += 1
                tetrahedron.append(index[tuple(corner)])
            tetrahedra.append(tetrahedron)
    return nodes, np.array(tetrahedra)


def as_grid(nodes, tetrahedra):
    grid = vtkUnstructuredGrid()
    points = vtkPoints()
    points.SetData(numpy_to_vtk(nodes, deep=True))
    grid.SetPoints(points)
    for t in tetrahedra:
        grid.InsertNextCell(VTK_TETRA, 4, [int(v) for v in t])
    return grid


class MeshInversionTest(unittest.TestCase):
    def test_against_numpy_signed_volumes(self):
        rng = np.random.default_rng(5)
        nodes, tetrahedra = tetrahedral_mesh(rng)
        rest = as_grid(nodes, tetrahedra)
        inverted_total = 0
        for trial in range(20):
            moved = nodes + rng.uniform(-0.35, 0.35, nodes.shape)
            deformed = as_grid(moved, tetrahedra)
            inversion = vtkffd.vtkFFDMeshInversion()
            inversion.SetInputData(deformed)
            inversion.SetRestMeshData(rest)
            inversion.Update()
            cells = inversion.GetOutput().GetCellData()
            flags = vtk_to_numpy(cells.GetArray("Inverted"))
            scaled = vtk_to_numpy(cells.GetArray("ScaledJacobian"))

            def volumes(x):
                edges = np.stack([x[tetrahedra[:, k]] - x[tetrahedra[:, 0]] for k in (1, 2, 3)], axis=1)
                return np.linalg.det(edges)

            before, after = volumes(nodes), volumes(moved)
            expected = np.where(np.sign(before) == np.sign(after), 0, 1)
            np.testing.assert_array_equal(flags, expected)
            self.assertEqual(inversion.GetNumberOfInvertedCells(), int(expected.sum()))
            inverted_total += int(expected.sum())
            # sqrt(2) det / the largest product of a corner's three edge lengths, times the rest orientation
            x = moved[tetrahedra]
            products = [np.prod([np.linalg.norm(x[:, (c + k) % 4] - x[:, c], axis=1) for k in (1, 2, 3)], axis=0)
                        for c in range(4)]
            reference = np.sqrt(2) * after * np.sign(before) / np.max(products, axis=0)
            np.testing.assert_allclose(scaled, reference, rtol=0, atol=1e-12)
            self.assertAlmostEqual(inversion.GetMinimumScaledJacobian(), reference.min(), delta=1e-12)
        self.assertGreater(inverted_total, 0)

    def test_mismatched_meshes_are_an_error(self):
        rng = np.random.default_rng(6)
        nodes, tetrahedra = tetrahedral_mesh(rng)
        inversion = vtkffd.vtkFFDMeshInversion()
        inversion.SetInputData(as_grid(nodes, tetrahedra))
        inversion.SetRestMeshData(as_grid(nodes[:-1], tetrahedra[:-6]))
        errors = catch_errors(inversion, executive=True)
        inversion.Update()
        self.assertTrue(any("must be one mesh" in m for m in errors.messages), errors.messages)
        self.assertEqual(inversion.GetOutput().GetNumberOfPoints(), 0)


if __name__ == "__main__":
    unittest.main()
