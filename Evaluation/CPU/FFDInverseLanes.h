// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDInverseLanes.h
 * @brief How the inverse's Newton search runs W points at a time (host only; the FFDCpu library's own).
 *
 * Included only by the library's translation unit of each level, which defines that level's kernel
 * (FFD_DEFINE_INVERSE_KERNEL(), compiled for its instruction set) and instantiates it (FFDGridPassLevels.h).
 */
#ifndef FFDInverseLanes_h
#define FFDInverseLanes_h

#include "FFDGridPassLevels.h"
#include "FFDInversePasses.h"
#include "FFDLaneCells.h"
#include "FFDSimdLevel.h"

#include <algorithm>
#include <cstring>
#include <limits>
#include <utility>

#if FFD_HAVE_LANES
namespace ffd
{
namespace detail
{
// The lanes at x that ffd::BindToCells() binds to `cell` (under clamping): along each axis of n cells, the
// parameter clamped to [0, 1] times n, truncated, within [0, n - 1], is the cell's index. Tested in lanes: most
// iterates stay in their cell, and binding them one by one would cost a fifth of the search.
template <typename Deformation, typename Wide, typename Lane>
inline unsigned StayingLanes(
  const Deformation& deformation, const Wide& wide, const ffd::CellSplit& split, const ffd::Vec3<Lane>& x, int cell)
{
  using Mask = typename Lane::IndexVector;
  int c[3];
  deformation.CellIndices(split, cell, c);
  const ffd::Vec3<Lane> stu = wide.Frame.ToParametric(x);
  const Lane largest(std::numeric_limits<double>::max());
  Mask stays = ~Mask{};
  for (int a = 0; a < 3; ++a)
  {
    const int n = ffd::BindingCells(deformation.BasisOf(), deformation.Voxels[a]);
    const Lane q = Clamp01(stu[a]) * Lane(n);
    const Mask below = c[a] == n - 1 ? ~Mask{} : q.V < Lane(c[a] + 1).V;
    stays &= InRange(stu[a], -largest, largest) & (q.V >= Lane(c[a]).V) & below;
  }
  return Lane::Bits(stays);
}

// The cells of the lanes in `active`: `known` where not null, else theirs in `cells` for the lanes of `keep`,
// else the cell that extends F to x for the search (a dense lattice's by BindToGrid() under clamping, a sparse
// lattice's by InverseLaneBinder::Bind()). A lane without one leaves `active`, which is returned. The other lanes
// take the first active lane's cell, so that they never add a cell to evaluate.
template <typename Deformation, typename Lane>
inline unsigned BindLanes(const InverseLaneSearch& settings, const Deformation& deformation, const ffd::Vec3<Lane>& x,
  const int* known, unsigned keep, unsigned active, int* cells)
{
  for (int l = 0; l < Lane::Width; ++l)
  {
    if (active >> l & 1u)
    {
      const ffd::Vec3<double> at = { x.x.V[l], x.y.V[l], x.z.V[l] };
      cells[l] = known           ? known[l]
        : keep >> l & 1u         ? cells[l]
        : deformation.IsSparse() ? settings.Binder.Bind(at)
                                 : BindToGrid(deformation.Frame, deformation.BasisOf(), deformation.Voxels, at, true);
      active &= cells[l] >= 0 ? ~0u : ~(1u << l);
    }
  }
  if (active != 0)
  {
    const int first = cells[__builtin_ctz(active)];
    for (int l = 0; l < Lane::Width; ++l)
    {
      cells[l] = active >> l & 1u ? cells[l] : first;
    }
  }
  return active;
}

// F(x), and J where `jacobian` is not null, at lanes bound to `cells`: all in one cell read each control point
// once for all lanes; lanes in several cells (a local basis) read each its own cell's (ffd::DeformInLaneCells(),
// as the evaluation does).
template <typename Deformation, typename Wide, typename Lane>
inline ffd::Vec3<Lane> DeformLanes(const Deformation& deformation, const Wide& wide, const ffd::CellSplit& split,
  const ffd::Vec3<Lane>& x, const int* cells, ffd::Mat3<Lane>* jacobian)
{
  if (std::all_of(cells, cells + Lane::Width, [cells](int c) { return c == cells[0]; }))
  {
    return jacobian ? wide.Deform(x, cells[0], *jacobian) : wide.Deform(x, cells[0]);
  }
  // The cells and their lanes as an entry of ffd::BlockCells::List for one group: count, -, (cell, lane bits)...
  int entry[2 + 2 * Lane::Width] = { 0 };
  for (int l = 0; l < Lane::Width; ++l)
  {
    int k = 0;
    while (k < entry[0] && entry[2 + 2 * k] != cells[l])
    {
      ++k;
    }
    entry[0] += k == entry[0];
    entry[2 + 2 * k] = cells[l];
    entry[3 + 2 * k] |= 1 << l;
  }
  const GroupCells<Lane> group(deformation, split, entry, 0);
  return jacobian ? ffd::DeformInLaneCells(wide, x, group, *jacobian) : ffd::DeformInLaneCells(wide, x, group);
}

// The search of a lane group: its iterate, the Jacobian of its last evaluation with one, the lanes still
// searching and their last residuals, and the rest positions found with J there.
template <typename Lane>
struct LaneSearch
{
  ffd::Vec3<Lane> X;
  ffd::Mat3<Lane> Jacobian;
  Lane Det;
  unsigned Active;
  Lane Previous;
  ffd::Vec3<Lane> Found;
  ffd::Mat3<Lane> FoundJacobian;
  unsigned Converged;
};

// Settles the searching lanes after an evaluation of residual `error`, in lanes: a lane leaves the search where
// det J <= 0, where the residual did not fall, or where the steps ran out; it converged where the residual is
// within the tolerance. Returns the largest residual of the lanes still searching.
template <typename Lane>
inline double SettleLanes(
  const InverseLaneSearch& settings, LaneSearch<Lane>& search, const Lane& error, int step, int iterations)
{
  using Mask = typename Lane::IndexVector;
  const Mask found = error.V <= Lane(settings.Tolerance).V;
  Mask drop = ~IsPositive(search.Det);
  if (step > 0)
  {
    drop |= ~(error.V < search.Previous.V);
  }
  if (step >= iterations)
  {
    drop |= ~found;
  }
  const unsigned converged = Lane::Bits(found & ~drop) & search.Active;
  search.Active &= ~(Lane::Bits(drop) | converged);
  search.Previous = error;
  if (converged)
  {
    const Mask in = MaskOfBits<Lane>(converged, std::make_index_sequence<Lane::Width>());
    search.Found = { Select(in, search.X.x, search.Found.x), Select(in, search.X.y, search.Found.y),
      Select(in, search.X.z, search.Found.z) };
    for (int i = 0; i < 9; ++i)
    {
      search.FoundJacobian.M[i / 3][i % 3] =
        Select(in, search.Jacobian.M[i / 3][i % 3], search.FoundJacobian.M[i / 3][i % 3]);
    }
    search.Converged |= converged;
  }
  double largest = 0;
  for (unsigned active = search.Active; active; active &= active - 1)
  {
    largest = std::max(largest, error.V[__builtin_ctz(active)]);
  }
  return largest;
}

/**
 * ffd::InvertPoint's Newton iteration in W lanes, without its line search: from x = y, x -= J^-1 (F(x) - y),
 * each iterate bound again (InverseLaneBinder::Bind()). A lane converges where |F(x) - y| <= tolerance with det J > 0,
 * within `iterations` steps, the residual falling at every step. Any other lane (det J <= 0, a residual that
 * does not fall, no cell, the steps run out) is left to ffd::InvertPoint, which starts over. Once every residual
 * is within one Newton step of the tolerance (InverseLaneSearch::ChordResidual), the evaluations leave J out, the
 * steps taking the last J (a chord step), unless the normals need J where x is found.
 */
template <int W, typename Deformation>
inline void NewtonInLanes(const InverseLaneSearch& settings, const Deformation& deformation, InverseLaneGroup& group)
{
  using Lane = ffd::Lanes<double, W>;
  const auto wide = deformation.template WithLanes<Lane>();
  const ffd::CellSplit split = ffd::CellSplit::For(deformation.BasisOf(), deformation.Voxels);
  ffd::Vec3<Lane> y;
  Lane::Deinterleave3(group.Y, y.x, y.y, y.z);
  const ffd::Mat3<Lane> identity = ffd::Mat3<Lane>::Identity();
  LaneSearch<Lane> search{ y, identity, Lane(1.0), (1u << group.Count) - 1, Lane(0.0), y, identity, 0u };
  bool withJacobian = true;
  int cells[W];
  for (int step = 0;; ++step)
  {
    const bool one = step > 0 && std::all_of(cells, cells + W, [&](int c) { return c == cells[0]; });
    const unsigned keep = one ? StayingLanes(deformation, wide, split, search.X, cells[0]) : 0u;
    search.Active =
      BindLanes(settings, deformation, search.X, step == 0 ? group.Cells : nullptr, keep, search.Active, cells);
    if (search.Active == 0)
    {
      Lane::Interleave3(search.Found.x, search.Found.y, search.Found.z, group.X);
      for (int i = 0; i < 9; ++i)
      {
        std::memcpy(group.J[i], &search.FoundJacobian.M[i / 3][i % 3].V, sizeof(Lane));
      }
      group.Converged = search.Converged;
      return;
    }
    const ffd::Vec3<Lane> r =
      DeformLanes(deformation, wide, split, search.X, cells, withJacobian ? &search.Jacobian : nullptr) - y;
    if (withJacobian)
    {
      search.Det = ffd::Determinant(search.Jacobian);
    }
    const double largest = SettleLanes(settings, search, sqrt(ffd::Dot(r, r)), step, settings.Iterations);
    withJacobian = settings.WithJacobianAtEnd || !(largest <= settings.ChordResidual);
    // J^-1 = Cofactor(J)^T / det J.
    const ffd::Mat3<Lane> c = ffd::Cofactor(search.Jacobian);
    const Lane scale = Lane(-1.0) / search.Det;
    search.X = search.X +
      scale *
        ffd::Vec3<Lane>{ c.M[0][0] * r.x + c.M[1][0] * r.y + c.M[2][0] * r.z,
          c.M[0][1] * r.x + c.M[1][1] * r.y + c.M[2][1] * r.z, c.M[0][2] * r.x + c.M[1][2] * r.y + c.M[2][2] * r.z };
  }
}

#define FFD_DEFINE_INVERSE_KERNEL(Level, Target, Bytes)                                                                \
  template <typename Deformation>                                                                                      \
  Target void InvertIn(                                                                                                \
    LevelTag<Level>, const Deformation& deformation, const InverseLaneSearch& search, InverseLaneGroup& group)         \
  {                                                                                                                    \
    NewtonInLanes<Bytes / int(sizeof(double))>(search, deformation, group);                                            \
  }

template <SimdLevel Level>
void InvertAt(const GridLattice<double>& lattice, const InverseLaneSearch& search, InverseLaneGroup& group)
{
  WithGridDeformation(
    lattice, [&](const auto& deformation) { InvertIn(LevelTag<Level>(), deformation, search, group); });
}

} // namespace detail
} // namespace ffd
#endif

#endif
