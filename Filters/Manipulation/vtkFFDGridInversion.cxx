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

#include "FFDCellTable.h"
#include "FFDCpuTuning.h"
#include "FFDInverse.h"
#include "FFDInversePasses.h"

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

// GridInversion::Bind() for the lanes of ffd::InvertInLanes().
class GridInversionBinder : public ffd::InverseLaneBinder
{
public:
  explicit GridInversionBinder(const GridInversion& inversion)
    : Inversion(inversion)
  {
  }
  int Bind(const ffd::Vec3<double>& x) const override { return this->Inversion.Bind(x); }

private:
  const GridInversion& Inversion;
};

// The points order[begin, end) (of cells cells[begin, end)) in groups of ffd::InverseLaneWidth(level), each through
// ffd::InvertInLanes() first, its lanes that did not converge there through GridInversion::InvertOne(). A few Newton
// steps in lanes find nearly every point of a smooth deformation; ffd::InvertPoint alone costs several times more
// per point.
template <typename Deformation>
void InvertInGroups(const GridInversion& inversion, const ffd::GridLattice<double>& lattice,
  const Deformation& deformation, ffd::SimdLevel level, const vtkIdType* order, const int* cells, vtkIdType begin,
  vtkIdType end)
{
  const int width = ffd::InverseLaneWidth(level);
  constexpr int LaneSteps = 8; // beyond, ffd::InvertPoint's line search does better
  const GridInversionBinder binder(inversion);
  const ffd::InverseLaneSearch search{ binder, inversion.Tolerance, inversion.ChordResidual,
    std::min(inversion.MaxIterations, LaneSteps), inversion.Out.Normals != nullptr };
  for (vtkIdType i = begin; width > 1 && i < end; i += width)
  {
    ffd::InverseLaneGroup group;
    group.Count = int(std::min<vtkIdType>(width, end - i));
    for (int l = 0; l < width; ++l)
    {
      const vtkIdType at = i + std::min(l, group.Count - 1);
      inversion.PointOf(order[at], group.Y + 3 * l);
      group.Cells[l] = cells[at];
    }
    ffd::InvertInLanes(level, lattice, search, group);
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
  for (vtkIdType i = begin; width == 1 && i < end; ++i)
  {
    inversion.InvertOne(deformation, order[i]);
  }
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
  // Cells in power form where the evaluation would take them so: F with its Jacobian by Horner's rule costs about
  // half the sums of the control points' weights and their derivatives, for at most 32 bytes a point (trilinear).
  std::vector<double> table;
  const ffd::GridLattice<double> passLattice =
    deformer.PassLattice(lattice.Displacements.data(), ffd::WorthCellTable(lattice.Basis, cellCount, n), table);
  bool completed = false;
  ffd::WithGridDeformation(passLattice,
    [&](const auto& deformation)
    {
      // The tiles that start in [first, last), whole: a point's lane group, and so its result, is the same however
      // the threads split the points.
      auto invert = [&](vtkIdType first, vtkIdType last)
      {
        OrderedTile ordered;
        for (vtkIdType begin = (first + tile - 1) / tile * tile; begin < last; begin += tile)
        {
          const vtkIdType end = std::min(n, begin + tile);
          ordered.Sort(inversion, begin, end);
          InvertInGroups(
            inversion, passLattice, deformation, level, ordered.Order.data(), ordered.Cells.data(), 0, end - begin);
        }
      };
      completed = vtkFFDForInChunks(self, n, tile, invert, 0.0, 1.0);
    });
  return completed;
}
