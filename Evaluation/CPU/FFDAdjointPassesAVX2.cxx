// SPDX-License-Identifier: BSD-3-Clause
// The adjoint's chunk sums compiled for AVX2 (32-byte lanes), in float64: their one copy (FFDGridPassLevels.h).
// Empty where the build leaves the level out (FFD_WIDEST_LANES) or has no lanes.
#include "FFDAdjointLanes.h"

#if FFD_HAVE_LANES && FFD_WIDEST_LANES >= 2
namespace ffd
{
namespace detail
{
FFD_DEFINE_ADJOINT_KERNEL(SimdLevel::AVX2, FFD_TARGET_AVX2, 32)
} // namespace detail
} // namespace ffd

FFD_INSTANTIATE_ADJOINT_PASS(ffd::SimdLevel::AVX2)
#endif
