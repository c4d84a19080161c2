# SPDX-License-Identifier: BSD-3-Clause
"""Meshes in files, chosen by extension: VTK XML (.vtp, .vtu, .vts, .vti), legacy VTK (.vtk), STL, PLY, OBJ,
and the Object File Format (.off) of CGAL's and Princeton's data, which VTK 9.1 does not read and this module
parses.

It imports only vtkmodules and numpy, never the package's compiled modules, so that Utilities/off_to_vtp.py can
load it from the source tree before anything is built. Errors are exceptions: ValueError for an unknown extension,
a malformed file or data a format cannot hold, FileNotFoundError for a missing file, OSError for a file that
cannot be written.
"""
import errno
import os
import re

import numpy as np
from vtkmodules.util.numpy_support import ID_TYPE_CODE, numpy_to_vtk, numpy_to_vtkIdTypeArray, vtk_to_numpy
from vtkmodules.vtkCommonCore import vtkCommand, vtkPoints
from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData
from vtkmodules.vtkIOGeometry import vtkOBJReader, vtkOBJWriter, vtkSTLReader, vtkSTLWriter
from vtkmodules.vtkIOLegacy import vtkDataSetReader, vtkDataSetWriter
from vtkmodules.vtkIOPLY import vtkPLYReader, vtkPLYWriter
from vtkmodules.vtkIOXML import (
    vtkXMLImageDataReader,
    vtkXMLImageDataWriter,
    vtkXMLPolyDataReader,
    vtkXMLPolyDataWriter,
    vtkXMLStructuredGridReader,
    vtkXMLStructuredGridWriter,
    vtkXMLUnstructuredGridReader,
    vtkXMLUnstructuredGridWriter,
    vtkXMLWriter,
)

VTK_FORMATS = {  # extension: (reader, writer, the data type its files hold)
    ".vtp": (vtkXMLPolyDataReader, vtkXMLPolyDataWriter, "vtkPolyData"),
    ".vtu": (vtkXMLUnstructuredGridReader, vtkXMLUnstructuredGridWriter, "vtkUnstructuredGrid"),
    ".vts": (vtkXMLStructuredGridReader, vtkXMLStructuredGridWriter, "vtkStructuredGrid"),
    ".vti": (vtkXMLImageDataReader, vtkXMLImageDataWriter, "vtkImageData"),
    ".vtk": (vtkDataSetReader, vtkDataSetWriter, "vtkDataSet"),
    ".stl": (vtkSTLReader, vtkSTLWriter, "vtkPolyData"),
    ".ply": (vtkPLYReader, vtkPLYWriter, "vtkPolyData"),
    ".obj": (vtkOBJReader, vtkOBJWriter, "vtkPolyData"),
}
EXTENSIONS = (*VTK_FORMATS, ".off")  # every extension read_mesh and write_mesh know


def one_line(text):
    """The line of a VTK error or warning message that says what happened, without the "ERROR: In file, line N"
    header before it, the object's address, or what an executive prints after it."""
    lines = text.strip().splitlines()
    if len(lines) > 1 and re.match(r"(ERROR|Warning): In ", lines[0]):
        lines = lines[1:]
    return " ".join(re.sub(r"\s*\(0x[0-9a-fA-F]+\)", "", lines[0]).split())


class VTKMessages:
    """Collects VTK's ErrorEvents (or WarningEvents), each as one_line() of its message, from the objects it
    observes, or from every object when it observes vtkOutputWindow, where the events of unobserved objects go."""

    def __init__(self):
        self.CallDataType = "string0"  # VTK passes the message as call data to observers that declare it
        self.messages = []  # what the algorithms said
        self.failures = []  # what executives said: only that an algorithm failed

    def __call__(self, caller, event, text):
        line = one_line(text)
        failure = re.match(r"\w+: Algorithm (\w+) returned failure for request", line)
        if failure:
            self.failures.append(f"{failure.group(1)} failed")
        else:
            self.messages.append(line)

    def first(self):
        """The first message that says why something failed, else the first failure, else None."""
        return (self.messages or self.failures or [None])[0]


def checked(vtk_object, action, what, error):
    """Runs `action` (the Update or Write of `vtk_object`, say) and raises `error`, with "`what`: VTK's first
    message" (`what`: a file's path, or what failed), if the object or an algorithm's executive reported an error
    meanwhile. Its observers are removed afterwards: the object is left as it was."""
    messages = VTKMessages()
    observed = [vtk_object, vtk_object.GetExecutive()] if hasattr(vtk_object, "GetExecutive") else [vtk_object]
    tags = [(each, each.AddObserver(vtkCommand.ErrorEvent, messages)) for each in observed]
    try:
        action()
    finally:
        for each, tag in tags:
            each.RemoveObserver(tag)
    if messages.first():
        raise error(f"{what}: {messages.first()}")


def _extension(path, extension):
    extension = (extension or os.path.splitext(path)[1]).lower()
    if extension not in EXTENSIONS:
        raise ValueError(f"{path}: unknown mesh format {extension or '(no extension)'!r}; "
                         f"known: {' '.join(EXTENSIONS)}")
    return extension


def read_mesh(path, extension=None):
    """The data set in the file `path`, of the format of its extension (or of `extension`, e.g. ".off", where the
    name does not say it). A file without points is malformed: readers of some formats (OBJ) report nothing else."""
    extension = _extension(path, extension)
    if not os.path.isfile(path):
        raise FileNotFoundError(errno.ENOENT, os.strerror(errno.ENOENT), path)
    if extension == ".off":
        return read_off(path)
    reader = VTK_FORMATS[extension][0]()
    reader.SetFileName(path)
    checked(reader, reader.Update, path, ValueError)
    data = reader.GetOutputDataObject(0)
    if data is None or data.GetNumberOfPoints() == 0:
        raise ValueError(f"{path}: no points read: an empty or malformed {extension} file")
    return data


def check_format(data, path, extension=None):
    """Returns the extension of the format of `path` (or `extension`), after a ValueError if it is unknown or cannot
    hold the data set `data` (or data of its type)."""
    extension = _extension(path, extension)
    holds = "vtkPolyData" if extension == ".off" else VTK_FORMATS[extension][2]
    if not data.IsA(holds):
        raise ValueError(f"{path}: a {extension} file holds a {holds}, not a {data.GetClassName()}")
    return extension


def write_mesh(data, path, extension=None):
    """Writes the data set `data` into the file `path` in the format of its extension (or of `extension`): VTK's
    XML appended and compressed, legacy VTK and STL binary; XML, legacy VTK and OFF keep float64 points exactly."""
    extension = check_format(data, path, extension)
    if extension == ".off":
        write_off(data, path)
        return
    writer = VTK_FORMATS[extension][1]()
    writer.SetFileName(path)
    writer.SetInputData(data)
    if isinstance(writer, vtkXMLWriter):
        writer.SetDataModeToAppended()
        writer.SetCompressorTypeToZLib()
    elif hasattr(writer, "SetFileTypeToBinary"):  # ASCII legacy VTK rounds doubles to 11 digits
        writer.SetFileTypeToBinary()
    checked(writer, writer.Write, path, OSError)


def read_off(path):
    """The polygon mesh of an OFF file as a vtkPolyData of float64 points: the header OFF, the counts of vertices,
    faces and edges (on the header's line or the next), x y z per vertex, then per face its vertex count and
    indices; '#' starts a comment, and anything after a face's indices (a colour) is ignored."""
    try:
        with open(path) as stream:
            lines = [(number, line.split("#", 1)[0].split()) for number, line in enumerate(stream, 1)]
    except UnicodeDecodeError:
        raise ValueError(f"{path}: not text, so not an OFF file") from None
    lines = [(number, words) for number, words in lines if words]
    if not lines:
        raise ValueError(f"{path}: empty, not an OFF file")
    if lines[0][1][0] != "OFF":
        raise ValueError(f"{path}: only plain OFF files are supported (header {lines[0][1][0]!r})")
    lines[0] = (lines[0][0], lines[0][1][1:])  # the counts follow OFF on its line, or have the next one
    if not lines[0][1]:
        del lines[0]
    number, counts = lines[0] if lines else (1, [])
    try:
        n_vertices, n_faces = int(counts[0]), int(counts[1])
    except (IndexError, ValueError):
        raise ValueError(f"{path}, line {number}: expected the numbers of vertices and faces") from None
    if min(n_vertices, n_faces) < 0:
        raise ValueError(f"{path}, line {number}: negative numbers of vertices or faces")
    vertices, faces = lines[1:1 + n_vertices], lines[1 + n_vertices:1 + n_vertices + n_faces]
    if len(vertices) != n_vertices or len(faces) != n_faces:
        raise ValueError(f"{path}: fewer vertices or faces than its header announces ({n_vertices}, {n_faces})")
    points = []
    for number, words in vertices:
        try:
            x, y, z = map(float, words[:3])
        except ValueError:
            raise ValueError(f"{path}, line {number}: expected the x y z of a vertex") from None
        points.append((x, y, z))
    offsets, connectivity = [0], []
    for number, words in faces:
        try:
            face = [int(word) for word in words[1:1 + int(words[0])]]
        except ValueError:
            face = []
        if not face or len(face) != int(words[0]) or min(face) < 0 or max(face) >= n_vertices:
            raise ValueError(f"{path}, line {number}: expected a face: its number of vertices, then as many "
                             f"vertex indices below {n_vertices}")
        connectivity.extend(face)
        offsets.append(len(connectivity))
    vtk_points = vtkPoints()
    vtk_points.SetData(numpy_to_vtk(np.array(points, dtype=np.float64).reshape(-1, 3), deep=True))
    polys = vtkCellArray()
    polys.SetData(numpy_to_vtkIdTypeArray(np.array(offsets, dtype=ID_TYPE_CODE), deep=True),
                  numpy_to_vtkIdTypeArray(np.array(connectivity, dtype=ID_TYPE_CODE), deep=True))
    mesh = vtkPolyData()
    mesh.SetPoints(vtk_points)
    mesh.SetPolys(polys)
    return mesh


def write_off(mesh, path):
    """Writes the points and polygons of the vtkPolyData `mesh` as an OFF file, each coordinate with 17 significant
    digits, which read_off() reads back bit for bit (in float64). Vertices, lines and strips have no place there."""
    others = mesh.GetNumberOfVerts() + mesh.GetNumberOfLines() + mesh.GetNumberOfStrips()
    if others:
        raise ValueError(f"{path}: an OFF file holds polygons only; this mesh has {others} vertex, line or strip cells")
    points = vtk_to_numpy(mesh.GetPoints().GetData()) if mesh.GetPoints() else np.empty((0, 3))
    offsets = vtk_to_numpy(mesh.GetPolys().GetOffsetsArray())
    connectivity = vtk_to_numpy(mesh.GetPolys().GetConnectivityArray())
    faces = [connectivity[start:end] for start, end in zip(offsets[:-1], offsets[1:])]
    with open(path, "w") as stream:
        stream.write(f"OFF\n{len(points)} {len(faces)} 0\n")
        np.savetxt(stream, points, fmt="%.17g")
        stream.writelines(f"{len(face)} {' '.join(map(str, face))}\n" for face in faces)
