#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""Level of detail from Python (docs/level-of-detail.md): exact refinement, coarsening by least squares,
detail lattices chosen with numpy, and several blocks on one mesh, each checked with numpy against the deformation
it must reproduce.

Run with Debian's /usr/bin/python3, PYTHONPATH=<build>/lib/python3/dist-packages and VOXELFFD_MESH_DIR set to the
folder of the meshes (ctest does both). Exits non-zero when a test fails.
"""
import unittest

import numpy as np
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy
from vtkmodules.util.vtkConstants import VTK_INT
from vtkmodules.vtkCommonCore import vtkPoints
from vtkmodules.vtkCommonDataModel import vtkPolyData, vtkUnstructuredGrid

import vtkffd
from ffdtesting import bbox_diagonal, build_lattice, points_of, read_mesh  # the same folder

Build = vtkffd.vtkFFDBuildLattice
BASES = (Build.BERNSTEIN, Build.TRILINEAR, Build.TRIQUADRATIC_BEZIER, Build.TRICUBIC_BEZIER, Build.CUBIC_BSPLINE)


def deformed(mesh, lattice, double=True):
    """The mesh's points deformed by the lattice, in float64 (or in the mesh's precision)."""
    deform = vtkffd.vtkFFDDeform()
    deform.SetInputData(mesh)
    deform.SetLatticeData(lattice)
    if double:
        deform.SetOutputPointsPrecision(1)  # vtkAlgorithm.DOUBLE_PRECISION
    deform.Update()
    return points_of(deform.GetOutput())


def move_active(lattice, rng, amplitude):
    """Moves the lattice's active points at random by up to `amplitude` per component, through numpy."""
    points = vtk_to_numpy(lattice.GetPoints().GetData())
    active = vtk_to_numpy(lattice.GetPointData().GetArray("Active")) != 0
    points[active] += rng.uniform(-amplitude, amplitude, (int(active.sum()), 3))
    lattice.GetPoints().Modified()


def cloud(xs):
    points = vtkPoints()
    points.SetData(numpy_to_vtk(np.ascontiguousarray(xs, dtype=np.float64), deep=True))
    data = vtkPolyData()
    data.SetPoints(points)
    return data


class TestLevelOfDetail(unittest.TestCase):
    def setUp(self):
        self.cow = read_mesh("cow")
        self.diagonal = bbox_diagonal(points_of(self.cow))
        self.rng = np.random.default_rng(20261126)

    def test_a_refined_lattice_deforms_the_cow_as_the_coarse_one(self):
        # Two float64 sums of at most 35 937 weighted displacements each (docs/level-of-detail.md): 1e-12 of
        # the diagonal bounds their difference.
        for basis in BASES:
            _, _, coarse = build_lattice(self.cow, (3, 2, 2), basis)
            move_active(coarse, self.rng, 0.05 * self.diagonal)
            refine = vtkffd.vtkFFDRefineLattice()
            refine.SetInputData(coarse)
            refine.Update()
            fine = refine.GetOutput()
            self.assertEqual(tuple(vtk_to_numpy(fine.GetFieldData().GetArray("FFDDivisions"))), (6, 4, 4))
            error = np.abs(deformed(self.cow, fine) - deformed(self.cow, coarse)).max()
            self.assertLessEqual(error, 1e-12 * self.diagonal, Build.GetBasisAsString(basis))

    def test_coarsening_a_refined_lattice_returns_it(self):
        # Points filling the frame determine every control point, and Regularization 1e-12 asks for the
        # least-squares fit. For the trilinear basis the scaled normal matrix's condition number kappa is about 60
        # over such points and the regularisation's bias below 1e-20 (TestFFDCoarsenLattice computes both), so the
        # solution is within kappa 1000 eps (1.3e-11) of the original, relative: 1e-9 leaves room for the sample.
        box = cloud(self.rng.uniform(0, 1, (5000, 3)) * (1.0, 0.6, 0.4))
        _, _, original = build_lattice(box, (3, 2, 2), Build.TRILINEAR)
        move_active(original, self.rng, 0.05)
        refine = vtkffd.vtkFFDRefineLattice()
        refine.SetInputData(original)
        coarsen = vtkffd.vtkFFDCoarsenLattice()
        coarsen.SetInputConnection(refine.GetOutputPort())
        coarsen.SetMeshData(box)
        coarsen.SetRegularization(1e-12)
        coarsen.Update()
        want = points_of(original) - vtk_to_numpy(original.GetPointData().GetArray("RestPosition"))
        got = points_of(coarsen.GetOutput()) - vtk_to_numpy(coarsen.GetOutput().GetPointData().GetArray("RestPosition"))
        self.assertLessEqual(np.abs(got - want).max(), 1e-9 * np.abs(want).max())
        self.assertLessEqual(coarsen.GetMaximumResidual(), 1e-9)

    def test_a_detail_lattice_over_numpy_selected_voxels_adds_local_detail(self):
        voxelize = vtkffd.vtkFFDVoxelize()
        voxelize.SetInputData(self.cow)
        voxelize.SetDivisions(4, 4, 4)
        build = vtkffd.vtkFFDBuildLattice()
        build.SetInputConnection(voxelize.GetOutputPort())
        build.SetBasisToCubicBSpline()
        build.Update()
        base = vtkUnstructuredGrid()
        base.DeepCopy(build.GetOutput())
        move_active(base, self.rng, 0.02 * self.diagonal)
        # The two voxels of the head end (i = 3) at mid height.
        selected = numpy_to_vtk(np.array([[3, 1, 1], [3, 2, 1]], dtype=np.int32), deep=True, array_type=VTK_INT)
        detail = vtkffd.vtkFFDBuildDetailLattice()
        detail.SetInputData(base)
        detail.SetSelectedVoxels(selected)
        detail.Update()
        self.assertEqual(detail.GetNumberOfRefinedVoxels(), 2)
        # Changing the selection's values alone re-executes the filter (as ParaView's properties change it).
        selected.SetNumberOfTuples(1)
        selected.Modified()
        detail.Update()
        self.assertEqual(detail.GetNumberOfRefinedVoxels(), 1)
        selected.InsertNextTuple3(3, 2, 1)
        selected.Modified()  # value changes do not touch an array's modification time by themselves
        detail.Update()
        self.assertEqual(detail.GetNumberOfRefinedVoxels(), 2)
        levels = vtkUnstructuredGrid()
        levels.DeepCopy(detail.GetOutput())
        add = vtkffd.vtkFFDDeformBlocks()
        add.SetCompositionToAdd()
        add.SetInputData(self.cow)
        add.AddLatticeData(base)
        add.AddLatticeData(levels)
        add.Update()
        base_only = deformed(self.cow, base, double=False)
        np.testing.assert_array_equal(points_of(add.GetOutput()), base_only)
        move_active(levels, self.rng, 0.02 * self.diagonal)
        add.Update()
        changed = np.any(points_of(add.GetOutput()) != base_only, axis=1)
        # The detail's cells reach 3 fine voxels (of 8) beyond the selection's halves (6 and 7) along the frame's
        # axis-aligned S: s >= 3/8.
        frame = vtk_to_numpy(base.GetFieldData().GetArray("FFDFrame")).reshape(4, 3)
        s = (points_of(self.cow)[:, 0] - frame[0, 0]) / frame[1, 0]
        self.assertTrue(changed.any())
        self.assertGreaterEqual(s[changed].min(), 3 / 8 - 1e-12)

    def test_blended_blocks_leave_the_points_of_blocks_at_rest_unchanged(self):
        points = points_of(self.cow)
        low, high = points.min(axis=0), points.max(axis=0)
        middle = 0.5 * (low[0] + high[0])
        blend = vtkffd.vtkFFDDeformBlocks()
        blend.SetInputData(self.cow)
        lattices = []
        for x0, x1 in ((low[0], middle), (middle, high[0])):
            voxelize = vtkffd.vtkFFDVoxelize()
            voxelize.SetInputData(self.cow)
            voxelize.SetFrame((x0, low[1], low[2]), (x1 - x0, 0, 0), (0, high[1] - low[1], 0), (0, 0, high[2] - low[2]))
            voxelize.SetDivisions(2, 2, 2)
            build = vtkffd.vtkFFDBuildLattice()
            build.SetInputConnection(voxelize.GetOutputPort())
            build.SetBasisToTricubicBezier()
            build.Update()
            lattice = vtkUnstructuredGrid()
            lattice.DeepCopy(build.GetOutput())
            lattices.append(lattice)
            blend.AddLatticeData(lattice)
        self.assertEqual(blend.GetNumberOfLattices(), 2)
        move_active(lattices[1], self.rng, 0.05 * self.diagonal)
        blend.Update()
        moved = points_of(blend.GetOutput())
        behind = points[:, 0] < middle
        np.testing.assert_array_equal(moved[behind], points[behind])
        self.assertTrue(np.any(moved[~behind] != points[~behind]))


if __name__ == "__main__":
    unittest.main()
