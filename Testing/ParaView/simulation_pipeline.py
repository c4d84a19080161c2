# SPDX-License-Identifier: BSD-3-Clause
"""The dynamics pipeline in paraview.simple, for test_paraview.py (Dynamics): run by pvbatch.

    pvbatch --dr simulation_pipeline.py PLUGIN MESH.vtp OUTPUT_FOLDER

The bear, FFDVoxelize (5 divisions), FFDBuildLattice (trilinear), FFD Simulate Lattice (gravity, a plane below the
bear as collider, EndTime 1 s) and FFDDeform (Lattice: the simulation), asked for each time of TIMES twice: by
UpdatePipeline(time), and by the animation scene rendering a view (as the GUI plays the animation). Written to
OUTPUT_FOLDER: report.json (the animation's time range; per time, the deformed mesh's bounds by either way, as
ParaView's data information reports them), and per time i the simulated lattice (lattice_i) and the deformed mesh
(deformed_i) of UpdatePipeline, in VTK XML raw binary, so that every double is exact.
"""
import json
import sys
from pathlib import Path

from paraview.simple import GetActiveViewOrCreate, GetAnimationScene, LoadPlugin, Render, Show, XMLPolyDataReader
from vtkmodules.vtkIOXML import vtkXMLDataSetWriter

TIMES = [0.0, 0.25, 0.5, 1.0]

LoadPlugin(sys.argv[1], ns=globals())
mesh_file, folder = sys.argv[2], Path(sys.argv[3])
folder.mkdir(parents=True, exist_ok=True)

mesh = XMLPolyDataReader(FileName=[mesh_file])
voxels = FFDVoxelize(Input=mesh, Divisions=[5, 5, 5])  # noqa: F821
lattice = FFDBuildLattice(Input=voxels, Basis="Trilinear")  # noqa: F821
simulation = FFDSimulateLattice(Input=lattice, Mesh=mesh, EndTime=1.0, Gravity=[0.0, 0.0, -9.81])  # noqa: F821
simulation.Collider = "Plane"
lattice.UpdatePipeline()
bottom = lattice.GetDataInformation().GetBounds()[4]
simulation.Collider.Origin = [0.0, 0.0, bottom - 0.25]
simulation.Collider.Normal = [0.0, 0.0, 1.0]
deformed = FFDDeform(Input=mesh, Lattice=simulation)  # noqa: F821


def write(proxy, name):
    """The output of `proxy` as pvbatch's single process holds it (the algorithm itself)."""
    writer = vtkXMLDataSetWriter()
    writer.SetDataModeToAppended()
    writer.EncodeAppendedDataOff()
    writer.SetInputData(proxy.GetClientSideObject().GetOutputDataObject(0))
    writer.SetFileName(str(folder / f"{name}.{writer.GetDefaultFileExtension()}"))
    if not writer.Write():
        sys.exit(f"could not write {writer.GetFileName()}")


report = {"times": TIMES, "updated": [], "animated": []}
for i, time in enumerate(TIMES):
    deformed.UpdatePipeline(time=time)
    report["updated"].append(list(deformed.GetDataInformation().GetBounds()))
    write(simulation, f"lattice_{i}")
    write(deformed, f"deformed_{i}")

view = GetActiveViewOrCreate("RenderView")
Show(deformed, view)
scene = GetAnimationScene()
scene.UpdateAnimationUsingDataTimeSteps()
report["time_range"] = [scene.StartTime, scene.EndTime]
for time in TIMES:
    scene.AnimationTime = time
    Render(view)
    report["animated"].append(list(deformed.GetDataInformation().GetBounds()))
(folder / "report.json").write_text(json.dumps(report))
