// SPDX-License-Identifier: BSD-3-Clause
#include "FFDInversePasses.h"

#include "FFDGridPassLevels.h"

namespace ffd
{

int InverseLaneWidth(SimdLevel level)
{
  int width = 1; // no lanes
  detail::WithCompiledLevel(level, [&](auto compiled) { width = 1 << int(decltype(compiled)::value); });
  return width;
}

void InvertInLanes(
  SimdLevel level, const GridLattice<double>& lattice, const InverseLaneSearch& search, InverseLaneGroup& group)
{
  if (!detail::WithCompiledLevel(
        level, [&](auto compiled) { detail::InvertAt<decltype(compiled)::value>(lattice, search, group); }))
  {
    group.Converged = 0; // no lanes: every point is the caller's
  }
}

} // namespace ffd
