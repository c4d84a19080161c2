// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDCellEdges.h"

#include "vtkCell.h"
#include "vtkCellArray.h"
#include "vtkDataSet.h"
#include "vtkDataSetAttributes.h"
#include "vtkFFDDataContract.h"
#include "vtkFFDSortedKeys.h"
#include "vtkGenericCell.h"
#include "vtkIdList.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkIntArray.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkUnsignedCharArray.h"

#include <algorithm>
#include <array>
#include <utility>
#include <vector>

vtkStandardNewMacro(vtkFFDCellEdges);

namespace
{
using Edges = std::vector<std::pair<vtkIdType, vtkIdType>>;

/// Adds the edge (a, b) as (min, max), unless a and b are one point.
void AddEdge(Edges& edges, vtkIdType a, vtkIdType b)
{
  if (a != b)
  {
    edges.emplace_back(std::min(a, b), std::max(a, b));
  }
}

/// The control net of a sparse lattice: an edge for each two points whose LatticeIndex differ by one along one
/// axis, found among the points' indices sorted as (k, j, i): whatever their values, which a flat key
/// i + nI (j + nJ k) could overflow or alias where they are negative.
void AddControlNet(vtkIntArray* latticeIndex, Edges& edges)
{
  using Key = std::array<int, 3>; // (k, j, i)
  const vtkIdType n = latticeIndex->GetNumberOfTuples();
  const int* index = latticeIndex->GetPointer(0);
  std::vector<std::pair<Key, vtkIdType>> keys(static_cast<size_t>(n));
  for (vtkIdType p = 0; p < n; ++p)
  {
    keys[p] = { { index[3 * p + 2], index[3 * p + 1], index[3 * p] }, p };
  }
  const vtkFFDSortedKeys<vtkIdType, Key> sorted(std::move(keys));
  for (vtkIdType p = 0; p < n; ++p)
  {
    for (int a = 0; a < 3; ++a)
    {
      Key next = { index[3 * p + 2], index[3 * p + 1], index[3 * p] };
      if (next[2 - a] == VTK_INT_MAX)
      {
        continue;
      }
      ++next[2 - a];
      if (const vtkIdType neighbour = sorted.FindId(next); neighbour >= 0)
      {
        AddEdge(edges, p, neighbour);
      }
    }
  }
}

/// The input's own points on `output`: shared when it has a vtkPoints (lattices and voxel grids do), else copied.
void SetPoints(vtkDataSet* input, vtkPolyData* output)
{
  vtkPointSet* pointSet = vtkPointSet::SafeDownCast(input);
  if (pointSet && pointSet->GetPoints())
  {
    output->SetPoints(pointSet->GetPoints());
    return;
  }
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(input->GetNumberOfPoints());
  for (vtkIdType id = 0; id < input->GetNumberOfPoints(); ++id)
  {
    points->SetPoint(id, input->GetPoint(id));
  }
  output->SetPoints(points);
}

/// The edges of the input's cells but hidden ghosts: false, with the error reported on `self`, where the ghost
/// array does not fit the cells or a cell names a point the input lacks.
bool AddCellEdges(vtkFFDCellEdges* self, vtkDataSet* input, Edges& edges)
{
  vtkUnsignedCharArray* ghosts = input->GetCellGhostArray();
  const vtkIdType numberOfPoints = input->GetNumberOfPoints();
  const vtkIdType numberOfCells = input->GetNumberOfCells();
  if (ghosts && ghosts->GetNumberOfValues() != numberOfCells)
  {
    vtkErrorWithObjectMacro(self, << "The input's cell ghost array has " << ghosts->GetNumberOfValues()
                                  << " values for " << numberOfCells << " cells.");
    return false;
  }
  vtkNew<vtkGenericCell> cell;
  vtkNew<vtkIdList> ids;
  edges.reserve(static_cast<size_t>(numberOfCells) * 12);
  for (vtkIdType cellId = 0; cellId < numberOfCells; ++cellId)
  {
    if (ghosts && (ghosts->GetValue(cellId) & vtkDataSetAttributes::HIDDENCELL))
    {
      continue;
    }
    input->GetCellPoints(cellId, ids); // checked before GetCell() reads the points they name
    for (vtkIdType p = 0; p < ids->GetNumberOfIds(); ++p)
    {
      if (ids->GetId(p) < 0 || ids->GetId(p) >= numberOfPoints)
      {
        vtkErrorWithObjectMacro(self, << "The input's cell " << cellId << " names point " << ids->GetId(p)
                                      << ", but it has " << numberOfPoints << " points.");
        return false;
      }
    }
    input->GetCell(cellId, cell);
    if (cell->GetCellDimension() == 1)
    {
      // A line or polyline is its own edge list (vtkCell::GetNumberOfEdges() is 0 for them).
      for (vtkIdType p = 0; p + 1 < cell->GetNumberOfPoints(); ++p)
      {
        AddEdge(edges, cell->GetPointId(p), cell->GetPointId(p + 1));
      }
      continue;
    }
    const int numberOfEdges = cell->GetNumberOfEdges();
    for (int e = 0; e < numberOfEdges; ++e)
    {
      vtkCell* edge = cell->GetEdge(e);
      AddEdge(edges, edge->GetPointId(0), edge->GetPointId(1));
    }
  }
  return true;
}
} // namespace

//------------------------------------------------------------------------------
int vtkFFDCellEdges::FillInputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkDataSet");
  return 1;
}

//------------------------------------------------------------------------------
int vtkFFDCellEdges::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkDataSet* input = vtkDataSet::GetData(inputVector[0]);
  vtkPolyData* output = vtkPolyData::GetData(outputVector);
  if (!input || !output)
  {
    vtkErrorMacro("Expected a vtkDataSet (a lattice or a voxel grid) on input 0.");
    return 0;
  }
  const vtkIdType numberOfPoints = input->GetNumberOfPoints();
  if (numberOfPoints == 0)
  {
    return 1;
  }
  SetPoints(input, output);

  // Edges as pairs of point ids, sorted and made unique at the end: the output does not depend on hashing.
  Edges edges;
  vtkIntArray* latticeIndex =
    vtkIntArray::SafeDownCast(input->GetPointData()->GetArray(vtkFFDDataContract::LatticeIndexArrayName()));
  if (latticeIndex && latticeIndex->GetNumberOfComponents() == 3 && latticeIndex->GetNumberOfTuples() == numberOfPoints)
  {
    AddControlNet(latticeIndex, edges);
  }
  else if (!AddCellEdges(this, input, edges))
  {
    output->Initialize();
    return 0;
  }
  return this->Finish(edges, output);
}

//------------------------------------------------------------------------------
int vtkFFDCellEdges::Finish(std::vector<std::pair<vtkIdType, vtkIdType>>& edges, vtkPolyData* output)
{
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  vtkNew<vtkCellArray> lines;
  lines->AllocateExact(static_cast<vtkIdType>(edges.size()), 2 * static_cast<vtkIdType>(edges.size()));
  for (const auto& edge : edges)
  {
    const vtkIdType ids[2] = { edge.first, edge.second };
    lines->InsertNextCell(2, ids);
  }
  output->SetLines(lines);
  return 1;
}

//------------------------------------------------------------------------------
void vtkFFDCellEdges::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
}
