// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDTestInputChecks.h
 * @brief What a filter says when an input is missing or of the wrong type (issue 30, item 17: before, only the
 * executive's "returned failure for request" and the request's dump).
 */
#ifndef FFDTestInputChecks_h
#define FFDTestInputChecks_h

#include "FFDTestErrorObserver.h"

#include "vtkAlgorithm.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPointSet.h"

#include <gtest/gtest.h>

#include <string>

namespace ffdtest
{
/// The errors of one Update() of `algorithm`, its own and its executive's.
inline std::string UpdateErrors(vtkAlgorithm* algorithm)
{
  vtkNew<FFDTestErrorObserver> errors;
  errors->WatchWithExecutive(algorithm);
  algorithm->Update();
  for (vtkObject* watched : { static_cast<vtkObject*>(algorithm), static_cast<vtkObject*>(algorithm->GetExecutive()) })
  {
    watched->RemoveObservers(vtkCommand::ErrorEvent, errors);
    watched->RemoveObservers(vtkCommand::WarningEvent, errors);
  }
  return errors->Errors;
}

/**
 * With input `port` of `algorithm` disconnected, then given a vtkImageData, Update() says "Input <port> (<role>)
 * is missing: <connect>" and "... must be a vtkPointSet; it is a vtkImageData: <connect>", where <connect>
 * begins with `connect`, and leaves no output points. The algorithm's other inputs are connected by the caller;
 * it is first updated as it is, which must succeed (so that an earlier output is there to be emptied).
 */
inline void ExpectClearInputErrors(
  vtkAlgorithm* algorithm, int port, const std::string& role, const std::string& connect, bool optional = false)
{
  EXPECT_EQ(UpdateErrors(algorithm), "") << "connected as the caller left it";
  auto outputPoints = [&]
  {
    vtkPointSet* output = vtkPointSet::SafeDownCast(algorithm->GetOutputDataObject(0));
    return output ? output->GetNumberOfPoints() : 0;
  };
  const std::string input = "Input " + std::to_string(port) + " (" + role + ")";
  vtkSmartPointer<vtkDataObject> kept = algorithm->GetInputDataObject(port, 0);
  if (!optional)
  {
    algorithm->SetInputDataObject(port, nullptr);
    const std::string errors = UpdateErrors(algorithm);
    EXPECT_NE(errors.find(input + " is missing: " + connect), std::string::npos) << errors;
    EXPECT_EQ(outputPoints(), 0) << "missing " << input;
  }
  algorithm->SetInputDataObject(port, kept);
  EXPECT_EQ(UpdateErrors(algorithm), "") << "reconnected";
  vtkNew<vtkImageData> image;
  image->SetDimensions(2, 2, 2);
  algorithm->SetInputDataObject(port, image);
  const std::string errors = UpdateErrors(algorithm);
  EXPECT_NE(errors.find(input + " must be a vtkPointSet; it is a vtkImageData: " + connect), std::string::npos)
    << errors;
  EXPECT_EQ(outputPoints(), 0) << "wrong type on " << input;
  algorithm->SetInputDataObject(port, kept);
}
} // namespace ffdtest

#endif
