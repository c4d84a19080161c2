// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDAdjoint.h
 * @brief What the CPU and CUDA adjoints of a grid lattice (W^T g) share: how the bound points are cut into chunks.
 *
 * Both sum each chunk's points, in one order, into a partial per term (a control point of the chunk's cell's
 * support), then add each control point's partials in one order: the same bits for any number of threads or
 * blocks. A chunk is at most AdjointChunkPoints() consecutive points of one cell (points grouped by cell, in
 * increasing id), a number set by the points and the support alone.
 */
#ifndef FFDAdjoint_h
#define FFDAdjoint_h

#include <cstdint>

namespace ffd
{
/// Points per chunk: 1024, more where the partials (chunks x `terms` per chunk) would pass 2^22 terms (the global
/// basis: a term per control point).
inline std::int64_t AdjointChunkPoints(std::int64_t points, int terms)
{
  const std::int64_t byTerms = (points * terms + (std::int64_t(1) << 22) - 1) >> 22;
  return byTerms > 1024 ? byTerms : 1024;
}
} // namespace ffd

#endif
