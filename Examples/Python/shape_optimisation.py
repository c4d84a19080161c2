#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""Shape optimisation through the adjoint: morphs the bear towards a sphere with a cubic B-spline lattice.

The design variables are the displacements D of the control points of a cubic B-spline lattice (vtkFFDVoxelize
+ vtkFFDBuildLattice, 4x4x4 voxels, 7x7x7 control points) over the bear. The objective is

    J(D) = mean_i (|X_i - c| - r)^2  +  smoothness * sum over lattice edges (a, b) |D_a - D_b|^2

where X_i are the bear's points deformed by vtkFFDDeform and the sphere (c, r) is centred on the bear's centroid with
the bear's mean distance from it as radius: the fit pulls the surface onto the sphere, the penalty keeps the
displacement field smooth so that the bear bends rather than crumples. Its gradient is exact: the fit's gradient
g_i = dJ/dX_i at the deformed points becomes dJ/dD = W^T g through vtkFFDSensitivity (the adjoint of vtkFFDDeform,
one pass over the points, no finite differences), to which the penalty's gradient is added. SciPy's L-BFGS-B
minimises J with that gradient (jac=True); the objective is printed at every iteration, and two PNGs are written:
the bear at rest and the optimised bear, each inside the target sphere (wireframe) with its lattice.

The same gradient comes from vtkffd.torch.deform (PyTorch) or vtkffd.sparse.weight_matrix (W.T @ g); this
example uses the filter itself.

Run it with Debian's /usr/bin/python3 (with python3-scipy), the built package on PYTHONPATH and an X server (Xvfb
will do):
    PYTHONPATH=build/lib/python3/dist-packages Utilities/with-display.sh /usr/bin/python3 \\
        Examples/Python/shape_optimisation.py
It exits non-zero when the objective does not decrease or a PNG cannot be written.
"""
import argparse
import sys
import time
from pathlib import Path

import numpy as np
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy
from vtkmodules.vtkCommonDataModel import vtkDataObject, vtkStructuredGrid
from vtkmodules.vtkFiltersSources import vtkSphereSource
from vtkmodules.vtkRenderingCore import vtkActor, vtkPolyDataMapper, vtkRenderer

# The mesh reading and rendering of the demo (this folder is on sys.path when run as a script).
from deform_mesh import REPOSITORY, read_mesh, union_bounds, vtkffd, write_png

try:
    from scipy.optimize import minimize
except ImportError as error:
    sys.exit(f"{error}: this example needs SciPy (Debian: apt-get install python3-scipy)")

DIVISIONS = (4, 4, 4)  # voxels per axis: a cubic B-spline lattice of 7x7x7 control points
GRADIENT = "dJdX"  # the mesh's point array that carries the fit's gradient into vtkFFDSensitivity


def parse_arguments():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--iterations", type=int, default=60, help="L-BFGS-B iterations at most (default: 60)")
    parser.add_argument("--smoothness", type=float, default=1e-4,
                        help="weight of the smoothness penalty (default: 1e-4)")
    parser.add_argument("--output-dir", type=Path, default=REPOSITORY / "build" / "demo",
                        help="folder for the PNGs (default: build/demo in the repository)")
    parser.add_argument("--size", type=int, nargs=2, default=(800, 800), metavar=("WIDTH", "HEIGHT"),
                        help="image size in pixels (default: 800 800)")
    arguments = parser.parse_args()
    if arguments.iterations < 1 or arguments.smoothness < 0:
        parser.error("--iterations must be at least 1 and --smoothness at least 0")
    return arguments


class SphereFit:
    """J(D) and dJ/dD for the bear's lattice: vtkFFDDeform forwards, vtkFFDSensitivity backwards. Both filters are
    kept, so the bear is bound to the lattice once (by each) for the whole optimisation."""

    def __init__(self, mesh, lattice, smoothness):
        self.lattice = lattice
        self.rest = vtk_to_numpy(lattice.GetPointData().GetArray("RestPosition")).copy()
        self.points = vtk_to_numpy(lattice.GetPoints().GetData())  # a view: writing it moves the lattice
        self.dims = lattice.GetDimensions()  # (nI, nJ, nK): numpy sees [k, j, i]
        self.smoothness = smoothness
        x = vtk_to_numpy(mesh.GetPoints().GetData()).astype(np.float64)
        self.center = x.mean(axis=0)
        self.radius = float(np.linalg.norm(x - self.center, axis=1).mean())

        self.deform = vtkffd.vtkFFDDeform()
        self.deform.SetInputData(mesh)
        self.deform.SetLatticeData(lattice)
        self.deform.SetOutputPointsPrecision(vtkffd.vtkFFDDeform.DOUBLE_PRECISION)

        self.mesh = mesh.NewInstance()  # the bear at rest with the gradient array; `mesh` itself stays as it is
        self.mesh.ShallowCopy(mesh)
        self.gradient = numpy_to_vtk(np.zeros((mesh.GetNumberOfPoints(), 3)), deep=True)
        self.gradient.SetName(GRADIENT)
        self.mesh.GetPointData().AddArray(self.gradient)
        self.sensitivity = vtkffd.vtkFFDSensitivity()
        self.sensitivity.SetInputData(self.mesh)
        self.sensitivity.SetLatticeData(lattice)
        self.sensitivity.SetInputArrayToProcess(0, 0, 0, vtkDataObject.FIELD_ASSOCIATION_POINTS, GRADIENT)

    def deformed(self, D):
        """The bear's points for displacements D (control points x 3, flat)."""
        self.points[...] = self.rest + D.reshape(-1, 3)
        self.lattice.GetPoints().Modified()  # numpy wrote behind VTK's back
        self.deform.Update()
        return vtk_to_numpy(self.deform.GetOutput().GetPoints().GetData())

    def penalty(self, D):
        """smoothness * sum |D_a - D_b|^2 over the lattice's edges, and its gradient."""
        grid = D.reshape(self.dims[2], self.dims[1], self.dims[0], 3)
        value, gradient = 0.0, np.zeros_like(grid)
        for axis in range(3):
            step = np.diff(grid, axis=axis)
            value += float(np.sum(step * step))
            pad = [(0, 0)] * 4
            pad[axis] = (1, 0)
            into = np.pad(step, pad)  # D_p - D_(p-1), 0 at the first point
            pad[axis] = (0, 1)
            out_of = np.pad(step, pad)  # D_(p+1) - D_p, 0 at the last point
            gradient += 2.0 * (into - out_of)
        return self.smoothness * value, self.smoothness * gradient.ravel()

    def fit(self, D):
        """The mean squared distance of the deformed points to the sphere, and its gradient at them."""
        offset = self.deformed(D) - self.center
        distance = np.linalg.norm(offset, axis=1)
        gap = distance - self.radius
        value = float(np.mean(gap * gap))
        gradient = (2.0 / len(gap)) * (gap / np.maximum(distance, 1e-300))[:, None] * offset
        return value, gradient

    def __call__(self, D):
        """J(D) and dJ/dD, for scipy.optimize.minimize(jac=True)."""
        fit, g = self.fit(D)
        vtk_to_numpy(self.gradient)[...] = g
        self.gradient.Modified()
        self.sensitivity.Update()  # dfit/dD = W^T g
        adjoint = vtk_to_numpy(self.sensitivity.GetOutput().GetPointData().GetArray("Sensitivity")).ravel()
        penalty, penalty_gradient = self.penalty(D)
        return fit + penalty, adjoint + penalty_gradient


def build_lattice(mesh):
    """The cubic B-spline lattice over the bear, dense (a grid the penalty indexes), our own copy."""
    voxelize = vtkffd.vtkFFDVoxelize()
    voxelize.SetInputData(mesh)
    voxelize.SetDivisions(*DIVISIONS)
    build = vtkffd.vtkFFDBuildLattice()
    build.SetInputConnection(voxelize.GetOutputPort())
    build.SetBasisToCubicBSpline()
    build.SetLatticeFormToDense()
    build.Update()
    if build.GetOutput().GetNumberOfPoints() == 0:
        sys.exit("the lattice could not be built (see the errors above)")
    lattice = vtkStructuredGrid()
    lattice.DeepCopy(build.GetOutput())
    return lattice


def render(output_path, size, mesh, lattice, sphere, camera_bounds):
    """The mesh (ivory), its lattice and the target sphere (a blue wireframe), offscreen, as a PNG."""
    renderer = vtkRenderer()
    for data, color, wireframe in ((mesh, (0.93, 0.90, 0.82), False), (sphere, (0.20, 0.35, 0.75), True)):
        mapper = vtkPolyDataMapper()
        mapper.SetInputData(data)
        actor = vtkActor()
        actor.SetMapper(mapper)
        actor.GetProperty().SetColor(*color)
        if wireframe:
            actor.GetProperty().SetRepresentationToWireframe()
            actor.GetProperty().SetOpacity(0.6)
        renderer.AddActor(actor)
    lattice_actor = vtkffd.vtkFFDLatticeActor()  # red control points, dark grey edges
    lattice_actor.SetInputData(lattice)
    lattice_actor.SetPointRadius(0.004 * np.linalg.norm(np.ptp(vtk_to_numpy(lattice.GetPoints().GetData()), axis=0)))
    lattice_actor.GetEdgeProperty().SetLineWidth(1.0)
    lattice_actor.GetEdgeProperty().SetOpacity(0.35)  # the lattice as context: the mesh and the sphere in front
    lattice_actor.ShowCulledPointsOff()
    renderer.AddActor(lattice_actor)
    renderer.GradientBackgroundOn()
    renderer.SetBackground(0.72, 0.76, 0.82)
    renderer.SetBackground2(0.98, 0.98, 0.99)
    camera = renderer.GetActiveCamera()
    camera.SetPosition(0.0, 0.0, 1.0)
    camera.SetFocalPoint(0.0, 0.0, 0.0)
    camera.SetViewUp(0.0, 1.0, 0.0)
    camera.Azimuth(30.0)
    camera.Elevation(15.0)
    renderer.ResetCamera(camera_bounds)  # the same framing before and after, on the mesh and the sphere
    camera.Zoom(1.15)
    write_png(renderer, size, output_path)


def sphere_of(center, radius):
    source = vtkSphereSource()
    source.SetCenter(*center)
    source.SetRadius(radius)
    source.SetThetaResolution(24)
    source.SetPhiResolution(12)
    source.Update()
    return source.GetOutput()


def main():
    arguments = parse_arguments()
    name, mesh = read_mesh("bear")
    lattice = build_lattice(mesh)
    rest_lattice = vtkStructuredGrid()
    rest_lattice.DeepCopy(lattice)
    problem = SphereFit(mesh, lattice, arguments.smoothness)
    n_i, n_j, n_k = problem.dims
    print(f"{name}: {mesh.GetNumberOfPoints()} vertices, cubic B-spline lattice of {n_i}x{n_j}x{n_k} control "
          f"points; target: the sphere of radius {problem.radius:.4g} about the centroid")

    history = []  # J at each iteration's point, for the printout and the check

    def report(D):
        history.append(problem(D)[0])  # the point scipy accepted; vtkFFDDeform is fast enough to evaluate again
        print(f"iteration {len(history):3d}: J = {history[-1]:.6g}")

    D0 = np.zeros(problem.rest.size)
    initial = problem(D0)[0]
    print(f"iteration   0: J = {initial:.6g}")
    start = time.perf_counter()
    result = minimize(problem, D0, jac=True, method="L-BFGS-B", callback=report,
                      options={"maxiter": arguments.iterations, "gtol": 1e-10})  # J is about 0.01: finer than 1e-5
    elapsed = time.perf_counter() - start
    final, _ = problem(result.x)  # also leaves the lattice and the deformed bear at the optimum
    fit, _ = problem.fit(result.x)
    print(f"L-BFGS-B: {result.nit} iterations, {result.nfev} evaluations of J and dJ/dD in {elapsed:.2f} s "
          f"({result.message})")
    print(f"J: {initial:.6g} -> {final:.6g}; RMS distance to the sphere: {np.sqrt(initial):.4g} -> {np.sqrt(fit):.4g} "
          f"({100.0 * np.sqrt(fit) / problem.radius:.2f} % of the radius)")

    deformed = problem.deform.GetOutput()
    sphere = sphere_of(problem.center, problem.radius)
    arguments.output_dir.mkdir(parents=True, exist_ok=True)
    before_png = arguments.output_dir / f"{name}_optimisation_before.png"
    after_png = arguments.output_dir / f"{name}_optimisation_after.png"
    camera_bounds = union_bounds(mesh, deformed, sphere)  # the lattice reaches beyond the picture
    render(before_png, arguments.size, mesh, rest_lattice, sphere, camera_bounds)
    render(after_png, arguments.size, deformed, lattice, sphere, camera_bounds)
    print(f"wrote {before_png} and {after_png}")

    if not final < initial:
        sys.exit(f"the objective did not decrease: {initial:.6g} -> {final:.6g}")
    missing = [str(png) for png in (before_png, after_png) if not png.is_file() or png.stat().st_size == 0]
    if missing:
        sys.exit(f"no image written: {', '.join(missing)}")


if __name__ == "__main__":
    main()
