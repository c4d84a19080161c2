// SPDX-License-Identifier: BSD-3-Clause
#include "FFDGridPasses.h"

#include "FFDGridPassLevels.h"

namespace ffd
{
namespace
{
template <typename Real>
void InPlace(SimdLevel level, const GridLattice<Real>& lattice, const Real* in, const int* cells, Real* out,
  const BlockCells& blocks, std::int64_t blockBegin, std::int64_t blockEnd, bool stream)
{
  stream = stream && reinterpret_cast<std::uintptr_t>(out) % 64 == 0;
  if (detail::WithCompiledLevel(level,
        [&](auto compiled) {
          detail::InPlaceAt<decltype(compiled)::value>(lattice, in, cells, out, blocks, blockBegin, blockEnd, stream);
        }))
  {
    return;
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
  if (detail::WithCompiledLevel(level,
        [&](auto compiled)
        {
          detail::WithJacobianAt<decltype(compiled)::value>(
            lattice, in, cells, blocks, inNormals, out, outNormals, determinants, begin, end);
        }))
  {
    return;
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
    if (detail::WithCompiledLevel(level,
          [&](auto compiled)
          { detail::GatheredAt<decltype(compiled)::value>(lattice, listed, gathered, t, staging, out); }))
    {
      continue;
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
