// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDGridWeights.h"

#include "vtkFFDGridDeformer.h"
#include "vtkPoints.h"

#include "FFDGridDeformation.h"

//------------------------------------------------------------------------------------------------------------
void vtkFFDForEachGridWeight(const vtkFFDGridDeformer& deformer, vtkPoints* points, vtkIdType begin, vtkIdType end,
  const std::function<void(vtkIdType, vtkIdType, double)>& add)
{
  const std::vector<int>& cellOf = deformer.GetCellOfPoint();
  const vtkFFDGridLattice& view = deformer.GetLattice();
  const vtkFFDSparseCells* cells = deformer.GetSparseCells();
  ffd::WithStaticBasis(view.Basis,
    [&](auto maxCount, auto)
    {
      const ffd::GridDeformation<decltype(maxCount)::value, double> deformation{ view.Basis,
        { view.Divisions[0], view.Divisions[1], view.Divisions[2] },
        { view.ControlPointsPerAxis[0], view.ControlPointsPerAxis[1], view.ControlPointsPerAxis[2] },
        view.Displacements.data(), ffd::Frame<double>::FromArray(view.Frame), nullptr,
        cells ? cells->GetVoxels().data() : nullptr, cells ? cells->GetSupports().data() : nullptr };
      for (vtkIdType p = begin; p < end; ++p)
      {
        if (cellOf[p] >= 0)
        {
          double x[3];
          points->GetPoint(p, x);
          deformation.ForEachWeight(
            { x[0], x[1], x[2] }, cellOf[p], [&](int controlPoint, double weight) { add(p, controlPoint, weight); });
        }
      }
    });
}

//------------------------------------------------------------------------------------------------------------
int vtkFFDGridWeightsPerPoint(const vtkFFDGridDeformer& deformer)
{
  const vtkFFDGridLattice& view = deformer.GetLattice();
  int count = 1;
  for (int a = 0; a < 3; ++a)
  {
    count *= ffd::SupportSize(view.Basis, view.Divisions[a]);
  }
  return count;
}
