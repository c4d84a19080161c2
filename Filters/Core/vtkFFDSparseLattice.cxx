// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDSparseLattice.h"

#include "vtkAlgorithm.h"
#include "vtkCellData.h"
#include "vtkCellType.h"
#include "vtkDoubleArray.h"
#include "vtkFFDDataContract.h"
#include "vtkFFDMemory.h"
#include "vtkFFDSortedKeys.h"
#include "vtkHigherOrderHexahedron.h"
#include "vtkIntArray.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkSMPThreadLocal.h"
#include "vtkSMPTools.h"
#include "vtkUnsignedCharArray.h"
#include "vtkUnstructuredGrid.h"

#include "vtkFFDOpenVDB.h"

#include <openvdb/tree/ValueAccessor.h>

#include <algorithm>
#include <memory>
#include <sstream>

struct vtkFFDActiveSet::Internals
{
  std::shared_ptr<openvdb::MaskTree> Tree = std::make_shared<openvdb::MaskTree>();
};

namespace
{
using MaskTree = openvdb::MaskTree;

/// Marks boxes in one thread's tree through an accessor, which caches the path to the last leaf touched (a
/// chunk's coordinates are mostly near each other). The accessor is not registered with the tree (IsSafe
/// false), which saves a locked insertion per chunk: the tree outlives it and loses no node meanwhile.
class TreeMarker final : public vtkFFDBoxMarker
{
public:
  explicit TreeMarker(MaskTree& tree)
    : Accessor(tree)
  {
  }

  void Mark(const int first[3], const int count[3]) override
  {
    for (int k = first[2]; k < first[2] + count[2]; ++k)
    {
      for (int j = first[1]; j < first[1] + count[1]; ++j)
      {
        for (int i = first[0]; i < first[0] + count[0]; ++i)
        {
          this->Accessor.setValueOn(openvdb::Coord(i, j, k));
        }
      }
    }
  }

private:
  openvdb::tree::ValueAccessor<MaskTree, false> Accessor;
};

/// The cells of `lattice` over the voxels, with ids stored as ArrayT's values (32 or 64 bits).
template <typename ArrayT>
vtkSmartPointer<vtkCellArray> MakeCells(
  const vtkFFDSparseLattice& lattice, ffd::GridBasis basis, const int divisions[3], const int* voxels, vtkIdType n)
{
  using Id = typename ArrayT::ValueType;
  const int c = ffd::SupportSize(basis, divisions[0]); // the same along every axis for a local basis
  const int perCell = c * c * c;
  // The place in the cell of support point (a, b, d), taken in tensor order a + c (b + c d): VTK's order of the
  // Bezier hexahedron of that degree (the corners first, as a VTK_HEXAHEDRON for degree 1), or tensor order.
  const int degree = ffd::BezierDegree(basis);
  const int order[3] = { degree, degree, degree };
  std::vector<int> place(perCell);
  for (int d = 0; d < c; ++d)
  {
    for (int b = 0; b < c; ++b)
    {
      for (int a = 0; a < c; ++a)
      {
        const int t = a + c * (b + c * d);
        place[t] = degree > 0 ? vtkHigherOrderHexahedron::PointIndexFromIJK(a, b, d, order) : t;
      }
    }
  }

  vtkNew<ArrayT> offsets, connectivity;
  offsets->SetNumberOfValues(n + 1);
  connectivity->SetNumberOfValues(n * perCell);
  Id* offset = offsets->GetPointer(0);
  Id* ids = connectivity->GetPointer(0);
  const vtkFFDSortedKeys<> keys(lattice.Points.data(), lattice.Points.data() + lattice.Points.size()); // viewed
  vtkSMPTools::For(0, n,
    [&](vtkIdType begin, vtkIdType end)
    {
      // Per row (b, d) of the support: where the previous voxel's row was found. The voxels come in increasing
      // order from vtkFFDVoxelize, so a row lies a few places after the same row of the previous voxel's support.
      std::vector<vtkIdType> hints(c * c, 0);
      for (vtkIdType v = begin; v < end; ++v)
      {
        int first[3], count[3];
        for (int a = 0; a < 3; ++a)
        {
          ffd::VoxelSupport(basis, divisions[a], voxels[3 * v + a], first[a], count[a]);
        }
        offset[v] = Id(v * perCell);
        Id* cell = ids + v * perCell;
        for (int d = 0; d < c; ++d)
        {
          for (int b = 0; b < c; ++b)
          {
            // A row's c points have consecutive linear indices, all in the set: they are consecutive there too.
            vtkIdType& hint = hints[b + c * d];
            hint =
              keys.LowerBoundFrom(hint, vtkFFDFlatIndex(first[0], first[1] + b, first[2] + d, lattice.PointsPerAxis));
            const Id rank = Id(hint);
            for (int a = 0; a < c; ++a)
            {
              cell[place[a + c * (b + c * d)]] = rank + Id(a);
            }
          }
        }
      }
    });
  offset[n] = Id(n * perCell);
  auto cells = vtkSmartPointer<vtkCellArray>::New();
  cells->SetData(offsets, connectivity);
  return cells;
}
} // namespace

//------------------------------------------------------------------------------------------------------------
vtkFFDActiveSet::vtkFFDActiveSet()
  : Internal(new Internals)
{
}

vtkFFDActiveSet::~vtkFFDActiveSet() = default;

//------------------------------------------------------------------------------------------------------------
void vtkFFDActiveSet::Mark(vtkIdType n, const std::function<void(vtkIdType, vtkIdType, vtkFFDBoxMarker&)>& body)
{
  // Each thread's tree, made at its first chunk (a tree cannot be copied from an exemplar).
  vtkSMPThreadLocal<std::shared_ptr<MaskTree>> trees;
  vtkSMPTools::For(0, n,
    [&](vtkIdType begin, vtkIdType end)
    {
      std::shared_ptr<MaskTree>& tree = trees.Local();
      if (!tree)
      {
        tree = std::make_shared<MaskTree>();
      }
      TreeMarker marker(*tree);
      body(begin, end, marker);
    });
  // A set union: the same set whatever the threads and their order. It runs TBB tasks of its own, so it is
  // made here rather than in the vtkSMPTools body. The first tree is taken rather than copied into an empty one,
  // and each is freed once merged: the peak is the threads' trees and what the union adds to the first.
  for (std::shared_ptr<MaskTree>& tree : trees)
  {
    if (this->Internal->Tree->empty())
    {
      std::swap(this->Internal->Tree, tree);
    }
    else
    {
      this->Internal->Tree->topologyUnion(*tree);
    }
    tree.reset();
  }
}

//------------------------------------------------------------------------------------------------------------
vtkIdType vtkFFDActiveSet::GetNumberOfMarked() const
{
  return vtkIdType(this->Internal->Tree->activeVoxelCount());
}

//------------------------------------------------------------------------------------------------------------
std::vector<vtkTypeInt64> vtkFFDActiveSet::TakeSortedIndices(const vtkTypeInt64 dims[3])
{
  // Marking sets single voxels, and the union of leaves keeps leaves: the tree has no active tiles.
  std::vector<vtkTypeInt64> indices = vtkFFDSortedIndices(*this->Internal->Tree, dims);
  this->Internal->Tree->clear();
  return indices;
}

//------------------------------------------------------------------------------------------------------------
bool vtkFFDSparseLattice::Build(vtkAlgorithm* self, ffd::GridBasis basis, const int divisions[3], const int* voxels,
  vtkIdType numVoxels, double bytesPerPoint, double bytesPerCell, const std::string& what)
{
  vtkTypeInt64 dims[3];
  for (int a = 0; a < 3; ++a)
  {
    // Control points along an axis are counted by an int (3 per voxel and the B-spline's ring at most).
    if (divisions[a] > (VTK_INT_MAX - 3) / 3)
    {
      vtkErrorWithObjectMacro(self, << what << ": " << divisions[a] << " divisions along axis " << a
                                    << " have more control points than an int counts: use fewer divisions.");
      return false;
    }
    this->PointsPerAxis[a] = ffd::ControlPointsAlongAxis(basis, divisions[a]);
    dims[a] = this->PointsPerAxis[a];
  }
  vtkFFDActiveSet set;
  MarkSupports(set, basis, divisions, voxels, numVoxels);

  const vtkIdType numPoints = set.GetNumberOfMarked();
  const int c = ffd::SupportSize(basis, divisions[0]);
  const vtkIdType perCell = c * c * c;
  const bool narrow = numPoints <= VTK_TYPE_INT32_MAX && numVoxels * perCell <= VTK_TYPE_INT32_MAX;
  // The sorted indices (8 bytes a point), the cells' ids and offsets, and the cell types that SetCells() adds.
  const double idBytes = narrow ? 4.0 : 8.0;
  const double bytes = (8.0 + bytesPerPoint) * double(numPoints) +
    (idBytes * double(perCell + 1) + 1.0 + bytesPerCell) * double(numVoxels);
  std::ostringstream request;
  request << what << " (" << numVoxels << " cells of " << perCell << " points, " << numPoints << " points)";
  if (!vtkFFDCheckMemory(self, request.str(), bytes))
  {
    return false;
  }
  this->Points = set.TakeSortedIndices(dims);
  this->CellType = basis == ffd::GridBasis::Trilinear ? VTK_HEXAHEDRON
    : basis == ffd::GridBasis::CubicBSpline           ? VTK_POLY_VERTEX
                                                      : VTK_BEZIER_HEXAHEDRON;
  this->Cells = narrow ? MakeCells<vtkCellArray::ArrayType32>(*this, basis, divisions, voxels, numVoxels)
                       : MakeCells<vtkCellArray::ArrayType64>(*this, basis, divisions, voxels, numVoxels);
  return true;
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDSparseLattice::MarkSupports(
  vtkFFDActiveSet& set, ffd::GridBasis basis, const int divisions[3], const int* voxels, vtkIdType numVoxels)
{
  set.Mark(numVoxels,
    [&](vtkIdType begin, vtkIdType end, vtkFFDBoxMarker& marker)
    {
      for (vtkIdType v = begin; v < end; ++v)
      {
        int first[3], count[3];
        for (int a = 0; a < 3; ++a)
        {
          ffd::VoxelSupport(basis, divisions[a], voxels[3 * v + a], first[a], count[a]);
        }
        marker.Mark(first, count);
      }
    });
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDSparseLattice::GetIndex(vtkIdType id, int index[3]) const
{
  const vtkTypeInt64 key = this->Points[id], nI = this->PointsPerAxis[0], nJ = this->PointsPerAxis[1];
  index[0] = int(key % nI);
  index[1] = int(key / nI % nJ);
  index[2] = int(key / nI / nJ);
}

//------------------------------------------------------------------------------------------------------------
vtkSmartPointer<vtkPoints> vtkFFDSparseLattice::MakeRestPoints(
  const ffd::Frame<double>& frame, ffd::GridBasis basis, const int divisions[3]) const
{
  const vtkIdType n = vtkIdType(this->Points.size());
  auto points = vtkSmartPointer<vtkPoints>::New();
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(n);
  double* x = vtkDoubleArray::SafeDownCast(points->GetData())->GetPointer(0);
  vtkSMPTools::For(0, n,
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType id = begin; id < end; ++id)
      {
        int ijk[3];
        this->GetIndex(id, ijk);
        const ffd::Vec3<double> p = vtkFFDRestPoint(frame, basis, divisions, ijk[0], ijk[1], ijk[2]);
        std::copy(&p.x, &p.x + 3, x + 3 * id);
      }
    });
  return points;
}

//------------------------------------------------------------------------------------------------------------
vtkSmartPointer<vtkIntArray> vtkFFDMakeVoxelIndex(const std::vector<vtkTypeInt64>& sorted, const int divisions[3])
{
  const vtkIdType numVoxels = vtkIdType(sorted.size());
  const vtkTypeInt64 nx = divisions[0], ny = divisions[1];
  auto voxelIndex = vtkSmartPointer<vtkIntArray>::New();
  voxelIndex->SetName(vtkFFDDataContract::VoxelIndexArrayName());
  voxelIndex->SetNumberOfComponents(3);
  voxelIndex->SetNumberOfTuples(numVoxels);
  int* ijk = voxelIndex->GetPointer(0);
  vtkSMPTools::For(0, numVoxels,
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType v = begin; v < end; ++v)
      {
        ijk[3 * v] = int(sorted[v] % nx);
        ijk[3 * v + 1] = int(sorted[v] / nx % ny);
        ijk[3 * v + 2] = int(sorted[v] / nx / ny);
      }
    });
  return voxelIndex;
}

//------------------------------------------------------------------------------------------------------------
bool vtkFFDMakeVoxelGrid(vtkAlgorithm* self, const double frame[12], const int divisions[3], vtkIntArray* voxelIndex,
  const std::string& what, vtkUnstructuredGrid* output)
{
  // The corners are the active control points of a TRILINEAR lattice over the active voxels (its point (i, j, k)
  // rests at (i/nx, j/ny, k/nz)), and the hexahedra are its cells.
  vtkFFDSparseLattice corners;
  if (!corners.Build(self, ffd::GridBasis::Trilinear, divisions, voxelIndex->GetPointer(0),
        voxelIndex->GetNumberOfTuples(), 24.0, 0.0, what))
  {
    return false;
  }
  output->SetPoints(corners.MakeRestPoints(ffd::Frame<double>::FromArray(frame), ffd::GridBasis::Trilinear, divisions));
  output->SetCells(corners.CellType, corners.Cells);
  output->GetCellData()->AddArray(voxelIndex);
  vtkFFDDataContract::SetFrame(output, frame);
  vtkFFDDataContract::SetDivisions(output, divisions);
  return true;
}

//------------------------------------------------------------------------------------------------------------
bool vtkFFDMakeSparseLattice(vtkAlgorithm* self, const double frame[12], ffd::GridBasis basis, const int divisions[3],
  vtkIntArray* voxelIndex, const std::string& what, vtkUnstructuredGrid* output)
{
  // Per control point: its position and RestPosition (24 bytes each), LatticeIndex (12) and Active (1). The
  // cells' VoxelIndex is the caller's array, shared.
  vtkFFDSparseLattice lattice;
  if (!lattice.Build(
        self, basis, divisions, voxelIndex->GetPointer(0), voxelIndex->GetNumberOfTuples(), 61.0, 0.0, what))
  {
    return false;
  }
  self->UpdateProgress(0.5);
  if (self->GetAbortExecute())
  {
    return true;
  }

  const vtkIdType numPoints = vtkIdType(lattice.Points.size());
  vtkSmartPointer<vtkPoints> points = lattice.MakeRestPoints(ffd::Frame<double>::FromArray(frame), basis, divisions);
  vtkNew<vtkDoubleArray> rest;
  rest->DeepCopy(points->GetData());
  rest->SetName(vtkFFDDataContract::RestPositionArrayName());
  vtkNew<vtkIntArray> latticeIndex;
  latticeIndex->SetName(vtkFFDDataContract::LatticeIndexArrayName());
  latticeIndex->SetNumberOfComponents(3);
  latticeIndex->SetNumberOfTuples(numPoints);
  int* index = latticeIndex->GetPointer(0);
  vtkSMPTools::For(0, numPoints,
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType id = begin; id < end; ++id)
      {
        lattice.GetIndex(id, index + 3 * id);
      }
    });
  vtkNew<vtkUnsignedCharArray> active;
  active->SetName(vtkFFDDataContract::ActiveArrayName());
  active->SetNumberOfValues(numPoints);
  active->FillValue(1);

  output->SetPoints(points);
  output->SetCells(lattice.CellType, lattice.Cells);
  output->GetPointData()->AddArray(rest);
  output->GetPointData()->AddArray(active);
  output->GetPointData()->AddArray(latticeIndex);
  output->GetCellData()->AddArray(voxelIndex);
  vtkFFDDataContract::SetFrame(output, frame);
  vtkFFDDataContract::SetDivisions(output, divisions);
  vtkFFDDataContract::SetBasis(output, int(basis));
  return true;
}
