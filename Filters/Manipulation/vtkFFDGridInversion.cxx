// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDGridInversion.h"

#include "vtkDoubleArray.h"
#include "vtkFFDDeform.h"
#include "vtkFFDForInChunks.h"
#include "vtkFFDGridDeformer.h"
#include "vtkFFDLatticeQueries.h"
#include "vtkFFDSparseLattice.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkSMPTools.h"

#include "FFDCellTable.h"
#include "FFDCpuTuning.h"
#include "FFDInverse.h"
#include "FFDLaneCells.h"
#include "FFDSimdLevel.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>
#include <utility>
#include <vector>

namespace
{
using ffd::InverseStatus;

// The cell whose evaluation extends F to x for the search: Bind()'s under CLAMP_TO_EDGE (beyond the frame, F as
// CLAMP_TO_EDGE extends it) and, for a sparse lattice's point in a voxel without a cell, the nearest cell within
// two voxels (its evaluation clamps x's local coordinates to that cell: F extended across the cell's faces). Under
// KEEP_POSITION, F jumps wherever the lattice's border or a sparse lattice's last cells moved: a mesh point pushed
// out of the cells would otherwise be found at its own place, which F keeps.
int SearchCell(const vtkFFDGridDeformer& deformer, const ffd::Frame<double>& frame, const ffd::Vec3<double>& x)
{
  const double p[3] = { x.x, x.y, x.z };
  const int cell = deformer.BindPoint(p, vtkFFDDeform::CLAMP_TO_EDGE);
  const vtkFFDSparseCells* sparse = deformer.GetSparseCells();
  const int* n = deformer.GetLattice().Divisions;
  int v[3];
  if (cell >= 0 || !sparse || !ffd::BindToCells(frame, n, x, true, v))
  {
    return cell;
  }
  const ffd::Vec3<double> stu = frame.ToParametric(x);
  const double q[3] = { stu.x * n[0], stu.y * n[1], stu.z * n[2] }; // in voxels
  double nearest = VTK_DOUBLE_MAX;
  int found = -1;
  for (int k = std::max(v[2] - 2, 0); k <= std::min(v[2] + 2, n[2] - 1); ++k)
  {
    for (int j = std::max(v[1] - 2, 0); j <= std::min(v[1] + 2, n[1] - 1); ++j)
    {
      for (int i = std::max(v[0] - 2, 0); i <= std::min(v[0] + 2, n[0] - 1); ++i)
      {
        const int c = sparse->Find(vtkFFDFlatIndex(i, j, k, n));
        if (c < 0)
        {
          continue;
        }
        const int w[3] = { i, j, k };
        double distance2 = 0;
        for (int a = 0; a < 3; ++a)
        {
          const double outside = std::max({ w[a] - q[a], 0.0, q[a] - (w[a] + 1) });
          distance2 += outside * outside;
        }
        if (distance2 < nearest || (distance2 == nearest && c < found))
        {
          nearest = distance2;
          found = c;
        }
      }
    }
  }
  return found;
}

// What the steps of a grid lattice's inversion share. A normal m at y goes back by the inverse's cofactor,
// det(J^-1) J^T: as J^T m, renormalised.
struct GridInversion
{
  const vtkFFDGridDeformer& Deformer;
  ffd::Frame<double> Frame;
  double Tolerance; // the largest |F(x) - y| accepted, in world units
  // A residual from which one Newton step reaches Tolerance: the residual squares at each step, times about
  // |J^-1| |F''| d ~ 1 (d the frame's diagonal): sqrt(Tolerance d).
  double ChordResidual;
  int MaxIterations;
  vtkPoints* Points;
  const double* Coordinates; // the points' doubles where they are stored so, else null
  vtkDataArray* Normals;
  const vtkFFDInverseOutput& Out;

  void PointOf(vtkIdType p, double y[3]) const
  {
    if (this->Coordinates) // element by element: GCC calls memmove for std::copy_n, then stalls reading y
    {
      const double* c = this->Coordinates + 3 * p;
      y[0] = c[0];
      y[1] = c[1];
      y[2] = c[2];
      return;
    }
    this->Points->GetPoint(p, y);
  }

  // The cell of x, as BindPoint() gives it under `clamp` (CLAMP_TO_EDGE, else KEEP_POSITION); a dense lattice's
  // inline (ffd::BindToGrid(), as BindPoint() binds), which saves a fifth of the inversion's time.
  int BindTo(const ffd::Vec3<double>& x, bool clamp) const
  {
    if (this->Deformer.GetSparseCells())
    {
      const double p[3] = { x.x, x.y, x.z };
      return this->Deformer.BindPoint(p, clamp ? vtkFFDDeform::CLAMP_TO_EDGE : vtkFFDDeform::KEEP_POSITION);
    }
    const vtkFFDGridLattice& lattice = this->Deformer.GetLattice();
    return ffd::BindToGrid(this->Frame, lattice.Basis, lattice.Divisions, x, clamp);
  }

  // The cell that extends F to x for the search (SearchCell()).
  int Bind(const ffd::Vec3<double>& x) const
  {
    return this->Deformer.GetSparseCells() ? SearchCell(this->Deformer, this->Frame, x) : this->BindTo(x, true);
  }

  // Writes point p's rest position x, found for y = F(x), with J there. Outside the lattice's cells F is the
  // identity: y is its own rest position there (so are non-finite points, which no cell binds), and has none
  // inside.
  void Finish(
    vtkIdType p, const double y[3], ffd::Vec3<double> x, ffd::Mat3<double> jacobian, InverseStatus status) const
  {
    if (this->BindTo(x, false) < 0)
    {
      const bool outside = this->BindTo(ffd::Vec3<double>::From(y), false) < 0;
      x = ffd::Vec3<double>::From(y);
      jacobian = ffd::Mat3<double>::Identity();
      status = outside ? InverseStatus::Converged : InverseStatus::NotConverged;
    }
    double* out = this->Out.Points + 3 * p;
    out[0] = x.x;
    out[1] = x.y;
    out[2] = x.z;
    this->Out.Status[p] = static_cast<unsigned char>(status);
    if (!this->Out.Normals)
    {
      return;
    }
    double m[3];
    this->Normals->GetTuple(p, m);
    double n[3];
    for (int a = 0; a < 3; ++a)
    {
      n[a] = jacobian.M[0][a] * m[0] + jacobian.M[1][a] * m[1] + jacobian.M[2][a] * m[2];
    }
    const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (int a = 0; a < 3; ++a)
    {
      this->Out.Normals[3 * p + a] = length > 0 ? n[a] / length : m[a];
    }
  }

  // Point p alone: ffd::InvertPoint, with its line search and its report of folds.
  template <typename Deformation>
  void InvertOne(const Deformation& deformation, vtkIdType p) const
  {
    double y[3];
    this->PointOf(p, y);
    ffd::Vec3<double> x = ffd::Vec3<double>::From(y);
    ffd::Mat3<double> jacobian = ffd::Mat3<double>::Identity();
    InverseStatus status = InverseStatus::Converged;
    if (std::isfinite(y[0]) && std::isfinite(y[1]) && std::isfinite(y[2])) // else kept, as F keeps them
    {
      const auto bind = [this](const ffd::Vec3<double>& at) { return this->Bind(at); };
      status = ffd::InvertPoint(
        deformation, bind, ffd::Vec3<double>::From(y), this->Tolerance, this->MaxIterations, x, jacobian);
    }
    this->Finish(p, y, x, jacobian, status);
  }
};

// A tile of consecutive points in the order of the cells that bind them (GridInversion::Bind()), so that most
// lane groups (InvertInGroups()) lie in one cell, a point's rest position lying near it: a mesh's vertices may
// come in any spatial order. A tile is ordered and inverted in one go, its points and results in cache.
struct OrderedTile
{
  static constexpr int Buckets = 4096; // a counting sort by cell modulo Buckets: whole cells for up to that many
  std::vector<vtkIdType> Order;        // the tile's point ids, ordered
  std::vector<int> Cells;              // their cells, in that order
  std::vector<int> Bound;              // the cell of each point of the tile, in the tile's order
  std::vector<vtkIdType> First;        // per bucket, where its points go in Order

  void Sort(const GridInversion& inversion, vtkIdType begin, vtkIdType end)
  {
    const vtkIdType count = end - begin;
    this->Order.resize(count);
    this->Cells.resize(count);
    this->Bound.resize(count);
    this->First.assign(Buckets + 1, 0);
    for (vtkIdType i = 0; i < count; ++i)
    {
      double y[3];
      inversion.PointOf(begin + i, y);
      this->Bound[i] = inversion.Bind(ffd::Vec3<double>::From(y));
      ++this->First[((this->Bound[i] + 1) & (Buckets - 1)) + 1]; // cell -1 first
    }
    std::partial_sum(this->First.begin(), this->First.end(), this->First.begin());
    for (vtkIdType i = 0; i < count; ++i)
    {
      const vtkIdType at = this->First[(this->Bound[i] + 1) & (Buckets - 1)]++;
      this->Order[at] = begin + i;
      this->Cells[at] = this->Bound[i];
    }
  }
};

#if FFD_HAVE_LANES
// Up to 8 points inverted together in SIMD lanes (NewtonInLanes()).
struct LaneGroup
{
  static constexpr int MaxWidth = 8;
  int Count = 0;          // its points; the lanes past them repeat its last point
  double Y[3 * MaxWidth]; // the deformed points, x y z each
  int Cells[MaxWidth];    // their cells (GridInversion::Bind())
  double X[3 * MaxWidth]; // the rest positions found
  double J[9][MaxWidth];  // the Jacobian there, by element (row by row) and lane
  unsigned Converged = 0; // the lanes whose rest position was found; the others are left to ffd::InvertPoint
};

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
// else GridInversion::Bind()'s. A lane without one leaves `active`, which is returned. The other lanes take the
// first active lane's cell, so that they never add a cell to evaluate.
template <typename Lane>
inline unsigned BindLanes(const GridInversion& inversion, const ffd::Vec3<Lane>& x, const int* known, unsigned keep,
  unsigned active, int* cells)
{
  for (int l = 0; l < Lane::Width; ++l)
  {
    if (active >> l & 1u)
    {
      cells[l] = known ? known[l] : keep >> l & 1u ? cells[l] : inversion.Bind({ x.x.V[l], x.y.V[l], x.z.V[l] });
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
  const ffd::detail::GroupCells<Lane> group(deformation, split, entry, 0);
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
  const GridInversion& inversion, LaneSearch<Lane>& search, const Lane& error, int step, int iterations)
{
  using Mask = typename Lane::IndexVector;
  const Mask found = error.V <= Lane(inversion.Tolerance).V;
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
    const Mask in = ffd::detail::MaskOfBits<Lane>(converged, std::make_index_sequence<Lane::Width>());
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
 * each iterate bound again (GridInversion::Bind()). A lane converges where |F(x) - y| <= tolerance with det J > 0,
 * within `iterations` steps, the residual falling at every step. Any other lane (det J <= 0, a residual that
 * does not fall, no cell, the steps run out) is left to ffd::InvertPoint, which starts over. Once every residual
 * is within one Newton step of the tolerance (GridInversion::ChordResidual), the evaluations leave J out, the
 * steps taking the last J (a chord step), unless the normals need J where x is found.
 */
template <int W, typename Deformation>
inline void NewtonInLanes(
  const GridInversion& inversion, const Deformation& deformation, int iterations, LaneGroup& group)
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
    search.Active = BindLanes(inversion, search.X, step == 0 ? group.Cells : nullptr, keep, search.Active, cells);
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
    const double largest = SettleLanes(inversion, search, sqrt(ffd::Dot(r, r)), step, iterations);
    withJacobian = inversion.Out.Normals || !(largest <= inversion.ChordResidual);
    // J^-1 = Cofactor(J)^T / det J.
    const ffd::Mat3<Lane> c = ffd::Cofactor(search.Jacobian);
    const Lane scale = Lane(-1.0) / search.Det;
    search.X = search.X +
      scale *
        ffd::Vec3<Lane>{ c.M[0][0] * r.x + c.M[1][0] * r.y + c.M[2][0] * r.z,
          c.M[0][1] * r.x + c.M[1][1] * r.y + c.M[2][1] * r.z, c.M[0][2] * r.x + c.M[1][2] * r.y + c.M[2][2] * r.z };
  }
}

// NewtonInLanes() compiled for each instruction set (as Evaluation/CPU/FFDGridLanes.h compiles its passes).
#define FFD_INVERSE_VARIANT(Suffix, Target, W)                                                                         \
  template <typename Deformation>                                                                                      \
  Target void NewtonInLanes##Suffix(                                                                                   \
    const GridInversion& inversion, const Deformation& deformation, int iterations, LaneGroup& group)                  \
  {                                                                                                                    \
    NewtonInLanes<W>(inversion, deformation, iterations, group);                                                       \
  }
FFD_INVERSE_VARIANT(AVX512, FFD_TARGET_AVX512, 8)
FFD_INVERSE_VARIANT(AVX2, FFD_TARGET_AVX2, 4)
FFD_INVERSE_VARIANT(SSE2, FFD_TARGET_SSE2, 2)
#undef FFD_INVERSE_VARIANT
#endif

// The lanes of NewtonInLanes() at `level` (1: none, points go one at a time).
int LaneWidth(ffd::SimdLevel level)
{
#if FFD_HAVE_LANES
  switch (level)
  {
    case ffd::SimdLevel::AVX512:
#if FFD_WIDEST_LANES >= 3
      return 8;
#endif
      [[fallthrough]];
    case ffd::SimdLevel::AVX2:
#if FFD_WIDEST_LANES >= 2
      return 4;
#endif
      [[fallthrough]];
    case ffd::SimdLevel::SSE2:
      return 2;
    case ffd::SimdLevel::None:
      break;
  }
#endif
  (void)level;
  return 1;
}

// The points order[begin, end) (of cells cells[begin, end)) in groups of LaneWidth(level), each through NewtonInLanes()
// first, its lanes that did not converge there through GridInversion::InvertOne(). A few Newton steps in lanes find
// nearly every point of a smooth deformation; ffd::InvertPoint alone costs several times more per point.
template <typename Deformation>
void InvertInGroups(const GridInversion& inversion, const Deformation& deformation, ffd::SimdLevel level,
  const vtkIdType* order, const int* cells, vtkIdType begin, vtkIdType end)
{
  const int width = LaneWidth(level);
#if FFD_HAVE_LANES
  constexpr int LaneSteps = 8; // beyond, ffd::InvertPoint's line search does better
  const int iterations = std::min(inversion.MaxIterations, LaneSteps);
  for (vtkIdType i = begin; width > 1 && i < end; i += width)
  {
    LaneGroup group;
    group.Count = int(std::min<vtkIdType>(width, end - i));
    for (int l = 0; l < width; ++l)
    {
      const vtkIdType at = i + std::min(l, group.Count - 1);
      inversion.PointOf(order[at], group.Y + 3 * l);
      group.Cells[l] = cells[at];
    }
    switch (width) // the wider variants only where compiled in, as in FFDGridLanes.h
    {
#if FFD_WIDEST_LANES >= 3
      case 8:
        NewtonInLanesAVX512(inversion, deformation, iterations, group);
        break;
#endif
#if FFD_WIDEST_LANES >= 2
      case 4:
        NewtonInLanesAVX2(inversion, deformation, iterations, group);
        break;
#endif
      default:
        NewtonInLanesSSE2(inversion, deformation, iterations, group);
    }
    for (int l = 0; l < group.Count; ++l)
    {
      if (group.Converged >> l & 1u)
      {
        ffd::Mat3<double> jacobian;
        for (int e = 0; e < 9; ++e)
        {
          jacobian.M[e / 3][e % 3] = group.J[e][l];
        }
        inversion.Finish(
          order[i + l], group.Y + 3 * l, ffd::Vec3<double>::From(group.X + 3 * l), jacobian, InverseStatus::Converged);
      }
      else
      {
        inversion.InvertOne(deformation, order[i + l]);
      }
    }
  }
#endif
  for (vtkIdType i = begin; width == 1 && i < end; ++i)
  {
    inversion.InvertOne(deformation, order[i]);
  }
}

// Calls f with the float64 deformation of vtkFFDWithGridDeformation() with its basis known at compile time
// (ffd::WithStaticBasis()), its fixed-size sums unrolled, and, for a local basis whose `cells` cells are few enough
// for `points` points (ffd::WorthCellTable(), as vtkFFDDeform decides), its cells in power form
// (ffd::FillCellTable()): F with its Jacobian by Horner's rule costs about half the sums of the control points'
// weights and their derivatives. The table then takes at most 32 bytes a point (trilinear; 6 for the cubic
// B-spline), where a sparse lattice of millions of cells would otherwise need GBs.
template <int MaxCount, typename F>
void WithStaticBasisOf(const ffd::GridDeformation<MaxCount, double>& d, int cells, vtkIdType points, F&& f)
{
  ffd::WithStaticBasis(d.Basis,
    [&](auto maxCount, auto basis)
    {
      constexpr int Basis = decltype(basis)::value;
      if constexpr (decltype(maxCount)::value == MaxCount)
      {
        using Plain = ffd::GridDeformation<MaxCount, double, Basis>;
        const Plain plain{ d.Basis, { d.Voxels[0], d.Voxels[1], d.Voxels[2] }, { d.Dims[0], d.Dims[1], d.Dims[2] },
          d.Displacements, d.Frame, nullptr, d.CellVoxels, d.CellSupports };
        if constexpr (Basis != int(ffd::GridBasis::Bernstein)) // one cell: no table
        {
          if (ffd::WorthCellTable(d.Basis, cells, points))
          {
            std::vector<double> table(std::size_t(cells) * ffd::CellTableStride(ffd::CellDegree(d.Basis)));
            vtkSMPTools::For(0, cells, 256,
              [&](int begin, int end)
              {
                ffd::FillCellTable(
                  d.Basis, d.Displacements, d.Voxels, d.Dims, d.CellVoxels, d.CellSupports, table.data(), begin, end);
              });
            f(ffd::GridDeformation<MaxCount, double, Basis, double, true>{ plain.Basis,
              { d.Voxels[0], d.Voxels[1], d.Voxels[2] }, { d.Dims[0], d.Dims[1], d.Dims[2] }, d.Displacements, d.Frame,
              table.data(), d.CellVoxels, d.CellSupports });
            return;
          }
        }
        f(plain);
      }
    });
}
} // namespace

//------------------------------------------------------------------------------------------------------------
// Grid lattices: Newton's method on the lattice's float64 evaluation, in SIMD lanes over tiles of points ordered
// by cell (OrderedTile, InvertInGroups()).
bool vtkFFDInvertByGrid(vtkAlgorithm* self, const vtkFFDGridDeformer& deformer, vtkPoints* points,
  vtkDataArray* normals, double tolerance, int maxIterations, const vtkFFDInverseOutput& out)
{
  const double* f = deformer.GetLattice().Frame;
  const double diagonal = std::hypot(f[3] + f[6] + f[9], f[4] + f[7] + f[10], f[5] + f[8] + f[11]);
  vtkDoubleArray* doubles = vtkDoubleArray::FastDownCast(points->GetData());
  const GridInversion inversion{ deformer, ffd::Frame<double>::FromArray(f), tolerance * diagonal,
    std::sqrt(tolerance) * diagonal, maxIterations, points,
    doubles && doubles->GetNumberOfComponents() == 3 ? doubles->GetPointer(0) : nullptr, normals, out };
  const vtkIdType n = points->GetNumberOfPoints();
  // Tiles of at most 16,384 points (384 kB of float64 coordinates), 64 or more where there are enough points; a
  // size of n alone, not of the threads.
  const vtkIdType tile = std::max<vtkIdType>(1024, std::min<vtkIdType>(16384, n / 64));
  const ffd::SimdLevel level = ffd::SimdLevelOfCpu();
  const vtkFFDGridLattice& lattice = deformer.GetLattice();
  const vtkFFDSparseCells* sparse = deformer.GetSparseCells();
  int cellCount = 1;
  for (int a = 0; a < 3; ++a)
  {
    cellCount *= ffd::BindingCells(lattice.Basis, lattice.Divisions[a]);
  }
  cellCount = sparse ? sparse->GetNumberOfCells() : cellCount;
  bool completed = false;
  vtkFFDWithGridDeformation(deformer,
    [&](const auto& dynamic)
    {
      WithStaticBasisOf(dynamic, cellCount, n,
        [&](const auto& deformation)
        {
          // The tiles that start in [first, last), whole: a point's lane group, and so its result, is the same
          // however the threads split the points.
          auto invert = [&](vtkIdType first, vtkIdType last)
          {
            OrderedTile ordered;
            for (vtkIdType begin = (first + tile - 1) / tile * tile; begin < last; begin += tile)
            {
              const vtkIdType end = std::min(n, begin + tile);
              ordered.Sort(inversion, begin, end);
              InvertInGroups(inversion, deformation, level, ordered.Order.data(), ordered.Cells.data(), 0, end - begin);
            }
          };
          completed = vtkFFDForInChunks(self, n, tile, invert, 0.0, 1.0);
        });
    });
  return completed;
}
