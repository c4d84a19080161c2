// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDCellEdges.h"

#include "vtkCell.h"
#include "vtkCellArray.h"
#include "vtkDataSet.h"
#include "vtkDataSetAttributes.h"
#include "vtkFFDDataContract.h"
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
/// The control net of a sparse lattice: addEdge(a, b) for each two points whose LatticeIndex differ by one along
/// one axis, found by binary search among the points' indices sorted as (k, j, i): whatever their values, which a
/// flat key i + nI (j + nJ k) could overflow or alias where they are negative.
template <typename AddEdge>
void AddControlNet(vtkIntArray* latticeIndex, AddEdge&& addEdge)
{
  using Key = std::array<int, 3>; // (k, j, i)
  const vtkIdType n = latticeIndex->GetNumberOfTuples();
  const int* index = latticeIndex->GetPointer(0);
  std::vector<std::pair<Key, vtkIdType>> sorted(static_cast<size_t>(n));
  for (vtkIdType p = 0; p < n; ++p)
  {
    sorted[p] = { { index[3 * p + 2], index[3 * p + 1], index[3 * p] }, p };
  }
  std::sort(sorted.begin(), sorted.end());
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
      const auto at = std::lower_bound(sorted.begin(), sorted.end(), std::make_pair(next, vtkIdType(0)));
      if (at != sorted.end() && at->first == next)
      {
        addEdge(p, at->second);
      }
    }
  }
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

  // The input's own points: shared when it has a vtkPoints (lattices and voxel grids do), copied otherwise.
  vtkPointSet* pointSet = vtkPointSet::SafeDownCast(input);
  if (pointSet && pointSet->GetPoints())
  {
    output->SetPoints(pointSet->GetPoints());
  }
  else
  {
    vtkNew<vtkPoints> points;
    points->SetDataTypeToDouble();
    points->SetNumberOfPoints(numberOfPoints);
    for (vtkIdType id = 0; id < numberOfPoints; ++id)
    {
      points->SetPoint(id, input->GetPoint(id));
    }
    output->SetPoints(points);
  }

  // Edges as pairs of point ids, sorted and made unique at the end: the output does not depend on hashing.
  std::vector<std::pair<vtkIdType, vtkIdType>> edges;
  auto addEdge = [&edges](vtkIdType a, vtkIdType b)
  {
    if (a != b)
    {
      edges.emplace_back(std::min(a, b), std::max(a, b));
    }
  };
  vtkIntArray* latticeIndex =
    vtkIntArray::SafeDownCast(input->GetPointData()->GetArray(vtkFFDDataContract::LatticeIndexArrayName()));
  if (latticeIndex && latticeIndex->GetNumberOfComponents() == 3 && latticeIndex->GetNumberOfTuples() == numberOfPoints)
  {
    AddControlNet(latticeIndex, addEdge);
    return this->Finish(edges, output);
  }
  vtkUnsignedCharArray* ghosts = input->GetCellGhostArray();
  const vtkIdType numberOfCells = input->GetNumberOfCells();
  if (ghosts && ghosts->GetNumberOfValues() != numberOfCells)
  {
    vtkErrorMacro(<< "The input's cell ghost array has " << ghosts->GetNumberOfValues() << " values for "
                  << numberOfCells << " cells.");
    output->Initialize();
    return 0;
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
        vtkErrorMacro(<< "The input's cell " << cellId << " names point " << ids->GetId(p) << ", but it has "
                      << numberOfPoints << " points.");
        output->Initialize();
        return 0;
      }
    }
    input->GetCell(cellId, cell);
    if (cell->GetCellDimension() == 1)
    {
      // A line or polyline is its own edge list (vtkCell::GetNumberOfEdges() is 0 for them).
      for (vtkIdType p = 0; p + 1 < cell->GetNumberOfPoints(); ++p)
      {
        addEdge(cell->GetPointId(p), cell->GetPointId(p + 1));
      }
      continue;
    }
    const int numberOfEdges = cell->GetNumberOfEdges();
    for (int e = 0; e < numberOfEdges; ++e)
    {
      vtkCell* edge = cell->GetEdge(e);
      addEdge(edge->GetPointId(0), edge->GetPointId(1));
    }
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
