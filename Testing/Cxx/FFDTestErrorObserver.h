// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDTestErrorObserver.h
 * @brief Captures the error and warning events of a VTK object, so that tests can assert on the message
 * (and the test log stays free of expected errors).
 */
#ifndef FFDTestErrorObserver_h
#define FFDTestErrorObserver_h

#include "vtkAlgorithm.h"
#include "vtkCommand.h"
#include "vtkExecutive.h"
#include "vtkObject.h"

#include <string>

class FFDTestErrorObserver : public vtkCommand
{
public:
  static FFDTestErrorObserver* New() { return new FFDTestErrorObserver; }

  /// Observes errors and warnings of object.
  void Watch(vtkObject* object)
  {
    object->AddObserver(vtkCommand::ErrorEvent, this);
    object->AddObserver(vtkCommand::WarningEvent, this);
  }

  /// Observes errors and warnings of an algorithm and of its executive (which reports a failed request too).
  void WatchWithExecutive(vtkAlgorithm* algorithm)
  {
    this->Watch(algorithm);
    this->Watch(algorithm->GetExecutive());
  }

  void Execute(vtkObject*, unsigned long event, void* callData) override
  {
    std::string& target = event == vtkCommand::ErrorEvent ? this->Errors : this->Warnings;
    target += callData ? static_cast<const char*>(callData) : "(no message)";
    target += "\n";
  }

  std::string Errors;
  std::string Warnings;
};

#endif
