# SPDX-License-Identifier: BSD-3-Clause
"""The VoxelFFD pipeline in paraview.simple, for test_paraview.py: run by pvbatch, alone or under MPI.

    pvbatch --dr paraview_pipeline.py PLUGIN MESH.vtp OUTPUT_FOLDER
    mpirun -np N pvbatch --dr paraview_pipeline.py PLUGIN MESH.vtp OUTPUT_FOLDER

The mesh gets its point ids (GenerateIds) and, with several processes, is split among them (RedistributeDataSet),
so that every process holds a piece, whose points shared with other pieces are marked (GenerateGlobalIds).
Then FFDVoxelize (principal axes: the frame that needs exact sums to be the same on every partition),
FFDBuildLattice (cubic B-spline, sparse), a Programmable Filter that moves every control point (lattice_moves.py)
and FFDDeform; and FFDBuildTetrahedralLattice, its nodes moved the same way, and FFDDeform (Extrapolate).
Written to OUTPUT_FOLDER (VTK XML, raw binary, so that every double is exact): the voxel grid and the lattices as
the first process holds them (each process holds the same), and every process's piece of the mesh and of the
deformed meshes (NAME_RANK).
"""
import sys
from pathlib import Path

from paraview import servermanager
from paraview.simple import FetchData, GenerateIds, LoadPlugin, ProgrammableFilter, XMLPolyDataReader
from vtkmodules.vtkIOXML import vtkXMLDataSetWriter

LoadPlugin(sys.argv[1], ns=globals())
# Not `output`: in pvbatch's single process a Programmable Filter's script runs in this module's namespace, and
# it defines and deletes `output` (and imports ParaView's array algorithms: min, max, ...).
mesh_file, folder = sys.argv[2], Path(sys.argv[3])
processes = servermanager.vtkProcessModule.GetProcessModule().GetNumberOfLocalPartitions()

# A copy of the lattice whose points lattice_moves.py moves (the same on every process, in pvbatch's Python).
MOVE = f"""
import sys
sys.path.insert(0, {str(Path(__file__).resolve().parent)!r})
from lattice_moves import move_control_points
lattice = self.GetOutputDataObject(0)
lattice.DeepCopy(self.GetInputDataObject(0, 0))
move_control_points(lattice)
"""

mesh = GenerateIds(Input=XMLPolyDataReader(FileName=[mesh_file]))
mesh.PointIdsArrayName = "MeshPointId"
mesh.GenerateCellIds = 0
if processes > 1:
    from paraview.simple import GenerateGlobalIds, RedistributeDataSet
    # Pieces of cells share the points on their borders: GenerateGlobalIds marks every copy but one as a ghost.
    mesh = GenerateGlobalIds(Input=RedistributeDataSet(Input=mesh))

voxels = FFDVoxelize(Input=mesh, Divisions=[5, 6, 4], FrameMode="Principal Axes")  # noqa: F821
lattice = FFDBuildLattice(Input=voxels, Basis="Cubic B-Spline", LatticeForm="Sparse")  # noqa: F821
moved = ProgrammableFilter(Input=lattice, Script=MOVE)
deformed = FFDDeform(Input=mesh, Lattice=moved)  # noqa: F821
tetrahedra = FFDBuildTetrahedralLattice(Input=mesh, SubdivisionLevels=1)  # noqa: F821
moved_tetrahedra = ProgrammableFilter(Input=tetrahedra, Script=MOVE)
tetrahedral_deformed = FFDDeform(Input=mesh, Lattice=moved_tetrahedra, OutsidePolicy="Extrapolate")  # noqa: F821

folder.mkdir(parents=True, exist_ok=True)


def write(data, name):
    writer = vtkXMLDataSetWriter()
    writer.SetDataModeToAppended()
    writer.EncodeAppendedDataOff()
    writer.SetInputData(data)
    writer.SetFileName(str(folder / f"{name}.{writer.GetDefaultFileExtension()}"))
    if not writer.Write():
        sys.exit(f"could not write {writer.GetFileName()}")


# The replicated outputs as the first process holds them; the distributed ones piece by piece, name_rank.
for proxy, name in ((voxels, "voxels"), (moved, "lattice"), (moved_tetrahedra, "tetrahedra")):
    proxy.UpdatePipeline()
    write(FetchData(proxy)[0], name)
for proxy, name in ((mesh, "mesh"), (deformed, "deformed"), (tetrahedral_deformed, "tetrahedral_deformed")):
    proxy.UpdatePipeline()
    for rank, piece in FetchData(proxy).items():
        write(piece, f"{name}_{rank}")
