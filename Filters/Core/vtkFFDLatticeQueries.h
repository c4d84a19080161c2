// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file vtkFFDLatticeQueries.h
 * @brief What the level-of-detail, dynamics and direct-manipulation filters ask of a lattice that
 * vtkFFDGridDeformer or vtkFFDTetrahedralDeformer has read (private to the Filters module).
 *
 * - The weights of its control points at bound points: the transpose of the deformation (ffd::GridDeformation::
 *   ForEachWeight, a tetrahedron's barycentric weights), the same numbers the evaluation sums: the lattice's
 *   masses (vtkFFDLatticeBody), least-squares fits (vtkFFDCoarsenLattice) and direct manipulation
 *   (vtkFFDDirectManipulation) are made of them.
 * - The voxels it covers: a sparse lattice's cells; for a dense lattice, the voxels whose whole support is
 *   `Active` (all of them without that array).
 * - Its control points by lattice index (i, j, k), dense or sparse alike.
 */
#ifndef vtkFFDLatticeQueries_h
#define vtkFFDLatticeQueries_h

#include "vtkFFDGridDeformer.h"
#include "vtkFFDSortedKeys.h"
#include "vtkType.h"

#include "FFDGridDeformation.h"

#include <functional>
#include <string>
#include <utility>
#include <vector>

class vtkFFDTetrahedralDeformer;
class vtkPoints;
class vtkPointSet;

/**
 * Calls f(deformation) with the float64 ffd::GridDeformation of the lattice that `deformer` read (its support's
 * size and its basis as template arguments, as the evaluation has them).
 */
template <typename F>
void vtkFFDWithGridDeformation(const vtkFFDGridDeformer& deformer, F&& f)
{
  const vtkFFDGridLattice& view = deformer.GetLattice();
  const vtkFFDSparseCells* cells = deformer.GetSparseCells();
  ffd::WithStaticBasis(view.Basis,
    [&](auto maxCount, auto basis)
    {
      f(ffd::GridDeformation<decltype(maxCount)::value, double, decltype(basis)::value>{ view.Basis,
        { view.Divisions[0], view.Divisions[1], view.Divisions[2] },
        { view.ControlPointsPerAxis[0], view.ControlPointsPerAxis[1], view.ControlPointsPerAxis[2] },
        view.Displacements.data(), ffd::Frame<double>::FromArray(view.Frame), nullptr,
        cells ? cells->GetVoxels().data() : nullptr, cells ? cells->GetSupports() : nullptr });
    });
}

/**
 * Calls add(point, controlPoint, weight) for every weight of each point of [begin, end) of `points` that the last
 * Bind() of `deformer` bound to a cell (those it did not are skipped); controlPoint is the lattice's point id. Safe
 * to call from several threads on disjoint ranges.
 */
void vtkFFDForEachGridWeight(const vtkFFDGridDeformer& deformer, vtkPoints* points, vtkIdType begin, vtkIdType end,
  const std::function<void(vtkIdType, vtkIdType, double)>& add);

/// vtkFFDForEachGridWeight() for a tetrahedral lattice: the four nodes of each bound point's tetrahedron.
void vtkFFDForEachTetrahedronWeight(const vtkFFDTetrahedralDeformer& deformer, vtkPoints* points, vtkIdType begin,
  vtkIdType end, const std::function<void(vtkIdType, vtkIdType, double)>& add);

/// How many control points weigh on a bound point: the support's size (64 for the cubic bases).
int vtkFFDGridWeightsPerPoint(const vtkFFDGridDeformer& deformer);

/**
 * The divisions twice `divisions` and the control points per axis of `basis` over them in `form`
 * (vtkFFDBuildLattice::LatticeForms): an empty string, or why a lattice cannot have them.
 */
std::string vtkFFDDoubledDivisions(
  ffd::GridBasis basis, const int divisions[3], int form, int doubled[3], int points[3]);

/// The voxels (i, j, k, in increasing order) that `lattice`, read by `deformer`, covers.
std::vector<int> vtkFFDCoveredVoxels(const vtkFFDGridDeformer& deformer, vtkPointSet* lattice);

/// A lattice's control points found by (i, j, k).
class vtkFFDControlPointIndex
{
public:
  /// For `lattice`, read by `deformer`: every point of a dense lattice, a sparse one's by their `LatticeIndex`.
  vtkFFDControlPointIndex(const vtkFFDGridDeformer& deformer, vtkPointSet* lattice);

  /// The point id of (i, j, k), or -1 where the lattice has no such point.
  vtkIdType Find(int i, int j, int k) const;

private:
  int Dims[3];
  bool Dense;
  vtkFFDSortedKeys<vtkIdType> Sorted; // a sparse lattice's flat indices and point ids
};

#endif
