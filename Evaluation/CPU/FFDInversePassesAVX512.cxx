// SPDX-License-Identifier: BSD-3-Clause
// The inverse's Newton search compiled for AVX512 (64-byte lanes), for every basis in float64: its one copy
// (FFDGridPassLevels.h). Empty where the build leaves the level out (FFD_WIDEST_LANES) or has no lanes.
#include "FFDInverseLanes.h"

#if FFD_HAVE_LANES && FFD_WIDEST_LANES >= 3
namespace ffd
{
namespace detail
{
FFD_DEFINE_INVERSE_KERNEL(SimdLevel::AVX512, FFD_TARGET_AVX512, 64)
} // namespace detail
} // namespace ffd

FFD_INSTANTIATE_INVERSE_PASS(ffd::SimdLevel::AVX512)
#endif
