#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""W as a SciPy CSR matrix (vtkffd.sparse.weight_matrix, vtkFFDWeightMatrix) against its two peers and a numpy
reference, on the bear and on random points around its frame (so that the outside policies matter):

- W @ (P - P_rest) is vtkFFDDeform's displacement of the mesh, in float64, for every grid basis, dense and sparse,
  and tetrahedral lattices, under every outside policy;
- W.T @ g is vtkFFDSensitivity's dJ/dP;
- a row's weights sum to 1 (partition of unity) for every point with weights; a point kept outside, or not
  finite, has none;
- the sparse form's W is the dense form's, its columns renumbered, bit for bit (the data contract's promise);
- the trilinear W is the tensor product of linear weights computed here in numpy (an independent reference);
- bad input raises, naming what is wrong.

Tolerances, from float64 rounding (u = 2^-53), per row i, relative to the row's scale
s_i = max|x_i| + sum_c |W_ic| max|D_c| (D = P - P_rest; maxima over the 3 coordinates, which the frame's inverse
mixes): W @ D and vtkFFDDeform evaluate one sum of m products w D in different orders and forms (Bezier cells in
power form), each product carrying the roundings of its weight (the parameters through the frame's inverse, the
basis polynomials), its multiplications and the sum; the filter's X - x adds u |X| more. Grids are allowed
(m + 8) u s_i (measured: at most 17 u s_i, triquadratic cells, 5 u s_i for the others). A tetrahedron's weights and
the filter's affine map of it both go through the inverse of its rest edge matrix, whose rounding grows with its
condition number kappa: allowed 8 (1 + kappa) u s_i (measured: at most kappa u s_i). For W.T @ g, a column of k
entries summed in two orders differs by at most 2 k u sum |w| |g|; allowed 2 (k + 8) u sum |w| |g|, as the weights agree bit for
bit on the CPU but may differ by a few u where vtkFFDSensitivity sums on a CUDA device. Row sums: m terms of
magnitude |w|, within m u sum |w| + u of 1. Fixed seeds.

Run with Debian's /usr/bin/python3, PYTHONPATH=<build>/lib/python3/dist-packages and VOXELFFD_MESH_DIR set (ctest
does both). Exits non-zero when a test fails.
"""
import unittest

import numpy as np
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy
from vtkmodules.vtkCommonCore import vtkPoints
from vtkmodules.vtkCommonDataModel import vtkDataObject, vtkImageData, vtkPolyData, vtkUnstructuredGrid

import vtkffd
import vtkffd.sparse
from ffdtesting import adjoint_bound, build_lattice, catch_errors, points_of, read_mesh  # the same folder

Build = vtkffd.vtkFFDBuildLattice
Deform = vtkffd.vtkFFDDeform
U = 2.0 ** -53
BASES = (Build.BERNSTEIN, Build.TRILINEAR, Build.TRIQUADRATIC_BEZIER, Build.TRICUBIC_BEZIER, Build.CUBIC_BSPLINE)
DIVISIONS = (3, 4, 2)
GRID_POLICIES = (Deform.KEEP_POSITION, Deform.CLAMP_TO_EDGE)
TETRAHEDRAL_POLICIES = (Deform.KEEP_POSITION, Deform.CLAMP_TO_EDGE, Deform.EXTRAPOLATE)


def point_set(points):
    """A vtkPolyData of float64 points and no cells: a mesh vtkFFDDeform moves."""
    vtk_points = vtkPoints()
    vtk_points.SetData(numpy_to_vtk(np.ascontiguousarray(points, dtype=np.float64), deep=True))
    data = vtkPolyData()
    data.SetPoints(vtk_points)
    return data


def frame_of(lattice):
    return vtk_to_numpy(lattice.GetFieldData().GetArray("FFDFrame")).astype(np.float64).reshape(4, 3)


def with_outside_points(bear, box_corner, box_axes, rng, count=600):
    """The bear's points followed by `count` random points in the parallelepiped box_corner + [-0.4, 1.4]^3 of
    box_axes (rows): a fifth to a half of them outside it on some axis."""
    stu = rng.uniform(-0.4, 1.4, size=(count, 3))
    return point_set(np.concatenate([points_of(bear), box_corner + stu @ box_axes]))


def move_randomly(lattice, rng, scale):
    """Moves every control point by a random offset of `scale`; returns the displacements P - P_rest."""
    points = vtk_to_numpy(lattice.GetPoints().GetData())
    points += rng.normal(scale=scale, size=points.shape)
    lattice.GetPoints().Modified()
    return points - vtk_to_numpy(lattice.GetPointData().GetArray("RestPosition"))


def deformed(mesh, lattice, policy):
    deform = Deform()
    deform.SetInputData(mesh)
    deform.SetLatticeData(lattice)
    deform.SetOutsidePolicy(policy)
    deform.SetOutputPointsPrecision(Deform.DOUBLE_PRECISION)
    deform.Update()
    return points_of(deform.GetOutput())


def sensitivity(mesh, lattice, gradient, policy):
    data = point_set(points_of(mesh))
    array = numpy_to_vtk(gradient, deep=True)
    array.SetName("dJdX")
    data.GetPointData().AddArray(array)
    filter_ = vtkffd.vtkFFDSensitivity()
    filter_.SetInputData(data)
    filter_.SetLatticeData(lattice)
    filter_.SetOutsidePolicy(policy)
    filter_.SetInputArrayToProcess(0, 0, 0, vtkDataObject.FIELD_ASSOCIATION_POINTS, "dJdX")
    filter_.Update()
    return vtk_to_numpy(filter_.GetOutput().GetPointData().GetArray("Sensitivity"))


def condition(W, rest):
    """Per row of a tetrahedral W, the condition number of its tetrahedron's rest edge matrix (1 for empty rows)."""
    rows = np.diff(W.indptr) == 4
    nodes = W.indices.reshape(-1, 4)
    edges = rest[nodes[:, 1:]] - rest[nodes[:, :1]]  # (rows, 3, 3)
    kappa = np.ones(W.shape[0])
    kappa[rows] = np.linalg.cond(edges)
    return kappa



class WeightMatrixTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.bear = read_mesh("bear")

    def check_against_peers(self, mesh, lattice, policy, rng, amplification):
        """W against vtkFFDDeform and vtkFFDSensitivity, W @ D within amplification(W) u s_i (see the module's
        docstring); returns W."""
        W = vtkffd.sparse.weight_matrix(mesh, lattice, policy)
        self.assertEqual(W.shape, (mesh.GetNumberOfPoints(), lattice.GetNumberOfPoints()))
        self.assertEqual(W.dtype, np.float64)
        self.assertTrue(W.has_canonical_format)  # increasing, distinct column ids in each row
        x = points_of(mesh)
        D = move_randomly(lattice, rng, 0.05 * np.ptp(x, axis=0).max())
        X = deformed(mesh, lattice, policy)
        scale = np.abs(x).max(axis=1) + abs(W) @ np.abs(D).max(axis=1)
        bound = (amplification(W) * U * scale)[:, None]
        error = np.abs(W @ D - (X - x))
        self.assertTrue(np.all(error <= bound), f"W (P - P_rest) differs from vtkFFDDeform's displacement by "
                        f"{error.max():.3g}, {(error / bound).max():.3g} times the bound")

        g = rng.normal(size=x.shape)
        bound = adjoint_bound(W, g)
        error = np.abs(W.T @ g - sensitivity(mesh, lattice, g, policy))
        self.assertTrue(np.all(error <= bound), f"W.T g differs from vtkFFDSensitivity by {error.max():.3g}, "
                        f"{(error / np.maximum(bound, 1e-300)).max():.3g} times the bound")

        # Partition of unity: m sums of terms at most 1 in size (but extrapolated weights, larger).
        rows = np.diff(W.indptr) > 0
        sums = np.asarray(W.sum(axis=1)).ravel()[rows]
        scale = np.asarray(abs(W).sum(axis=1)).ravel()[rows]
        np.testing.assert_array_less(np.abs(sums - 1.0), np.diff(W.indptr)[rows] * U * scale + U)
        return W

    def test_every_grid_basis_dense_and_sparse_every_policy(self):
        rng = np.random.default_rng(33)
        for basis in BASES:
            for form in ("dense", "sparse") if basis != Build.BERNSTEIN else ("dense",):
                voxelize, build, lattice = build_lattice(self.bear, DIVISIONS, basis)
                if form == "sparse":
                    build.SetLatticeFormToSparse()
                    build.Update()
                    lattice = vtkUnstructuredGrid()
                    lattice.DeepCopy(build.GetOutput())
                frame = frame_of(lattice)
                mesh = with_outside_points(self.bear, frame[0], frame[1:], rng)
                for policy in GRID_POLICIES:
                    with self.subTest(basis=Build.GetBasisAsString(basis), form=form, policy=policy):
                        rest = vtk_to_numpy(lattice.GetPointData().GetArray("RestPosition"))
                        lattice.GetPoints().SetData(numpy_to_vtk(rest, deep=True))  # at rest again
                        W = self.check_against_peers(mesh, lattice, policy, rng, lambda W: np.diff(W.indptr) + 8)
                        empty = np.diff(W.indptr) == 0
                        if policy == Deform.KEEP_POSITION:  # some points outside keep theirs, no bear point
                            self.assertTrue(empty.any() and not empty[:self.bear.GetNumberOfPoints()].any())
                        elif form == "dense":  # every point clamped into the dense grid has weights
                            self.assertFalse(empty.any())

    def test_sparse_form_is_the_dense_form_renumbered(self):
        for basis in BASES[1:]:
            with self.subTest(basis=Build.GetBasisAsString(basis)):
                voxelize, build, dense = build_lattice(self.bear, DIVISIONS, basis)
                build.SetLatticeFormToSparse()
                build.Update()
                sparse = build.GetOutput()
                index = vtk_to_numpy(sparse.GetPointData().GetArray("LatticeIndex")).astype(np.int64)
                n = dense.GetDimensions()
                ids = index[:, 0] + n[0] * (index[:, 1] + n[1] * index[:, 2])
                W_dense = vtkffd.sparse.weight_matrix(self.bear, dense)
                W_sparse = vtkffd.sparse.weight_matrix(self.bear, sparse)
                self.assertEqual(W_sparse.shape, (self.bear.GetNumberOfPoints(), len(ids)))
                self.assertEqual(W_dense.nnz, W_sparse.nnz)
                self.assertEqual((W_dense[:, ids] != W_sparse).nnz, 0)

    def test_trilinear_weights_match_a_numpy_reference(self):
        voxelize, build, lattice = build_lattice(self.bear, DIVISIONS, Build.TRILINEAR)
        W = vtkffd.sparse.weight_matrix(self.bear, lattice)
        frame = frame_of(lattice)
        stu = np.linalg.solve(frame[1:].T, (points_of(self.bear) - frame[0]).T).T * DIVISIONS
        cell = np.minimum(np.floor(stu), np.array(DIVISIONS) - 1).astype(np.int64)
        local = stu - cell
        n = lattice.GetDimensions()
        reference = np.zeros(W.shape)
        for corner in np.ndindex(2, 2, 2):
            weight = np.prod(np.where(np.array(corner) == 1, local, 1.0 - local), axis=1)
            ijk = cell + corner
            reference[np.arange(len(ijk)), ijk[:, 0] + n[0] * (ijk[:, 1] + n[1] * ijk[:, 2])] += weight
        # Each weight is a product of 3 factors of at most 1, each within a few u of the reference's.
        np.testing.assert_allclose(W.toarray(), reference, rtol=0, atol=16 * U)

    def test_tetrahedral_every_policy(self):
        rng = np.random.default_rng(34)
        build = vtkffd.vtkFFDBuildTetrahedralLattice()
        build.SetInputData(self.bear)
        build.Update()
        lattice = vtkUnstructuredGrid()
        lattice.DeepCopy(build.GetOutput())
        rest = vtk_to_numpy(lattice.GetPointData().GetArray("RestPosition")).copy()
        low, high = rest.min(axis=0), rest.max(axis=0)
        mesh = with_outside_points(self.bear, low, np.diag(high - low), rng)
        for policy in TETRAHEDRAL_POLICIES:
            with self.subTest(policy=policy):
                lattice.GetPoints().SetData(numpy_to_vtk(rest, deep=True))
                W = self.check_against_peers(mesh, lattice, policy, rng, lambda W: 8 * (1 + condition(W, rest)))
                empty = np.diff(W.indptr) == 0
                self.assertEqual(empty.any(), policy == Deform.KEEP_POSITION)
                if policy == Deform.EXTRAPOLATE:  # points beyond the hull: some negative weights
                    self.assertLess(W.data.min(), 0.0)
                else:
                    self.assertGreaterEqual(W.data.min(), -1e-12)

    def test_points_not_finite_have_empty_rows(self):
        x = points_of(self.bear)
        x[5] = np.nan
        x[7, 1] = np.inf
        mesh = point_set(x)
        build = vtkffd.vtkFFDBuildTetrahedralLattice()
        build.SetInputData(self.bear)
        build.Update()
        for lattice, policies in ((build_lattice(self.bear, DIVISIONS, Build.CUBIC_BSPLINE)[2], GRID_POLICIES),
                                  (build.GetOutput(), TETRAHEDRAL_POLICIES)):
            for policy in policies:
                with self.subTest(lattice=lattice.GetClassName(), policy=policy):
                    W = vtkffd.sparse.weight_matrix(mesh, lattice, policy)
                    self.assertEqual(np.diff(W.indptr)[[4, 5, 6, 7]].tolist(), [W.indptr[1], 0, W.indptr[1], 0])
                    self.assertTrue(np.isfinite(W.data).all())

    def test_empty_mesh_gives_an_empty_matrix(self):
        voxelize, build, lattice = build_lattice(self.bear, DIVISIONS, Build.CUBIC_BSPLINE)
        W = vtkffd.sparse.weight_matrix(point_set(np.zeros((0, 3))), lattice)
        self.assertEqual((W.shape, W.nnz), ((0, lattice.GetNumberOfPoints()), 0))

    def test_bad_input_raises(self):
        voxelize, build, lattice = build_lattice(self.bear, DIVISIONS, Build.CUBIC_BSPLINE)
        with self.assertRaisesRegex(TypeError, "mesh must be a vtkPointSet"):
            vtkffd.sparse.weight_matrix(None, lattice)
        with self.assertRaisesRegex(TypeError, "lattice must be a vtkPointSet, not vtkImageData"):
            vtkffd.sparse.weight_matrix(self.bear, vtkImageData())
        with self.assertRaisesRegex(ValueError, "outside_policy 7"):
            vtkffd.sparse.weight_matrix(self.bear, lattice, 7)
        with self.assertRaisesRegex(ValueError, "EXTRAPOLATE needs a tetrahedral lattice"):
            vtkffd.sparse.weight_matrix(self.bear, lattice, Deform.EXTRAPOLATE)
        with self.assertRaisesRegex(ValueError, "weight_matrix: .*FFDFrame"):
            vtkffd.sparse.weight_matrix(self.bear, self.bear)  # a mesh is no lattice
        broken = vtkUnstructuredGrid()  # a tetrahedral lattice without RestPosition
        broken.SetPoints(self.bear.GetPoints())
        with self.assertRaisesRegex(ValueError, "RestPosition"):
            vtkffd.sparse.weight_matrix(self.bear, broken)

    def test_failed_compute_empties_the_matrix(self):
        voxelize, build, lattice = build_lattice(self.bear, DIVISIONS, Build.TRILINEAR)
        matrix = vtkffd.vtkFFDWeightMatrix()
        self.assertEqual(matrix.Compute(self.bear, lattice), 1)
        kept = vtk_to_numpy(matrix.GetValues())  # a view of the first result's array
        first = kept.copy()
        self.assertEqual(matrix.GetNumberOfRows(), self.bear.GetNumberOfPoints())
        matrix.SetOutsidePolicy(Deform.EXTRAPOLATE)
        catcher = catch_errors(matrix)
        self.assertEqual(matrix.Compute(self.bear, lattice), 0)
        self.assertEqual(len(catcher.messages), 1)
        self.assertEqual((matrix.GetNumberOfRows(), matrix.GetNumberOfColumns()), (0, 0))
        self.assertEqual(vtk_to_numpy(matrix.GetRowOffsets()).tolist(), [0])
        self.assertEqual(matrix.GetValues().GetNumberOfValues(), 0)
        np.testing.assert_array_equal(kept, first)  # arrays handed out before are left alone


if __name__ == "__main__":
    unittest.main()
