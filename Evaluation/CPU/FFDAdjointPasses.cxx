// SPDX-License-Identifier: BSD-3-Clause
#include "FFDAdjointPasses.h"

#include "FFDGridPassLevels.h"

namespace ffd
{

bool SumAdjointChunkInLanes(SimdLevel level, const GridLattice<double>& lattice, const AdjointChunk& chunk)
{
  return detail::WithCompiledLevel(
    level, [&](auto compiled) { detail::AdjointAt<decltype(compiled)::value>(lattice, chunk); });
}

} // namespace ffd
