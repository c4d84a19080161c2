// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file vtkFFDGridWeights.h
 * @brief The weights of a grid lattice's control points at bound points (private to the Filters module).
 *
 * The transpose of the deformation: for each point bound by vtkFFDGridDeformer::Bind(), the control points of its
 * cell's support and their weights (ffd::GridDeformation::ForEachWeight), the same numbers the evaluation sums.
 * What the lattice's masses (vtkFFDLatticeBody) and least-squares fits (vtkFFDCoarsenLattice) are made of.
 */
#ifndef vtkFFDGridWeights_h
#define vtkFFDGridWeights_h

#include "vtkType.h"

#include <functional>

class vtkFFDGridDeformer;
class vtkPoints;

/**
 * Calls add(point, controlPoint, weight) for every weight of each point of [begin, end) of `points` that the last
 * Bind() of `deformer` bound to a cell (those it did not are skipped); controlPoint is the lattice's point id. Safe
 * to call from several threads on disjoint ranges.
 */
void vtkFFDForEachGridWeight(const vtkFFDGridDeformer& deformer, vtkPoints* points, vtkIdType begin, vtkIdType end,
  const std::function<void(vtkIdType, vtkIdType, double)>& add);

/// How many control points weigh on a bound point: the support's size (64 for the cubic bases).
int vtkFFDGridWeightsPerPoint(const vtkFFDGridDeformer& deformer);

#endif
