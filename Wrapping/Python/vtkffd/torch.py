# SPDX-License-Identifier: BSD-3-Clause
"""vtkFFDDeform as a differentiable PyTorch function of the control points.

    deformed = vtkffd.torch.deform(mesh, lattice, control_points)   # (points, 3), control_points' dtype
    loss = objective(deformed)
    loss.backward()                                                  # control_points.grad = W^T dloss/ddeformed

The forward pass is vtkFFDDeform of `mesh` (at rest) by `lattice` with its points replaced by `control_points`
(a (lattice points, 3) tensor, float32 or float64); the backward pass is vtkFFDSensitivity with the incoming
gradient as its point array: dJ/dP = W^T g, exact (the deformation is linear in the control points), in float64,
then cast to the control points' dtype. float64 control points deform in float64, float32 ones in float32 (the
mesh's points as they are, the output in vtkFFDDeform's single precision). Tensors on another device are copied
to the host and the results back to it: the work runs in VTK on the host (or vtkFFDDeform's CUDA backend).

deform() binds the mesh to the lattice at each call; an optimisation that calls it many times makes one
Deformation, which binds once and keeps its filters:

    deformation = vtkffd.torch.Deformation(mesh, lattice)
    for step in range(100):
        deformed = deformation(control_points)

PyTorch is optional: `import vtkffd` never imports it, and this module raises ImportError, saying what to install,
where it is missing. Inside the package `import torch` is PyTorch itself (imports are absolute).
"""
try:
    import torch
    from torch.autograd.function import once_differentiable
except ImportError as error:
    raise ImportError(f"vtkffd.torch needs PyTorch ({error}): install python3-torch (Debian) or torch (pip); "
                      "the rest of vtkffd works without it") from error

import numpy as np
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkCommonCore import vtkDoubleArray, vtkPoints
from vtkmodules.vtkCommonDataModel import vtkDataObject, vtkPointSet

from . import meshio, vtkFFDDeform, vtkFFDSensitivity

GRADIENT_NAME = "vtkffd.torch gradient"  # the mesh's point array that carries g into vtkFFDSensitivity
OUTSIDE_POLICIES = (vtkFFDDeform.KEEP_POSITION, vtkFFDDeform.CLAMP_TO_EDGE, vtkFFDDeform.EXTRAPOLATE)


def _copy_structure(data):
    """A shallow copy of a VTK data set: its own object, sharing the arrays (to add or replace some)."""
    copy = data.NewInstance()
    copy.ShallowCopy(data)
    return copy


def _doubles(array_view, tensor):
    """Writes a (n, 3) tensor into a float64 numpy view of a VTK array."""
    array_view[...] = tensor.detach().to(device="cpu", dtype=torch.float64).numpy()


class Deformation:
    """The deformation of `mesh` (a vtkPointSet at rest) by `lattice` (any lattice vtkFFDDeform takes) under
    `outside_policy` (vtkFFDDeform's), as a function of the lattice's control points: call it with a
    (lattice points, 3) tensor. It keeps a vtkFFDDeform and a vtkFFDSensitivity, whose bindings stay while the mesh's
    points and the lattice's rest state do (neither is modified: it works on shallow copies with its own points and
    gradient arrays)."""

    def __init__(self, mesh, lattice, outside_policy=vtkFFDDeform.KEEP_POSITION):
        for what, data in (("mesh", mesh), ("lattice", lattice)):
            if not isinstance(data, vtkPointSet):
                raise TypeError(f"vtkffd.torch: the {what} must be a vtkPointSet, not {type(data).__name__}")
        if outside_policy not in OUTSIDE_POLICIES:
            raise ValueError(f"vtkffd.torch: outside_policy {outside_policy!r} is none of "
                             "vtkFFDDeform.KEEP_POSITION (0), CLAMP_TO_EDGE (1), EXTRAPOLATE (2)")
        self.point_count = mesh.GetNumberOfPoints()
        self.control_point_count = lattice.GetNumberOfPoints()
        self._lattice = _copy_structure(lattice)
        points = vtkPoints()
        points.SetDataTypeToDouble()  # the data contract's lattice points
        points.SetNumberOfPoints(self.control_point_count)
        self._lattice.SetPoints(points)
        self._control_points = vtk_to_numpy(points.GetData()).reshape(-1, 3)  # a view
        self._deform = vtkFFDDeform()
        self._deform.SetInputData(mesh)
        self._deform.SetLatticeData(self._lattice)
        self._deform.SetOutsidePolicy(outside_policy)

        # The adjoint's mesh: float64 points, so that its weights are float64 on every backend (vtkFFDSensitivity
        # computes them on a CUDA device in the precision of the points it binds).
        self._mesh = _copy_structure(mesh)
        if self.point_count:
            rest = vtkPoints()
            rest.SetDataTypeToDouble()
            rest.DeepCopy(mesh.GetPoints())
            self._mesh.SetPoints(rest)
        gradient = vtkDoubleArray()
        gradient.SetName(GRADIENT_NAME)
        gradient.SetNumberOfComponents(3)
        gradient.SetNumberOfTuples(self.point_count)
        self._mesh.GetPointData().AddArray(gradient)
        self._gradient_array = gradient
        self._gradient = vtk_to_numpy(gradient).reshape(-1, 3)  # a view
        self._sensitivity = vtkFFDSensitivity()
        self._sensitivity.SetInputData(self._mesh)
        self._sensitivity.SetLatticeData(self._lattice)  # its weights depend on its rest state alone
        self._sensitivity.SetOutsidePolicy(outside_policy)
        self._sensitivity.SetInputArrayToProcess(0, 0, 0, vtkDataObject.FIELD_ASSOCIATION_POINTS, GRADIENT_NAME)

    def __call__(self, control_points):
        """The mesh's deformed points, a (mesh points, 3) tensor of control_points' dtype and device,
        differentiable with respect to control_points."""
        if not isinstance(control_points, torch.Tensor):
            raise TypeError(f"vtkffd.torch: control_points must be a torch.Tensor, not {type(control_points).__name__}")
        if control_points.dtype not in (torch.float32, torch.float64):
            raise TypeError(f"vtkffd.torch: control_points must be float32 or float64, not {control_points.dtype}")
        if tuple(control_points.shape) != (self.control_point_count, 3):
            raise ValueError(f"vtkffd.torch: control_points must have shape ({self.control_point_count}, 3), one row "
                             f"per lattice point, not {tuple(control_points.shape)}")
        return _DeformFunction.apply(self, control_points)

    @property
    def number_of_bindings(self):
        """How many times the mesh was bound to the lattice: by vtkFFDDeform and by vtkFFDSensitivity (1 each after
        any number of calls, unless the mesh's points or the lattice's rest state changed)."""
        return self._deform.GetNumberOfBindings() + self._sensitivity.GetNumberOfBindings()

    def forward_points(self, control_points):
        """vtkFFDDeform's points for control_points, as a tensor of their dtype and device (no autograd)."""
        _doubles(self._control_points, control_points)
        self._lattice.GetPoints().Modified()  # numpy wrote behind VTK's back
        double = control_points.dtype == torch.float64
        self._deform.SetOutputPointsPrecision(
            vtkFFDDeform.DOUBLE_PRECISION if double else vtkFFDDeform.SINGLE_PRECISION)
        meshio.checked(self._deform, self._deform.Update, "vtkffd.torch: vtkFFDDeform", ValueError)
        output = self._deform.GetOutput()
        if output.GetNumberOfPoints() != self.point_count:
            raise ValueError("vtkffd.torch: vtkFFDDeform gave no points")
        points = np.array(vtk_to_numpy(output.GetPoints().GetData()), dtype=np.float64 if double else np.float32)
        return torch.from_numpy(points.reshape(-1, 3)).to(control_points.device)

    def gradient(self, grad_output, like):
        """vtkFFDSensitivity's W^T grad_output, as a tensor of the dtype and device of `like`."""
        _doubles(self._gradient, grad_output)
        self._gradient_array.Modified()
        meshio.checked(self._sensitivity, self._sensitivity.Update, "vtkffd.torch: vtkFFDSensitivity", ValueError)
        sums = self._sensitivity.GetOutput().GetPointData().GetArray(self._sensitivity.GetSensitivityArrayName())
        if sums is None:
            raise ValueError("vtkffd.torch: vtkFFDSensitivity gave no gradient")
        return torch.from_numpy(np.array(vtk_to_numpy(sums)).reshape(-1, 3)).to(dtype=like.dtype, device=like.device)


class _DeformFunction(torch.autograd.Function):
    """Forward vtkFFDDeform, backward vtkFFDSensitivity (the transpose of the same linear map)."""

    @staticmethod
    def forward(ctx, deformation, control_points):
        ctx.deformation = deformation
        ctx.like = torch.empty(0, dtype=control_points.dtype, device=control_points.device)
        return deformation.forward_points(control_points)

    @staticmethod
    @once_differentiable
    def backward(ctx, grad_output):
        return None, ctx.deformation.gradient(grad_output, ctx.like)


def deform(mesh, lattice, control_points, outside_policy=vtkFFDDeform.KEEP_POSITION):
    """The points of `mesh` (a vtkPointSet at rest) deformed by `lattice` with its points at `control_points` (a
    (lattice points, 3) tensor, float32 or float64), under `outside_policy` (vtkFFDDeform's): a (mesh points, 3)
    tensor of control_points' dtype, whose gradient with respect to control_points is vtkFFDSensitivity's. Binds
    the mesh at each call: make a Deformation to call it often."""
    return Deformation(mesh, lattice, outside_policy)(control_points)
