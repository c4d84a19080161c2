#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""The Rendering module from Python: vtkFFDLatticeActor's parts (grid and hand-made tetrahedral lattices, voxel
boxes without the hidden voxels, culled points, displacement colours), vtkFFDCellEdges, vtkFFDControlPoints,
and vtkFFDLatticeRepresentation / vtkFFDLatticeWidget's API, keys, dragging mesh points (direct manipulation) and
bad input (no lattice, a lattice without the data contract's arrays, malformed arrays). Renders offscreen, so it runs in an X display
(Utilities/with-display.sh); PYTHONPATH=<build>/lib/python3/dist-packages.
"""
import unittest

import numpy as np
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy
from vtkmodules.vtkCommonCore import vtkCommand, vtkIdList, vtkPoints
from vtkmodules.vtkCommonDataModel import VTK_TETRA, vtkStructuredGrid, vtkUnstructuredGrid
from vtkmodules.vtkCommonExecutionModel import vtkAlgorithm
from vtkmodules.vtkFiltersSources import vtkSphereSource
from vtkmodules.vtkInteractionStyle import vtkInteractorStyleTrackballCamera
from vtkmodules.vtkRenderingCore import vtkInteractorObserver, vtkRenderer, vtkRenderWindowInteractor
import vtkmodules.vtkRenderingOpenGL2  # noqa: F401

import vtkffd
from ffdtesting import build_lattice, catch_errors, offscreen_window, run_with_errors  # the same folder


def cube_tetrahedra():
    """A unit cube split into 5 tetrahedra (8 points, 18 edges: 12 cube edges and 6 face diagonals), with the
    data contract's point arrays, as a tetrahedral lattice (paper Figure 9) will carry them."""
    corners = np.array([[i, j, k] for k in (0, 1) for j in (0, 1) for i in (0, 1)], dtype=float)
    grid = vtkUnstructuredGrid()
    points = vtkPoints()
    points.SetData(numpy_to_vtk(corners, deep=True))
    grid.SetPoints(points)
    for tet in ((0, 1, 2, 4), (1, 3, 2, 7), (1, 4, 5, 7), (2, 4, 7, 6), (1, 2, 4, 7)):
        ids = vtkIdList()
        for p in tet:
            ids.InsertNextId(p)
        grid.InsertNextCell(VTK_TETRA, ids)
    rest = numpy_to_vtk(corners, deep=True)
    rest.SetName("RestPosition")
    grid.GetPointData().AddArray(rest)
    active = numpy_to_vtk(np.array([1, 1, 1, 1, 1, 1, 1, 0], dtype=np.uint8), deep=True)
    active.SetName("Active")
    grid.GetPointData().AddArray(active)
    return grid


def sphere_lattice(divisions=(5, 5, 5)):
    """A 6 x 6 x 6 TRILINEAR lattice around a sphere's surface: the corner voxels and the inner ones hold no
    point, so some control points are culled."""
    sphere = vtkSphereSource()
    sphere.SetThetaResolution(24)
    sphere.SetPhiResolution(16)
    return build_lattice(sphere.GetOutputPort(), divisions, vtkffd.vtkFFDBuildLattice.TRILINEAR)


def parts(actor):
    """The part actors of a vtkFFDLatticeActor, by their mapper's class and input size."""
    actor.GetBounds()  # brings the parts up to date, as a render does
    collection = actor.GetParts()
    return [collection.GetItemAsObject(i) for i in range(collection.GetNumberOfItems())]


def part_inputs(actor):
    return [p.GetMapper().GetInputDataObject(0, 0) for p in parts(actor) if p.GetVisibility()]


class LatticeActorTest(unittest.TestCase):
    def test_tetrahedral_lattice_points_and_edges(self):
        grid = cube_tetrahedra()
        actor = vtkffd.vtkFFDLatticeActor()
        actor.SetInputData(grid)
        inputs = part_inputs(actor)
        lines = [d for d in inputs if d.GetNumberOfLines() > 0]
        vertices = sorted(d.GetNumberOfVerts() for d in inputs if d.GetNumberOfVerts() > 0)
        self.assertEqual(len(lines), 1)
        self.assertEqual(lines[0].GetNumberOfLines(), 18)
        self.assertEqual(vertices, [1, 7])  # one culled, seven active control points
        # The edges follow the lattice's points: move one and render again.
        grid.GetPoints().SetPoint(7, 2.0, 2.0, 2.0)
        grid.GetPoints().Modified()
        self.assertEqual(actor.GetBounds()[1] > 1.9, True)
        lines = [d for d in part_inputs(actor) if d.GetNumberOfLines() > 0][0]
        self.assertEqual(lines.GetPoint(7), (2.0, 2.0, 2.0))

    def test_voxel_boxes_are_the_active_voxels(self):
        voxelize, build, lattice = sphere_lattice()
        voxelize.Update()
        grid = voxelize.GetOutput()
        active = voxelize.GetNumberOfActiveVoxels()
        self.assertLess(active, 125)  # the sphere leaves the corner and inner voxels empty
        self.assertEqual(grid.GetNumberOfCells(), active)  # the voxel grid holds the active voxels only
        edges = vtkffd.vtkFFDCellEdges()
        edges.SetInputData(grid)
        edges.Update()
        # Reference: the unique edges of the active voxels, from their VoxelIndex, as pairs of corners.
        unique = set()
        for i, j, k in vtk_to_numpy(grid.GetCellData().GetArray("VoxelIndex")):
            for a in range(8):
                c = (i + (a & 1), j + ((a >> 1) & 1), k + ((a >> 2) & 1))
                for axis in range(3):
                    if c[axis] == (i, j, k)[axis]:
                        d = list(c)
                        d[axis] += 1
                        unique.add((c, tuple(d)))
        self.assertEqual(edges.GetOutput().GetNumberOfLines(), len(unique))

        # Hidden cells are skipped: the full 5x5x5 grid's 3 * 5 * 6 * 6 edges, and fewer with a hidden corner cell.
        full = vtkStructuredGrid()
        full.SetDimensions(6, 6, 6)
        corners = vtkPoints()
        corners.SetData(numpy_to_vtk(np.array([[i, j, k] for k in range(6) for j in range(6) for i in range(6)],
                                              dtype=float), deep=True))
        full.SetPoints(corners)
        edges.SetInputData(full)
        edges.Update()
        self.assertEqual(edges.GetOutput().GetNumberOfLines(), 3 * 5 * 6 * 6)
        full.BlankCell(0)
        full.Modified()
        edges.Update()
        self.assertEqual(edges.GetOutput().GetNumberOfLines(), 3 * 5 * 6 * 6 - 3)  # its edges on the grid's corner

        actor = vtkffd.vtkFFDLatticeActor()
        actor.SetInputData(lattice)
        actor.SetVoxelGridConnection(voxelize.GetOutputPort())
        self.assertEqual(len(part_inputs(actor)), 4)  # active, culled points, lattice edges, voxel boxes
        actor.SetVoxelGridData(None)
        self.assertEqual(len(part_inputs(actor)), 3)

    def test_sparse_lattice_draws_its_control_net(self):
        # Every local basis: the sparse lattice's edges are the lines between its control points one lattice step
        # apart (reference: pairs of LatticeIndex from numpy), the control points are all drawn active, and the
        # edges follow a moved point.
        sphere = vtkSphereSource()
        sphere.SetThetaResolution(24)
        sphere.SetPhiResolution(16)
        for basis in (vtkffd.vtkFFDBuildLattice.TRILINEAR, vtkffd.vtkFFDBuildLattice.TRIQUADRATIC_BEZIER,
                      vtkffd.vtkFFDBuildLattice.TRICUBIC_BEZIER, vtkffd.vtkFFDBuildLattice.CUBIC_BSPLINE):
            voxelize = vtkffd.vtkFFDVoxelize()
            voxelize.SetInputConnection(sphere.GetOutputPort())
            voxelize.SetDivisions(5, 5, 5)
            build = vtkffd.vtkFFDBuildLattice()
            build.SetInputConnection(voxelize.GetOutputPort())
            build.SetBasis(basis)
            build.Update()
            lattice = vtkUnstructuredGrid()
            lattice.DeepCopy(build.GetOutputDataObject(0))
            index = vtk_to_numpy(lattice.GetPointData().GetArray("LatticeIndex"))
            present = {tuple(ijk) for ijk in index}
            expected = sum(1 for ijk in present for axis in range(3)
                           if tuple(ijk[a] + (a == axis) for a in range(3)) in present)
            actor = vtkffd.vtkFFDLatticeActor()
            actor.SetInputData(lattice)
            inputs = part_inputs(actor)
            lines = [d for d in inputs if d.GetNumberOfLines() > 0]
            vertices = [d.GetNumberOfVerts() for d in inputs if d.GetNumberOfVerts() > 0]
            self.assertEqual(len(lines), 1, basis)
            self.assertEqual(lines[0].GetNumberOfLines(), expected, basis)
            self.assertEqual(vertices, [lattice.GetNumberOfPoints()], basis)  # all active, none culled
            lattice.GetPoints().SetPoint(0, 9.0, 9.0, 9.0)
            lattice.GetPoints().Modified()
            lines = [d for d in part_inputs(actor) if d.GetNumberOfLines() > 0][0]
            self.assertEqual(lines.GetPoint(0), (9.0, 9.0, 9.0))

    def test_control_points_arrays_and_colours(self):
        _, build, lattice = sphere_lattice()
        points = vtk_to_numpy(lattice.GetPoints().GetData())
        moved = int(np.flatnonzero(vtk_to_numpy(lattice.GetPointData().GetArray("Active")))[0])
        points[moved] += (0.0, 0.3, 0.4)
        lattice.GetPoints().Modified()
        control = vtkffd.vtkFFDControlPoints()
        control.SetInputData(lattice)
        control.Update()
        out = control.GetOutput()
        self.assertEqual(out.GetNumberOfPoints(), build.GetNumberOfActiveControlPoints())
        ids = vtk_to_numpy(out.GetPointData().GetArray("LatticePointId"))
        lengths = vtk_to_numpy(out.GetPointData().GetArray("DisplacementLength"))
        self.assertAlmostEqual(float(lengths[list(ids).index(moved)]), 0.5, delta=1e-12)
        self.assertEqual(float(np.delete(lengths, list(ids).index(moved)).max()), 0.0)
        control.SetSelectionToCulled()
        control.Update()
        self.assertEqual(control.GetOutput().GetNumberOfPoints(), 216 - build.GetNumberOfActiveControlPoints())

        actor = vtkffd.vtkFFDLatticeActor()
        actor.SetInputData(lattice)
        actor.ColorByDisplacementOn()
        glyphs = [p for p in parts(actor) if p.GetProperty() is actor.GetPointProperty()][0]
        self.assertTrue(glyphs.GetMapper().GetScalarVisibility())
        self.assertAlmostEqual(glyphs.GetMapper().GetScalarRange()[1], 0.5, delta=1e-12)
        actor.SetDisplacementRange(0.0, 2.0)
        actor.GetBounds()
        self.assertEqual(glyphs.GetMapper().GetScalarRange(), (0.0, 2.0))
        actor.ShowCulledPointsOff()
        self.assertFalse([p for p in parts(actor) if p.GetProperty() is actor.GetCulledPointProperty()][0]
                         .GetVisibility())

    def test_lattice_without_contract_arrays(self):
        grid = cube_tetrahedra()
        grid.GetPointData().RemoveArray("Active")
        grid.GetPointData().RemoveArray("RestPosition")
        actor = vtkffd.vtkFFDLatticeActor()
        actor.SetInputData(grid)
        vertices = [d.GetNumberOfVerts() for d in part_inputs(actor) if d.GetNumberOfVerts() > 0]
        self.assertEqual(vertices, [8])  # every point active, displacement 0

    def test_malformed_rest_position_is_an_error(self):
        grid = cube_tetrahedra()
        bad = numpy_to_vtk(np.zeros((8, 2)), deep=True)
        bad.SetName("RestPosition")
        grid.GetPointData().AddArray(bad)
        control = vtkffd.vtkFFDControlPoints()
        errors = run_with_errors(control, grid)
        self.assertTrue(any("RestPosition" in m for m in errors), errors)
        self.assertEqual(control.GetOutput().GetNumberOfPoints(), 0)

    def test_cell_naming_a_missing_point_is_an_error(self):
        # A tetrahedron naming point 100000 of 8: refused before any point is read through it (it crashed).
        grid = cube_tetrahedra()
        grid.GetCells().ReplaceCellAtId(1, 4, [0, 1, 100000, 3])
        edges = vtkffd.vtkFFDCellEdges()
        errors = run_with_errors(edges, grid)
        self.assertTrue(any("names point 100000" in m for m in errors), errors)
        self.assertEqual(edges.GetOutput().GetNumberOfLines(), 0)

    def test_no_input_renders_nothing_and_does_not_fail(self):
        actor = vtkffd.vtkFFDLatticeActor()
        self.assertIn("Lattice: (none)", str(actor))
        renderer = vtkRenderer()
        renderer.AddActor(actor)
        window = offscreen_window(renderer)
        window.Render()
        actor.SetInputData(None)
        window.Render()


class LatticeWidgetTest(unittest.TestCase):
    def setUp(self):
        _, self.build, self.lattice = sphere_lattice()
        self.renderer = vtkRenderer()
        self.window = offscreen_window(self.renderer, (400, 400))
        self.interactor = vtkRenderWindowInteractor()
        self.interactor.SetRenderWindow(self.window)
        self.interactor.SetInteractorStyle(vtkInteractorStyleTrackballCamera())
        self.widget = vtkffd.vtkFFDLatticeWidget()
        self.widget.SetInteractor(self.interactor)
        self.widget.CreateDefaultRepresentation()
        self.rep = self.widget.GetLatticeRepresentation()

    def enable(self, lattice):
        self.rep.SetLattice(lattice)
        self.widget.On()
        self.renderer.ResetCamera(-1, 1, -1, 1, -1, 1)
        self.window.Render()

    def display(self, point_id):
        d = [0.0, 0.0, 0.0]
        vtkInteractorObserver.ComputeWorldToDisplay(self.renderer, *self.lattice.GetPoint(point_id), d)
        return round(d[0]), round(d[1])

    def event(self, event, position, shift=False):
        self.interactor.SetEventInformation(position[0], position[1], 0, 1 if shift else 0)
        self.interactor.InvokeEvent(event)

    def key(self, code, sym):
        self.interactor.SetKeyEventInformation(0, 0, code, 0, sym)
        self.interactor.InvokeEvent(vtkCommand.KeyPressEvent)

    def test_selection_api_and_culled_points(self):
        self.enable(self.lattice)
        active = vtk_to_numpy(self.lattice.GetPointData().GetArray("Active"))
        culled = int(np.flatnonzero(active == 0)[0])
        self.assertFalse(self.rep.SelectControlPoint(culled))
        chosen = int(np.flatnonzero(active)[0])
        self.assertFalse(self.rep.SelectControlPoint(216))  # out of range
        self.rep.PickCulledPointsOn()
        self.assertTrue(self.rep.SelectControlPoint(culled))
        self.assertTrue(self.rep.SelectControlPoint(chosen))
        self.assertFalse(self.rep.ToggleControlPoint(culled))
        ids = vtkIdList()
        self.rep.GetSelectedControlPoints(ids)
        self.assertEqual([ids.GetId(i) for i in range(ids.GetNumberOfIds())], [chosen])
        before = np.array(self.lattice.GetPoint(chosen))
        self.assertTrue(self.rep.MoveSelectedControlPoints((0.1, 0.2, 0.3)))
        np.testing.assert_allclose(np.array(self.lattice.GetPoint(chosen)) - before, (0.1, 0.2, 0.3), atol=1e-15)
        self.assertTrue(self.rep.ResetLatticeToRest())
        self.assertEqual(self.lattice.GetPoint(chosen), tuple(before))

    def test_selection_is_dropped_when_the_lattice_changes_size(self):
        """Issue 30, item 16: ids selected before the lattice's points shrank were kept, and
        MoveSelectedControlPoints() wrote past the end of its points. The selection is dropped once the number of
        points changes; nothing moves and nothing is written."""
        self.enable(self.lattice)
        active = np.flatnonzero(vtk_to_numpy(self.lattice.GetPointData().GetArray("Active")))
        first, last = int(active[0]), int(active[-1])
        self.assertTrue(self.rep.SelectControlPoint(first) and self.rep.SelectControlPoint(last))
        _, _, smaller = sphere_lattice((2, 2, 2))  # 27 points: `last` is past its end
        self.assertLess(smaller.GetNumberOfPoints(), last)
        self.lattice.ShallowCopy(smaller)  # as a pipeline re-executing into the same object would
        before = vtk_to_numpy(self.lattice.GetPoints().GetData()).copy()
        self.assertFalse(self.rep.MoveSelectedControlPoints((0.1, 0.2, 0.3)))
        np.testing.assert_array_equal(vtk_to_numpy(self.lattice.GetPoints().GetData()), before)
        self.assertEqual(self.rep.GetNumberOfSelectedControlPoints(), 0)
        self.assertFalse(self.rep.IsControlPointSelected(first))
        self.window.Render()  # the highlight names no point past the end either
        # Selecting anew on the smaller lattice works as before.
        self.assertTrue(self.rep.SelectControlPoint(first))
        self.assertTrue(self.rep.MoveSelectedControlPoints((0.1, 0.2, 0.3)))
        np.testing.assert_allclose(np.array(self.lattice.GetPoint(first)) - before[first], (0.1, 0.2, 0.3), atol=1e-15)

    def click(self, position, shift=False):
        self.event(vtkCommand.MouseMoveEvent, position, shift)
        self.event(vtkCommand.LeftButtonPressEvent, position, shift)
        self.event(vtkCommand.LeftButtonReleaseEvent, position, shift)
        return self.rep.GetHoveredControlPoint()

    def test_shift_click_escape_and_reset_key(self):
        self.enable(self.lattice)
        active = np.flatnonzero(vtk_to_numpy(self.lattice.GetPointData().GetArray("Active")))
        first_position = self.display(int(active[0]))
        # A second active point well apart on screen from the first (more than twice the pick tolerance).
        second_position = next(self.display(int(i)) for i in active
                               if np.hypot(*np.subtract(self.display(int(i)), first_position)) > 30)
        first = self.click(first_position)
        self.assertGreaterEqual(first, 0)
        self.assertEqual(self.rep.GetNumberOfSelectedControlPoints(), 1)
        second = self.click(second_position, shift=True)
        self.assertNotEqual(second, first)
        self.assertTrue(self.rep.IsControlPointSelected(first) and self.rep.IsControlPointSelected(second))
        self.click(second_position, shift=True)  # Shift+click again toggles it off
        self.assertEqual(self.rep.GetNumberOfSelectedControlPoints(), 1)
        self.key("\x1b", "Escape")
        self.assertEqual(self.rep.GetNumberOfSelectedControlPoints(), 0)
        vtk_to_numpy(self.lattice.GetPoints().GetData())[:] += 0.25
        self.lattice.GetPoints().Modified()
        self.key("x", "x")
        np.testing.assert_array_equal(vtk_to_numpy(self.lattice.GetPoints().GetData()),
                                      vtk_to_numpy(self.lattice.GetPointData().GetArray("RestPosition")))

    def world(self, position, depth):
        w = [0.0, 0.0, 0.0, 0.0]
        vtkInteractorObserver.ComputeDisplayToWorld(self.renderer, position[0], position[1], depth, w)
        return np.array(w[:3])

    def test_mesh_point_mode_drags_a_point_of_the_surface(self):
        """Key `m`, then a drag of a sphere's point: the point, deformed by the moved lattice, is where the cursor
        took it (its start plus the cursor's motion on the view-parallel plane through it) within 1e-9 of the
        lattice's size (one target: the solve is exact up to rounding); only the 8 control points of its voxel
        move. MoveMeshPoint() without events; bad ids and a missing mesh are errors."""
        sphere = vtkSphereSource()
        sphere.SetThetaResolution(24)
        sphere.SetPhiResolution(16)
        sphere.Update()
        mesh = sphere.GetOutput()
        self.rep.SetMesh(mesh)
        self.enable(self.lattice)
        self.key("m", "m")
        self.assertEqual(self.rep.GetManipulationMode(), vtkffd.vtkFFDLatticeRepresentation.MESH_POINTS)
        deform = vtkffd.vtkFFDDeform()
        deform.SetInputData(mesh)
        deform.SetLatticeData(self.lattice)
        deform.SetOutputPointsPrecision(vtkAlgorithm.DOUBLE_PRECISION)  # the sphere's points are float
        rest = vtk_to_numpy(self.lattice.GetPointData().GetArray("RestPosition")).copy()
        size = float(np.linalg.norm(rest.max(axis=0) - rest.min(axis=0)))

        # A point facing the camera (which looks down -z).
        points = vtk_to_numpy(mesh.GetPoints().GetData())
        d = [0.0, 0.0, 0.0]
        vtkInteractorObserver.ComputeWorldToDisplay(self.renderer, *points[int(np.argmax(points[:, 2]))], d)
        start = (round(d[0]), round(d[1]))
        self.event(vtkCommand.MouseMoveEvent, start)
        self.event(vtkCommand.LeftButtonPressEvent, start)
        picked = self.rep.GetHoveredMeshPoint()
        self.assertGreaterEqual(picked, 0)
        self.assertTrue(self.widget.IsDragging())
        vtkInteractorObserver.ComputeWorldToDisplay(self.renderer, *points[picked], d)
        depth = d[2]
        end = (start[0] + 30, start[1] + 12)
        self.event(vtkCommand.MouseMoveEvent, (start[0] + 15, start[1] + 5))
        self.event(vtkCommand.MouseMoveEvent, end)
        self.event(vtkCommand.LeftButtonReleaseEvent, end)
        self.assertFalse(self.widget.IsDragging())
        expected = points[picked] + self.world(end, depth) - self.world(start, depth)
        self.assertGreater(np.linalg.norm(expected - points[picked]), 0.05 * size)
        deform.Update()
        got = np.array(deform.GetOutput().GetPoint(picked))
        self.assertLess(np.linalg.norm(got - expected), 1e-9 * size)
        moved = np.flatnonzero(np.any(vtk_to_numpy(self.lattice.GetPoints().GetData()) != rest, axis=1))
        self.assertTrue(1 <= len(moved) <= 8, moved)

        other = int(np.argmin(points[:, 0]))
        target = np.array(deform.GetOutput().GetPoint(other)) + (0.0, 0.1 * size, 0.0)
        self.assertTrue(self.rep.MoveMeshPoint(other, target))
        deform.Update()
        self.assertLess(np.linalg.norm(np.array(deform.GetOutput().GetPoint(other)) - target), 1e-9 * size)
        errors = catch_errors(self.rep)
        self.assertFalse(self.rep.MoveMeshPoint(mesh.GetNumberOfPoints(), target))
        self.rep.SetMesh(None)
        self.assertFalse(self.rep.MoveMeshPoint(0, target))
        self.assertEqual(len(errors.messages), 2, errors.messages)
        self.key("m", "m")
        self.assertEqual(self.rep.GetManipulationMode(), vtkffd.vtkFFDLatticeRepresentation.CONTROL_POINTS)

    def test_no_lattice(self):
        self.widget.On()
        self.window.Render()
        errors = catch_errors(self.rep)
        for event in (vtkCommand.MouseMoveEvent, vtkCommand.LeftButtonPressEvent, vtkCommand.MouseMoveEvent,
                      vtkCommand.LeftButtonReleaseEvent):
            self.event(event, (200, 200))
        self.key("x", "x")
        self.assertFalse(self.rep.ResetLatticeToRest())
        self.assertTrue(any("No lattice" in m for m in errors.messages), errors.messages)
        self.assertFalse(self.rep.MoveSelectedControlPoints((1.0, 0.0, 0.0)))
        self.assertIsNone(self.rep.GetBounds())

    def test_lattice_without_rest_position_drags_but_does_not_reset(self):
        # A point culled in the built lattice: without an `Active` array every point is pickable.
        culled = int(np.flatnonzero(vtk_to_numpy(self.lattice.GetPointData().GetArray("Active")) == 0)[0])
        bare = vtkStructuredGrid()
        bare.SetDimensions(6, 6, 6)
        bare.SetPoints(self.lattice.GetPoints())  # no point arrays at all
        self.lattice = bare
        self.enable(bare)
        start = self.display(culled)
        before = vtk_to_numpy(bare.GetPoints().GetData()).copy()
        self.event(vtkCommand.MouseMoveEvent, start)
        self.event(vtkCommand.LeftButtonPressEvent, start)
        self.event(vtkCommand.MouseMoveEvent, (start[0] + 25, start[1]))
        self.event(vtkCommand.LeftButtonReleaseEvent, (start[0] + 25, start[1]))
        moved = np.flatnonzero(np.any(vtk_to_numpy(bare.GetPoints().GetData()) != before, axis=1))
        self.assertEqual(list(moved), [self.rep.GetHoveredControlPoint()])  # every point pickable, one moved
        errors = catch_errors(self.rep)
        self.assertFalse(self.rep.ResetLatticeToRest())
        self.assertTrue(any("RestPosition" in m for m in errors.messages), errors.messages)


if __name__ == "__main__":
    unittest.main()
