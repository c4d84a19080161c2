// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkFFDGridAdjoint
 * @brief   W^T g of a grid lattice on the CPU, deterministic (private to the Sensitivity module)
 *
 * vtkFFDSensitivity's sums for grid lattices on vtkSMPTools threads, in the CUDA adjoint's shape
 * (FFDAdjoint.h): a plan per binding (the bound points grouped by cell, in increasing id, cut into chunks; each
 * chunk's terms, the control points of its cell's support, grouped by control point), then at each Sum() every
 * chunk's points summed into a float64 partial per term, the chunks in parallel (in SIMD lanes:
 * FFDAdjointPasses.h), and every control point's partials added in the plan's order. A point's term is
 * (W1[j] W2[l]) (W0[i] g), the weights of ffd::GridDeformation::WeightsInCell() in float64. No atomics, no order
 * set by the threads: the same bits for any number of them (on one CPU: the lanes' width sets the order).
 */
#ifndef vtkFFDGridAdjoint_h
#define vtkFFDGridAdjoint_h

#include "vtkFFDBindingKey.h"
#include "vtkType.h"

#include <cstdint>
#include <vector>

namespace ffd
{
struct AdjointChunk;
}
class vtkAlgorithm;
class vtkFFDGridDeformer;
class vtkPoints;

class vtkFFDGridAdjoint
{
public:
  /**
   * W^T g into `sums` (3 per control point of the grid's lattice, overwritten): `grid` bound per `key` to
   * `points` (its last SetLattice() and Bind()), g 3 doubles per point. Progress to `self` from 0.5 to 1; false
   * where it was aborted (sums then undefined).
   */
  bool Sum(const vtkFFDGridDeformer& grid, const vtkFFDBindingKey& key, vtkPoints* points, const double* g,
    double* sums, vtkAlgorithm* self);

  /// Number of plans made (one per binding).
  vtkIdType GetNumberOfPlans() const { return this->Plans; }

private:
  struct Chunk
  {
    int Cell;
    vtkIdType Begin, End; // positions in Order
  };

  template <typename Deformation>
  void MakePlan(const Deformation& deformation, const vtkFFDGridDeformer& grid, vtkPoints* points);
  template <typename Deformation>
  void SumChunk(const Deformation& deformation, const ffd::AdjointChunk& chunk) const;
  void Gather(double* sums) const;

  vtkFFDBindingKey For; // what the plan is for, with the lattice's count of control points
  vtkIdType ControlPoints = -1;
  vtkIdType Plans = 0;
  int Counts[3] = { 0, 0, 0 }; // a support's control points along each axis
  int Terms = 0;
  std::vector<std::int64_t> Order; // the bound points by cell, then id
  std::vector<double> X;           // their coordinates in float64, in that order
  std::vector<Chunk> Chunks;
  std::vector<vtkIdType> TermStart, TermOrder; // the terms (chunk Terms + k) by control point, then term
  std::vector<double> Partials;                // 3 per term
};

#endif
