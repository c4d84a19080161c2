// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDLatticeQueries.h"

#include "vtkDataArray.h"
#include "vtkFFDBuildLattice.h"
#include "vtkFFDDataContract.h"
#include "vtkFFDGridDeformer.h"
#include "vtkFFDSparseLattice.h"
#include "vtkFFDTetrahedralDeformer.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"

#include "FFDGridDeformation.h"

#include <algorithm>

//------------------------------------------------------------------------------------------------------------
void vtkFFDForEachGridWeight(const vtkFFDGridDeformer& deformer, vtkPoints* points, vtkIdType begin, vtkIdType end,
  const std::function<void(vtkIdType, vtkIdType, double)>& add)
{
  const std::vector<int>& cellOf = deformer.GetCellOfPoint();
  vtkFFDWithGridDeformation(deformer,
    [&](const auto& deformation)
    {
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
void vtkFFDForEachTetrahedronWeight(const vtkFFDTetrahedralDeformer& deformer, vtkPoints* points, vtkIdType begin,
  vtkIdType end, const std::function<void(vtkIdType, vtkIdType, double)>& add)
{
  const std::vector<int>& cellOf = deformer.GetCellOfPoint();
  const std::vector<vtkIdType>& nodes = deformer.GetNodes();
  for (vtkIdType p = begin; p < end; ++p)
  {
    const int t = cellOf[p];
    if (t >= 0)
    {
      double x[3];
      points->GetPoint(p, x);
      const ffd::Vec3<double> stu = deformer.GetFrames()[t].ToParametric({ x[0], x[1], x[2] });
      const double weights[4] = { 1.0 - stu.x - stu.y - stu.z, stu.x, stu.y, stu.z };
      for (int corner = 0; corner < 4; ++corner)
      {
        add(p, nodes[4 * std::size_t(t) + corner], weights[corner]);
      }
    }
  }
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

//------------------------------------------------------------------------------------------------------------
std::string vtkFFDDoubledDivisions(
  ffd::GridBasis basis, const int divisions[3], int form, int doubled[3], int points[3])
{
  for (int a = 0; a < 3; ++a)
  {
    if (divisions[a] > VTK_INT_MAX / 2)
    {
      return "twice the " + std::to_string(divisions[a]) + " divisions along axis " + std::to_string(a) +
        " is not an int.";
    }
    doubled[a] = 2 * divisions[a];
  }
  std::string why;
  vtkFFDBuildLattice::GetControlPointsPerAxis(int(basis), doubled, points, why, form);
  return why;
}

//------------------------------------------------------------------------------------------------------------
std::vector<int> vtkFFDCoveredVoxels(const vtkFFDGridDeformer& deformer, vtkPointSet* lattice)
{
  if (const vtkFFDSparseCells* cells = deformer.GetSparseCells())
  {
    return cells->GetVoxels();
  }
  const vtkFFDGridLattice& view = deformer.GetLattice();
  vtkDataArray* active = lattice->GetPointData()->GetArray(vtkFFDDataContract::ActiveArrayName());
  const int* n = view.Divisions;
  const int* dims = view.ControlPointsPerAxis;
  std::vector<int> voxels;
  for (int k = 0; k < n[2]; ++k)
  {
    for (int j = 0; j < n[1]; ++j)
    {
      for (int i = 0; i < n[0]; ++i)
      {
        const int voxel[3] = { i, j, k };
        int first[3], count[3];
        for (int a = 0; a < 3; ++a)
        {
          ffd::VoxelSupport(view.Basis, n[a], voxel[a], first[a], count[a]);
        }
        bool covered = true;
        for (int c = first[2]; covered && active && c < first[2] + count[2]; ++c)
        {
          for (int b = first[1]; covered && b < first[1] + count[1]; ++b)
          {
            for (int a = first[0]; covered && a < first[0] + count[0]; ++a)
            {
              covered = active->GetComponent(a + vtkIdType(dims[0]) * (b + vtkIdType(dims[1]) * c), 0) != 0;
            }
          }
        }
        if (covered)
        {
          voxels.insert(voxels.end(), voxel, voxel + 3);
        }
      }
    }
  }
  return voxels;
}

//------------------------------------------------------------------------------------------------------------
vtkFFDControlPointIndex::vtkFFDControlPointIndex(const vtkFFDGridDeformer& deformer, vtkPointSet* lattice)
  : Dense(!deformer.GetLattice().Sparse)
{
  std::copy(deformer.GetLattice().ControlPointsPerAxis, deformer.GetLattice().ControlPointsPerAxis + 3, this->Dims);
  if (this->Dense)
  {
    return;
  }
  // The deformer has checked that every point has a LatticeIndex within the lattice.
  vtkDataArray* index = lattice->GetPointData()->GetArray(vtkFFDDataContract::LatticeIndexArrayName());
  std::vector<std::pair<vtkTypeInt64, vtkIdType>> keys(std::size_t(lattice->GetNumberOfPoints()));
  for (vtkIdType p = 0; p < lattice->GetNumberOfPoints(); ++p)
  {
    keys[std::size_t(p)] = { vtkFFDFlatIndex(int(index->GetComponent(p, 0)), int(index->GetComponent(p, 1)),
                               int(index->GetComponent(p, 2)), this->Dims),
      p };
  }
  this->Sorted = vtkFFDSortedKeys<vtkIdType>(std::move(keys));
}

//------------------------------------------------------------------------------------------------------------
vtkIdType vtkFFDControlPointIndex::Find(int i, int j, int k) const
{
  if (i < 0 || j < 0 || k < 0 || i >= this->Dims[0] || j >= this->Dims[1] || k >= this->Dims[2])
  {
    return -1;
  }
  const vtkTypeInt64 key = vtkFFDFlatIndex(i, j, k, this->Dims);
  if (this->Dense)
  {
    return vtkIdType(key);
  }
  return this->Sorted.FindId(key);
}
