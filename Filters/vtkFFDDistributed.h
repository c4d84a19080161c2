// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file vtkFFDDistributed.h
 * @brief What the filters that build a lattice from a mesh split among processes (MPI) share: every process
 * gets the same numbers, bit for bit those one process computes from the whole mesh (private to the Filters
 * module).
 *
 * Each function is collective: every process of `controller` calls it, in the same order. With a null
 * controller or a single process, each returns its input as it is.
 */
#ifndef vtkFFDDistributed_h
#define vtkFFDDistributed_h

#include "vtkType.h"

#include "FFDExactSum.h"

#include <vector>

class vtkMultiProcessController;

/// Whether `controller` spreads the input over more than one process.
bool vtkFFDIsDistributed(vtkMultiProcessController* controller);

/// Each sum becomes the sum over every process (its partials added to every other process's: exact).
void vtkFFDSumOverProcesses(vtkMultiProcessController* controller, std::vector<ffd::ExactSum>& sums);

/// `count` summed, `low` and `high` (3 each) reduced by min and max over every process.
void vtkFFDBoundsOverProcesses(vtkMultiProcessController* controller, vtkIdType& count, double low[3], double high[3]);

/// The union over every process of each one's increasing `values`, increasing, each once.
std::vector<vtkTypeInt64> vtkFFDUnionOverProcesses(
  vtkMultiProcessController* controller, const std::vector<vtkTypeInt64>& values);

/// Every process's `values` put together, in process order.
std::vector<double> vtkFFDGatherOverProcesses(vtkMultiProcessController* controller, const std::vector<double>& values);

/// Each of the `count` flags becomes 1 where it is not 0 on some process.
void vtkFFDAnyOverProcesses(vtkMultiProcessController* controller, unsigned char* flags, vtkIdType count);

#endif
