// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDGridLanes.h
 * @brief Deforms points W at a time on the CPU, with the widest SIMD the CPU has (host only).
 *
 * GridDeformation's functions instantiated on Lanes<Real, W> (FFDLanes.h) deform W points at once. The points
 * are taken in blocks of BlockSize consecutive points, and a binding chooses how (MaxCellsInPlace(), from its
 * mean number of cells a block):
 * - In place (DeformBlocksInPlace()), reading and writing memory in order. A lane group in one cell reads each
 *   control point once for all lanes. A group in several cells (listed at binding, ListBlockCells()) computes
 *   each lane's weights once, then each cell's sum in all lanes, kept in that cell's lanes
 *   (DeformInLaneCells(), FFDLaneCells.h).
 * - Gathered (DeformGathered()): the points of the blocks in more than MaxCellsInPlace() cells are listed once,
 *   at binding, tile by tile, each tile's sorted by cell (ListGatheredPoints()); the caller keeps a copy of
 *   their coordinates in that order (CopyGatheredPoints()). The pass deforms a tile's list in order into a
 *   staging buffer that stays in cache, then writes the tile's results out in point order, each read from its
 *   place in the buffer.
 * A mesh whose vertices come in a spatially coherent order has most of its groups in one cell and a few in two
 * or three: it is deformed in place. A mesh in random vertex order (several cells a block on average) would
 * evaluate several cells a group: all its blocks are gathered.
 * Every lane's result depends only on its own point and cell, so a point is deformed the same whichever pass
 * takes it and however the work is split among threads. The one-point code (SimdLevel::None) computes the same
 * function; it may differ in the last bit, where the wide code fuses a multiply and an add.
 *
 * The default build must run on any x86-64, so the wide variants are compiled with GCC's target attribute
 * (AVX-512: 16 floats or 8 doubles a lane group; AVX2 and FMA: 8 or 4) and chosen at run time by
 * SimdLevelOfCpu(); `flatten` inlines every kernel function into them, so that no out-of-line copy compiled for
 * one instruction set is shared with code compiled for another. SSE2 (any x86-64) takes 4 floats or 2 doubles.
 */
#ifndef FFDGridLanes_h
#define FFDGridLanes_h

#include "FFDCellTable.h"
#include "FFDDeformPoint.h"
#include "FFDGridDeformation.h"
#include "FFDLaneCells.h"
#include "FFDPointBlocks.h"

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <vector>

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

#if FFD_HAVE_LANES
} // namespace detail

namespace detail
{
/// The flat index of the first control point of a cell (not -1) of a local basis, or a sparse lattice's cell's
/// first entry in CellSupports, and the cell's index along each axis.
template <typename Deformation>
inline int FirstOfCell(const Deformation& deformation, const CellSplit& split, int cell, int index[3])
{
  deformation.CellIndices(split, cell, index);
  if (deformation.IsSparse())
  {
    const int n = deformation.SupportCount();
    return cell * n * n * n;
  }
  int first[3], count;
  for (int a = 0; a < 3; ++a)
  {
    VoxelSupport(deformation.BasisOf(), deformation.Voxels[a], index[a], first[a], count);
  }
  return first[0] + deformation.Dims[0] * (first[1] + deformation.Dims[1] * first[2]);
}

/// The mask of the lanes whose bits are set.
template <typename Lane, std::size_t... L>
inline typename Lane::IndexVector MaskOfBits(unsigned bits, std::index_sequence<L...>)
{
  using Mask = typename Lane::IndexVector;
  using Index = typename Lane::Index;
  const Mask lane = { Index(Index(1) << L)... };
  return (lane & (Mask{} + Index(bits))) != Mask{};
}

/**
 * The cells of lane group `group` (of the BlockSize / W of a block) of a local basis, from the block's entry in
 * BlockCells::List, for DeformInLaneCells(). Lanes bound to no cell take the first cell's
 * indices (and keep their position).
 */
template <typename Lane>
struct GroupCells
{
  using Mask = typename Lane::IndexVector;
  int Count = 0;
  int Cells[Lane::Width];      ///< each cell (BindToGrid()'s flat index)
  int Firsts[Lane::Width];     ///< each cell's first control point (not with a CellTable)
  int Indices[Lane::Width][3]; ///< each cell's index along each axis (not with a CellTable)
  Mask Lanes[Lane::Width];     ///< each cell's lanes
  Mask Bound = {};             ///< the lanes bound to a cell

  template <typename Deformation>
  GroupCells(const Deformation& deformation, const CellSplit& split, const int* entry, int group)
  {
    const unsigned lanes = unsigned((std::uint64_t(1) << Lane::Width) - 1);
    for (int k = 0; k < entry[0]; ++k)
    {
      const unsigned bits = (unsigned(entry[3 + 2 * k]) >> (group * Lane::Width)) & lanes;
      if (bits == 0)
      {
        continue;
      }
      const Mask mine = MaskOfBits<Lane>(bits, std::make_index_sequence<Lane::Width>());
      const int cell = entry[2 + 2 * k];
      this->Cells[this->Count] = cell;
      if constexpr (!Deformation::UsesCellTable())
      {
        this->Firsts[this->Count] = FirstOfCell(deformation, split, cell, this->Indices[this->Count]);
      }
      this->Lanes[this->Count] = mine;
      this->Bound |= mine;
      ++this->Count;
    }
  }
};

template <typename Lane>
inline typename Lane::IndexVector LaneCellsOf(const int* cells)
{
  typedef int CellVector __attribute__((vector_size(Lane::Width * sizeof(int))));
  CellVector narrow;
  std::memcpy(&narrow, cells, sizeof(narrow));
  return __builtin_convertvector(narrow, typename Lane::IndexVector);
}

/// Blocks of the in-place pass (of a local basis) whose points are not all in one cell.
template <typename Lane, bool Streaming, typename Deformation, typename Wide, typename Real>
inline void DeformInSeveralCells(const Deformation& deformation, const Wide& wide, const CellSplit& split,
  const BlockCells& blocks, const Real* in, Real* out, std::int64_t outFirst, const std::int64_t* several,
  int severalCount)
{
  for (int s = 0; s < severalCount; ++s)
  {
    const int* entry = blocks.List.data() + blocks.Entry[std::size_t(several[s])];
    for (int group = 0; group < BlockSize / Lane::Width; ++group)
    {
      const std::int64_t i = several[s] * BlockSize + group * Lane::Width;
      Vec3<Lane> x;
      Lane::Deinterleave3(in + 3 * i, x.x, x.y, x.z);
      const GroupCells<Lane> cells(deformation, split, entry, group);
      Vec3<Lane> y = x;
      if (cells.Count > 0)
      {
        const Vec3<Lane> yc = DeformInLaneCells(wide, x, cells);
        y = { Select(cells.Bound, yc.x, x.x), Select(cells.Bound, yc.y, x.y), Select(cells.Bound, yc.z, x.z) };
      }
      Lane::template Interleave3<Streaming>(y.x, y.y, y.z, out + 3 * (i - outFirst));
    }
  }
}

/// The in-place pass over blocks [blockBegin, blockEnd); point i's result goes to out + 3 (i - outFirst), by
/// non-temporal stores where Streaming (out + 3 (blockBegin BlockSize - outFirst) aligned to 64 bytes).
template <int W, bool Streaming, typename Deformation, typename Real>
inline void BlocksInPlaceInLanes(const Deformation& deformation, const Real* in, const int* cells, Real* out,
  const BlockCells& blocks, std::int64_t blockBegin, std::int64_t blockEnd, std::int64_t outFirst)
{
  static_assert(BlockSize % W == 0, "a block is a whole number of lane groups");
  using Lane = Lanes<Real, W>;
  using Mask = typename Lane::IndexVector;
  const auto wide = deformation.template WithLanes<Lane>();
  const bool global = deformation.BasisOf() == GridBasis::Bernstein;
  const CellSplit split = CellSplit::For(deformation.BasisOf(), deformation.Voxels);
  blockEnd = std::min(blockEnd, std::int64_t(blocks.Entry.size())); // the last, partial block is gathered
  // Blocks in several cells are deformed after the others of a window of blocks, still in cache: kept out of the
  // loop over the window, their code leaves that loop's registers to the common case.
  std::int64_t several[InPlaceWindow];
  for (std::int64_t window = blockBegin; window < blockEnd; window += InPlaceWindow)
  {
    int severalCount = 0;
    for (std::int64_t b = window; b < blockEnd && b < window + InPlaceWindow; ++b)
    {
      if (!blocks.InPlace(b))
      {
        continue;
      }
      if (b + PrefetchBlocks < blockEnd)
      {
        // The points a few blocks ahead: the hardware prefetcher does not fetch them in time on large meshes.
        const char* ahead = reinterpret_cast<const char*>(in + 3 * (b + PrefetchBlocks) * BlockSize);
        for (std::size_t line = 0; line < 3 * BlockSize * sizeof(Real); line += 64)
        {
          __builtin_prefetch(ahead + line);
        }
      }
      if (!global && blocks.Entry[std::size_t(b)] >= 0)
      {
        several[severalCount++] = b;
        continue;
      }
      const int first = cells[b * BlockSize];
      int c[3];
      if constexpr (!Deformation::UsesCellTable())
      {
        deformation.CellIndices(split, first < 0 ? 0 : first, c);
      }
      constexpr int Groups = BlockSize / W;
      const std::int64_t begin = b * BlockSize;
      Vec3<Lane> x[Groups], y[Groups];
      for (int g = 0; g < Groups; ++g)
      {
        Lane::Deinterleave3(in + 3 * (begin + g * W), x[g].x, x[g].y, x[g].z);
        y[g] = x[g]; // lanes of cell -1 keep their position
      }
      if (global)
      {
        // The global basis has one cell, 0.
        for (int g = 0; g < Groups; ++g)
        {
          const Mask bound = LaneCellsOf<Lane>(cells + begin + g * W) >= Mask{};
          const Vec3<Lane> yc = wide.Deform(x[g], 0);
          y[g] = { Select(bound, yc.x, x[g].x), Select(bound, yc.y, x[g].y), Select(bound, yc.z, x[g].z) };
        }
      }
      else if (first >= 0)
      {
        // One cell: each control point read once for all lanes of a group, or with a cell table each coefficient
        // once for all lanes of the block (GridDeformation::Deform() of Groups groups).
        if constexpr (Deformation::UsesCellTable())
        {
          wide.template Deform<Groups>(x, first, y);
        }
        else
        {
          for (int g = 0; g < Groups; ++g)
          {
            y[g] = wide.DeformInCell(x[g], first, c);
          }
        }
      }
      for (int g = 0; g < Groups; ++g)
      {
        Lane::template Interleave3<Streaming>(y[g].x, y[g].y, y[g].z, out + 3 * (begin + g * W - outFirst));
      }
    }
    DeformInSeveralCells<Lane, Streaming>(deformation, wide, split, blocks, in, out, outFirst, several, severalCount);
  }
}

/**
 * Point i deformed with its Jacobian (DeformOnePointWithJacobian()) in every lane of a group of its own: by the
 * lane code, not by scalar code, which the compiler may contract into multiply-adds differently in each of its
 * instantiations (that of a dense lattice and that of a sparse one would then differ in the last bit).
 */
template <typename Lane, typename Wide, typename Real>
inline void OnePointInLanes(const Wide& wide, const Real* in, const int* cells, const Real* inNormals, Real* out,
  Real* outNormals, Real* determinants, std::int64_t i)
{
  auto first = [](const Lane& lane)
  {
    Real v;
    std::memcpy(&v, &lane.V, sizeof(Real));
    return v;
  };
  const Vec3<Lane> x = { Lane(in[3 * i]), Lane(in[3 * i + 1]), Lane(in[3 * i + 2]) };
  Mat3<Lane> jacobian = Mat3<Lane>::Identity(); // cell -1 keeps its position
  const Vec3<Lane> y = cells[i] < 0 ? x : wide.Deform(x, cells[i], jacobian);
  out[3 * i] = first(y.x);
  out[3 * i + 1] = first(y.y);
  out[3 * i + 2] = first(y.z);
  if (outNormals)
  {
    const Vec3<Lane> n = { Lane(inNormals[3 * i]), Lane(inNormals[3 * i + 1]), Lane(inNormals[3 * i + 2]) };
    const Vec3<Lane> m = TransformNormal(jacobian, n);
    outNormals[3 * i] = first(m.x);
    outNormals[3 * i + 1] = first(m.y);
    outNormals[3 * i + 2] = first(m.z);
  }
  if (determinants)
  {
    determinants[i] = first(Determinant(jacobian));
  }
}

template <int W, typename Deformation, typename Real>
inline void WithJacobianInLanes(const Deformation& deformation, const Real* in, const int* cells,
  const BlockCells& blocks, const Real* inNormals, Real* out, Real* outNormals, Real* determinants, std::int64_t begin,
  std::int64_t end)
{
  using Lane = Lanes<Real, W>;
  using Mask = typename Lane::IndexVector;
  const auto wide = deformation.template WithLanes<Lane>();
  const bool global = deformation.BasisOf() == GridBasis::Bernstein;
  const CellSplit split = CellSplit::For(deformation.BasisOf(), deformation.Voxels);
  const Mat3<Lane> identity = Mat3<Lane>::Identity();
  // Whole blocks in lanes (begin is a block's first point), the last points one at a time (OnePointInLanes()).
  const std::int64_t whole = std::min(end, std::int64_t(blocks.Entry.size()) * BlockSize);
  std::int64_t i = begin;
  for (; i < whole; i += W)
  {
    Vec3<Lane> x;
    Lane::Deinterleave3(in + 3 * i, x.x, x.y, x.z);
    const int entry = blocks.Entry[std::size_t(i / BlockSize)];
    Vec3<Lane> yc = x;
    Mat3<Lane> jc = identity;
    Mask bound = {};
    if (global)
    {
      bound = LaneCellsOf<Lane>(cells + i) >= Mask{};
      yc = wide.Deform(x, 0, jc);
    }
    else if (entry < 0)
    {
      // One cell (or none) for the whole block.
      if (cells[i] >= 0)
      {
        bound = ~Mask{};
        yc = wide.Deform(x, cells[i], jc);
      }
    }
    else
    {
      // Every cell of the group: the weights and their derivatives once for all lanes, a sum per cell.
      const GroupCells<Lane> group(deformation, split, blocks.List.data() + entry, int(i % BlockSize) / W);
      bound = group.Bound;
      if (group.Count > 0)
      {
        yc = DeformInLaneCells(wide, x, group, jc);
      }
    }
    // Lanes of cell -1 keep their position, their Jacobian is the identity.
    const Vec3<Lane> y = { Select(bound, yc.x, x.x), Select(bound, yc.y, x.y), Select(bound, yc.z, x.z) };
    Mat3<Lane> jacobian;
    for (int r = 0; r < 3; ++r)
    {
      for (int c = 0; c < 3; ++c)
      {
        jacobian.M[r][c] = Select(bound, jc.M[r][c], identity.M[r][c]);
      }
    }
    Lane::Interleave3(y.x, y.y, y.z, out + 3 * i);
    if (outNormals)
    {
      Vec3<Lane> normal;
      Lane::Deinterleave3(inNormals + 3 * i, normal.x, normal.y, normal.z);
      const Vec3<Lane> m = TransformNormal(jacobian, normal);
      Lane::Interleave3(m.x, m.y, m.z, outNormals + 3 * i);
    }
    if (determinants)
    {
      const Lane det = Determinant(jacobian);
      std::memcpy(determinants + i, &det.V, sizeof(det.V));
    }
  }
  for (; i < end; ++i) // the points of the last, partial block
  {
    OnePointInLanes<Lane>(wide, in, cells, inNormals, out, outNormals, determinants, i);
  }
}

/// Tile t of the gathered list deformed into staged, then written out (WriteTile(), compiled for the same
/// instruction set: float64 points copied as 4 Reals take one 32-byte move with AVX).
template <int W, typename Deformation, typename Real>
inline void GatheredInLanes(const Deformation& deformation, const Real* listed, const GatheredPoints& gathered,
  std::int64_t t, Real* staged, Real* out)
{
  const std::int64_t first = gathered.TileBlocks[std::size_t(t)], last = gathered.TileBlocks[std::size_t(t) + 1];
  BlocksInPlaceInLanes<W, false>(
    deformation, listed, gathered.Cells.data(), staged, gathered.Blocks, first, last, first * BlockSize);
  WriteTile(gathered, t, staged, out);
}

// The wide variants of both passes, one function per instruction set (see the file's documentation).
#define FFD_LANE_VARIANTS(Suffix, Target, Bytes)                                                                       \
  template <typename Deformation, typename Real>                                                                       \
  Target void BlocksInPlace##Suffix(const Deformation& deformation, const Real* in, const int* cells, Real* out,       \
    const BlockCells& blocks, std::int64_t blockBegin, std::int64_t blockEnd, bool stream)                             \
  {                                                                                                                    \
    constexpr int W = Bytes / sizeof(Real);                                                                            \
    if (stream)                                                                                                        \
    {                                                                                                                  \
      BlocksInPlaceInLanes<W, true>(deformation, in, cells, out, blocks, blockBegin, blockEnd, 0);                     \
      _mm_sfence(); /* the non-temporal stores are seen by other threads after this */                                 \
    }                                                                                                                  \
    else                                                                                                               \
    {                                                                                                                  \
      BlocksInPlaceInLanes<W, false>(deformation, in, cells, out, blocks, blockBegin, blockEnd, 0);                    \
    }                                                                                                                  \
  }                                                                                                                    \
  template <typename Deformation, typename Real>                                                                       \
  Target void WithJacobian##Suffix(const Deformation& deformation, const Real* in, const int* cells,                   \
    const BlockCells& blocks, const Real* inNormals, Real* out, Real* outNormals, Real* determinants,                  \
    std::int64_t begin, std::int64_t end)                                                                              \
  {                                                                                                                    \
    WithJacobianInLanes<Bytes / sizeof(Real)>(                                                                         \
      deformation, in, cells, blocks, inNormals, out, outNormals, determinants, begin, end);                           \
  }                                                                                                                    \
  template <typename Deformation, typename Real>                                                                       \
  Target void Gathered##Suffix(const Deformation& deformation, const Real* listed, const GatheredPoints& gathered,     \
    std::int64_t t, Real* staged, Real* out)                                                                           \
  {                                                                                                                    \
    GatheredInLanes<Bytes / sizeof(Real)>(deformation, listed, gathered, t, staged, out);                              \
  }
FFD_LANE_VARIANTS(AVX512, FFD_TARGET_AVX512, 64)
FFD_LANE_VARIANTS(AVX2, FFD_TARGET_AVX2, 32)
FFD_LANE_VARIANTS(SSE2, FFD_TARGET_SSE2, 16)
#undef FFD_LANE_VARIANTS
#endif
} // namespace detail

/**
 * First pass: out = the deformation of in for the points of blocks [blockBegin, blockEnd) that are deformed in
 * place (BlockCells::InPlace(); `blocks` from ListBlockCells() with the maxCells given to GatheredBlocks()); the
 * others, and the last block where it is partial, are left to DeformGathered(). 3 values per point (x y z),
 * cells[i] from BindToGrid() (-1: the point keeps its position). `level` at most SimdLevelOfCpu(). With
 * `stream` (StreamOutput()), and out aligned to 64 bytes, the lanes write by non-temporal stores.
 */
template <typename Deformation, typename Real>
inline void DeformBlocksInPlace(SimdLevel level, const Deformation& deformation, const Real* in, const int* cells,
  Real* out, const BlockCells& blocks, std::int64_t blockBegin, std::int64_t blockEnd, bool stream = false)
{
#if FFD_HAVE_LANES
  stream = stream && reinterpret_cast<std::uintptr_t>(out) % 64 == 0;
  switch (level)
  {
    case SimdLevel::AVX512:
#if FFD_WIDEST_LANES >= 3
      return detail::BlocksInPlaceAVX512(deformation, in, cells, out, blocks, blockBegin, blockEnd, stream);
#endif
      [[fallthrough]];
    case SimdLevel::AVX2:
#if FFD_WIDEST_LANES >= 2
      return detail::BlocksInPlaceAVX2(deformation, in, cells, out, blocks, blockBegin, blockEnd, stream);
#endif
      [[fallthrough]];
    case SimdLevel::SSE2:
      return detail::BlocksInPlaceSSE2(deformation, in, cells, out, blocks, blockBegin, blockEnd, stream);
    case SimdLevel::None:
      break;
  }
#endif
  for (std::int64_t b = blockBegin; b < blockEnd && b < std::int64_t(blocks.Entry.size()); ++b)
  {
    if (blocks.InPlace(b))
    {
      for (std::int64_t i = b * BlockSize; i < (b + 1) * BlockSize; ++i)
      {
        detail::DeformOnePoint(deformation, in, cells, out, i, 0);
      }
    }
  }
}

/**
 * Points [begin, end) with their Jacobians, in order (no gathering; begin is the first point of a block, `blocks`
 * from ListBlockCells() of all points): out as DeformBlocksInPlace() and DeformGathered() write it, and, where
 * not null, outNormals (the normals inNormals transformed, TransformNormal()) and determinants (of the
 * Jacobians). Every array holds Real values, 3 per point but determinants.
 */
template <typename Deformation, typename Real>
inline void DeformWithJacobian(SimdLevel level, const Deformation& deformation, const Real* in, const int* cells,
  const BlockCells& blocks, const Real* inNormals, Real* out, Real* outNormals, Real* determinants, std::int64_t begin,
  std::int64_t end)
{
#if FFD_HAVE_LANES
  switch (level)
  {
    case SimdLevel::AVX512:
#if FFD_WIDEST_LANES >= 3
      return detail::WithJacobianAVX512(
        deformation, in, cells, blocks, inNormals, out, outNormals, determinants, begin, end);
#endif
      [[fallthrough]];
    case SimdLevel::AVX2:
#if FFD_WIDEST_LANES >= 2
      return detail::WithJacobianAVX2(
        deformation, in, cells, blocks, inNormals, out, outNormals, determinants, begin, end);
#endif
      [[fallthrough]];
    case SimdLevel::SSE2:
      return detail::WithJacobianSSE2(
        deformation, in, cells, blocks, inNormals, out, outNormals, determinants, begin, end);
    case SimdLevel::None:
      break;
  }
#endif
  for (std::int64_t i = begin; i < end; ++i)
  {
    detail::DeformOnePointWithJacobian(deformation, in, cells, inNormals, out, outNormals, determinants, i);
  }
}

/**
 * Second pass: the listed points of tiles [tileBegin, tileEnd) of `gathered` (of GatheredPoints::TileCount()),
 * whose coordinates `listed` holds in listed order (CopyGatheredPoints()), each written to its place in out.
 * `staging` holds GatherStaging Reals, the caller's so that a thread allocates it once.
 */
template <typename Deformation, typename Real>
inline void DeformGathered(SimdLevel level, const Deformation& deformation, const Real* listed,
  const GatheredPoints& gathered, Real* out, std::int64_t tileBegin, std::int64_t tileEnd, Real* staging)
{
  for (std::int64_t t = tileBegin; t < tileEnd; ++t)
  {
    const std::int64_t first = gathered.TileBlocks[std::size_t(t)], last = gathered.TileBlocks[std::size_t(t) + 1];
    if (first == last)
    {
      continue;
    }
    switch (level)
    {
#if FFD_HAVE_LANES
      case SimdLevel::AVX512:
#if FFD_WIDEST_LANES >= 3
        detail::GatheredAVX512(deformation, listed, gathered, t, staging, out);
        continue;
#endif
        [[fallthrough]];
      case SimdLevel::AVX2:
#if FFD_WIDEST_LANES >= 2
        detail::GatheredAVX2(deformation, listed, gathered, t, staging, out);
        continue;
#endif
        [[fallthrough]];
      case SimdLevel::SSE2:
        detail::GatheredSSE2(deformation, listed, gathered, t, staging, out);
        continue;
#endif
      default:
        break;
    }
    for (std::int64_t g = first * BlockSize; g < last * BlockSize; ++g)
    {
      detail::DeformOnePoint(deformation, listed, gathered.Cells.data(), staging, g, first * BlockSize);
    }
    detail::WriteTile(gathered, t, staging, out);
  }
}

} // namespace ffd

#endif
