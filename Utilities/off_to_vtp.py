#!/usr/bin/python3
"""Converts Object File Format meshes (.off, as in CGAL's data) to VTK XML PolyData (.vtp).

VTK 9.1 has no OFF reader. Usage: off_to_vtp.py INPUT.off OUTPUT.vtp
Handles comments, counts on the header's line or the next, polygons of any size and trailing face colours.
"""
import importlib.util
import sys
from pathlib import Path


def load_meshio():
    """The package's vtkffd/meshio.py, loaded from the source tree: the set-up runs this before anything is built,
    and meshio imports only vtkmodules and numpy."""
    path = Path(__file__).resolve().parents[1] / "Wrapping" / "Python" / "vtkffd" / "meshio.py"
    spec = importlib.util.spec_from_file_location("vtkffd_meshio", path)
    meshio = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(meshio)
    return meshio


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    meshio = load_meshio()
    try:  # the extensions are given: the set-up writes to a temporary name, renamed once complete
        meshio.write_mesh(meshio.read_mesh(sys.argv[1], ".off"), sys.argv[2], ".vtp")
    except (OSError, ValueError) as error:
        sys.exit(f"cannot convert {sys.argv[1]} to {sys.argv[2]}: {error}")


if __name__ == "__main__":
    main()
