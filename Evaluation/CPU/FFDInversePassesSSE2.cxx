// SPDX-License-Identifier: BSD-3-Clause
// The inverse's Newton search compiled for SSE2 (16-byte lanes), for every basis in float64: its one copy
// (FFDGridPassLevels.h). Empty where the build leaves the level out (FFD_WIDEST_LANES) or has no lanes.
#include "FFDInverseLanes.h"

#if FFD_HAVE_LANES && FFD_WIDEST_LANES >= 1
namespace ffd
{
namespace detail
{
FFD_DEFINE_INVERSE_KERNEL(SimdLevel::SSE2, FFD_TARGET_SSE2, 16)
} // namespace detail
} // namespace ffd

FFD_INSTANTIATE_INVERSE_PASS(ffd::SimdLevel::SSE2)
#endif
