// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDAdjointLanes.h
 * @brief How the adjoint's chunk sums run W points at a time (host only; the FFDCpu library's own).
 *
 * Included only by the library's translation unit of each level, which defines that level's kernel
 * (FFD_DEFINE_ADJOINT_KERNEL(), compiled for its instruction set) and instantiates it (FFDGridPassLevels.h).
 */
#ifndef FFDAdjointLanes_h
#define FFDAdjointLanes_h

#include "FFDAdjointPasses.h"
#include "FFDGridPassLevels.h"
#include "FFDSimdLevel.h"

#include <algorithm>
#include <cstring>

#if FFD_HAVE_LANES
namespace ffd
{
namespace detail
{
/**
 * The chunk's sums in lanes of W doubles: per group of W points (the last one padded with a zero gradient), their
 * weights in lanes, then for every term k and component c, sums[k][c] += (W1[j] W2[l]) (W0[i] g[c]) lane by lane;
 * at the end each term's lanes are added in lane order into the partial.
 */
template <int W, typename Deformation>
inline void SumChunkInLanes(const Deformation& deformation, const AdjointChunk& chunk)
{
  using Lane = Lanes<double, W>;
  const auto wide = deformation.template WithLanes<Lane>();
  const int n0 = SupportSize(deformation.BasisOf(), deformation.Voxels[0]);
  const int n1 = SupportSize(deformation.BasisOf(), deformation.Voxels[1]);
  const int n2 = SupportSize(deformation.BasisOf(), deformation.Voxels[2]);
  const int terms = n0 * n1 * n2;
  // W doubles a term and component, moved as unaligned vectors: a std::vector of 64-byte lanes would need
  // aligned storage that the allocator of a build without AVX-512 does not promise.
  double* sums = chunk.Scratch;
  std::fill(sums, sums + 3 * std::size_t(terms) * W, 0.0);
  int cell[3];
  deformation.CellIndices(chunk.Cell, cell);
  constexpr int M = Deformation::MaxWeights;
  for (std::int64_t first = 0; first < chunk.Count; first += W)
  {
    double x[3 * W], g[3 * W];
    for (int l = 0; l < W; ++l)
    {
      const std::int64_t p = std::min<std::int64_t>(first + l, chunk.Count - 1); // padding repeats the last point
      std::copy(chunk.X + 3 * p, chunk.X + 3 * p + 3, x + 3 * l);
      const bool real = first + l < chunk.Count;
      for (int c = 0; c < 3; ++c)
      {
        g[3 * l + c] = real ? chunk.G[3 * chunk.Ids[p] + c] : 0.0;
      }
    }
    Vec3<Lane> at, gradient;
    Lane::Deinterleave3(x, at.x, at.y, at.z);
    Lane::Deinterleave3(g, gradient.x, gradient.y, gradient.z);
    AxisWeights<M, Lane> axes[3];
    wide.WeightsInCell(at, cell, axes);
    Lane wsg[3 * M];
    for (int i = 0; i < n0; ++i)
    {
      wsg[3 * i] = axes[0].W[i] * gradient.x;
      wsg[3 * i + 1] = axes[0].W[i] * gradient.y;
      wsg[3 * i + 2] = axes[0].W[i] * gradient.z;
    }
    for (int l = 0; l < n2; ++l)
    {
      for (int j = 0; j < n1; ++j)
      {
        const Lane w = axes[1].W[j] * axes[2].W[l];
        double* row = sums + 3 * std::size_t(n0) * std::size_t(j + n1 * l) * W;
        for (int v = 0; v < 3 * n0; ++v)
        {
          Lane sum;
          std::memcpy(&sum.V, row + v * W, sizeof(sum.V));
          sum += w * wsg[v];
          std::memcpy(row + v * W, &sum.V, sizeof(sum.V));
        }
      }
    }
  }
  for (std::size_t v = 0; v < 3 * std::size_t(terms); ++v)
  {
    double sum = 0.0;
    for (int l = 0; l < W; ++l)
    {
      sum += sums[v * W + std::size_t(l)];
    }
    chunk.Partial[v] = sum;
  }
}

// A level's kernel: SumChunkInLanes() compiled for its instruction set (Target), in lanes of its width.
#define FFD_DEFINE_ADJOINT_KERNEL(Level, Target, Bytes)                                                                \
  template <typename Deformation>                                                                                      \
  Target void AdjointIn(LevelTag<Level>, const Deformation& deformation, const AdjointChunk& chunk)                    \
  {                                                                                                                    \
    SumChunkInLanes<Bytes / int(sizeof(double))>(deformation, chunk);                                                  \
  }

template <SimdLevel Level>
void AdjointAt(const GridLattice<double>& lattice, const AdjointChunk& chunk)
{
  WithGridDeformation(lattice, [&](const auto& deformation) { AdjointIn(LevelTag<Level>(), deformation, chunk); });
}

} // namespace detail
} // namespace ffd
#endif

#endif
