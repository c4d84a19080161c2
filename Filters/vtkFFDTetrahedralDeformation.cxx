// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDTetrahedralDeformation.h"

#include "vtkFFDDataContract.h"
#include "vtkFFDDeformPoints.h"
#include "vtkFFDForInChunks.h"
#include "vtkFFDLatticeDisplacements.h"

#include "vtkAOSDataArrayTemplate.h"
#include "vtkArrayDispatch.h"
#include "vtkCellArray.h"
#include "vtkCellType.h"
#include "vtkDataArray.h"
#include "vtkDataArrayRange.h"
#include "vtkFieldData.h"
#include "vtkGenericCell.h"
#include "vtkIdList.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkSMPThreadLocalObject.h"
#include "vtkSMPTools.h"
#include "vtkStaticCellLocator.h"
#include "vtkUnstructuredGrid.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>

namespace
{
// Weight units by which a point may lie outside its tetrahedron and still count as inside: the band that
// absorbs rounding on faces, as ffd::ParametricTolerance() does for grid frames.
constexpr double InsideTolerance = 1e-10;

// Marks points that lie outside every tetrahedron until the outside policy decides, and points the walk
// could not place (binding only).
constexpr int Outside = -2;
constexpr int Undecided = -3;

bool IsFinite(const double x[3])
{
  return std::isfinite(x[0]) && std::isfinite(x[1]) && std::isfinite(x[2]);
}

//------------------------------------------------------------------------------------------------------------
// Locating points in the rest tetrahedra: a walk through face neighbours from a nearby seed does most of the
// work; VTK's vtkStaticCellLocator is the authority where the walk stops without an answer.
struct Walker
{
  const std::vector<ffd::Frame<double>>& Frames;
  const std::vector<unsigned char>& Degenerate;
  const std::vector<int>& Neighbours; // 4 per tetrahedron: across the face opposite node i, -1 on the boundary

  // Steps after which a walk gives up (it may cycle in a mesh that is not Delaunay); the locator takes over.
  static constexpr int MaxSteps = 256;

  /**
   * The tetrahedron holding x (its smallest weight >= -InsideTolerance) reached from `start` by stepping across
   * the face opposite the most negative weight, or -1 when the walk leaves the mesh, meets a tetrahedron without
   * volume or runs too long; `last` is the last tetrahedron it visited.
   */
  int Walk(int start, const ffd::Vec3<double>& x, int& last) const
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
};

// A uniform grid over the rest nodes' bounds whose cells remember a tetrahedron near their centre, where walks
// start.
struct Seeds
{
  double Origin[3], Spacing[3];
  int Size = 1;
  std::vector<int> Tetrahedra;

  int Of(const double x[3]) const
  {
    int index = 0;
    for (int a = 2; a >= 0; --a)
    {
      const double c = std::floor((x[a] - this->Origin[a]) / this->Spacing[a]);
      index = index * this->Size + static_cast<int>(std::min(std::max(c, 0.0), double(this->Size - 1)));
    }
    return this->Tetrahedra[index];
  }
};

// Walks every point from its seed to its tetrahedron; points the walk leaves undecided go to LocateFunctor.
struct WalkFunctor
{
  vtkPoints* Points;
  const Walker& Walk;
  const Seeds& Starts;
  int* Cells;

  void operator()(vtkIdType begin, vtkIdType end) const
  {
    for (vtkIdType id = begin; id < end; ++id)
    {
      double x[3];
      this->Points->GetPoint(id, x);
      if (!IsFinite(x))
      {
        this->Cells[id] = -1;
        continue;
      }
      int last;
      const int walked = this->Walk.Walk(this->Starts.Of(x), ffd::Vec3<double>::From(x), last);
      this->Cells[id] = walked >= 0 ? walked : Undecided;
    }
  }
};

// Locates the points the walks left undecided with VTK's locator: it proposes a tetrahedron (its own inside
// test has a looser tolerance) that the weights of equation 5 confirm, and failing that, every tetrahedron of
// the point's locator bin is tested and the one the point lies deepest in wins.
struct LocateFunctor
{
  vtkPoints* Points;
  vtkStaticCellLocator* Locator;
  const std::vector<ffd::Frame<double>>& Frames;
  const std::vector<unsigned char>& Degenerate;
  const std::vector<vtkIdType>& Undecided;
  int* Cells;
  vtkSMPThreadLocalObject<vtkGenericCell> Cell;
  vtkSMPThreadLocalObject<vtkIdList> Candidates;

  void Initialize() {}

  double Margin(vtkIdType tetrahedron, const double x[3]) const
  {
    return this->Degenerate[tetrahedron]
      ? -std::numeric_limits<double>::infinity()
      : ffd::InsideMargin(this->Frames[tetrahedron].ToParametric(ffd::Vec3<double>::From(x)));
  }

  void operator()(vtkIdType begin, vtkIdType end)
  {
    vtkGenericCell* cell = this->Cell.Local();
    vtkIdList* candidates = this->Candidates.Local();
    for (vtkIdType u = begin; u < end; ++u)
    {
      const vtkIdType id = this->Undecided[u];
      double x[3], pcoords[3], weights[4];
      this->Points->GetPoint(id, x);
      const vtkIdType proposed = this->Locator->FindCell(x, 0.0, cell, pcoords, weights);
      if (proposed >= 0 && this->Margin(proposed, x) >= 0.0)
      {
        this->Cells[id] = static_cast<int>(proposed);
        continue;
      }
      double bounds[6] = { x[0], x[0], x[1], x[1], x[2], x[2] };
      this->Locator->FindCellsWithinBounds(bounds, candidates);
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
      this->Cells[id] = bestMargin >= -InsideTolerance ? static_cast<int>(best) : Outside;
    }
  }

  void Reduce() {}
};

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

// Seeds for the walks: about 8 tetrahedra per grid cell, each cell's tetrahedron found by a walk from its
// neighbour's (or, outside the mesh, the boundary tetrahedron where that walk stopped).
Seeds MakeSeeds(const std::vector<double>& rest, const Walker& walk)
{
  Seeds seeds;
  double lo[3] = { rest[0], rest[1], rest[2] }, hi[3] = { rest[0], rest[1], rest[2] };
  for (size_t i = 0; i < rest.size(); i += 3)
  {
    for (int a = 0; a < 3; ++a)
    {
      lo[a] = std::min(lo[a], rest[i + a]);
      hi[a] = std::max(hi[a], rest[i + a]);
    }
  }
  const double cells = static_cast<double>(walk.Frames.size()) / 8.0;
  seeds.Size = std::max(1, std::min(64, static_cast<int>(std::cbrt(cells))));
  for (int a = 0; a < 3; ++a)
  {
    seeds.Origin[a] = lo[a];
    seeds.Spacing[a] = std::max(hi[a] - lo[a], std::numeric_limits<double>::min()) / seeds.Size;
  }
  seeds.Tetrahedra.resize(static_cast<size_t>(seeds.Size) * seeds.Size * seeds.Size);
  int previous = static_cast<int>(
    std::find(walk.Degenerate.begin(), walk.Degenerate.end(), 0) - walk.Degenerate.begin());
  for (int k = 0, index = 0; k < seeds.Size; ++k)
  {
    for (int j = 0; j < seeds.Size; ++j)
    {
      for (int i = 0; i < seeds.Size; ++i, ++index)
      {
        const ffd::Vec3<double> centre = { seeds.Origin[0] + (i + 0.5) * seeds.Spacing[0],
          seeds.Origin[1] + (j + 0.5) * seeds.Spacing[1], seeds.Origin[2] + (k + 0.5) * seeds.Spacing[2] };
        int last = previous;
        const int found = walk.Walk(previous, centre, last);
        previous = found >= 0 ? found : (walk.Degenerate[last] ? previous : last);
        seeds.Tetrahedra[index] = previous;
      }
    }
  }
  return seeds;
}

//------------------------------------------------------------------------------------------------------------
template <typename Real>
struct EvaluateWorker
{
  template <typename PointArrayT>
  void operator()(PointArrayT* inPoints, const int* cells, const ffd::TetrahedronMap<Real>* maps,
    vtkDataArray* inNormals, vtkDataArray* outNormals, Real* outPoints, Real* determinants, vtkAlgorithm* self,
    double progressBegin, double progressEnd, bool& completed)
  {
    const vtkIdType n = inPoints->GetNumberOfTuples();
    // A point reads its tetrahedron's affine map (12 numbers) and applies it.
    completed = vtkFFDDeformPoints(inPoints, cells, ffd::TetrahedralDeformation<Real>{ maps }, inNormals,
      outNormals, outPoints, determinants, self, vtkFFDGrain(n, 8.0), progressBegin, progressEnd);
  }
};
} // namespace

//------------------------------------------------------------------------------------------------------------
bool vtkFFDTetrahedralDeformation::Key::operator==(const Key& o) const
{
  return this->Points == o.Points && this->PointsMTime == o.PointsMTime &&
    this->NumberOfPoints == o.NumberOfPoints && this->Policy == o.Policy;
}

vtkFFDTetrahedralDeformation::vtkFFDTetrahedralDeformation() = default;
vtkFFDTetrahedralDeformation::~vtkFFDTetrahedralDeformation() = default;

//------------------------------------------------------------------------------------------------------------
bool vtkFFDTetrahedralDeformation::IsTetrahedralLattice(vtkDataObject* lattice)
{
  return vtkUnstructuredGrid::SafeDownCast(lattice) &&
    !lattice->GetFieldData()->GetAbstractArray(vtkFFDDataContract::FrameArrayName());
}

//------------------------------------------------------------------------------------------------------------
std::string vtkFFDTetrahedralDeformation::SetLattice(vtkUnstructuredGrid* lattice)
{
  this->Lattice = lattice;
  const std::string fix = " Build it with vtkFFDBuildTetrahedralLattice, or give a vtkUnstructuredGrid of "
                          "tetrahedra with a RestPosition point array (see vtkFFDDeform).";
  const vtkIdType numberOfCells = lattice->GetNumberOfCells();
  const vtkIdType numberOfNodes = lattice->GetNumberOfPoints();
  if (numberOfCells == 0 || numberOfNodes == 0)
  {
    return "The tetrahedral lattice has no cells." + fix;
  }
  const bool allTetrahedra = lattice->IsHomogeneous() && lattice->GetCellType(0) == VTK_TETRA;
  for (vtkIdType c = 0; c < numberOfCells && !allTetrahedra; ++c)
  {
    if (lattice->GetCellType(c) != VTK_TETRA)
    {
      std::ostringstream msg;
      msg << "The tetrahedral lattice's cell " << c << " is not a tetrahedron (VTK cell type "
          << lattice->GetCellType(c) << ")." << fix;
      return msg.str();
    }
  }
  vtkDataArray* rest = lattice->GetPointData()->GetArray(vtkFFDDataContract::RestPositionArrayName());
  if (!rest || rest->GetNumberOfComponents() != 3 || rest->GetNumberOfTuples() != numberOfNodes)
  {
    return "The tetrahedral lattice has no RestPosition point array of 3 components per point." + fix;
  }
  this->RestPositions = rest;
  const vtkIdType notFinite =
    vtkFFDReadLatticeDisplacements(lattice, rest, this->Displacements, &this->RestValues);
  if (notFinite >= 0)
  {
    return "Tetrahedral lattice point " + std::to_string(notFinite) + " or its RestPosition is not finite.";
  }
  if (numberOfCells > MaxTetrahedra)
  {
    return "The tetrahedral lattice has " + std::to_string(numberOfCells) + " tetrahedra; at most " +
      std::to_string(MaxTetrahedra) + " are supported.";
  }
  // The connectivity is read again only when it changed (an update usually moves nodes only): the cell array,
  // or its arrays edited in place (vtkCellArray's time does not follow theirs), or the count of nodes its ids
  // must stay below.
  vtkCellArray* cells = lattice->GetCells();
  const vtkMTimeType cellsTime = std::max(
    { cells->GetMTime(), cells->GetConnectivityArray()->GetMTime(), cells->GetOffsetsArray()->GetMTime() });
  if (cells != this->NodesSource || cellsTime != this->NodesSourceMTime ||
    numberOfNodes != this->NodesSourceNodeCount || this->Nodes.size() != static_cast<size_t>(4 * numberOfCells))
  {
    // Every cell's point ids are checked here, before anything reads a node through them.
    this->Nodes.resize(4 * numberOfCells);
    for (vtkIdType c = 0; c < numberOfCells; ++c)
    {
      vtkIdType count;
      const vtkIdType* ids;
      cells->GetCellAtId(c, count, ids);
      const vtkIdType* bad = count == 4
        ? std::find_if(ids, ids + 4, [numberOfNodes](vtkIdType id) { return id < 0 || id >= numberOfNodes; })
        : ids;
      if (bad != ids + 4)
      {
        this->Nodes.clear();
        this->NodesSource = nullptr;
        std::ostringstream msg;
        msg << "The tetrahedral lattice's cell " << c;
        if (count != 4)
        {
          msg << " is a tetrahedron of " << count << " point ids instead of 4.";
        }
        else
        {
          msg << " names point " << *bad << ", but the lattice has " << numberOfNodes << " points (ids 0 to "
              << numberOfNodes - 1 << ").";
        }
        return msg.str() + fix;
      }
      std::copy(ids, ids + 4, this->Nodes.begin() + 4 * c);
    }
    this->NodesSource = cells;
    this->NodesSourceMTime = cellsTime;
    this->NodesSourceNodeCount = numberOfNodes;
    this->NodesRead = true;
  }
  return std::string();
}

//------------------------------------------------------------------------------------------------------------
vtkFFDTetrahedralDeformation::Key vtkFFDTetrahedralDeformation::KeyOf(vtkPoints* points, int policy) const
{
  Key key;
  key.Points = points;
  key.PointsMTime = points->GetMTime();
  key.NumberOfPoints = points->GetNumberOfPoints();
  key.Policy = policy;
  return key;
}

//------------------------------------------------------------------------------------------------------------
bool vtkFFDTetrahedralDeformation::Bind(vtkPoints* points, int outsidePolicy, vtkAlgorithm* self,
  double progressBegin, double progressEnd, bool& rebound)
{
  rebound = false;
  const Key key = this->KeyOf(points, outsidePolicy);
  // The connectivity is compared only when it was read again (a rebuilt lattice): 6 MB for 181 k tetrahedra.
  const bool sameNodes = !this->NodesRead || this->Nodes == this->BoundNodes;
  this->NodesRead = false;
  if (key == this->Bound && this->RestValues == this->BoundRest && sameNodes)
  {
    return true;
  }
  this->Bound = Key();

  // The rest frame of every tetrahedron; those without volume are never bound to.
  const vtkIdType numberOfTetrahedra = static_cast<vtkIdType>(this->Nodes.size() / 4);
  this->Frames.resize(numberOfTetrahedra);
  this->Degenerate.assign(numberOfTetrahedra, 0);
  vtkSMPTools::For(0, numberOfTetrahedra, [this](vtkIdType begin, vtkIdType end) {
    for (vtkIdType t = begin; t < end; ++t)
    {
      const double* corner[4];
      for (int i = 0; i < 4; ++i)
      {
        corner[i] = this->RestValues.data() + 3 * this->Nodes[4 * t + i];
      }
      if (ffd::CheckTetrahedron(corner[0], corner[1], corner[2], corner[3]) != ffd::FrameStatus::Valid)
      {
        this->Degenerate[t] = 1;
        continue;
      }
      this->Frames[t] = ffd::TetrahedronFrame(corner[0], corner[1], corner[2], corner[3]);
    }
  });
  this->NumberOfDegenerate = std::count(this->Degenerate.begin(), this->Degenerate.end(), 1);
  const auto first = std::find(this->Degenerate.begin(), this->Degenerate.end(), 1);
  this->FirstDegenerate = first == this->Degenerate.end() ? -1 : first - this->Degenerate.begin();

  // VTK's locators over the rest tetrahedra, built only when a walk leaves a point undecided or the outside
  // policy needs nearest points.
  vtkNew<vtkPoints> restPoints;
  // vtkPoints::SetData() may rename or otherwise touch the array it is given: give it a copy that shares the
  // lattice's memory, so the user's RestPosition keeps its modification time.
  const auto restCopy = vtk::TakeSmartPointer(this->RestPositions->NewInstance());
  restCopy->ShallowCopy(this->RestPositions);
  restPoints->SetData(restCopy);
  vtkNew<vtkUnstructuredGrid> rest;
  rest->SetPoints(restPoints);
  rest->SetCells(this->Lattice->GetCellTypesArray(), this->Lattice->GetCells());
  vtkNew<vtkStaticCellLocator> locator;
  auto buildLocator = [&]() {
    if (!locator->GetDataSet())
    {
      locator->SetDataSet(rest);
      locator->BuildLocator();
      vtkNew<vtkGenericCell> warmUp;
      rest->GetCell(0, warmUp); // the first GetCell() is not thread-safe (vtkDataSet)
    }
  };

  const vtkIdType numberOfPoints = points->GetNumberOfPoints();
  this->Cells.resize(numberOfPoints);
  if (this->NumberOfDegenerate == numberOfTetrahedra)
  {
    std::fill(this->Cells.begin(), this->Cells.end(), Undecided);
  }
  else
  {
    this->Neighbours = FaceNeighbours(this->Nodes);
    const Walker walker{ this->Frames, this->Degenerate, this->Neighbours };
    const Seeds seeds = MakeSeeds(this->RestValues, walker);
    WalkFunctor walk{ points, walker, seeds, this->Cells.data() };
    const double middle = progressBegin + 0.8 * (progressEnd - progressBegin);
    if (!vtkFFDForInChunks(self, numberOfPoints, 1024, walk, progressBegin, middle))
    {
      return false;
    }
  }
  std::vector<vtkIdType> undecided;
  for (vtkIdType id = 0; id < numberOfPoints; ++id)
  {
    if (this->Cells[id] == Undecided)
    {
      undecided.push_back(id);
    }
  }
  if (!undecided.empty())
  {
    buildLocator();
    LocateFunctor locate{ points, locator, this->Frames, this->Degenerate, undecided, this->Cells.data(), {}, {} };
    if (!vtkFFDForInChunks(self, static_cast<vtkIdType>(undecided.size()), 256, locate,
          progressBegin + 0.8 * (progressEnd - progressBegin), progressEnd))
    {
      return false;
    }
  }

  // The outside policy, for the (usually few) points outside every tetrahedron.
  this->Clamped.clear();
  vtkNew<vtkGenericCell> cell;
  for (vtkIdType id = 0; id < numberOfPoints; ++id)
  {
    if (this->Cells[id] != Outside)
    {
      continue;
    }
    this->Cells[id] = -1;
    if (outsidePolicy == KEEP_POSITION)
    {
      continue;
    }
    double x[3], closest[3], dist2;
    vtkIdType tetrahedron = -1; // VTK leaves it as is where no tetrahedron gives a distance (none has volume)
    int subId;
    points->GetPoint(id, x);
    buildLocator();
    locator->FindClosestPoint(x, closest, cell, tetrahedron, subId, dist2);
    if (tetrahedron < 0 || this->Degenerate[tetrahedron])
    {
      continue; // its nearest tetrahedron has no map: it keeps its position
    }
    if (outsidePolicy == EXTRAPOLATE)
    {
      this->Cells[id] = static_cast<int>(tetrahedron);
      continue;
    }
    const ffd::Frame<double>& frame = this->Frames[tetrahedron];
    const ffd::Vec3<double> c = ffd::Vec3<double>::From(closest);
    this->Clamped.push_back({ id, static_cast<int>(tetrahedron), c,
      ffd::ClosestPointGradient(frame, frame.ToParametric(c), 1e-9) });
  }
  std::vector<unsigned char> used(numberOfTetrahedra, 0);
  for (const int tetrahedron : this->Cells)
  {
    if (tetrahedron >= 0)
    {
      used[tetrahedron] = 1;
    }
  }
  this->Used.clear();
  for (vtkIdType t = 0; t < numberOfTetrahedra; ++t)
  {
    if (used[t])
    {
      this->Used.push_back(static_cast<int>(t));
    }
  }
  this->Bound = key;
  this->BoundRest = this->RestValues;
  this->BoundNodes = this->Nodes;
  this->BindTime.Modified();
  rebound = true;
  return true;
}

//------------------------------------------------------------------------------------------------------------
ffd::TetrahedronMap<double> vtkFFDTetrahedralDeformation::Map(vtkIdType tetrahedron) const
{
  if (this->Degenerate[tetrahedron])
  {
    return ffd::TetrahedronMap<double>{}; // never used: nothing is bound to it
  }
  ffd::Vec3<double> d[4];
  for (int i = 0; i < 4; ++i)
  {
    d[i] = ffd::Vec3<double>::From(this->Displacements.data() + 3 * this->Nodes[4 * tetrahedron + i]);
  }
  return ffd::MakeTetrahedronMap(this->Frames[tetrahedron], d[0], d[1], d[2], d[3]);
}

template <typename Real>
void vtkFFDTetrahedralDeformation::ComputeMaps(std::vector<ffd::TetrahedronMap<Real>>& maps) const
{
  // Only the tetrahedra some point is bound to: the others' maps are never read.
  maps.resize(this->Frames.size());
  vtkSMPTools::For(0, static_cast<vtkIdType>(this->Used.size()), [&](vtkIdType begin, vtkIdType end) {
    for (vtkIdType u = begin; u < end; ++u)
    {
      maps[this->Used[u]] = this->Map(this->Used[u]).template As<Real>();
    }
  });
}

//------------------------------------------------------------------------------------------------------------
bool vtkFFDTetrahedralDeformation::Evaluate(vtkPoints* points, vtkDataArray* normals, vtkDataArray* outPoints,
  vtkDataArray* outNormals, vtkDataArray* outDeterminants, vtkAlgorithm* self, double progressBegin,
  double progressEnd)
{
  bool completed = false;
  auto evaluate = [&](auto realTag) {
    using Real = decltype(realTag);
    using RealArray = vtkAOSDataArrayTemplate<Real>;
    std::vector<ffd::TetrahedronMap<Real>>& maps = this->MapsIn(Real());
    this->ComputeMaps(maps);
    Real* out = static_cast<RealArray*>(outPoints)->GetPointer(0);
    Real* det = outDeterminants ? static_cast<RealArray*>(outDeterminants)->GetPointer(0) : nullptr;
    EvaluateWorker<Real> worker;
    if (!vtkArrayDispatch::DispatchByValueType<vtkArrayDispatch::Reals>::Execute(points->GetData(), worker,
          this->Cells.data(), maps.data(), normals, outNormals, out, det, self, progressBegin, progressEnd,
          completed))
    {
      worker(points->GetData(), this->Cells.data(), maps.data(), normals, outNormals, out, det, self,
        progressBegin, progressEnd, completed);
    }
  };
  if (outPoints->GetDataType() == VTK_DOUBLE)
  {
    evaluate(double());
  }
  else
  {
    evaluate(float());
  }
  if (completed)
  {
    this->ApplyClampedPoints(points, normals, outPoints, outNormals, outDeterminants);
  }
  return completed;
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDTetrahedralDeformation::ApplyClampedPoints(vtkPoints* points, vtkDataArray* normals,
  vtkDataArray* outPoints, vtkDataArray* outNormals, vtkDataArray* outDeterminants) const
{
  for (const ClampedPoint& p : this->Clamped)
  {
    const ffd::TetrahedronMap<double> map = this->Map(p.Tetrahedron);
    double x[3];
    points->GetPoint(p.Point, x);
    const ffd::Vec3<double> y = ffd::Vec3<double>::From(x) + map.Displacement(p.Closest);
    outPoints->SetTuple3(p.Point, y.x, y.y, y.z);
    if (outNormals || outDeterminants)
    {
      ffd::Mat3<double> jacobian = map.Gradient * p.Gradient;
      for (int c = 0; c < 3; ++c)
      {
        jacobian.M[c][c] += 1.0;
      }
      if (outNormals)
      {
        double n[3];
        normals->GetTuple(p.Point, n);
        const ffd::Vec3<double> m = ffd::TransformNormal(jacobian, ffd::Vec3<double>::From(n));
        outNormals->SetTuple3(p.Point, m.x, m.y, m.z);
      }
      if (outDeterminants)
      {
        outDeterminants->SetTuple1(p.Point, ffd::Determinant(jacobian));
      }
    }
  }
}
