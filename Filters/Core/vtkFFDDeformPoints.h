// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file vtkFFDDeformPoints.h
 * @brief The CPU evaluation of bound points one at a time, from VTK arrays of any type, for grid and tetrahedral
 * lattices alike (private to the VoxelFFD modules).
 *
 * It serves what the SIMD passes of grid lattices do not take (points of another type than the output's, normals
 * of another type than the points') and every tetrahedral evaluation. Each point goes through
 * ffd::DeformBoundPoint, as on the CUDA backend.
 */
#ifndef vtkFFDDeformPoints_h
#define vtkFFDDeformPoints_h

#include "vtkFFDForInChunks.h"

#include "vtkDataArray.h"
#include "vtkDataArrayRange.h"

#include "FFDDeformPoint.h"

template <typename DeformationT, typename Real, typename PointArrayT>
struct vtkFFDDeformPointsFunctor
{
  PointArrayT* InPoints;
  const int* CellOfPoint; // per point: the cell it is bound to, -1 where it keeps its position
  const DeformationT& Deformation;
  vtkDataArray* InNormals; // nullptr: no normals to transform
  vtkDataArray* OutNormals;
  Real* OutPoints;
  Real* Determinants; // nullptr: not asked for

  void operator()(vtkIdType begin, vtkIdType end)
  {
    const bool withJacobian = this->OutNormals || this->Determinants;
    const auto inPoints = vtk::DataArrayTupleRange<3>(this->InPoints, begin, end);
    vtkIdType id = begin;
    for (const auto x : inPoints)
    {
      const ffd::Vec3<Real> xr = { Real(x[0]), Real(x[1]), Real(x[2]) };
      Real* out = this->OutPoints + 3 * id;
      if (!withJacobian)
      {
        ffd::DeformBoundPoint<false>(this->Deformation, xr, this->CellOfPoint[id], out);
        ++id;
        continue;
      }
      double normal[3] = { 0, 0, 0 };
      if (this->OutNormals)
      {
        this->InNormals->GetTuple(id, normal);
      }
      const Real n[3] = { Real(normal[0]), Real(normal[1]), Real(normal[2]) };
      Real m[3];
      ffd::DeformBoundPoint<true>(this->Deformation, xr, this->CellOfPoint[id], out, n, this->OutNormals ? m : nullptr,
        this->Determinants ? this->Determinants + id : nullptr);
      if (this->OutNormals)
      {
        this->OutNormals->SetTuple3(id, m[0], m[1], m[2]);
      }
      ++id;
    }
  }
};

/**
 * Every point of `inPoints` deformed by `deformation` from the cell it is bound to, into outPoints (3 Reals a
 * point) and, where not null, outNormals (inNormals transformed) and determinants, in tasks of at least `grain`
 * points reporting progress from progressBegin to progressEnd. False when the algorithm was aborted.
 */
template <typename Real, typename Deformation, typename PointArrayT>
bool vtkFFDDeformPoints(PointArrayT* inPoints, const int* cellOfPoint, const Deformation& deformation,
  vtkDataArray* inNormals, vtkDataArray* outNormals, Real* outPoints, Real* determinants, vtkAlgorithm* self,
  vtkIdType grain, double progressBegin, double progressEnd)
{
  vtkFFDDeformPointsFunctor<Deformation, Real, PointArrayT> functor{ inPoints, cellOfPoint, deformation, inNormals,
    outNormals, outPoints, determinants };
  return vtkFFDForInChunks(self, inPoints->GetNumberOfTuples(), grain, functor, progressBegin, progressEnd);
}

#endif
