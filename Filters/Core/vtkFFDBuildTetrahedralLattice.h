// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkFFDBuildTetrahedralLattice
 * @brief   builds a tetrahedral control mesh around a mesh from its convex hull and centroid
 *
 * The tetrahedral counterpart of vtkFFDVoxelize + vtkFFDBuildLattice (paper section III.E, Figure 9). The input
 * is any vtkPointSet; the output is a vtkUnstructuredGrid of tetrahedra that encloses the input's finite points:
 * the convex hull of the points (computed by Qhull, triangulated) joined to their centroid, one tetrahedron per
 * hull triangle. Its points are double precision and rest in place, with the data contract's point arrays
 * `RestPosition` and `Active` (vtkFFDDataContract). Connect it to vtkFFDDeform's input 1 and move its points to
 * deform the mesh.
 *
 * - Padding (default 0.05) moves the hull's nodes away from the centroid by that fraction of their distance,
 *   so that the points on the hull lie inside the control mesh, not on its faces.
 * - SubdivisionLevels (default 0) refines the control mesh for finer control (level of detail): each level
 *   splits every tetrahedron into eight at its edges' midpoints (its inner octahedron along the shortest
 *   diagonal), so a level multiplies the tetrahedra by 8 and the nodes by about 5.
 * - A node is active when it influences an input point: it has a weight above 1e-9 for a point in one of its
 *   tetrahedra (bound as vtkFFDDeform binds it). The others are culled: `Active` is 0 and the ghost array marks
 *   them HIDDENPOINT, as vtkFFDBuildLattice does for grid lattices.
 *
 * The hull is Qhull's of the points in lexicographic order, and the centroid an exact sum rounded once, so the
 * lattice does not depend on the points' order. A mesh split among processes (Controller with more than one
 * process, as for vtkFFDVoxelize): every process takes every process's finite points for the hull (24 bytes a
 * point), the centroid is that of all of them, and a node is active where it is on some process, so each process
 * outputs the same lattice, bit for bit the one a single process makes of the whole mesh. Every process must
 * execute the filter then.
 *
 * Every tetrahedron is positively oriented. An input with fewer than four finite points, or whose points are
 * flat (no 3D hull), is an error and gives an empty output; non-finite points are ignored.
 *
 * @sa vtkFFDDeform vtkFFDBuildLattice vtkFFDDataContract
 */
#ifndef vtkFFDBuildTetrahedralLattice_h
#define vtkFFDBuildTetrahedralLattice_h

#include "vtkFFDFiltersCoreModule.h" // For export macro
#include "vtkUnstructuredGridAlgorithm.h"

class vtkMultiProcessController;

class VTKFFDFILTERSCORE_EXPORT vtkFFDBuildTetrahedralLattice : public vtkUnstructuredGridAlgorithm
{
public:
  static vtkFFDBuildTetrahedralLattice* New();
  vtkTypeMacro(vtkFFDBuildTetrahedralLattice, vtkUnstructuredGridAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// How far the hull's nodes move away from the centroid, as a fraction of their distance (default 0.05).
  vtkSetClampMacro(Padding, double, 0.0, 10.0);
  vtkGetMacro(Padding, double);
  ///@}

  ///@{
  /// Times every tetrahedron is split into eight (default 0, at most 5).
  vtkSetClampMacro(SubdivisionLevels, int, 0, 5);
  vtkGetMacro(SubdivisionLevels, int);
  ///@}

  ///@{
  /// Statistics of the last execution: triangles of the convex hull, and nodes marked active.
  vtkGetMacro(NumberOfHullFaces, vtkIdType);
  vtkGetMacro(NumberOfActiveNodes, vtkIdType);
  ///@}

  ///@{
  /// The processes among which the mesh is split (default: vtkMultiProcessController::GetGlobalController());
  /// null or one process: this one only.
  virtual void SetController(vtkMultiProcessController*);
  vtkGetObjectMacro(Controller, vtkMultiProcessController);
  ///@}

protected:
  vtkFFDBuildTetrahedralLattice();
  ~vtkFFDBuildTetrahedralLattice() override;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  /// An allocation that fails becomes an error and an empty output, never an exception out of Update().
  /// With several processes, asks for this process's piece of the mesh, whatever was asked of the output.
  int RequestUpdateExtent(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  vtkTypeBool ProcessRequest(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  double Padding;
  int SubdivisionLevels;
  vtkIdType NumberOfHullFaces;
  vtkIdType NumberOfActiveNodes;
  vtkMultiProcessController* Controller;

private:
  vtkFFDBuildTetrahedralLattice(const vtkFFDBuildTetrahedralLattice&) = delete;
  void operator=(const vtkFFDBuildTetrahedralLattice&) = delete;
};

#endif
