// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDTetrahedralDeformer.h"

#include "vtkFFDDataContract.h"
#include "vtkFFDDeformPoints.h"
#include "vtkFFDForInChunks.h"
#include "vtkFFDLatticeDisplacements.h"
#include "vtkFFDTetrahedronLocator.h"

#include "vtkAOSDataArrayTemplate.h"
#include "vtkArrayDispatch.h"
#include "vtkCellArray.h"
#include "vtkCellType.h"
#include "vtkDataArray.h"
#include "vtkDataArrayRange.h"
#include "vtkFieldData.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkSMPTools.h"
#include "vtkUnstructuredGrid.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace
{
// Marks points that lie outside every tetrahedron until the outside policy decides, and points the walk
// could not place (binding only).
constexpr int Outside = -2;
constexpr int Undecided = -3;

bool IsFinite(const double x[3])
{
  return std::isfinite(x[0]) && std::isfinite(x[1]) && std::isfinite(x[2]);
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
    completed = vtkFFDDeformPoints(inPoints, cells, ffd::TetrahedralDeformation<Real>{ maps }, inNormals, outNormals,
      outPoints, determinants, self, vtkFFDGrain(n, 8.0), progressBegin, progressEnd);
  }
};

/// What keeps `lattice` from being a lattice of tetrahedra (no cells, or a cell of another type), or an empty
/// string. `fix` ends each message.
std::string CheckAllTetrahedra(vtkUnstructuredGrid* lattice, const std::string& fix)
{
  const vtkIdType numberOfCells = lattice->GetNumberOfCells();
  if (numberOfCells == 0 || lattice->GetNumberOfPoints() == 0)
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
  return std::string();
}

/// What is wrong with the point ids of tetrahedron `c` (not 4 of them, or one outside [0, numberOfNodes)), or an
/// empty string. `fix` ends the message.
std::string CellIdsProblem(
  vtkIdType c, vtkIdType count, const vtkIdType* ids, vtkIdType numberOfNodes, const std::string& fix)
{
  const vtkIdType* bad = count == 4
    ? std::find_if(ids, ids + 4, [numberOfNodes](vtkIdType id) { return id < 0 || id >= numberOfNodes; })
    : ids;
  if (bad == ids + 4)
  {
    return std::string();
  }
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
} // namespace

//------------------------------------------------------------------------------------------------------------

vtkFFDTetrahedralDeformer::vtkFFDTetrahedralDeformer() = default;
vtkFFDTetrahedralDeformer::~vtkFFDTetrahedralDeformer() = default;

//------------------------------------------------------------------------------------------------------------
bool vtkFFDTetrahedralDeformer::IsTetrahedralLattice(vtkDataObject* lattice)
{
  return vtkUnstructuredGrid::SafeDownCast(lattice) &&
    !lattice->GetFieldData()->GetAbstractArray(vtkFFDDataContract::FrameArrayName());
}

//------------------------------------------------------------------------------------------------------------
std::string vtkFFDTetrahedralDeformer::SetLattice(vtkUnstructuredGrid* lattice)
{
  this->Lattice = lattice;
  const std::string fix = " Build it with vtkFFDBuildTetrahedralLattice, or give a vtkUnstructuredGrid of "
                          "tetrahedra with a RestPosition point array (see vtkFFDDeform).";
  const vtkIdType numberOfCells = lattice->GetNumberOfCells();
  const vtkIdType numberOfNodes = lattice->GetNumberOfPoints();
  std::string why = CheckAllTetrahedra(lattice, fix);
  if (!why.empty())
  {
    return why;
  }
  vtkDataArray* rest = lattice->GetPointData()->GetArray(vtkFFDDataContract::RestPositionArrayName());
  if (!rest || rest->GetNumberOfComponents() != 3 || rest->GetNumberOfTuples() != numberOfNodes)
  {
    return "The tetrahedral lattice has no RestPosition point array of 3 components per point." + fix;
  }
  why = vtkFFDCheckLatticePrecision(lattice, rest, "The tetrahedral lattice");
  if (!why.empty())
  {
    return why;
  }
  this->RestPositions = rest;
  const vtkIdType bad = vtkFFDReadLatticeDisplacements(lattice, rest, this->Displacements, &this->RestValues);
  if (bad >= 0)
  {
    return vtkFFDLatticePointProblem(lattice, rest, bad, "Tetrahedral lattice point");
  }
  if (numberOfCells > MaxTetrahedra)
  {
    return "The tetrahedral lattice has " + std::to_string(numberOfCells) + " tetrahedra; at most " +
      std::to_string(MaxTetrahedra) + " are supported.";
  }
  return this->ReadNodes(lattice, fix);
}

//------------------------------------------------------------------------------------------------------------
std::string vtkFFDTetrahedralDeformer::ReadNodes(vtkUnstructuredGrid* lattice, const std::string& fix)
{
  // The connectivity is read again only when it changed (an update usually moves nodes only): the cell array,
  // or its arrays edited in place (vtkCellArray's time does not follow theirs), or the count of nodes its ids
  // must stay below.
  const vtkIdType numberOfCells = lattice->GetNumberOfCells();
  const vtkIdType numberOfNodes = lattice->GetNumberOfPoints();
  vtkCellArray* cells = lattice->GetCells();
  const vtkMTimeType cellsTime =
    std::max({ cells->GetMTime(), cells->GetConnectivityArray()->GetMTime(), cells->GetOffsetsArray()->GetMTime() });
  if (cells == this->NodesSource && cellsTime == this->NodesSourceMTime &&
    numberOfNodes == this->NodesSourceNodeCount && this->Nodes.size() == static_cast<size_t>(4 * numberOfCells))
  {
    return std::string();
  }
  // Every cell's point ids are checked here, before anything reads a node through them.
  this->Nodes.resize(4 * numberOfCells);
  for (vtkIdType c = 0; c < numberOfCells; ++c)
  {
    vtkIdType count;
    const vtkIdType* ids;
    cells->GetCellAtId(c, count, ids);
    std::string problem = CellIdsProblem(c, count, ids, numberOfNodes, fix);
    if (!problem.empty())
    {
      this->Nodes.clear();
      this->NodesSource = nullptr;
      return problem;
    }
    std::copy(ids, ids + 4, this->Nodes.begin() + 4 * c);
  }
  this->NodesSource = cells;
  this->NodesSourceMTime = cellsTime;
  this->NodesSourceNodeCount = numberOfNodes;
  this->NodesRead = true;
  return std::string();
}

//------------------------------------------------------------------------------------------------------------
bool vtkFFDTetrahedralDeformer::Bind(
  vtkPoints* points, int outsidePolicy, vtkAlgorithm* self, double progressBegin, double progressEnd, bool& rebound)
{
  rebound = false;
  const vtkFFDBindingKey key = vtkFFDBindingKey::Of(points, outsidePolicy);
  // The connectivity is compared only when it was read again (a rebuilt lattice): 6 MB for 181 k tetrahedra.
  const bool sameNodes = !this->NodesRead || this->Nodes == this->BoundNodes;
  this->NodesRead = false;
  if (key == this->Bound && this->RestValues == this->BoundRest && sameNodes)
  {
    return true;
  }
  this->Bound = vtkFFDBindingKey();

  this->ComputeRestFrames();
  vtkFFDTetrahedronLocator locator(
    this->Frames, this->Degenerate, this->Nodes, this->RestValues, this->Lattice, this->RestPositions);
  // 80 % of the progress for the walks, which see every point; the rest for VTK's locator, which sees the few
  // points they leave.
  const double middle = progressBegin + 0.8 * (progressEnd - progressBegin);
  if (!this->WalkPoints(points, locator, self, progressBegin, middle) ||
    !this->LocateUndecidedPoints(points, locator, self, middle, progressEnd))
  {
    return false;
  }
  this->ApplyOutsidePolicy(points, outsidePolicy, locator);
  this->ListUsedTetrahedra();

  this->Bound = key;
  this->BoundRest = this->RestValues;
  this->BoundNodes = this->Nodes;
  this->BindTime.Modified();
  rebound = true;
  return true;
}

//------------------------------------------------------------------------------------------------------------
// The rest frame of every tetrahedron; those without volume are never bound to.
void vtkFFDTetrahedralDeformer::ComputeRestFrames()
{
  const vtkIdType numberOfTetrahedra = static_cast<vtkIdType>(this->Nodes.size() / 4);
  this->Frames.resize(numberOfTetrahedra);
  this->Degenerate.assign(numberOfTetrahedra, 0);
  vtkSMPTools::For(0, numberOfTetrahedra,
    [this](vtkIdType begin, vtkIdType end)
    {
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
}

//------------------------------------------------------------------------------------------------------------
// Every point's tetrahedron by a walk from its seed, or Undecided; -1 for a non-finite point, which keeps its
// position. Without a tetrahedron of volume nothing walks: every point is Undecided.
bool vtkFFDTetrahedralDeformer::WalkPoints(vtkPoints* points, const vtkFFDTetrahedronLocator& locator,
  vtkAlgorithm* self, double progressBegin, double progressEnd)
{
  const vtkIdType numberOfPoints = points->GetNumberOfPoints();
  this->CellOfPoint.resize(numberOfPoints);
  if (this->NumberOfDegenerate == this->GetNumberOfTetrahedra())
  {
    std::fill(this->CellOfPoint.begin(), this->CellOfPoint.end(), Undecided);
    return true;
  }
  int* cells = this->CellOfPoint.data();
  auto walk = [points, &locator, cells](vtkIdType begin, vtkIdType end)
  {
    for (vtkIdType id = begin; id < end; ++id)
    {
      double x[3];
      points->GetPoint(id, x);
      if (!IsFinite(x))
      {
        cells[id] = -1;
        continue;
      }
      const int walked = locator.Walk(x);
      cells[id] = walked >= 0 ? walked : Undecided;
    }
  };
  return vtkFFDForInChunks(self, numberOfPoints, 1024, walk, progressBegin, progressEnd);
}

//------------------------------------------------------------------------------------------------------------
// The Undecided points' tetrahedra by VTK's locator, or Outside.
bool vtkFFDTetrahedralDeformer::LocateUndecidedPoints(
  vtkPoints* points, vtkFFDTetrahedronLocator& locator, vtkAlgorithm* self, double progressBegin, double progressEnd)
{
  std::vector<vtkIdType> undecided;
  for (vtkIdType id = 0; id < static_cast<vtkIdType>(this->CellOfPoint.size()); ++id)
  {
    if (this->CellOfPoint[id] == Undecided)
    {
      undecided.push_back(id);
    }
  }
  if (undecided.empty())
  {
    return true;
  }
  locator.BuildCellLocator();
  int* cells = this->CellOfPoint.data();
  auto locate = [points, &locator, &undecided, cells](vtkIdType begin, vtkIdType end)
  {
    for (vtkIdType u = begin; u < end; ++u)
    {
      double x[3];
      points->GetPoint(undecided[u], x);
      const int found = locator.FindTetrahedron(x);
      cells[undecided[u]] = found >= 0 ? found : Outside;
    }
  };
  return vtkFFDForInChunks(self, static_cast<vtkIdType>(undecided.size()), 256, locate, progressBegin, progressEnd);
}

//------------------------------------------------------------------------------------------------------------
// The outside policy, for the (usually few) points outside every tetrahedron: they keep their position (-1),
// follow their nearest tetrahedron (EXTRAPOLATE) or are clamped to its nearest point (CLAMP_TO_EDGE).
void vtkFFDTetrahedralDeformer::ApplyOutsidePolicy(
  vtkPoints* points, int outsidePolicy, vtkFFDTetrahedronLocator& locator)
{
  this->Clamped.clear();
  for (vtkIdType id = 0; id < static_cast<vtkIdType>(this->CellOfPoint.size()); ++id)
  {
    if (this->CellOfPoint[id] != Outside)
    {
      continue;
    }
    this->CellOfPoint[id] = -1;
    if (outsidePolicy == KEEP_POSITION)
    {
      continue;
    }
    double x[3], closest[3];
    points->GetPoint(id, x);
    locator.BuildCellLocator();
    const int tetrahedron = locator.FindClosestTetrahedron(x, closest);
    if (tetrahedron < 0 || this->Degenerate[tetrahedron])
    {
      continue; // its nearest tetrahedron has no map: it keeps its position
    }
    if (outsidePolicy == EXTRAPOLATE)
    {
      this->CellOfPoint[id] = tetrahedron;
      continue;
    }
    const ffd::Frame<double>& frame = this->Frames[tetrahedron];
    const ffd::Vec3<double> c = ffd::Vec3<double>::From(closest);
    this->Clamped.push_back({ id, tetrahedron, c, ffd::ClosestPointGradient(frame, frame.ToParametric(c), 1e-9) });
  }
}

//------------------------------------------------------------------------------------------------------------
// The tetrahedra some point is bound to, in increasing order: the only maps an evaluation computes.
void vtkFFDTetrahedralDeformer::ListUsedTetrahedra()
{
  std::vector<unsigned char> used(this->Frames.size(), 0);
  for (const int tetrahedron : this->CellOfPoint)
  {
    if (tetrahedron >= 0)
    {
      used[tetrahedron] = 1;
    }
  }
  this->Used.clear();
  for (size_t t = 0; t < used.size(); ++t)
  {
    if (used[t])
    {
      this->Used.push_back(static_cast<int>(t));
    }
  }
}

//------------------------------------------------------------------------------------------------------------
ffd::TetrahedronMap<double> vtkFFDTetrahedralDeformer::Map(vtkIdType tetrahedron) const
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
void vtkFFDTetrahedralDeformer::ComputeMaps(std::vector<ffd::TetrahedronMap<Real>>& maps) const
{
  // Only the tetrahedra some point is bound to: the others' maps are never read.
  maps.resize(this->Frames.size());
  vtkSMPTools::For(0, static_cast<vtkIdType>(this->Used.size()),
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType u = begin; u < end; ++u)
      {
        maps[this->Used[u]] = this->Map(this->Used[u]).template As<Real>();
      }
    });
}

//------------------------------------------------------------------------------------------------------------
bool vtkFFDTetrahedralDeformer::Evaluate(vtkPoints* points, vtkDataArray* normals, vtkDataArray* outPoints,
  vtkDataArray* outNormals, vtkDataArray* outDeterminants, vtkAlgorithm* self, double progressBegin, double progressEnd)
{
  bool completed = false;
  auto evaluate = [&](auto realTag)
  {
    using Real = decltype(realTag);
    using RealArray = vtkAOSDataArrayTemplate<Real>;
    std::vector<ffd::TetrahedronMap<Real>>& maps = this->MapsIn(Real());
    this->ComputeMaps(maps);
    Real* out = static_cast<RealArray*>(outPoints)->GetPointer(0);
    Real* det = outDeterminants ? static_cast<RealArray*>(outDeterminants)->GetPointer(0) : nullptr;
    EvaluateWorker<Real> worker;
    if (!vtkArrayDispatch::DispatchByValueType<vtkArrayDispatch::Reals>::Execute(points->GetData(), worker,
          this->CellOfPoint.data(), maps.data(), normals, outNormals, out, det, self, progressBegin, progressEnd,
          completed))
    {
      worker(points->GetData(), this->CellOfPoint.data(), maps.data(), normals, outNormals, out, det, self,
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
void vtkFFDTetrahedralDeformer::ApplyClampedPoints(vtkPoints* points, vtkDataArray* normals, vtkDataArray* outPoints,
  vtkDataArray* outNormals, vtkDataArray* outDeterminants) const
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
