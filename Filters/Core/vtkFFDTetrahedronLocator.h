// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkFFDTetrahedronLocator
 * @brief   finds the rest tetrahedron of a tetrahedral lattice that holds a point, for vtkFFDTetrahedralDeformer
 *
 * Private to the Filters module (not wrapped). Built once per binding from the rest tetrahedra: their frames
 * (ffd::TetrahedronFrame, whose parameters are the weights of equation 5), which of them have no volume, their
 * nodes and the nodes' rest positions. Walk() steps across faces towards the face of the most negative weight,
 * from a hint or from the seed nearest the point in a coarse grid (about 8 tetrahedra a grid cell). Where a walk
 * gives no answer (it left a non-convex mesh, met a tetrahedron without volume, or cycled), FindTetrahedron()
 * asks VTK's vtkStaticCellLocator for candidates and the weights decide: VTK's locator alone tests each
 * candidate through vtkCell::EvaluatePosition, slow on the long tetrahedra of a hull's fan, whose bounds overlap
 * by the hundreds (BENCHMARKS.md). FindClosestTetrahedron(), for points outside every tetrahedron, is VTK's
 * locator's nearest cell.
 *
 * A point counts as inside a tetrahedron when its smallest weight is at least -1e-10 (the band that absorbs
 * rounding on faces). Tetrahedra without volume never hold a point.
 *
 * Walk() and FindTetrahedron() may run concurrently (vtkSMPTools); BuildCellLocator() and
 * FindClosestTetrahedron() are for one thread at a time.
 */
#ifndef vtkFFDTetrahedronLocator_h
#define vtkFFDTetrahedronLocator_h

#include "vtkSMPThreadLocalObject.h"
#include "vtkSmartPointer.h"
#include "vtkType.h"

#include "FFDTetrahedra.h"

#include <vector>

class vtkDataArray;
class vtkGenericCell;
class vtkIdList;
class vtkStaticCellLocator;
class vtkUnstructuredGrid;

class vtkFFDTetrahedronLocator
{
public:
  /**
   * Over the rest tetrahedra: `frames` and `degenerate` (1 for a tetrahedron without volume) are kept by
   * reference and must outlive the locator; `nodes` (4 per tetrahedron) and `restValues` (3 per node) give the
   * face neighbours and the grid of seeds. `lattice`'s cells and its `restPositions` array are what VTK's
   * locator searches, once BuildCellLocator() is called.
   */
  vtkFFDTetrahedronLocator(const std::vector<ffd::Frame<double>>& frames, const std::vector<unsigned char>& degenerate,
    const std::vector<vtkIdType>& nodes, const std::vector<double>& restValues, vtkUnstructuredGrid* lattice,
    vtkDataArray* restPositions);
  ~vtkFFDTetrahedronLocator();
  vtkFFDTetrahedronLocator(const vtkFFDTetrahedronLocator&) = delete;
  vtkFFDTetrahedronLocator& operator=(const vtkFFDTetrahedronLocator&) = delete;

  /**
   * The tetrahedron holding x (finite), reached by walking from the tetrahedron `hint` (-1: the seed nearest
   * x), or -1 when the walk gives no answer (FindTetrahedron() then decides). Always -1 when no tetrahedron
   * has volume.
   */
  int Walk(const double x[3], int hint = -1) const;

  /**
   * Builds VTK's locator, which FindTetrahedron() and FindClosestTetrahedron() search: call it before them. Not
   * in the constructor: walks usually place every point, and then it is not needed. Does nothing a second time.
   */
  void BuildCellLocator();

  /**
   * The tetrahedron holding x according to VTK's locator: the one it proposes if the weights confirm it (its own
   * inside test is looser), else, of every tetrahedron in x's bin of the locator, the one x lies deepest in;
   * -1 when x lies in none.
   */
  int FindTetrahedron(const double x[3]) const;

  /**
   * The tetrahedron nearest x, and its point nearest x (`closest`); among tetrahedra as near (within 1e-10 of
   * the squared distance), the lowest id of one with volume, else of one without: the same answer however VTK's
   * locator ordered them. -1 when VTK's locator finds none (when no tetrahedron has volume).
   */
  int FindClosestTetrahedron(const double x[3], double closest[3]) const;

private:
  /// A walk from `start`; `last` is the last tetrahedron it visited.
  int WalkFrom(int start, const ffd::Vec3<double>& x, int& last) const;
  void MakeSeeds(const std::vector<double>& rest);
  int SeedOf(const double x[3]) const;
  /// How far inside a tetrahedron x lies in weight units (ffd::InsideMargin); -infinity without volume.
  double Margin(vtkIdType tetrahedron, const double x[3]) const;

  const std::vector<ffd::Frame<double>>& Frames;
  const std::vector<unsigned char>& Degenerate;
  std::vector<int> Neighbours; // 4 per tetrahedron: across the face opposite node i, -1 on the boundary

  // A uniform grid over the rest nodes' bounds whose cells remember a tetrahedron near their centre, where walks
  // start; empty when no tetrahedron has volume.
  double SeedOrigin[3] = { 0.0, 0.0, 0.0 };
  double SeedSpacing[3] = { 1.0, 1.0, 1.0 };
  int SeedSize = 1;
  std::vector<int> Seeds;

  vtkSmartPointer<vtkUnstructuredGrid> Lattice;
  vtkSmartPointer<vtkDataArray> RestPositions;
  vtkSmartPointer<vtkUnstructuredGrid> Rest; // the rest tetrahedra as VTK's locator sees them
  vtkSmartPointer<vtkStaticCellLocator> CellLocator;
  // Each thread's scratch for VTK's queries.
  mutable vtkSMPThreadLocalObject<vtkGenericCell> Cell;
  mutable vtkSMPThreadLocalObject<vtkIdList> Candidates;
};

#endif
