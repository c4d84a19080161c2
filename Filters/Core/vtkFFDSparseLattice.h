// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file vtkFFDSparseLattice.h
 * @brief Sparse sets of grid coordinates and the cells over them (private to the Filters module).
 *
 * Both sparse outputs are built here: vtkFFDVoxelize's voxel grid (the voxels that hold points, then their corners,
 * which are the active control points of a TRILINEAR lattice over them) and vtkFFDBuildLattice's sparse lattice
 * (the control points in the supports of the active voxels), the same way for those filters and for
 * vtkFFDVDBReader, which rebuilds both from a file's voxels. Their cost follows the coordinates that are active,
 * never the grid's size: a set is found in parallel with OpenVDB (a MaskTree per thread, merged by topology union,
 * as OpenVDB's own tools build masks) and read out as linear indices i + n0 (j + n1 k), int64 since grids of
 * 1024^3 voxels and beyond overflow an int, sorted; a cell finds its points by binary search. Every result is the
 * same whatever the number of threads. This header is OpenVDB-free (vtkFFDOpenVDB.h says who includes OpenVDB).
 */
#ifndef vtkFFDSparseLattice_h
#define vtkFFDSparseLattice_h

#include "vtkCellArray.h"
#include "vtkFFDFlatIndex.h"
#include "vtkSmartPointer.h"
#include "vtkType.h"

#include "FFDFrame.h"
#include "FFDGridBasis.h"

#include <functional>
#include <memory>
#include <string>
#include <vector>

class vtkAlgorithm;
class vtkIntArray;
class vtkPoints;
class vtkUnstructuredGrid;

/// Marks boxes of grid coordinates: what the body of vtkFFDActiveSet::Mark() is given.
class vtkFFDBoxMarker
{
public:
  /// Marks the coordinates first[a] .. first[a] + count[a] - 1 along every axis a.
  virtual void Mark(const int first[3], const int count[3]) = 0;

protected:
  ~vtkFFDBoxMarker() = default;
};

/// A sparse set of grid coordinates (each in [0, 2^31)), marked in parallel.
class vtkFFDActiveSet
{
public:
  vtkFFDActiveSet();
  ~vtkFFDActiveSet();
  vtkFFDActiveSet(const vtkFFDActiveSet&) = delete;
  vtkFFDActiveSet& operator=(const vtkFFDActiveSet&) = delete;

  /// Runs body(begin, end, marker) over [0, n) with vtkSMPTools; each call marks the coordinates of its items.
  void Mark(vtkIdType n, const std::function<void(vtkIdType, vtkIdType, vtkFFDBoxMarker&)>& body);

  /// How many distinct coordinates are marked.
  vtkIdType GetNumberOfMarked() const;

  /// The marked coordinates as i + dims[0] (j + dims[1] k), in increasing order; the set is emptied.
  std::vector<vtkTypeInt64> TakeSortedIndices(const vtkTypeInt64 dims[3]);

private:
  struct Internals;
  std::unique_ptr<Internals> Internal;
};

/// Position of control point (i, j, k) of a lattice of `basis` at rest: the one formula of the dense and sparse
/// lattices and of the voxel grid's corners (the TRILINEAR lattice's points), so that they agree bit for bit.
inline ffd::Vec3<double> vtkFFDRestPoint(
  const ffd::Frame<double>& frame, ffd::GridBasis basis, const int divisions[3], int i, int j, int k)
{
  return frame.ToWorld({ ffd::RestParameter(basis, divisions[0], i), ffd::RestParameter(basis, divisions[1], j),
    ffd::RestParameter(basis, divisions[2], k) });
}

/**
 * The sparse lattice of a local basis over a list of voxels (i, j, k): its points, the union of the voxels'
 * supports (ffd::VoxelSupport), as sorted linear indices i + nI (j + nJ k), and one cell per voxel, in the list's
 * order, naming the points of the voxel's support by their rank in that list, in the order of the basis's cell
 * type: VTK_HEXAHEDRON (TRILINEAR), VTK_BEZIER_HEXAHEDRON of 27 or 64 points (the Bezier sub-regions, in
 * vtkHigherOrderHexahedron::PointIndexFromIJK's order) and VTK_POLY_VERTEX of 64 points, i fastest
 * (CUBIC_BSPLINE, which has no VTK cell type). The cell array uses 32-bit storage where the ids fit.
 */
struct vtkFFDSparseLattice
{
  int PointsPerAxis[3] = { 0, 0, 0 };
  std::vector<vtkTypeInt64> Points;
  vtkSmartPointer<vtkCellArray> Cells;
  int CellType = 0;

  /**
   * Builds it for `numVoxels` voxels, whose (i, j, k) are voxels[3 v .. 3 v + 2], each within `divisions`, and
   * distinct. Before anything proportional to the lattice is allocated, the memory it needs, with the caller's
   * own `bytesPerPoint` and `bytesPerCell`, is checked (vtkFFDCheckMemory; `what` names the request in the error):
   * false when it is not there.
   */
  bool Build(vtkAlgorithm* self, ffd::GridBasis basis, const int divisions[3], const int* voxels, vtkIdType numVoxels,
    double bytesPerPoint, double bytesPerCell, const std::string& what);

  /// Marks the supports of the voxels in `set`: their union is the lattice's points (Build()'s first step, and
  /// what vtkFFDVDBWriter checks a lattice's points against).
  static void MarkSupports(
    vtkFFDActiveSet& set, ffd::GridBasis basis, const int divisions[3], const int* voxels, vtkIdType numVoxels);

  /// (i, j, k) of point `id`.
  void GetIndex(vtkIdType id, int index[3]) const;

  /// The points at rest (double), computed in parallel with vtkFFDRestPoint().
  vtkSmartPointer<vtkPoints> MakeRestPoints(
    const ffd::Frame<double>& frame, ffd::GridBasis basis, const int divisions[3]) const;
};

/// The `VoxelIndex` array (3 ints a voxel) of the voxels whose linear indices i + nx (j + ny k) are `sorted`.
vtkSmartPointer<vtkIntArray> vtkFFDMakeVoxelIndex(const std::vector<vtkTypeInt64>& sorted, const int divisions[3]);

/**
 * Fills `output` with vtkFFDVoxelize's voxel grid of the voxels of `voxelIndex` (distinct, within `divisions`, in
 * increasing order as vtkFFDVoxelize finds them): their corners, one hexahedron each with its `VoxelIndex` (the
 * array itself), `FFDFrame` and `FFDDivisions`. False, with the error reported on `self`, when the memory it needs
 * is not there (`what` names the request).
 */
bool vtkFFDMakeVoxelGrid(vtkAlgorithm* self, const double frame[12], const int divisions[3], vtkIntArray* voxelIndex,
  const std::string& what, vtkUnstructuredGrid* output);

/**
 * Fills `output` with vtkFFDBuildLattice's sparse lattice of the local `basis` at rest over the voxels of
 * `voxelIndex` (distinct, within `divisions`): its points in increasing lattice order with `RestPosition`, `Active`
 * and `LatticeIndex`, one cell per voxel in `voxelIndex`'s order with its `VoxelIndex` (the array itself),
 * `FFDFrame`, `FFDDivisions` and `FFDBasis`. Reports progress 0.5 on `self` once the points are known and returns
 * there, with the output empty, when `self` is aborted. False, with the error reported on `self`, when the memory
 * it needs is not there (`what` names the request).
 */
bool vtkFFDMakeSparseLattice(vtkAlgorithm* self, const double frame[12], ffd::GridBasis basis, const int divisions[3],
  vtkIntArray* voxelIndex, const std::string& what, vtkUnstructuredGrid* output);

#endif
