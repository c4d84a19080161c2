// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDLaneCells.h
 * @brief GridDeformation for lanes bound to different cells of a local basis (host only).
 *
 * A lane group of the in-place pass whose points lie in several cells (FFDGridLanes.h) computes each lane's
 * weights (or local coordinates) once from its own cell's indices, then each cell's sum in all lanes, kept in
 * that cell's lanes: from GridDeformation's own building blocks, so that a lane's result is bit for bit the one
 * it gets when all lanes share its cell.
 */
#ifndef FFDLaneCells_h
#define FFDLaneCells_h

#include "FFDGridDeformation.h"

#include <cstdint>
#include <utility>

namespace ffd
{

namespace detail
{
/// The control points of a lane group's cells (DeformInLaneCells()), each lane reading its own
/// cell's: for one sum with its gradient over all lanes, which costs less than one per cell. Supports is a sparse
/// lattice's GridDeformation::CellSupports, null for a dense one.
template <typename Real, typename Group>
struct GroupValues
{
  const Real* Displacements;
  const int* Supports;
  const Group* Cells;

  /// Control point `index` (relative to the cell's first one) of the group's k-th cell.
  const Real* Of(int k, int index) const
  {
    const int at = this->Cells->Firsts[k] + index;
    return this->Displacements + 3 * std::size_t(this->Supports ? this->Supports[at] : at);
  }
};

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

} // namespace detail

/// Control point `index` (relative to its cell's first one) of each lane's cell: a broadcast and a select per
/// cell of the group.
template <typename Real, typename Group>
struct LatticeValues<detail::GroupValues<Real, Group>>
{
  template <typename Lane>
  static Vec3<Lane> Get(const detail::GroupValues<Real, Group>* values, int index)
  {
    const Group& group = *values->Cells;
    const Real* v = values->Of(0, index);
    Vec3<Lane> value = { Lane(v[0]), Lane(v[1]), Lane(v[2]) };
    for (int k = 1; k < group.Count; ++k)
    {
      v = values->Of(k, index);
      value = { Select(group.Lanes[k], Lane(v[0]), value.x), Select(group.Lanes[k], Lane(v[1]), value.y),
        Select(group.Lanes[k], Lane(v[2]), value.z) };
    }
    return value;
  }
};

/// The weights along each axis at parameters stu of lanes in the cells of indices `cell` (DeformInLaneCells()),
/// as ComputeAxisWeights() computes them for one cell.
template <int MaxCount, typename Real, int StaticBasis, typename Lane, bool WithCellTable, GridStorage Storage>
inline void LaneCellWeights(
  const GridDeformation<MaxCount, Real, StaticBasis, Lane, WithCellTable, Storage>& deformation, const Vec3<Lane>& stu,
  const Vec3<Lane>& cell, bool withDerivative, AxisWeights<MaxCount, Lane>* axes)
{
  const Lane p[3] = { stu.x, stu.y, stu.z };
  const Lane c[3] = { cell.x, cell.y, cell.z };
  for (int a = 0; a < 3; ++a)
  {
    const Lane n = Lane(deformation.Voxels[a]);
    axes[a].First = 0;
    ComputeLocalAxisWeights(deformation.BasisOf(), n, Clamp01(p[a] * n - c[a]), withDerivative, axes[a]);
  }
}

/**
 * The displacement (and, where `gradient` is not null, dD/d(s, t, u)) at parameters stu of lanes in the cells
 * of `group` (DeformInLaneCells()): each lane's weights (or local coordinates) from its own cell's indices,
 * then each cell's sum in all lanes, kept in that cell's lanes.
 */
template <int MaxCount, typename Real, int StaticBasis, typename Lane, bool WithCellTable, GridStorage Storage,
  typename Group>
inline Vec3<Lane> SumInLaneCells(
  const GridDeformation<MaxCount, Real, StaticBasis, Lane, WithCellTable, Storage>& deformation, const Vec3<Lane>& stu,
  const Group& group, Mat3<Lane>* gradient)
{
  Vec3<Lane> index;
  for (int k = 0; k < group.Count; ++k)
  {
    Vec3<Lane> ck;
    if constexpr (WithCellTable)
    {
      const Real* entry = deformation.CellEntry(group.Cells[k]);
      ck = { Lane(entry[0]), Lane(entry[1]), Lane(entry[2]) };
    }
    else
    {
      ck = { Lane(group.Indices[k][0]), Lane(group.Indices[k][1]), Lane(group.Indices[k][2]) };
    }
    const auto& lanes = group.Lanes[k];
    index = k == 0
      ? ck
      : Vec3<Lane>{ Select(lanes, ck.x, index.x), Select(lanes, ck.y, index.y), Select(lanes, ck.z, index.z) };
  }
  Lane r[3];
  AxisWeights<MaxCount, Lane> axes[3];
  if constexpr (WithCellTable)
  {
    deformation.TableCoordinates(stu, index, r);
  }
  else
  {
    LaneCellWeights(deformation, stu, index, gradient != nullptr, axes);
  }
  // A cell's control points: on the lattice's grid from its first (dense), or on its support (sparse).
  const auto cellDims = deformation.CellDims();
  const int* dims = deformation.IsSparse() ? cellDims.D : deformation.Dims;
  if constexpr (!WithCellTable)
  {
    if (gradient && group.Count > 1)
    {
      // One sum with its gradient over values read per lane: a cell's sum with its gradient (12 multiply-adds
      // a control point) costs more than reading its control points into its lanes (6 operations).
      const detail::GroupValues<Real, Group> values{ deformation.Displacements, deformation.CellSupports, &group };
      return SumTensorProductWithGradient(&values, dims, axes, *gradient);
    }
  }
  Vec3<Lane> d;
  for (int k = 0; k < group.Count; ++k)
  {
    Mat3<Lane> gk;
    Vec3<Lane> dk;
    if constexpr (WithCellTable)
    {
      deformation.template CellPowerForm<1>(deformation.CellEntry(group.Cells[k]), &r, &dk, gradient ? &gk : nullptr);
      if (gradient)
      {
        gk = deformation.TableGradient(gk);
      }
    }
    else
    {
      if (deformation.IsSparse())
      {
        const SupportValues<Real> values{ deformation.Displacements, deformation.CellSupports + group.Firsts[k] };
        dk = gradient ? SumTensorProductWithGradient(&values, dims, axes, gk) : SumTensorProduct(&values, dims, axes);
      }
      else
      {
        const Real* values = deformation.Displacements + 3 * group.Firsts[k];
        dk = gradient ? SumTensorProductWithGradient(values, dims, axes, gk) : SumTensorProduct(values, dims, axes);
      }
    }
    if (k == 0)
    {
      d = dk;
      if (gradient)
      {
        *gradient = gk;
      }
      continue;
    }
    const auto& lanes = group.Lanes[k];
    d = { Select(lanes, dk.x, d.x), Select(lanes, dk.y, d.y), Select(lanes, dk.z, d.z) };
    if (gradient)
    {
      for (int row = 0; row < 3; ++row)
      {
        for (int column = 0; column < 3; ++column)
        {
          gradient->M[row][column] = Select(lanes, gk.M[row][column], gradient->M[row][column]);
        }
      }
    }
  }
  return d;
}

/**
 * Deform() for lanes bound to different cells of a local basis (Lane a Lanes type). `group` has the Count cells
 * of the lanes: the k-th is Cells[k] (BindToGrid()'s flat index), its lanes Lanes[k], and, read without a
 * CellTable, its index along each axis Indices[k] and its first control point Firsts[k]
 * (i + Dims[0] (j + Dims[1] k), or, for a sparse lattice, its first entry in CellSupports) (GroupCells in
 * FFDGridLanes.h).
 */
template <int MaxCount, typename Real, int StaticBasis, typename Lane, bool WithCellTable, GridStorage Storage,
  typename Group>
inline Vec3<Lane> DeformInLaneCells(
  const GridDeformation<MaxCount, Real, StaticBasis, Lane, WithCellTable, Storage>& deformation, const Vec3<Lane>& x,
  const Group& group)
{
  Mat3<Lane>* noGradient = nullptr;
  return x + SumInLaneCells(deformation, deformation.Frame.ToParametric(x), group, noGradient);
}

/// DeformInLaneCells() and the Jacobian dX_ffd/dX there.
template <int MaxCount, typename Real, int StaticBasis, typename Lane, bool WithCellTable, GridStorage Storage,
  typename Group>
inline Vec3<Lane> DeformInLaneCells(
  const GridDeformation<MaxCount, Real, StaticBasis, Lane, WithCellTable, Storage>& deformation, const Vec3<Lane>& x,
  const Group& group, Mat3<Lane>& jacobian)
{
  const Vec3<Lane> stu = deformation.Frame.ToParametric(x);
  Mat3<Lane> gradient;
  Mat3<Lane>* withGradient = &gradient;
  const Vec3<Lane> d = SumInLaneCells(deformation, stu, group, withGradient);
  jacobian = deformation.JacobianAt(stu, gradient);
  return x + d;
}

} // namespace ffd

#endif
