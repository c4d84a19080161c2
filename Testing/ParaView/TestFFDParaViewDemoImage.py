# SPDX-License-Identifier: BSD-3-Clause
"""Image regression test of the ParaView demo (Examples/ParaView/deform_mesh.py), run by pvbatch in an X display:
its two screenshots (the bear with its rest Bernstein lattice, and deformed with the moved lattice) compared with
Testing/Data/Baseline/TestFFDParaViewDemo{Before,After}.png through vtkmodules.test.Testing (ParaView's copy).
TestFFDParaViewDemo{Before,After}_1.png are the alternates that vtkTesting also accepts (VTK's `_N` convention): the
control points that lie just behind the bear's surface are hidden by it on some CPUs and show through on others, as
llvmpipe's code for the CPU resolves the depth of the point spheres against the bear's surface.

    pvbatch --dr TestFFDParaViewDemoImage.py PLUGIN BASELINE_FOLDER TEMPORARY_FOLDER
"""
import importlib.util
import sys
from pathlib import Path

from vtkmodules.test import Testing
from vtkmodules.vtkIOImage import vtkPNGReader

# vtkTesting's image-difference error, as the other image tests: repeated renders under Xvfb/llvmpipe are
# identical; 0.05 absorbs small rasterization differences between Mesa versions.
THRESHOLD = 0.05
SIZE = 500  # pixels a side: small enough to be quick, large enough to show the lattice

plugin, baselines, temporary = sys.argv[1], Path(sys.argv[2]), Path(sys.argv[3])
demo_path = Path(__file__).resolve().parents[2] / "Examples" / "ParaView" / "deform_mesh.py"
spec = importlib.util.spec_from_file_location("paraview_demo", demo_path)
demo = importlib.util.module_from_spec(spec)
spec.loader.exec_module(demo)
demo.main(["bear", "--plugin", plugin, "--output-dir", str(temporary), "--size", str(SIZE), str(SIZE)])

Testing.VTK_TEMP_DIR = str(temporary)  # where a failing comparison leaves its images
for stage in ("before", "after"):
    screenshot = vtkPNGReader()
    screenshot.SetFileName(str(temporary / f"bear_{stage}.png"))
    screenshot.Update()
    Testing.compareImageWithSavedImage(screenshot, str(baselines / f"TestFFDParaViewDemo{stage.title()}.png"),
                                       threshold=THRESHOLD)
print("both screenshots match their baselines")
