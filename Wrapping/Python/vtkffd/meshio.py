# SPDX-License-Identifier: BSD-3-Clause
"""Meshes in files, chosen by extension: VTK XML (.vtp, .vtu, .vts, .vti), legacy VTK (.vtk), STL, PLY, OBJ,
and the Object File Format (.off) of CGAL's and Princeton's data, which VTK 9.1 does not read and this module
parses.

It imports only vtkmodules and numpy, never the package's compiled modules, so that Utilities/off_to_vtp.py can
load it from the source tree before anything is built. Errors are exceptions: ValueError for an unknown extension,
a malformed file or data a format cannot hold, FileNotFoundError for a missing file, OSError for a file that
cannot be written.

Reading checks what VTK's readers trust: the sizes of binary STL and PLY files (a PLY file cut short crashes
vtkPLYReader), the warnings by which legacy VTK reports a file cut short, and that every cell names points the
data set has. Writing is all or nothing (write_atomically): a failed write leaves the file that was there.
"""
import errno
import os
import re
import struct
import subprocess
import sys
import tempfile

import numpy as np
from vtkmodules.util.numpy_support import ID_TYPE_CODE, numpy_to_vtk, numpy_to_vtkIdTypeArray, vtk_to_numpy
from vtkmodules.vtkCommonCore import vtkCommand, vtkOutputWindow, vtkPoints
from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData
from vtkmodules.vtkCommonMisc import vtkErrorCode
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
    if len(lines) > 1 and re.match(r"(ERROR|Warning|Generic Warning): In ", lines[0]):
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
        if text is None:  # VTK passes None for a message that is not UTF-8: one that quotes a garbled file
            self.failures.append("a message that is not text (a garbled or binary file?)")
            return
        line = one_line(text)
        failure = re.match(r"\w+: Algorithm (\w+) returned failure for request", line)
        if failure:
            self.failures.append(f"{failure.group(1)} failed")
        else:
            self.messages.append(line)

    def first(self):
        """The first message that says why something failed, else the first failure, else None."""
        return (self.messages or self.failures or [None])[0]


def checked(vtk_object, action, what, error, warnings=False):
    """Runs `action` (the Update or Write of `vtk_object`, say) and raises `error`, with "`what`: VTK's first
    message" (`what`: a file's path, or what failed), if the object, an algorithm's executive or an object that
    reports only to vtkOutputWindow (a reader's or writer's helper) reported an error meanwhile; with `warnings`, a
    warning too (legacy VTK's readers report a file cut short by a warning alone). Its observers are removed
    afterwards: the object is left as it was."""
    messages = VTKMessages()
    observed = [vtk_object, vtk_object.GetExecutive()] if hasattr(vtk_object, "GetExecutive") else [vtk_object]
    events = (vtkCommand.ErrorEvent, vtkCommand.WarningEvent) if warnings else (vtkCommand.ErrorEvent,)
    tags = [(each, each.AddObserver(event, messages)) for each in observed + [vtkOutputWindow.GetInstance()]
            for event in events]
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
    name does not say it). A file without points is malformed: readers of some formats (OBJ) report nothing else;
    so is one cut short or garbled where its reader does not notice (see the module's docstring)."""
    extension = _extension(path, extension)
    if not os.path.isfile(path):
        raise FileNotFoundError(errno.ENOENT, os.strerror(errno.ENOENT), path)
    if extension == ".off":
        return read_off(path)
    check_header(path, extension)
    reader = VTK_FORMATS[extension][0]()
    reader.SetFileName(path)
    checked(reader, reader.Update, path, ValueError, warnings=True)
    data = reader.GetOutputDataObject(0)
    if data is None or data.GetNumberOfPoints() == 0:
        raise ValueError(f"{path}: no points read: an empty or malformed {extension} file")
    check_cells(data, path)
    return data


def check_cells(data, what):
    """Raises ValueError, naming `what`, when the cells of the data set (a vtkPolyData, vtkUnstructuredGrid or
    vtkStructuredGrid) do not fit its points: an id outside them, offsets that do not run from 0 up to the
    connectivity's size, cell types not one per cell, structured dimensions other than the number of points.
    Readers build such data sets from files garbled or cut short, and filters would read outside the points."""
    points = data.GetNumberOfPoints()
    if data.IsA("vtkStructuredGrid"):
        if int(np.prod(data.GetDimensions())) != points:
            raise ValueError(f"{what}: dimensions {list(data.GetDimensions())} for {points} points: a garbled file")
        return
    if data.IsA("vtkPolyData"):
        arrays = (data.GetVerts(), data.GetLines(), data.GetPolys(), data.GetStrips())
    elif data.IsA("vtkUnstructuredGrid"):
        arrays = (data.GetCells(),)
        types = data.GetCellTypesArray()
        if data.GetCells() and (0 if types is None else types.GetNumberOfTuples()) != data.GetNumberOfCells():
            raise ValueError(f"{what}: not one cell type per cell: a garbled file")
    else:
        return
    for cells in (each for each in arrays if each is not None):
        offsets = vtk_to_numpy(cells.GetOffsetsArray())
        connectivity = vtk_to_numpy(cells.GetConnectivityArray())
        if len(offsets) and (offsets[0] != 0 or offsets[-1] != len(connectivity) or np.any(np.diff(offsets) < 0)):
            raise ValueError(f"{what}: cell offsets that do not run from 0 to the connectivity's size: a garbled file")
        if len(connectivity) and (connectivity.min() < 0 or connectivity.max() >= points):
            bad = connectivity.max() if connectivity.max() >= points else connectivity.min()
            raise ValueError(f"{what}: a cell names point {bad}, but there are {points} points: a garbled file")


def _is_text(head):
    return all(32 <= byte < 127 or byte in b"\t\n\r\f\v" for byte in head)


def check_header(path, extension, what=None):
    """Raises ValueError, "`what` (default `path`): the reason", when the file `path` is not of the format of
    `extension` where VTK's reader would go on regardless, or crash: VTK's files without their first bytes (their
    parsers report to the log, not to the reader's observers), legacy files that crash VTK's reader, binary STL
    and PLY files whose sizes do not add up."""
    what = what or path
    magic = {".vtk": b"# vtk DataFile", ".vtp": b"<", ".vtu": b"<", ".vts": b"<", ".vti": b"<"}.get(extension)
    if magic is not None:
        with open(path, "rb") as stream:
            if not stream.read(64).lstrip().startswith(magic):
                raise ValueError(f"{what}: it is not a VTK {'legacy' if extension == '.vtk' else 'XML'} file")
    if extension == ".vtk":
        _check_legacy_reader_survives(path, what)
    elif extension in (".stl", ".ply"):
        (_check_stl if extension == ".stl" else _check_ply)(path, what)


_LEGACY_PROBE = """import sys
from vtkmodules.vtkCommonCore import vtkLogger
from vtkmodules.vtkIOLegacy import vtkDataSetReader
vtkLogger.SetStderrVerbosity(vtkLogger.VERBOSITY_OFF)
reader = vtkDataSetReader()
reader.SetFileName(sys.argv[1])
reader.Update()
"""


def _check_legacy_reader_survives(path, what):
    """VTK 9.1's legacy reader goes on with arrays it failed to read: some files cut short (in field data, or in
    an array's header) crash it, which no check in this process could catch. So it reads the file first in a
    child process; its errors are left to the read that follows."""
    child = subprocess.run([sys.executable, "-c", _LEGACY_PROBE, os.path.abspath(path)], capture_output=True,
                           env=dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path)), check=False)
    if child.returncode != 0:
        raise ValueError(f"{what}: VTK's legacy reader crashes on it (exit status {child.returncode}): a file cut "
                         "short or garbled")


def _check_stl(path, what):
    """vtkSTLReader takes a file that is not text for a binary STL and reads triangles up to its end, whatever its
    header counts: random bytes make a mesh. A binary STL is an 80-byte header, a count and 50 bytes a triangle."""
    size = os.path.getsize(path)
    with open(path, "rb") as stream:
        head = stream.read(256)
    if head.lstrip().startswith(b"solid") and _is_text(head):
        return  # ASCII, which VTK's parser checks
    count = struct.unpack_from("<I", head, 80)[0] if len(head) >= 84 else 0
    if size < 84 or size != 84 + 50 * count:
        raise ValueError(f"{what}: not an STL file: neither text starting with 'solid' nor binary (an 80-byte "
                         f"header, a count, 50 bytes a triangle: {84 + 50 * count} bytes for its count, {size} here)")


_PLY_SIZES = {"char": 1, "uchar": 1, "int8": 1, "uint8": 1, "short": 2, "ushort": 2, "int16": 2, "uint16": 2,
              "int": 4, "uint": 4, "int32": 4, "uint32": 4, "float": 4, "float32": 4, "double": 8, "float64": 8}
_PLY_COUNTS = {"char": "b", "uchar": "B", "int8": "b", "uint8": "B", "short": "h", "ushort": "H", "int16": "h",
               "uint16": "H", "int": "i", "uint": "I", "int32": "i", "uint32": "I"}


def _ply_header(what, data):
    """(format, [(element, count, properties)]) of a PLY file's header, and where its data starts; a property is
    its size in bytes for a scalar, (count's struct format, item size) for a list."""
    end = data.find(b"end_header")
    newline = data.find(b"\n", end)
    if not data.startswith(b"ply") or end < 0 or newline < 0:
        raise ValueError(f"{what}: not a PLY file (no 'ply' ... 'end_header' header)")
    elements, form, line = [], None, ""
    try:
        for line in data[:end].decode("ascii", "replace").splitlines()[1:]:
            words = line.split()
            if not words or words[0] in ("comment", "obj_info"):
                continue
            if words[0] == "format":
                form = words[1]
            elif words[0] == "element":
                elements.append((words[1], int(words[2]), []))
                if elements[-1][1] < 0:
                    raise ValueError
            elif words[0] == "property" and words[1] == "list":
                elements[-1][2].append((_PLY_COUNTS[words[2]], _PLY_SIZES[words[3]]))
            elif words[0] == "property":
                elements[-1][2].append(_PLY_SIZES[words[1]])
            else:
                raise ValueError
    except (ValueError, IndexError, KeyError):
        raise ValueError(f"{what}: a PLY header line that is not one: {line!r}") from None
    if form not in ("ascii", "binary_little_endian", "binary_big_endian"):
        raise ValueError(f"{what}: PLY format {form!r}: ascii, binary_little_endian or binary_big_endian")
    return form, elements, newline + 1


def _check_ply(path, what):
    """vtkPLYReader trusts the header's counts: a binary file cut short crashes it or reads garbage. Each element's
    rows, their lists walked by their counts, must fit in the file; an ASCII file needs a line a row."""
    with open(path, "rb") as stream:
        data = stream.read()
    form, elements, offset = _ply_header(what, data)
    if form == "ascii":
        rows = sum(count for _, count, _ in elements)
        if len(data[offset:].splitlines()) < rows:
            raise ValueError(f"{what}: cut short: its header announces {rows} rows, it has fewer lines")
        return
    order = "<" if form == "binary_little_endian" else ">"
    for name, count, properties in elements:
        offset = _ply_rows_end(data, offset, count, properties, order)
        if offset is None:
            announced = ", ".join(f"{count} {name}" for name, count, _ in elements)
            raise ValueError(f"{what}: cut short or garbled: the elements its header announces ({announced}) do not "
                             f"fit in its {len(data)} bytes")


def _ply_rows_end(data, offset, count, properties, order):
    """Where `count` binary rows of `properties` (_ply_header's) from `offset` end in `data`; None past its end, or
    at a negative list count."""
    if all(isinstance(p, int) for p in properties):
        end = offset + count * sum(properties)
        return end if end <= len(data) else None
    for _ in range(count):
        for p in properties:
            if isinstance(p, int):
                offset += p
                continue
            if offset + struct.calcsize(p[0]) > len(data):
                return None
            items = struct.unpack_from(order + p[0], data, offset)[0]
            if items < 0:
                return None
            offset += struct.calcsize(p[0]) + items * p[1]
        if offset > len(data):
            return None
    return offset


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
    XML appended and compressed, legacy VTK and STL binary; XML, legacy VTK and OFF keep float64 points exactly.
    All or nothing (write_atomically); OSError when it fails."""
    extension = check_format(data, path, extension)
    if extension == ".off":
        write_off(data, path)
        return
    writer = VTK_FORMATS[extension][1]()
    writer.SetInputData(data)
    if isinstance(writer, vtkXMLWriter):
        writer.SetDataModeToAppended()
        writer.SetCompressorTypeToZLib()
    elif hasattr(writer, "SetFileTypeToBinary"):  # ASCII legacy VTK rounds doubles to 11 digits
        writer.SetFileTypeToBinary()

    def write(temporary):
        write_vtk(writer, temporary, path, OSError)
        if extension in (".ply", ".obj"):  # their writers do not check their streams: read the file back
            _check_written(data, temporary, extension, path)

    write_atomically(path, write)


def write_vtk(writer, temporary, what, error):
    """Runs a VTK writer (vtkFFDVDBWriter too) into the file `temporary` (write_atomically's) and raises `error`,
    "`what`: VTK's first message", if the writer, its executive or a helper of it reported an error, or OSError
    if it returned failure or set an error code without one."""
    writer.SetFileName(temporary)
    written = []
    checked(writer, lambda: written.append(writer.Write()), what, error)
    if not written[0] or writer.GetErrorCode():
        raise OSError(f"{what}: {writer.GetClassName()} failed: "
                      f"{vtkErrorCode.GetStringFromErrorCode(writer.GetErrorCode())}")


def _check_written(data, temporary, extension, path):
    """Raises OSError unless the file `temporary` reads back with the points and faces `data` was written with:
    VTK's PLY writer writes polygons; its OBJ writer polygons, strips as triangles, and polylines."""
    faces, lines = data.GetNumberOfPolys(), 0
    if extension == ".obj":
        strips = vtk_to_numpy(data.GetStrips().GetOffsetsArray()) if data.GetStrips() else np.zeros(1)
        faces, lines = faces + int(np.sum(np.diff(strips) - 2)), data.GetNumberOfLines()
    try:
        back = read_mesh(temporary, extension)
        complete = (back.GetNumberOfPoints(), back.GetNumberOfPolys(), back.GetNumberOfLines()) == (
            data.GetNumberOfPoints(), faces, lines)
    except ValueError:
        complete = False
    if not complete:
        raise OSError(f"{path}: the {extension} file written is incomplete (disk full?)")


def write_atomically(path, write):
    """Writes the file `path` all or nothing: `write(temporary)` writes a new file beside it (the same folder, so
    the same file system), which replaces `path` by a rename once `write` returned and the file is on disk. When
    anything fails, the new file is removed, `path` is left as it was, and the exception is raised with `path` in
    place of the new file's name. A symbolic link stays one (the file it names is replaced); a path that exists
    and is not a regular file (a device, a folder) is refused. The new file gets the permissions of the old one,
    or those of the umask."""
    target = os.path.realpath(path)
    if os.path.exists(target) and not os.path.isfile(target):
        raise OSError(errno.EINVAL, "not a regular file", path)
    folder, name = os.path.split(target)
    stem, extension = os.path.splitext(name)
    try:
        descriptor, temporary = tempfile.mkstemp(prefix=f".{stem}.", suffix=f".partial{extension}", dir=folder)
    except OSError as error:
        raise OSError(error.errno, error.strerror, path) from None
    os.close(descriptor)
    try:
        mask = os.umask(0)
        os.umask(mask)
        os.chmod(temporary, os.stat(target).st_mode & 0o7777 if os.path.exists(target) else 0o666 & ~mask)
        write(temporary)
        descriptor = os.open(temporary, os.O_RDONLY)
        try:
            os.fsync(descriptor)
        finally:
            os.close(descriptor)
        os.replace(temporary, target)
    except BaseException as error:
        if os.path.exists(temporary):
            os.remove(temporary)
        if isinstance(error, OSError) and error.errno is not None:
            raise OSError(error.errno, error.strerror, path) from None
        error.args = tuple(a.replace(temporary, path) if isinstance(a, str) else a for a in error.args)
        raise


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
            size = int(words[0])
            face = [int(word) for word in words[1:1 + size]]
        except ValueError:
            size, face = -1, []
        if not face or len(face) != size or min(face) < 0 or max(face) >= n_vertices:
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
    digits, which read_off() reads back bit for bit (in float64). Vertices, lines and strips have no place there.
    All or nothing (write_atomically)."""
    others = mesh.GetNumberOfVerts() + mesh.GetNumberOfLines() + mesh.GetNumberOfStrips()
    if others:
        raise ValueError(f"{path}: an OFF file holds polygons only; this mesh has {others} vertex, line or strip cells")
    points = vtk_to_numpy(mesh.GetPoints().GetData()) if mesh.GetPoints() else np.empty((0, 3))
    offsets = vtk_to_numpy(mesh.GetPolys().GetOffsetsArray())
    connectivity = vtk_to_numpy(mesh.GetPolys().GetConnectivityArray())
    faces = [connectivity[start:end] for start, end in zip(offsets[:-1], offsets[1:])]

    def write(temporary):
        with open(temporary, "w") as stream:
            stream.write(f"OFF\n{len(points)} {len(faces)} 0\n")
            np.savetxt(stream, points, fmt="%.17g")
            stream.writelines(f"{len(face)} {' '.join(map(str, face))}\n" for face in faces)

    write_atomically(path, write)
