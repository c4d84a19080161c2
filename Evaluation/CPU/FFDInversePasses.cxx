// SPDX-License-Identifier: BSD-3-Clause
#include "FFDInversePasses.h"

#include "FFDGridPassLevels.h"

namespace ffd
{

int InverseLaneWidth(SimdLevel level)
{
#if FFD_HAVE_LANES
  switch (SimdLevel(std::min(int(level), FFD_WIDEST_LANES)))
  {
    case SimdLevel::AVX512:
      return 8;
    case SimdLevel::AVX2:
      return 4;
    case SimdLevel::SSE2:
      return 2;
    default:
      break;
  }
#endif
  (void)level;
  return 1;
}

void InvertInLanes(
  SimdLevel level, const GridLattice<double>& lattice, const InverseLaneSearch& search, InverseLaneGroup& group)
{
  switch (InverseLaneWidth(level))
  {
#if FFD_HAVE_LANES
#if FFD_WIDEST_LANES >= 3
    case 8:
      return detail::InvertAt<SimdLevel::AVX512>(lattice, search, group);
#endif
#if FFD_WIDEST_LANES >= 2
    case 4:
      return detail::InvertAt<SimdLevel::AVX2>(lattice, search, group);
#endif
    case 2:
      return detail::InvertAt<SimdLevel::SSE2>(lattice, search, group);
#endif
    default:
      group.Converged = 0; // no lanes: every point is the caller's
  }
}

} // namespace ffd
