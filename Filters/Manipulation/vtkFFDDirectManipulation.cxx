// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDDirectManipulation.h"

#include "vtkDoubleArray.h"
#include "vtkFFDDeform.h"
#include "vtkFFDGridDeformer.h"
#include "vtkFFDInputChecks.h"
#include "vtkFFDLatticeQueries.h"
#include "vtkFFDMemory.h"
#include "vtkFFDStatistics.h"
#include "vtkFFDTetrahedralDeformer.h"
#include "vtkIdTypeArray.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkMath.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSmartPointer.h"
#include "vtkUnstructuredGrid.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkFFDDirectManipulation);

namespace
{
bool IsFinite(const double x[3])
{
  return std::isfinite(x[0]) && std::isfinite(x[1]) && std::isfinite(x[2]);
}

/// The targets' mesh points at rest, into `rest`; an empty string, or why the targets cannot be used.
std::string ReadTargets(vtkIdTypeArray* ids, vtkPoints* positions, vtkPointSet* mesh, vtkPoints* rest)
{
  const vtkIdType count = ids->GetNumberOfValues();
  rest->SetNumberOfPoints(count);
  std::ostringstream why;
  for (vtkIdType t = 0; t < count; ++t)
  {
    const vtkIdType id = ids->GetValue(t);
    if (id < 0 || id >= mesh->GetNumberOfPoints())
    {
      why << "Target " << t << " names mesh point " << id << "; the mesh has " << mesh->GetNumberOfPoints()
          << " points: give SetTargetPointIds() ids from 0 to " << mesh->GetNumberOfPoints() - 1 << ".";
      return why.str();
    }
    double x[3], target[3];
    mesh->GetPoint(id, x);
    positions->GetPoint(t, target);
    if (!IsFinite(x))
    {
      why << "Target " << t << " names mesh point " << id << ", whose coordinates (" << x[0] << ", " << x[1] << ", "
          << x[2] << ") are not finite: it has no place in the lattice; remove it from SetTargetPointIds().";
      return why.str();
    }
    if (!IsFinite(target))
    {
      why << "Target position " << t << " (" << target[0] << ", " << target[1] << ", " << target[2]
          << ") is not finite: give SetTargetPositions() finite world coordinates.";
      return why.str();
    }
    rest->SetPoint(t, x);
  }
  return why.str();
}

/// dP = W^+ (T - F), or W^T (W W^T + lambda I)^-1 (T - F) with lambda = `regularization` times mean(diag W W^T).
Eigen::MatrixXd SolveMove(const Eigen::MatrixXd& w, const Eigen::MatrixXd& change, double regularization)
{
  if (regularization > 0)
  {
    Eigen::MatrixXd gram = w * w.transpose();
    const double lambda = regularization * gram.diagonal().mean();
    gram.diagonal().array() += lambda > 0 ? lambda : regularization;
    return w.transpose() * gram.ldlt().solve(change);
  }
  return Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd>(w).solve(change);
}

/// False, said why, where there is no mesh, not one position per target id, or no usable regularization.
bool CheckSettings(
  vtkFFDDirectManipulation* self, vtkPointSet* mesh, vtkPoints* positions, vtkIdType count, double regularization)
{
  if (!mesh || !mesh->GetPoints())
  {
    vtkErrorWithObjectMacro(
      self, << "No mesh: SetMeshConnection() (input 1) to the mesh at rest that the lattice deforms.");
    return false;
  }
  if (!positions || positions->GetNumberOfPoints() != count)
  {
    vtkErrorWithObjectMacro(self, << "There are " << count << " target point ids but "
                                  << (positions ? positions->GetNumberOfPoints() : 0)
                                  << " target positions: give one position per id.");
    return false;
  }
  if (!std::isfinite(regularization) || regularization < 0)
  {
    vtkErrorWithObjectMacro(self, << "Regularization is " << regularization
                                  << ": give SetRegularization() a finite number >= 0 (0, the default: the "
                                     "pseudo-inverse).");
    return false;
  }
  return true;
}

/// The targets' rest points, into `rest`, and where the lattice takes them now; nullptr, said why, where the
/// targets cannot be used or deformed.
vtkSmartPointer<vtkPointSet> PlaceTargets(vtkFFDDirectManipulation* self, vtkIdTypeArray* ids, vtkPoints* positions,
  vtkPointSet* mesh, vtkPointSet* lattice, vtkPoints* rest)
{
  const std::string unusable = ReadTargets(ids, positions, mesh, rest);
  if (!unusable.empty())
  {
    vtkErrorWithObjectMacro(self, << unusable);
    return nullptr;
  }
  vtkNew<vtkPolyData> targets;
  targets->SetPoints(rest);
  vtkNew<vtkFFDDeform> deform;
  deform->SetInputData(targets);
  deform->SetLatticeData(lattice);
  deform->SetOutputPointsPrecision(vtkAlgorithm::DOUBLE_PRECISION);
  deform->Update();
  vtkSmartPointer<vtkPointSet> now = vtkPointSet::SafeDownCast(deform->GetOutputDataObject(0));
  if (!now || now->GetNumberOfPoints() != ids->GetNumberOfValues())
  {
    vtkErrorWithObjectMacro(self, << "Could not deform the targets by the lattice (see the error above).");
    return nullptr;
  }
  return now;
}

/// An entry of W: the weight of a target on a control point.
struct Entry
{
  vtkIdType Target;
  vtkIdType ControlPoint;
  double Weight;
};

/// The nonzero entries of W, each target's weights on the control points of its cell, and each target's cell
/// (-1: outside the lattice, said so); false, said why, where the targets cannot be bound to the lattice.
bool TargetWeights(vtkFFDDirectManipulation* self, vtkPointSet* lattice, vtkPoints* rest, std::vector<Entry>& entries,
  std::vector<int>& cellOf)
{
  const vtkIdType count = rest->GetNumberOfPoints();
  auto add = [&](vtkIdType target, vtkIdType controlPoint, double weight)
  {
    if (weight != 0)
    {
      entries.push_back({ target, controlPoint, weight });
    }
  };
  bool rebound = false;
  if (vtkFFDTetrahedralDeformer::IsTetrahedralLattice(lattice))
  {
    vtkFFDTetrahedralDeformer tetrahedra;
    const std::string why = tetrahedra.SetLattice(vtkUnstructuredGrid::SafeDownCast(lattice));
    if (!why.empty() || !tetrahedra.Bind(rest, vtkFFDTetrahedralDeformer::KEEP_POSITION, nullptr, 0, 1, rebound))
    {
      vtkErrorWithObjectMacro(self, << "Cannot bind the targets to the lattice. " << why);
      return false;
    }
    cellOf = tetrahedra.GetCellOfPoint();
    vtkFFDForEachTetrahedronWeight(tetrahedra, rest, 0, count, add);
  }
  else
  {
    vtkFFDGridDeformer grid;
    const std::string why = grid.SetLattice(lattice);
    if (!why.empty() || !grid.Bind(rest, vtkFFDDeform::KEEP_POSITION, nullptr, 0, 1, rebound))
    {
      vtkErrorWithObjectMacro(self, << "Cannot bind the targets to the lattice. " << why);
      return false;
    }
    cellOf = grid.GetCellOfPoint();
    vtkFFDForEachGridWeight(grid, rest, 0, count, add);
  }
  const vtkIdType outside = std::count(cellOf.begin(), cellOf.end(), -1);
  if (outside > 0)
  {
    vtkWarningWithObjectMacro(
      self, << outside << " of the " << count << " targets lie outside the lattice: they cannot be moved.");
  }
  return true;
}

/// The control points that move some target, in increasing order, and the column of W of each.
std::vector<vtkIdType> MovingControlPoints(const std::vector<Entry>& entries, std::map<vtkIdType, Eigen::Index>& column)
{
  for (const Entry& e : entries)
  {
    column.emplace(e.ControlPoint, 0);
  }
  std::vector<vtkIdType> controlPoints;
  for (auto& c : column)
  {
    c.second = Eigen::Index(controlPoints.size());
    controlPoints.push_back(c.first);
  }
  return controlPoints;
}

/// W: a row per target, a column per control point that moves some target.
Eigen::MatrixXd WeightMatrix(
  const std::vector<Entry>& entries, std::map<vtkIdType, Eigen::Index>& column, vtkIdType count)
{
  Eigen::MatrixXd w = Eigen::MatrixXd::Zero(count, Eigen::Index(column.size()));
  for (const Entry& e : entries)
  {
    w(Eigen::Index(e.Target), column[e.ControlPoint]) = e.Weight;
  }
  return w;
}

/// T - F: from where the lattice takes each target's point now to the target (0 for a target outside).
Eigen::MatrixXd TargetChanges(vtkPoints* positions, vtkPointSet* now, const std::vector<int>& cellOf)
{
  const vtkIdType count = now->GetNumberOfPoints();
  Eigen::MatrixXd change(count, 3);
  for (vtkIdType t = 0; t < count; ++t)
  {
    double target[3], at[3];
    positions->GetPoint(t, target);
    now->GetPoint(t, at);
    for (int c = 0; c < 3; ++c)
    {
      change(t, c) = cellOf[t] >= 0 ? target[c] - at[c] : 0.0;
    }
  }
  return change;
}

/// The lattice's points with `controlPoints` moved by the rows of `move`; `moved` counts those that moved.
vtkSmartPointer<vtkPoints> MovedPoints(
  vtkPointSet* lattice, const std::vector<vtkIdType>& controlPoints, const Eigen::MatrixXd& move, vtkIdType& moved)
{
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->DeepCopy(lattice->GetPoints());
  for (std::size_t c = 0; c < controlPoints.size(); ++c)
  {
    double x[3];
    points->GetPoint(controlPoints[c], x);
    for (int a = 0; a < 3; ++a)
    {
      x[a] += move(Eigen::Index(c), a);
    }
    points->SetPoint(controlPoints[c], x);
    moved += move.row(Eigen::Index(c)).squaredNorm() > 0;
  }
  return points.Get();
}

/// The largest distance from a target to where its point goes: the fit's miss `missed` (T - F - W dP) for a
/// target inside the lattice, else the distance to where the lattice takes its point now (for every target where
/// `missed` is null).
double MaximumDistance(
  vtkPoints* positions, vtkPointSet* now, const std::vector<int>& cellOf, const Eigen::MatrixXd* missed)
{
  double maximum = 0;
  for (vtkIdType t = 0; t < now->GetNumberOfPoints(); ++t)
  {
    double target[3], at[3];
    positions->GetPoint(t, target);
    now->GetPoint(t, at);
    maximum = std::max(maximum,
      missed && cellOf[t] >= 0 ? missed->row(t).norm() : std::sqrt(vtkMath::Distance2BetweenPoints(target, at)));
  }
  return maximum;
}
} // namespace

//------------------------------------------------------------------------------------------------------------
vtkFFDDirectManipulation::vtkFFDDirectManipulation()
  : Regularization(0)
  , NumberOfMovedControlPoints(0)
  , MaximumTargetDistance(0)
{
  this->SetNumberOfInputPorts(2);
}

//------------------------------------------------------------------------------------------------------------
vtkFFDDirectManipulation::~vtkFFDDirectManipulation() = default;

//------------------------------------------------------------------------------------------------------------
void vtkFFDDirectManipulation::SetTargetPointIds(vtkIdTypeArray* ids)
{
  if (this->TargetPointIds != ids)
  {
    this->TargetPointIds = ids;
    this->Modified();
  }
}

//------------------------------------------------------------------------------------------------------------
vtkIdTypeArray* vtkFFDDirectManipulation::GetTargetPointIds()
{
  return this->TargetPointIds;
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDDirectManipulation::SetTargetPositions(vtkPoints* positions)
{
  if (this->TargetPositions != positions)
  {
    this->TargetPositions = positions;
    this->Modified();
  }
}

//------------------------------------------------------------------------------------------------------------
vtkPoints* vtkFFDDirectManipulation::GetTargetPositions()
{
  return this->TargetPositions;
}

//------------------------------------------------------------------------------------------------------------
vtkMTimeType vtkFFDDirectManipulation::GetMTime()
{
  vtkMTimeType time = this->Superclass::GetMTime();
  if (this->TargetPointIds)
  {
    time = std::max(time, this->TargetPointIds->GetMTime());
  }
  if (this->TargetPositions)
  {
    time = std::max(time, this->TargetPositions->GetMTime());
  }
  return time;
}

//------------------------------------------------------------------------------------------------------------
int vtkFFDDirectManipulation::FillInputPortInformation(int port, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkPointSet");
  if (port == 1)
  {
    info->Set(vtkAlgorithm::INPUT_IS_OPTIONAL(), 1); // needed only with targets; RequestData says so
  }
  return 1;
}

//------------------------------------------------------------------------------------------------------------
vtkTypeBool vtkFFDDirectManipulation::ProcessRequest(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  return vtkFFDCatchAllocationFailure(
    this, outputVector, [&] { return this->Superclass::ProcessRequest(request, inputVector, outputVector); });
}

//------------------------------------------------------------------------------------------------------------
int vtkFFDDirectManipulation::RequestDataObject(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  if (!(vtkFFDCheckInput(this, inputVector[0], 0, "vtkPointSet", "the lattice",
          "SetInputConnection() to the lattice to move, the output of vtkFFDBuildLattice or "
          "vtkFFDBuildTetrahedralLattice.") &&
        vtkFFDCheckInput(this, inputVector[1], 1, "vtkPointSet", "the mesh",
          "SetMeshConnection() to the mesh at rest that the lattice deforms.", true)))
  {
    return vtkFFDEmptyOutputs(outputVector);
  }
  return this->Superclass::RequestDataObject(request, inputVector, outputVector);
}

//------------------------------------------------------------------------------------------------------------
int vtkFFDDirectManipulation::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkPointSet* lattice = vtkPointSet::GetData(inputVector[0]);
  vtkPointSet* mesh = vtkPointSet::GetData(inputVector[1]);
  vtkPointSet* output = vtkPointSet::GetData(outputVector);
  this->NumberOfMovedControlPoints = 0;
  this->MaximumTargetDistance = 0;
  const vtkFFDStatisticsOnReturn statistics(output,
    [this](vtkDataObject* out)
    {
      vtkFFDRecordCount(out, "NumberOfMovedControlPoints", this->NumberOfMovedControlPoints);
      vtkFFDRecordValue(out, "MaximumTargetDistance", this->MaximumTargetDistance);
    });
  if (!lattice || lattice->GetNumberOfPoints() == 0)
  {
    return 1;
  }
  output->ShallowCopy(lattice);
  const vtkIdType count = this->TargetPointIds ? this->TargetPointIds->GetNumberOfValues() : 0;
  if (count == 0)
  {
    return 1; // nothing asked: the lattice as it is
  }
  auto fail = [output]
  {
    output->Initialize();
    return 0;
  };
  if (!CheckSettings(this, mesh, this->TargetPositions, count, this->Regularization))
  {
    return fail();
  }

  // The targets' rest points, where the lattice takes them now, and W: each target's weights.
  vtkNew<vtkPoints> rest;
  rest->SetDataTypeToDouble();
  const vtkSmartPointer<vtkPointSet> now =
    PlaceTargets(this, this->TargetPointIds, this->TargetPositions, mesh, lattice, rest);
  std::vector<Entry> entries;
  std::vector<int> cellOf;
  if (!now || !TargetWeights(this, lattice, rest, entries, cellOf))
  {
    return fail();
  }
  std::map<vtkIdType, Eigen::Index> column;
  const std::vector<vtkIdType> controlPoints = MovingControlPoints(entries, column);
  if (controlPoints.empty())
  {
    // No target inside: no control point can move them (and W would have no column to decompose).
    this->MaximumTargetDistance = MaximumDistance(this->TargetPositions, now, cellOf, nullptr);
    return 1;
  }
  std::ostringstream request;
  request << "Direct manipulation of " << count << " targets over " << controlPoints.size() << " control points";
  if (!vtkFFDCheckMemory(this, request.str(), 8.0 * double(count) * double(controlPoints.size() + count + 6)))
  {
    return fail();
  }

  const Eigen::MatrixXd w = WeightMatrix(entries, column, count);
  const Eigen::MatrixXd change = TargetChanges(this->TargetPositions, now, cellOf);
  const Eigen::MatrixXd move = SolveMove(w, change, this->Regularization);
  if (!move.allFinite())
  {
    vtkErrorMacro(<< "The solve failed with Regularization " << this->Regularization
                  << (this->Regularization > 0 ? ": give SetRegularization() a smaller number."
                                               : ": set a Regularization above 0."));
    return fail();
  }
  output->SetPoints(MovedPoints(lattice, controlPoints, move, this->NumberOfMovedControlPoints));
  const Eigen::MatrixXd missed = change - w * move;
  this->MaximumTargetDistance = MaximumDistance(this->TargetPositions, now, cellOf, &missed);
  return 1;
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDDirectManipulation::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "TargetPointIds: " << (this->TargetPointIds ? this->TargetPointIds->GetNumberOfValues() : 0)
     << " ids\n";
  os << indent << "Regularization: " << this->Regularization << "\n";
  os << indent << "NumberOfMovedControlPoints: " << this->NumberOfMovedControlPoints << "\n";
  os << indent << "MaximumTargetDistance: " << this->MaximumTargetDistance << "\n";
}
