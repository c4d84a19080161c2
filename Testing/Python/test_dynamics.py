#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""vtkFFDLatticeDynamics, vtkFFDMagneticSphere and vtkFFDSimulateLattice from Python, against references written
here: under gravity alone the body falls as backward Euler does, u_n = g h^2 n (n + 1) / 2, every simulated
control point alike (numpy views of the lattice's points, the culled ones unmoved); impulses are the momentum
that stays, queued before the first step too; the pipeline's lattice at a time does not depend on the order of the
requests, and a vtkFFDDeform downstream follows it in time (against a vtkFFDDeform of its own on each time's
lattice); a time beyond the end is the end; bad input and settings that cannot be simulated are errors.

Run with Debian's /usr/bin/python3, PYTHONPATH=<build>/lib/python3/dist-packages and VOXELFFD_MESH_DIR set to the
folder of the meshes (ctest does both). Exits non-zero when a test fails.
"""
import math
import unittest

import numpy as np
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkCommonCore import vtkPoints
from vtkmodules.vtkCommonDataModel import vtkDataObject, vtkStructuredGrid
from vtkmodules.vtkCommonExecutionModel import vtkStreamingDemandDrivenPipeline

import vtkffd
from ffdtesting import bbox_diagonal, build_lattice, catch_errors, points_of, read_mesh  # the same folder


class DynamicsTest(unittest.TestCase):
    def setUp(self):
        self.mesh = read_mesh("bear")
        _, _, self.lattice = build_lattice(self.mesh, (5, 5, 5), vtkffd.vtkFFDBuildLattice.TRILINEAR)
        self.size = bbox_diagonal(points_of(self.lattice))

    def test_gravity_translates_the_simulated_points(self):
        # Tolerance: the linear solve's relative error, about cond * epsilon a step (cond < 10^3 here), over 60
        # steps: 1e-10 of the translation.
        before = points_of(self.lattice)
        active = vtk_to_numpy(self.lattice.GetPointData().GetArray("Active")) != 0
        dynamics = vtkffd.vtkFFDLatticeDynamics()
        dynamics.SetLattice(self.lattice)
        dynamics.SetMesh(self.mesh)
        dynamics.SetGravity(0.0, -9.81, 0.0)
        self.assertEqual(dynamics.Step(60), 1)
        h = dynamics.GetTimeStep()
        drop = -9.81 * h * h * 60 * 61 / 2
        expected = before.copy()
        expected[active, 1] += drop
        moved = vtk_to_numpy(self.lattice.GetPoints().GetData())  # a view of the points the simulation wrote
        np.testing.assert_allclose(moved, expected, rtol=0, atol=1e-10 * abs(drop))
        self.assertAlmostEqual(dynamics.GetTime(), 60 * h, delta=1e-12)
        self.assertEqual(dynamics.GetNumberOfSimulatedPoints(), int(active.sum()))
        masses = np.array([dynamics.GetMass(p) for p in range(self.lattice.GetNumberOfPoints())])
        self.assertTrue(np.all(masses[~active] == 0) and np.all(masses[active] > 0))
        self.assertAlmostEqual(masses.sum(), dynamics.GetTotalMass(), delta=1e-12)

    def test_impulses_are_the_momentum_that_stays(self):
        dynamics = vtkffd.vtkFFDLatticeDynamics()
        dynamics.SetLattice(self.lattice)
        dynamics.SetMesh(self.mesh)
        self.assertEqual(dynamics.Initialize(), 1)
        simulated = [p for p in range(self.lattice.GetNumberOfPoints()) if dynamics.GetMass(p) > 0]
        dynamics.ApplyImpulse(simulated[0], 0.5, 0.0, 0.0)
        dynamics.ApplyImpulse(simulated[-1], 0.0, -0.25, 0.125)
        self.assertEqual(dynamics.Step(200), 1)
        momentum = [0.0, 0.0, 0.0]
        dynamics.GetMomentum(momentum)
        np.testing.assert_allclose(momentum, [0.5, -0.25, 0.125], rtol=0, atol=1e-10)

    def test_the_lattice_at_a_time_does_not_depend_on_the_requests(self):
        simulate = vtkffd.vtkFFDSimulateLattice()
        simulate.SetInputData(self.lattice)
        simulate.SetMeshData(self.mesh)
        simulate.SetEndTime(1.0)
        sphere = vtkffd.vtkFFDMagneticSphere()
        path = vtkPoints()
        centre = points_of(self.lattice).mean(axis=0)
        for i in range(8):
            angle = 2 * math.pi * i / 8
            path.InsertNextPoint(centre[0] + 0.6 * self.size * math.cos(angle), centre[1],
                                 centre[2] + 0.6 * self.size * math.sin(angle))
        sphere.SetPath(path)
        sphere.SetRadius(0.1 * self.size)
        sphere.SetStrength(30.0)
        simulate.GetDynamics().AddMagneticSphere(sphere)
        simulate.UpdateInformation()
        self.assertEqual(simulate.GetOutputInformation(0).Get(vtkStreamingDemandDrivenPipeline.TIME_RANGE()),
                         (0.0, 1.0))

        def at(t):
            simulate.UpdateTimeStep(t)
            return points_of(simulate.GetOutput())

        direct = at(0.75)
        self.assertGreater(np.abs(direct - points_of(self.lattice)).max(), 1e-4 * self.size)
        simulate.Modified()  # starts again
        at(0.25)
        np.testing.assert_array_equal(at(0.75), direct)  # continued from 0.25
        np.testing.assert_array_equal(at(0.0), points_of(self.lattice))  # started again: the input

    def test_a_deformed_mesh_follows_the_simulation_in_time(self):
        # Issue 30, item 2: simulation -> vtkFFDDeform, asked for several times (the last one earlier: the
        # simulation starts again). Before, vtkFFDDeform announced only the static mesh's time (none), so no time
        # request re-executed it and the bear never moved. At each time its output must be the bear deformed by
        # the lattice the simulation outputs then, through a vtkFFDDeform of its own on a copy (the same bits).
        simulate = vtkffd.vtkFFDSimulateLattice()
        simulate.SetInputData(self.lattice)
        simulate.SetMeshData(self.mesh)
        simulate.SetEndTime(1.0)
        simulate.GetDynamics().SetGravity(0.0, -9.81, 0.0)
        deform = vtkffd.vtkFFDDeform()
        deform.SetInputData(self.mesh)
        deform.SetLatticeConnection(simulate.GetOutputPort())
        deform.UpdateInformation()
        self.assertEqual(deform.GetOutputInformation(0).Get(vtkStreamingDemandDrivenPipeline.TIME_RANGE()),
                         (0.0, 1.0))
        lowest = []
        for t in (0.0, 0.5, 1.0, 0.5):
            self.assertEqual(deform.UpdateTimeStep(t), 1)
            copy = vtkStructuredGrid()
            copy.ShallowCopy(simulate.GetOutput())
            alone = vtkffd.vtkFFDDeform()
            alone.SetInputData(self.mesh)
            alone.SetLatticeData(copy)
            alone.Update()
            np.testing.assert_array_equal(points_of(deform.GetOutput()), points_of(alone.GetOutput()), f"t={t}")
            lowest.append(points_of(deform.GetOutput())[:, 1].min())
        # Free fall of backward Euler: 30 steps of 1/60 s fall g h^2 30 * 31 / 2 = 1.27 (the bear is ~1 high).
        self.assertLess(lowest[1], lowest[0] - 0.5)
        self.assertLess(lowest[2], lowest[1])
        self.assertEqual(lowest[3], lowest[1])

    def test_a_time_beyond_the_end_is_the_end(self):
        # Issue 30, item 11: 1e5 s with EndTime 1 s is the lattice at 1 s (before: six million steps, and the
        # output said 1e5 s).
        def at(t):
            simulate = vtkffd.vtkFFDSimulateLattice()
            simulate.SetInputData(self.lattice)
            simulate.SetEndTime(1.0)
            simulate.GetDynamics().SetGravity(0.0, -9.81, 0.0)
            simulate.UpdateTimeStep(t)
            return simulate.GetOutput().GetInformation().Get(vtkDataObject.DATA_TIME_STEP()), points_of(
                simulate.GetOutput())

        far_time, far = at(1e5)
        self.assertEqual(far_time, 1.0)
        np.testing.assert_array_equal(far, at(1.0)[1])

    def test_impulses_before_the_first_step_are_applied(self):
        # Issue 30, item 15: the first step's initialization discarded them; a bad id or value is refused.
        dynamics = vtkffd.vtkFFDLatticeDynamics()
        dynamics.SetLattice(self.lattice)
        errors = catch_errors(dynamics)
        active = np.flatnonzero(vtk_to_numpy(self.lattice.GetPointData().GetArray("Active")))
        self.assertEqual(dynamics.ApplyImpulse(-1, 1.0, 0.0, 0.0), 0)
        self.assertIn("the lattice has no point -1", errors.messages[-1])
        self.assertEqual(dynamics.ApplyImpulse(int(active[0]), math.inf, 0.0, 0.0), 0)
        self.assertIn("the impulse must be finite", errors.messages[-1])
        self.assertEqual(dynamics.ApplyImpulse(int(active[0]), 0.0, 0.5, 0.0), 1)
        self.assertEqual(dynamics.Step(10), 1)
        momentum = [0.0, 0.0, 0.0]
        dynamics.GetMomentum(momentum)
        # No external force: the impulse's momentum stays (tolerance as above).
        np.testing.assert_allclose(momentum, [0.0, 0.5, 0.0], rtol=0, atol=1e-10)

    def test_settings_that_cannot_be_simulated_are_errors(self):
        # Issue 30, item 15: a NaN setting filled every control point with NaN and Step() succeeded.
        dynamics = vtkffd.vtkFFDLatticeDynamics()
        dynamics.SetLattice(self.lattice)
        dynamics.SetMesh(self.mesh)
        errors = catch_errors(dynamics)
        before = points_of(self.lattice)
        for setter, bad, good in (("SetTimeStep", math.nan, 1.0 / 60.0), ("SetTotalMass", -1.0, 1.0),
                                  ("SetSpringStiffness", math.inf, 1.0), ("SetCoreStiffness", math.nan, 10.0)):
            getattr(dynamics, setter)(bad)
            self.assertEqual(dynamics.Step(5), 0, setter)
            self.assertIn(f"{setter}({bad:g})", errors.messages[-1])
            np.testing.assert_array_equal(points_of(self.lattice), before, setter)
            getattr(dynamics, setter)(good)
        dynamics.SetGravity(0.0, math.nan, 0.0)
        self.assertEqual(dynamics.Step(5), 0)
        self.assertIn("SetGravity(0, nan, 0): gravity must be finite", errors.messages[-1])
        np.testing.assert_array_equal(points_of(self.lattice), before)

    def test_bad_input_is_an_error(self):
        dynamics = vtkffd.vtkFFDLatticeDynamics()
        errors = catch_errors(dynamics)
        self.assertEqual(dynamics.Step(), 0)
        self.assertIn("No lattice to simulate", errors.messages[-1])
        dynamics.SetLattice(self.lattice)
        dynamics.PinPoint(10 ** 6, 0.0, 0.0, 0.0)
        self.assertEqual(dynamics.Step(), 0)
        self.assertIn("is pinned but is not a simulated control point", errors.messages[-1])


if __name__ == "__main__":
    unittest.main()
