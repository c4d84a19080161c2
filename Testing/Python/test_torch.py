#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""vtkffd.torch: vtkFFDDeform as a torch.autograd.Function of the control points, its backward vtkFFDSensitivity.

- torch.autograd.gradcheck passes in float64 (central differences against the backward, per output) for the
  trilinear, cubic B-spline (dense and sparse), Bernstein and tetrahedral lattices;
- the forward is vtkFFDDeform's output bit for bit, the backward W.T @ g of vtkffd.sparse within float64 rounding;
- float32 forward and backward agree with float64 within bounds derived from float32 rounding (below);
- a Deformation binds once however often it is called;
- `import vtkffd` does not import torch, and without torch `import vtkffd.torch` raises an ImportError that says
  what to install (a subprocess whose sys.modules['torch'] is None);
- bad input raises, naming what is wrong.

float32 bounds (u32 = 2^-24, u = 2^-53), per mesh point i with m weights: the forward evaluates in float32 from
control points rounded to float32 (|P - fl32(P)| <= u32 |P|), so it differs from float64 by at most
(m + 8) u32 (max|x_i| + sum_c |W_ic| max|D_c|) + u32 sum_c |W_ic| max|P_c| (the first term as the float64 grid
bound of test_weight_matrix). The backward sums W.T fl32(g) in float64, then rounds to float32: within
(2 u32 + 2 (k + 8) u) |W|.T |g| of W.T g, k the column's entries (+ 8: the weights of a CUDA device may differ
from the host's by a few u, as in test_weight_matrix). Fixed seeds.

Run with Debian's /usr/bin/python3 (with python3-torch), PYTHONPATH=<build>/lib/python3/dist-packages and
VOXELFFD_MESH_DIR set (ctest does both). Exits non-zero when a test fails.
"""
import os
import subprocess
import sys
import unittest

import numpy as np
import torch
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy
from vtkmodules.vtkCommonDataModel import vtkUnstructuredGrid
from vtkmodules.vtkFiltersSources import vtkSphereSource

import vtkffd
import vtkffd.sparse
import vtkffd.torch
from ffdtesting import adjoint_bound, build_lattice, points_of, read_mesh  # the same folder

Build = vtkffd.vtkFFDBuildLattice
Deform = vtkffd.vtkFFDDeform
U32, U = 2.0 ** -24, 2.0 ** -53


def sphere():
    """A small float32 mesh (26 points): gradcheck differentiates every output by every control point."""
    source = vtkSphereSource()
    source.SetThetaResolution(6)
    source.SetPhiResolution(6)
    source.SetRadius(1.0)
    source.Update()
    return source.GetOutput()


def scaled(mesh, factor):
    """A copy of `mesh` with its points scaled about the origin."""
    copy = mesh.NewInstance()
    copy.DeepCopy(mesh)
    copy.GetPoints().SetData(numpy_to_vtk(points_of(mesh) * factor, deep=True))
    return copy


def rest_of(lattice):
    return torch.from_numpy(vtk_to_numpy(lattice.GetPointData().GetArray("RestPosition")).astype(np.float64))


def sparse_lattice(mesh, divisions, basis):
    voxelize, build, dense = build_lattice(mesh, divisions, basis)
    build.SetLatticeFormToSparse()
    build.Update()
    lattice = vtkUnstructuredGrid()
    lattice.DeepCopy(build.GetOutput())
    return lattice


def tetrahedral_lattice(mesh):
    build = vtkffd.vtkFFDBuildTetrahedralLattice()
    build.SetInputData(mesh)
    build.SetSubdivisionLevels(0)
    build.Update()
    lattice = vtkUnstructuredGrid()
    lattice.DeepCopy(build.GetOutput())
    return lattice


def vtk_deformed(mesh, lattice, P, precision):
    """vtkFFDDeform's points for a copy of `lattice` moved to P (numpy float64)."""
    moved = lattice.NewInstance()
    moved.DeepCopy(lattice)
    moved.GetPoints().SetData(numpy_to_vtk(np.ascontiguousarray(P, dtype=np.float64), deep=True))
    deform = Deform()
    deform.SetInputData(mesh)
    deform.SetLatticeData(moved)
    deform.SetOutputPointsPrecision(precision)
    deform.Update()
    return vtk_to_numpy(deform.GetOutput().GetPoints().GetData())



class TorchTest(unittest.TestCase):
    def test_gradcheck_in_float64(self):
        mesh = sphere()
        outside = scaled(mesh, 1.6)  # points beyond the lattices built over `mesh`: the outside policies apply
        generator = torch.Generator().manual_seed(33)
        tetrahedral = tetrahedral_lattice(mesh)
        cases = (  # name, mesh, lattice, policy
            ("trilinear", mesh, build_lattice(mesh, (2, 2, 2), Build.TRILINEAR)[2], Deform.KEEP_POSITION),
            ("trilinear, clamped", outside, build_lattice(mesh, (2, 2, 2), Build.TRILINEAR)[2], Deform.CLAMP_TO_EDGE),
            ("cubic B-spline", mesh, build_lattice(mesh, (2, 2, 1), Build.CUBIC_BSPLINE)[2], Deform.KEEP_POSITION),
            ("sparse cubic B-spline", mesh, sparse_lattice(mesh, (2, 2, 1), Build.CUBIC_BSPLINE), Deform.KEEP_POSITION),
            ("Bernstein", mesh, build_lattice(mesh, (2, 1, 2), Build.BERNSTEIN)[2], Deform.KEEP_POSITION),
            ("tetrahedral", mesh, tetrahedral, Deform.KEEP_POSITION),
            ("tetrahedral, clamped", outside, tetrahedral, Deform.CLAMP_TO_EDGE),
            ("tetrahedral, extrapolated", outside, tetrahedral, Deform.EXTRAPOLATE),
        )
        for name, points, lattice, policy in cases:
            with self.subTest(lattice=name):
                rest = rest_of(lattice)
                P = rest + 0.05 * torch.randn(rest.shape, generator=generator, dtype=torch.float64)
                P.requires_grad_()
                deformation = vtkffd.torch.Deformation(points, lattice, policy)
                self.assertTrue(torch.autograd.gradcheck(deformation, (P,), eps=1e-6, atol=1e-8, rtol=1e-6))
                self.assertEqual(deformation.number_of_bindings, 2)  # one each for deform and sensitivity
        # The function form, which binds at every call.
        lattice = cases[4][2]
        P = rest_of(lattice).requires_grad_()
        self.assertTrue(torch.autograd.gradcheck(lambda P: vtkffd.torch.deform(mesh, lattice, P), (P,)))

    def test_forward_is_vtkFFDDeform_and_backward_is_the_transpose(self):
        mesh = read_mesh("bear")
        rng = np.random.default_rng(34)
        for name, lattice in (("cubic B-spline", sparse_lattice(mesh, (6, 7, 3), Build.CUBIC_BSPLINE)),
                              ("tetrahedral", tetrahedral_lattice(mesh))):
            with self.subTest(lattice=name):
                rest = rest_of(lattice).numpy()
                P = rest + rng.normal(scale=0.05, size=rest.shape)
                for dtype, precision in ((torch.float64, Deform.DOUBLE_PRECISION),
                                         (torch.float32, Deform.SINGLE_PRECISION)):
                    Pt = torch.tensor(P, dtype=dtype)
                    X = vtkffd.torch.deform(mesh, lattice, Pt)
                    self.assertEqual(X.dtype, dtype)
                    expected = vtk_deformed(mesh, lattice, Pt.double().numpy(), precision)
                    np.testing.assert_array_equal(X.numpy(), expected)
                W = vtkffd.sparse.weight_matrix(mesh, lattice)
                g = rng.normal(size=(mesh.GetNumberOfPoints(), 3))
                Pt = torch.tensor(P, requires_grad=True)
                vtkffd.torch.deform(mesh, lattice, Pt).backward(torch.from_numpy(g))
                bound = adjoint_bound(W, g)
                self.assertTrue(np.all(np.abs(Pt.grad.numpy() - W.T @ g) <= bound))

    def test_float32_agrees_with_float64(self):
        mesh = read_mesh("bear")
        rng = np.random.default_rng(35)
        for basis in (Build.TRILINEAR, Build.CUBIC_BSPLINE, Build.BERNSTEIN):
            with self.subTest(basis=Build.GetBasisAsString(basis)):
                lattice = build_lattice(mesh, (3, 4, 2), basis)[2]
                rest = rest_of(lattice).numpy()
                P64 = torch.tensor(rest + rng.normal(scale=0.05, size=rest.shape), requires_grad=True)
                P32 = P64.detach().float().requires_grad_()
                deformation = vtkffd.torch.Deformation(mesh, lattice)
                X64, X32 = deformation(P64), deformation(P32)
                self.assertEqual((X64.dtype, X32.dtype), (torch.float64, torch.float32))

                W = vtkffd.sparse.weight_matrix(mesh, lattice)
                x = points_of(mesh)
                D = np.abs(P64.detach().numpy() - rest).max(axis=1)
                m = np.diff(W.indptr)
                bound = (m + 8) * U32 * (np.abs(x).max(axis=1) + abs(W) @ D) \
                    + U32 * (abs(W) @ np.abs(P64.detach().numpy()).max(axis=1))
                error = np.abs(X32.detach().numpy().astype(np.float64) - X64.detach().numpy()).max(axis=1)
                self.assertTrue(np.all(error <= bound), f"forward: {(error / bound).max():.3g} times the bound")

                g = torch.from_numpy(rng.normal(size=x.shape))
                X64.backward(g)
                X32.backward(g.float())
                self.assertEqual(P32.grad.dtype, torch.float32)
                k = np.diff(W.tocsc().indptr)[:, None]
                bound = (2 * U32 + 2 * (k + 8) * U) * (abs(W).T @ np.abs(g.numpy()))
                error = np.abs(P32.grad.numpy().astype(np.float64) - P64.grad.numpy())
                self.assertTrue(np.all(error <= bound), f"backward: {(error / np.maximum(bound, 1e-300)).max():.3g} "
                                "times the bound")

    def test_a_deformation_binds_once(self):
        mesh = read_mesh("bear")
        lattice = build_lattice(mesh, (4, 4, 4), Build.CUBIC_BSPLINE)[2]
        deformation = vtkffd.torch.Deformation(mesh, lattice)
        P = rest_of(lattice).requires_grad_()
        for step in range(3):
            loss = (deformation(P) ** 2).sum()
            loss.backward()
            with torch.no_grad():
                P -= 1e-3 * P.grad
            P.grad = None
        self.assertEqual(deformation.number_of_bindings, 2)

    def test_vtkffd_imports_without_torch(self):
        environment = dict(os.environ)
        plain = subprocess.run([sys.executable, "-c", "import sys, vtkffd, vtkffd.sparse; "
                                "print('torch' in sys.modules)"], env=environment, capture_output=True, text=True)
        self.assertEqual((plain.returncode, plain.stdout.strip()), (0, "False"), plain.stderr)
        shim = ("import sys\n"
                "sys.modules['torch'] = None  # as if PyTorch were not installed\n"
                "import vtkffd, vtkffd.sparse, vtkffd.interchange\n"
                "try:\n"
                "    import vtkffd.torch\n"
                "except ImportError as error:\n"
                "    print(error)\n")
        result = subprocess.run([sys.executable, "-c", shim], env=environment, capture_output=True, text=True)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertIn("vtkffd.torch needs PyTorch", result.stdout)
        self.assertIn("python3-torch", result.stdout)

    def test_bad_input_raises(self):
        mesh = sphere()
        lattice = build_lattice(mesh, (2, 2, 2), Build.TRILINEAR)[2]
        rest = rest_of(lattice)
        deformation = vtkffd.torch.Deformation(mesh, lattice)
        with self.assertRaisesRegex(TypeError, "must be a torch.Tensor, not ndarray"):
            deformation(rest.numpy())
        with self.assertRaisesRegex(TypeError, "float32 or float64, not torch.int64"):
            deformation(rest.long())
        with self.assertRaisesRegex(ValueError, r"shape \(27, 3\).*not \(26, 3\)"):
            deformation(rest[1:])
        bad = rest.clone()
        bad[4, 1] = float("nan")
        with self.assertRaisesRegex(ValueError, "vtkFFDDeform"):
            deformation(bad)
        with self.assertRaisesRegex(TypeError, "the mesh must be a vtkPointSet, not NoneType"):
            vtkffd.torch.Deformation(None, lattice)
        with self.assertRaisesRegex(ValueError, "outside_policy 5"):
            vtkffd.torch.Deformation(mesh, lattice, 5)
        with self.assertRaisesRegex(ValueError, "tetrahedral"):
            vtkffd.torch.deform(mesh, lattice, rest, Deform.EXTRAPOLATE)


if __name__ == "__main__":
    unittest.main()
