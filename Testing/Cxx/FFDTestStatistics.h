// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDTestStatistics.h
 * @brief Checks a statistic that a filter recorded in its output's field data (Filters/Core/vtkFFDStatistics.h).
 */
#ifndef FFDTestStatistics_h
#define FFDTestStatistics_h

#include "vtkDataObject.h"
#include "vtkFieldData.h"
#include "vtkIdTypeArray.h"

#include <gtest/gtest.h>

/// Expects the field array `name` of `output` to be one vtkIdType equal to `expected`.
inline void ExpectRecordedCount(vtkDataObject* output, const char* name, vtkIdType expected)
{
  vtkIdTypeArray* array = vtkIdTypeArray::SafeDownCast(output->GetFieldData()->GetAbstractArray(name));
  ASSERT_NE(array, nullptr) << name;
  ASSERT_EQ(array->GetNumberOfValues(), 1) << name;
  EXPECT_EQ(array->GetValue(0), expected) << name;
}

#endif
