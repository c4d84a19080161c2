#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""Direct manipulation and inverse mapping from Python (docs/manipulation-and-inverse.md): mesh
point ids and targets from numpy, the moved lattice's deformation checked with numpy; a manipulated mesh mapped
back to rest with vtkFFDInverseDeform.

Run with Debian's /usr/bin/python3, PYTHONPATH=<build>/lib/python3/dist-packages and VOXELFFD_MESH_DIR set to the
folder of the meshes (ctest does both). Exits non-zero when a test fails.
"""
import unittest

import numpy as np
from vtkmodules.util.numpy_support import numpy_to_vtk, numpy_to_vtkIdTypeArray, vtk_to_numpy
from vtkmodules.vtkCommonCore import vtkPoints
from vtkmodules.vtkCommonDataModel import vtkUnstructuredGrid

import vtkffd
from ffdtesting import bbox_diagonal, catch_errors, points_of, read_mesh  # the same folder


def deformed(mesh, lattice):
    deform = vtkffd.vtkFFDDeform()
    deform.SetInputData(mesh)
    deform.SetLatticeData(lattice)
    deform.SetOutputPointsPrecision(1)  # vtkAlgorithm.DOUBLE_PRECISION
    deform.Update()
    return points_of(deform.GetOutput())


class TestDirectManipulation(unittest.TestCase):
    def setUp(self):
        self.mesh = read_mesh("elephant")
        self.diagonal = bbox_diagonal(points_of(self.mesh))
        voxelize = vtkffd.vtkFFDVoxelize()
        voxelize.SetInputData(self.mesh)
        voxelize.SetDivisions(5, 5, 5)
        build = vtkffd.vtkFFDBuildLattice()
        build.SetInputConnection(voxelize.GetOutputPort())
        build.SetBasisToTricubicBezier()
        build.Update()
        self.lattice = vtkUnstructuredGrid()
        self.lattice.DeepCopy(build.GetOutput())

    def manipulate(self, ids, targets):
        manipulate = vtkffd.vtkFFDDirectManipulation()
        manipulate.SetInputData(self.lattice)
        manipulate.SetMeshData(self.mesh)
        manipulate.SetTargetPointIds(numpy_to_vtkIdTypeArray(np.asarray(ids, dtype=np.int64), deep=True))
        positions = vtkPoints()
        positions.SetData(numpy_to_vtk(np.asarray(targets, dtype=np.float64), deep=True))
        manipulate.SetTargetPositions(positions)
        manipulate.Update()
        return manipulate

    def test_targets_are_met_and_far_control_points_stay(self):
        # Two points at the ends of the elephant, each pulled by 3% of its size. A target's deformed point sums at
        # most 64 weighted displacements in float64: 1e-10 of the diagonal bounds what rounding leaves of it.
        points = points_of(self.mesh)
        ids = [int(points[:, 0].argmin()), int(points[:, 0].argmax())]
        targets = points[ids] + 0.03 * self.diagonal * np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
        manipulate = self.manipulate(ids, targets)
        moved = manipulate.GetOutput()
        np.testing.assert_allclose(deformed(self.mesh, moved)[ids], targets, rtol=0, atol=1e-10 * self.diagonal)
        change = np.linalg.norm(points_of(moved) - points_of(self.lattice), axis=1)
        self.assertEqual(int((change > 0).sum()), manipulate.GetNumberOfMovedControlPoints())
        # Each target moves the control points of its Bezier sub-region only: at most 2 x 64.
        self.assertLessEqual(manipulate.GetNumberOfMovedControlPoints(), 128)
        self.assertLess(manipulate.GetMaximumTargetDistance(), 1e-10 * self.diagonal)

    def test_a_bad_id_is_an_error(self):
        manipulate = vtkffd.vtkFFDDirectManipulation()
        errors = catch_errors(manipulate, executive=True)
        manipulate.SetInputData(self.lattice)
        manipulate.SetMeshData(self.mesh)
        manipulate.SetTargetPointIds(numpy_to_vtkIdTypeArray(np.array([10 ** 9], dtype=np.int64), deep=True))
        positions = vtkPoints()
        positions.InsertNextPoint(0.0, 0.0, 0.0)
        manipulate.SetTargetPositions(positions)
        manipulate.Update()
        self.assertTrue(any("names mesh point" in m for m in errors.messages), errors.messages)

    def test_the_inverse_takes_the_deformed_mesh_back_to_rest(self):
        # Newton stops at 1e-12 of the frame's diagonal, so the round trip is within |J^-1| 1e-12 of it: with
        # det J > 0.5 everywhere (asserted: a pull of one point concentrates the move, and larger pulls fold the
        # sub-region) 1e-10 of the mesh's diagonal bounds it with margin. The status array says all were found.
        points = points_of(self.mesh)
        ids = [int(points[:, 2].argmax())]
        moved = self.manipulate(ids, points[ids] + 0.005 * self.diagonal).GetOutput()
        deform = vtkffd.vtkFFDDeform()
        deform.SetInputData(self.mesh)
        deform.SetLatticeData(moved)
        deform.SetOutputPointsPrecision(1)  # vtkAlgorithm.DOUBLE_PRECISION
        deform.ComputeJacobianDeterminantOn()
        deform.Update()
        determinants = deform.GetOutput().GetPointData().GetArray(vtkffd.vtkFFDDeform.JacobianDeterminantArrayName())
        self.assertGreater(determinants.GetRange()[0], 0.5)
        inverse = vtkffd.vtkFFDInverseDeform()
        inverse.SetInputConnection(deform.GetOutputPort())
        inverse.SetLatticeData(moved)
        inverse.Update()
        back = inverse.GetOutput()
        np.testing.assert_allclose(points_of(back), points, rtol=0, atol=1e-10 * self.diagonal)
        status = vtk_to_numpy(back.GetPointData().GetArray(vtkffd.vtkFFDInverseDeform.InverseStatusArrayName()))
        self.assertEqual(int(status.max()), 0)
        self.assertEqual(inverse.GetNumberOfFoldedPoints() + inverse.GetNumberOfUnconvergedPoints(), 0)


if __name__ == "__main__":
    unittest.main()
