// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDTetrahedronLocator.h"

#include "vtkDataArray.h"
#include "vtkGenericCell.h"
#include "vtkIdList.h"
#include "vtkNew.h"
#include "vtkPoints.h"
#include "vtkSMPTools.h"
#include "vtkStaticCellLocator.h"
#include "vtkUnstructuredGrid.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>

namespace
{
// Weight units by which a point may lie outside its tetrahedron and still count as inside: the band that
// absorbs rounding on faces, as ffd::ParametricTolerance() does for grid frames.
constexpr double InsideTolerance = 1e-10;

// Steps after which a walk gives up (it may cycle in a mesh that is not Delaunay); VTK's locator takes over.
constexpr int MaxSteps = 256;

// The face neighbours of every tetrahedron (4 per tetrahedron, across the face opposite node i; -1 on the
// boundary), by sorting the faces.
std::vector<int> FaceNeighbours(const std::vector<vtkIdType>& nodes)
{
  struct Face
  {
    std::array<vtkIdType, 3> Nodes;
    int Side; // 4 * tetrahedron + the opposite node
    bool operator<(const Face& o) const { return this->Nodes < o.Nodes; }
  };
  const int numberOfTetrahedra = static_cast<int>(nodes.size() / 4);
  std::vector<Face> faces;
  faces.reserve(4 * numberOfTetrahedra);
  for (int t = 0; t < numberOfTetrahedra; ++t)
  {
    for (int i = 0; i < 4; ++i)
    {
      Face face{ {}, 4 * t + i };
      for (int k = 0, n = 0; k < 4; ++k)
      {
        if (k != i)
        {
          face.Nodes[n++] = nodes[4 * t + k];
        }
      }
      std::sort(face.Nodes.begin(), face.Nodes.end());
      faces.push_back(face);
    }
  }
  vtkSMPTools::Sort(faces.begin(), faces.end());
  std::vector<int> neighbours(4 * numberOfTetrahedra, -1);
  for (size_t f = 0; f + 1 < faces.size(); ++f)
  {
    if (faces[f].Nodes == faces[f + 1].Nodes)
    {
      neighbours[faces[f].Side] = faces[f + 1].Side / 4;
      neighbours[faces[f + 1].Side] = faces[f].Side / 4;
      ++f;
    }
  }
  return neighbours;
}
} // namespace

//------------------------------------------------------------------------------------------------------------
vtkFFDTetrahedronLocator::vtkFFDTetrahedronLocator(const std::vector<ffd::Frame<double>>& frames,
  const std::vector<unsigned char>& degenerate, const std::vector<vtkIdType>& nodes,
  const std::vector<double>& restValues, vtkUnstructuredGrid* lattice, vtkDataArray* restPositions)
  : Frames(frames)
  , Degenerate(degenerate)
  , Lattice(lattice)
  , RestPositions(restPositions)
{
  // Without a tetrahedron of volume no walk can start: VTK's locator answers alone.
  if (std::find(degenerate.begin(), degenerate.end(), 0) != degenerate.end())
  {
    this->Neighbours = FaceNeighbours(nodes);
    this->MakeSeeds(restValues);
  }
}

vtkFFDTetrahedronLocator::~vtkFFDTetrahedronLocator() = default;

//------------------------------------------------------------------------------------------------------------
// Seeds for the walks: about 8 tetrahedra per grid cell, each cell's tetrahedron found by a walk from its
// neighbour's (or, outside the mesh, the boundary tetrahedron where that walk stopped).
void vtkFFDTetrahedronLocator::MakeSeeds(const std::vector<double>& rest)
{
  double lo[3] = { rest[0], rest[1], rest[2] }, hi[3] = { rest[0], rest[1], rest[2] };
  for (size_t i = 0; i < rest.size(); i += 3)
  {
    for (int a = 0; a < 3; ++a)
    {
      lo[a] = std::min(lo[a], rest[i + a]);
      hi[a] = std::max(hi[a], rest[i + a]);
    }
  }
  const double cells = static_cast<double>(this->Frames.size()) / 8.0;
  const int size = std::max(1, std::min(64, static_cast<int>(std::cbrt(cells))));
  this->SeedSize = size;
  for (int a = 0; a < 3; ++a)
  {
    this->SeedOrigin[a] = lo[a];
    this->SeedSpacing[a] = std::max(hi[a] - lo[a], std::numeric_limits<double>::min()) / size;
  }
  this->Seeds.resize(static_cast<size_t>(size) * size * size);
  int previous =
    static_cast<int>(std::find(this->Degenerate.begin(), this->Degenerate.end(), 0) - this->Degenerate.begin());
  for (int k = 0, index = 0; k < size; ++k)
  {
    for (int j = 0; j < size; ++j)
    {
      for (int i = 0; i < size; ++i, ++index)
      {
        const ffd::Vec3<double> centre = { this->SeedOrigin[0] + (i + 0.5) * this->SeedSpacing[0],
          this->SeedOrigin[1] + (j + 0.5) * this->SeedSpacing[1],
          this->SeedOrigin[2] + (k + 0.5) * this->SeedSpacing[2] };
        int last = previous;
        const int found = this->WalkFrom(previous, centre, last);
        previous = found >= 0 ? found : (this->Degenerate[last] ? previous : last);
        this->Seeds[index] = previous;
      }
    }
  }
}

//------------------------------------------------------------------------------------------------------------
int vtkFFDTetrahedronLocator::SeedOf(const double x[3]) const
{
  int index = 0;
  for (int a = 2; a >= 0; --a)
  {
    const double c = std::floor((x[a] - this->SeedOrigin[a]) / this->SeedSpacing[a]);
    index = index * this->SeedSize + static_cast<int>(std::min(std::max(c, 0.0), double(this->SeedSize - 1)));
  }
  return this->Seeds[index];
}

//------------------------------------------------------------------------------------------------------------
int vtkFFDTetrahedronLocator::Walk(const double x[3], int hint) const
{
  if (this->Seeds.empty())
  {
    return -1;
  }
  int last;
  return this->WalkFrom(hint >= 0 ? hint : this->SeedOf(x), ffd::Vec3<double>::From(x), last);
}

// Steps across the face opposite the most negative weight until every weight is >= -InsideTolerance.
int vtkFFDTetrahedronLocator::WalkFrom(int start, const ffd::Vec3<double>& x, int& last) const
{
  int t = start;
  for (int step = 0; step < MaxSteps && t >= 0; ++step)
  {
    last = t;
    if (this->Degenerate[t])
    {
      return -1;
    }
    const ffd::Vec3<double> stu = this->Frames[t].ToParametric(x);
    const double w[4] = { 1.0 - stu.x - stu.y - stu.z, stu.x, stu.y, stu.z };
    int k = 0;
    for (int i = 1; i < 4; ++i)
    {
      k = w[i] < w[k] ? i : k;
    }
    if (w[k] >= -InsideTolerance)
    {
      return t;
    }
    t = this->Neighbours[4 * t + k];
  }
  return -1;
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDTetrahedronLocator::BuildCellLocator()
{
  if (this->CellLocator)
  {
    return;
  }
  vtkNew<vtkPoints> restPoints;
  // vtkPoints::SetData() may rename or otherwise touch the array it is given: give it a copy that shares the
  // lattice's memory, so the user's RestPosition keeps its modification time.
  const auto restCopy = vtk::TakeSmartPointer(this->RestPositions->NewInstance());
  restCopy->ShallowCopy(this->RestPositions);
  restPoints->SetData(restCopy);
  this->Rest = vtkSmartPointer<vtkUnstructuredGrid>::New();
  this->Rest->SetPoints(restPoints);
  this->Rest->SetCells(this->Lattice->GetCellTypesArray(), this->Lattice->GetCells());
  this->CellLocator = vtkSmartPointer<vtkStaticCellLocator>::New();
  this->CellLocator->SetDataSet(this->Rest);
  this->CellLocator->BuildLocator();
  vtkNew<vtkGenericCell> warmUp;
  this->Rest->GetCell(0, warmUp); // the first GetCell() is not thread-safe (vtkDataSet)
}

//------------------------------------------------------------------------------------------------------------
double vtkFFDTetrahedronLocator::Margin(vtkIdType tetrahedron, const double x[3]) const
{
  return this->Degenerate[tetrahedron]
    ? -std::numeric_limits<double>::infinity()
    : ffd::InsideMargin(this->Frames[tetrahedron].ToParametric(ffd::Vec3<double>::From(x)));
}

int vtkFFDTetrahedronLocator::FindTetrahedron(const double x[3]) const
{
  vtkGenericCell* cell = this->Cell.Local();
  vtkIdList* candidates = this->Candidates.Local();
  double position[3] = { x[0], x[1], x[2] }, pcoords[3], weights[4];
  const vtkIdType proposed = this->CellLocator->FindCell(position, 0.0, cell, pcoords, weights);
  if (proposed >= 0 && this->Margin(proposed, x) >= 0.0)
  {
    return static_cast<int>(proposed);
  }
  double bounds[6] = { x[0], x[0], x[1], x[1], x[2], x[2] };
  this->CellLocator->FindCellsWithinBounds(bounds, candidates);
  vtkIdType best = -1;
  double bestMargin = -std::numeric_limits<double>::infinity();
  for (vtkIdType c = 0; c < candidates->GetNumberOfIds(); ++c)
  {
    const double margin = this->Margin(candidates->GetId(c), x);
    if (margin > bestMargin)
    {
      bestMargin = margin;
      best = candidates->GetId(c);
    }
  }
  return bestMargin >= -InsideTolerance ? static_cast<int>(best) : -1;
}

//------------------------------------------------------------------------------------------------------------
int vtkFFDTetrahedronLocator::FindClosestTetrahedron(const double x[3], double closest[3]) const
{
  vtkIdType tetrahedron = -1; // VTK leaves it as is where no tetrahedron gives a distance (none has volume)
  int subId;
  double dist2;
  vtkGenericCell* cell = this->Cell.Local();
  this->CellLocator->FindClosestPoint(x, closest, cell, tetrahedron, subId, dist2);
  if (tetrahedron < 0)
  {
    return -1;
  }
  // Several tetrahedra are often as near (x's nearest point a node or an edge they share), and which of them
  // VTK's locator returns depends on the order its parallel build gave them: take the lowest id among those as
  // near, one with volume first, so that a point's result is the same at every binding.
  const double margin = 1e-9 * this->Rest->GetLength();
  const double box[6] = { closest[0] - margin, closest[0] + margin, closest[1] - margin, closest[1] + margin,
    closest[2] - margin, closest[2] + margin };
  vtkNew<vtkIdList> candidates;
  this->CellLocator->FindCellsWithinBounds(const_cast<double*>(box), candidates);
  const double tie = dist2 + 1e-10 * (dist2 + margin * margin);
  std::pair<bool, vtkIdType> best(this->Degenerate[tetrahedron] != 0, tetrahedron);
  for (vtkIdType i = 0; i < candidates->GetNumberOfIds(); ++i)
  {
    const vtkIdType id = candidates->GetId(i);
    const std::pair<bool, vtkIdType> key(this->Degenerate[id] != 0, id);
    if (!(key < best))
    {
      continue;
    }
    this->Rest->GetCell(id, cell);
    double nearest[3], pcoords[3], weights[4], d2;
    if (cell->EvaluatePosition(x, nearest, subId, pcoords, d2, weights) >= 0 && d2 <= tie)
    {
      best = key;
      std::copy_n(nearest, 3, closest);
    }
  }
  return static_cast<int>(best.second);
}
