// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDAdjointPasses.h
 * @brief The adjoint's chunk sums (W^T g) in SIMD lanes: an entry point of the FFDCpu library (host only).
 *
 * The CPU adjoint (vtkFFDSensitivity through vtkFFDGridAdjoint) sums each chunk of points of one cell
 * (FFDAdjoint.h) into a float64 partial per term, a control point of the cell's support. Here W points of the
 * chunk at a time, in float64 lanes of the widest level the CPU runs (W = 2, 4 or 8), each lane summing its own
 * points (the chunk's points l, l + W, ...) in order, and the lanes added in lane order at the end: one order for
 * any number of threads. A point's term is (W1[j] W2[l]) (W0[i] g), its weights GridDeformation::WeightsInCell()'s.
 */
#ifndef FFDAdjointPasses_h
#define FFDAdjointPasses_h

#include "FFDGridPasses.h"

#include <cstddef>
#include <cstdint>

namespace ffd
{

/// A chunk of the adjoint's sums: `Count` points of cell `Cell`, their coordinates X (3 each, in chunk order) and
/// ids (where their gradient is: g + 3 id), summed into Partial (3 per term k = i + n0 (j + n1 l) of the support),
/// through Scratch, the lanes' sums: AdjointScratchSize() doubles of the caller's thread.
struct AdjointChunk
{
  int Cell;
  std::int64_t Count;
  const double* X;
  const std::int64_t* Ids;
  const double* G;
  double* Partial;
  double* Scratch;
};

/// The doubles of an AdjointChunk's Scratch for `terms` terms a chunk: 3 a term in lanes of up to 8.
inline std::size_t AdjointScratchSize(int terms)
{
  return 3 * std::size_t(terms) * 8;
}

/// Sums `chunk` in lanes of `level` on the lattice (its displacements are not read); false where the build has no
/// lanes for it (the caller sums the chunk point by point).
bool SumAdjointChunkInLanes(SimdLevel level, const GridLattice<double>& lattice, const AdjointChunk& chunk);

} // namespace ffd

#endif
