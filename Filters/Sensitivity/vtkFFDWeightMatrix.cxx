// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDWeightMatrix.h"

#include "vtkFFDForInChunks.h"
#include "vtkFFDGridDeformer.h"
#include "vtkFFDLatticeQueries.h"
#include "vtkFFDMemory.h"
#include "vtkFFDTetrahedralDeformer.h"

#include "vtkDoubleArray.h"
#include "vtkIdTypeArray.h"
#include "vtkObjectFactory.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkSMPTools.h"
#include "vtkUnstructuredGrid.h"

#include <algorithm>
#include <new>
#include <stdexcept>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkFFDWeightMatrix);

namespace
{
// offsets[p + 1] = offsets[p] + length(p) over [0, n), offsets[0] = 0: each block of rows sums its lengths, the
// blocks' totals are added in order, then each block writes its offsets from its start. Integer sums: the same
// offsets whatever the threads.
template <typename Length>
void PrefixSum(vtkIdType n, Length&& length, vtkIdType* offsets)
{
  const vtkIdType blocks = std::max<vtkIdType>(1, std::min<vtkIdType>(256, n / 65536));
  std::vector<vtkIdType> start(std::size_t(blocks) + 1, 0);
  auto rows = [&](vtkIdType block, vtkIdType& begin, vtkIdType& end)
  {
    begin = n * block / blocks;
    end = n * (block + 1) / blocks;
  };
  vtkSMPTools::For(0, blocks,
    [&](vtkIdType first, vtkIdType last)
    {
      for (vtkIdType block = first; block < last; ++block)
      {
        vtkIdType begin, end, sum = 0;
        rows(block, begin, end);
        for (vtkIdType p = begin; p < end; ++p)
        {
          sum += length(p);
        }
        start[block + 1] = sum;
      }
    });
  for (vtkIdType block = 0; block < blocks; ++block)
  {
    start[block + 1] += start[block];
  }
  offsets[0] = 0;
  vtkSMPTools::For(0, blocks,
    [&](vtkIdType first, vtkIdType last)
    {
      for (vtkIdType block = first; block < last; ++block)
      {
        vtkIdType begin, end, offset = start[block];
        rows(block, begin, end);
        for (vtkIdType p = begin; p < end; ++p)
        {
          offset += length(p);
          offsets[p + 1] = offset;
        }
      }
    });
}

// Orders a row's entries by column id (an insertion sort: rows are short, and a grid's already ordered).
void SortRow(vtkIdType* columns, double* values, vtkIdType count)
{
  for (vtkIdType a = 1; a < count; ++a)
  {
    const vtkIdType column = columns[a];
    const double value = values[a];
    vtkIdType b = a;
    for (; b > 0 && columns[b - 1] > column; --b)
    {
      columns[b] = columns[b - 1];
      values[b] = values[b - 1];
    }
    columns[b] = column;
    values[b] = value;
  }
}

// Calls write(p, columns, values) for every row p, in parallel, with the row's entries, then orders them.
template <typename Write>
void FillRows(vtkIdType n, int perRow, const vtkIdType* offsets, vtkIdType* columns, double* values, Write&& write)
{
  vtkSMPTools::For(0, n, vtkFFDGrain(n, perRow),
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType p = begin; p < end; ++p)
      {
        if (offsets[p + 1] > offsets[p])
        {
          write(p, columns + offsets[p], values + offsets[p]);
          SortRow(columns + offsets[p], values + offsets[p], offsets[p + 1] - offsets[p]);
        }
      }
    });
}
} // namespace

//------------------------------------------------------------------------------------------------------------
struct vtkFFDWeightMatrix::vtkInternals
{
  vtkFFDGridDeformer Grid; // keeps the lattice view that ForEachWeight reads
  vtkFFDTetrahedralDeformer Tetrahedra;
};

vtkFFDWeightMatrix::vtkFFDWeightMatrix()
  : OutsidePolicy(vtkFFDDeform::KEEP_POSITION)
  , NumberOfRows(0)
  , NumberOfColumns(0)
  , RowOffsets(vtkSmartPointer<vtkIdTypeArray>::New())
  , ColumnIds(vtkSmartPointer<vtkIdTypeArray>::New())
  , Values(vtkSmartPointer<vtkDoubleArray>::New())
  , Internals(new vtkInternals)
{
  this->RowOffsets->InsertNextValue(0);
}

vtkFFDWeightMatrix::~vtkFFDWeightMatrix() = default;

vtkIdTypeArray* vtkFFDWeightMatrix::GetRowOffsets()
{
  return this->RowOffsets;
}

vtkIdTypeArray* vtkFFDWeightMatrix::GetColumnIds()
{
  return this->ColumnIds;
}

vtkDoubleArray* vtkFFDWeightMatrix::GetValues()
{
  return this->Values;
}

//------------------------------------------------------------------------------------------------------------
int vtkFFDWeightMatrix::Compute(vtkPointSet* mesh, vtkPointSet* lattice)
{
  // New arrays, so that those handed out before keep their values; empty (one offset, 0) until filled.
  this->RowOffsets = vtkSmartPointer<vtkIdTypeArray>::New();
  this->RowOffsets->InsertNextValue(0);
  this->ColumnIds = vtkSmartPointer<vtkIdTypeArray>::New();
  this->Values = vtkSmartPointer<vtkDoubleArray>::New();
  this->NumberOfRows = this->NumberOfColumns = 0;
  this->Modified();
  if (!mesh || !lattice)
  {
    vtkErrorMacro("Compute() needs the mesh at rest (vtkFFDDeform's input 0) and the lattice (its input 1); "
      << (mesh ? "the lattice" : "the mesh") << " is null.");
    return 0;
  }
  bool filled = false;
  try
  {
    filled = vtkFFDTetrahedralDeformer::IsTetrahedralLattice(lattice) ? this->FillTetrahedral(mesh, lattice)
                                                                      : this->FillGrid(mesh, lattice);
  }
  catch (const std::bad_alloc&)
  {
    vtkErrorMacro("Out of memory: an allocation failed; the matrix is empty.");
  }
  catch (const std::length_error& e)
  {
    vtkErrorMacro("Out of memory: a size was too large (" << e.what() << "); the matrix is empty.");
  }
  if (!filled)
  {
    this->RowOffsets->SetNumberOfValues(1);
    this->RowOffsets->SetValue(0, 0);
    this->ColumnIds->Initialize();
    this->Values->Initialize();
    return 0;
  }
  this->NumberOfRows = mesh->GetNumberOfPoints();
  this->NumberOfColumns = lattice->GetNumberOfPoints();
  return 1;
}

//------------------------------------------------------------------------------------------------------------
bool vtkFFDWeightMatrix::AllocateRows(const std::vector<int>& cellOf, int perRow)
{
  const vtkIdType n = vtkIdType(cellOf.size());
  this->RowOffsets->SetNumberOfValues(n + 1);
  vtkIdType* offsets = this->RowOffsets->GetPointer(0);
  PrefixSum(
    n, [&](vtkIdType p) { return cellOf[p] >= 0 ? vtkIdType(perRow) : 0; }, offsets);
  const vtkIdType entries = offsets[n];
  const double bytes = double(entries) * double(sizeof(vtkIdType) + sizeof(double));
  if (bytes > vtkFFDAvailableMemory())
  {
    vtkErrorMacro("The weights of " << n << " points, " << entries << " entries, need " << vtkFFDFormatBytes(bytes)
                                    << " of memory, but only " << vtkFFDFormatBytes(vtkFFDAvailableMemory())
                                    << " is available.");
    return false;
  }
  this->ColumnIds->SetNumberOfValues(entries);
  this->Values->SetNumberOfValues(entries);
  return true;
}

bool vtkFFDWeightMatrix::FillGrid(vtkPointSet* mesh, vtkPointSet* lattice)
{
  vtkFFDGridDeformer& grid = this->Internals->Grid;
  const std::string problem = grid.SetLattice(lattice);
  if (!problem.empty() || this->OutsidePolicy == vtkFFDDeform::EXTRAPOLATE)
  {
    vtkErrorMacro(<< (problem.empty() ? "The outside policy EXTRAPOLATE needs a tetrahedral lattice." : problem));
    return false;
  }
  const vtkIdType n = mesh->GetNumberOfPoints();
  bool rebound = false;
  if (n > 0 && !grid.Bind(mesh->GetPoints(), this->OutsidePolicy, nullptr, 0.0, 1.0, rebound))
  {
    return false;
  }
  const std::vector<int> none;
  const std::vector<int>& cellOf = n > 0 ? grid.GetCellOfPoint() : none;
  const int perRow = vtkFFDGridWeightsPerPoint(grid);
  if (!this->AllocateRows(cellOf, perRow))
  {
    return false;
  }
  vtkPoints* points = mesh->GetPoints();
  vtkFFDWithGridDeformation(grid,
    [&](const auto& deformation)
    {
      FillRows(n, perRow, this->RowOffsets->GetPointer(0), this->ColumnIds->GetPointer(0), this->Values->GetPointer(0),
        [&](vtkIdType p, vtkIdType* columns, double* values)
        {
          double x[3];
          points->GetPoint(p, x);
          int k = 0;
          deformation.ForEachWeight({ x[0], x[1], x[2] }, cellOf[p],
            [&](int controlPoint, double w)
            {
              columns[k] = controlPoint;
              values[k++] = w;
            });
        });
    });
  return true;
}

// A point bound to a tetrahedron has its barycentric weights at the point; a point clamped to the control mesh
// those at its nearest point there (as vtkFFDTetrahedralDeformer::ApplyClampedPoints() moves it).
bool vtkFFDWeightMatrix::FillTetrahedral(vtkPointSet* mesh, vtkPointSet* lattice)
{
  vtkFFDTetrahedralDeformer& tetrahedra = this->Internals->Tetrahedra;
  const std::string problem = tetrahedra.SetLattice(vtkUnstructuredGrid::SafeDownCast(lattice));
  if (!problem.empty())
  {
    vtkErrorMacro(<< problem);
    return false;
  }
  const vtkIdType n = mesh->GetNumberOfPoints();
  bool rebound = false;
  if (n > 0 && !tetrahedra.Bind(mesh->GetPoints(), this->OutsidePolicy, nullptr, 0.0, 1.0, rebound))
  {
    return false;
  }
  std::vector<int> cellOf = n > 0 ? tetrahedra.GetCellOfPoint() : std::vector<int>();
  std::vector<int> clampedIndex(cellOf.size(), -1);
  const std::vector<vtkFFDTetrahedralDeformer::ClampedPoint>& clamped = tetrahedra.GetClampedPoints();
  for (std::size_t c = 0; n > 0 && c < clamped.size(); ++c)
  {
    cellOf[clamped[c].Point] = clamped[c].Tetrahedron;
    clampedIndex[clamped[c].Point] = int(c);
  }
  if (!this->AllocateRows(cellOf, 4))
  {
    return false;
  }
  vtkPoints* points = mesh->GetPoints();
  const std::vector<vtkIdType>& nodes = tetrahedra.GetNodes();
  FillRows(n, 4, this->RowOffsets->GetPointer(0), this->ColumnIds->GetPointer(0), this->Values->GetPointer(0),
    [&](vtkIdType p, vtkIdType* columns, double* values)
    {
      ffd::Vec3<double> at;
      if (clampedIndex[p] >= 0)
      {
        at = clamped[clampedIndex[p]].Closest;
      }
      else
      {
        double x[3];
        points->GetPoint(p, x);
        at = { x[0], x[1], x[2] };
      }
      const int t = cellOf[p];
      const ffd::Vec3<double> stu = tetrahedra.GetFrames()[t].ToParametric(at);
      const double w[4] = { 1.0 - stu.x - stu.y - stu.z, stu.x, stu.y, stu.z };
      for (int k = 0; k < 4; ++k)
      {
        columns[k] = nodes[4 * std::size_t(t) + k];
        values[k] = w[k];
      }
    });
  return true;
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDWeightMatrix::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "OutsidePolicy: " << this->OutsidePolicy << "\n";
  os << indent << "NumberOfRows: " << this->NumberOfRows << "\n";
  os << indent << "NumberOfColumns: " << this->NumberOfColumns << "\n";
  os << indent << "Entries: " << this->ColumnIds->GetNumberOfValues() << "\n";
}
