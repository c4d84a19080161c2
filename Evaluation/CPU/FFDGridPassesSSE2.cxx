// SPDX-License-Identifier: BSD-3-Clause
// The evaluation's CPU passes compiled for SSE2 (16-byte lanes), for every basis and both precisions: their one
// copy (FFDGridPassLevels.h). Empty where the build leaves the level out (FFD_WIDEST_LANES) or has no lanes.
#include "FFDGridLanes.h"

#if FFD_HAVE_LANES && FFD_WIDEST_LANES >= 1
namespace ffd
{
namespace detail
{
FFD_DEFINE_GRID_KERNELS(SimdLevel::SSE2, FFD_TARGET_SSE2, 16)
} // namespace detail
} // namespace ffd

FFD_INSTANTIATE_GRID_PASSES(ffd::SimdLevel::SSE2)
#endif
