// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file vtkFFDFlatIndex.h
 * @brief The flat index of a voxel or control point in its grid (private to the Filters module).
 */
#ifndef vtkFFDFlatIndex_h
#define vtkFFDFlatIndex_h

#include "vtkType.h"

/// The flat index i + dims[0] (j + dims[1] k) of a voxel or control point of a grid of `dims` (VTK's structured
/// order): the sparse sets' key, an int64 since grids of 1024^3 and beyond overflow an int.
template <typename DimT>
inline vtkTypeInt64 vtkFFDFlatIndex(vtkTypeInt64 i, vtkTypeInt64 j, vtkTypeInt64 k, const DimT dims[3])
{
  return i + vtkTypeInt64(dims[0]) * (j + vtkTypeInt64(dims[1]) * k);
}

#endif
