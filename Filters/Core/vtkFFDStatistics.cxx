// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDStatistics.h"

#include "vtkDataObject.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkIdTypeArray.h"
#include "vtkNew.h"
#include "vtkStringArray.h"

namespace
{
template <typename ArrayT, typename ValueT>
void Record(vtkDataObject* output, const char* name, const ValueT& value)
{
  vtkNew<ArrayT> array;
  array->SetName(name);
  array->InsertNextValue(value);
  output->GetFieldData()->AddArray(array); // replaces an array of the same name
}
} // namespace

void vtkFFDRecordCount(vtkDataObject* output, const char* name, vtkIdType value)
{
  Record<vtkIdTypeArray>(output, name, value);
}

void vtkFFDRecordValue(vtkDataObject* output, const char* name, double value)
{
  Record<vtkDoubleArray>(output, name, value);
}

void vtkFFDRecordText(vtkDataObject* output, const char* name, const std::string& value)
{
  Record<vtkStringArray>(output, name, value);
}
