#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""The FFD pipeline driven from Python: vtkFFDVoxelize -> vtkFFDBuildLattice -> (numpy moves the lattice's points)
-> vtkFFDDeform, on the real elephant mesh, checked against independent float64 numpy references written here: the
paper's equations 2 and 3 for the global basis, the definitions of the trilinear and cubic B-spline bases for the
local ones (and their locality).

Run with Debian's /usr/bin/python3, PYTHONPATH=<build>/lib/python3/dist-packages and VOXELFFD_MESH_DIR set to the
folder of the meshes (ctest does both). Exits non-zero when a test fails.
"""
import math
import os
import unittest

import numpy as np
from vtkmodules.util.numpy_support import numpy_to_vtk, numpy_to_vtkIdTypeArray, vtk_to_numpy
from vtkmodules.vtkCommonCore import vtkPoints
from vtkmodules.vtkCommonDataModel import vtkPolyData
from vtkmodules.vtkCommonExecutionModel import vtkAlgorithm

import vtkffd
from ffdtesting import bbox_diagonal, build_lattice, catch_errors, points_of, read_mesh  # the same folder

# Deformed points agree with the float64 reference within this fraction of the mesh's bounding-box diagonal:
# both sides compute in double precision from the same input points, so the only differences
# are rounding in evaluation orders that differ (de Casteljau and displacement form against binomials times
# powers on absolute positions), a few 1e-16 relative per term.
RELATIVE_TOLERANCE = 1e-9


def reference_deform(frame, divisions, control_points, x):
    """Equations 2 and 3 in float64: parameters by triple products, then the Bernstein sum over absolute
    control points P_ijk (VTK order, i fastest) of a lattice of degree (l, m, n) = divisions."""
    x0, s, t, u = frame[0:3], frame[3:6], frame[6:9], frame[9:12]
    d = x - x0
    tu, su, st = np.cross(t, u), np.cross(s, u), np.cross(s, t)
    params = [d @ tu / (s @ tu), d @ su / (t @ su), d @ st / (u @ st)]
    l, m, n = divisions

    def bernstein(degree, v):
        return np.stack([math.comb(degree, i) * v**i * (1.0 - v) ** (degree - i) for i in range(degree + 1)], axis=1)

    bs, bt, bu = bernstein(l, params[0]), bernstein(m, params[1]), bernstein(n, params[2])
    p = control_points.reshape(n + 1, m + 1, l + 1, 3)  # [k, j, i]
    return np.einsum("pi,pj,pk,kjic->pc", bs, bt, bu, p)


class TestPipeline(unittest.TestCase):
    def setUp(self):
        self.mesh = read_mesh("elephant")
        self.mesh_points = points_of(self.mesh)
        self.diagonal = bbox_diagonal(self.mesh_points)

        # The test owns a copy of the lattice that it moves; the filters keep their own output.
        self.voxelize, self.build, self.lattice = build_lattice(
            self.mesh, (2, 3, 4), vtkffd.vtkFFDBuildLattice.BERNSTEIN)

        self.deform = vtkffd.vtkFFDDeform()
        self.deform.SetInputData(self.mesh)
        self.deform.SetLatticeData(self.lattice)
        self.deform.SetOutputPointsPrecision(vtkAlgorithm.DOUBLE_PRECISION)

    def frame(self):
        return vtk_to_numpy(self.lattice.GetFieldData().GetArray("FFDFrame")).astype(np.float64)

    def lattice_points(self):
        """The lattice's points as a writable numpy view (double precision, as the data contract says)."""
        return vtk_to_numpy(self.lattice.GetPoints().GetData())

    def move_lattice(self, seed):
        points = self.lattice_points()
        rng = np.random.default_rng(seed)
        points += rng.normal(scale=0.05 * self.diagonal, size=points.shape)
        self.lattice.GetPoints().Modified()

    def deformed_points(self):
        self.deform.Update()
        return vtk_to_numpy(self.deform.GetOutput().GetPoints().GetData())

    def test_import_exposes_classes(self):
        for name in ("vtkFFDVoxelize", "vtkFFDBuildLattice", "vtkFFDDeform", "vtkFFDLatticeActor"):
            self.assertTrue(hasattr(vtkffd, name), name)

    def test_lattice_follows_data_contract(self):
        self.assertEqual(self.lattice.GetDimensions(), (3, 4, 5))
        self.assertEqual(self.lattice.GetPoints().GetDataType(), 11)  # VTK_DOUBLE
        divisions = vtk_to_numpy(self.lattice.GetFieldData().GetArray("FFDDivisions"))
        np.testing.assert_array_equal(divisions, [2, 3, 4])
        # Equation 1: P_ijk = X0 + i/l S + j/m T + k/n U, VTK order.
        frame = self.frame()
        k, j, i = np.meshgrid(np.arange(5) / 4, np.arange(4) / 3, np.arange(3) / 2, indexing="ij")
        expected = (frame[0:3] + np.outer(i.ravel(), frame[3:6]) + np.outer(j.ravel(), frame[6:9])
                    + np.outer(k.ravel(), frame[9:12]))
        rest = vtk_to_numpy(self.lattice.GetPointData().GetArray("RestPosition"))
        np.testing.assert_allclose(self.lattice_points(), expected, rtol=0, atol=1e-12 * self.diagonal)
        np.testing.assert_array_equal(rest, self.lattice_points())

    def test_dense_lattice_feeds_structured_consumers(self):
        # A structured grid's consumers ask for pieces of its WHOLE_EXTENT, announced before execution from the
        # divisions and basis (vtkFFDVoxelize's, then each lattice filter's); without it they (and ParaView's
        # displays) got an empty lattice. Each consumer downstream of a filter that makes a dense lattice must
        # give what it gives on a copy of the lattice (no pipeline before it), also with a filter between the
        # voxel grid and the lattice (as ParaView puts after every filter).
        from vtkmodules.vtkCommonDataModel import vtkStructuredGrid
        from vtkmodules.vtkFiltersCore import vtkPassThrough
        from vtkmodules.vtkFiltersExtraction import vtkExtractEdges
        from vtkmodules.vtkFiltersGeometry import vtkDataSetSurfaceFilter
        between = vtkPassThrough()
        between.SetInputConnection(self.voxelize.GetOutputPort())

        builds = []  # an output port does not keep its filter alive

        def build(basis):
            lattice = vtkffd.vtkFFDBuildLattice()
            lattice.SetInputConnection(between.GetOutputPort())
            lattice.SetBasis(basis)
            lattice.SetLatticeFormToDense()
            builds.append(lattice)
            return lattice

        refine = vtkffd.vtkFFDRefineLattice()
        refine.SetInputConnection(build(vtkffd.vtkFFDBuildLattice.TRIQUADRATIC_BEZIER).GetOutputPort())
        coarsen = vtkffd.vtkFFDCoarsenLattice()  # half of (2, 3, 4), rounded up
        coarsen.SetInputConnection(build(vtkffd.vtkFFDBuildLattice.CUBIC_BSPLINE).GetOutputPort())
        coarsen.SetMeshData(self.mesh)
        into_trilinear = vtkffd.vtkFFDCoarsenLattice()
        into_trilinear.SetInputConnection(build(vtkffd.vtkFFDBuildLattice.BERNSTEIN).GetOutputPort())
        into_trilinear.SetMeshData(self.mesh)
        into_trilinear.SetDivisions(3, 2, 2)
        into_trilinear.SetBasis(vtkffd.vtkFFDBuildLattice.TRILINEAR)
        for producer, dimensions in ((build(vtkffd.vtkFFDBuildLattice.BERNSTEIN), (3, 4, 5)),
                                     (build(vtkffd.vtkFFDBuildLattice.TRIQUADRATIC_BEZIER), (5, 7, 9)),
                                     (refine, (9, 13, 17)), (coarsen, (4, 5, 5)), (into_trilinear, (4, 3, 3))):
            producer.Update()
            copy = vtkStructuredGrid()
            copy.DeepCopy(producer.GetOutput())
            self.assertEqual(copy.GetDimensions(), dimensions, producer.GetClassName())
            for consumer in (vtkDataSetSurfaceFilter, vtkExtractEdges):
                downstream, alone = consumer(), consumer()
                downstream.SetInputConnection(producer.GetOutputPort())
                alone.SetInputData(copy)
                downstream.Update()
                alone.Update()
                what = f"{consumer.__name__} after {producer.GetClassName()}"
                self.assertGreater(alone.GetOutput().GetNumberOfCells(), 0, what)
                self.assertEqual(downstream.GetOutput().GetNumberOfCells(), alone.GetOutput().GetNumberOfCells(),
                                 what)
                np.testing.assert_array_equal(points_of(downstream.GetOutput()), points_of(alone.GetOutput()),
                                              err_msg=what)

    def test_rest_lattice_leaves_mesh_unchanged(self):
        self.deform.SetOutputPointsPrecision(vtkAlgorithm.DEFAULT_PRECISION)
        # The deformation is added as displacements P - P_rest, all exactly zero here: the points come back
        # bit for bit, in the input's precision.
        output = self.deformed_points()
        input_points = vtk_to_numpy(self.mesh.GetPoints().GetData())
        self.assertEqual(output.dtype, input_points.dtype)
        np.testing.assert_array_equal(output, input_points)

    def test_numpy_moved_lattice_matches_reference(self):
        self.move_lattice(seed=20240611)
        expected = reference_deform(self.frame(), (2, 3, 4), self.lattice_points().copy(), self.mesh_points)
        output = self.deformed_points()
        error = np.abs(output - expected).max()
        self.assertLessEqual(error, RELATIVE_TOLERANCE * self.diagonal)
        # The random moves are large enough that the test can fail: the mesh really moved.
        self.assertGreater(np.abs(output - self.mesh_points).max(), 0.01 * self.diagonal)

    def test_moving_only_the_lattice_does_not_rebind(self):
        first = self.deformed_points().copy()
        self.assertEqual(self.deform.GetNumberOfBindings(), 1)
        for seed in (1, 2):
            self.move_lattice(seed)
            moved = self.deformed_points()
            self.assertEqual(self.deform.GetNumberOfBindings(), 1)
            self.assertGreater(np.abs(moved - first).max(), 0.01 * self.diagonal)
            expected = reference_deform(self.frame(), (2, 3, 4), self.lattice_points().copy(), self.mesh_points)
            self.assertLessEqual(np.abs(moved - expected).max(), RELATIVE_TOLERANCE * self.diagonal)

    def test_numpy_point_set_and_affine_lattice(self):
        # A point set built from numpy (numpy_to_vtk) deformed by a lattice moved by an affine map: Bernstein
        # bases reproduce affine maps (linear precision), so the output is the map applied to the points.
        rng = np.random.default_rng(7)
        cloud = rng.uniform(-1.0, 1.0, size=(500, 3)) * [2.0, 1.0, 0.5]
        vtk_points = vtkPoints()
        vtk_points.SetData(numpy_to_vtk(cloud, deep=True))
        point_set = vtkPolyData()
        point_set.SetPoints(vtk_points)

        _, _, lattice = build_lattice(point_set, (3, 2, 2))
        matrix = np.eye(3) + rng.uniform(-0.3, 0.3, size=(3, 3))
        offset = rng.uniform(-1.0, 1.0, size=3)
        control = vtk_to_numpy(lattice.GetPoints().GetData())
        control[:] = control @ matrix.T + offset
        lattice.GetPoints().Modified()

        deform = vtkffd.vtkFFDDeform()
        deform.SetInputData(point_set)
        deform.SetLatticeData(lattice)
        deform.Update()
        output = vtk_to_numpy(deform.GetOutput().GetPoints().GetData())
        self.assertEqual(output.dtype, np.float64)
        np.testing.assert_allclose(output, cloud @ matrix.T + offset, rtol=0,
                                   atol=RELATIVE_TOLERANCE * bbox_diagonal(cloud))

    def test_lattice_without_rest_position_is_an_error(self):
        self.lattice.GetPointData().RemoveArray("RestPosition")
        # The executive reports the failed request too; catch it so the log shows only unexpected errors.
        errors = catch_errors(self.deform, executive=True)
        self.deform.Update()
        self.assertTrue(any("RestPosition" in message for message in errors.messages), errors.messages)
        self.assertEqual(self.deform.GetOutput().GetNumberOfPoints(), 0)

    def expect_error(self, algorithm, needle):
        """Updates algorithm and asserts that it failed with an error containing needle and an empty output."""
        errors = catch_errors(algorithm, executive=True)
        self.assertEqual(algorithm.GetExecutive().Update(), 0)
        self.assertTrue(any(needle in message for message in errors.messages), errors.messages)
        self.assertEqual(algorithm.GetOutputDataObject(0).GetNumberOfPoints(), 0)

    def test_points_marked_as_copies_count_once(self):
        # A piece of a distributed mesh holds copies of points that another piece owns, marked DUPLICATEPOINT
        # in its ghost array (vtkGenerateGlobalIds): they must not weigh twice in the principal axes or in the
        # tetrahedral lattice's centroid. The elephant plus marked copies of 2000 of its points gives the
        # elephant's frame and tetrahedra bit for bit; unmarked, the copies change them.
        from vtkmodules.vtkCommonDataModel import vtkDataSetAttributes
        rng = np.random.default_rng(20261126)
        copies = rng.choice(self.mesh.GetNumberOfPoints(), 2000, replace=False)
        with_copies = vtkPolyData()
        points = vtkPoints()
        points.SetDataTypeToDouble()
        points.SetData(numpy_to_vtk(np.concatenate([self.mesh_points, self.mesh_points[copies]]), deep=True))
        with_copies.SetPoints(points)
        ghosts = np.zeros(points.GetNumberOfPoints(), np.uint8)
        ghosts[self.mesh.GetNumberOfPoints():] = vtkDataSetAttributes.DUPLICATEPOINT
        ghost_array = numpy_to_vtk(ghosts, deep=True)
        ghost_array.SetName(vtkDataSetAttributes.GhostArrayName())

        def lattices(mesh):
            voxelize = vtkffd.vtkFFDVoxelize()
            voxelize.SetInputData(mesh)
            voxelize.SetFrameModeToPrincipalAxes()
            voxelize.SetDivisions(5, 6, 4)
            tetrahedral = vtkffd.vtkFFDBuildTetrahedralLattice()
            tetrahedral.SetInputData(mesh)
            voxelize.Update()
            tetrahedral.Update()
            return (vtk_to_numpy(voxelize.GetOutput().GetFieldData().GetArray("FFDFrame")),
                    points_of(tetrahedral.GetOutput()))

        plain = vtkPolyData()
        plain.SetPoints(vtkPoints())
        plain.GetPoints().SetData(numpy_to_vtk(self.mesh_points, deep=True))
        expected_frame, expected_nodes = lattices(plain)
        unmarked_frame, unmarked_nodes = lattices(with_copies)
        self.assertFalse(np.array_equal(unmarked_frame, expected_frame))
        self.assertFalse(np.array_equal(unmarked_nodes, expected_nodes))
        with_copies.GetPointData().AddArray(ghost_array)
        frame, nodes = lattices(with_copies)
        np.testing.assert_array_equal(frame, expected_frame)
        np.testing.assert_array_equal(nodes, expected_nodes)

    def test_memory_follows_the_active_voxels(self):
        # The abort: divisions of 100000^3 once asked for a dense voxel grid beyond any machine's memory.
        # The voxel grid and a sparse lattice now hold the active voxels only; a dense lattice of that size is
        # still refused before anything is allocated, with what it needs. The interpreter goes on.
        self.voxelize.SetDivisions(100000, 100000, 100000)
        self.voxelize.Update()
        active = self.voxelize.GetNumberOfActiveVoxels()
        self.assertEqual(self.voxelize.GetOutput().GetNumberOfCells(), active)
        self.assertLessEqual(active, self.mesh.GetNumberOfPoints())
        build = vtkffd.vtkFFDBuildLattice()
        build.SetInputConnection(self.voxelize.GetOutputPort())
        build.SetBasisToTrilinear()
        build.Update()
        self.assertGreater(build.GetOutput().GetNumberOfPoints(), active)  # sparse: the active voxels' corners
        self.voxelize.SetDivisions(1200, 1200, 1200)
        build.SetLatticeFormToDense()  # 1201^3 control points, 86 GB
        self.expect_error(build, "of memory, but only")
        # Voxels and corners are indexed by int64: (2^31)^2 * 2 corners are beyond it.
        self.voxelize.SetDivisions(2**31 - 1, 2**31 - 1, 1)
        self.expect_error(self.voxelize, "64-bit index")
        self.voxelize.SetDivisions(2, 3, 4)
        self.voxelize.Update()
        self.assertEqual(self.voxelize.GetNumberOfActiveVoxels(), self.voxelize.GetOutput().GetNumberOfCells())

    @unittest.skipIf("LD_PRELOAD" in os.environ, "the sanitizers' runtime reserves more address space than the limit")
    def test_an_allocation_that_fails_is_an_error_not_an_abort(self):
        # Under an address-space limit of 512 MB above what the interpreter has mapped, a dense lattice that the
        # machine's memory would hold (1.4 GB estimated for 301^3 control points) cannot be allocated: VTK throws
        # std::bad_alloc, which the filter turns into an error and an empty output. In a child process, so that the
        # limit stays there; before the fix the child died of SIGABRT.
        script = """
import resource, sys
import vtkffd
from vtkmodules.vtkCommonDataModel import vtkPolyData
from vtkmodules.vtkCommonCore import vtkPoints
points = vtkPoints()
points.InsertNextPoint(0, 0, 0)
points.InsertNextPoint(1, 1, 1)
cloud = vtkPolyData()
cloud.SetPoints(points)
voxelize = vtkffd.vtkFFDVoxelize()
voxelize.SetInputData(cloud)
voxelize.SetDivisions(300, 300, 300)
voxelize.Update()
build = vtkffd.vtkFFDBuildLattice()
build.SetInputConnection(voxelize.GetOutputPort())
build.SetBasisToTrilinear()
build.SetLatticeFormToDense()
messages = []
class Catcher:
    CallDataType = "string0"
    def __call__(self, caller, event, message):
        messages.append(message)
catcher = Catcher()
build.AddObserver("ErrorEvent", catcher)
build.GetExecutive().AddObserver("ErrorEvent", Catcher())
size = next(int(line.split()[1]) for line in open("/proc/self/status") if line.startswith("VmSize:"))
limit = size * 1024 + (512 << 20)
resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
status = build.GetExecutive().Update()
print(status, build.GetOutput().GetNumberOfPoints(), any("Out of memory" in m for m in messages))
"""
        import subprocess
        import sys
        result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300)
        self.assertEqual(result.returncode, 0, result.stderr[-2000:])
        self.assertEqual(result.stdout.split(), ["0", "0", "True"], result.stdout + result.stderr[-2000:])

    def test_lattice_actor_sizes_points_from_the_current_lattice(self):
        actor = vtkffd.vtkFFDLatticeActor()
        actor.SetInputData(self.lattice)
        self.assertEqual(actor.GetPointRadius(), 0.0)
        self.assertEqual(actor.GetPointProperty().GetColor(), (0.9, 0.1, 0.1))
        self.assertEqual(actor.GetEdgeProperty().GetLineWidth(), 2.0)
        # Asking for the bounds brings the automatic radius up to date, as rendering does.
        actor.GetBounds()
        fraction = vtkffd.vtkFFDLatticeActor.GetAutomaticRadiusFraction()
        self.assertAlmostEqual(actor.GetRenderedPointRadius(), fraction * self.lattice.GetLength(), delta=1e-12)
        points = self.lattice_points()
        points *= 2.0
        self.lattice.GetPoints().Modified()
        bounds = actor.GetBounds()
        self.assertAlmostEqual(actor.GetRenderedPointRadius(), fraction * self.lattice.GetLength(), delta=1e-12)
        # The spheres stick out of the lattice's bounds by their radius (less a little: the tessellated sphere
        # has no vertex exactly on its equator).
        radius = actor.GetRenderedPointRadius()
        self.assertAlmostEqual(bounds[1], self.lattice.GetBounds()[1] + radius, delta=0.05 * radius)
        actor.SetPointRadius(0.125)
        actor.GetBounds()
        self.assertEqual(actor.GetRenderedPointRadius(), 0.125)


def local_axis_weights(basis, voxels, s):
    """Weights of every control point along an axis of `voxels` voxels at the parameters s (shape (P,), in
    [0, 1]), as dense (P, points) arrays, from the bases' definitions as functions of the distance to each
    control point's rest parameter, in voxel units: the trilinear hat max(0, 1 - |d|) centred on i/n, and the
    uniform cubic B-spline centred on (i - 1)/n, (4 - 6d^2 + 3|d|^3)/6 for |d| < 1, (2 - |d|)^3/6 for
    1 <= |d| < 2."""
    x = s[:, None] * voxels
    if basis == vtkffd.vtkFFDBuildLattice.TRILINEAR:
        d = np.abs(x - np.arange(voxels + 1)[None, :])
        return np.maximum(0.0, 1.0 - d)
    d = np.abs(x - (np.arange(voxels + 3)[None, :] - 1))
    return np.where(d < 1, (4 - 6 * d**2 + 3 * d**3) / 6, np.where(d < 2, (2 - d) ** 3 / 6, 0.0))


class TestLocalBases(unittest.TestCase):
    """A local basis through the pipeline with the lattice moved by numpy, against a numpy reference written
    from the definitions, and its locality: moving one control point moves only the points in its support."""

    DIVISIONS = (3, 4, 2)
    BASES = (vtkffd.vtkFFDBuildLattice.TRILINEAR, vtkffd.vtkFFDBuildLattice.CUBIC_BSPLINE)

    def setUp(self):
        self.mesh = read_mesh("elephant")
        self.mesh_points = points_of(self.mesh)

    def pipeline(self, basis):
        """Voxelize -> build the lattice of `basis` -> a copy the test moves -> deform."""
        _, _, lattice = build_lattice(self.mesh, self.DIVISIONS, basis)
        deform = vtkffd.vtkFFDDeform()
        deform.SetInputData(self.mesh)
        deform.SetLatticeData(lattice)
        deform.SetOutputPointsPrecision(vtkAlgorithm.DOUBLE_PRECISION)
        return lattice, deform

    def parameters(self, lattice):
        """(s, t, u) of the mesh points: equation 2, by triple products."""
        frame = vtk_to_numpy(lattice.GetFieldData().GetArray("FFDFrame")).astype(np.float64)
        x0, s, t, u = frame[0:3], frame[3:6], frame[6:9], frame[9:12]
        d = self.mesh_points - x0
        tu, su, st = np.cross(t, u), np.cross(s, u), np.cross(s, t)
        return [d @ tu / (s @ tu), d @ su / (t @ su), d @ st / (u @ st)], float(np.linalg.norm(s + t + u))

    def reference(self, basis, lattice, rest):
        """X + sum_ijk w_i(s) w_j(t) w_k(u) (P_ijk - P_ijk^rest) for the mesh points, all inside the frame."""
        params, _ = self.parameters(lattice)
        ws, wt, wu = (local_axis_weights(basis, n, np.clip(p, 0.0, 1.0)) for n, p in zip(self.DIVISIONS, params))
        nk, nj, ni = wu.shape[1], wt.shape[1], ws.shape[1]
        moved = (vtk_to_numpy(lattice.GetPoints().GetData()) - rest).reshape(nk, nj, ni, 3)
        return self.mesh_points + np.einsum("pi,pj,pk,kjic->pc", ws, wt, wu, moved)

    def test_local_basis_matches_numpy_reference(self):
        for seed, basis in enumerate(self.BASES):
            lattice, deform = self.pipeline(basis)
            rest = vtk_to_numpy(lattice.GetPointData().GetArray("RestPosition")).copy()
            _, diagonal = self.parameters(lattice)
            points = vtk_to_numpy(lattice.GetPoints().GetData())
            points += np.random.default_rng(seed).normal(scale=0.03 * diagonal, size=points.shape)
            lattice.GetPoints().Modified()
            deform.Update()
            output = vtk_to_numpy(deform.GetOutput().GetPoints().GetData())
            self.assertLessEqual(np.abs(output - self.reference(basis, lattice, rest)).max(),
                                 RELATIVE_TOLERANCE * diagonal, basis)
            self.assertGreater(np.abs(output - self.mesh_points).max(), 0.01 * diagonal, basis)

    def test_moving_one_control_point_is_local(self):
        rng = np.random.default_rng(2024)
        for basis in self.BASES:
            lattice, deform = self.pipeline(basis)
            rest = vtk_to_numpy(lattice.GetPointData().GetArray("RestPosition")).copy()
            params, diagonal = self.parameters(lattice)
            # A control point that influences the voxel of a random mesh point: the voxel's first control point
            # along each axis, plus 0 or 1 (trilinear), 0 to 3 (B-spline).
            seed_point = rng.integers(len(self.mesh_points))
            voxel = [min(int(p[seed_point] * n), n - 1) for p, n in zip(params, self.DIVISIONS)]
            span = 2 if basis == vtkffd.vtkFFDBuildLattice.TRILINEAR else 4
            i, j, k = (v + int(rng.integers(span)) for v in voxel)
            ni, nj, _ = lattice.GetDimensions()
            points = vtk_to_numpy(lattice.GetPoints().GetData())
            points[i + ni * (j + nj * k)] += np.array([0.1, -0.05, 0.07]) * diagonal
            lattice.GetPoints().Modified()
            deform.Update()
            output = vtk_to_numpy(deform.GetOutput().GetPoints().GetData())

            # The support of control point (i, j, k), from the definitions: parameters within one voxel of its
            # rest parameter i/n (trilinear), within two voxels of (i - 1)/n (B-spline), on every axis.
            centre, reach = ((i, j, k), 1.0) if span == 2 else ((i - 1, j - 1, k - 1), 2.0)
            in_support = np.all([np.abs(p * n - c) < reach for p, n, c in zip(params, self.DIVISIONS, centre)],
                                axis=0)
            changed = np.any(output != self.mesh_points, axis=1)
            self.assertFalse(np.any(changed & ~in_support), basis)
            self.assertTrue(changed[seed_point], basis)
            self.assertLess(in_support.sum(), len(self.mesh_points), basis)
            self.assertLessEqual(np.abs(output - self.reference(basis, lattice, rest)).max(),
                                 RELATIVE_TOLERANCE * diagonal, basis)



class TestStatistics(unittest.TestCase):
    """Every statistic that a filter's getter returns is also a one-value field array of its output, of the
    getter's name without Get (ParaView reads the output's field data: its information properties read 0 before
    an update computes them). Each is compared with its getter after a real update."""

    def expect_recorded(self, algorithm, names):
        algorithm.Update()
        field_data = algorithm.GetOutputDataObject(0).GetFieldData()
        for name in names:
            array = field_data.GetAbstractArray(name)
            self.assertIsNotNone(array, f"{algorithm.GetClassName()}: {name}")
            self.assertEqual(array.GetNumberOfValues(), 1, name)
            self.assertEqual(array.GetValue(0), getattr(algorithm, "Get" + name)(), name)

    def test_every_filter_records_its_statistics(self):
        bear = read_mesh("bear")
        voxelize, build, lattice = build_lattice(bear, (3, 3, 3), vtkffd.vtkFFDBuildLattice.CUBIC_BSPLINE)
        self.expect_recorded(voxelize, ["NumberOfActiveVoxels"])
        self.expect_recorded(build, ["NumberOfActiveControlPoints"])
        tetrahedra = vtkffd.vtkFFDBuildTetrahedralLattice()
        tetrahedra.SetInputData(bear)
        self.expect_recorded(tetrahedra, ["NumberOfHullFaces", "NumberOfActiveNodes"])
        rng = np.random.default_rng(20261129)
        points = vtk_to_numpy(lattice.GetPoints().GetData())
        points += rng.uniform(-0.02, 0.02, points.shape)
        lattice.GetPoints().Modified()
        deform = vtkffd.vtkFFDDeform()
        deform.SetInputData(bear)
        deform.SetLatticeData(lattice)
        deform.SetBackendToCPU()
        self.expect_recorded(deform, ["LastBackendUsed"])
        inverse = vtkffd.vtkFFDInverseDeform()
        inverse.SetInputConnection(deform.GetOutputPort())
        inverse.SetLatticeData(lattice)
        self.expect_recorded(inverse, ["NumberOfFoldedPoints", "NumberOfUnconvergedPoints"])
        coarsen = vtkffd.vtkFFDCoarsenLattice()
        coarsen.SetInputData(lattice)
        coarsen.SetMeshData(bear)
        self.expect_recorded(coarsen, ["ResidualRMS", "MaximumResidual"])
        detail = vtkffd.vtkFFDBuildDetailLattice()
        detail.SetInputData(lattice)
        detail.SetSecondDerivativeThreshold(1e-6)
        self.expect_recorded(detail, ["NumberOfRefinedVoxels"])
        manipulate = vtkffd.vtkFFDDirectManipulation()
        manipulate.SetInputData(build.GetOutput())
        manipulate.SetMeshData(bear)
        manipulate.SetTargetPointIds(numpy_to_vtkIdTypeArray(np.array([0, 100], dtype=np.int64), deep=True))
        targets = vtkPoints()
        targets.SetData(numpy_to_vtk(points_of(bear)[[0, 100]] + 0.01, deep=True))
        manipulate.SetTargetPositions(targets)
        self.expect_recorded(manipulate, ["NumberOfMovedControlPoints", "MaximumTargetDistance"])
        simulate = vtkffd.vtkFFDSimulateLattice()
        simulate.SetInputData(build.GetOutput())
        dynamics = simulate.GetDynamics()
        dynamics.SetGravity(0.0, -9.81, 0.0)
        simulate.UpdateTimeStep(0.1)
        field_data = simulate.GetOutputDataObject(0).GetFieldData()
        for name in ("Time", "NumberOfSimulatedPoints", "NumberOfSprings", "KineticEnergy", "PotentialEnergy"):
            self.assertEqual(field_data.GetAbstractArray(name).GetValue(0), getattr(dynamics, "Get" + name)(), name)
        self.assertGreater(field_data.GetAbstractArray("KineticEnergy").GetValue(0), 0.0)  # falling


class TestDataContract(unittest.TestCase):
    """vtkFFDDataContract's static setters given None: an error on VTK's output window, nothing set, no crash. Each
    call runs in its own interpreter, so that a crash (as it was: a segfault) fails the test, not the runner."""

    def run_script(self, body):
        import subprocess
        import sys
        script = "import vtkffd\nfrom vtkmodules.vtkCommonDataModel import vtkStructuredGrid\n" + body
        return subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)

    def test_setters_given_none_are_errors_not_crashes(self):
        contract = "vtkffd.vtkFFDDataContract"
        for call, expected in (
                ("SetFrame(None, [0.0] * 12)", "cannot set FFDFrame: the data object is null"),
                ("SetDivisions(None, [1, 2, 3])", "cannot set FFDDivisions: the data object is null"),
                ("SetBasis(None, 1)", "cannot set FFDBasis: the data object is null")):
            with self.subTest(call=call):
                result = self.run_script("%s.%s\nprint('returned')\n" % (contract, call))
                self.assertEqual(result.returncode, 0, result.stderr[-2000:])
                self.assertEqual(result.stdout.split(), ["returned"])
                self.assertIn(expected, result.stderr)

    def test_a_grid_keeps_its_arrays_when_a_setter_fails(self):
        # The values None: refused by the wrapping or by the setter; either way the grid gains no array.
        for call in ("SetFrame(grid, None)", "SetDivisions(grid, None)"):
            with self.subTest(call=call):
                result = self.run_script(
                    "grid = vtkStructuredGrid()\n"
                    "try:\n    vtkffd.vtkFFDDataContract.%s\nexcept (TypeError, ValueError):\n    pass\n"
                    "print(grid.GetFieldData().GetNumberOfArrays())\n" % call)
                self.assertEqual(result.returncode, 0, result.stderr[-2000:])
                self.assertEqual(result.stdout.split(), ["0"])


if __name__ == "__main__":
    unittest.main()
