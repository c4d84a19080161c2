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

#include <string>

class vtkDataObject;

/// Records a count, a real number or a word as the field array `name` of `output`, replacing one of that name.
void vtkFFDRecordCount(vtkDataObject* output, const char* name, vtkIdType value);
void vtkFFDRecordValue(vtkDataObject* output, const char* name, double value);
void vtkFFDRecordText(vtkDataObject* output, const char* name, const std::string& value);

#endif
