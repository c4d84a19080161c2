// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDGridPassLevels.h
 * @brief What the FFDCpu library's dispatch (FFDGridPasses.cxx) and its translation units per SIMD level share.
 *
 * Each level's passes are function templates on the level and the precision, declared here, defined by
 * FFDGridLanes.h and explicitly instantiated by that level's translation unit only (FFD_INSTANTIATE_GRID_PASSES):
 * the one compiled copy of each. Library-internal (not for the VTK modules, which call FFDGridPasses.h).
 */
#ifndef FFDGridPassLevels_h
#define FFDGridPassLevels_h

#include "FFDAdjointPasses.h"
#include "FFDDeformPoint.h"
#include "FFDGridDeformation.h"
#include "FFDGridPasses.h"
#include "FFDInversePasses.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <type_traits>

namespace ffd
{
namespace detail
{
/// Point i deformed alone, written to out + 3 (i - outFirst): cell -1 keeps its position.
template <typename Deformation, typename Real>
inline void DeformOnePoint(
  const Deformation& deformation, const Real* in, const int* cells, Real* out, std::int64_t i, std::int64_t outFirst)
{
  DeformBoundPoint<false>(deformation, Vec3<Real>::From(in + 3 * i), cells[i], out + 3 * (i - outFirst));
}

/**
 * Tile t's results, staged in its run's order (DeformGathered()), written out in point order. In a whole block each
 * point but the last is copied as 4 Reals, the fourth landing on the next point's x, which the next copy then
 * writes; `staged` holds one Real past the tile (GatherStaging) for the read of the last staged point's. With
 * the copies unrolled over the block, that is one move a point instead of two and no loop per point.
 */
template <typename Real>
inline void WriteTile(const GatheredPoints& gathered, std::int64_t t, const Real* staged, Real* out)
{
  for (std::int64_t k = gathered.TileSources[std::size_t(t)]; k < gathered.TileSources[std::size_t(t) + 1]; ++k)
  {
    const std::int64_t first = gathered.Sources[std::size_t(k)] * BlockSize;
    const std::uint16_t* ranks = gathered.Ranks.data() + k * BlockSize;
    const int count = int(std::min<std::int64_t>(BlockSize, gathered.Points - first));
    Real* to = out + 3 * first;
    if (count == BlockSize)
    {
#pragma GCC unroll 16
      for (int l = 0; l < BlockSize - 1; ++l)
      {
        std::memcpy(to + 3 * l, staged + 3 * std::int64_t(ranks[l]), 4 * sizeof(Real));
      }
      std::memcpy(to + 3 * (BlockSize - 1), staged + 3 * std::int64_t(ranks[BlockSize - 1]), 3 * sizeof(Real));
      continue;
    }
    for (int l = 0; l < count; ++l)
    {
      std::memcpy(to + 3 * l, staged + 3 * std::int64_t(ranks[l]), 3 * sizeof(Real));
    }
  }
}

/// Point i deformed alone with its Jacobian: its position and, where `outNormals` (or `determinants`) is not
/// null, its transformed normal (its Jacobian's determinant).
template <typename Deformation, typename Real>
inline void DeformOnePointWithJacobian(const Deformation& deformation, const Real* in, const int* cells,
  const Real* inNormals, Real* out, Real* outNormals, Real* determinants, std::int64_t i)
{
  DeformBoundPoint<true>(deformation, Vec3<Real>::From(in + 3 * i), cells[i], out + 3 * i,
    outNormals ? inNormals + 3 * i : nullptr, outNormals ? outNormals + 3 * i : nullptr,
    determinants ? determinants + i : nullptr);
}

/// The level of the kernels of a translation unit (FFD_DEFINE_GRID_KERNELS(), FFD_DEFINE_INVERSE_KERNEL()).
template <SimdLevel Level>
struct LevelTag
{
};

/**
 * f(level) with `level` (at most SimdLevelOfCpu()) as a compile-time constant, std::integral_constant<SimdLevel,
 * L>, L the widest level compiled in (FFD_WIDEST_LANES) up to `level`: the one place that knows which levels a
 * build has. False, and f not called, where there are no lanes or `level` is None.
 */
template <typename F>
bool WithCompiledLevel(SimdLevel level, F&& f)
{
#if FFD_HAVE_LANES
  switch (SimdLevel(std::min(int(level), FFD_WIDEST_LANES)))
  {
#if FFD_WIDEST_LANES >= 3
    case SimdLevel::AVX512:
      f(std::integral_constant<SimdLevel, SimdLevel::AVX512>());
      return true;
#endif
#if FFD_WIDEST_LANES >= 2
    case SimdLevel::AVX2:
      f(std::integral_constant<SimdLevel, SimdLevel::AVX2>());
      return true;
#endif
    case SimdLevel::SSE2:
      f(std::integral_constant<SimdLevel, SimdLevel::SSE2>());
      return true;
    default:
      break;
  }
#endif
  (void)level;
  (void)f;
  return false;
}

template <SimdLevel Level, typename Real>
void InPlaceAt(const GridLattice<Real>& lattice, const Real* in, const int* cells, Real* out, const BlockCells& blocks,
  std::int64_t blockBegin, std::int64_t blockEnd, bool stream);
template <SimdLevel Level, typename Real>
void WithJacobianAt(const GridLattice<Real>& lattice, const Real* in, const int* cells, const BlockCells& blocks,
  const Real* inNormals, Real* out, Real* outNormals, Real* determinants, std::int64_t begin, std::int64_t end);
template <SimdLevel Level, typename Real>
void GatheredAt(const GridLattice<Real>& lattice, const Real* listed, const GatheredPoints& gathered, std::int64_t t,
  Real* staged, Real* out);
template <SimdLevel Level>
void InvertAt(const GridLattice<double>& lattice, const InverseLaneSearch& search, InverseLaneGroup& group);
template <SimdLevel Level>
void AdjointAt(const GridLattice<double>& lattice, const AdjointChunk& chunk);

} // namespace detail
} // namespace ffd

// The explicit instantiations of one level's passes (each in its translation unit, so that a module links only
// the passes it calls): the evaluation's in both precisions, the inverse's search and the adjoint's sums in float64.
#define FFD_INSTANTIATE_GRID_PASSES_OF(Level, Real)                                                                    \
  template void ffd::detail::InPlaceAt<Level, Real>(const ffd::GridLattice<Real>&, const Real*, const int*, Real*,     \
    const ffd::BlockCells&, std::int64_t, std::int64_t, bool);                                                         \
  template void ffd::detail::WithJacobianAt<Level, Real>(const ffd::GridLattice<Real>&, const Real*, const int*,       \
    const ffd::BlockCells&, const Real*, Real*, Real*, Real*, std::int64_t, std::int64_t);                             \
  template void ffd::detail::GatheredAt<Level, Real>(                                                                  \
    const ffd::GridLattice<Real>&, const Real*, const ffd::GatheredPoints&, std::int64_t, Real*, Real*);
#define FFD_INSTANTIATE_GRID_PASSES(Level)                                                                             \
  FFD_INSTANTIATE_GRID_PASSES_OF(Level, float)                                                                         \
  FFD_INSTANTIATE_GRID_PASSES_OF(Level, double)
#define FFD_INSTANTIATE_INVERSE_PASS(Level)                                                                            \
  template void ffd::detail::InvertAt<Level>(                                                                          \
    const ffd::GridLattice<double>&, const ffd::InverseLaneSearch&, ffd::InverseLaneGroup&);
#define FFD_INSTANTIATE_ADJOINT_PASS(Level)                                                                            \
  template void ffd::detail::AdjointAt<Level>(const ffd::GridLattice<double>&, const ffd::AdjointChunk&);

#endif
