// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDDataContract.h"

#include "vtkDataObject.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkIntArray.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"

#include <algorithm>
#include <cmath>

vtkStandardNewMacro(vtkFFDDataContract);

namespace
{
// The field array `name` when it exists with exactly `count` values of type ArrayT.
template <typename ArrayT>
ArrayT* FindFieldArray(vtkDataObject* data, const char* name, vtkIdType count)
{
  vtkFieldData* fd = data ? data->GetFieldData() : nullptr;
  ArrayT* array = fd ? ArrayT::SafeDownCast(fd->GetAbstractArray(name)) : nullptr;
  if (!array || array->GetNumberOfValues() != count)
  {
    return nullptr;
  }
  return array;
}

template <typename ArrayT, typename ValueT>
void SetFieldArray(vtkDataObject* data, const char* name, const ValueT* values, int count)
{
  // Static methods have no object to report through: VTK's output window shows the error (Python: None passed).
  if (!data || !values)
  {
    vtkErrorWithObjectMacro(nullptr,
      "vtkFFDDataContract cannot set " << name << ": " << (!data ? "the data object" : "the values")
                                       << " is null. Pass a data object and " << count << " values.");
    return;
  }
  vtkNew<ArrayT> array;
  array->SetName(name);
  array->SetNumberOfValues(count);
  for (int c = 0; c < count; ++c)
  {
    array->SetValue(c, values[c]);
  }
  data->GetFieldData()->AddArray(array); // replaces an array of the same name
}
} // namespace

bool vtkFFDDataContract::GetFrame(vtkDataObject* data, double frame[12])
{
  vtkDoubleArray* array = FindFieldArray<vtkDoubleArray>(data, FrameArrayName(), 12);
  if (!array)
  {
    return false;
  }
  if (!frame)
  {
    vtkErrorWithObjectMacro(nullptr, "vtkFFDDataContract::GetFrame(): the output array is null; pass 12 doubles.");
    return false;
  }
  double values[12];
  for (int c = 0; c < 12; ++c)
  {
    values[c] = array->GetValue(c);
    if (!std::isfinite(values[c]))
    {
      return false;
    }
  }
  std::copy(values, values + 12, frame);
  return true;
}

void vtkFFDDataContract::SetFrame(vtkDataObject* data, const double frame[12])
{
  SetFieldArray<vtkDoubleArray>(data, FrameArrayName(), frame, 12);
}

bool vtkFFDDataContract::GetDivisions(vtkDataObject* data, int divisions[3])
{
  vtkIntArray* array = FindFieldArray<vtkIntArray>(data, DivisionsArrayName(), 3);
  if (!array || array->GetValue(0) < 1 || array->GetValue(1) < 1 || array->GetValue(2) < 1)
  {
    return false;
  }
  if (!divisions)
  {
    vtkErrorWithObjectMacro(nullptr, "vtkFFDDataContract::GetDivisions(): the output array is null; pass 3 ints.");
    return false;
  }
  for (int c = 0; c < 3; ++c)
  {
    divisions[c] = array->GetValue(c);
  }
  return true;
}

void vtkFFDDataContract::SetDivisions(vtkDataObject* data, const int divisions[3])
{
  SetFieldArray<vtkIntArray>(data, DivisionsArrayName(), divisions, 3);
}

bool vtkFFDDataContract::GetBasis(vtkDataObject* data, int& basis)
{
  vtkIntArray* array = FindFieldArray<vtkIntArray>(data, BasisArrayName(), 1);
  if (!array)
  {
    return false;
  }
  basis = array->GetValue(0);
  return true;
}

void vtkFFDDataContract::SetBasis(vtkDataObject* data, int basis)
{
  SetFieldArray<vtkIntArray>(data, BasisArrayName(), &basis, 1);
}

void vtkFFDDataContract::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
}
