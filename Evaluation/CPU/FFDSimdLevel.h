// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDSimdLevel.h
 * @brief The SIMD instruction sets of the CPU passes, and the widest one this CPU runs (host only).
 *
 * The default build must run on any x86-64, so the wide passes are compiled with GCC's target attribute
 * (AVX-512: 16 floats or 8 doubles a lane group; AVX2 and FMA: 8 or 4), one translation unit per level
 * (FFDGridPasses*.cxx), and chosen at run time by SimdLevelOfCpu(); `flatten` inlines every kernel function into
 * them, so that no out-of-line copy compiled for one instruction set is shared with code compiled for another.
 * SSE2 (any x86-64) takes 4 floats or 2 doubles.
 */
#ifndef FFDSimdLevel_h
#define FFDSimdLevel_h

#include <cstdlib>
#include <cstring>

#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__)) && !defined(__CUDACC__)
#define FFD_HAVE_LANES 1
#include "FFDLanes.h"
#define FFD_TARGET_AVX512 __attribute__((target("avx512f,avx512dq,avx512vl,avx512bw,avx2,fma,bmi2"), flatten))
#define FFD_TARGET_AVX2 __attribute__((target("avx2,fma,bmi2"), flatten))
#define FFD_TARGET_SSE2 __attribute__((flatten))
#else
#define FFD_HAVE_LANES 0
#endif

// The widest lanes compiled in, a SimdLevel value: every level (3, AVX-512) unless the build says fewer. The
// sanitizer build compiles SSE2's only (CMakeLists.txt says why); SimdLevelOfCpu() never names one left out.
#ifndef FFD_WIDEST_LANES
#define FFD_WIDEST_LANES 3
#endif

namespace ffd
{

/// Instruction sets of the blocks: SSE2 (any x86-64: 4 floats, 2 doubles), AVX2 with FMA, AVX-512.
enum class SimdLevel
{
  None = 0, ///< one point at a time
  SSE2 = 1,
  AVX2 = 2,
  AVX512 = 3,
};

/**
 * The widest level this CPU runs (None where lanes are not compiled in), at most the one that the environment
 * variable VOXELFFD_MAX_SIMD names (none, sse2, avx2 or avx512) where it is set: so that a machine runs its
 * tests, or a user's case, as a CPU without AVX-512 or AVX2 would.
 */
inline SimdLevel SimdLevelOfCpu()
{
#if FFD_HAVE_LANES
  __builtin_cpu_init();
  SimdLevel level = SimdLevel::SSE2;
  if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl") &&
    __builtin_cpu_supports("avx512bw"))
  {
    level = SimdLevel::AVX512;
  }
  else if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") && __builtin_cpu_supports("bmi2"))
  {
    level = SimdLevel::AVX2;
  }
  if (int(level) > FFD_WIDEST_LANES)
  {
    level = SimdLevel(FFD_WIDEST_LANES);
  }
  if (const char* cap = std::getenv("VOXELFFD_MAX_SIMD"))
  {
    const char* names[] = { "none", "sse2", "avx2", "avx512" };
    for (int l = 0; l < int(level); ++l)
    {
      if (std::strcmp(cap, names[l]) == 0)
      {
        return SimdLevel(l);
      }
    }
  }
  return level;
#else
  return SimdLevel::None;
#endif
}

} // namespace ffd

#endif
