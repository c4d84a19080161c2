// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDBindingKey.h"

#include "vtkFFDDeform.h"
#include "vtkPoints.h"

#include <algorithm>

//------------------------------------------------------------------------------------------------------------
vtkFFDBindingKey vtkFFDBindingKey::Of(vtkPoints* points, int outsidePolicy)
{
  vtkFFDBindingKey key;
  key.Points = points;
  key.PointsMTime = points->GetMTime();
  key.NumberOfPoints = points->GetNumberOfPoints();
  key.OutsidePolicy = outsidePolicy;
  return key;
}

//------------------------------------------------------------------------------------------------------------
vtkFFDBindingKey vtkFFDBindingKey::OfGrid(vtkPoints* points, int outsidePolicy, const double frame[12],
  const int divisions[3], int basis, std::uint64_t sparseCells)
{
  vtkFFDBindingKey key = Of(points, outsidePolicy);
  std::copy(frame, frame + 12, key.Frame.begin());
  std::copy(divisions, divisions + 3, key.Divisions.begin());
  key.Basis = basis;
  key.SparseCells = sparseCells;
  return key;
}

//------------------------------------------------------------------------------------------------------------
bool vtkFFDBindingKey::ClampsOutside() const
{
  return this->OutsidePolicy == vtkFFDDeform::CLAMP_TO_EDGE;
}

//------------------------------------------------------------------------------------------------------------
bool vtkFFDBindingKey::operator==(const vtkFFDBindingKey& other) const
{
  return this->Points == other.Points && this->PointsMTime == other.PointsMTime &&
    this->NumberOfPoints == other.NumberOfPoints && this->OutsidePolicy == other.OutsidePolicy &&
    this->Frame == other.Frame && this->Divisions == other.Divisions && this->Basis == other.Basis &&
    this->SparseCells == other.SparseCells;
}
