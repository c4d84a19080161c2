# SPDX-License-Identifier: BSD-3-Clause
"""Lattices to and from other tools (docs/interchange-and-files.md, "Interchange"): PyGeM's FFD parameter files (.prm),
VTK's vtkBSplineTransform and vtkGridTransform, ITK's BSplineTransform in its text transform files (.tfm), and the
lattice files of VTK and OpenVDB, chosen by extension (read_lattice, write_lattice).

Every import returns a dense lattice (vtkStructuredGrid, docs/pipeline-and-data-contract.md, "Data contract") built by
vtkFFDBuildLattice (lattice_at_rest) with its points moved by the other tool's displacements, so that vtkFFDDeform
deforms a mesh as that tool does inside the frame. Outside the frame each tool keeps its own rule: PyGeM and ITK leave
points where they are, as vtkFFDDeform does by default; vtkGridTransform clamps to its grid's edge, as
vtkFFDDeform's ClampToEdge policy does; vtkBSplineTransform's border modes extend the spline in ways that no
policy reproduces.

Every export takes a dense or sparse grid lattice of the format's basis. A sparse lattice is gathered by its
`LatticeIndex`, and the control points it lacks (culled: they influence none of its voxels) get a zero
displacement: the exported deformation then equals the lattice's over the lattice's active voxels, which hold
every point of the mesh it was built over, and may differ elsewhere.

A malformed file (cut short, garbled, or sizes that do not add up), a transform that is no lattice, or a lattice a
format cannot hold (another basis, a tetrahedral lattice, a frame that the format cannot orient, points that are
not finite) raises ValueError with the reason, in one line (VTK's errors are caught by vtkffd.meshio.checked); a
missing file raises FileNotFoundError. Files are written all or nothing (vtkffd.meshio.write_atomically): a write
that fails raises OSError and leaves the file that was there.
"""
import configparser
import math
import os
import re

import numpy as np
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy
from vtkmodules.util.vtkConstants import (
    VTK_CHAR, VTK_DOUBLE, VTK_FLOAT, VTK_INT, VTK_LINEAR_INTERPOLATION, VTK_SHORT, VTK_UNSIGNED_CHAR,
    VTK_UNSIGNED_SHORT)
from vtkmodules.vtkCommonCore import reference
from vtkmodules.vtkCommonDataModel import vtkImageData, vtkStructuredGrid, vtkUnstructuredGrid
from vtkmodules.vtkFiltersHybrid import vtkBSplineTransform, vtkGridTransform

from . import meshio, vtkFFDBuildLattice, vtkFFDDataContract, vtkFFDVDBReader, vtkFFDVDBWriter

__all__ = [
    "lattice_at_rest", "read_prm", "write_prm", "lattice_from_bspline_transform", "bspline_transform_from_lattice",
    "lattice_from_grid_transform", "grid_transform_from_lattice", "read_tfm", "write_tfm", "LATTICE_EXTENSIONS",
    "lattice_extension", "read_lattice", "write_lattice"]

BERNSTEIN = vtkFFDBuildLattice.BERNSTEIN
TRILINEAR = vtkFFDBuildLattice.TRILINEAR
TRIQUADRATIC_BEZIER = vtkFFDBuildLattice.TRIQUADRATIC_BEZIER
TRICUBIC_BEZIER = vtkFFDBuildLattice.TRICUBIC_BEZIER
CUBIC_BSPLINE = vtkFFDBuildLattice.CUBIC_BSPLINE

# A frame axis whose component off its coordinate axis is below this fraction of its length counts as
# axis-aligned, and two axes whose cosine is below it as orthogonal: frames made by rotations and products of
# float64 matrices are so within a few 1e-16, and what an export then drops moves the other tool's frame by at most
# this fraction of its size.
_ALIGNMENT_TOLERANCE = 1e-10


# --- building and reading lattices ------------------------------------------------------------------------------


def _basis_name(basis):
    return vtkFFDBuildLattice.GetBasisAsString(int(basis))


def _control_points_per_axis(basis, divisions):
    n = np.asarray(divisions, dtype=np.int64)
    return {BERNSTEIN: n + 1, TRILINEAR: n + 1, TRIQUADRATIC_BEZIER: 2 * n + 1, TRICUBIC_BEZIER: 3 * n + 1,
            CUBIC_BSPLINE: n + 3}[basis]


def lattice_at_rest(frame, divisions, basis):
    """The dense lattice (vtkStructuredGrid) of `basis` (vtkFFDBuildLattice's enum: 0 BERNSTEIN to 4
    CUBIC_BSPLINE) over the frame X0, S, T, U (12 numbers) divided into `divisions` (3 ints) voxels, at rest, every
    control point active: vtkFFDBuildLattice's output over a voxel grid that lists every voxel, deep-copied.
    ValueError for divisions below one, an unknown basis, or what the filter refuses (a flat frame, a Bernstein
    degree above its maximum, more control points than it indexes)."""
    frame = np.asarray(frame, dtype=np.float64).reshape(-1)
    if frame.size != 12 or not np.all(np.isfinite(frame)):
        raise ValueError("a frame is 12 finite numbers (X0, S, T, U), not %r" % (frame.tolist(),))
    divisions = np.asarray(divisions).reshape(-1)
    if divisions.size != 3 or np.any(divisions != np.round(divisions)) or np.any(divisions < 1):
        raise ValueError("divisions are 3 integers of at least 1, not %r" % (divisions.tolist(),))
    divisions = [int(n) for n in divisions]
    if int(basis) not in (BERNSTEIN, TRILINEAR, TRIQUADRATIC_BEZIER, TRICUBIC_BEZIER, CUBIC_BSPLINE):
        raise ValueError("unknown basis %r: vtkFFDBuildLattice's are 0 (BERNSTEIN) to 4 (CUBIC_BSPLINE)" % (basis,))
    axes = frame[3:].reshape(3, 3)
    if not np.all(np.isfinite(np.linalg.norm(axes, axis=1))) or not np.isfinite(np.linalg.det(axes)):
        raise ValueError("the frame's edges S, T, U (%s) are too long: their lengths or the frame's volume overflow "
                         "float64" % axes.tolist())
    # The voxel image's index takes some 72 bytes a voxel (numpy's grids and the VTK array); the builder checks
    # the lattice it makes.
    _require_memory(72.0 * math.prod(divisions), "a dense lattice of %s divisions" % divisions)
    # The builder reads only the field arrays and VoxelIndex: an image of the voxels, each listed once.
    voxels = vtkImageData()
    voxels.SetDimensions(divisions[0] + 1, divisions[1] + 1, divisions[2] + 1)
    vtkFFDDataContract.SetFrame(voxels, frame.tolist())
    vtkFFDDataContract.SetDivisions(voxels, divisions)
    k, j, i = np.mgrid[0:divisions[2], 0:divisions[1], 0:divisions[0]]  # i fastest: the image's cell order
    index = numpy_to_vtk(np.stack([i.ravel(), j.ravel(), k.ravel()], axis=1).astype(np.int32), deep=True,
                         array_type=VTK_INT)
    index.SetName(vtkFFDDataContract.VoxelIndexArrayName())
    voxels.GetCellData().AddArray(index)
    build = vtkFFDBuildLattice()
    build.SetBasis(int(basis))
    build.SetLatticeFormToDense()
    build.SetInputData(voxels)
    failure = "cannot build a %s lattice of %s divisions over frame %s" % (_basis_name(basis), divisions,
                                                                           frame.tolist())
    meshio.checked(build, build.Update, failure, ValueError)
    output = build.GetOutput()
    if output is None or output.GetNumberOfPoints() == 0:
        raise ValueError(failure + ": empty output")
    lattice = vtkStructuredGrid()
    lattice.DeepCopy(output)
    return lattice


def _require_memory(size, what):
    """Raises ValueError when `size` bytes for `what` exceed the memory the system can still give (MemAvailable,
    as vtkFFDMemory.h reads it for the filters): a size read from a file or set by a user, checked before numpy
    allocates it (Linux lets a process reserve far more than it can touch)."""
    available = os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    try:
        with open("/proc/meminfo") as meminfo:
            available = next(int(line.split()[1]) * 1024 for line in meminfo if line.startswith("MemAvailable:"))
    except (OSError, StopIteration, ValueError, IndexError):
        pass
    if size > available:
        raise ValueError("%s: %.3g GB needed, more than the %.3g GB of memory available" % (what, size / 2**30,
                                                                                          available / 2**30))


def _lattice_with_displacements(frame, divisions, basis, displacement):
    """lattice_at_rest(frame, divisions, basis) with each control point moved by `displacement` (nK, nJ, nI, 3)."""
    lattice = lattice_at_rest(frame, divisions, basis)
    points = vtk_to_numpy(lattice.GetPoints().GetData())  # a view of the double points, at rest
    points += np.asarray(displacement, dtype=np.float64).reshape(points.shape)
    lattice.GetPoints().Modified()
    return lattice


def _grid_lattice(lattice, where):
    """(frame (4, 3): X0, S, T, U; divisions (3,); basis; displacement (nK, nJ, nI, 3)) of a dense or sparse grid
    lattice, the sparse one's missing control points at zero; ValueError, naming `where`, for anything else."""
    if not isinstance(lattice, (vtkStructuredGrid, vtkUnstructuredGrid)):
        raise ValueError("%s takes a lattice (vtkStructuredGrid or vtkUnstructuredGrid), not %s" % (
            where, type(lattice).__name__))
    point_data = lattice.GetPointData()
    rest = point_data.GetArray(vtkFFDDataContract.RestPositionArrayName())
    frame = [0.0] * 12
    if not vtkFFDDataContract.GetFrame(lattice, frame):
        if rest is not None:
            raise ValueError("%s takes grid lattices; this one has no FFDFrame (a tetrahedral lattice?), and a "
                             "control mesh of tetrahedra has no grid to write" % where)
        raise ValueError("%s takes a lattice of the data contract; this data set has no FFDFrame of 12 finite "
                         "numbers" % where)
    divisions = [0, 0, 0]
    if not vtkFFDDataContract.GetDivisions(lattice, divisions):
        raise ValueError("%s: the lattice has no FFDDivisions of 3 ints of at least 1" % where)
    basis = reference(0)
    if not vtkFFDDataContract.GetBasis(lattice, basis) or int(basis) not in range(BERNSTEIN, CUBIC_BSPLINE + 1):
        raise ValueError("%s: the lattice has no FFDBasis of 0 to 4" % where)
    basis = int(basis)
    if rest is None or rest.GetNumberOfComponents() != 3 or lattice.GetPoints() is None or \
            rest.GetNumberOfTuples() != lattice.GetNumberOfPoints():
        raise ValueError("%s: the lattice has no RestPosition of 3 components per point" % where)
    _require_finite(lattice, where)
    counts = _control_points_per_axis(basis, divisions)
    moved = vtk_to_numpy(lattice.GetPoints().GetData()).astype(np.float64) - vtk_to_numpy(rest)
    if isinstance(lattice, vtkStructuredGrid):
        if tuple(lattice.GetDimensions()) != tuple(int(n) for n in counts):
            raise ValueError("%s: a dense %s lattice of %s divisions has %s control points per axis, this one %s" % (
                where, _basis_name(basis), divisions, counts.tolist(), list(lattice.GetDimensions())))
        displacement = moved.reshape(counts[2], counts[1], counts[0], 3)
    else:
        index = point_data.GetArray(vtkFFDDataContract.LatticeIndexArrayName())
        if index is None or index.GetNumberOfComponents() != 3:
            raise ValueError("%s: an unstructured lattice needs a LatticeIndex of 3 ints per point (a sparse "
                             "lattice), or FFDFrame away (a tetrahedral one, which has no grid to write)" % where)
        index = vtk_to_numpy(index).astype(np.int64)
        if len(index) and (np.any(index < 0) or np.any(index >= counts)):
            raise ValueError("%s: a LatticeIndex lies outside the %s control points per axis" % (
                where, counts.tolist()))
        displacement = np.zeros((counts[2], counts[1], counts[0], 3))
        displacement[index[:, 2], index[:, 1], index[:, 0]] = moved
    return np.array(frame).reshape(4, 3), np.array(divisions), basis, displacement


def _require_finite(lattice, where):
    """Raises ValueError, naming `where`, when a point or RestPosition of the lattice (whose RestPosition has one
    3-vector per point) is not finite: no reader, ours included, takes such a lattice back."""
    for name, values in (("point", lattice.GetPoints().GetData()),
                         (vtkFFDDataContract.RestPositionArrayName(), lattice.GetPointData().GetArray(
                             vtkFFDDataContract.RestPositionArrayName()))):
        bad = np.flatnonzero(~np.all(np.isfinite(vtk_to_numpy(values)), axis=1))
        if len(bad):
            raise ValueError("%s: the %s of control point %d is not finite (%d control points have NaN or infinite "
                             "coordinates): move them to finite positions first" % (where, name, bad[0], len(bad)))


def _require_basis(basis, wanted, what):
    if basis != wanted:
        raise ValueError("%s holds a %s lattice, not %s: build the lattice with that basis (vtkFFDBuildLattice's "
                         "SetBasisTo...), or refit it with vtkFFDCoarsenLattice's Basis" % (
                             what, _basis_name(wanted), _basis_name(basis)))


def _axis_aligned(frame, what):
    """The signed lengths (S_x, T_y, U_z) of an axis-aligned frame (S along +x or -x, and so on: a negative
    length becomes a negative spacing, which VTK's warp transforms evaluate alike); ValueError for any other."""
    axes = frame[1:]
    lengths = np.diag(axes).copy()
    off = axes - np.diag(lengths)
    if np.any(np.abs(off) > _ALIGNMENT_TOLERANCE * np.linalg.norm(axes, axis=1)[:, None]) or np.any(lengths == 0):
        raise ValueError("%s has no orientation: the frame's S, T, U must lie along x, y, z (vtkFFDVoxelize's "
                         "default AXIS_ALIGNED frame); this one is S %s, T %s, U %s" % (
                             what, axes[0].tolist(), axes[1].tolist(), axes[2].tolist()))
    return lengths


def _number(x):
    """The shortest text that reads back as the float64 x (integral values without '.0', as ITK writes them)."""
    text = repr(float(x))
    return text[:-2] if text.endswith(".0") else text


# --- PyGeM ------------------------------------------------------------------------------------------------------


def _pygem_rotation(angles):
    """PyGeM's FFD.rotation_matrix: angles2matrix(z, y, x) composes Rx Ry Rz (pygem/utils.py), angles in degrees
    (pygem/ffd.py, np.radians); the box's edges are its columns scaled by the box lengths."""
    ax, ay, az = (math.radians(a) for a in angles)
    rx = np.array([[1.0, 0.0, 0.0], [0.0, math.cos(ax), -math.sin(ax)], [0.0, math.sin(ax), math.cos(ax)]])
    ry = np.array([[math.cos(ay), 0.0, math.sin(ay)], [0.0, 1.0, 0.0], [-math.sin(ay), 0.0, math.cos(ay)]])
    rz = np.array([[math.cos(az), -math.sin(az), 0.0], [math.sin(az), math.cos(az), 0.0], [0.0, 0.0, 1.0]])
    return rx @ ry @ rz


def _pygem_angles(rotation):
    """Degrees (x, y, z) whose _pygem_rotation is `rotation` (a proper rotation). R = Rx(a) Ry(b) Rz(c) has
    R[0] = (cos b cos c, -cos b sin c, sin b); a then follows from R Rz(c)^T = Rx(a) Ry(b), whose second column is
    (0, cos a, sin a). Taking a from that product, not from entries scaled by cos b, keeps the angles consistent
    near b = +-90 degrees, where c alone is ill-determined."""
    r = rotation
    b = math.atan2(r[0, 2], math.hypot(r[0, 0], r[0, 1]))
    c = math.atan2(-r[0, 1], r[0, 0])
    column = r @ np.array([math.sin(c), math.cos(c), 0.0])  # (R Rz(c)^T)[:, 1] = R Rz(c)^T e_y
    a = math.atan2(column[2], column[1])
    return [math.degrees(a), math.degrees(b), math.degrees(c)]


def read_prm(path):
    """The dense BERNSTEIN lattice of a PyGeM FFD parameter file (pygem/ffd.py, FFD.read_parameters): control
    points (nx, ny, nz) give divisions (nx-1, ny-1, nz-1); the frame is the box, X0 = box origin and S, T, U its
    edges, the box lengths along the columns of Rx Ry Rz (rotation angles x, y, z in degrees about the origin);
    control point (i, j, k) moves by mu_x S + mu_y T + mu_z U, its weights ("parameter x/y/z" lines "i j k
    value", in box-length units; lines left out are zero). vtkFFDDeform then deforms every point as PyGeM's FFD
    does: inside the box by the Bernstein sum, outside not at all."""
    if not os.path.isfile(path):
        raise FileNotFoundError("no PyGeM parameter file at %s" % path)
    config = configparser.RawConfigParser()  # as PyGeM reads it
    try:
        with open(path, encoding="utf-8") as stream:
            text = stream.read()
        config.read_string(text, source=path)
    except (configparser.Error, UnicodeDecodeError) as error:
        raise ValueError("%s is not a PyGeM parameter file: %s" % (path, " ".join(str(error).split()))) from None
    if text and not text.endswith("\n"):  # PyGeM's files and ours end with one; a cut in a number reads as one
        raise ValueError("%s does not end with a line break: a file cut short? (if it is whole, end it with one)" %
                         path)

    def value(section, key, kind):
        try:
            text = config.get(section, key)
        except configparser.Error:
            raise ValueError("%s: PyGeM's [%s] '%s' is missing" % (path, section, key)) from None
        try:
            number = kind(text)
        except ValueError:
            raise ValueError("%s: [%s] '%s' is %r, not %s" % (
                path, section, key, text, "an integer" if kind is int else "a number")) from None
        if kind is float and not math.isfinite(number):
            raise ValueError("%s: [%s] '%s' is not finite" % (path, section, key))
        return number

    counts = [value("Box info", "n control points " + a, int) for a in "xyz"]
    lengths = [value("Box info", "box length " + a, float) for a in "xyz"]
    origin = [value("Box info", "box origin " + a, float) for a in "xyz"]
    angles = [value("Box info", "rotation angle " + a, float) for a in "xyz"]
    if min(counts) < 2:
        raise ValueError("%s: %s control points per axis; a lattice needs at least 2 (one voxel) on each" % (
            path, counts))
    if 0.0 in lengths:
        raise ValueError("%s: a box length of 0 makes a flat box" % path)
    _require_memory(24.0 * math.prod(counts), "%s: %s control points" % (path, "x".join(map(str, counts))))
    weights = np.zeros((3, counts[0], counts[1], counts[2]))  # PyGeM's array_mu_x, _y, _z, indexed [i, j, k]
    listed = np.zeros(weights.shape, dtype=bool)
    for c, axis in enumerate("xyz"):
        try:
            text = config.get("Parameters weights", "parameter " + axis)
        except configparser.Error:
            raise ValueError("%s: PyGeM's [Parameters weights] 'parameter %s' is missing" % (path, axis)) from None
        for line in text.split("\n"):
            fields = line.split()
            if not fields:
                continue
            try:
                if len(fields) != 4:
                    raise ValueError
                i, j, k = (int(f) for f in fields[:3])
                weight = float(fields[3])
            except ValueError:
                raise ValueError("%s: 'parameter %s' line %r is not 'i j k weight'" % (path, axis, line)) from None
            if not (0 <= i < counts[0] and 0 <= j < counts[1] and 0 <= k < counts[2]):
                raise ValueError("%s: 'parameter %s' line %r names a control point outside the %s" % (
                    path, axis, line.strip(), "x".join(str(n) for n in counts)))
            if not math.isfinite(weight):
                raise ValueError("%s: 'parameter %s' line %r has a weight that is not finite" % (
                    path, axis, line.strip()))
            weights[c, i, j, k] = weight  # a repeated line overrides, as in PyGeM
            listed[c, i, j, k] = True
    # Lines left out are zero, but PyGeM and write_prm list every control point: a file that lists all of them
    # for one axis and not for another was cut short.
    complete = listed.reshape(3, -1).all(axis=1)
    if complete.any() and not complete.all():
        axis = "xyz"[int(np.argmin(complete))]
        raise ValueError("%s: 'parameter %s' lists %d of the %d control points, while 'parameter %s' lists them all: "
                         "a file cut short?" % (path, axis, listed["xyz".index(axis)].sum(), listed[0].size,
                                                "xyz"[int(np.argmax(complete))]))
    edges = _pygem_rotation(angles) * np.array(lengths)  # columns: S, T, U
    frame = np.concatenate([origin, edges[:, 0], edges[:, 1], edges[:, 2]])
    # mu[c][i, j, k] -> [k, j, i, c], then each weight along its own edge.
    displacement = weights.transpose(3, 2, 1, 0) @ edges.T
    return _lattice_with_displacements(frame, [n - 1 for n in counts], BERNSTEIN, displacement)


def write_prm(lattice, path):
    """Writes a BERNSTEIN lattice whose frame's S, T, U are orthogonal as a PyGeM FFD parameter file (the inverse
    of read_prm): box origin X0, box lengths |S|, |T|, |U| (|U| negated for a left-handed frame, whose U then points
    against the rotation's third column), the angles of the rotation (S/|S|, T/|T|, U/|U|) in PyGeM's order,
    and each control point's displacement in (S, T, U) units. Numbers are written to round-trip exactly.
    ValueError for another basis, a tetrahedral lattice, or a frame whose axes are not orthogonal (PyGeM's box is a
    rotated box)."""
    frame, divisions, basis, displacement = _grid_lattice(lattice, "a PyGeM parameter file")
    _require_basis(basis, BERNSTEIN, "PyGeM's FFD")
    axes = frame[1:]
    lengths = np.linalg.norm(axes, axis=1)
    for a, b in ((0, 1), (0, 2), (1, 2)):
        if abs(axes[a] @ axes[b]) > _ALIGNMENT_TOLERANCE * lengths[a] * lengths[b]:
            raise ValueError("PyGeM's box is a rotated box, but this frame's %s and %s are not orthogonal (S %s, "
                             "T %s, U %s): build the lattice over a box (vtkFFDVoxelize's AXIS_ALIGNED or "
                             "PRINCIPAL_AXES frame)" % ("STU"[a], "STU"[b], axes[0].tolist(), axes[1].tolist(),
                                                        axes[2].tolist()))
    rotation = (axes / lengths[:, None]).T  # columns S/|S|, T/|T|, U/|U|
    if np.linalg.det(rotation) < 0:  # left-handed: a rotation with U's column reversed and a negative length
        rotation[:, 2] = -rotation[:, 2]
        lengths[2] = -lengths[2]
    angles = _pygem_angles(rotation)
    # mu solves displacement = mu_x S + mu_y T + mu_z U; back to PyGeM's [c][i, j, k].
    weights = np.linalg.solve(axes.T, displacement.reshape(-1, 3).T).reshape(
        3, *displacement.shape[:3]).transpose(0, 3, 2, 1)
    counts = [int(n) + 1 for n in divisions]
    lines = ["[Box info]",
             "# The FFD box (PyGeM, pygem/ffd.py): control points, lengths and origin along its axes,",
             "# rotation angles in degrees about x, y, z (rotation Rx Ry Rz about the origin). Written by VoxelFFD.",
             ""]
    lines += ["n control points %s: %d" % (a, n) for a, n in zip("xyz", counts)]
    lines += ["box length %s: %s" % (a, _number(x)) for a, x in zip("xyz", lengths)]
    lines += ["box origin %s: %s" % (a, _number(x)) for a, x in zip("xyz", frame[0])]
    lines += ["rotation angle %s: %s" % (a, _number(x)) for a, x in zip("xyz", angles)]
    lines += ["", "[Parameters weights]",
              "# Displacements of control points i j k, in units of the box lengths."]
    for c, axis in enumerate("xyz"):
        rows = ["%d   %d   %d   %s" % (i, j, k, _number(weights[c, i, j, k]))
                for i in range(counts[0]) for j in range(counts[1]) for k in range(counts[2])]
        lines.append("parameter %s: %s" % (axis, rows[0]))
        lines += ["             " + row for row in rows[1:]]  # indented: configparser's continuation lines
    _write_text(path, "\n".join(lines) + "\n")


def _write_text(path, text):
    """Writes `text` into the file `path`, UTF-8, all or nothing (vtkffd.meshio.write_atomically)."""

    def write(temporary):
        with open(temporary, "w", encoding="utf-8") as stream:
            stream.write(text)

    meshio.write_atomically(path, write)


# --- VTK's transforms -------------------------------------------------------------------------------------------


def _image_node_zero(image):
    """The world position of an image's first point: its origin moved by the extent's start (VTK's warp
    transforms index the grid from the extent's start, ignoring the image's direction matrix)."""
    extent = image.GetExtent()
    return np.array(image.GetOrigin()) + np.array(extent[0::2]) * np.array(image.GetSpacing())


def _image_divisions(image, border, what, name):
    """The divisions of the lattice over a transform's image of divisions + `border` points along each axis, and
    the image's spacing; ValueError where an axis has too few points for one voxel."""
    dims = np.array(image.GetDimensions())
    if np.any(dims < border + 1):
        raise ValueError("%s: the %s is %s points; a lattice needs at least %d (one voxel) along each axis"
                         % (what, name, dims.tolist(), border + 1))
    return dims - border, np.array(image.GetSpacing())


def _image_vectors(image, what):
    """The image's 3-component point scalars as an (nK, nJ, nI, 3) float64 array."""
    scalars = image.GetPointData().GetScalars()
    if scalars is None or scalars.GetNumberOfComponents() != 3:
        raise ValueError("%s's grid needs point scalars of 3 components (the displacements)" % what)
    dims = image.GetDimensions()
    return vtk_to_numpy(scalars).astype(np.float64).reshape(dims[2], dims[1], dims[0], 3), scalars.GetDataType()


def _displacement_image(node_zero, spacing, displacement):
    image = vtkImageData()
    image.SetDimensions(displacement.shape[2], displacement.shape[1], displacement.shape[0])
    image.SetOrigin(*node_zero)
    image.SetSpacing(*spacing)
    values = numpy_to_vtk(np.ascontiguousarray(displacement.reshape(-1, 3)), deep=True, array_type=VTK_DOUBLE)
    values.SetName("Displacement")
    image.GetPointData().SetScalars(values)
    return image


def _check_transform(transform, kind, what):
    if not isinstance(transform, kind):
        raise ValueError("%s takes a %s, not %s" % (what, kind.__name__, type(transform).__name__))
    if transform.GetInverseFlag():
        raise ValueError("%s: the %s is inverted (Inverse()), which no lattice evaluates" % (what, kind.__name__))
    # Update() brings the grid up to date through its pipeline connection; checked() leaves the caller's transform
    # without its observer.
    meshio.checked(transform, transform.Update, "%s: the %s refuses its grid" % (what, kind.__name__), ValueError)


def lattice_from_bspline_transform(transform):
    """The dense CUBIC_BSPLINE lattice of a vtkBSplineTransform: its coefficient image's dims minus 3 divisions,
    control point (i, j, k) at the image's point (i, j, k) (from the extent's start) moved by its coefficient times
    DisplacementScale, the frame from the image's point (1, 1, 1) (X0) spanning dims - 3 spacings along x, y, z;
    the image's direction matrix is ignored, as the transform ignores it. vtkFFDDeform then deforms every point
    inside the frame as the transform does, whatever its border mode (inside, the spline never reaches past the
    image). ValueError for a transform without coefficients, an inverted one, coefficients other than 3 float or
    double components, or fewer than 4 points along an axis."""
    what = "lattice_from_bspline_transform"
    _check_transform(transform, vtkBSplineTransform, what)
    image = transform.GetCoefficientData()
    if image is None:
        raise ValueError("%s: the vtkBSplineTransform has no coefficient image" % what)
    coefficients, data_type = _image_vectors(image, "vtkBSplineTransform")
    if data_type not in (VTK_FLOAT, VTK_DOUBLE):
        raise ValueError("%s: vtkBSplineTransform evaluates float or double coefficients only" % what)
    divisions, spacing = _image_divisions(image, 3, what, "coefficient image")
    frame = np.concatenate([_image_node_zero(image) + spacing, np.diag(spacing * divisions).ravel()])
    return _lattice_with_displacements(frame, divisions, CUBIC_BSPLINE,
                                       coefficients * transform.GetDisplacementScale())


def bspline_transform_from_lattice(lattice):
    """A vtkBSplineTransform (border mode Edge, DisplacementScale 1) of a CUBIC_BSPLINE lattice whose frame lies
    along x, y, z (each axis forwards or backwards): coefficient image of n + 3 points per axis for n divisions,
    spacing S_x/n, T_y/n, U_z/n, origin at control point (0, 0, 0)'s rest position X0 - (spacing), coefficients
    the displacements (double) in the lattice's order (Testing/Cxx/TestFFDDeformLocal.cxx,
    CubicBSplineEqualsVTKBSplineTransform). It deforms every point inside the frame as vtkFFDDeform does; outside,
    Edge extends the spline. ValueError for another basis or a frame that is not axis-aligned
    (vtkBSplineTransform has no orientation)."""
    frame, divisions, basis, displacement = _grid_lattice(lattice, "bspline_transform_from_lattice")
    _require_basis(basis, CUBIC_BSPLINE, "a vtkBSplineTransform")
    spacing = _axis_aligned(frame, "vtkBSplineTransform") / divisions
    transform = vtkBSplineTransform()
    transform.SetCoefficientData(_displacement_image(frame[0] - spacing, spacing, displacement))
    transform.SetBorderModeToEdge()
    transform.SetDisplacementScale(1.0)
    return transform


def lattice_from_grid_transform(transform):
    """The dense TRILINEAR lattice of a vtkGridTransform with linear interpolation: its displacement grid's dims
    minus 1 divisions, control point (i, j, k) at the grid's point (i, j, k) (from the extent's start) moved by its
    value times DisplacementScale plus DisplacementShift (added to each component, as the transform does), the
    frame the grid's box; the image's direction matrix is ignored, as the transform ignores it. vtkFFDDeform then
    deforms every point inside the frame as the transform does, and every point with
    SetOutsidePolicyToClampToEdge() (the transform clamps its grid index to the grid: vtkGridTransform.cxx,
    vtkTrilinearInterpolation), both up to the transform's fixed-point cell fraction (vtkInterpolationMath::Floor
    keeps 16 bits: an error of up to 2^-16 of the displacement's change across a cell). ValueError for a transform
    without a grid, an inverted one, another interpolation mode, a grid other than 3 components of the types the
    transform reads, or fewer than 2 points along an axis."""
    what = "lattice_from_grid_transform"
    _check_transform(transform, vtkGridTransform, what)
    if transform.GetInterpolationMode() != VTK_LINEAR_INTERPOLATION:
        raise ValueError("%s: a TRILINEAR lattice is vtkGridTransform's linear interpolation, and this transform "
                         "interpolates %s" % (what, transform.GetInterpolationModeAsString()))
    image = transform.GetDisplacementGrid()
    if image is None:
        raise ValueError("%s: the vtkGridTransform has no displacement grid" % what)
    values, data_type = _image_vectors(image, "vtkGridTransform")
    if data_type not in (VTK_CHAR, VTK_UNSIGNED_CHAR, VTK_SHORT, VTK_UNSIGNED_SHORT, VTK_FLOAT, VTK_DOUBLE):
        # vtkGridTransform::InternalUpdate refuses other types and then leaves every point where it is.
        raise ValueError("%s: vtkGridTransform reads (unsigned) char, (unsigned) short, float or double grids "
                         "only" % what)
    divisions, spacing = _image_divisions(image, 1, what, "displacement grid")
    frame = np.concatenate([_image_node_zero(image), np.diag(spacing * divisions).ravel()])
    displacement = values * transform.GetDisplacementScale() + transform.GetDisplacementShift()
    return _lattice_with_displacements(frame, divisions, TRILINEAR, displacement)


def grid_transform_from_lattice(lattice):
    """A vtkGridTransform (linear interpolation, DisplacementScale 1, DisplacementShift 0) of a TRILINEAR lattice
    whose frame lies along x, y, z (each axis forwards or backwards): displacement grid of n + 1 points per axis
    for n divisions, origin X0, spacing S_x/n, T_y/n, U_z/n, values the displacements (double) in the lattice's
    order. It deforms every point inside the frame as vtkFFDDeform does, and outside as vtkFFDDeform's
    ClampToEdge policy does, up to its fixed-point cell fraction (lattice_from_grid_transform). ValueError for
    another basis or a frame that is not axis-aligned (vtkGridTransform has no orientation)."""
    frame, divisions, basis, displacement = _grid_lattice(lattice, "grid_transform_from_lattice")
    _require_basis(basis, TRILINEAR, "a vtkGridTransform")
    spacing = _axis_aligned(frame, "vtkGridTransform") / divisions
    transform = vtkGridTransform()
    transform.SetDisplacementGridData(_displacement_image(frame[0], spacing, displacement))
    transform.SetInterpolationModeToLinear()
    transform.SetDisplacementScale(1.0)
    transform.SetDisplacementShift(0.0)
    return transform


# --- ITK ------------------------------------------------------------------------------------------------------

_ITK_BSPLINE = re.compile(r"^BSplineTransform_(double|float)_3_3$")
_ITK_COMPOSITE = re.compile(r"^CompositeTransform_(double|float)_3_3$")


def _itk_numbers(path, name, text):
    try:
        numbers = np.array([float(token) for token in text.split()])
    except ValueError:
        raise ValueError("%s: '%s:' holds something other than numbers" % (path, name)) from None
    if not np.all(np.isfinite(numbers)):
        raise ValueError("%s: '%s:' holds numbers that are not finite" % (path, name))
    return numbers


def _itk_transforms(path):
    """The transforms of an ITK text transform file (itkTxtTransformIO.cxx, Read): lines 'Name: value', '#' lines
    and blank ones skipped; each 'Transform:' starts a transform that the 'Parameters:' and 'FixedParameters:'
    after it belong to. Returns [(type, parameters or None, fixed parameters or None)]."""
    if not os.path.isfile(path):
        raise FileNotFoundError("no ITK transform file at %s" % path)
    try:
        with open(path, encoding="utf-8") as stream:
            text = stream.read()
    except UnicodeDecodeError:
        raise ValueError("%s is not an ITK text transform file (it is not text)" % path) from None
    transforms = []
    for number, line in enumerate(text.splitlines(), 1):
        line = line.strip()
        if not line or line.startswith("#"):
            continue
        name, colon, value = line.partition(":")
        if not colon:
            raise ValueError("%s, line %d: ITK's lines are 'Name: value', not %r" % (path, number, line[:60]))
        name, value = name.strip(), value.strip()
        if name == "Transform":
            transforms.append([value, None, None])
        elif name in ("Parameters", "FixedParameters"):
            if not transforms:
                raise ValueError("%s, line %d: %s before any 'Transform:'" % (path, number, name))
            transforms[-1][1 if name == "Parameters" else 2] = _itk_numbers(path, name, value)
        elif name == "ComponentTransformFile":
            raise ValueError("%s: a composite transform whose components are other files; write the B-spline "
                             "transform into this file instead" % path)
        else:
            raise ValueError("%s, line %d: unknown entry %r of an ITK transform file" % (path, number, name))
    if not transforms:
        raise ValueError("%s holds no 'Transform:': not an ITK text transform file" % path)
    return transforms


def read_tfm(path):
    """The dense CUBIC_BSPLINE lattice of an ITK text transform file holding one BSplineTransform_double_3_3 (or
    _float_3_3), alone or as the only transform of a CompositeTransform. ITK's fixed parameters
    (itkBSplineTransform.hxx) are the coefficient grid's size (mesh size + 3), origin (one node before the
    transform domain), spacing, and direction matrix row-major (direction[i][j] at 9 + 3 i + j); its parameters
    the coefficients, all x (grid order, i fastest) then all y then all z, displacements in world coordinates.
    The frame is X0 = origin + D spacing (node (1, 1, 1)), S = D[:, 0] spacing[0] (size[0] - 3), and so on;
    vtkFFDDeform then deforms every point as ITK's TransformPoint does: inside the domain by the spline, outside
    not at all. ValueError for other transforms, several, or malformed parameters."""
    transforms = _itk_transforms(path)
    kinds = [t[0] for t in transforms]
    if len(transforms) == 2 and _ITK_COMPOSITE.match(kinds[0]):
        if transforms[0][1] is not None and len(transforms[0][1]):
            raise ValueError("%s: the CompositeTransform has parameters of its own" % path)
        transforms = transforms[1:]
    elif len(transforms) > 1 or _ITK_COMPOSITE.match(kinds[0]):
        raise ValueError("%s holds the transforms %s: a lattice is one BSplineTransform, alone or the only one of a "
                         "CompositeTransform" % (path, kinds))
    kind, parameters, fixed = transforms[0]
    if not _ITK_BSPLINE.match(kind):
        raise ValueError("%s holds a %s: a lattice is ITK's cubic BSplineTransform_double_3_3 (or _float_3_3)" % (
            path, kind))
    if parameters is None or fixed is None:
        raise ValueError("%s: the %s lacks its %s" % (
            path, kind, "'Parameters:'" if parameters is None else "'FixedParameters:'"))
    if fixed.size != 18:
        raise ValueError("%s: a 3D BSplineTransform has 18 fixed parameters (grid size, origin, spacing, direction),"
                         " this one %d" % (path, fixed.size))
    size, origin, spacing = fixed[0:3], fixed[3:6], fixed[6:9]
    direction = fixed[9:18].reshape(3, 3)
    if np.any(size != np.round(size)) or np.any(size < 4):
        raise ValueError("%s: grid size %s; a lattice needs whole numbers of at least 4 (one mesh cell + 3)" % (
            path, size.tolist()))
    if np.any(spacing <= 0):
        raise ValueError("%s: grid spacing %s; ITK's spacings are positive" % (path, spacing.tolist()))
    if abs(np.linalg.det(direction)) < 1e-12:
        raise ValueError("%s: the grid's direction matrix %s is singular" % (path, direction.tolist()))
    if 3 * np.prod(size) != parameters.size:  # in float64, before a size of 1e300 becomes an integer
        raise ValueError("%s: a grid of %s nodes has %.17g parameters (3 per node), this one %d" % (
            path, size.tolist(), 3 * np.prod(size), parameters.size))
    size = size.astype(np.int64)
    divisions = size - 3
    axes = direction * (spacing * divisions)  # columns: S, T, U
    frame = np.concatenate([origin + direction @ spacing, axes[:, 0], axes[:, 1], axes[:, 2]])
    displacement = parameters.reshape(3, size[2], size[1], size[0]).transpose(1, 2, 3, 0)
    return _lattice_with_displacements(frame, divisions, CUBIC_BSPLINE, displacement)


def write_tfm(lattice, path):
    """Writes a CUBIC_BSPLINE lattice as an ITK text transform file of one BSplineTransform_double_3_3 (the
    inverse of read_tfm): grid size n + 3, spacing |S|/n, |T|/n, |U|/n, direction columns S/|S|, T/|T|, U/|U|
    (any frame: they need not be orthogonal), origin X0 - S/n - T/n - U/n, the displacements as parameters.
    Numbers are written to round-trip exactly. ValueError for another basis or a tetrahedral lattice."""
    frame, divisions, basis, displacement = _grid_lattice(lattice, "an ITK transform file")
    _require_basis(basis, CUBIC_BSPLINE, "ITK's BSplineTransform")
    axes = frame[1:]
    lengths = np.linalg.norm(axes, axis=1)
    direction = (axes / lengths[:, None]).T
    spacing = lengths / divisions
    origin = frame[0] - direction @ spacing
    size = divisions + 3
    parameters = np.concatenate([displacement[..., c].ravel() for c in range(3)])
    fixed = np.concatenate([size, origin, spacing, direction.ravel()])  # ravel: row-major, as ITK stores it
    _write_text(path, "#Insight Transform File V1.0\n#Transform 0\nTransform: BSplineTransform_double_3_3\n"
                "Parameters: " + " ".join(_number(x) for x in parameters) + "\n"
                "FixedParameters: " + " ".join(_number(x) for x in fixed) + "\n")


# --- files by extension -----------------------------------------------------------------------------------------

LATTICE_EXTENSIONS = (".vts", ".vtu", ".vtk", ".vdb", ".prm", ".tfm")  # read_lattice's and write_lattice's


def lattice_extension(path):
    """The extension of `path`, in lower case, after a ValueError if it is none of LATTICE_EXTENSIONS: what
    read_lattice and write_lattice check first, and a caller before the work whose lattice it writes."""
    extension = os.path.splitext(path)[1].lower()
    if extension not in LATTICE_EXTENSIONS:
        raise ValueError("%s: unknown lattice file type %r; VoxelFFD reads and writes %s" % (
            path, extension, ", ".join(LATTICE_EXTENSIONS)))
    return extension


def _require_lattice_arrays(data, path):
    rest = data.GetPointData().GetArray(vtkFFDDataContract.RestPositionArrayName())
    if data.GetPoints() is None or rest is None or rest.GetNumberOfComponents() != 3 or \
            rest.GetNumberOfTuples() != data.GetNumberOfPoints():
        raise ValueError("%s holds no lattice: its points have no RestPosition of 3 components each "
                         "(docs/pipeline-and-data-contract.md, \"Data contract\")" % path)


def read_lattice(path):
    """A lattice from a file, by its extension: .vts (dense, VTK XML), .vtu (sparse or tetrahedral, VTK XML), .vtk
    (either, VTK legacy), each read by vtkffd.meshio's reader of the extension, .vdb (sparse, vtkFFDVDBReader),
    .prm (read_prm), .tfm (read_tfm). ValueError for another extension, a file its reader refuses (VTK's warnings
    included: a legacy file cut short gives only one), a data set that is no lattice (no RestPosition of one
    3-vector per point), or cells that name points it does not have."""
    extension = lattice_extension(path)
    if not os.path.isfile(path):
        raise FileNotFoundError("no lattice file at %s" % path)
    if extension == ".prm":
        return read_prm(path)
    if extension == ".tfm":
        return read_tfm(path)
    failure = "cannot read a lattice from %s" % path
    meshio.check_header(path, extension, failure)
    reader = vtkFFDVDBReader() if extension == ".vdb" else meshio.VTK_FORMATS[extension][0]()
    reader.SetFileName(path)
    meshio.checked(reader, reader.Update, failure, ValueError, warnings=True)
    data = reader.GetOutputDataObject(0)
    if not isinstance(data, (vtkStructuredGrid, vtkUnstructuredGrid)):
        raise ValueError("%s: it holds %s" % (failure, "a " + type(data).__name__ if data else "nothing"))
    _require_lattice_arrays(data, path)
    meshio.check_cells(data, failure)
    lattice = type(data)()
    lattice.DeepCopy(data)
    return lattice


def write_lattice(lattice, path):
    """Writes a lattice to a file, by its extension: .vts (a dense lattice), .vtu (a sparse or tetrahedral one),
    .vtk (either), each by vtkffd.meshio's write_mesh (XML compressed, legacy binary: doubles stay exact), .vdb (a
    sparse lattice of a local basis, vtkFFDVDBWriter), .prm (write_prm), .tfm (write_tfm). ValueError for another
    extension or a lattice the format cannot hold, or whose points are not finite; OSError when the file cannot be
    written, which then is as it was (vtkffd.meshio.write_atomically)."""
    extension = lattice_extension(path)
    if extension == ".prm":
        return write_prm(lattice, path)
    if extension == ".tfm":
        return write_tfm(lattice, path)
    if not isinstance(lattice, (vtkStructuredGrid, vtkUnstructuredGrid)):
        raise ValueError("write_lattice takes a lattice (vtkStructuredGrid or vtkUnstructuredGrid), not %s" % (
            type(lattice).__name__))
    _require_lattice_arrays(lattice, "the data set to write to " + path)
    _require_finite(lattice, path)
    if extension == ".vts" and not isinstance(lattice, vtkStructuredGrid):
        raise ValueError("%s: .vts holds dense lattices (vtkStructuredGrid); write this %s to .vtu" % (
            path, type(lattice).__name__))
    if extension == ".vtu" and not isinstance(lattice, vtkUnstructuredGrid):
        raise ValueError("%s: .vtu holds sparse and tetrahedral lattices (vtkUnstructuredGrid); write this dense "
                         "lattice to .vts" % path)
    if extension != ".vdb":
        return meshio.write_mesh(lattice, path)
    writer = vtkFFDVDBWriter()
    writer.SetInputData(lattice)
    # The lattices it refuses are ValueErrors, as those of the other formats.
    meshio.write_atomically(path, lambda temporary: meshio.write_vtk(writer, temporary, "cannot write " + path,
                                                                     ValueError))
    return None
