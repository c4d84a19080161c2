// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDSparseCells.h"

#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkFFDDataContract.h"
#include "vtkFFDFlatIndex.h"
#include "vtkIdList.h"
#include "vtkIntArray.h"
#include "vtkPointData.h"
#include "vtkSMPThreadLocal.h"
#include "vtkSMPThreadLocalObject.h"
#include "vtkSMPTools.h"
#include "vtkTypeInt32Array.h"
#include "vtkUnstructuredGrid.h"

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <sstream>
#include <type_traits>
#include <utility>

namespace
{
/// The 3-component int array `name` of `data` with `count` tuples, or null.
vtkIntArray* IndexArray(vtkFieldData* data, const char* name, vtkIdType count)
{
  vtkIntArray* array = vtkIntArray::SafeDownCast(data->GetAbstractArray(name));
  return array && array->GetNumberOfComponents() == 3 && array->GetNumberOfTuples() == count ? array : nullptr;
}

/// What index arrays that no longer fit their lattice most often mean: vtkTransformFilter (and ParaView's
/// Transform, where it is the default) transforms every 3-component array as a vector, the indices included.
const std::string Transformed = " If a transform moved the lattice, the lattice's LatticeIndex/VoxelIndex no longer "
                                "match its FFDFrame: it moved them as vectors (VTK's vtkTransformFilter / ParaView's "
                                "Transform with TransformAllInputVectors on); transform the lattice with that option "
                                "off, so that only its points move.";

/// What Read() needs to check and place one cell's points.
struct CellReader
{
  vtkCellArray* Cells;
  const int* VoxelIndices;   // 3 per cell
  const int* LatticeIndices; // 3 per point
  vtkIdType NumberOfPoints;  // the ids cells may name: [0, NumberOfPoints)
  ffd::GridBasis Basis;
  const int* Divisions;
  int N; // control points per axis of a support

  /// Places the points of cell `cell`, whose voxel is `voxel`, into support (N^3 slots, -1 where empty); false,
  /// with the reason in `why` when not null, where they are not exactly the voxel's support.
  bool Place(vtkIdType cell, const int voxel[3], vtkIdList* ids, int* support, std::string* why) const
  {
    this->Cells->GetCellAtId(cell, ids); // into a list of the caller's thread: thread-safe for any storage
    const vtkIdType size = ids->GetNumberOfIds();
    const vtkIdType* points = ids->GetPointer(0);
    const int n3 = this->N * this->N * this->N;
    std::fill(support, support + n3, -1);
    int first[3];
    for (int a = 0; a < 3; ++a)
    {
      int count;
      ffd::VoxelSupport(this->Basis, this->Divisions[a], voxel[a], first[a], count);
    }
    auto fail = [&](const std::string& what)
    {
      if (why)
      {
        std::ostringstream msg;
        msg << "Cell " << cell << " (voxel " << voxel[0] << ", " << voxel[1] << ", " << voxel[2] << ") " << what;
        *why = msg.str();
      }
      return false;
    };
    if (size != n3)
    {
      return fail("has " + std::to_string(size) + " points; its support has " + std::to_string(n3) + ".");
    }
    for (vtkIdType p = 0; p < size; ++p)
    {
      if (points[p] < 0 || points[p] >= this->NumberOfPoints)
      {
        return fail("names point " + std::to_string(points[p]) + ", but the lattice has " +
          std::to_string(this->NumberOfPoints) + " points (ids 0 to " + std::to_string(this->NumberOfPoints - 1) +
          "): a cell may only name the lattice's own points.");
      }
      const int* index = this->LatticeIndices + 3 * points[p];
      int slot = 0;
      for (int a = 2; a >= 0; --a)
      {
        const int local = index[a] - first[a];
        if (local < 0 || local >= this->N)
        {
          return fail("lists point " + std::to_string(points[p]) +
            ", whose LatticeIndex is outside the voxel's support." + Transformed);
        }
        slot = slot * this->N + local;
      }
      if (support[slot] >= 0)
      {
        return fail("lists two points of the same LatticeIndex." + Transformed);
      }
      support[slot] = static_cast<int>(points[p]);
    }
    return true;
  }

  /**
   * Places the points of every cell, in the order of `order` (each cell's voxel's flat index, with its cell id),
   * into `supports`, or, where it is null, into a buffer compared with `own` (the connectivity; `differs` tells
   * whether any cell's is not its support). Returns the first position whose cell is not a support (the number of
   * cells where there is none).
   */
  vtkIdType PlaceAll(
    const vtkFFDSortedKeys<int>& order, int* supports, const int* own, std::atomic<bool>& differs) const
  {
    const vtkIdType numCells = order.GetSize();
    const int n3 = this->N * this->N * this->N;
    std::atomic<vtkIdType> firstBad(numCells);
    vtkSMPThreadLocalObject<vtkIdList> ids;
    vtkSMPThreadLocal<std::vector<int>> buffers;
    vtkSMPTools::For(0, numCells,
      [&](vtkIdType begin, vtkIdType end)
      {
        std::vector<int>& buffer = buffers.Local();
        buffer.resize(n3);
        for (vtkIdType r = begin; r < end; ++r)
        {
          const int cell = order.GetId(r);
          int* support = supports ? supports + size_t(n3) * r : buffer.data();
          if (!this->Place(cell, this->VoxelIndices + 3 * cell, ids.Local(), support, nullptr))
          {
            vtkIdType seen = firstBad.load();
            while (r < seen && !firstBad.compare_exchange_weak(seen, r))
            {
            }
          }
          else if (!supports && !std::equal(support, support + n3, own + size_t(n3) * r))
          {
            differs = true;
          }
        }
      });
    return firstBad.load();
  }
};

const std::string Fix = " Build the lattice with vtkFFDBuildLattice, or keep its data contract "
                        "(docs/pipeline-and-data-contract.md, \"Data contract\").";

/// Why the lattice's index arrays or sizes are not those of a sparse lattice, or an empty string.
std::string CheckArrays(vtkUnstructuredGrid* lattice, vtkIntArray* latticeIndex, vtkIntArray* voxelIndex)
{
  // An index array of 3 components but not of ints is what a transform of double precision leaves.
  auto notInts = [](vtkFieldData* data, const char* name)
  {
    vtkDataArray* array = data->GetArray(name);
    return array && array->GetNumberOfComponents() == 3 && !vtkIntArray::SafeDownCast(array) ? Transformed : "";
  };
  if (!latticeIndex)
  {
    return "The sparse lattice has no LatticeIndex point array (3 ints per point)." +
      notInts(lattice->GetPointData(), vtkFFDDataContract::LatticeIndexArrayName()) + Fix;
  }
  if (!voxelIndex)
  {
    return "The sparse lattice has no VoxelIndex cell array (3 ints per cell)." +
      notInts(lattice->GetCellData(), vtkFFDDataContract::VoxelIndexArrayName()) + Fix;
  }
  const vtkIdType numPoints = lattice->GetNumberOfPoints();
  const vtkIdType numCells = lattice->GetNumberOfCells();
  if (numCells == 0 || numCells > VTK_INT_MAX || numPoints > VTK_INT_MAX)
  {
    return "The sparse lattice has " + std::to_string(numCells) + " cells and " + std::to_string(numPoints) +
      " points: it needs at least one cell, and at most 2^31 - 1 of each." + Fix;
  }
  return std::string();
}

/// The first of the `count` indices (3 ints each) that is outside [0, limits) along an axis, or -1.
vtkIdType FirstOutside(const int* index, const int* limits, vtkIdType count)
{
  std::atomic<vtkIdType> first(count);
  vtkSMPTools::For(0, count,
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType t = begin; t < end && t < first; ++t)
      {
        for (int a = 0; a < 3; ++a)
        {
          if (index[3 * t + a] < 0 || index[3 * t + a] >= limits[a])
          {
            vtkIdType seen = first.load();
            while (t < seen && !first.compare_exchange_weak(seen, t))
            {
            }
          }
        }
      }
    });
  return first == count ? vtkIdType(-1) : first.load();
}

/// Why the cells' voxels or the points' lattice indices are outside the lattice's shape, or an empty string.
std::string CheckIndices(const CellReader& reader, vtkIdType numCells)
{
  int pointsPerAxis[3];
  for (int a = 0; a < 3; ++a)
  {
    pointsPerAxis[a] = ffd::ControlPointsAlongAxis(reader.Basis, reader.Divisions[a]);
  }
  if (const vtkIdType bad = FirstOutside(reader.VoxelIndices, reader.Divisions, numCells); bad >= 0)
  {
    return "The VoxelIndex of cell " + std::to_string(bad) + " is outside the lattice's FFDDivisions." + Transformed +
      Fix;
  }
  if (const vtkIdType bad = FirstOutside(reader.LatticeIndices, pointsPerAxis, reader.NumberOfPoints); bad >= 0)
  {
    return "The LatticeIndex of point " + std::to_string(bad) + " is outside the lattice's control points per axis." +
      Transformed + Fix;
  }
  return std::string();
}

/// The cells by their voxels' flat indices, with their ids.
vtkFFDSortedKeys<int> SortCells(const int* voxels, vtkIdType numCells, const int divisions[3])
{
  std::vector<std::pair<vtkTypeInt64, int>> order(static_cast<size_t>(numCells));
  vtkSMPTools::For(0, numCells,
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType c = begin; c < end; ++c)
      {
        const int* v = voxels + 3 * c;
        order[c] = { vtkFFDFlatIndex(v[0], v[1], v[2], divisions), int(c) };
      }
    });
  return vtkFFDSortedKeys<int>(std::move(order));
}

/**
 * Places each cell's points by their LatticeIndex, in the order of `order`: into `copy`, unless the lattice's
 * connectivity already is that, which only the B-spline's cells (in support order) can be; `viewed` says which.
 * Returns why a cell is not a support, or an empty string.
 */
std::string PlaceSupports(
  const CellReader& reader, const vtkFFDSortedKeys<int>& order, std::vector<int>& copy, bool& viewed)
{
  static_assert(std::is_same<vtkTypeInt32, int>::value, "32-bit cell ids are ints");
  const vtkIdType numCells = order.GetSize();
  const int n3 = reader.N * reader.N * reader.N;
  bool inOrder = true;
  for (vtkIdType r = 0; r < numCells && inOrder; ++r)
  {
    inOrder = order.GetId(r) == r;
  }
  std::atomic<bool> differs(true);
  vtkIdType firstBad = numCells;
  if (reader.Basis == ffd::GridBasis::CubicBSpline && inOrder && !reader.Cells->IsStorage64Bit())
  {
    differs = false;
    firstBad = reader.PlaceAll(order, nullptr, reader.Cells->GetConnectivityArray32()->GetPointer(0), differs);
  }
  if (differs && firstBad == numCells)
  {
    copy.resize(size_t(n3) * size_t(numCells));
    firstBad = reader.PlaceAll(order, copy.data(), nullptr, differs);
  }
  viewed = !differs;
  if (firstBad < numCells)
  {
    std::string why;
    vtkNew<vtkIdList> idList;
    const int cell = order.GetId(firstBad);
    std::vector<int> support(n3);
    reader.Place(cell, reader.VoxelIndices + 3 * cell, idList, support.data(), &why);
    return why + Fix;
  }
  return std::string();
}

/// The flat indices of `order`, and the voxels (i, j, k) in that order in `ordered`.
std::vector<vtkTypeInt64> OrderVoxels(const vtkFFDSortedKeys<int>& order, const int* voxels, std::vector<int>& ordered)
{
  std::vector<vtkTypeInt64> keys(order.GetSize());
  ordered.resize(3 * keys.size());
  vtkSMPTools::For(0, order.GetSize(),
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType r = begin; r < end; ++r)
      {
        keys[r] = order.GetKey(r);
        std::copy(voxels + 3 * order.GetId(r), voxels + 3 * order.GetId(r) + 3, ordered.data() + 3 * r);
      }
    });
  return keys;
}

/// FNV-1a over the cells' voxels (what a binding depends on) and supports (what a device holds).
std::uint64_t HashCells(const vtkFFDSortedKeys<>& keys, const int* supports, size_t numSupportIds)
{
  std::uint64_t hash = 14695981039346656037ull;
  for (vtkIdType r = 0; r < keys.GetSize(); ++r)
  {
    hash = (hash ^ std::uint64_t(keys.GetKey(r))) * 1099511628211ull;
  }
  for (const int* id = supports; id != supports + numSupportIds; ++id)
  {
    hash = (hash ^ std::uint64_t(*id)) * 1099511628211ull;
  }
  return hash;
}
} // namespace

//------------------------------------------------------------------------------------------------------------
std::string vtkFFDSparseCells::Read(vtkUnstructuredGrid* lattice, ffd::GridBasis basis, const int divisions[3])
{
  const vtkIdType numPoints = lattice->GetNumberOfPoints();
  const vtkIdType numCells = lattice->GetNumberOfCells();
  vtkCellArray* cells = lattice->GetCells();
  vtkIntArray* latticeIndex =
    IndexArray(lattice->GetPointData(), vtkFFDDataContract::LatticeIndexArrayName(), numPoints);
  vtkIntArray* voxelIndex = IndexArray(lattice->GetCellData(), vtkFFDDataContract::VoxelIndexArrayName(), numCells);
  if (std::string why = CheckArrays(lattice, latticeIndex, voxelIndex); !why.empty())
  {
    return why;
  }
  const void* source[3] = { cells, latticeIndex, voxelIndex };
  // The cell array's own time does not follow its arrays' when they are edited in place.
  const vtkMTimeType cellsTime =
    std::max({ cells->GetMTime(), cells->GetConnectivityArray()->GetMTime(), cells->GetOffsetsArray()->GetMTime() });
  const vtkMTimeType sourceTime[3] = { cellsTime, latticeIndex->GetMTime(), voxelIndex->GetMTime() };
  if (std::equal(source, source + 3, this->Source) && std::equal(sourceTime, sourceTime + 3, this->SourceTime) &&
    numPoints == this->SourcePoints && basis == this->SourceBasis &&
    std::equal(divisions, divisions + 3, this->SourceDivisions))
  {
    return std::string();
  }
  this->SourcePoints = -1; // valid again once read

  const int* voxels = voxelIndex->GetPointer(0);
  const CellReader reader{ cells, voxels, latticeIndex->GetPointer(0), numPoints, basis, divisions,
    ffd::SupportSize(basis, divisions[0]) };
  if (std::string why = CheckIndices(reader, numCells); !why.empty())
  {
    return why;
  }
  // The cells in the order of their voxels' flat indices, each voxel once.
  const vtkFFDSortedKeys<int> order = SortCells(voxels, numCells, divisions);
  if (const vtkIdType twice = order.FindRepeated(); twice >= 0)
  {
    return "Cells " + std::to_string(order.GetId(twice)) + " and " + std::to_string(order.GetId(twice + 1)) +
      " have the same VoxelIndex: a sparse lattice has one cell per voxel." + Transformed + Fix;
  }
  this->Supports = nullptr; // into SupportsCopy, which PlaceSupports() may move
  bool viewed = false;
  if (std::string why = PlaceSupports(reader, order, this->SupportsCopy, viewed); !why.empty())
  {
    return why;
  }
  if (viewed)
  {
    std::vector<int>().swap(this->SupportsCopy);
    this->Connectivity = cells->GetConnectivityArray32();
    this->Supports = cells->GetConnectivityArray32()->GetPointer(0);
  }
  else
  {
    this->Connectivity = nullptr;
    this->Supports = this->SupportsCopy.data();
  }
  this->Keys = vtkFFDSortedKeys<>(OrderVoxels(order, voxels, this->Voxels));

  const int n = reader.N;
  this->Fingerprint = HashCells(this->Keys, this->Supports, size_t(n * n * n) * size_t(numCells));
  std::copy(source, source + 3, this->Source);
  std::copy(sourceTime, sourceTime + 3, this->SourceTime);
  std::copy(divisions, divisions + 3, this->SourceDivisions);
  this->SourceBasis = basis;
  this->SourcePoints = numPoints;
  return std::string();
}

//------------------------------------------------------------------------------------------------------------
int vtkFFDSparseCells::Find(std::int64_t key) const
{
  return static_cast<int>(this->Keys.Find(key));
}
