# SPDX-License-Identifier: BSD-3-Clause
"""The demo's move of a dense lattice's control points: the top layer pulled up and twisted, the middle layers
bulged out. numpy and vtkmodules only, so that the Python demo (deform_mesh.py), the level-of-detail example and
the ParaView demo (Examples/ParaView/deform_mesh.py, inside pvbatch's VTK) move the lattice with the same code.
"""
import numpy as np
from vtkmodules.util.numpy_support import vtk_to_numpy

# CGAL's meshes stand along +Y, the frame's T axis: "up" below is T, and the camera looks along -Z.
TWIST_DEGREES = 40.0  # rotation of the top layer about the vertical axis (zero at the bottom layer)
BULGE = 0.35  # outward push of the middle layers, as a fraction of their distance to the axis
STRETCH = 0.25  # lift of the top layer, as a fraction of the frame's height


def twist_lattice(lattice):
    """Moves a dense lattice's points (a vtkStructuredGrid of vtkFFDBuildLattice) in place."""
    dimensions = [0, 0, 0]
    lattice.GetDimensions(dimensions)  # the form that ParaView's VTK has not deprecated
    n_i, n_j, n_k = dimensions
    frame = vtk_to_numpy(lattice.GetFieldData().GetArray("FFDFrame"))
    origin, s_axis, t_axis, u_axis = frame.reshape(4, 3)
    rest = vtk_to_numpy(lattice.GetPointData().GetArray("RestPosition")).reshape(n_k, n_j, n_i, 3)
    # A view of the lattice's own points (VTK order: i fastest, so the numpy shape is k, j, i).
    points = vtk_to_numpy(lattice.GetPoints().GetData()).reshape(n_k, n_j, n_i, 3)

    # Parameter t of each layer along T, from the rest positions: a B-spline lattice's outer layers lie outside
    # the frame, at t < 0 and t > 1.
    parameters = np.linalg.solve(np.column_stack((s_axis, t_axis, u_axis)), (rest[0, :, 0] - origin).T)
    height = parameters[1][None, :, None, None]
    axis = t_axis / np.linalg.norm(t_axis)
    centre = origin + 0.5 * s_axis + 0.5 * u_axis + height * t_axis  # the vertical axis through the frame
    offset = rest - centre
    angle = np.radians(TWIST_DEGREES) * height
    # Rotate the part of each offset across the axis (Rodrigues' formula with no along-axis term), scale it.
    along = (offset @ axis)[..., None] * axis
    across = offset - along
    rotated = across * np.cos(angle) + np.cross(axis, across) * np.sin(angle)
    scale = 1.0 + BULGE * np.sin(np.pi * height)
    points[...] = centre + along + scale * rotated + STRETCH * height**2 * t_axis
    lattice.GetPoints().Modified()  # numpy wrote behind VTK's back: tell the pipeline
