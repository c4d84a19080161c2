// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDMeshInversion.h"

#include "vtkFFDForInChunks.h"
#include "vtkFFDInputChecks.h"
#include "vtkFFDMemory.h"

#include "vtkCellData.h"
#include "vtkCellType.h"
#include "vtkDataArrayRange.h"
#include "vtkDoubleArray.h"
#include "vtkIdList.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkSMPThreadLocal.h"
#include "vtkSMPThreadLocalObject.h"
#include "vtkUnsignedCharArray.h"

#include "FFDCellJacobian.h"

#include <algorithm>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkFFDMeshInversion);

namespace
{
// The points of a data set as float64, 3 a point.
std::vector<double> PointsAsDoubles(vtkPointSet* mesh)
{
  std::vector<double> values(3 * static_cast<std::size_t>(mesh->GetNumberOfPoints()));
  if (mesh->GetPoints())
  {
    const auto range = vtk::DataArrayValueRange<3>(mesh->GetPoints()->GetData());
    std::copy(range.begin(), range.end(), values.begin());
  }
  return values;
}

// The kernel's cell of a VTK cell type and the order to read its nodes in (a voxel's as a hexahedron's); false for
// any other type.
bool VolumeCellOf(int vtkType, ffd::VolumeCell& type, const int*& order)
{
  static const int identity[8] = { 0, 1, 2, 3, 4, 5, 6, 7 };
  static const int voxel[8] = { 0, 1, 3, 2, 4, 5, 7, 6 };
  order = vtkType == VTK_VOXEL ? voxel : identity;
  switch (vtkType)
  {
    case VTK_TETRA:
      type = ffd::VolumeCell::Tetrahedron;
      return true;
    case VTK_HEXAHEDRON:
    case VTK_VOXEL:
      type = ffd::VolumeCell::Hexahedron;
      return true;
    case VTK_WEDGE:
      type = ffd::VolumeCell::Wedge;
      return true;
    case VTK_PYRAMID:
      type = ffd::VolumeCell::Pyramid;
      return true;
    default:
      return false;
  }
}

// The first cell (lowest id) that cannot be measured, and why.
struct Problem
{
  vtkIdType Cell = VTK_ID_MAX;
  std::string What;
};

// Each cell's state and scaled Jacobian; the lowest-id problem per thread.
struct CellMeasure
{
  vtkPointSet* Deformed;
  vtkPointSet* Rest;
  const std::vector<double>& DeformedPoints;
  const std::vector<double>& RestPoints;
  vtkUnsignedCharArray* States;
  vtkDoubleArray* Scaled;
  vtkSMPThreadLocalObject<vtkIdList> Ids, RestIds;
  vtkSMPThreadLocal<Problem> Problems;

  // The problem of cell c, if any: what is wrong with it.
  std::string Check(vtkIdType c, int type, int restType, vtkIdList* ids, vtkIdList* restIds)
  {
    ffd::VolumeCell kind;
    const int* order;
    if (!VolumeCellOf(type, kind, order))
    {
      return "is of VTK cell type " + std::to_string(type) +
        ", not a linear volume cell (VTK_TETRA, VTK_HEXAHEDRON, VTK_VOXEL, VTK_WEDGE or VTK_PYRAMID)";
    }
    if (restType != type || ids->GetNumberOfIds() != restIds->GetNumberOfIds() ||
      !std::equal(ids->begin(), ids->end(), restIds->begin()))
    {
      return "differs between the deformed mesh and the mesh at rest (type or points)";
    }
    return ids->GetNumberOfIds() == ffd::NodesOf(kind) ? std::string()
                                                       : "has " + std::to_string(ids->GetNumberOfIds()) + " points";
  }

  void operator()(vtkIdType begin, vtkIdType end)
  {
    vtkIdList* ids = this->Ids.Local();
    vtkIdList* restIds = this->RestIds.Local();
    Problem& problem = this->Problems.Local();
    for (vtkIdType c = begin; c < end; ++c)
    {
      this->Deformed->GetCellPoints(c, ids);
      this->Rest->GetCellPoints(c, restIds);
      const int type = this->Deformed->GetCellType(c);
      std::string what = this->Check(c, type, this->Rest->GetCellType(c), ids, restIds);
      if (!what.empty())
      {
        if (c < problem.Cell)
        {
          problem = { c, std::move(what) };
        }
        continue;
      }
      this->Measure(c, type, ids);
    }
  }

  // The state and scaled Jacobian of a checked cell.
  void Measure(vtkIdType c, int type, vtkIdList* ids)
  {
    ffd::VolumeCell kind;
    const int* order;
    VolumeCellOf(type, kind, order);
    ffd::Vec3<double> rest[8], moved[8];
    for (int n = 0; n < ffd::NodesOf(kind); ++n)
    {
      const std::size_t id = static_cast<std::size_t>(ids->GetId(order[n]));
      rest[n] = ffd::Vec3<double>::From(this->RestPoints.data() + 3 * id);
      moved[n] = ffd::Vec3<double>::From(this->DeformedPoints.data() + 3 * id);
    }
    double det[ffd::MaxCellJacobians], scaled[ffd::MaxCellJacobians];
    double restDet[ffd::MaxCellJacobians], restScaled[ffd::MaxCellJacobians];
    const int count = ffd::CellJacobians(kind, moved, det, scaled);
    ffd::CellJacobians(kind, rest, restDet, restScaled);
    const bool positive = std::all_of(restDet, restDet + count, [](double d) { return d > 0.0; });
    const bool negative = std::all_of(restDet, restDet + count, [](double d) { return d < 0.0; });
    const double sign = negative ? -1.0 : 1.0;
    bool inverted = false;
    double smallest = VTK_DOUBLE_MAX;
    for (int j = 0; j < count; ++j)
    {
      inverted = inverted || !(sign * det[j] > 0.0);
      smallest = std::min(smallest, sign * scaled[j]);
    }
    this->States->SetValue(c,
      !(positive || negative) ? vtkFFDMeshInversion::INVALID_AT_REST
                              : (inverted ? vtkFFDMeshInversion::INVERTED : vtkFFDMeshInversion::VALID));
    this->Scaled->SetValue(c, smallest);
  }
};
} // namespace

//------------------------------------------------------------------------------------------------------------
vtkFFDMeshInversion::vtkFFDMeshInversion()
{
  this->SetNumberOfInputPorts(2);
}

int vtkFFDMeshInversion::FillInputPortInformation(int port, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkPointSet");
  return port <= 1 ? 1 : 0;
}

vtkTypeBool vtkFFDMeshInversion::ProcessRequest(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  return vtkFFDCatchAllocationFailure(
    this, outputVector, [&] { return this->Superclass::ProcessRequest(request, inputVector, outputVector); });
}

// The output is the deformed mesh: of input 0's type.
int vtkFFDMeshInversion::RequestDataObject(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  if (!(vtkFFDCheckInput(this, inputVector[0], 0, "vtkPointSet", "the deformed mesh",
          "SetInputConnection() to the deformed volume mesh (vtkFFDDeform's output).") &&
        vtkFFDCheckInput(this, inputVector[1], 1, "vtkPointSet", "the mesh at rest",
          "SetRestMeshConnection() to the same mesh at rest (vtkFFDDeform's input 0).")))
  {
    return vtkFFDEmptyOutputs(outputVector);
  }
  vtkDataObject* mesh = vtkDataObject::GetData(inputVector[0]);
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  vtkDataObject* output = outInfo->Get(vtkDataObject::DATA_OBJECT());
  if (!output || !output->IsA(mesh->GetClassName()))
  {
    outInfo->Set(vtkDataObject::DATA_OBJECT(), vtk::TakeSmartPointer(mesh->NewInstance()));
  }
  return 1;
}

//------------------------------------------------------------------------------------------------------------
int vtkFFDMeshInversion::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkPointSet* deformed = vtkPointSet::GetData(inputVector[0]);
  vtkPointSet* rest = vtkPointSet::GetData(inputVector[1]);
  vtkPointSet* output = vtkPointSet::GetData(outputVector);
  this->NumberOfInvertedCells = this->NumberOfInvalidRestCells = 0;
  this->MinimumScaledJacobian = 1.0;
  if (!deformed || !rest || !output)
  {
    vtkErrorMacro("Input 0 (the deformed mesh) and input 1 (the mesh at rest) must be vtkPointSets.");
    return 0;
  }
  output->ShallowCopy(deformed);
  const vtkIdType cells = deformed->GetNumberOfCells();
  if (deformed->GetNumberOfPoints() != rest->GetNumberOfPoints() || cells != rest->GetNumberOfCells())
  {
    vtkErrorMacro("The deformed mesh has " << deformed->GetNumberOfPoints() << " points and " << cells
                                           << " cells, the mesh at rest " << rest->GetNumberOfPoints() << " and "
                                           << rest->GetNumberOfCells() << ": they must be one mesh.");
    output->Initialize();
    return 0;
  }
  if (cells == 0)
  {
    return 1;
  }
  deformed->GetCellType(0); // builds a vtkPolyData's cells here, not in the threads below
  rest->GetCellType(0);
  vtkNew<vtkUnsignedCharArray> states;
  states->SetName("Inverted");
  states->SetNumberOfValues(cells);
  vtkNew<vtkDoubleArray> scaled;
  scaled->SetName("ScaledJacobian");
  scaled->SetNumberOfValues(cells);
  const std::vector<double> deformedPoints = PointsAsDoubles(deformed), restPoints = PointsAsDoubles(rest);
  CellMeasure measure{ deformed, rest, deformedPoints, restPoints, states, scaled, {}, {}, {} };
  if (!vtkFFDForInChunks(this, cells, vtkFFDGrain(cells, 64.0), measure, 0.0, 0.95))
  {
    output->Initialize();
    return 1; // aborted
  }
  Problem first;
  for (const Problem& problem : measure.Problems)
  {
    first = problem.Cell < first.Cell ? problem : first;
  }
  if (first.Cell != VTK_ID_MAX)
  {
    vtkErrorMacro("Cell " << first.Cell << " " << first.What << ".");
    output->Initialize();
    return 0;
  }
  double smallest = VTK_DOUBLE_MAX; // a pyramid's may exceed 1
  for (vtkIdType c = 0; c < cells; ++c)
  {
    const unsigned char state = states->GetValue(c);
    this->NumberOfInvertedCells += state == INVERTED ? 1 : 0;
    this->NumberOfInvalidRestCells += state == INVALID_AT_REST ? 1 : 0;
    smallest = state != INVALID_AT_REST ? std::min(smallest, scaled->GetValue(c)) : smallest;
  }
  this->MinimumScaledJacobian = smallest < VTK_DOUBLE_MAX ? smallest : 1.0;
  output->GetCellData()->AddArray(states);
  output->GetCellData()->AddArray(scaled);
  this->UpdateProgress(1.0);
  return 1;
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDMeshInversion::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "NumberOfInvertedCells: " << this->NumberOfInvertedCells << "\n";
  os << indent << "NumberOfInvalidRestCells: " << this->NumberOfInvalidRestCells << "\n";
  os << indent << "MinimumScaledJacobian: " << this->MinimumScaledJacobian << "\n";
}
