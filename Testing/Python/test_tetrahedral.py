#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""The tetrahedral FFD from Python: vtkFFDBuildTetrahedralLattice -> (numpy moves the nodes) -> vtkFFDDeform on
the real elephant mesh, checked against an independent float64 numpy reference written here (barycentric weights
by solving [B-A, C-A, D-A] w = X - A for every point in every tetrahedron, the absolute form sum w P), and the
filters' Python API (properties, policies, errors on bad lattices).

Run with Debian's /usr/bin/python3, PYTHONPATH=<build>/lib/python3/dist-packages and VOXELFFD_MESH_DIR set (ctest
does both). Exits non-zero when a test fails.
"""
import unittest

import numpy as np
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy
from vtkmodules.vtkCommonDataModel import vtkUnstructuredGrid

import vtkffd
from ffdtesting import bbox_diagonal, catch_errors, points_of, read_mesh  # the same folder

# Deformed points agree with the reference within this fraction of the mesh's bounding-box diagonal: both
# compute in double precision; the filter folds the weights into one affine map per tetrahedron, the reference
# solves a 3x3 system per point.
RELATIVE_TOLERANCE = 1e-10


def reference_deform(rest, moved, tetrahedra, points):
    """Every point's position under the control mesh: the tetrahedron where its smallest weight is largest (its
    own, or one it is on the face of), the weights' sum of the moved nodes; points outside every tetrahedron by
    more than 1e-9 keep their position."""
    a = rest[tetrahedra[:, 0]]
    edges = np.stack([rest[tetrahedra[:, k]] - a for k in (1, 2, 3)], axis=2)  # (T, 3, 3): columns B-A, C-A, D-A
    inverse = np.linalg.inv(edges)
    out = points.copy()
    for i, x in enumerate(points):
        stu = np.einsum("tij,tj->ti", inverse, x - a)  # (T, 3)
        weights = np.concatenate([1.0 - stu.sum(axis=1, keepdims=True), stu], axis=1)
        margins = weights.min(axis=1)
        t = int(np.argmax(margins))
        if margins[t] >= -1e-9:
            out[i] = weights[t] @ moved[tetrahedra[t]]
    return out


class TetrahedralPipelineTest(unittest.TestCase):
    def setUp(self):
        self.mesh = read_mesh("elephant")
        self.build = vtkffd.vtkFFDBuildTetrahedralLattice()
        self.build.SetInputData(self.mesh)
        self.build.SetSubdivisionLevels(1)
        self.build.Update()

    def test_lattice_keeps_the_data_contract(self):
        lattice = self.build.GetOutput()
        self.assertIsInstance(lattice, vtkUnstructuredGrid)
        self.assertEqual(lattice.GetNumberOfCells(), 8 * self.build.GetNumberOfHullFaces())
        self.assertTrue(lattice.IsHomogeneous())
        self.assertEqual(lattice.GetCellType(0), 10)  # VTK_TETRA
        rest = vtk_to_numpy(lattice.GetPointData().GetArray("RestPosition"))
        np.testing.assert_array_equal(rest, vtk_to_numpy(lattice.GetPoints().GetData()))
        active = vtk_to_numpy(lattice.GetPointData().GetArray("Active"))
        self.assertEqual(int(active.sum()), self.build.GetNumberOfActiveNodes())
        self.assertGreater(self.build.GetPadding(), 0.0)

    def test_moved_nodes_deform_the_mesh_as_the_reference_does(self):
        lattice = vtkUnstructuredGrid()
        lattice.DeepCopy(self.build.GetOutput())
        rest = vtk_to_numpy(lattice.GetPointData().GetArray("RestPosition")).copy()
        rng = np.random.default_rng(5)
        moved = rest + rng.uniform(-0.03, 0.03, rest.shape)
        lattice.GetPoints().SetData(numpy_to_vtk(moved, deep=True))

        deform = vtkffd.vtkFFDDeform()
        deform.SetInputData(self.mesh)
        deform.SetLatticeData(lattice)
        deform.SetBackendToCPU()
        deform.Update()
        self.assertEqual(deform.GetLastBackendUsed(), "CPU")
        self.assertEqual(deform.GetNumberOfBindings(), 1)
        points = points_of(self.mesh)
        got = vtk_to_numpy(deform.GetOutput().GetPoints().GetData())
        tetrahedra = vtk_to_numpy(lattice.GetCells().GetConnectivityArray()).reshape(-1, 4)
        expected = reference_deform(rest, moved, tetrahedra, points)
        diagonal = bbox_diagonal(points)
        self.assertLess(float(np.abs(got - expected).max()), RELATIVE_TOLERANCE * diagonal)
        self.assertGreater(float(np.abs(got - points).max()), 0.01 * diagonal)

        # Moving the nodes again re-uses the binding.
        lattice.GetPoints().SetData(numpy_to_vtk(rest, deep=True))
        deform.Update()
        np.testing.assert_array_equal(vtk_to_numpy(deform.GetOutput().GetPoints().GetData()), points)
        self.assertEqual(deform.GetNumberOfBindings(), 1)

    def test_outside_policies_by_name(self):
        deform = vtkffd.vtkFFDDeform()
        for setter, name in ((deform.SetOutsidePolicyToKeepPosition, "KeepPosition"),
                             (deform.SetOutsidePolicyToClampToEdge, "ClampToEdge"),
                             (deform.SetOutsidePolicyToExtrapolate, "Extrapolate")):
            setter()
            self.assertEqual(deform.GetOutsidePolicyAsString(), name)

    def test_a_lattice_of_hexahedra_is_an_error(self):
        from vtkmodules.vtkCommonDataModel import vtkImageData
        from vtkmodules.vtkFiltersCore import vtkAppendFilter
        image = vtkImageData()
        image.SetDimensions(3, 3, 3)
        append = vtkAppendFilter()  # an unstructured grid of voxels
        append.AddInputData(image)
        append.Update()
        hexahedra = append.GetOutput()
        hexahedra.GetPointData().AddArray(numpy_to_vtk(vtk_to_numpy(hexahedra.GetPoints().GetData()), deep=True))
        hexahedra.GetPointData().GetArray(0).SetName("RestPosition")
        deform = vtkffd.vtkFFDDeform()
        catcher = catch_errors(deform, executive=True)
        deform.SetInputData(self.mesh)
        deform.SetLatticeData(hexahedra)
        deform.Update()
        self.assertEqual(deform.GetOutput().GetNumberOfPoints(), 0)
        self.assertTrue(any("is not a tetrahedron" in m for m in catcher.messages), catcher.messages)


    def test_overflowing_nodes_and_integer_rest_positions_are_errors(self):
        # A node at 1e308 made every deformed point NaN or inf, and an integer RestPosition (the contract says
        # doubles) moved the mesh by its truncation, both without a word: now each is an error, the output empty.
        def deformed_with(change):
            lattice = vtkUnstructuredGrid()
            lattice.DeepCopy(self.build.GetOutput())
            change(lattice)
            deform = vtkffd.vtkFFDDeform()
            catcher = catch_errors(deform, executive=True)
            deform.SetInputData(self.mesh)
            deform.SetLatticeData(lattice)
            deform.Update()
            return deform.GetOutput().GetNumberOfPoints(), catcher.messages

        def far_node(lattice):
            vtk_to_numpy(lattice.GetPoints().GetData())[7] = (1e308, 0.0, 0.0)
            lattice.GetPoints().Modified()

        def integer_rest(lattice):
            rest = vtk_to_numpy(lattice.GetPointData().GetArray("RestPosition"))
            integers = numpy_to_vtk(rest.astype(np.int32), deep=True)
            integers.SetName("RestPosition")
            lattice.GetPointData().AddArray(integers)

        for change, expected in (
                (far_node, "Tetrahedral lattice point 7 or its RestPosition is not finite or lies beyond +-1e+100"),
                (integer_rest, "RestPosition array holds int values; the data contract asks for doubles")):
            with self.subTest(change=change.__name__):
                count, messages = deformed_with(change)
                self.assertEqual(count, 0)
                self.assertTrue(any(expected in m for m in messages), messages)


if __name__ == "__main__":
    unittest.main()
