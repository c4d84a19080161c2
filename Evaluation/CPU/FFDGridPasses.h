// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDGridPasses.h
 * @brief The CPU passes of a grid lattice over bound points: the entry points of the FFDCpu library (host only).
 *
 * Non-template functions, one per pass and precision, over a lattice described at run time (GridLattice). The
 * library compiles each pass once per SIMD level, in a translation unit per level (FFDGridPassesSSE2.cxx,
 * FFDGridPassesAVX2.cxx, FFDGridPassesAVX512.cxx), for each basis (ffd::WithStaticBasis()) with and without
 * a cell table, and chooses here the level asked for: the VTK modules, the ParaView plugin and the kernel tests
 * link these same functions. How the passes split the points: FFDGridLanes.h.
 */
#ifndef FFDGridPasses_h
#define FFDGridPasses_h

#include "FFDCellTable.h"
#include "FFDFrame.h"
#include "FFDGridBasis.h"
#include "FFDGridDeformation.h"
#include "FFDPointBlocks.h"
#include "FFDSimdLevel.h"

#include <cstdint>

namespace ffd
{

/// A grid lattice as the passes read it: the fields of a GridDeformation, its basis chosen at run time.
template <typename Real>
struct GridLattice
{
  GridBasis Basis;
  int Voxels[3];             ///< the lattice's divisions
  int Dims[3];               ///< control points per axis
  const Real* Displacements; ///< 3 per control point (GridDeformation::Displacements)
  ffd::Frame<Real> Frame;
  const Real* CellTable = nullptr; ///< FillCellTable() of Displacements; not null: cells evaluated from it
  const int* CellVoxels = nullptr; ///< a sparse lattice's (GridDeformation::CellVoxels), else null
  const int* CellSupports = nullptr;
};

/// f(deformation) with `lattice` as the GridDeformation of its basis (WithStaticBasis()), evaluated from its
/// cell table where it has one: how the passes instantiate the kernels, for a caller's own loop over points.
template <typename Real, typename F>
inline void WithGridDeformation(const GridLattice<Real>& lattice, F&& f)
{
  WithStaticBasis(lattice.Basis,
    [&](auto maxCount, auto basis)
    {
      constexpr int MaxCount = decltype(maxCount)::value, Basis = decltype(basis)::value;
      auto make = [&](auto withCellTable)
      {
        return GridDeformation<MaxCount, Real, Basis, Real, decltype(withCellTable)::value>{ lattice.Basis,
          { lattice.Voxels[0], lattice.Voxels[1], lattice.Voxels[2] },
          { lattice.Dims[0], lattice.Dims[1], lattice.Dims[2] }, lattice.Displacements, lattice.Frame,
          lattice.CellTable, lattice.CellVoxels, lattice.CellSupports };
      };
      if constexpr (Basis != int(GridBasis::Bernstein))
      {
        if (lattice.CellTable)
        {
          f(make(std::true_type()));
          return;
        }
      }
      f(make(std::false_type()));
    });
}

/**
 * First pass: out = the deformation of in for the points of blocks [blockBegin, blockEnd) that are deformed in
 * place (BlockCells::InPlace(); `blocks` from ListBlockCells() with the maxCells given to GatheredBlocks()); the
 * others, and the last block where it is partial, are left to DeformGathered(). 3 values per point (x y z),
 * cells[i] from BindToGrid() (-1: the point keeps its position). `level` at most SimdLevelOfCpu(). With
 * `stream` (StreamOutput()), and out aligned to 64 bytes, the lanes write by non-temporal stores.
 */
void DeformBlocksInPlace(SimdLevel level, const GridLattice<float>& lattice, const float* in, const int* cells,
  float* out, const BlockCells& blocks, std::int64_t blockBegin, std::int64_t blockEnd, bool stream = false);
void DeformBlocksInPlace(SimdLevel level, const GridLattice<double>& lattice, const double* in, const int* cells,
  double* out, const BlockCells& blocks, std::int64_t blockBegin, std::int64_t blockEnd, bool stream = false);

/**
 * Points [begin, end) with their Jacobians, in order (no gathering; begin is the first point of a block, `blocks`
 * from ListBlockCells() of all points): out as DeformBlocksInPlace() and DeformGathered() write it, and, where
 * not null, outNormals (the normals inNormals transformed, TransformNormal()) and determinants (of the
 * Jacobians). Every array holds Real values, 3 per point but determinants.
 */
void DeformWithJacobian(SimdLevel level, const GridLattice<float>& lattice, const float* in, const int* cells,
  const BlockCells& blocks, const float* inNormals, float* out, float* outNormals, float* determinants,
  std::int64_t begin, std::int64_t end);
void DeformWithJacobian(SimdLevel level, const GridLattice<double>& lattice, const double* in, const int* cells,
  const BlockCells& blocks, const double* inNormals, double* out, double* outNormals, double* determinants,
  std::int64_t begin, std::int64_t end);

/**
 * Second pass: the listed points of tiles [tileBegin, tileEnd) of `gathered` (of GatheredPoints::TileCount()),
 * whose coordinates `listed` holds in listed order (CopyGatheredPoints()), each written to its place in out.
 * `staging` holds GatherStaging Reals, the caller's so that a thread allocates it once.
 */
void DeformGathered(SimdLevel level, const GridLattice<float>& lattice, const float* listed,
  const GatheredPoints& gathered, float* out, std::int64_t tileBegin, std::int64_t tileEnd, float* staging);
void DeformGathered(SimdLevel level, const GridLattice<double>& lattice, const double* listed,
  const GatheredPoints& gathered, double* out, std::int64_t tileBegin, std::int64_t tileEnd, double* staging);

} // namespace ffd

#endif
