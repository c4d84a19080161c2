// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDDeformExecutive.h"

#include "vtkDataObject.h"
#include "vtkFFDDeform.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkObjectFactory.h"

vtkStandardNewMacro(vtkFFDDeformExecutive);

int vtkFFDDeformExecutive::NeedToExecuteData(
  int outputPort, vtkInformationVector** inInfoVec, vtkInformationVector* outInfoVec)
{
  if (this->Superclass::NeedToExecuteData(outputPort, inInfoVec, outInfoVec))
  {
    return 1;
  }
  vtkInformation* outInfo = outInfoVec->GetInformationObject(outputPort < 0 ? 0 : outputPort);
  vtkDataObject* output = outInfo ? outInfo->Get(vtkDataObject::DATA_OBJECT()) : nullptr;
  const bool onDevice = output && output->GetInformation()->Has(vtkFFDDeform::DEVICE_OUTPUT());
  return onDevice && !outInfo->Get(vtkFFDDeform::KEEP_OUTPUT_ON_DEVICE()) ? 1 : 0;
}
