#!/usr/bin/python3
"""Converts Object File Format meshes (.off, as in CGAL's data) to VTK XML PolyData (.vtp).

VTK 9.1 has no OFF reader. Usage: off_to_vtp.py INPUT.off OUTPUT.vtp
Handles comments, counts on the header's line or the next, polygons of any size and trailing face colours.
"""
import sys

import numpy as np
from vtkmodules.util.numpy_support import numpy_to_vtk, numpy_to_vtkIdTypeArray
from vtkmodules.vtkCommonCore import vtkPoints
from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData
from vtkmodules.vtkIOXML import vtkXMLPolyDataWriter


def read_off(path):
    with open(path) as f:
        lines = [line.split("#", 1)[0].split() for line in f]
    lines = [words for words in lines if words]
    header = lines[0][0]
    if header != "OFF":
        raise ValueError(f"{path}: only plain OFF files are supported (header {header!r})")
    counts = lines[0][1:] or lines[1]
    first = 1 if lines[0][1:] else 2
    n_vertices, n_faces = int(counts[0]), int(counts[1])
    points = np.array([words[:3] for words in lines[first:first + n_vertices]], dtype=np.float64)
    offsets, connectivity = [0], []
    for words in lines[first + n_vertices:first + n_vertices + n_faces]:
        size = int(words[0])
        connectivity.extend(int(v) for v in words[1:1 + size])  # any face colour after the indices is ignored
        offsets.append(len(connectivity))
    if len(points) != n_vertices or len(offsets) != n_faces + 1:
        raise ValueError(f"{path}: fewer vertices or faces than its header announces")
    if max(connectivity, default=0) >= n_vertices:
        raise ValueError(f"{path}: a face refers to a vertex that does not exist")
    return points, np.array(offsets), np.array(connectivity)


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    points, offsets, connectivity = read_off(sys.argv[1])
    vtk_points = vtkPoints()
    vtk_points.SetData(numpy_to_vtk(points, deep=True))
    polys = vtkCellArray()
    polys.SetData(numpy_to_vtkIdTypeArray(offsets, deep=True), numpy_to_vtkIdTypeArray(connectivity, deep=True))
    mesh = vtkPolyData()
    mesh.SetPoints(vtk_points)
    mesh.SetPolys(polys)
    writer = vtkXMLPolyDataWriter()
    writer.SetFileName(sys.argv[2])
    writer.SetInputData(mesh)
    writer.SetDataModeToAppended()
    writer.SetCompressorTypeToZLib()
    if not writer.Write():
        sys.exit(f"cannot write {sys.argv[2]}")


if __name__ == "__main__":
    main()
