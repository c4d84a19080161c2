// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file vtkFFDStatistics.h
 * @brief A filter's statistics of its last execution, recorded in its output's field data (private).
 *
 * Each statistic that a filter's getter returns (vtkFFDVoxelize::GetNumberOfActiveVoxels(),
 * vtkFFDDeform::GetLastBackendUsed(), ...) is also a one-value field array of its output, named as the getter
 * without "Get". ParaView reads a proxy's information properties before RequestData computes them, so its
 * Information panel and paraview.simple (`FFDVoxelize(...).FieldData['NumberOfActiveVoxels']`) show them from
 * the output instead; under MPI every process records the same values.
 */
#ifndef vtkFFDStatistics_h
#define vtkFFDStatistics_h

#include "vtkType.h"

#include <new>
#include <string>
#include <utility>

class vtkDataObject;

/// Records a count, a real number or a word as the field array `name` of `output`, replacing one of that name.
void vtkFFDRecordCount(vtkDataObject* output, const char* name, vtkIdType value);
void vtkFFDRecordValue(vtkDataObject* output, const char* name, double value);
void vtkFFDRecordText(vtkDataObject* output, const char* name, const std::string& value);

/**
 * Records a filter's statistics in its output when RequestData returns, whichever way it returns (an empty input,
 * an error, the end): made at the top of RequestData with a function that records them,
 *   const vtkFFDStatisticsOnReturn statistics(output, [this](vtkDataObject* out) { vtkFFDRecordCount(...); });
 */
template <typename Record>
class vtkFFDStatisticsOnReturn
{
public:
  vtkFFDStatisticsOnReturn(vtkDataObject* output, Record record)
    : Output(output)
    , RecordStatistics(std::move(record))
  {
  }
  ~vtkFFDStatisticsOnReturn()
  {
    try
    {
      if (this->Output)
      {
        this->RecordStatistics(this->Output);
      }
    }
    catch (const std::bad_alloc&)
    {
      // Out of memory already (RequestData is unwinding from it): the statistics are lost, not the process.
    }
  }
  vtkFFDStatisticsOnReturn(const vtkFFDStatisticsOnReturn&) = delete;
  void operator=(const vtkFFDStatisticsOnReturn&) = delete;

private:
  vtkDataObject* Output;
  Record RecordStatistics;
};

#endif
