#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""A mesh split among MPI processes (docs/mpi.md): with vtkMPIController as the global controller,
vtkFFDVoxelize on 2 and 3 processes, each holding a piece of the bear (every N-th point, in reverse order),
gives every process the voxel grid that one process makes of the whole bear, bit for bit (axis-aligned and
principal-axes frames); each process builds the same lattice, deforms its piece, and the pieces put together are
the serial deformation, bit for bit. The same for vtkFFDBuildTetrahedralLattice: the same nodes, tetrahedra and
`Active` on every process as in one. Exact equality is the claim: bounds are reduced by min and max, the principal
axes' and the centroid's sums are exact (rounded once), the voxels are a sorted union, the hull is that of the
processes' hull vertices in lexicographic order, and a node is active where it is on some process.

Runs itself under `mpirun -np N` (Debian's openmpi-bin, mpi4py); run with Debian's /usr/bin/python3,
PYTHONPATH=<build>/lib/python3/dist-packages and VOXELFFD_MESH_DIR (ctest sets both).
"""
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

import numpy as np
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy
from vtkmodules.vtkCommonCore import vtkPoints
from vtkmodules.vtkCommonDataModel import vtkPolyData, vtkStructuredGrid

import vtkffd
from ffdtesting import points_of, read_mesh  # the same folder

FRAME_MODES = (int(vtkffd.vtkFFDVoxelize.AXIS_ALIGNED), int(vtkffd.vtkFFDVoxelize.PRINCIPAL_AXES))
TETRAHEDRA = "tetrahedra"  # the third case, next to the two frame modes


def point_cloud(points):
    cloud = vtkPolyData()
    vtk_points = vtkPoints()
    vtk_points.SetData(numpy_to_vtk(np.ascontiguousarray(points), deep=True))
    cloud.SetPoints(vtk_points)
    return cloud


def deformed(points, lattice):
    """`points` deformed by `lattice` (vtkFFDDeform on the CPU), as an (N, 3) array."""
    deform = vtkffd.vtkFFDDeform()
    deform.SetInputData(point_cloud(points))
    deform.SetLatticeData(lattice)
    deform.SetBackendToCPU()
    deform.Update()
    return points_of(deform.GetOutput())


def pipeline(points, frame_mode):
    """Voxelize `points` (3 x 4 x 5 voxels), build the tricubic Bezier lattice (dense), move every control point
    by a pseudo-random vector the same on every process, and deform `points`. Returns (voxel grid's frame,
    VoxelIndex, deformed points)."""
    voxelize = vtkffd.vtkFFDVoxelize()
    voxelize.SetInputData(point_cloud(points))
    voxelize.SetDivisions(3, 4, 5)
    voxelize.SetFrameMode(frame_mode)
    build = vtkffd.vtkFFDBuildLattice()
    build.SetInputConnection(voxelize.GetOutputPort())
    build.SetBasisToTricubicBezier()
    build.SetLatticeFormToDense()
    build.Update()
    lattice = vtkStructuredGrid()
    lattice.DeepCopy(build.GetOutput())
    moved = vtk_to_numpy(lattice.GetPoints().GetData())
    moved += np.random.default_rng(19).uniform(-0.02, 0.02, moved.shape)
    grid = voxelize.GetOutput()
    return (vtk_to_numpy(grid.GetFieldData().GetArray("FFDFrame")).copy(),
            vtk_to_numpy(grid.GetCellData().GetArray("VoxelIndex")).copy(), deformed(points, lattice))


def tetrahedral_pipeline(points):
    """vtkFFDBuildTetrahedralLattice of `points` (subdivided once), its nodes moved by a pseudo-random vector the
    same on every process, and `points` deformed. Returns (nodes, tetrahedra and Active, deformed points)."""
    build = vtkffd.vtkFFDBuildTetrahedralLattice()
    build.SetInputData(point_cloud(points))
    build.SetSubdivisionLevels(1)
    build.Update()
    lattice = build.GetOutput()
    structure = np.concatenate([vtk_to_numpy(lattice.GetCells().GetConnectivityArray()),
                                vtk_to_numpy(lattice.GetPointData().GetArray("Active"))])
    nodes = points_of(lattice)
    moved = vtk_to_numpy(lattice.GetPoints().GetData())
    moved += np.random.default_rng(23).uniform(-0.01, 0.01, moved.shape)
    return nodes, structure, deformed(points, lattice)


def run(case, points):
    return tetrahedral_pipeline(points) if case == TETRAHEDRA else pipeline(points, case)


def worker(output):
    """One process of `mpirun`: its piece of the bear through the pipeline; rank 0 saves what every process got."""
    from mpi4py import MPI  # initializes MPI before VTK's controller uses it
    from vtkmodules.vtkParallelCore import vtkMultiProcessController
    from vtkmodules.vtkParallelMPI import vtkMPIController

    controller = vtkMPIController()
    controller.Initialize()
    vtkMultiProcessController.SetGlobalController(controller)
    comm = MPI.COMM_WORLD
    rank, size = comm.Get_rank(), comm.Get_size()
    bear = points_of(read_mesh("bear"))
    ids = np.arange(len(bear))[rank::size][::-1]  # every size-th point, in reverse order
    results = {}
    for mode in (*FRAME_MODES, TETRAHEDRA):
        placement, structure, deformed = run(mode, bear[ids])
        placements, structures = comm.gather(placement, root=0), comm.gather(structure, root=0)
        pieces, piece_ids = comm.gather(deformed, root=0), comm.gather(ids, root=0)
        if rank == 0:
            together = np.empty_like(bear)
            together[np.concatenate(piece_ids)] = np.concatenate(pieces)
            results[mode] = (placements, structures, together)
    if rank == 0:
        np.save(output, np.array([results], dtype=object), allow_pickle=True)
    controller.Finalize(1)


class TestSeveralProcesses(unittest.TestCase):
    def test_two_and_three_processes_give_the_serial_result(self):
        mpirun = shutil.which("mpirun")
        self.assertIsNotNone(mpirun, "mpirun is missing: the set-up installs openmpi-bin")
        bear = points_of(read_mesh("bear"))
        serial = {mode: run(mode, bear) for mode in (*FRAME_MODES, TETRAHEDRA)}
        for processes in (2, 3):
            with tempfile.TemporaryDirectory() as folder:
                output = os.path.join(folder, "results.npy")
                # Containers often forbid the cross-memory attach of Open MPI's shared-memory transport.
                environment = dict(os.environ, OMPI_MCA_btl_vader_single_copy_mechanism="none")
                subprocess.run([mpirun, "--allow-run-as-root", "--oversubscribe", "-np", str(processes),
                                sys.executable, os.path.abspath(__file__), "--worker", output],
                               check=True, timeout=120, env=environment)
                results = np.load(output, allow_pickle=True)[0]
            for mode in (*FRAME_MODES, TETRAHEDRA):
                placement, structure, deformed = serial[mode]
                placements, structures, together = results[mode]
                for rank in range(processes):
                    with self.subTest(processes=processes, mode=mode, rank=rank):
                        np.testing.assert_array_equal(placements[rank], placement)
                        np.testing.assert_array_equal(structures[rank], structure)
                with self.subTest(processes=processes, mode=mode):
                    np.testing.assert_array_equal(together, deformed)
                    self.assertGreater(np.abs(deformed - bear).max(), 1e-3)  # the lattice did move points


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "--worker":
        worker(sys.argv[2])
    else:
        unittest.main()
