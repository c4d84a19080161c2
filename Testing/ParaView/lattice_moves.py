# SPDX-License-Identifier: BSD-3-Clause
"""The control-point move of the ParaView tests: numpy and vtkmodules only, so that pvbatch's Programmable Filter
(inside ParaView's VTK) and the reference pipeline of test_paraview.py (Debian's VTK) run the same code."""
import numpy as np
from vtkmodules.util.numpy_support import vtk_to_numpy


def move_control_points(lattice):
    """Moves each point of a lattice (grid or tetrahedral) in place by a smooth function of its rest position: a
    shear and a swirl of about a tenth of the rest positions' size."""
    rest = vtk_to_numpy(lattice.GetPointData().GetArray("RestPosition"))
    if len(rest) == 0:
        return
    low, high = rest.min(axis=0), rest.max(axis=0)
    size = float(np.linalg.norm(high - low))
    r = (rest - low) / np.where(high > low, high - low, 1.0)
    points = vtk_to_numpy(lattice.GetPoints().GetData())
    points[:, 0] += 0.10 * size * np.sin(np.pi * r[:, 1]) * r[:, 2]
    points[:, 1] += 0.08 * size * r[:, 0] * r[:, 0]
    points[:, 2] -= 0.06 * size * np.cos(np.pi * r[:, 0]) * r[:, 1]
    lattice.GetPoints().Modified()
