# SPDX-License-Identifier: BSD-3-Clause
"""The weights of a deformation as a SciPy sparse matrix, for optimisers that assemble their own systems.

vtkFFDDeform moves each point x_i of a mesh to X_i = x_i + sum_c W[i, c] (P_c - P_c^rest): W (points x control
points, float64) is linear in nothing else, so X = x + W @ (P - P_rest), the gradient at the control points of an
objective with gradient g at the deformed points is W.T @ g (what vtkFFDSensitivity computes), and the
Jacobian-vector product under a control-point direction dP is W @ dP. weight_matrix() returns W as a
scipy.sparse.csr_matrix made by vtkFFDWeightMatrix (C++, in parallel): a row per mesh point, a column per lattice
point (its point id), a row's columns in increasing order, every control point of the point's support stored (a
weight of 0 included), an empty row for a point that keeps its position outside the lattice.

SciPy is imported when weight_matrix() is called, not with this module: `import vtkffd` never needs it.
"""
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkCommonDataModel import vtkPointSet

from . import meshio, vtkFFDDeform, vtkFFDWeightMatrix

OUTSIDE_POLICIES = (vtkFFDDeform.KEEP_POSITION, vtkFFDDeform.CLAMP_TO_EDGE, vtkFFDDeform.EXTRAPOLATE)


def weight_matrix(mesh, lattice, outside_policy=vtkFFDDeform.KEEP_POSITION):
    """W as a scipy.sparse.csr_matrix of shape (mesh points, lattice points), float64: vtkFFDDeform's weights for
    `mesh` (a vtkPointSet at rest, vtkFFDDeform's input 0) and `lattice` (its input 1: a grid lattice of
    vtkFFDBuildLattice, dense or sparse, any basis, or a tetrahedral lattice) under `outside_policy`
    (vtkFFDDeform.KEEP_POSITION, CLAMP_TO_EDGE, or EXTRAPOLATE for tetrahedral lattices). The matrix's arrays are
    views of the ones vtkFFDWeightMatrix filled (scipy may copy the indices into int32). Raises TypeError for
    inputs that are not vtkPointSets, ValueError for a policy that is none of these or what vtkFFDWeightMatrix
    reports (a malformed lattice, EXTRAPOLATE with a grid lattice, too little memory), ImportError without SciPy."""
    try:
        import scipy.sparse
    except ImportError as error:
        raise ImportError(f"vtkffd.sparse.weight_matrix needs SciPy ({error}): install python3-scipy (Debian) "
                          "or scipy (pip)") from error
    for what, data in (("mesh", mesh), ("lattice", lattice)):
        if not isinstance(data, vtkPointSet):
            raise TypeError(f"weight_matrix: the {what} must be a vtkPointSet, not {type(data).__name__}")
    if outside_policy not in OUTSIDE_POLICIES:
        raise ValueError(f"weight_matrix: outside_policy {outside_policy!r} is none of vtkFFDDeform.KEEP_POSITION "
                         "(0), CLAMP_TO_EDGE (1), EXTRAPOLATE (2)")
    matrix = vtkFFDWeightMatrix()
    matrix.SetOutsidePolicy(outside_policy)
    computed = []
    meshio.checked(matrix, lambda: computed.append(matrix.Compute(mesh, lattice)), "weight_matrix", ValueError)
    if not computed[0]:
        raise ValueError("weight_matrix: vtkFFDWeightMatrix failed without a message")
    shape = (matrix.GetNumberOfRows(), matrix.GetNumberOfColumns())
    return scipy.sparse.csr_matrix((vtk_to_numpy(matrix.GetValues()), vtk_to_numpy(matrix.GetColumnIds()),
                                    vtk_to_numpy(matrix.GetRowOffsets())), shape=shape)
