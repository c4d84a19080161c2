// SPDX-License-Identifier: BSD-3-Clause
#include "FFDGridPasses.h"

#include "FFDGridPassLevels.h"

namespace ffd
{
namespace
{
/// The level asked for, or the widest compiled in below it (FFD_WIDEST_LANES); None where there are no lanes.
SimdLevel CompiledLevel(SimdLevel level)
{
#if FFD_HAVE_LANES
  return SimdLevel(std::min(int(level), FFD_WIDEST_LANES));
#else
  (void)level;
  return SimdLevel::None;
#endif
}

template <typename Real>
void InPlace(SimdLevel level, const GridLattice<Real>& lattice, const Real* in, const int* cells, Real* out,
  const BlockCells& blocks, std::int64_t blockBegin, std::int64_t blockEnd, bool stream)
{
  stream = stream && reinterpret_cast<std::uintptr_t>(out) % 64 == 0;
  switch (CompiledLevel(level))
  {
#if FFD_HAVE_LANES
#if FFD_WIDEST_LANES >= 3
    case SimdLevel::AVX512:
      return detail::InPlaceAt<SimdLevel::AVX512>(lattice, in, cells, out, blocks, blockBegin, blockEnd, stream);
#endif
#if FFD_WIDEST_LANES >= 2
    case SimdLevel::AVX2:
      return detail::InPlaceAt<SimdLevel::AVX2>(lattice, in, cells, out, blocks, blockBegin, blockEnd, stream);
#endif
    case SimdLevel::SSE2:
      return detail::InPlaceAt<SimdLevel::SSE2>(lattice, in, cells, out, blocks, blockBegin, blockEnd, stream);
#endif
    default:
      break;
  }
  WithGridDeformation(lattice,
    [&](const auto& deformation)
    {
      for (std::int64_t b = blockBegin; b < blockEnd && b < std::int64_t(blocks.Entry.size()); ++b)
      {
        if (!blocks.InPlace(b))
        {
          continue;
        }
        for (std::int64_t i = b * BlockSize; i < (b + 1) * BlockSize; ++i)
        {
          detail::DeformOnePoint(deformation, in, cells, out, i, 0);
        }
      }
    });
}

template <typename Real>
void WithJacobian(SimdLevel level, const GridLattice<Real>& lattice, const Real* in, const int* cells,
  const BlockCells& blocks, const Real* inNormals, Real* out, Real* outNormals, Real* determinants, std::int64_t begin,
  std::int64_t end)
{
  switch (CompiledLevel(level))
  {
#if FFD_HAVE_LANES
#if FFD_WIDEST_LANES >= 3
    case SimdLevel::AVX512:
      return detail::WithJacobianAt<SimdLevel::AVX512>(
        lattice, in, cells, blocks, inNormals, out, outNormals, determinants, begin, end);
#endif
#if FFD_WIDEST_LANES >= 2
    case SimdLevel::AVX2:
      return detail::WithJacobianAt<SimdLevel::AVX2>(
        lattice, in, cells, blocks, inNormals, out, outNormals, determinants, begin, end);
#endif
    case SimdLevel::SSE2:
      return detail::WithJacobianAt<SimdLevel::SSE2>(
        lattice, in, cells, blocks, inNormals, out, outNormals, determinants, begin, end);
#endif
    default:
      break;
  }
  WithGridDeformation(lattice,
    [&](const auto& deformation)
    {
      for (std::int64_t i = begin; i < end; ++i)
      {
        detail::DeformOnePointWithJacobian(deformation, in, cells, inNormals, out, outNormals, determinants, i);
      }
    });
}

template <typename Real>
void Gathered(SimdLevel level, const GridLattice<Real>& lattice, const Real* listed, const GatheredPoints& gathered,
  Real* out, std::int64_t tileBegin, std::int64_t tileEnd, Real* staging)
{
  for (std::int64_t t = tileBegin; t < tileEnd; ++t)
  {
    const std::int64_t first = gathered.TileBlocks[std::size_t(t)], last = gathered.TileBlocks[std::size_t(t) + 1];
    if (first == last)
    {
      continue;
    }
    switch (CompiledLevel(level))
    {
#if FFD_HAVE_LANES
#if FFD_WIDEST_LANES >= 3
      case SimdLevel::AVX512:
        detail::GatheredAt<SimdLevel::AVX512>(lattice, listed, gathered, t, staging, out);
        continue;
#endif
#if FFD_WIDEST_LANES >= 2
      case SimdLevel::AVX2:
        detail::GatheredAt<SimdLevel::AVX2>(lattice, listed, gathered, t, staging, out);
        continue;
#endif
      case SimdLevel::SSE2:
        detail::GatheredAt<SimdLevel::SSE2>(lattice, listed, gathered, t, staging, out);
        continue;
#endif
      default:
        break;
    }
    WithGridDeformation(lattice,
      [&](const auto& deformation)
      {
        for (std::int64_t g = first * BlockSize; g < last * BlockSize; ++g)
        {
          detail::DeformOnePoint(deformation, listed, gathered.Cells.data(), staging, g, first * BlockSize);
        }
      });
    detail::WriteTile(gathered, t, staging, out);
  }
}
} // namespace

void DeformBlocksInPlace(SimdLevel level, const GridLattice<float>& lattice, const float* in, const int* cells,
  float* out, const BlockCells& blocks, std::int64_t blockBegin, std::int64_t blockEnd, bool stream)
{
  InPlace(level, lattice, in, cells, out, blocks, blockBegin, blockEnd, stream);
}

void DeformBlocksInPlace(SimdLevel level, const GridLattice<double>& lattice, const double* in, const int* cells,
  double* out, const BlockCells& blocks, std::int64_t blockBegin, std::int64_t blockEnd, bool stream)
{
  InPlace(level, lattice, in, cells, out, blocks, blockBegin, blockEnd, stream);
}

void DeformWithJacobian(SimdLevel level, const GridLattice<float>& lattice, const float* in, const int* cells,
  const BlockCells& blocks, const float* inNormals, float* out, float* outNormals, float* determinants,
  std::int64_t begin, std::int64_t end)
{
  WithJacobian(level, lattice, in, cells, blocks, inNormals, out, outNormals, determinants, begin, end);
}

void DeformWithJacobian(SimdLevel level, const GridLattice<double>& lattice, const double* in, const int* cells,
  const BlockCells& blocks, const double* inNormals, double* out, double* outNormals, double* determinants,
  std::int64_t begin, std::int64_t end)
{
  WithJacobian(level, lattice, in, cells, blocks, inNormals, out, outNormals, determinants, begin, end);
}

void DeformGathered(SimdLevel level, const GridLattice<float>& lattice, const float* listed,
  const GatheredPoints& gathered, float* out, std::int64_t tileBegin, std::int64_t tileEnd, float* staging)
{
  Gathered(level, lattice, listed, gathered, out, tileBegin, tileEnd, staging);
}

void DeformGathered(SimdLevel level, const GridLattice<double>& lattice, const double* listed,
  const GatheredPoints& gathered, double* out, std::int64_t tileBegin, std::int64_t tileEnd, double* staging)
{
  Gathered(level, lattice, listed, gathered, out, tileBegin, tileEnd, staging);
}

} // namespace ffd
