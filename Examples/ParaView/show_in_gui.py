# SPDX-License-Identifier: BSD-3-Clause
"""The ParaView demo's pipeline (deform_mesh.py) built in the ParaView GUI, for a user to explore: the bear, its
voxels, the Bernstein lattice, the moved lattice and the deformed bear appear in the Pipeline Browser, the
deformed bear and the moved lattice in the view.

    paraview --plugins=build/paraview/lib/paraview-5.11/plugins/VoxelFFD/VoxelFFD.so \\
      --script=Examples/ParaView/show_in_gui.py

run from the repository's folder: the GUI runs a --script as a string, with no __file__ to find the demo by.
"""
import importlib.util
from pathlib import Path

from paraview.simple import GetActiveViewOrCreate, Render, SetActiveSource

# The demo by its path: beside this file where Python knows it, else from the repository's folder.
here = Path(__file__).resolve().parent if "__file__" in globals() else Path.cwd() / "Examples" / "ParaView"
demo_path = here / "deform_mesh.py"
if not demo_path.is_file():
    raise FileNotFoundError(f"{demo_path} is missing: run the GUI from the repository's folder")
spec = importlib.util.spec_from_file_location("paraview_demo", demo_path)
demo = importlib.util.module_from_spec(spec)
spec.loader.exec_module(demo)

demo.load_plugin(demo.PLUGIN)
pipeline = demo.build_pipeline(demo.mesh_path("bear"))
view = GetActiveViewOrCreate("RenderView")
view.OrientationAxesVisibility = 0
demo.show_scene(view, pipeline["deformed"], pipeline["moved"])
demo.frame_camera(view, demo.union_bounds(pipeline["deformed"], pipeline["moved"]))
SetActiveSource(pipeline["deformed"])
Render(view)
