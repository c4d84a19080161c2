// SPDX-License-Identifier: BSD-3-Clause
// The adjoint's chunk sums compiled for SSE2 (16-byte lanes), in float64: their one copy (FFDGridPassLevels.h).
// Empty where the build leaves the level out (FFD_WIDEST_LANES) or has no lanes.
#include "FFDAdjointLanes.h"

#if FFD_HAVE_LANES && FFD_WIDEST_LANES >= 1
namespace ffd
{
namespace detail
{
FFD_DEFINE_ADJOINT_KERNEL(SimdLevel::SSE2, FFD_TARGET_SSE2, 16)
} // namespace detail
} // namespace ffd

FFD_INSTANTIATE_ADJOINT_PASS(ffd::SimdLevel::SSE2)
#endif
