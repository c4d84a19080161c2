// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file vtkFFDInputChecks.h
 * @brief One clear error for an input that is missing or of the wrong type (private to the Filters module).
 *
 * A vtkPointSetAlgorithm makes its output in RequestDataObject(), the pipeline's first request, as a copy of input
 * 0's type: where that input is missing or is not a vtkPointSet it fails without a word, and the executive says
 * only that the algorithm "returned failure for request", followed by the request's dump. The filters'
 * RequestDataObject() overrides check their inputs first with vtkFFDCheckInput(), so that the error names the
 * input, says what it is, and what to connect instead.
 */
#ifndef vtkFFDInputChecks_h
#define vtkFFDInputChecks_h

#include "vtkAlgorithm.h"
#include "vtkDataObject.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkSetGet.h"

#include <string>

/**
 * True where every connection of input `port` of `self` (`inputs`, that port's information vector) holds a
 * `type` (a class name, e.g. "vtkPointSet"), and where it has none but is `optional`. Otherwise reports on `self`
 * which input is wrong (`port` and `role`, e.g. "the mesh"), what it holds, and `connect`, what to do (e.g.
 * "SetInputConnection() to the mesh to deform."), and returns false.
 */
inline bool vtkFFDCheckInput(vtkAlgorithm* self, vtkInformationVector* inputs, int port, const char* type,
  const char* role, const char* connect, bool optional = false)
{
  const int count = inputs ? inputs->GetNumberOfInformationObjects() : 0;
  if (count == 0 && !optional)
  {
    vtkErrorWithObjectMacro(self, << "Input " << port << " (" << role << ") is missing: " << connect);
    return false;
  }
  for (int c = 0; c < count; ++c)
  {
    vtkDataObject* data = inputs->GetInformationObject(c)->Get(vtkDataObject::DATA_OBJECT());
    if (!data || !data->IsA(type))
    {
      vtkErrorWithObjectMacro(self, << "Input " << port << " (" << role << ")"
                                    << (count > 1 ? ", connection " + std::to_string(c) + "," : std::string())
                                    << " must be a " << type << "; it is "
                                    << (data ? std::string("a ") + data->GetClassName() : std::string("empty")) << ": "
                                    << connect);
      return false;
    }
  }
  return true;
}

/// Empties every output (an earlier update's stays otherwise, as if it were this one's) and returns 0: what a
/// RequestDataObject() override returns after a failed vtkFFDCheckInput().
inline int vtkFFDEmptyOutputs(vtkInformationVector* outputs)
{
  for (int i = 0; outputs && i < outputs->GetNumberOfInformationObjects(); ++i)
  {
    if (vtkDataObject* output = vtkDataObject::GetData(outputs, i))
    {
      output->Initialize();
    }
  }
  return 0;
}

#endif
