// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDDeformPoint.h
 * @brief One bound point's results (position, transformed normal, det J): the same function for every lattice
 * kind, backend and evaluation path that takes points one at a time.
 */
#ifndef FFDDeformPoint_h
#define FFDDeformPoint_h

#include "FFDVector.h"

namespace ffd
{

/**
 * Point x bound to `cell` deformed by `deformation` (anything with Deform(x, cell) and Deform(x, cell, jacobian),
 * as GridDeformation and TetrahedralDeformation have); cell -1 keeps its position and its Jacobian is the
 * identity. Writes the deformed point to out[0..2] and, where WithJacobian, `normal` transformed
 * (TransformNormal()) to outNormal[0..2] and the Jacobian's determinant to *determinant, each where its pointer
 * is not null.
 */
template <bool WithJacobian, typename Deformation, typename Real>
FFD_INLINE void DeformBoundPoint(const Deformation& deformation, const Vec3<Real>& x, int cell, Real* out,
  const Real* normal = nullptr, Real* outNormal = nullptr, Real* determinant = nullptr)
{
  Vec3<Real> y = x;
  Mat3<Real> jacobian = Mat3<Real>::Identity();
  if (cell >= 0)
  {
    if constexpr (WithJacobian)
    {
      y = deformation.Deform(x, cell, jacobian);
    }
    else
    {
      y = deformation.Deform(x, cell);
    }
  }
  out[0] = y.x;
  out[1] = y.y;
  out[2] = y.z;
  if constexpr (WithJacobian)
  {
    if (outNormal)
    {
      const Vec3<Real> m = TransformNormal(jacobian, Vec3<Real>::From(normal));
      outNormal[0] = m.x;
      outNormal[1] = m.y;
      outNormal[2] = m.z;
    }
    if (determinant)
    {
      *determinant = Determinant(jacobian);
    }
  }
}

} // namespace ffd

#endif
