#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""Interchange from Python (docs/interchange-and-files.md, "Interchange"): vtkffd.interchange's lattices at rest against
vtkFFDBuildLattice's; PyGeM .prm files and ITK .tfm files written by hand in the tests and evaluated by numpy
references of PyGeM's and ITK's formulas, written here from their sources (pygem/ffd.py and pygem/utils.py;
itkBSplineTransform.hxx, itkBSplineInterpolationWeightFunction.hxx); vtkBSplineTransform and vtkGridTransform
evaluated by VTK's own vtkTransformFilter; .tfm files read and written by ITK's own code (Testing/ITK, where the
build found ITK); round trips through every format and file extension; bad lattices and
malformed files.

Every comparison of two deformations of a real mesh takes the tolerance 1e-12 of its diagonal: both sides are
float64 sums of at most 64 (Bernstein: at most 60) weighted displacements of a few percent of the diagonal, with
weights that sum to one, each weight computed from a parameter that the two sides get by different but
backward-stable float64 operations; their rounding is some 1e-16 of the diagonal times a small factor (the
number of terms, the lattice's divisions), well below 1e-12, while any error of convention (an axis, an index
order, a transposed matrix, a misplaced node) moves points by a good part of the displacements, 1e-3 of the
diagonal or more. Round trips are checked within 1e-12 of the frame's diagonal for the same reason: a number
written to text with repr reads back exactly, and what remains is the rounding of a rotation, a division or a
sum.

Run with Debian's /usr/bin/python3, PYTHONPATH=<build>/lib/python3/dist-packages and VOXELFFD_MESH_DIR set to the
folder of the meshes (ctest does both). Exits non-zero when a test fails.
"""
import configparser
import math
import os
import subprocess
import tempfile
import unittest

import numpy as np
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy
from vtkmodules.util.vtkConstants import VTK_FLOAT, VTK_SHORT
from vtkmodules.vtkCommonCore import vtkPoints
from vtkmodules.vtkCommonDataModel import VTK_TETRA, vtkImageData, vtkUnstructuredGrid
from vtkmodules.vtkFiltersGeneral import vtkTransformFilter
from vtkmodules.vtkFiltersHybrid import vtkBSplineTransform, vtkGridTransform
from vtkmodules.vtkIOLegacy import vtkDataSetWriter
from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridWriter

import vtkffd
from vtkffd import interchange, meshio
from ffdtesting import bbox_diagonal, build_lattice, points_of, read_mesh  # the same folder

Build = vtkffd.vtkFFDBuildLattice
BASES = (Build.BERNSTEIN, Build.TRILINEAR, Build.TRIQUADRATIC_BEZIER, Build.TRICUBIC_BEZIER, Build.CUBIC_BSPLINE)
EXACT = 1e-12  # of the mesh's or the frame's diagonal: see the module's docstring
# ITK's own code (Testing/ITK/FFDITKTransformPeer.cxx), where the build found ITK (ctest sets it).
ITK_PEER = os.environ.get("VOXELFFD_ITK_PEER", "")

# --- the pipeline and lattices -----------------------------------------------------------------------------------


def deformed(mesh, lattice, clamp=False):
    """The mesh's points deformed by vtkFFDDeform, in float64 (points outside the frame kept, or clamped)."""
    deform = vtkffd.vtkFFDDeform()
    deform.SetInputData(mesh)
    deform.SetLatticeData(lattice)
    deform.SetOutputPointsPrecision(1)  # vtkAlgorithm.DOUBLE_PRECISION
    if clamp:
        deform.SetOutsidePolicyToClampToEdge()
    deform.Update()
    return points_of(deform.GetOutput())


def transformed(mesh, transform):
    """The mesh's points moved by a VTK transform through vtkTransformFilter, in float64."""
    apply = vtkTransformFilter()
    apply.SetInputData(mesh)
    apply.SetTransform(transform)
    apply.SetOutputPointsPrecision(1)
    apply.Update()
    return points_of(apply.GetOutput())


def frame_of(lattice):
    return vtk_to_numpy(lattice.GetFieldData().GetArray("FFDFrame")).astype(np.float64).reshape(4, 3)


def field(lattice, name):
    return vtk_to_numpy(lattice.GetFieldData().GetArray(name)).tolist()


def frame_diagonal(frame):
    return float(np.linalg.norm(frame[1] + frame[2] + frame[3]))


def inside_frame(points, frame, margin=1e-9):
    """The points whose frame parameters lie in [0, 1], and those of them farther than `margin` from its faces
    (where two evaluations' rounding could put a point on either side)."""
    stu = np.linalg.solve(frame[1:].T, (points - frame[0]).T).T
    inside = np.all((stu >= 0) & (stu <= 1), axis=1)
    clear = inside & np.all((np.abs(stu) > margin) & (np.abs(stu - 1) > margin), axis=1)
    return inside, clear


def vtk_grid_slack(lattice):
    """What vtkGridTransform's fixed-point index adds to the difference of its deformation and ours. It finds a
    point's fraction in its cell with vtkInterpolationMath::Floor (vtkImageInterpolatorInternals.h), which adds
    2^-17 and keeps 16 bits after the point: the fraction is off by up to 2^-16, and trilinear interpolation
    moves by at most the largest difference of two neighbouring displacements along an axis per unit of fraction.
    The sum of those over the three axes, times 2^-16, bounds it (some 1e-6 of the bear's diagonal here)."""
    dims = lattice.GetDimensions()
    displacement = (points_of(lattice) - vtk_to_numpy(lattice.GetPointData().GetArray("RestPosition"))).reshape(
        dims[2], dims[1], dims[0], 3)
    return 2.0 ** -16 * sum(float(np.abs(np.diff(displacement, axis=a)).max()) for a in range(3))


def move(lattice, rng, amplitude):
    """Moves every control point of the lattice at random by up to `amplitude` per component (numpy view)."""
    points = vtk_to_numpy(lattice.GetPoints().GetData())
    points += rng.uniform(-amplitude, amplitude, points.shape)
    lattice.GetPoints().Modified()


def principal_axes_lattice(mesh, divisions, basis, form_dense=True):
    """vtkFFDVoxelize's PRINCIPAL_AXES frame (rotated, right-handed) and vtkFFDBuildLattice, copied."""
    voxelize = vtkffd.vtkFFDVoxelize()
    voxelize.SetInputData(mesh)
    voxelize.SetFrameModeToPrincipalAxes()
    voxelize.SetDivisions(*divisions)
    build = Build()
    build.SetInputConnection(voxelize.GetOutputPort())
    build.SetBasis(basis)
    if form_dense:
        build.SetLatticeFormToDense()
    build.Update()
    lattice = type(build.GetOutput())()
    lattice.DeepCopy(build.GetOutput())
    return lattice


def sparse_lattice(mesh, divisions, basis):
    """A sparse lattice (vtkFFDBuildLattice's default form for a local basis) over the mesh, copied."""
    voxelize = vtkffd.vtkFFDVoxelize()
    voxelize.SetInputData(mesh)
    voxelize.SetDivisions(*divisions)
    build = Build()
    build.SetInputConnection(voxelize.GetOutputPort())
    build.SetBasis(basis)
    build.Update()
    lattice = vtkUnstructuredGrid()
    lattice.DeepCopy(build.GetOutput())
    return lattice


def read_text(path):
    with open(path) as stream:
        return stream.read()


def tetrahedral_lattice():
    """A control mesh of one tetrahedron with RestPosition and no FFDFrame
    (docs/pipeline-and-data-contract.md, "Data contract")."""
    corners = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    points = vtkPoints()
    points.SetData(numpy_to_vtk(corners, deep=True))
    lattice = vtkUnstructuredGrid()
    lattice.SetPoints(points)
    lattice.InsertNextCell(VTK_TETRA, 4, [0, 1, 2, 3])
    rest = numpy_to_vtk(corners, deep=True)
    rest.SetName("RestPosition")
    lattice.GetPointData().AddArray(rest)
    return lattice


# --- PyGeM's FFD, written from pygem/ffd.py and pygem/utils.py ----------------------------------------------------


def pygem_read(path):
    """FFD.read_parameters: [Box info] and [Parameters weights] through configparser, weights [axis][i, j, k]."""
    config = configparser.RawConfigParser()
    config.read(path)
    box = {key: [config.getfloat("Box info", "%s %s" % (key, a)) for a in "xyz"]
           for key in ("box length", "box origin", "rotation angle")}
    counts = [config.getint("Box info", "n control points " + a) for a in "xyz"]
    mu = np.zeros((3, *counts))
    for c, axis in enumerate("xyz"):
        for line in config.get("Parameters weights", "parameter " + axis).split("\n"):
            if line.split():
                values = line.split()
                mu[c][tuple(int(v) for v in values[0:3])] = float(values[3])
    return box["box length"], box["box origin"], box["rotation angle"], mu


def pygem_deform(points, parameters):
    """FFD.__call__: the points mapped to the unit cube by the box (origin, edges = rotation_matrix @
    diag(box_length), rotation_matrix = angles2matrix(z, y, x) = Rx Ry Rz of the angles in degrees), those in
    [0, 1]^3 shifted by the Bernstein sum of the weights and mapped back, the others kept. Returns the deformed
    points and the reference coordinates."""
    lengths, origin, angles, mu = parameters
    ax, ay, az = np.radians(angles)
    rx = np.array([[1, 0, 0], [0, np.cos(ax), -np.sin(ax)], [0, np.sin(ax), np.cos(ax)]])
    ry = np.array([[np.cos(ay), 0, np.sin(ay)], [0, 1, 0], [-np.sin(ay), 0, np.cos(ay)]])
    rz = np.array([[np.cos(az), -np.sin(az), 0], [np.sin(az), np.cos(az), 0], [0, 0, 1]])
    edges = rx @ ry @ rz @ np.diag(lengths)
    reference = np.linalg.solve(edges, (points - np.asarray(origin)).T).T
    inside = np.all((reference >= 0) & (reference <= 1), axis=1)

    def bernstein(x, count):
        return np.stack([math.comb(count - 1, i) * (1 - x) ** (count - 1 - i) * x ** i for i in range(count)], 1)

    r = reference[inside]
    bx, by, bz = (bernstein(r[:, a], mu.shape[1 + a]) for a in range(3))
    shift = np.einsum("pi,pj,pk,cijk->pc", bx, by, bz, mu)
    result = points.copy()
    result[inside] = ((r + shift) @ edges.T) + np.asarray(origin)
    return result, reference


# --- ITK's BSplineTransform, written from itkBSplineTransform.hxx and itkBSplineInterpolationWeightFunction.hxx ----


def itk_read(path):
    """(transform types, Parameters, FixedParameters of the last transform) of an ITK text transform file."""
    kinds, parameters, fixed = [], None, None
    with open(path) as stream:
        for line in stream:
            line = line.strip()
            if not line or line.startswith("#"):
                continue
            name, _, value = line.partition(":")
            if name == "Transform":
                kinds.append(value.strip())
            elif name == "Parameters":
                parameters = np.array(value.split(), dtype=np.float64)
            elif name == "FixedParameters":
                fixed = np.array(value.split(), dtype=np.float64)
    return kinds, parameters, fixed


def cubic_bspline(x):
    """BSplineKernelFunction<3>: the centred cubic B-spline."""
    x = np.abs(x)
    return np.where(x < 1, (4 - 6 * x ** 2 + 3 * x ** 3) / 6, np.where(x < 2, (2 - x) ** 3 / 6, 0.0))


def itk_deform(points, parameters, fixed):
    """BSplineTransform::TransformPoint: the continuous index of the coefficient grid (size, origin, spacing,
    direction stored row-major: direction[i][j] = fixed[9 + 3 i + j]), the point kept outside the valid region
    1 <= index < size - 2, else moved by sum_m c_m beta3(index - m) over the 4 x 4 x 4 nodes from
    floor(index - 1), the coefficients all x (i fastest), then all y, then all z. Returns the deformed points
    and the continuous indices."""
    size, origin, spacing = fixed[0:3].astype(int), fixed[3:6], fixed[6:9]
    direction = fixed[9:18].reshape(3, 3)
    index = np.linalg.solve(direction @ np.diag(spacing), (points - origin).T).T
    inside = np.all((index >= 1) & (index < size - 2), axis=1)
    coefficients = parameters.reshape(3, size[2], size[1], size[0])
    result = points.copy()
    x = index[inside]
    start = np.floor(x - 1).astype(int)
    moved = np.zeros_like(x)
    for m in np.ndindex(4, 4, 4):
        node = start + np.array(m)
        weight = np.prod(cubic_bspline(x - node), axis=1)
        moved += weight[:, None] * coefficients[:, node[:, 2], node[:, 1], node[:, 0]].T
    result[inside] += moved
    return result, index


# --- the tests -------------------------------------------------------------------------------------------------


class InterchangeTest(unittest.TestCase):
    def setUp(self):
        self.bear = read_mesh("bear")
        self.points = points_of(self.bear)
        self.diagonal = bbox_diagonal(self.points)
        self.rng = np.random.default_rng(20270315)
        self.folder = tempfile.TemporaryDirectory()

    def tearDown(self):
        self.folder.cleanup()

    def path(self, name):
        return os.path.join(self.folder.name, name)

    def write_text(self, name, text):
        with open(self.path(name), "w") as stream:
            stream.write(text)
        return self.path(name)

    def assertSameDeformation(self, ours, theirs, where=None, slack=0.0):
        """Within 1e-12 of the diagonal (the module's docstring), plus `slack` where the other side is coarser."""
        if where is not None:
            ours, theirs = ours[where], theirs[where]
        np.testing.assert_allclose(ours, theirs, rtol=0, atol=EXACT * self.diagonal + slack)

    def assertSameLattice(self, read, written):
        """The same frame, divisions and basis, and the same points and rest positions, within 1e-12 of the frame's
        diagonal (round trips through text and transforms)."""
        scale = frame_diagonal(frame_of(written))
        np.testing.assert_allclose(frame_of(read), frame_of(written), rtol=0, atol=EXACT * scale)
        self.assertEqual(field(read, "FFDDivisions"), field(written, "FFDDivisions"))
        self.assertEqual(field(read, "FFDBasis"), field(written, "FFDBasis"))
        self.assertEqual(read.GetNumberOfPoints(), written.GetNumberOfPoints())
        np.testing.assert_allclose(points_of(read), points_of(written), rtol=0, atol=EXACT * scale)
        np.testing.assert_allclose(vtk_to_numpy(read.GetPointData().GetArray("RestPosition")),
                                   vtk_to_numpy(written.GetPointData().GetArray("RestPosition")), rtol=0,
                                   atol=EXACT * scale)


class TestLatticeAtRest(InterchangeTest):
    def test_it_is_the_builders_lattice_with_every_control_point_active(self):
        # The same formula on the same frame: rest positions bit for bit, and the points at rest.
        for basis in BASES:
            _, _, built = build_lattice(self.bear, (3, 2, 4), basis)
            lattice = interchange.lattice_at_rest(frame_of(built).ravel(), [3, 2, 4], basis)
            self.assertEqual(lattice.GetDimensions(), built.GetDimensions())
            for name in ("FFDFrame", "FFDDivisions", "FFDBasis"):
                self.assertEqual(field(lattice, name), field(built, name))
            rest = vtk_to_numpy(lattice.GetPointData().GetArray("RestPosition"))
            np.testing.assert_array_equal(rest, vtk_to_numpy(built.GetPointData().GetArray("RestPosition")))
            np.testing.assert_array_equal(points_of(lattice), rest)
            self.assertTrue(np.all(vtk_to_numpy(lattice.GetPointData().GetArray("Active")) == 1))

    def test_bad_frames_divisions_and_bases_are_errors(self):
        frame = [0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1]
        for args, words in (((frame, [0, 1, 1], 0), "divisions"), ((frame, [1, 1, 1], 7), "unknown basis"),
                            ((frame[:9], [1, 1, 1], 0), "12 finite"),
                            (([0, 0, 0, 1, 0, 0, 2, 0, 0, 0, 0, 1], [1, 1, 1], 0), "cannot build"),
                            ((frame, [40, 1, 1], 0), "cannot build")):  # flat frame; Bernstein degree 40 > 32
            with self.assertRaisesRegex(ValueError, words, msg=words):
                interchange.lattice_at_rest(*args)


class TestPyGeM(InterchangeTest):
    def handwritten_prm(self):
        """A PyGeM parameter file, in its format, whose rotated box holds the middle of the bear."""
        low, high = self.points.min(axis=0), self.points.max(axis=0)
        origin = low + 0.25 * (high - low)
        lengths = 0.6 * (high - low)
        return self.write_text("bear.prm", """
[Box info]
# a 3 x 2 x 4 grid of control points
n control points x: 3
n control points y: 2
n control points z: 4
box length x: %r
box length y: %r
box length z: %r
box origin x: %r
box origin y: %r
box origin z: %r
rotation angle x: 20.0
rotation angle y: -35.0
rotation angle z: 50.0

[Parameters weights]
# lines left out are zero
parameter x: 0   0   0   0.1
             2   1   3   -0.2
             1   0   2   0.15
parameter y: 1   1   1   0.2
             0   1   3   0.05
             2   0   1   -0.07
parameter z: 2   0   0   -0.1
             1   1   2   0.12
""" % (*lengths, *origin))

    def test_a_handwritten_file_deforms_as_pygem(self):
        path = self.handwritten_prm()
        lattice = interchange.read_prm(path)
        self.assertEqual(field(lattice, "FFDBasis"), [Build.BERNSTEIN])
        self.assertEqual(field(lattice, "FFDDivisions"), [2, 1, 3])
        theirs, reference = pygem_deform(self.points, pygem_read(path))
        inside = np.all((reference >= 0) & (reference <= 1), axis=1)
        clear = np.all((np.abs(reference) > 1e-9) & (np.abs(reference - 1) > 1e-9), axis=1)
        # The box holds part of the bear: PyGeM moves the points inside it and keeps the others, as we do.
        self.assertGreater(inside.sum(), 1000)
        self.assertGreater((~inside).sum(), 1000)
        ours = deformed(self.bear, lattice)
        self.assertGreater(np.abs(ours - self.points).max(), 0.01 * self.diagonal)
        self.assertSameDeformation(ours, theirs, clear)

    def test_an_exported_lattice_deforms_as_vtkFFDDeform_in_pygem(self):
        # Axis-aligned (angles 0) and principal axes (three non-zero angles) frames; every point is in the frame.
        for lattice in (build_lattice(self.bear, (2, 3, 4), Build.BERNSTEIN)[2],
                        principal_axes_lattice(self.bear, (3, 2, 2), Build.BERNSTEIN)):
            move(lattice, self.rng, 0.03 * self.diagonal)
            path = self.path("exported.prm")
            interchange.write_prm(lattice, path)
            theirs, reference = pygem_deform(self.points, pygem_read(path))
            self.assertTrue(np.all((reference >= 0) & (reference <= 1)))
            self.assertSameDeformation(deformed(self.bear, lattice), theirs)
        self.assertTrue(all(abs(a) > 0.1 for a in pygem_read(path)[2]), pygem_read(path)[2])  # rotated

    def test_round_trips(self):
        # A lattice -> file -> lattice, for a right- and a left-handed frame (written with a negative length);
        # the hand-written file -> lattice -> file -> lattice.
        right = principal_axes_lattice(self.bear, (2, 2, 3), Build.BERNSTEIN)
        x0, s, t, u = frame_of(right)
        left = interchange.lattice_at_rest(np.concatenate([x0 + u, s, t, -u]), [2, 2, 3], Build.BERNSTEIN)
        for lattice in (right, left):
            move(lattice, self.rng, 0.03 * self.diagonal)
            interchange.write_prm(lattice, self.path("a.prm"))
            self.assertSameLattice(interchange.read_prm(self.path("a.prm")), lattice)
            theirs, _ = pygem_deform(self.points, pygem_read(self.path("a.prm")))
            self.assertSameDeformation(deformed(self.bear, lattice), theirs)
        first = interchange.read_prm(self.handwritten_prm())
        interchange.write_prm(first, self.path("b.prm"))
        self.assertSameLattice(interchange.read_prm(self.path("b.prm")), first)

    def test_errors(self):
        _, _, trilinear = build_lattice(self.bear, (2, 2, 2), Build.TRILINEAR)
        skewed = interchange.lattice_at_rest([0, 0, 0, 1, 0, 0, 0.5, 1, 0, 0, 0, 1], [2, 2, 2], Build.BERNSTEIN)
        for lattice, words in ((trilinear, "Bernstein lattice, not Trilinear"), (skewed, "not orthogonal"),
                               (tetrahedral_lattice(), "tetrahedral"), (self.bear, "takes a lattice")):
            with self.assertRaisesRegex(ValueError, words, msg=words):
                interchange.write_prm(lattice, self.path("bad.prm"))
        good = read_text(self.handwritten_prm())
        for text, words in ((good.replace("n control points y: 2", "n control points y: 1"), "at least 2"),
                            (good.replace("n control points y: 2", "n control points y: two"), "not an integer"),
                            (good.replace("rotation angle z: 50.0\n", ""), "'rotation angle z' is missing"),
                            (good.replace("2   1   3   -0.2", "2   2   3   -0.2"), "outside the 3x2x4"),
                            (good.replace("2   1   3   -0.2", "2   1   -0.2"), "not 'i j k weight'"),
                            (good.replace("parameter z:", "parameter w:"), "'parameter z' is missing"),
                            (good.replace("box length x:", "box length x: 0.0\n#"), "flat box"),
                            ("no section header\n", "not a PyGeM parameter file")):
            with self.assertRaisesRegex(ValueError, words, msg=words):
                interchange.read_prm(self.write_text("bad.prm", text))
        with self.assertRaises(FileNotFoundError):
            interchange.read_prm(self.path("missing.prm"))

    def test_files_cut_short_and_sizes_beyond_memory_are_errors(self):
        # write_prm lists every control point for each axis, as PyGeM does: a cut in the middle of a number leaves
        # a number (-0.2 -> -0.), a cut at a line's end a shorter list, whose missing lines would read as zeros.
        lattice = interchange.lattice_at_rest([0, 0, 0, 2, 0, 0, 0, 3, 0, 0, 0, 1], [2, 3, 1], Build.BERNSTEIN)
        move(lattice, self.rng, 0.1)
        interchange.write_prm(lattice, self.path("whole.prm"))
        whole = read_text(self.path("whole.prm"))
        self.assertRegex(whole, r"\.\d{4,}\n$")  # a cut 3 characters before the end leaves a number
        cut_in_z = whole.index("\n", whole.index("parameter z")) + 1
        for text, words in ((whole[:-3], "does not end with a line break"),
                            (whole[:cut_in_z], "'parameter z' lists 1 of the 24 control points"),
                            (whole.replace("n control points x: 3", "n control points x: 2147483647"),
                             "GB needed")):
            with self.assertRaisesRegex(ValueError, words, msg=words):
                interchange.read_prm(self.write_text("cut.prm", text))


class TestVTKTransforms(InterchangeTest):
    def part_of_the_bear(self, basis, divisions, mirrored=False):
        """A lattice at rest over a box that holds the middle of the bear only, every control point active;
        `mirrored`, the same box with S along -x and U along -z (the transforms' spacings negative)."""
        low, high = self.points.min(axis=0), self.points.max(axis=0)
        x0, size = low + 0.2 * (high - low), 0.6 * (high - low)
        if mirrored:
            x0, size = x0 + size * [1, 0, 1], size * [-1, 1, -1]
        return interchange.lattice_at_rest(np.concatenate([x0, np.diag(size).ravel()]), divisions, basis)

    def test_an_exported_bspline_transform_deforms_as_vtkFFDDeform_inside_the_frame(self):
        # The bear's own lattice (every point inside) and one over part of it (points outside excluded: there
        # vtkBSplineTransform's Edge mode extends the spline and vtkFFDDeform keeps the points).
        for lattice in (build_lattice(self.bear, (4, 5, 6), Build.CUBIC_BSPLINE)[2],
                        self.part_of_the_bear(Build.CUBIC_BSPLINE, (3, 4, 2)),
                        self.part_of_the_bear(Build.CUBIC_BSPLINE, (3, 4, 2), mirrored=True)):
            move(lattice, self.rng, 0.03 * self.diagonal)
            transform = interchange.bspline_transform_from_lattice(lattice)
            self.assertEqual(transform.GetBorderModeAsString(), "Edge")
            inside, clear = inside_frame(self.points, frame_of(lattice))
            self.assertGreater(inside.sum(), 1000)
            self.assertSameDeformation(deformed(self.bear, lattice), transformed(self.bear, transform), clear)

    def bspline_transform(self):
        """A vtkBSplineTransform built by hand: float coefficients at random, an extent that does not start at 0,
        DisplacementScale 0.75, border mode Zero; its grid covers the middle of the bear."""
        low, high = self.points.min(axis=0), self.points.max(axis=0)
        image = vtkImageData()
        image.SetExtent(2, 7, -1, 5, 0, 6)  # 6 x 7 x 7 coefficients: 3 x 4 x 4 voxels
        spacing = 0.5 * (high - low) / np.array([3, 4, 4])
        node_one = low + 0.25 * (high - low)  # where the frame begins: the image's node (3, 0, 1)
        image.SetSpacing(*spacing)
        image.SetOrigin(*(node_one - spacing * np.array([3, 0, 1])))
        coefficients = self.rng.normal(0, 0.02 * self.diagonal, (7 * 7 * 6, 3)).astype(np.float32)
        image.GetPointData().SetScalars(numpy_to_vtk(coefficients, deep=True, array_type=VTK_FLOAT))
        transform = vtkBSplineTransform()
        transform.SetCoefficientData(image)
        transform.SetDisplacementScale(0.75)
        transform.SetBorderModeToZero()
        return transform

    def test_an_imported_bspline_transform_deforms_as_vtk_inside_the_frame(self):
        transform = self.bspline_transform()
        lattice = interchange.lattice_from_bspline_transform(transform)
        self.assertEqual(field(lattice, "FFDDivisions"), [3, 4, 4])
        self.assertEqual(field(lattice, "FFDBasis"), [Build.CUBIC_BSPLINE])
        inside, clear = inside_frame(self.points, frame_of(lattice))
        self.assertGreater(inside.sum(), 1000)
        self.assertGreater((~inside).sum(), 1000)
        self.assertSameDeformation(deformed(self.bear, lattice), transformed(self.bear, transform), clear)

    def test_bspline_round_trips(self):
        _, _, lattice = build_lattice(self.bear, (3, 4, 5), Build.CUBIC_BSPLINE)
        move(lattice, self.rng, 0.03 * self.diagonal)
        self.assertSameLattice(
            interchange.lattice_from_bspline_transform(interchange.bspline_transform_from_lattice(lattice)), lattice)
        transform = self.bspline_transform()
        again = interchange.bspline_transform_from_lattice(interchange.lattice_from_bspline_transform(transform))
        self.assertEqual(again.GetDisplacementScale(), 1.0)
        theirs, ours = transform.GetCoefficientData(), again.GetCoefficientData()
        self.assertEqual(theirs.GetDimensions(), ours.GetDimensions())
        scale = float(np.linalg.norm(np.array(theirs.GetSpacing()) * 3))
        np.testing.assert_allclose(interchange._image_node_zero(ours), interchange._image_node_zero(theirs), rtol=0,
                                   atol=EXACT * scale)
        np.testing.assert_allclose(ours.GetSpacing(), theirs.GetSpacing(), rtol=0, atol=EXACT * scale)
        np.testing.assert_allclose(vtk_to_numpy(ours.GetPointData().GetScalars()),
                                   0.75 * vtk_to_numpy(theirs.GetPointData().GetScalars()).astype(np.float64),
                                   rtol=0, atol=EXACT * scale)

    def test_an_exported_grid_transform_deforms_as_vtkFFDDeform(self):
        # Inside the frame as vtkFFDDeform does; everywhere as its ClampToEdge policy does, which is
        # vtkGridTransform's clamping of the grid index (vtkGridTransform.cxx, vtkTrilinearInterpolation).
        for lattice in (build_lattice(self.bear, (5, 4, 6), Build.TRILINEAR)[2],
                        self.part_of_the_bear(Build.TRILINEAR, (3, 3, 2), mirrored=True),
                        self.part_of_the_bear(Build.TRILINEAR, (3, 3, 2))):
            move(lattice, self.rng, 0.03 * self.diagonal)
            transform = interchange.grid_transform_from_lattice(lattice)
            theirs, slack = transformed(self.bear, transform), vtk_grid_slack(lattice)
            inside, clear = inside_frame(self.points, frame_of(lattice))
            self.assertSameDeformation(deformed(self.bear, lattice), theirs, clear, slack)
            self.assertSameDeformation(deformed(self.bear, lattice, clamp=True), theirs, slack=slack)
        self.assertGreater((~inside).sum(), 1000)

    def grid_transform(self):
        """A vtkGridTransform built by hand: short displacements at random with DisplacementScale and Shift, an
        extent that does not start at 0, over the middle of the bear."""
        low, high = self.points.min(axis=0), self.points.max(axis=0)
        image = vtkImageData()
        image.SetExtent(-2, 2, 1, 4, 3, 8)  # 5 x 4 x 6 points: 4 x 3 x 5 voxels
        spacing = 0.6 * (high - low) / np.array([4, 3, 5])
        image.SetSpacing(*spacing)
        image.SetOrigin(*(low + 0.2 * (high - low) - spacing * np.array([-2, 1, 3])))
        values = self.rng.integers(-1000, 1000, (5 * 4 * 6, 3)).astype(np.int16)
        image.GetPointData().SetScalars(numpy_to_vtk(values, deep=True, array_type=VTK_SHORT))
        transform = vtkGridTransform()
        transform.SetDisplacementGridData(image)
        transform.SetDisplacementScale(2e-5 * self.diagonal)
        transform.SetDisplacementShift(0.005 * self.diagonal)
        return transform

    def test_an_imported_grid_transform_deforms_as_vtk(self):
        transform = self.grid_transform()
        lattice = interchange.lattice_from_grid_transform(transform)
        self.assertEqual(field(lattice, "FFDDivisions"), [4, 3, 5])
        theirs, slack = transformed(self.bear, transform), vtk_grid_slack(lattice)
        inside, clear = inside_frame(self.points, frame_of(lattice))
        self.assertGreater((~inside).sum(), 1000)
        self.assertSameDeformation(deformed(self.bear, lattice), theirs, clear, slack)
        self.assertSameDeformation(deformed(self.bear, lattice, clamp=True), theirs, slack=slack)

    def test_grid_round_trips(self):
        _, _, lattice = build_lattice(self.bear, (3, 4, 5), Build.TRILINEAR)
        move(lattice, self.rng, 0.03 * self.diagonal)
        self.assertSameLattice(
            interchange.lattice_from_grid_transform(interchange.grid_transform_from_lattice(lattice)), lattice)
        transform = self.grid_transform()
        again = interchange.grid_transform_from_lattice(interchange.lattice_from_grid_transform(transform))
        self.assertEqual((again.GetDisplacementScale(), again.GetDisplacementShift()), (1.0, 0.0))
        theirs, ours = transform.GetDisplacementGrid(), again.GetDisplacementGrid()
        scale = float(np.linalg.norm(np.array(theirs.GetSpacing()) * 4))
        np.testing.assert_allclose(interchange._image_node_zero(ours), interchange._image_node_zero(theirs), rtol=0,
                                   atol=EXACT * scale)
        expected = (vtk_to_numpy(theirs.GetPointData().GetScalars()) * transform.GetDisplacementScale()
                    + transform.GetDisplacementShift())
        np.testing.assert_allclose(vtk_to_numpy(ours.GetPointData().GetScalars()), expected, rtol=0,
                                   atol=EXACT * scale)

    def test_errors(self):
        rotated = principal_axes_lattice(self.bear, (2, 2, 2), Build.CUBIC_BSPLINE)
        _, _, trilinear = build_lattice(self.bear, (2, 2, 2), Build.TRILINEAR)
        _, _, bspline = build_lattice(self.bear, (2, 2, 2), Build.CUBIC_BSPLINE)
        for export, lattice, words in (
                (interchange.bspline_transform_from_lattice, rotated, "no orientation"),
                (interchange.bspline_transform_from_lattice, trilinear, "CubicBSpline lattice, not Trilinear"),
                (interchange.bspline_transform_from_lattice, tetrahedral_lattice(), "tetrahedral"),
                (interchange.grid_transform_from_lattice, bspline, "Trilinear lattice, not CubicBSpline")):
            with self.assertRaisesRegex(ValueError, words, msg=words):
                export(lattice)
        with self.assertRaisesRegex(ValueError, "no coefficient image"):
            interchange.lattice_from_bspline_transform(vtkBSplineTransform())
        with self.assertRaisesRegex(ValueError, "no displacement grid"):
            interchange.lattice_from_grid_transform(vtkGridTransform())
        with self.assertRaisesRegex(ValueError, "takes a vtkGridTransform"):
            interchange.lattice_from_grid_transform(vtkBSplineTransform())
        cubic = self.grid_transform()
        cubic.SetInterpolationModeToCubic()
        with self.assertRaisesRegex(ValueError, "interpolates Cubic"):
            interchange.lattice_from_grid_transform(cubic)
        flat = vtkImageData()
        flat.SetDimensions(6, 7, 3)  # 3 points along z: no voxel
        flat.GetPointData().SetScalars(numpy_to_vtk(np.zeros((6 * 7 * 3, 3)), deep=True))
        small = vtkBSplineTransform()
        small.SetCoefficientData(flat)
        with self.assertRaisesRegex(ValueError, "coefficient image is \\[6, 7, 3\\] points; .* at least 4"):
            interchange.lattice_from_bspline_transform(small)
        thin = vtkImageData()
        thin.SetDimensions(6, 1, 3)  # 1 point along y: no voxel of a vtkGridTransform's grid
        thin.GetPointData().SetScalars(numpy_to_vtk(np.zeros((6 * 3, 3)), deep=True))
        one_point = vtkGridTransform()
        one_point.SetDisplacementGridData(thin)
        with self.assertRaisesRegex(ValueError, "displacement grid is \\[6, 1, 3\\] points; .* at least 2"):
            interchange.lattice_from_grid_transform(one_point)
        integers = vtkImageData()
        integers.SetDimensions(5, 5, 5)
        integers.GetPointData().SetScalars(numpy_to_vtk(np.zeros((125, 3), dtype=np.int32), deep=True))
        refused = vtkBSplineTransform()
        refused.SetCoefficientData(integers)
        with self.assertRaisesRegex(ValueError, "float or double"):  # VTK's own error, caught
            interchange.lattice_from_bspline_transform(refused)
        inverted = self.bspline_transform()
        inverted.Inverse()
        with self.assertRaisesRegex(ValueError, "inverted"):
            interchange.lattice_from_bspline_transform(inverted)


class TestITK(InterchangeTest):
    def handwritten_tfm(self, composite=False):
        """An ITK text transform file of a BSplineTransform whose grid (mesh 3 x 2 x 4) is rotated by 35 degrees
        about (1, 2, 3) and holds the middle of the bear; coefficients at random."""
        axis = np.array([1.0, 2.0, 3.0]) / math.sqrt(14)
        k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
        angle = math.radians(35)
        direction = np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * k @ k  # Rodrigues
        mesh, spacing = np.array([3, 2, 4]), np.array([0.25, 0.3, 0.15]) * self.diagonal / 2
        centre = 0.5 * (self.points.min(axis=0) + self.points.max(axis=0))
        origin = centre - direction @ (spacing * mesh / 2) - direction @ spacing  # one node before the domain
        parameters = np.random.default_rng(7).normal(0, 0.02 * self.diagonal, 3 * np.prod(mesh + 3))  # same each call
        fixed = np.concatenate([mesh + 3, origin, spacing, direction.ravel()])  # direction row-major
        text = "#Insight Transform File V1.0\n#Transform 0\n"
        if composite:
            text += "Transform: CompositeTransform_double_3_3\n#Transform 1\n"
        text += "Transform: BSplineTransform_double_3_3\nParameters: %s\nFixedParameters: %s\n" % (
            " ".join(repr(float(x)) for x in parameters), " ".join(repr(float(x)) for x in fixed))
        return self.write_text("composite.tfm" if composite else "bear.tfm", text)

    def test_a_handwritten_file_deforms_as_itk(self):
        path = self.handwritten_tfm()
        lattice = interchange.read_tfm(path)
        self.assertEqual(field(lattice, "FFDDivisions"), [3, 2, 4])
        self.assertEqual(field(lattice, "FFDBasis"), [Build.CUBIC_BSPLINE])
        _, parameters, fixed = itk_read(path)
        theirs, index = itk_deform(self.points, parameters, fixed)
        size = fixed[0:3]
        inside = np.all((index >= 1) & (index < size - 2), axis=1)
        clear = np.all((np.abs(index - 1) > 1e-9) & (np.abs(index - (size - 2)) > 1e-9), axis=1)
        self.assertGreater(inside.sum(), 1000)
        self.assertGreater((~inside).sum(), 1000)
        self.assertSameDeformation(deformed(self.bear, lattice), theirs, clear)
        # A CompositeTransform of that one transform reads the same.
        self.assertSameLattice(interchange.read_tfm(self.handwritten_tfm(composite=True)), lattice)

    def test_an_exported_lattice_deforms_as_vtkFFDDeform_in_itk(self):
        # A rotated dense lattice and a sparse one (control points gathered by LatticeIndex, the missing ones at
        # zero): over the mesh, in the lattice's active voxels, ITK's deformation is ours.
        dense = principal_axes_lattice(self.bear, (3, 4, 3), Build.CUBIC_BSPLINE)
        sparse = sparse_lattice(self.bear, (6, 6, 5), Build.CUBIC_BSPLINE)
        for lattice in (dense, sparse):
            move(lattice, self.rng, 0.03 * self.diagonal)
            interchange.write_tfm(lattice, self.path("exported.tfm"))
            kinds, parameters, fixed = itk_read(self.path("exported.tfm"))
            self.assertEqual(kinds, ["BSplineTransform_double_3_3"])
            theirs, index = itk_deform(self.points, parameters, fixed)
            self.assertSameDeformation(deformed(self.bear, lattice), theirs)
        self.assertLess(np.abs(fixed[9:18] - np.eye(3).ravel()).max(), 1e-300)  # sparse: axis-aligned
        self.assertLess(sparse.GetNumberOfPoints(), np.prod(fixed[0:3]))

    def test_round_trips(self):
        lattice = principal_axes_lattice(self.bear, (2, 3, 4), Build.CUBIC_BSPLINE)
        move(lattice, self.rng, 0.03 * self.diagonal)
        interchange.write_tfm(lattice, self.path("a.tfm"))
        self.assertSameLattice(interchange.read_tfm(self.path("a.tfm")), lattice)
        first = interchange.read_tfm(self.handwritten_tfm())
        interchange.write_tfm(first, self.path("b.tfm"))
        self.assertSameLattice(interchange.read_tfm(self.path("b.tfm")), first)
        # The file's numbers come back within the same rounding.
        _, parameters, fixed = itk_read(self.handwritten_tfm())
        _, again, fixed_again = itk_read(self.path("b.tfm"))
        np.testing.assert_allclose(again, parameters, rtol=0, atol=EXACT * self.diagonal)
        np.testing.assert_allclose(fixed_again, fixed, rtol=0, atol=EXACT * self.diagonal)

    def test_errors(self):
        _, _, trilinear = build_lattice(self.bear, (2, 2, 2), Build.TRILINEAR)
        with self.assertRaisesRegex(ValueError, "CubicBSpline lattice, not Trilinear"):
            interchange.write_tfm(trilinear, self.path("bad.tfm"))
        with self.assertRaisesRegex(ValueError, "tetrahedral"):
            interchange.write_tfm(tetrahedral_lattice(), self.path("bad.tfm"))
        good = read_text(self.handwritten_tfm())
        one = good.split("#Transform 0\n")[1]
        parameters = one.split("\n")[1]
        for text, words in (
                (good.replace("BSplineTransform_double_3_3", "AffineTransform_double_3_3"), "AffineTransform"),
                (good + "#Transform 1\n" + one, "holds the transforms"),
                (good.replace("#Transform 0\n", "#Transform 0\nTransform: CompositeTransform_double_3_3\n")
                 + "Transform: TranslationTransform_double_3_3\nParameters: 0 0 0\nFixedParameters:\n",
                 "holds the transforms"),
                (good.replace(parameters, parameters + " 0.5"), "has 630 parameters"),
                (good.replace(parameters, parameters.replace(" ", " x", 1)), "other than numbers"),
                (good.replace("FixedParameters: 6.0 5.0 7.0", "FixedParameters: 6.0 5.0"), "18 fixed parameters"),
                (good.replace("FixedParameters: 6.0 5.0 7.0", "FixedParameters: 6.0 5.0 3.0"), "at least 4"),
                (good.replace(parameters + "\n", ""), "lacks its 'Parameters:'"),
                (good.replace("Transform: ", "Transform "), "'Name: value'"),
                ("#Insight Transform File V1.0\n#Transform 0\nTransform: CompositeTransform_double_3_3\n"
                 "ComponentTransformFile: bear_0.tfm\n", "other files"),
                ("#Insight Transform File V1.0\n", "no 'Transform:'")):
            with self.assertRaisesRegex(ValueError, words, msg=words):
                interchange.read_tfm(self.write_text("bad.tfm", text))
        with self.assertRaises(FileNotFoundError):
            interchange.read_tfm(self.path("missing.tfm"))


@unittest.skipUnless(ITK_PEER, "ITK was not found at configure time (the set-up installs libinsighttoolkit5-dev)")
class TestITKOwnCode(InterchangeTest):
    """ITK 5's TransformFileReader and BSplineTransform::TransformPoint (FFDITKTransformPeer), not a reference
    written here: our exports deform the bear in ITK as vtkFFDDeform does, and a file written by ITK's
    TransformFileWriter deforms it through read_tfm as ITK does."""

    def itk_apply(self, path):
        np.savetxt(self.path("in.txt"), self.points, fmt="%.17g")
        subprocess.run([ITK_PEER, "apply", path, self.path("in.txt"), self.path("out.txt")], check=True)
        return np.loadtxt(self.path("out.txt"))

    def test_itk_deforms_our_exports_as_vtkFFDDeform(self):
        dense = principal_axes_lattice(self.bear, (3, 4, 3), Build.CUBIC_BSPLINE)
        sparse = sparse_lattice(self.bear, (6, 6, 5), Build.CUBIC_BSPLINE)
        for lattice in (dense, sparse):
            move(lattice, self.rng, 0.03 * self.diagonal)
            interchange.write_tfm(lattice, self.path("ours.tfm"))
            self.assertSameDeformation(deformed(self.bear, lattice), self.itk_apply(self.path("ours.tfm")))

    def test_we_deform_itks_files_as_itk(self):
        # A box over the middle of the bear, so that points lie inside and outside the valid region; points
        # within 1e-9 of its faces (in grid units) are left out: there the two sides may decide differently.
        low, high = self.points.min(axis=0), self.points.max(axis=0)
        origin, size = low + 0.2 * (high - low), 0.6 * (high - low)
        subprocess.run([ITK_PEER, "make", self.path("itk.tfm"), "11", *("%.17g" % v for v in (*origin, *size))],
                       check=True)
        _, parameters, fixed = itk_read(self.path("itk.tfm"))
        _, index = itk_deform(self.points, parameters, fixed)
        grid = fixed[0:3]
        inside = np.all((index >= 1) & (index < grid - 2), axis=1)
        clear = np.all((np.abs(index - 1) > 1e-9) & (np.abs(index - (grid - 2)) > 1e-9), axis=1)
        self.assertGreater(inside.sum(), 1000)
        self.assertGreater((~inside).sum(), 1000)
        theirs = self.itk_apply(self.path("itk.tfm"))
        self.assertGreater(np.abs(theirs - self.points).max(), 1e-3 * self.diagonal)  # it does move points
        self.assertSameDeformation(deformed(self.bear, interchange.read_tfm(self.path("itk.tfm"))), theirs, clear)


class TestFiles(InterchangeTest):
    def test_round_trips_by_extension(self):
        # VTK's and OpenVDB's files keep every double: the points and rest positions come back bit for bit; .prm
        # and .tfm within the rounding of their conversions.
        dense = build_lattice(self.bear, (3, 3, 4), Build.TRIQUADRATIC_BEZIER)[2]
        sparse = sparse_lattice(self.bear, (5, 4, 4), Build.CUBIC_BSPLINE)
        bernstein = principal_axes_lattice(self.bear, (2, 2, 2), Build.BERNSTEIN)
        bspline = principal_axes_lattice(self.bear, (2, 3, 2), Build.CUBIC_BSPLINE)
        for lattice in (dense, sparse, bernstein, bspline):
            move(lattice, self.rng, 0.03 * self.diagonal)
        cases = (("a.vts", dense, True), ("a.vtu", sparse, True), ("tetrahedra.vtu", tetrahedral_lattice(), True),
                 ("dense.vtk", dense, True), ("sparse.vtk", sparse, True), ("a.vdb", sparse, True),
                 ("a.prm", bernstein, False), ("A.TFM", bspline, False))  # extensions in any case
        for name, lattice, exact in cases:
            interchange.write_lattice(lattice, self.path(name))
            read = interchange.read_lattice(self.path(name))
            self.assertIs(type(read), type(lattice), name)
            if exact:
                np.testing.assert_array_equal(points_of(read), points_of(lattice), name)
                for data in ("GetPointData", "GetFieldData"):
                    ours, theirs = getattr(read, data)(), getattr(lattice, data)()
                    for a in range(theirs.GetNumberOfArrays()):
                        np.testing.assert_array_equal(vtk_to_numpy(ours.GetArray(theirs.GetArrayName(a))),
                                                      vtk_to_numpy(theirs.GetArray(a)), name)
            else:
                self.assertSameLattice(read, lattice)
            self.assertSameDeformation(deformed(self.bear, read), deformed(self.bear, lattice))

    def test_errors(self):
        dense = build_lattice(self.bear, (2, 2, 2), Build.TRILINEAR)[2]
        sparse = sparse_lattice(self.bear, (2, 2, 2), Build.TRILINEAR)
        for lattice, name, words in ((dense, "a.obj", "unknown lattice file type '.obj'"),
                                     (sparse, "a.vts", "write this vtkUnstructuredGrid to .vtu"),
                                     (dense, "a.vtu", "write this dense lattice to .vts"),
                                     (dense, "a.vdb", "cannot write"), (self.bear, "a.vtk", "takes a lattice")):
            with self.assertRaisesRegex(ValueError, words, msg=words):
                interchange.write_lattice(lattice, self.path(name))
        with self.assertRaises(FileNotFoundError):
            interchange.read_lattice(self.path("missing.vts"))
        with self.assertRaisesRegex(ValueError, "unknown lattice file type"):
            interchange.read_lattice(self.path("missing.txt"))
        # A data set that is no lattice (the voxel grid), and a file that is no VTK file.
        voxelize = vtkffd.vtkFFDVoxelize()
        voxelize.SetInputData(self.bear)
        writer = vtkXMLUnstructuredGridWriter()
        writer.SetInputConnection(voxelize.GetOutputPort())
        writer.SetFileName(self.path("voxels.vtu"))
        writer.Write()
        with self.assertRaisesRegex(ValueError, "holds no lattice"):
            interchange.read_lattice(self.path("voxels.vtu"))
        for name in ("garbage.vts", "garbage.vtk", "garbage.vdb"):
            with self.assertRaisesRegex(ValueError, "cannot read a lattice", msg=name):
                interchange.read_lattice(self.write_text(name, "not a lattice\n"))
        with self.assertRaisesRegex(ValueError, "holds a vtkUnstructuredGrid|cannot read a lattice"):
            os.rename(self.path("voxels.vtu"), self.path("voxels.vts"))  # an unstructured grid in a .vts
            interchange.read_lattice(self.path("voxels.vts"))

    def test_files_cut_short_or_garbled_are_errors(self):
        # Legacy VTK reports a binary file cut short by a warning alone (its lattice then moves the bear by 1e273).
        sparse = sparse_lattice(self.bear, (4, 4, 4), Build.CUBIC_BSPLINE)
        interchange.write_lattice(sparse, self.path("whole.vtk"))
        with open(self.path("whole.vtk"), "rb") as stream:
            whole = stream.read()
        with open(self.path("cut.vtk"), "wb") as stream:
            stream.write(whole[:-100])  # in the last array: the lattice's points and RestPosition are whole
        with self.assertRaisesRegex(ValueError, "cannot read a lattice from .*cut.vtk: Error reading binary data"):
            interchange.read_lattice(self.path("cut.vtk"))
        # A RestPosition shorter than the points (legacy VTK's reader takes it), a cell that names a point the
        # lattice lacks (the filters would read past the points).
        short = vtkUnstructuredGrid()
        short.DeepCopy(sparse)
        rest = short.GetPointData().GetArray("RestPosition")
        rest.SetNumberOfTuples(rest.GetNumberOfTuples() - 1)
        garbled = vtkUnstructuredGrid()
        garbled.DeepCopy(sparse)
        vtk_to_numpy(garbled.GetCells().GetConnectivityArray())[5] = garbled.GetNumberOfPoints()
        for lattice, name, words in ((short, "short.vtk", "holds no lattice"),
                                     (garbled, "garbled.vtu", "names point %d, but there are %d" % (
                                         (sparse.GetNumberOfPoints(),) * 2))):
            writer = vtkDataSetWriter() if name.endswith(".vtk") else vtkXMLUnstructuredGridWriter()
            writer.SetInputData(lattice)
            writer.SetFileName(self.path(name))
            writer.Write()
            with self.assertRaisesRegex(ValueError, words, msg=name):
                interchange.read_lattice(self.path(name))

    def test_a_lattice_that_is_not_finite_is_not_written(self):
        # What the readers refuse: .prm and .tfm files of NaN weights, lattices of NaN points in VTK's files.
        cases = ((principal_axes_lattice(self.bear, (2, 2, 2), Build.BERNSTEIN), ("a.prm", "a.vts", "a.vtk")),
                 (principal_axes_lattice(self.bear, (2, 3, 2), Build.CUBIC_BSPLINE), ("a.tfm",)),
                 (sparse_lattice(self.bear, (4, 4, 4), Build.CUBIC_BSPLINE), ("a.vtu", "a.vdb")))
        for lattice, names in cases:
            vtk_to_numpy(lattice.GetPoints().GetData())[3] = np.nan
            for name in names:
                self.write_text(name, "the file that was there\n")
                with self.assertRaisesRegex(ValueError, "point of control point 3 is not finite", msg=name):
                    interchange.write_lattice(lattice, self.path(name))
                self.assertEqual(read_text(self.path(name)), "the file that was there\n", name)

    def test_writes_are_all_or_nothing(self):
        """write_atomically (every writer of vtkffd.interchange and vtkffd.meshio): a write that fails part-way
        leaves the file that was there and nothing beside it, and says which file; one that succeeds keeps a
        symbolic link and the file's permissions. The command line's test fills the disk under every format."""
        self.write_text("old.vts", "the file that was there\n")
        os.chmod(self.path("old.vts"), 0o640)
        os.symlink("old.vts", self.path("link.vts"))

        def fail_part_way(temporary):
            with open(temporary, "w") as stream:
                stream.write("half a lattice")
            raise OSError(f"{temporary}: the disk is full")

        with self.assertRaisesRegex(OSError, "^%s: the disk is full$" % self.path("link.vts")):
            meshio.write_atomically(self.path("link.vts"), fail_part_way)
        self.assertEqual(sorted(os.listdir(self.folder.name)), ["link.vts", "old.vts"])
        self.assertEqual(read_text(self.path("old.vts")), "the file that was there\n")
        lattice = build_lattice(self.bear, (2, 2, 2), Build.TRILINEAR)[2]
        interchange.write_lattice(lattice, self.path("link.vts"))
        self.assertTrue(os.path.islink(self.path("link.vts")))
        self.assertEqual(os.stat(self.path("old.vts")).st_mode & 0o777, 0o640)
        np.testing.assert_array_equal(points_of(interchange.read_lattice(self.path("old.vts"))), points_of(lattice))
        self.assertEqual(sorted(os.listdir(self.folder.name)), ["link.vts", "old.vts"])
        # A folder that does not exist, and a path that is a folder.
        os.mkdir(self.path("folder.vts"))
        for name, words in (("missing/a.vts", "No such file"), ("folder.vts", "not a regular file")):
            with self.assertRaisesRegex(OSError, words, msg=name) as caught:
                interchange.write_lattice(lattice, self.path(name))
            self.assertEqual(caught.exception.filename, self.path(name))


if __name__ == "__main__":
    unittest.main()
