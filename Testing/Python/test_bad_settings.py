#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""Bad settings and bad inputs over every public filter of the `vtkffd` package (and vtkFFDLatticeDynamics,
vtkFFDMagneticSphere, vtkFFDDataContract): the regression net for the classes of defects of issue 30 (a check only
in RequestInformation; NaN, inf, negative and huge settings; ids not validated against the point count; a missing or
wrong-typed input), some 1,300 cases on small inputs (a vtkSphereSource mesh and lattices of every kind built over
it) in a few seconds.

Every case runs in a child process (this file run with --group NAME --from INDEX; the cases of a group share a
child, which prints each case's name before running it), under an address-space limit of 4 GiB above what the
child has mapped at start (so that an unbounded allocation fails fast instead of stalling the machine) and an alarm
of CASE_SECONDS per case. A child that dies names its case: a signal (SIGSEGV, SIGABRT, SIGFPE, ...) is a crash,
the alarm's SIGALRM a hang; the group's next cases run in a new child.

Filters run as ParaView's executive runs them: RequestInformation, then RequestData even where RequestInformation
failed (executive UpdateInformation(), PropagateUpdateExtent(), UpdateData()), so that a check made only in
RequestInformation does not pass. The pass rule of a case:
  - the filter reports an error (an ErrorEvent on the filter, on an object it owns such as its Dynamics, or on its
    executive other than the generic "returned failure for request"), the message is not empty and, where the case
    names the offending setting, it or an error on VTK's output window during the case (where a filter says "see
    the error above") names it, case and spaces ignored; and every output is empty or as it was before; or
  - it succeeds without an error, every output point is finite, and what else the case checks holds (the normals
    and Jacobian determinants of vtkFFDDeform finite, the residuals of vtkFFDCoarsenLattice finite; where the case
    corrupts ids or indices that the filter might not read, the output that of the intact input), unless the case
    must end in an error (ids or indices that name no point or voxel, huge sizes, a missing or wrong-typed input,
    a value outside a documented range, an integer RestPosition): then success fails with "no error".
What is not a filter follows the same rule through its return values: vtkFFDLatticeDynamics::Step() and
ApplyImpulse() (an error leaves the lattice's points as they were), vtkFFDVDBWriter::Write(), and
vtkFFDDataContract's static setters (an error on VTK's output window) and getters (false for what is not valid).

A failing case is reported with what happened: crash (the signal), hang, silent corruption (non-finite output
without an error), silent change, no error, error with output, error does not name the setting, failed without a
message, or an exception in Python. Run with Debian's /usr/bin/python3 and
PYTHONPATH=<build>/lib/python3/dist-packages (ctest sets it). Exits non-zero when a case fails.
"""
import json
import os
import resource
import signal
import subprocess
import sys
import tempfile
import unittest
from concurrent.futures import ThreadPoolExecutor

import numpy as np
from vtkmodules.util.numpy_support import numpy_to_vtk, numpy_to_vtkIdTypeArray, vtk_to_numpy
from vtkmodules.vtkCommonCore import VTK_INT, reference, vtkOutputWindow, vtkPoints, vtkStringOutputWindow
from vtkmodules.vtkCommonDataModel import (vtkImageData, vtkPlane, vtkPolyData, vtkSphere, vtkStructuredGrid,
                                           vtkUnstructuredGrid)
from vtkmodules.vtkCommonExecutionModel import vtkStreamingDemandDrivenPipeline
from vtkmodules.vtkFiltersSources import vtkSphereSource

import vtkffd
from ffdtesting import ErrorCatcher  # the same folder

CASE_SECONDS = 20  # a case of these small inputs takes milliseconds; one still running after this hangs
MEMORY_LIMIT = 4 << 30  # bytes of address space a child may map beyond what it has at start
FOLDER_VARIABLE = "VOXELFFD_BAD_SETTINGS_FOLDER"  # where the children write their files
Build = vtkffd.vtkFFDBuildLattice
NAN, INF, HUGE = float("nan"), float("inf"), 1e308
INT_MAX = 2**31 - 1

# ---------------------------------------------------------------------------------------------------------------
# Inputs (built in the child, cached; the cases get copies).

_cache = {}


def cached(key, make):
    if key not in _cache:
        _cache[key] = make()
    return _cache[key]


def sphere_mesh(radius=0.5):
    """A vtkSphereSource surface (122 points, with point normals) of `radius` about the origin: a new copy."""
    def make():
        source = vtkSphereSource()
        source.SetRadius(radius)
        source.SetOutputPointsPrecision(1)  # vtkAlgorithm.DOUBLE_PRECISION: a point can hold 1e308
        source.SetThetaResolution(12)
        source.SetPhiResolution(12)
        source.Update()
        return source.GetOutput()
    mesh = vtkPolyData()
    mesh.DeepCopy(cached(("sphere", radius), make))
    return mesh


def points_mesh(points):
    """A vtkPolyData of the (N, 3) `points`, in double precision, without cells."""
    vtk_points = vtkPoints()
    vtk_points.SetDataTypeToDouble()
    vtk_points.SetData(numpy_to_vtk(np.asarray(points, dtype=np.float64).reshape(-1, 3), deep=True))
    mesh = vtkPolyData()
    mesh.SetPoints(vtk_points)
    return mesh


def mesh_with_point(value, index=5):
    """The sphere mesh with point `index` set to (value, value, value)."""
    mesh = sphere_mesh()
    vtk_to_numpy(mesh.GetPoints().GetData())[index] = value
    mesh.GetPoints().Modified()
    return mesh


def set_value(obj, setter, value):
    """obj.Set<setter>(value), a tuple as its parts."""
    method = getattr(obj, "Set" + setter)
    method(*value) if isinstance(value, tuple) else method(value)


def configure(obj, settings):
    for setter, value in settings.items():
        set_value(obj, setter, value)
    return obj


def copy_of(data):
    copy = data.NewInstance()
    copy.DeepCopy(data)
    return copy


def voxel_grid(divisions=(4, 4, 4), frame=None):
    """vtkFFDVoxelize's output over the sphere (a copy): `divisions`, and an explicit frame where given."""
    def make():
        voxelize = vtkffd.vtkFFDVoxelize()
        voxelize.SetInputData(sphere_mesh())
        voxelize.SetDivisions(*divisions)
        if frame is not None:
            voxelize.SetFrame(*frame)
        voxelize.Update()
        return copy_of(voxelize.GetOutput())
    return copy_of(cached(("voxels", divisions, frame), make))


# The lattices the cases start from: (basis, form, divisions); "tetra" is vtkFFDBuildTetrahedralLattice's.
LATTICES = {
    "dense_bernstein": (Build.BERNSTEIN, Build.DENSE, (3, 3, 3)),
    "dense_trilinear": (Build.TRILINEAR, Build.DENSE, (4, 4, 4)),
    "dense_tricubic": (Build.TRICUBIC_BEZIER, Build.DENSE, (2, 2, 2)),
    "sparse_trilinear": (Build.TRILINEAR, Build.SPARSE, (4, 4, 4)),
    "sparse_bspline": (Build.CUBIC_BSPLINE, Build.SPARSE, (4, 4, 4)),
    "tetra": None,
}


def lattice(kind, moved=True):
    """A copy of the lattice `kind` over the sphere, its points moved a little (a deformation that is not the
    identity) unless `moved` is false."""
    def make():
        if kind == "tetra":
            build = vtkffd.vtkFFDBuildTetrahedralLattice()
            build.SetInputData(sphere_mesh())
        else:
            basis, form, divisions = LATTICES[kind]
            build = vtkffd.vtkFFDBuildLattice()
            build.SetInputData(voxel_grid(divisions))
            build.SetBasis(basis)
            build.SetLatticeForm(form)
        build.Update()
        assert build.GetOutput().GetNumberOfPoints() > 0, kind
        return copy_of(build.GetOutput())
    result = copy_of(cached(("lattice", kind), make))
    if moved:
        points = vtk_to_numpy(result.GetPoints().GetData())
        points += np.random.default_rng(30).uniform(-0.02, 0.02, points.shape)
        result.GetPoints().Modified()
    return result


def is_unstructured(kind):
    return not kind.startswith("dense")


# Bad lattices: each a function of a good one (a copy it may change) giving the data to connect, or None for no
# connection at all.

def _every_fifth(data, value):
    points = vtk_to_numpy(data.GetPoints().GetData())
    points[::5] = value
    data.GetPoints().Modified()
    return data


def _cell_id(data, value):
    connectivity = vtk_to_numpy(data.GetCells().GetConnectivityArray())  # a view
    connectivity[len(connectivity) // 2] = data.GetNumberOfPoints() + 7 if value is None else value
    data.GetCells().Modified()
    data.Modified()
    return data


def _truncate_points(data, arrays_too):
    """Removes the last 4 points (and, `arrays_too`, the point arrays' last 4 tuples); the cells still name them."""
    count = data.GetNumberOfPoints() - 4
    points = vtkPoints()
    points.SetDataTypeToDouble()
    points.SetData(numpy_to_vtk(vtk_to_numpy(data.GetPoints().GetData())[:count].copy(), deep=True))
    data.SetPoints(points)
    if arrays_too:
        for a in range(data.GetPointData().GetNumberOfArrays()):
            data.GetPointData().GetArray(a).SetNumberOfTuples(count)
    return data


def _rest(data, make):
    rest = data.GetPointData().GetArray("RestPosition")
    replacement = make(vtk_to_numpy(rest).copy())
    data.GetPointData().RemoveArray("RestPosition")
    if replacement is not None:
        replacement.SetName("RestPosition")
        data.GetPointData().AddArray(replacement)
    return data


def _field(data, name, values, array_type):
    data.GetFieldData().RemoveArray(name)
    array = numpy_to_vtk(np.asarray(values), deep=True, array_type=array_type)
    array.SetName(name)
    data.GetFieldData().AddArray(array)
    return data


def _strip_field_data(data):
    data.GetFieldData().Initialize()
    return data


def _image(_):
    image = vtkImageData()
    image.SetDimensions(3, 3, 3)
    return image


def _tuple_array(data, where, name, change, array_type=VTK_INT):
    """Replaces the array `name` of the point or cell data `where` by change(its values) (none where None), an
    array of `array_type` (None: numpy's)."""
    attributes = data.GetPointData() if where == "point" else data.GetCellData()
    values = change(vtk_to_numpy(attributes.GetArray(name)).copy())
    attributes.RemoveArray(name)
    if values is not None:
        array = numpy_to_vtk(values, deep=True, array_type=array_type)
        array.SetName(name)
        attributes.AddArray(array)
    return data


def _set_middle(values, row):
    values[len(values) // 2] = row
    return values


# name: (make, the kinds it applies to: "all", "unstructured", "sparse" or "grid" (not tetrahedral), its class):
#   "ids": ids that name no point, or arrays shorter than the points: an error for every filter that reads them
#          (those that deform or simulate); a filter that does not read them (vtkFFDCellEdges and vtkFFDVDBWriter
#          read a sparse lattice's LatticeIndex, not its cells) may succeed with what the intact lattice gives;
#   "index": a sparse lattice's LatticeIndex or VoxelIndex outside its divisions or short: an error, or the output
#          of the intact lattice (the array is not read);
#   "input": a missing or wrong-typed lattice: always an error;
#   "rest": RestPosition missing or integer (the contract says doubles): an error for the filters that deform;
#   "value": anything else, judged by the general rule.
BAD_LATTICES = {
    "nan_points": (lambda d: _every_fifth(d, NAN), "all", "value"),
    "huge_points": (lambda d: _every_fifth(d, HUGE), "all", "value"),
    "cell_id_past_end": (lambda d: _cell_id(d, None), "unstructured", "ids"),
    "cell_id_negative": (lambda d: _cell_id(d, -3), "unstructured", "ids"),
    "last_points_removed": (lambda d: _truncate_points(d, True), "all", "ids"),
    "points_shorter_than_arrays": (lambda d: _truncate_points(d, False), "all", "ids"),
    "rest_position_short": (lambda d: _rest(d, lambda r: numpy_to_vtk(r[:-4].copy(), deep=True)), "all", "ids"),
    "rest_position_missing": (lambda d: _rest(d, lambda r: None), "all", "rest"),
    "rest_position_integer": (
        lambda d: _rest(d, lambda r: numpy_to_vtk(np.trunc(r).astype(np.int32), deep=True)), "all", "rest"),
    "rest_position_nan": (lambda d: _rest(d, lambda r: numpy_to_vtk(np.where(r > 0, NAN, r), deep=True)), "all",
                          "value"),
    "lattice_index_past_divisions": (
        lambda d: _tuple_array(d, "point", "LatticeIndex", lambda v: _set_middle(v, (1000, 0, 0))), "sparse", "index"),
    "lattice_index_negative": (
        lambda d: _tuple_array(d, "point", "LatticeIndex", lambda v: _set_middle(v, (-5, 0, 0))), "sparse", "index"),
    "lattice_index_short": (lambda d: _tuple_array(d, "point", "LatticeIndex", lambda v: v[:-4]), "sparse", "index"),
    "voxel_index_past_divisions": (
        lambda d: _tuple_array(d, "cell", "VoxelIndex", lambda v: _set_middle(v, (1000, 0, 0))), "sparse", "index"),
    "voxel_index_negative": (
        lambda d: _tuple_array(d, "cell", "VoxelIndex", lambda v: _set_middle(v, (0, -5, 0))), "sparse", "index"),
    "voxel_index_short": (lambda d: _tuple_array(d, "cell", "VoxelIndex", lambda v: v[:-2]), "sparse", "index"),
    "no_field_data": (_strip_field_data, "all", "value"),
    "frame_nan": (lambda d: _field(d, "FFDFrame", [NAN] * 12, None), "all", "value"),
    "divisions_doubled": (lambda d: _field(
        d, "FFDDivisions", 2 * vtk_to_numpy(d.GetFieldData().GetArray("FFDDivisions")), VTK_INT), "grid", "ids"),
    "basis_99": (lambda d: _field(d, "FFDBasis", [99], VTK_INT), "all", "value"),
    "image_data": (_image, "all", "input"),
    # Not an error in itself: an empty piece of a distributed lattice is ordinary input, whose output may be empty.
    "empty_grid": (lambda d: vtkUnstructuredGrid(), "all", "value"),
    "missing": (lambda d: None, "all", "input"),
}


def bad_lattice(kind, variant):
    return BAD_LATTICES[variant][0](lattice(kind))


def variants_for(kind):
    applies = {"all": True, "unstructured": is_unstructured(kind), "sparse": kind.startswith("sparse"),
               "grid": kind != "tetra"}
    return [v for v, (_, where, _) in BAD_LATTICES.items() if applies[where]]


# ---------------------------------------------------------------------------------------------------------------
# Running a case and judging its outcome.

GENERIC = ("returned failure for request", "No update piece number has been set")
# The errors on VTK's output window during the case (run_child() clears them): where a filter's error says "see the
# error above", an object inside it (its lattice builder, its deformer) reported the details there.
WINDOW = ErrorCatcher()


def text_of(message):
    """A VTK error message without its "ERROR: In file, line N\\nclass (0x...): " header."""
    body = message.split("\n", 1)[1] if message.startswith("ERROR: In ") and "\n" in message else message
    if "): " in body.split("\n", 1)[0]:
        body = body.split("): ", 1)[1]
    return body.strip()


def observe(algorithm=None, others=()):
    """Observes the ErrorEvents of `algorithm`, its executive and `others`; returns the list they fill (the
    executive's generic ones left out when judged)."""
    catcher = ErrorCatcher()
    for obj in ([algorithm, algorithm.GetExecutive()] if algorithm is not None else []) + list(others):
        obj.AddObserver("ErrorEvent", catcher)
    return catcher.messages


def outputs_of(algorithm):
    """The points of each output port: a float64 array, or None where the output has none."""
    result = []
    for port in range(algorithm.GetNumberOfOutputPorts()):
        data = algorithm.GetOutputDataObject(port)
        points = data.GetPoints() if data is not None and hasattr(data, "GetPoints") else None
        result.append(None if points is None or points.GetNumberOfPoints() == 0
                      else vtk_to_numpy(points.GetData()).astype(np.float64))
    return result


def execute(algorithm, time=None):
    """Updates `algorithm` as ParaView's executive does: RequestInformation, then RequestData even where the first
    failed. Returns UpdateData's status."""
    executive = algorithm.GetExecutive()
    executive.UpdateInformation()
    if time is not None:
        algorithm.GetOutputInformation(0).Set(vtkStreamingDemandDrivenPipeline.UPDATE_TIME_STEP(), time)
    executive.PropagateUpdateExtent(0)
    return executive.UpdateData(0)


def names(message, needle):
    if isinstance(needle, str):
        needle = (needle,)
    flat = message.lower().replace(" ", "")
    return any(n.lower().replace(" ", "") in flat for n in needle)


def judge(messages, status, before, after, must_error, needle, extra=None):
    """The pass rule (module docstring) on what a case observed: None when it passes, else what went wrong."""
    errors = [text_of(m) for m in messages if not any(g in m for g in GENERIC)]
    nonfinite = [int((~np.isfinite(p)).any(axis=1).sum()) if p is not None else 0 for p in after]
    if errors or any(g in m for m in messages for g in GENERIC[:1]):
        if not errors or not any(errors):
            return "failed without a message (only the executive's generic failure)"
        for port, (b, a) in enumerate(zip(before, after)):
            if a is not None and not (b is not None and b.shape == a.shape and np.array_equal(a, b, equal_nan=True)):
                return "error with output: port %d holds %d points (%d not finite) after the error %r" % (
                    port, len(a), nonfinite[port], errors[0][:300])
        if needle and not any(names(e, needle) for e in errors + WINDOW.messages):
            return "error does not name %s: %r" % (needle if isinstance(needle, str) else " or ".join(needle),
                                                   errors[0][:300])
        return None
    if status == 0:
        return "failed without a message"
    if any(nonfinite):
        return "silent corruption: %s output points not finite, no error" % (
            ", ".join("%d of %d" % (n, len(p)) for n, p in zip(nonfinite, after) if n))
    if must_error:
        return "no error: succeeded with %s output points" % "/".join(
            str(0 if p is None else len(p)) for p in after)
    for check in (extra if isinstance(extra, (list, tuple)) else [extra]):
        problem = check() if check else None
        if problem:
            return problem
    return None


def run_filter(algorithm, must_error=False, needle=None, time=None, others=(), extra=None):
    """Executes `algorithm` (see execute()) and judges it."""
    messages = observe(algorithm, others)
    before = outputs_of(algorithm)
    status = execute(algorithm, time)
    return judge(messages, status, before, outputs_of(algorithm), must_error, needle, extra)


def run_call(obj, call, points_of, must_error=False, needle=None):
    """Calls call() (a method of `obj` returning 1 or 0) and judges it; `points_of()` gives the points whose
    change counts as output (those of the lattice a vtkFFDLatticeDynamics moves)."""
    messages = observe(None, [obj])
    def snapshot():
        data = points_of()
        return [None if data is None or data.GetPoints() is None else
                vtk_to_numpy(data.GetPoints().GetData()).astype(np.float64)]
    before = snapshot()
    status = call()
    after = snapshot()
    if messages and status != 0:
        return "error reported but the call returned %r: %r" % (status, text_of(messages[0])[:300])
    if not messages:
        before = after  # a success may move the points; only their finiteness counts
    return judge(messages, status, before, after, must_error, needle)


def output_parts(algorithm):
    """What two runs must share to give the same output: each port's points and cell connectivity."""
    parts = []
    for port in range(algorithm.GetNumberOfOutputPorts()):
        data = algorithm.GetOutputDataObject(port)
        points = data.GetPoints() if hasattr(data, "GetPoints") else None
        parts.append(None if points is None else vtk_to_numpy(points.GetData()))
        for cells in ("GetVerts", "GetLines", "GetPolys", "GetCells"):
            array = getattr(data, cells)() if hasattr(data, cells) else None
            if array is not None and hasattr(array, "GetConnectivityArray"):
                parts.append(vtk_to_numpy(array.GetConnectivityArray()))
    return parts


def same_output_as(algorithm, make_reference, time=None):
    """An extra check: the output of `algorithm` is that of make_reference() (the same filter on intact input)."""
    def check():
        reference = make_reference()
        observe(reference)
        execute(reference, time)
        got, want = output_parts(algorithm), output_parts(reference)
        if len(got) != len(want) or not all(
                (a is None and b is None) or (a is not None and b is not None and a.shape == b.shape and
                                              np.array_equal(a, b, equal_nan=True)) for a, b in zip(got, want)):
            return "silent change: no error, and the output differs from the intact lattice's"
        return None
    return check


def add_lattice_cases(group, prefix, kinds, make, run=None, reads=("ids", "input", "rest"), same=None, time=None,
                      skip=()):
    """A case for each bad lattice of each of `kinds`: `make(lattice_data)` gives the filter, `run(algorithm,
    must_error, needle, extra)` judges it (run_filter by default). The bad lattices in `reads` (classes or names)
    must be errors; those in `same` (by default the class "index", and "ids" where not in `reads`) must be errors
    or give the intact lattice's output."""
    run = run or (lambda algorithm, must, needle, extra: run_filter(algorithm, must, needle, time=time, extra=extra))
    same = same if same is not None else ("index",) + (() if "ids" in reads else ("ids",))
    for kind in kinds:
        for variant in variants_for(kind):
            if variant in skip:
                continue
            category = BAD_LATTICES[variant][2]

            def function(k=kind, v=variant, must=variant in reads or category in reads,
                         compare=variant in same or category in same):
                algorithm = make(bad_lattice(k, v))
                extra = same_output_as(algorithm, lambda: make(lattice(k)), time) if compare else None
                return run(algorithm, must, None, extra)
            add(group, "%s.%s,lattice=%s" % (prefix, kind, variant), function)


# ---------------------------------------------------------------------------------------------------------------
# The cases: GROUPS[group][name] = a function returning None (pass) or what went wrong.

GROUPS = {}


def add(group, name, function):
    assert name not in GROUPS.setdefault(group, {}), name
    GROUPS[group][name] = function


# vtkFFDVoxelize ------------------------------------------------------------------------------------------------

def voxelize(mesh=None, **settings):
    algorithm = vtkffd.vtkFFDVoxelize()
    if mesh is not None:
        algorithm.SetInputData(mesh)
    return configure(algorithm, settings)


for axis in range(3):
    for value in (0, -1, INT_MAX):
        divisions = [4, 4, 4]
        divisions[axis] = value
        add("voxelize", "voxelize.Divisions=%s" % (tuple(divisions),),
            lambda d=tuple(divisions), v=value: run_filter(voxelize(sphere_mesh(), Divisions=d),
                                                         must_error=v < 1, needle="Divisions"))
add("voxelize", "voxelize.Divisions=max^3",
    lambda: run_filter(voxelize(sphere_mesh(), Divisions=(INT_MAX,) * 3), must_error=True, needle="Divisions"))
for mode in ("AXIS_ALIGNED", "PRINCIPAL_AXES"):
    for value in (NAN, INF, HUGE, -1.0):
        add("voxelize", "voxelize.Padding=%r,%s" % (value, mode),
            lambda v=value, m=mode: run_filter(voxelize(sphere_mesh(), Padding=v,
                                                        FrameMode=getattr(vtkffd.vtkFFDVoxelize, m)),
                                               needle="Padding"))
UNIT = ((1.0, 0, 0), (0, 1.0, 0), (0, 0, 1.0))
for label, frame, must in (
        ("origin_nan", ((NAN, 0, 0),) + UNIT, True),
        ("s_nan", ((-1, -1, -1), (NAN, 0, 0), (0, 2, 0), (0, 0, 2)), True),
        ("t_inf", ((-1, -1, -1), (2, 0, 0), (0, INF, 0), (0, 0, 2)), True),
        ("edges_1e308", ((-1, -1, -1), (HUGE, 0, 0), (0, HUGE, 0), (0, 0, HUGE)), False),
        ("origin_1e308", ((HUGE, HUGE, HUGE),) + UNIT, False),
        ("origin_-1e308_edges_1e308", ((-HUGE, -HUGE, -HUGE), (HUGE, 0, 0), (0, HUGE, 0), (0, 0, HUGE)), False),
        ("flat_u_zero", ((-1, -1, -1), (2, 0, 0), (0, 2, 0), (0, 0, 0)), True),
        ("flat_coplanar", ((-1, -1, -1), (2, 0, 0), (0, 2, 0), (2, 2, 0)), True),
        ("tiny_1e-300", ((-1, -1, -1), (1e-300, 0, 0), (0, 1e-300, 0), (0, 0, 1e-300)), False)):
    add("voxelize", "voxelize.Frame=" + label,
        lambda f=frame, m=must: run_filter(voxelize(sphere_mesh(), Frame=f), must_error=m, needle="frame"))
add("voxelize", "voxelize.Frame=flat_u_zero,Divisions=0",
    lambda: run_filter(voxelize(sphere_mesh(), Frame=((-1, -1, -1), (2, 0, 0), (0, 2, 0), (0, 0, 0)),
                                Divisions=(0, 4, 4)), must_error=True))
for label, make, must in (
        ("missing", lambda: None, True),
        ("image_data", lambda: _image(None), True),
        ("empty", lambda: vtkPolyData(), False),
        ("one_point", lambda: points_mesh([0.5, 0.5, 0.5]), False),
        ("collinear", lambda: points_mesh([[0, 0, 0], [1, 1, 1], [2, 2, 2]]), False),
        ("nan_point", lambda: mesh_with_point(NAN), False),
        ("inf_point", lambda: mesh_with_point(INF), False),
        ("1e308_point", lambda: mesh_with_point(HUGE), False),
        ("all_nan", lambda: points_mesh(np.full((10, 3), NAN)), False)):
    for mode in ("AXIS_ALIGNED", "PRINCIPAL_AXES"):
        add("voxelize", "voxelize.input=%s,%s" % (label, mode),
            lambda mk=make, m=must, fm=mode: run_filter(
                voxelize(mk(), FrameMode=getattr(vtkffd.vtkFFDVoxelize, fm)), must_error=m))


# vtkFFDBuildLattice --------------------------------------------------------------------------------------------

def build_lattice(grid, basis=Build.TRILINEAR, form=Build.AUTOMATIC):
    algorithm = vtkffd.vtkFFDBuildLattice()
    if grid is not None:
        algorithm.SetInputData(grid)
    algorithm.SetBasis(basis)
    algorithm.SetLatticeForm(form)
    return algorithm


FAR_FRAME = ((10.0, 10.0, 10.0),) + UNIT  # no point of the sphere inside: a voxel grid without active voxels
for basis in range(5):
    for form in range(3):
        for grid_label, divisions, frame in (("normal", (3, 3, 3), None), ("no_active_voxel", (3, 3, 3), FAR_FRAME)):
            add("build_lattice", "build.%s,%s,%s" % (Build.GetBasisAsString(basis), ("AUTOMATIC", "DENSE", "SPARSE")[
                form], grid_label),
                lambda b=basis, f=form, d=divisions, fr=frame: run_filter(build_lattice(voxel_grid(d, fr), b, f)))


def _with_index(change, array_type=VTK_INT):
    """A maker of the voxel grid with its VoxelIndex array changed (see _tuple_array())."""
    return lambda: _tuple_array(voxel_grid(), "cell", "VoxelIndex", change, array_type)


BAD_VOXEL_GRIDS = {  # name: (make, must be an error)
    "VoxelIndex_missing": (_with_index(lambda v: None), True),
    "VoxelIndex_past_divisions": (_with_index(lambda v: _set_middle(v, (100, 0, 0))), True),
    "VoxelIndex_max_int": (_with_index(lambda v: _set_middle(v, (INT_MAX, INT_MAX, INT_MAX))), True),
    "VoxelIndex_negative": (_with_index(lambda v: _set_middle(v, (-1, 0, 0))), True),
    "VoxelIndex_two_components": (_with_index(lambda v: v[:, :2].copy()), True),
    "VoxelIndex_float": (_with_index(lambda v: v.astype(np.float64), None), False),
    "VoxelIndex_short": (_with_index(lambda v: v[:-3].copy()), False),
    "divisions_one": (lambda: _field(voxel_grid(), "FFDDivisions", [1, 1, 1], VTK_INT), True),
    "divisions_zero": (lambda: _field(voxel_grid(), "FFDDivisions", [0, 4, 4], VTK_INT), True),
    "divisions_negative": (lambda: _field(voxel_grid(), "FFDDivisions", [-4, 4, 4], VTK_INT), True),
    "divisions_2000": (lambda: _field(voxel_grid(), "FFDDivisions", [2000, 2000, 2000], VTK_INT), False),
    "frame_nan": (lambda: _field(voxel_grid(), "FFDFrame", [NAN] * 12, None), True),
    "frame_flat": (lambda: _field(voxel_grid(), "FFDFrame", [0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 0], None), True),
    "frame_1e308": (lambda: _field(voxel_grid(), "FFDFrame", [0, 0, 0] + [HUGE] * 9, None), False),
    "no_field_data": (lambda: _strip_field_data(voxel_grid()), True),
    "image_data": (lambda: _image(None), True),
    "empty_grid": (lambda: vtkUnstructuredGrid(), False),
    "missing": (lambda: None, True),
}
for grid_label, (make, must) in BAD_VOXEL_GRIDS.items():
    for basis, form in ((Build.BERNSTEIN, Build.DENSE), (Build.TRILINEAR, Build.SPARSE),
                        (Build.CUBIC_BSPLINE, Build.DENSE)):
        add("build_lattice", "build.%s,%s,voxels=%s" % (Build.GetBasisAsString(basis), ("DENSE", "SPARSE")[
            form - 1], grid_label), lambda mk=make, m=must, b=basis, f=form: run_filter(build_lattice(mk(), b, f),
                                                                                        must_error=m))
add("build_lattice", "build.TRILINEAR,DENSE,Divisions=2000^3",
    lambda: run_filter(build_lattice(voxel_grid((2000, 2000, 2000)), Build.TRILINEAR, Build.DENSE),
                       must_error=True))
add("build_lattice", "build.BERNSTEIN,DENSE,Divisions=100^3",
    lambda: run_filter(build_lattice(voxel_grid((100, 100, 100)), Build.BERNSTEIN, Build.DENSE)))
add("build_lattice", "build.CUBIC_BSPLINE,SPARSE,Divisions=max,4,4",
    lambda: run_filter(build_lattice(voxel_grid((INT_MAX, 4, 4)), Build.CUBIC_BSPLINE, Build.SPARSE)))


# vtkFFDBuildTetrahedralLattice ---------------------------------------------------------------------------------

def tetrahedral(mesh, **settings):
    algorithm = vtkffd.vtkFFDBuildTetrahedralLattice()
    if mesh is not None:
        algorithm.SetInputData(mesh)
    return configure(algorithm, settings)


for value in (NAN, INF, -1.0, HUGE):
    add("tetrahedral", "tetra.Padding=%r" % value,
        lambda v=value: run_filter(tetrahedral(sphere_mesh(), Padding=v), needle="Padding"))
# The most levels over a cube's corners (12 hull triangles, 12 * 8^5 tetrahedra: a fraction of a second; over the
# sphere, 20 times more).
CUBE = np.array([[i, j, k] for k in (0, 1) for j in (0, 1) for i in (0, 1)], dtype=np.float64)
for levels in (5, INT_MAX, -1):
    add("tetrahedral", "tetra.SubdivisionLevels=%d" % levels,
        lambda v=levels: run_filter(tetrahedral(points_mesh(CUBE), SubdivisionLevels=v), needle="SubdivisionLevels"))
add("tetrahedral", "tetra.SubdivisionLevels=5,Padding=nan",
    lambda: run_filter(tetrahedral(points_mesh(CUBE), SubdivisionLevels=5, Padding=NAN), needle="Padding"))
for label, make, must in (
        ("missing", lambda: None, True),
        ("image_data", lambda: _image(None), True),
        ("empty", lambda: vtkPolyData(), False),
        ("one_point", lambda: points_mesh([0.5, 0.5, 0.5]), False),
        ("three_points", lambda: points_mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]]), False),
        ("coplanar", lambda: points_mesh(np.c_[np.random.default_rng(1).uniform(size=(50, 2)), np.zeros(50)]), False),
        ("nan_point", lambda: mesh_with_point(NAN), False),
        ("inf_point", lambda: mesh_with_point(INF), False),
        ("1e308_point", lambda: mesh_with_point(HUGE), False),
        ("all_nan", lambda: points_mesh(np.full((10, 3), NAN)), False)):
    add("tetrahedral", "tetra.input=" + label, lambda mk=make, m=must: run_filter(tetrahedral(mk()), must_error=m))


# vtkFFDDeform --------------------------------------------------------------------------------------------------

POLICIES = ("KEEP_POSITION", "CLAMP_TO_EDGE", "EXTRAPOLATE")
BACKENDS = ("AUTOMATIC", "CPU", "CUDA")


def deform(mesh, lattice_data, policy=0, backend=1, normals=True, jacobian=True):
    algorithm = vtkffd.vtkFFDDeform()
    if mesh is not None:
        algorithm.SetInputData(mesh)
    if lattice_data is not None:
        algorithm.SetLatticeData(lattice_data)
    algorithm.SetOutsidePolicy(policy)
    algorithm.SetBackend(backend)
    algorithm.SetTransformNormals(normals)
    algorithm.SetComputeJacobianDeterminant(jacobian)
    return algorithm


def finite_arrays(algorithm, names_=("Normals", "JacobianDeterminant")):
    """An extra check: the output's point arrays `names_` (those present) are finite."""
    def check():
        data = algorithm.GetOutputDataObject(0)
        for name in names_:
            array = data.GetPointData().GetArray(name)
            if array is not None and not np.isfinite(vtk_to_numpy(array)).all():
                return "silent corruption: the output's %s array is not finite, no error" % name
        return None
    return check


def run_deform(algorithm, must_error=False, needle=None, extra=None):
    return run_filter(algorithm, must_error, needle, extra=[finite_arrays(algorithm), extra])


# A mesh larger than the lattices' sphere, so that points lie outside and every OutsidePolicy has work.
for kind in ("dense_bernstein", "sparse_trilinear", "sparse_bspline", "dense_tricubic", "tetra"):
    for policy in range(3):
        for backend in range(3):
            for lattice_label, make in (("moved", lambda k: lattice(k)),
                                        ("nan_points", lambda k: bad_lattice(k, "nan_points"))):
                add("deform", "deform.%s,%s,%s,%s" % (kind, POLICIES[policy], BACKENDS[backend], lattice_label),
                    lambda k=kind, p=policy, b=backend, mk=make: run_deform(deform(sphere_mesh(0.7), mk(k), p, b)))
    add_lattice_cases("deform", "deform", [kind], lambda data: deform(sphere_mesh(0.7), data),
                      lambda algorithm, must, needle, extra: run_deform(algorithm, must, needle, extra),
                      skip=("nan_points",))
for label, make in (("missing", lambda: None), ("image_data", lambda: _image(None))):
    add("deform", "deform.input0=" + label,
        lambda mk=make: run_deform(deform(mk(), lattice("sparse_bspline")), must_error=True))
add("deform", "deform.input0=empty", lambda: run_deform(deform(vtkPolyData(), lattice("sparse_bspline"))))
add("deform", "deform.tetra,lattice=one_node_1e308",
    lambda: run_deform(deform(sphere_mesh(0.7), _every_fifth(lattice("tetra"), HUGE))))


# vtkFFDInverseDeform -------------------------------------------------------------------------------------------

def deformed_mesh(kind):
    algorithm = deform(sphere_mesh(), lattice(kind), normals=False, jacobian=False)
    algorithm.Update()
    return copy_of(algorithm.GetOutput())


def inverse(mesh, lattice_data, **settings):
    algorithm = vtkffd.vtkFFDInverseDeform()
    if mesh is not None:
        algorithm.SetInputData(mesh)
    if lattice_data is not None:
        algorithm.SetLatticeData(lattice_data)
    return configure(algorithm, settings)


for kind in ("dense_bernstein", "sparse_bspline", "tetra"):
    for settings in ({"Tolerance": NAN}, {"Tolerance": INF}, {"Tolerance": 0.0}, {"Tolerance": -1.0},
                     {"MaximumNumberOfIterations": -1}, {"MaximumNumberOfIterations": 0},
                     {"Tolerance": 0.0, "MaximumNumberOfIterations": INT_MAX}):
        add("inverse", "inverse.%s,%s" % (kind, ",".join("%s=%r" % kv for kv in settings.items())),
            lambda k=kind, s=settings: run_filter(inverse(deformed_mesh(k), lattice(k), **s),
                                                  needle=tuple(s)))
    add_lattice_cases("inverse", "inverse", [kind], lambda data, k=kind: inverse(deformed_mesh(k), data))
for label, make in (("missing", lambda: None), ("image_data", lambda: _image(None))):
    add("inverse", "inverse.input0=" + label,
        lambda mk=make: run_filter(inverse(mk(), lattice("sparse_bspline")), must_error=True))


# vtkFFDRefineLattice -------------------------------------------------------------------------------------------

def refine(lattice_data, levels=1):
    algorithm = vtkffd.vtkFFDRefineLattice()
    if lattice_data is not None:
        algorithm.SetInputData(lattice_data)
    algorithm.SetLevels(levels)
    return algorithm


# Levels 16 on the 4^3 lattices is the issue's case: 4 * 2^16 control points an axis, an error before allocating.
for kind in ("dense_bernstein", "dense_trilinear", "sparse_trilinear", "sparse_bspline", "dense_tricubic",
             "tetra"):
    for levels in (16, 8, -1):
        add("refine", "refine.%s,Levels=%d" % (kind, levels),
            lambda k=kind, n=levels: run_filter(refine(lattice(k), n), must_error=n == 16))
    add_lattice_cases("refine", "refine", [kind], refine)


# vtkFFDCoarsenLattice ------------------------------------------------------------------------------------------

def coarsen(lattice_data, mesh, deformed=None, **settings):
    algorithm = vtkffd.vtkFFDCoarsenLattice()
    if lattice_data is not None:
        algorithm.SetInputData(lattice_data)
    if mesh is not None:
        algorithm.SetMeshData(mesh)
    if deformed is not None:
        algorithm.SetDeformedMeshData(deformed)
    return configure(algorithm, settings)


def run_coarsen(algorithm, must_error=False, needle=None, extra=None):
    def residuals():
        values = (algorithm.GetResidualRMS(), algorithm.GetMaximumResidual())
        return None if np.isfinite(values).all() else "silent corruption: residuals %r, no error" % (values,)
    return run_filter(algorithm, must_error, needle, extra=[residuals, extra])


for kind in ("sparse_bspline", "dense_trilinear"):
    # 100000^3 voxels: a sparse output holds the active ones only, a dense one cannot be allocated.
    for divisions, must in (((0, 0, 0), False), ((-1, -1, -1), False), ((0, 4, -1), False),
                            ((INT_MAX,) * 3, True), ((100000,) * 3, kind.startswith("dense")),
                            ((INT_MAX, 1, 1), False)):
        add("coarsen", "coarsen.%s,Divisions=%s" % (kind, divisions),
            lambda k=kind, d=divisions, m=must: run_coarsen(coarsen(lattice(k), sphere_mesh(), Divisions=d),
                                                            must_error=m, needle="Divisions"))
    for value in (NAN, INF, -1.0, 0.0):
        add("coarsen", "coarsen.%s,Regularization=%r" % (kind, value),
            lambda k=kind, v=value: run_coarsen(coarsen(lattice(k), sphere_mesh(), Regularization=v),
                                                needle="Regularization"))
    for label, make_mesh, make_deformed, must in (
            ("mesh=nan_point", lambda: mesh_with_point(NAN), lambda: None, False),
            ("mesh=inf_point", lambda: mesh_with_point(INF), lambda: None, False),
            ("mesh=all_nan", lambda: points_mesh(np.full((10, 3), NAN)), lambda: None, False),
            ("mesh=missing", lambda: None, lambda: None, True),
            ("mesh=image_data", lambda: _image(None), lambda: None, True),
            ("mesh=empty", lambda: vtkPolyData(), lambda: None, True),
            ("mesh=outside_the_frame", lambda: points_mesh(np.full((10, 3), 50.0)), lambda: None, True),
            ("deformed=fewer_points", sphere_mesh, lambda: points_mesh(vtk_to_numpy(
                sphere_mesh().GetPoints().GetData())[:-5]), True),
            ("deformed=more_points", sphere_mesh, lambda: points_mesh(np.r_[vtk_to_numpy(
                sphere_mesh().GetPoints().GetData()), np.zeros((5, 3))]), True),
            ("deformed=nan_point", sphere_mesh, lambda: mesh_with_point(NAN), False),
            ("deformed=image_data", sphere_mesh, lambda: _image(None), True)):
        add("coarsen", "coarsen.%s,%s" % (kind, label),
            lambda k=kind, mm=make_mesh, md=make_deformed, m=must: run_coarsen(coarsen(lattice(k), mm(), md()),
                                                                                must_error=m))
    add("coarsen", "coarsen.%s,Basis=BERNSTEIN,Divisions=60^3" % kind,
        lambda k=kind: run_coarsen(coarsen(lattice(k), sphere_mesh(), Basis=0, Divisions=(60, 60, 60))))
add_lattice_cases("coarsen", "coarsen", ("sparse_bspline", "dense_trilinear", "dense_bernstein", "tetra"),
                  lambda data: coarsen(data, sphere_mesh()),
                  lambda algorithm, must, needle, extra: run_coarsen(algorithm, must, needle, extra))


# vtkFFDBuildDetailLattice --------------------------------------------------------------------------------------

def detail(lattice_data, selected=None, threshold=None):
    algorithm = vtkffd.vtkFFDBuildDetailLattice()
    if lattice_data is not None:
        algorithm.SetInputData(lattice_data)
    if selected is not None:
        array = numpy_to_vtk(np.asarray(selected, dtype=np.int32), deep=True, array_type=VTK_INT)
        algorithm.SetSelectedVoxels(array)
        algorithm._selected = array  # kept alive with the filter
    if threshold is not None:
        algorithm.SetSecondDerivativeThreshold(threshold)
    return algorithm


for kind in ("sparse_bspline", "sparse_trilinear"):
    for value in (NAN, INF, HUGE, -1.0):
        add("detail", "detail.%s,SecondDerivativeThreshold=%r" % (kind, value),
            lambda k=kind, v=value: run_filter(detail(lattice(k), threshold=v), needle="SecondDerivativeThreshold"))
    for label, selected, must in (("past_divisions", [[100, 0, 0]], True), ("negative", [[-1, 0, 0]], True),
                                  ("max_int", [[INT_MAX] * 3], True), ("two_components", [[1, 1], [2, 2]], True),
                                  ("duplicates", [[1, 1, 1]] * 50, False), ("empty", np.zeros((0, 3)), False)):
        add("detail", "detail.%s,SelectedVoxels=%s" % (kind, label),
            lambda k=kind, s=selected, m=must: run_filter(detail(lattice(k), s), must_error=m,
                                                          needle="Selected voxel" if m else None))
    add_lattice_cases("detail", "detail", [kind], lambda data: detail(data, [[1, 1, 1], [2, 1, 1]], threshold=1e-3))
add("detail", "detail.dense_bernstein", lambda: run_filter(detail(lattice("dense_bernstein"), [[1, 1, 1]])))
add("detail", "detail.tetra", lambda: run_filter(detail(lattice("tetra"), [[1, 1, 1]])))


# vtkFFDDeformBlocks --------------------------------------------------------------------------------------------

def blocks(mesh, lattices, composition=0, backend=1):
    algorithm = vtkffd.vtkFFDDeformBlocks()
    if mesh is not None:
        algorithm.SetInputData(mesh)
    for data in lattices:
        if data is not None:
            algorithm.AddLatticeData(data)
    algorithm.SetComposition(composition)
    algorithm.SetBackend(backend)
    return algorithm


for composition in (0, 1):
    name = ("BLEND", "ADD")[composition]
    add("blocks", "blocks.%s,no_lattices" % name,
        lambda c=composition: run_filter(blocks(sphere_mesh(0.7), [], c)))
    # A good lattice and a bad one (a missing one is no lattice: "no_lattices").
    add_lattice_cases("blocks", "blocks." + name, ("dense_tricubic", "sparse_bspline", "tetra"),
                      lambda data, c=composition: blocks(sphere_mesh(0.7), [lattice("sparse_trilinear"), data], c),
                      skip=("missing",))
    for backend in range(3):
        add("blocks", "blocks.%s,%s,two_nan_lattices" % (name, BACKENDS[backend]),
            lambda c=composition, b=backend: run_filter(blocks(sphere_mesh(0.7), [
                bad_lattice("sparse_bspline", "nan_points"), bad_lattice("dense_bernstein", "nan_points")], c, b)))
for label, make in (("missing", lambda: None), ("image_data", lambda: _image(None))):
    add("blocks", "blocks.input0=" + label,
        lambda mk=make: run_filter(blocks(mk(), [lattice("sparse_bspline")]), must_error=True))


# vtkFFDDirectManipulation --------------------------------------------------------------------------------------

def direct(lattice_data, mesh, ids, targets, regularization=None):
    algorithm = vtkffd.vtkFFDDirectManipulation()
    if lattice_data is not None:
        algorithm.SetInputData(lattice_data)
    if mesh is not None:
        algorithm.SetMeshData(mesh)
    if ids is not None:
        algorithm.SetTargetPointIds(numpy_to_vtkIdTypeArray(np.asarray(ids, dtype=np.int64).reshape(-1), deep=True))
    if targets is not None:
        positions = vtkPoints()
        positions.SetDataTypeToDouble()
        positions.SetData(numpy_to_vtk(np.asarray(targets, dtype=np.float64).reshape(-1, 3), deep=True))
        algorithm.SetTargetPositions(positions)
    if regularization is not None:
        algorithm.SetRegularization(regularization)
    return algorithm


def pulled(ids, by=0.02):
    return vtk_to_numpy(sphere_mesh().GetPoints().GetData())[ids].astype(np.float64) + by


def half_frame_lattice(kind):
    """A lattice over the half x > 0.1 of the sphere (explicit frame): points with x < 0 are outside it."""
    basis, form, _ = LATTICES[kind]
    grid = voxel_grid((2, 2, 2), ((0.1, -0.6, -0.6), (0.6, 0, 0), (0, 1.2, 0), (0, 0, 1.2)))
    build = build_lattice(grid, basis, form)
    build.Update()
    return copy_of(build.GetOutput())


ids = [0, 60]  # the mesh points the direct manipulation cases pull
for kind in ("dense_tricubic", "sparse_bspline", "sparse_trilinear"):
    for value in (NAN, INF, HUGE, -1.0):
        add("direct", "direct.%s,Regularization=%r" % (kind, value),
            lambda k=kind, v=value: run_filter(direct(lattice(k), sphere_mesh(), ids, pulled(ids), v),
                                               needle="Regularization"))
    n = sphere_mesh().GetNumberOfPoints()
    for label, bad_ids, targets, must in (
            ("id=point_count", [0, n], pulled([0, 1]), True),
            ("id=1e9", [10**9], pulled([0]), True),
            ("id=-1", [-1, 0], pulled([0, 1]), True),
            ("id=-2^63", [-2**63], pulled([0]), True),
            ("more_ids_than_targets", [0, 1, 2], pulled([0]), True),
            ("more_targets_than_ids", [0], pulled([0, 1, 2]), True),
            ("ids_without_targets", [0, 1], None, True),
            ("targets_nan", ids, np.full((2, 3), NAN), False),
            ("targets_inf", ids, np.full((2, 3), INF), False),
            ("targets_1e308", ids, np.full((2, 3), HUGE), False),
            ("no_targets", None, None, False),
            ("same_id_two_targets", [0, 0], np.r_[pulled([0]), pulled([0], -0.02)], False)):
        add("direct", "direct.%s,%s" % (kind, label),
            lambda k=kind, i=bad_ids, t=targets, m=must: run_filter(direct(lattice(k), sphere_mesh(), i, t),
                                                                    must_error=m))
    add("direct", "direct.%s,targets_all_outside" % kind,
        lambda k=kind: run_filter(direct(half_frame_lattice(k), sphere_mesh(), [0, 1, 2], pulled([0, 1, 2]))))
    add("direct", "direct.%s,target_on_nan_mesh_point" % kind,
        lambda k=kind: run_filter(direct(lattice(k), mesh_with_point(NAN, 5), [5], pulled([5]))))
    add("direct", "direct.%s,every_target_on_nan_mesh_point" % kind,
        lambda k=kind: run_filter(direct(lattice(k), points_mesh(np.full((4, 3), NAN)), [0, 1, 2, 3],
                                         np.zeros((4, 3)))))
    for label, make, must in (("mesh=missing", lambda: None, True), ("mesh=image_data", lambda: _image(None), True),
                              ("mesh=empty", lambda: vtkPolyData(), True)):
        add("direct", "direct.%s,%s" % (kind, label),
            lambda k=kind, mk=make, m=must: run_filter(direct(lattice(k), mk(), ids, pulled(ids)), must_error=m))
    add_lattice_cases("direct", "direct", [kind], lambda data: direct(data, sphere_mesh(), ids, pulled(ids)))
add("direct", "direct.tetra", lambda: run_filter(direct(lattice("tetra"), sphere_mesh(), [0], pulled([0]))))


# vtkFFDLatticeDynamics, vtkFFDMagneticSphere, vtkFFDSimulateLattice --------------------------------------------

def dynamics_over(lattice_data, mesh=None):
    dynamics = vtkffd.vtkFFDLatticeDynamics()
    dynamics.SetLattice(lattice_data)
    dynamics.SetMesh(sphere_mesh() if mesh is None else mesh)
    return dynamics


def step(dynamics, steps=3, must_error=False, needle=None):
    return run_call(dynamics, lambda: dynamics.Step(steps), dynamics.GetLattice, must_error, needle)


# setter: [(value, must be an error)]: every double setting NaN, inf, negative (and zero where it must be > 0).
DYNAMICS_SETTINGS = {
    "TimeStep": [(NAN, True), (INF, True), (-1 / 60, True), (0.0, True), (HUGE, False)],
    "TotalMass": [(NAN, True), (INF, True), (-1.0, True), (0.0, True), (1e-300, False)],
    "MinimumMassFraction": [(NAN, True), (INF, True), (-0.5, True), (0.0, True), (2.0, True)],
    "SpringStiffness": [(NAN, True), (INF, True), (-1.0, True), (HUGE, False)],
    "SpringDamping": [(NAN, True), (INF, True), (-1.0, True), (HUGE, False)],
    "CoreStiffness": [(NAN, True), (INF, True), (-1.0, True), (HUGE, False)],
    "Gravity": [((NAN, 0, 0), True), ((0, INF, 0), True), ((0, -9.81, 0), False), ((0, -HUGE, 0), False)],
}


def simulate(lattice_data, mesh="sphere", end_time=None, steps_limit=None):
    algorithm = vtkffd.vtkFFDSimulateLattice()
    if lattice_data is not None:
        algorithm.SetInputData(lattice_data)
    if isinstance(mesh, str):
        algorithm.SetMeshData(sphere_mesh())
    elif mesh is not None:
        algorithm.SetInputData(1, mesh)  # SetMeshData() takes only a vtkPointSet: the pipeline's way for others
    if end_time is not None:
        algorithm.SetEndTime(end_time)
    if steps_limit is not None:
        algorithm.SetMaximumNumberOfSteps(steps_limit)
    return algorithm


def run_simulate(algorithm, time=0.05, must_error=False, needle=None, extra=None):
    """Runs the filter at `time`, its Dynamics object's errors counted as its own."""
    return run_filter(algorithm, must_error, needle, time=time, others=[algorithm.GetDynamics()], extra=extra)


def _with_dynamics(algorithm, change):
    change(algorithm.GetDynamics())
    return algorithm


for setter, values in DYNAMICS_SETTINGS.items():
    for value, must in values:
        label = "%s=%r" % (setter, value)
        add("dynamics", "dynamics.Step,sparse_trilinear," + label,
            lambda s=setter, v=value, m=must: step(configure(dynamics_over(lattice("sparse_trilinear", False)),
                                                             {s: v}), must_error=m, needle=s))
        add("simulate", "simulate.sparse_trilinear,Dynamics." + label,
            lambda s=setter, v=value, m=must: run_simulate(_with_dynamics(
                simulate(lattice("sparse_trilinear", False)), lambda d: configure(d, {s: v})), must_error=m, needle=s))
add("dynamics", "dynamics.Step,dense_trilinear,TimeStep=nan",
    lambda: step(configure(dynamics_over(lattice("dense_trilinear", False)), {"TimeStep": NAN}), must_error=True))
add("dynamics", "dynamics.Step,tetra,SpringStiffness=inf",
    lambda: step(configure(dynamics_over(lattice("tetra", False)), {"SpringStiffness": INF}), must_error=True))


def _with_sphere(dynamics, **settings):
    sphere = vtkffd.vtkFFDMagneticSphere()
    sphere.SetRadius(0.2)
    sphere.SetStrength(5.0)
    for key, value in settings.items():
        if key == "Path":
            path = vtkPoints()
            for p in value:
                path.InsertNextPoint(*p)
            sphere.SetPath(path)
        else:
            set_value(sphere, key, value)
    dynamics.AddMagneticSphere(sphere)
    return dynamics


# (settings, must be an error, the setting an error names): an infinite or huge value is not wrong in itself, only
# where its pull makes the positions non-finite, which the step says.
SPHERE_SETTINGS = [
    ({"Center": (NAN, 0, 0)}, True, "Center"), ({"Center": (0, INF, 0)}, True, "Center"),
    ({"Center": (HUGE, 0, 0)}, False, None),
    ({"Radius": NAN}, True, "Radius"), ({"Radius": INF}, False, None), ({"Radius": 0.0}, True, "Radius"),
    ({"Radius": -1.0}, True, "Radius"),
    ({"Strength": NAN}, True, "Strength"), ({"Strength": INF}, False, None),
    ({"Strength": -1.0}, True, "Strength"), ({"Strength": HUGE}, False, None),
    ({"Falloff": NAN}, True, "Falloff"), ({"Falloff": -1.0}, True, "Falloff"), ({"Falloff": INF}, False, None),
    ({"Range": NAN}, True, "Range"), ({"Range": -1.0}, True, "Range"),
    ({"Path": [(0, 0, 0)]}, True, "Path"), ({"Path": [(0, 0, 0), (NAN, 0, 0)]}, True, "Path"),
    ({"Path": [(0, 0, 0), (1, 0, 0)], "Period": 0.0}, True, "Period"),
    ({"Path": [(0, 0, 0), (1, 0, 0)], "Period": NAN}, True, "Period"),
    ({"Path": [(0, 0, 0), (1, 0, 0)], "Period": -1.0}, True, "Period"),
    ({"Path": [(0, 0, 0), (0, 0, 0)], "Period": 1.0}, False, None),
]
for settings, must, needle in SPHERE_SETTINGS:
    label = ",".join("%s=%r" % kv for kv in settings.items())
    add("dynamics", "dynamics.Step,MagneticSphere." + label,
        lambda s=settings, m=must, n=needle: step(_with_sphere(dynamics_over(lattice("sparse_trilinear", False)),
                                                               **s), must_error=m, needle=n))
    add("simulate", "simulate.MagneticSphere." + label,
        lambda s=settings, m=must, n=needle: run_simulate(_with_dynamics(simulate(lattice("sparse_trilinear", False)),
                                                                         lambda d: _with_sphere(d, **s)),
                                                          must_error=m, needle=n))


def _impulse(point_id, impulse, must):
    dynamics = dynamics_over(lattice("sparse_trilinear", False))
    messages = observe(None, [dynamics])
    status = dynamics.ApplyImpulse(point_id, *impulse)
    errors = [text_of(m) for m in messages if text_of(m)]
    if must and status != 0:
        return "no error: ApplyImpulse(%r, %r) before the first Step() returned %r" % (point_id, impulse, status)
    if status == 0 and not errors:
        return "ApplyImpulse returned 0 without a message"
    if status != 0 and errors:
        return "ApplyImpulse returned %r after the error %r" % (status, errors[0][:300])
    return step(dynamics, 2)


for point_id, impulse, must in ((10**6, (1, 0, 0), True), (-1, (1, 0, 0), True), (0, (NAN, 0, 0), True),
                                (0, (0, INF, 0), True), (0, (HUGE, 0, 0), False)):
    add("dynamics", "dynamics.ApplyImpulse(%r,%r)" % (point_id, impulse),
        lambda p=point_id, i=impulse, m=must: _impulse(p, i, m))


def _pin(point_id, target):
    dynamics = dynamics_over(lattice("sparse_trilinear", False))
    dynamics.PinPoint(point_id, *target)
    return dynamics


for point_id, target, must in ((10**6, (0, 0, 0), True), (-1, (0, 0, 0), True), (0, (NAN, 0, 0), True),
                               (0, (INF, 0, 0), True), (0, (HUGE, 0, 0), False)):
    add("dynamics", "dynamics.PinPoint(%r,%r)" % (point_id, target),
        lambda p=point_id, t=target, m=must: step(_pin(p, t), must_error=m))


def _collider(make):
    dynamics = dynamics_over(lattice("sparse_trilinear", False))
    collider = make()
    dynamics.AddCollider(collider)
    return dynamics


def _plane(origin, normal):
    plane = vtkPlane()
    plane.SetOrigin(*origin)
    plane.SetNormal(*normal)
    return plane


def _ball(center, radius):
    ball = vtkSphere()
    ball.SetCenter(*center)
    ball.SetRadius(radius)
    return ball


for label, make in (("plane_origin_nan", lambda: _plane((NAN, 0, 0), (0, 1, 0))),
                    ("plane_normal_nan", lambda: _plane((0, 0, 0), (NAN, 1, 0))),
                    ("plane_normal_zero", lambda: _plane((0, 0, 0), (0, 0, 0))),
                    ("plane_origin_1e308", lambda: _plane((0, HUGE, 0), (0, 1, 0))),
                    ("sphere_radius_nan", lambda: _ball((0, 0, 0), NAN)),
                    ("sphere_radius_1e308", lambda: _ball((0, 0, 0), HUGE))):
    add("dynamics", "dynamics.Step,collider=" + label, lambda mk=make: step(_collider(mk)))

# The simulation reads the lattice's cells and points but not its RestPosition (it starts at rest from the points).
SIMULATION_KINDS = ("sparse_trilinear", "dense_trilinear", "tetra")
add_lattice_cases("simulate", "simulate", SIMULATION_KINDS, simulate, reads=("ids", "input"), time=0.05,
                  run=lambda algorithm, must, needle, extra: run_simulate(algorithm, 0.05, must, needle, extra))
for kind in SIMULATION_KINDS:
    for variant in variants_for(kind):
        if BAD_LATTICES[variant][2] != "input":  # SetLattice() takes a vtkPointSet: "no_lattice" below
            add("dynamics", "dynamics.Step,%s,lattice=%s" % (kind, variant),
                lambda k=kind, v=variant: step(dynamics_over(bad_lattice(k, v)),
                                               must_error=BAD_LATTICES[v][2] == "ids"))
add("dynamics", "dynamics.Step,no_lattice",
    lambda: step(vtkffd.vtkFFDLatticeDynamics(), must_error=True, needle="lattice"))
add("dynamics", "dynamics.Step,mesh=nan_point",
    lambda: step(dynamics_over(lattice("sparse_trilinear", False), mesh_with_point(NAN))))
add("dynamics", "dynamics.Step(-1)", lambda: step(dynamics_over(lattice("sparse_trilinear", False)), -1))

for value, must in ((NAN, True), (INF, True), (-1.0, True), (HUGE, False)):
    add("simulate", "simulate.EndTime=%r" % value,
        lambda v=value, m=must: run_simulate(simulate(lattice("sparse_trilinear", False), end_time=v), must_error=m,
                                             needle="EndTime"))
for value in (0, -1):
    add("simulate", "simulate.MaximumNumberOfSteps=%d" % value,
        lambda v=value: run_simulate(simulate(lattice("sparse_trilinear", False), steps_limit=v), must_error=True,
                                     needle="MaximumNumberOfSteps"))
add("simulate", "simulate.time=1e5,EndTime=1e5",
    lambda: run_simulate(simulate(lattice("sparse_trilinear", False), end_time=1e5), time=1e5, must_error=True,
                         needle="MaximumNumberOfSteps"))
add("simulate", "simulate.time=1e5,EndTime=10",
    lambda: run_simulate(simulate(lattice("sparse_trilinear", False), end_time=10.0), time=1e5))
for value in (NAN, INF, -INF, -1.0):
    add("simulate", "simulate.time=%r" % value,
        lambda v=value: run_simulate(simulate(lattice("sparse_trilinear", False)), time=v))


def _no_dynamics():
    algorithm = simulate(lattice("sparse_trilinear", False))
    algorithm.SetDynamics(None)
    return run_filter(algorithm, must_error=True, needle="Dynamics", time=0.05)


add("simulate", "simulate.Dynamics=None", _no_dynamics)


for label, make in (("missing", lambda: None), ("image_data", lambda: _image(None)),
                    ("nan_point", lambda: mesh_with_point(NAN))):
    add("simulate", "simulate.mesh=" + label,
        lambda mk=make, l=label: run_simulate(simulate(lattice("sparse_trilinear", False), mesh=mk()),
                                              must_error=l == "image_data"))
for label, make in (("missing", lambda: None), ("image_data", lambda: _image(None))):
    add("simulate", "simulate.input0=" + label,
        lambda mk=make: run_simulate(simulate(mk()), must_error=True))


def _sphere_queries():
    """GetCenterAt() and GetAcceleration() at NaN/inf times and points: no crash (the values are not judged)."""
    sphere = vtkffd.vtkFFDMagneticSphere()
    path = vtkPoints()
    path.InsertNextPoint(0, 0, 0)
    path.InsertNextPoint(1, 0, 0)
    sphere.SetPath(path)
    sphere.SetPeriod(0.0)
    center, acceleration = [0.0] * 3, [0.0] * 3
    for t in (NAN, INF, -INF, 1e300):
        sphere.GetCenterAt(t, center)
        sphere.GetAcceleration((NAN, 0, 0), t, acceleration)
    sphere.SetPath(None)
    sphere.GetAccelerationAround((0, 0, 0), (0, 0, 0), acceleration)
    return None


add("dynamics", "MagneticSphere.queries_at_nan", _sphere_queries)


# vtkFFDVDBReader, vtkFFDVDBWriter ------------------------------------------------------------------------------

def folder():
    """The files' folder: the parent's temporary one (it removes it), or one of this child's own."""
    if not os.environ.get(FOLDER_VARIABLE):
        os.environ[FOLDER_VARIABLE] = tempfile.mkdtemp(prefix="voxelffd-bad-settings-")
    return os.environ[FOLDER_VARIABLE]


def a_file(name, content):
    path = os.path.join(folder(), name)
    with open(path, "wb") as stream:
        stream.write(content)
    return path


def valid_vdb():
    def make():
        path = os.path.join(folder(), "valid.vdb")
        writer = vtkffd.vtkFFDVDBWriter()
        writer.SetInputData(lattice("sparse_bspline"))
        writer.SetFileName(path)
        writer.Write()
        with open(path, "rb") as stream:
            return stream.read()
    return cached("vdb", make)


def read_vdb(path):
    reader = vtkffd.vtkFFDVDBReader()
    if path is not None:
        reader.SetFileName(path)
    return reader


def flipped(content, where):
    data = bytearray(content)
    data[where] ^= 0xFF
    return bytes(data)


for label, make, must in (
        ("missing_file", lambda: os.path.join(folder(), "no such file.vdb"), True),
        ("empty_file", lambda: a_file("empty.vdb", b""), True),
        ("text_file", lambda: a_file("text.vdb", b"this is not a .vdb file\n" * 20), True),
        ("directory", folder, True),
        ("no_file_name", lambda: None, True),
        ("valid", lambda: a_file("copy.vdb", valid_vdb()), False),
        ("cut_to_4096_bytes", lambda: a_file("cut.vdb", valid_vdb()[:4096]), True),
        ("cut_to_half", lambda: a_file("half.vdb", valid_vdb()[:len(valid_vdb()) // 2]), True),
        # Without its last byte the file has no trailer of vtkFFDVDBWriter's: a .vdb of another writer, whose
        # grids OpenVDB reads whole (what follows them is not read).
        ("last_byte_missing", lambda: a_file("short.vdb", valid_vdb()[:-1]), False),
        ("byte_flipped_at_100", lambda: a_file("flip100.vdb", flipped(valid_vdb(), 100)), True),
        ("byte_flipped_in_the_middle", lambda: a_file("flipmid.vdb", flipped(valid_vdb(), len(valid_vdb()) // 2)),
         True),
        ("header_then_zeros", lambda: a_file("zeros.vdb", valid_vdb()[:64] + bytes(100000)), True)):
    add("vdb", "vdb_reader." + label, lambda mk=make, m=must: run_filter(read_vdb(mk()), must_error=m))


def write_vdb(data, path, must_error=False, same_as=None):
    """Writes `data` to `path`: an error and Write() 0, or success (which must not be, with `must_error`; which
    must write what the file `same_as` holds, read back, where given: the files differ by their headers' ids)."""
    writer = vtkffd.vtkFFDVDBWriter()
    if data is not None:
        writer.SetInputData(data)
    if path is not None:
        writer.SetFileName(path)
    messages = observe(writer)
    status = writer.Write()
    errors = [text_of(m) for m in messages if not any(g in m for g in GENERIC)]
    if errors:
        return None if status == 0 else "Write() returned %r after the error %r" % (status, errors[0][:300])
    if messages or status == 0:
        return "failed without a message"
    if must_error:
        return "no error: Write() returned %r" % status
    if same_as is not None:
        written, intact = read_vdb(path), read_vdb(same_as)
        written.Update()
        intact.Update()
        if not all(np.array_equal(a, b) for a, b in zip(output_parts(written), output_parts(intact))):
            return "silent change: no error, and the file holds another lattice than the intact one's"
    return None


for label, make_path, must in (
        ("unwritable_folder", lambda: "/nonexistent-folder/voxelffd/lattice.vdb", True),
        ("path_is_a_directory", folder, True),
        ("path_under_a_file", lambda: os.path.join(a_file("plain", b"x"), "lattice.vdb"), True),
        ("no_file_name", lambda: None, True),
        ("empty_file_name", lambda: "", True)):
    add("vdb", "vdb_writer.FileName=" + label,
        lambda mk=make_path, m=must: write_vdb(lattice("sparse_bspline"), mk(), m))
# The writer reads a sparse lattice's points, arrays and LatticeIndex and VoxelIndex, not its cells.
for variant in variants_for("sparse_bspline"):
    category = BAD_LATTICES[variant][2]
    add("vdb", "vdb_writer.lattice=" + variant,
        lambda v=variant, c=category: write_vdb(
            bad_lattice("sparse_bspline", v), os.path.join(folder(), "out.vdb"),
            c == "input" or (c == "ids" and not v.startswith("cell_id")),
            a_file("intact.vdb", valid_vdb()) if c == "index" or v.startswith("cell_id") else None))
add("vdb", "vdb_writer.lattice=dense_trilinear",
    lambda: write_vdb(lattice("dense_trilinear"), os.path.join(folder(), "dense.vdb"), True))
add("vdb", "vdb_writer.lattice=tetra", lambda: write_vdb(lattice("tetra"), os.path.join(folder(), "tetra.vdb"), True))


# vtkFFDControlPoints, vtkFFDCellEdges (the Rendering module's filters) -----------------------------------------

def rendering_filter(name, data, selection=None):
    algorithm = getattr(vtkffd, name)()
    if data is not None:
        algorithm.SetInputData(data)
    if selection is not None:
        algorithm.SetSelection(selection)
    return algorithm


# They show the lattice as it is (a NaN control point as NaN, an empty grid as nothing), so only what they read
# must be valid. vtkFFDCellEdges draws a tetrahedral lattice's cells, and a sparse one's control net from its
# LatticeIndex whatever its values (its cells where the array does not fit): a cell id it does not read leaves its
# output as it is. vtkFFDControlPoints reads the point arrays, not the cells or indices.
for name, reads, same in (
        ("vtkFFDCellEdges", ("missing",), ("cell_id_past_end", "cell_id_negative")),
        ("vtkFFDControlPoints", ("rest_position_short", "image_data", "missing"),
         ("cell_id_past_end", "cell_id_negative", "index"))):
    add_lattice_cases("rendering", name, ("dense_bernstein", "sparse_bspline", "tetra"),
                      lambda data, n=name: rendering_filter(n, data), reads=reads, same=same,
                      skip=("nan_points", "huge_points"))
for selection in range(3):
    add("rendering", "vtkFFDControlPoints.Selection=%d,rest_position_short" % selection,
        lambda s=selection: run_filter(rendering_filter("vtkFFDControlPoints",
                                                        bad_lattice("sparse_bspline", "rest_position_short"), s),
                                       must_error=True))


# vtkFFDDataContract --------------------------------------------------------------------------------------------

def output_window_text(call):
    """Runs call() with VTK's output window captured; returns (call's value, the text written there)."""
    window = vtkStringOutputWindow()
    previous = vtkOutputWindow.GetInstance()  # kept alive by this reference while replaced
    vtkOutputWindow.SetInstance(window)
    try:
        value = call()
    finally:
        vtkOutputWindow.SetInstance(previous)
    return value, window.GetOutput()


def contract_setter(call, needle):
    try:
        _, text = output_window_text(call)
    except (TypeError, ValueError):
        return None  # refused by the wrapping: nothing reached the C++ setter
    if not text.strip():
        return "no error: the call printed nothing"
    return None if names(text, needle) else "error does not name %s: %r" % (needle, text[:300])


def contract_getter(call, expected=False):
    try:
        value, _ = output_window_text(call)
    except (TypeError, ValueError):
        return None
    return None if value == expected else "returned %r, expected %r" % (value, expected)


Contract = vtkffd.vtkFFDDataContract


def grid_with(name, values, array_type=None):
    return _field(vtkStructuredGrid(), name, values, array_type)


for label, call, needle in (
        ("SetFrame(None,zeros)", lambda: Contract.SetFrame(None, [0.0] * 12), "FFDFrame"),
        ("SetDivisions(None,1,2,3)", lambda: Contract.SetDivisions(None, [1, 2, 3]), "FFDDivisions"),
        ("SetBasis(None,1)", lambda: Contract.SetBasis(None, 1), "FFDBasis")):
    add("contract", "contract." + label, lambda c=call, n=needle: contract_setter(c, n))
for label, call, needle in (
        ("SetFrame(grid,None)", lambda: Contract.SetFrame(vtkStructuredGrid(), None), "FFDFrame"),
        ("SetDivisions(grid,None)", lambda: Contract.SetDivisions(vtkStructuredGrid(), None), "FFDDivisions"),
        ("SetFrame(None,None)", lambda: Contract.SetFrame(None, None), "FFDFrame"),
        ("SetDivisions(None,None)", lambda: Contract.SetDivisions(None, None), "FFDDivisions")):
    add("contract", "contract." + label, lambda c=call, n=needle: contract_setter(c, n))


def _getter(kind, data):
    if kind == "Basis":
        value = reference(0)
        return lambda: Contract.GetBasis(data, value)
    return lambda: getattr(Contract, "Get" + kind)(data, [0.0] * 12 if kind == "Frame" else [0] * 3)


for label, kind, make in (
        ("GetFrame(None)", "Frame", lambda: None),
        ("GetDivisions(None)", "Divisions", lambda: None),
        ("GetBasis(None)", "Basis", lambda: None),
        ("GetFrame(no_array)", "Frame", vtkStructuredGrid),
        ("GetFrame(nan)", "Frame", lambda: grid_with("FFDFrame", [NAN] * 12)),
        ("GetFrame(inf)", "Frame", lambda: grid_with("FFDFrame", [INF] + [0.0] * 11)),
        ("GetFrame(3_values)", "Frame", lambda: grid_with("FFDFrame", [0.0] * 3)),
        ("GetDivisions(zero)", "Divisions", lambda: grid_with("FFDDivisions", [0, 1, 1], VTK_INT)),
        ("GetDivisions(negative)", "Divisions", lambda: grid_with("FFDDivisions", [-3, 1, 1], VTK_INT)),
        ("GetDivisions(2_values)", "Divisions", lambda: grid_with("FFDDivisions", [1, 1], VTK_INT)),
        ("GetDivisions(doubles_nan)", "Divisions", lambda: grid_with("FFDDivisions", [NAN, 1.0, 1.0])),
        ("GetDivisions(doubles_1e308)", "Divisions", lambda: grid_with("FFDDivisions", [HUGE, 1.0, 1.0])),
        ("GetBasis(empty_array)", "Basis", lambda: grid_with("FFDBasis", np.zeros(0, np.int32), VTK_INT))):
    add("contract", "contract." + label, lambda k=kind, mk=make: contract_getter(_getter(k, mk())))
add("contract", "contract.SetFrame(grid,nan)_then_GetFrame", lambda: _set_then_get(
    "Frame", [NAN] * 12, [0.0] * 12))
add("contract", "contract.SetDivisions(grid,-1,0,2)_then_GetDivisions", lambda: _set_then_get(
    "Divisions", [-1, 0, 2], [0] * 3))


def _set_then_get(kind, values, buffer):
    grid = vtkStructuredGrid()
    output_window_text(lambda: getattr(Contract, "Set" + kind)(grid, values))
    return contract_getter(lambda: getattr(Contract, "Get" + kind)(grid, buffer))


# ---------------------------------------------------------------------------------------------------------------
# The child: runs the cases of a group from an index, printing each name before it runs.

def run_child(group, start):
    if "LD_PRELOAD" not in os.environ:  # the sanitizers' runtime reserves more address space than any limit
        size = next(int(line.split()[1]) for line in open("/proc/self/status") if line.startswith("VmSize:"))
        limit = size * 1024 + MEMORY_LIMIT
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    vtkOutputWindow.GetInstance().AddObserver("ErrorEvent", WINDOW)
    cases = list(GROUPS[group].items())
    for name, function in cases[start:]:
        del WINDOW.messages[:]
        print("START " + name, flush=True)
        signal.alarm(CASE_SECONDS)  # SIGALRM's default action ends the process: a hang in C++ ends too
        try:
            problem = function()
        except Exception as error:  # noqa: BLE001  (reported as the case's failure)
            problem = "exception in Python: %s: %s" % (type(error).__name__, error)
        signal.alarm(0)
        print("RESULT " + json.dumps([name, problem]), flush=True)
    return 0


# ---------------------------------------------------------------------------------------------------------------
# The parent: runs each group's children and collects {case: problem or None}.

def run_group(group, files):
    """Runs the cases of `group`, a new child after each one that ends its child, with `files` the folder of their
    files; returns {name: problem}."""
    cases = list(GROUPS[group])
    results = {}
    start = 0
    while start < len(cases):
        child = subprocess.run([sys.executable, os.path.abspath(__file__), "--group", group, "--from", str(start)],
                               capture_output=True, text=True, timeout=CASE_SECONDS * (len(cases) - start) + 60,
                               env=dict(os.environ, **{FOLDER_VARIABLE: files}))
        started = None
        for line in child.stdout.splitlines():
            if line.startswith("START "):
                started = line[6:]
            elif line.startswith("RESULT "):
                name, problem = json.loads(line[7:])
                results[name] = problem
                started = None
        if child.returncode == 0 and started is None and len(results) == len(cases):
            break
        missing = [c for c in cases if c not in results]
        # A child that died outside a case: at its start (the next case is named) or at its exit.
        victim = started or (missing[0] if missing else "%s: the child's exit" % group)
        if child.returncode < 0:
            number = -child.returncode
            what = "hang: still running after %d s" % CASE_SECONDS if number == signal.SIGALRM else \
                "crash: %s" % signal.Signals(number).name
        else:
            what = "the child exited with %d" % child.returncode
        # The last lines of its log, less the trivial producers' complaints of the extents of failed requests.
        tail = [line for line in child.stderr.splitlines() if line.strip() and "vtkTrivialProducer" not in line][-3:]
        results[victim] = what + ("; stderr: " + " | ".join(tail)[-400:] if tail else "")
        start = cases.index(victim) + 1 if victim in cases else len(cases)
    return results


RESULTS = {}


def setUpModule():
    # Two children at a time: the cases are small, so the run is bound by the interpreters' starts and the cores.
    with tempfile.TemporaryDirectory(prefix="voxelffd-bad-settings-") as files, ThreadPoolExecutor(2) as pool:
        RESULTS.update(zip(GROUPS, pool.map(lambda group: run_group(group, files), GROUPS)))


class TestBadSettings(unittest.TestCase):
    """One test per group of cases; its failure lists every failing case with what happened."""


def _group_test(group):
    def test(self):
        results = RESULTS[group]
        failures = {name: problem for name, problem in results.items() if problem}
        self.assertEqual(set(GROUPS[group]) - set(results), set(), "cases not run")
        if failures:
            self.fail("\n%d of %d cases failed:\n" % (len(failures), len(results)) + "\n".join(
                "  %s: %s" % item for item in sorted(failures.items())))
    return test


for _group in GROUPS:
    setattr(TestBadSettings, "test_" + _group, _group_test(_group))


if __name__ == "__main__":
    if len(sys.argv) == 5 and sys.argv[1] == "--group":
        sys.exit(run_child(sys.argv[2], int(sys.argv[4])))
    unittest.main()
