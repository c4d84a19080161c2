# SPDX-License-Identifier: BSD-3-Clause
"""What the Python tests of this folder share: the real meshes, the points as float64 numpy arrays, the
voxelize -> build lattice set-up with a copy of the lattice that a test moves, the catching of VTK's error events,
and the off-screen render window. Not a test itself: the tests import it from their own folder (ctest runs them
as scripts from here, so this folder is first on sys.path).
"""
import os

import numpy as np
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkCommonDataModel import vtkStructuredGrid
from vtkmodules.vtkCommonExecutionModel import vtkAlgorithmOutput
from vtkmodules.vtkIOXML import vtkXMLPolyDataReader
from vtkmodules.vtkRenderingCore import vtkRenderWindow

import vtkffd

MESH_DIR = os.environ.get(
    "VOXELFFD_MESH_DIR", os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "Data", "Meshes"))


def read_mesh(name):
    """The real mesh `name` (e.g. "elephant") that Utilities/setup.sh fetches into VOXELFFD_MESH_DIR."""
    path = os.path.join(MESH_DIR, name + ".vtp")
    if not os.path.isfile(path):
        raise FileNotFoundError(path + " is missing: run Utilities/setup.sh, which fetches the meshes")
    reader = vtkXMLPolyDataReader()
    reader.SetFileName(path)
    reader.Update()
    return reader.GetOutput()


def points_of(data):
    """The points of a VTK point set as an (N, 3) float64 numpy array (a copy)."""
    return vtk_to_numpy(data.GetPoints().GetData()).astype(np.float64)


def bbox_diagonal(points):
    """The diagonal of the bounding box of (N, 3) points: the scale of the tests' tolerances."""
    return float(np.linalg.norm(points.max(axis=0) - points.min(axis=0)))


def build_lattice(source, divisions, basis=None):
    """vtkFFDVoxelize of `source` (a data set, or an algorithm's output port) into `divisions` voxels, then
    vtkFFDBuildLattice (of `basis`, or its default basis) in the dense form, updated; returns (voxelize, build,
    lattice), the lattice a deep copy of the builder's output for the test to move (the filters keep their own
    output)."""
    voxelize = vtkffd.vtkFFDVoxelize()
    if isinstance(source, vtkAlgorithmOutput):
        voxelize.SetInputConnection(source)
    else:
        voxelize.SetInputData(source)
    voxelize.SetDivisions(*divisions)
    build = vtkffd.vtkFFDBuildLattice()
    build.SetInputConnection(voxelize.GetOutputPort())
    if basis is not None:
        build.SetBasis(basis)
    build.SetLatticeFormToDense()  # the grid that the tests index
    build.Update()
    lattice = vtkStructuredGrid()
    lattice.DeepCopy(build.GetOutput())
    return voxelize, build, lattice


class ErrorCatcher:
    """Collects the messages of ErrorEvents (and keeps expected errors out of the log)."""

    def __init__(self):
        self.CallDataType = "string0"  # VTK passes the message as call data to observers that declare it
        self.messages = []

    def __call__(self, caller, event, message):
        self.messages.append(message)


def catch_errors(obj, executive=False):
    """An ErrorCatcher observing obj's ErrorEvents. With `executive`, the errors of obj's executive (which
    reports a failed request too) are caught as well, and dropped, so that the log shows only unexpected ones."""
    catcher = ErrorCatcher()
    obj.AddObserver("ErrorEvent", catcher)
    if executive:
        obj.GetExecutive().AddObserver("ErrorEvent", ErrorCatcher())
    return catcher


def run_with_errors(algorithm, data):
    """Runs `algorithm` on `data` (SetInputData, Update) with its errors caught; returns their messages."""
    algorithm.SetInputData(data)
    catcher = catch_errors(algorithm)
    algorithm.Update()
    return catcher.messages


def offscreen_window(renderer, size=None, multisamples=None):
    """An off-screen vtkRenderWindow showing `renderer`, of `size` (width, height) and `multisamples` where given
    (0 for the image tests: multisampling differs between GL drivers)."""
    window = vtkRenderWindow()
    window.SetOffScreenRendering(1)
    if multisamples is not None:
        window.SetMultiSamples(multisamples)
    if size is not None:
        window.SetSize(*size)
    window.AddRenderer(renderer)
    return window


UNIT_ROUNDOFF = 2.0 ** -53


def adjoint_bound(W, g):
    """How far vtkFFDSensitivity's W^T g may be from W.T @ g: both sum k terms per control point in float64, in
    different orders and associations, 2 (k + 8) u of the terms' sizes; and the weights themselves differ where
    they are evaluated in SIMD lanes with FMA or on a GPU rather than one by one, by a few u of 1 (of the weight
    where it is larger, extrapolated): a tiny weight's relative error is not small. 16 u max(1, |w|) a term."""
    k = np.diff(W.tocsc().indptr)[:, None]
    sizes = abs(W)
    sizes.data = np.maximum(sizes.data, 1.0)
    return 2 * (k + 8) * UNIT_ROUNDOFF * (abs(W).T @ np.abs(g)) + 16 * UNIT_ROUNDOFF * (sizes.T @ np.abs(g))
