// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDControlPoints.h"

#include "vtkCellArray.h"
#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkFFDDataContract.h"
#include "vtkIdTypeArray.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"

#include <cmath>

vtkStandardNewMacro(vtkFFDControlPoints);

//------------------------------------------------------------------------------
const char* vtkFFDControlPoints::GetSelectionAsString()
{
  switch (this->Selection)
  {
    case ACTIVE:
      return "Active";
    case CULLED:
      return "Culled";
    default:
      return "All";
  }
}

//------------------------------------------------------------------------------
int vtkFFDControlPoints::FillInputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkPointSet");
  return 1;
}

//------------------------------------------------------------------------------
int vtkFFDControlPoints::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkPointSet* lattice = vtkPointSet::GetData(inputVector[0]);
  vtkPolyData* output = vtkPolyData::GetData(outputVector);
  if (!lattice || !output)
  {
    vtkErrorMacro("Expected a vtkPointSet lattice (e.g. vtkFFDBuildLattice's output) on input 0.");
    return 0;
  }
  const vtkIdType n = lattice->GetNumberOfPoints();
  if (n == 0)
  {
    return 1; // an empty lattice gives an empty output, as the filters do
  }

  vtkPointData* pd = lattice->GetPointData();
  vtkDataArray* active = pd->GetArray(vtkFFDDataContract::ActiveArrayName());
  if (active && (active->GetNumberOfComponents() != 1 || active->GetNumberOfTuples() != n))
  {
    vtkErrorMacro("The lattice's `" << vtkFFDDataContract::ActiveArrayName() << "` array has "
                                    << active->GetNumberOfComponents() << " components and "
                                    << active->GetNumberOfTuples() << " tuples; the data contract asks for one "
                                    << "component per control point (" << n << ").");
    return 0;
  }
  vtkDataArray* rest = pd->GetArray(vtkFFDDataContract::RestPositionArrayName());
  if (rest && (rest->GetNumberOfComponents() != 3 || rest->GetNumberOfTuples() != n))
  {
    vtkErrorMacro("The lattice's `" << vtkFFDDataContract::RestPositionArrayName() << "` array has "
                                    << rest->GetNumberOfComponents() << " components and " << rest->GetNumberOfTuples()
                                    << " tuples; the data contract asks for "
                                    << "three components per control point (" << n << ").");
    return 0;
  }

  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  vtkNew<vtkIdTypeArray> ids;
  ids->SetName(LatticePointIdArrayName());
  vtkNew<vtkDoubleArray> lengths;
  lengths->SetName(DisplacementLengthArrayName());
  // Lattices have thousands of points, not millions: a serial loop keeps the order of the lattice.
  for (vtkIdType id = 0; id < n; ++id)
  {
    const bool isActive = !active || active->GetComponent(id, 0) != 0.0;
    if ((this->Selection == ACTIVE && !isActive) || (this->Selection == CULLED && isActive))
    {
      continue;
    }
    double x[3];
    lattice->GetPoint(id, x);
    double length = 0.0;
    if (rest)
    {
      double r[3];
      rest->GetTuple(id, r);
      length = std::sqrt((x[0] - r[0]) * (x[0] - r[0]) + (x[1] - r[1]) * (x[1] - r[1]) + (x[2] - r[2]) * (x[2] - r[2]));
    }
    points->InsertNextPoint(x);
    ids->InsertNextValue(id);
    lengths->InsertNextValue(length);
  }

  vtkNew<vtkCellArray> vertices;
  const vtkIdType kept = points->GetNumberOfPoints();
  for (vtkIdType p = 0; p < kept; ++p)
  {
    vertices->InsertNextCell(1, &p);
  }
  output->SetPoints(points);
  output->SetVerts(vertices);
  output->GetPointData()->AddArray(ids);
  output->GetPointData()->SetScalars(lengths);
  return 1;
}

//------------------------------------------------------------------------------
void vtkFFDControlPoints::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Selection: " << this->GetSelectionAsString() << "\n";
}
