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

#include "vtkSmartPointer.h"
#include "vtkType.h"

#include "FFDExactSum.h"

#include <vector>

class vtkDataArray;
class vtkInformationVector;
class vtkMultiProcessController;
class vtkPointSet;

/// The points of `input` that count in sums over processes (an empty array for an empty piece): all of them,
/// or, where its ghost array marks some as copies of another process's (DUPLICATEPOINT, as vtkGenerateGlobalIds
/// marks the points that pieces share), a copy without those, so that each point of a mesh split among processes
/// counts once.
vtkSmartPointer<vtkDataArray> vtkFFDOwnedPoints(vtkPointSet* input);

/// The update request of the filters whose output is the same on every process, built from every process's
/// piece: with several processes, each asks its input for its own piece (without ghost levels), whatever was
/// asked of the output (a lattice asks for all of it). False where `controller` is not distributed: the
/// caller's superclass then passes the request on as usual.
bool vtkFFDRequestOwnPiece(vtkMultiProcessController* controller, vtkInformationVector** inputVector);

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
