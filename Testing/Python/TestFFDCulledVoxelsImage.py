#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""Image regression test of the paper's Figures 3 and 10 layout ("Local Voxel Regions" on a large mesh): the
armadillo (the largest test mesh, 26002 points) voxelized with 10 x 10 x 10 voxels and a TRILINEAR lattice of
11 x 11 x 11 = 1331 control points. Only the active voxels are drawn (blue boxes, vtkFFDVoxelize hides the
others); culled control points are light grey. One active control point, the one nearest to the mesh's upper-left
extreme point (largest y - x/2), is dragged up and outwards; one culled control point (the corner of the frame, beyond the mesh) is dragged as well: as
the circled point of Figure 10, it moves no mesh point at all. The armadillo is coloured by how far its points
moved. Compared with Testing/Data/Baseline/TestFFDCulledVoxelsImage.png through vtkmodules.test.Testing.

Run: /usr/bin/python3 TestFFDCulledVoxelsImage.py -B <baseline folder> -T <temporary folder>, with
PYTHONPATH=<build>/lib/python3/dist-packages and VOXELFFD_MESH_DIR (ctest sets all of them).
"""
import numpy as np
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy
from vtkmodules.vtkRenderingCore import vtkActor, vtkPolyDataMapper, vtkRenderer
import vtkmodules.vtkRenderingOpenGL2  # noqa: F401  (the OpenGL render window behind vtkRenderWindow)
from vtkmodules.test import Testing

import vtkffd
from ffdtesting import build_lattice, offscreen_window, read_mesh  # the same folder

# vtkTesting's image-difference error, as the C++ image tests: repeated renders under Xvfb/llvmpipe are
# identical; 0.05 absorbs small rasterization differences between Mesa versions.
THRESHOLD = 0.05


class TestFFDCulledVoxelsImage(Testing.vtkTest):
    def test_culled_voxels(self):
        mesh = read_mesh("armadillo")
        voxelize, build, lattice = build_lattice(mesh, (10, 10, 10), vtkffd.vtkFFDBuildLattice.TRILINEAR)
        self.assertEqual(lattice.GetNumberOfPoints(), 1331)
        active_voxels = voxelize.GetNumberOfActiveVoxels()
        active_points = build.GetNumberOfActiveControlPoints()
        print("armadillo: %d points, 1331 control points, %d active voxels, %d active control points"
              % (mesh.GetNumberOfPoints(), active_voxels, active_points))
        # The figure's point: a large share of a 10^3 grid around a mesh is empty and culled.
        self.assertLess(active_voxels, 1000 * 6 // 10)
        self.assertLess(active_points, 1331)

        frame = vtk_to_numpy(lattice.GetFieldData().GetArray("FFDFrame"))
        s, t, u = frame[3:6], frame[6:9], frame[9:12]
        active = vtk_to_numpy(lattice.GetPointData().GetArray("Active"))
        points = vtk_to_numpy(lattice.GetPoints().GetData()).reshape(11, 11, 11, 3)  # [k, j, i], a view

        def point_id(i, j, k):
            return i + 11 * (j + 11 * k)

        # The active control point nearest to the mesh's upper-left extreme point (largest y - x/2).
        mesh_points = vtk_to_numpy(mesh.GetPoints().GetData())
        hand = mesh_points[np.argmax(mesh_points[:, 1] - 0.5 * mesh_points[:, 0])]
        flat = points.reshape(-1, 3)
        distances = np.linalg.norm(flat - hand, axis=1)
        distances[active == 0] = np.inf
        moved_active = int(np.argmin(distances))
        flat[moved_active] += -0.12 * s + 0.10 * t
        culled_corner = point_id(10, 10, 10)
        self.assertEqual(active[culled_corner], 0, "the frame's far corner should be culled")
        flat[culled_corner] += 0.08 * s + 0.08 * t + 0.08 * u
        lattice.GetPoints().Modified()

        deform = vtkffd.vtkFFDDeform()
        deform.SetInputData(mesh)
        deform.SetLatticeData(lattice)
        deform.Update()
        deformed = deform.GetOutput()
        displacement = np.linalg.norm(vtk_to_numpy(deformed.GetPoints().GetData()) - mesh_points, axis=1)
        moved = int(np.count_nonzero(displacement > 0.0))
        print("mesh points moved: %d of %d" % (moved, mesh.GetNumberOfPoints()))
        self.assertGreater(moved, 0)
        self.assertLess(moved, mesh.GetNumberOfPoints() // 10)  # 8 voxels of 1000: a local region

        # The culled point alone moves nothing: the same lattice without the active point's move.
        flat[moved_active] = vtk_to_numpy(lattice.GetPointData().GetArray("RestPosition"))[moved_active]
        lattice.GetPoints().Modified()
        deform.Update()
        self.assertEqual(deform.GetNumberOfBindings(), 1)  # only the points moved: the binding is cached
        only_culled = vtk_to_numpy(deform.GetOutput().GetPoints().GetData())
        self.assertTrue(np.array_equal(only_culled, mesh_points), "moving a culled control point moved the mesh")

        # The picture: the deformed mesh of both moves, coloured by displacement.
        flat[moved_active] += -0.12 * s + 0.10 * t
        lattice.GetPoints().Modified()
        deform.Update()
        shown = deform.GetOutput()
        distance = numpy_to_vtk(np.linalg.norm(
            vtk_to_numpy(shown.GetPoints().GetData()) - mesh_points, axis=1), deep=True)
        distance.SetName("Displacement")
        shown.GetPointData().SetScalars(distance)
        mapper = vtkPolyDataMapper()
        mapper.SetInputData(shown)
        mapper.SetScalarRange(0.0, distance.GetRange()[1])
        mapper.GetLookupTable().SetHueRange(0.12, 0.0)
        mapper.GetLookupTable().SetSaturationRange(0.1, 0.9)
        mapper.GetLookupTable().SetValueRange(0.95, 0.7)
        actor = vtkActor()
        actor.SetMapper(mapper)

        lattice_actor = vtkffd.vtkFFDLatticeActor()
        lattice_actor.SetInputData(lattice)
        lattice_actor.SetVoxelGridConnection(voxelize.GetOutputPort())
        lattice_actor.SetShowEdges(False)  # the voxel boxes are the lattice's edges at rest
        lattice_actor.SetPointRadius(0.006 * lattice.GetLength())

        renderer = vtkRenderer()
        renderer.AddActor(actor)
        renderer.AddActor(lattice_actor)
        renderer.SetBackground(1.0, 1.0, 1.0)
        window = offscreen_window(renderer, (500, 500), multisamples=0)
        camera = renderer.GetActiveCamera()
        # CGAL's armadillo stands along +Y and faces +Z: its front, a little from the side and from above.
        camera.SetPosition(0.0, 0.0, 1.0)
        camera.SetViewUp(0.0, 1.0, 0.0)
        camera.Azimuth(25.0)
        camera.Elevation(20.0)
        renderer.ResetCamera(lattice.GetBounds())
        camera.Zoom(1.1)
        window.Render()
        Testing.compareImage(window, Testing.getAbsImagePath("TestFFDCulledVoxelsImage.png"), threshold=THRESHOLD)


if __name__ == "__main__":
    Testing.main([(TestFFDCulledVoxelsImage, "test")])
