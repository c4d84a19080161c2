// SPDX-License-Identifier: BSD-3-Clause
// The evaluation's CPU passes compiled for AVX512 (64-byte lanes), for every basis and both precisions: their one
// copy (FFDGridPassLevels.h). Empty where the build leaves the level out (FFD_WIDEST_LANES) or has no lanes.
#include "FFDGridLanes.h"

#if FFD_HAVE_LANES && FFD_WIDEST_LANES >= 3
namespace ffd
{
namespace detail
{
FFD_DEFINE_GRID_KERNELS(SimdLevel::AVX512, FFD_TARGET_AVX512, 64)
} // namespace detail
} // namespace ffd

FFD_INSTANTIATE_GRID_PASSES(ffd::SimdLevel::AVX512)
#endif
