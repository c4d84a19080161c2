// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDInversePasses.h
 * @brief The inverse's Newton search in SIMD lanes: entry points of the FFDCpu library (host only).
 *
 * vtkFFDInverseDeform maps deformed points y back to rest positions x with F(x) = y. On a grid lattice it starts
 * W points at a time here: ffd::InvertPoint's Newton iteration without its line search, in the forward map's
 * lanes (float64), each lane group in one translation unit per SIMD level beside the evaluation's passes
 * (FFDGridPasses.h). The lanes that do not converge cleanly are the caller's, through ffd::InvertPoint.
 */
#ifndef FFDInversePasses_h
#define FFDInversePasses_h

#include "FFDGridPasses.h"
#include "FFDVector.h"

namespace ffd
{

/// Up to InverseLaneGroup::MaxWidth points inverted together (InverseLaneWidth() of them at a level).
struct InverseLaneGroup
{
  static constexpr int MaxWidth = 8;
  int Count = 0;          ///< its points; the lanes past them repeat its last point
  double Y[3 * MaxWidth]; ///< the deformed points, x y z each
  int Cells[MaxWidth];    ///< their cells (InverseLaneBinder::Bind())
  double X[3 * MaxWidth]; ///< the rest positions found
  double J[9][MaxWidth];  ///< the Jacobian there, by element (row by row) and lane
  unsigned Converged = 0; ///< the lanes whose rest position was found; the others are the caller's
};

/// The cell that extends F to x for the search in a sparse lattice (as ffd::InvertPoint's `bind`; a dense
/// lattice's lanes are bound by ffd::BindToGrid() under clamping): called for the lanes that leave their cell.
class InverseLaneBinder
{
public:
  virtual ~InverseLaneBinder() = default;
  virtual int Bind(const Vec3<double>& x) const = 0;
};

/// How the lanes search: a lane converges where |F(x) - y| <= Tolerance with det J > 0, within Iterations steps,
/// the residual falling at every step. Once every residual is within ChordResidual (one Newton step from the
/// tolerance), the evaluations leave J out, the steps taking the last J, unless WithJacobianAtEnd (the caller
/// needs J where x is found, for normals).
struct InverseLaneSearch
{
  const InverseLaneBinder& Binder;
  double Tolerance;
  double ChordResidual;
  int Iterations;
  bool WithJacobianAtEnd;
};

/// The lanes of a group at `level` (at most InverseLaneGroup::MaxWidth; 1: none, the caller inverts points one at
/// a time).
int InverseLaneWidth(SimdLevel level);

/// The Newton search of `group` (its Count points, their cells known) in lanes of `level`'s width, on the lattice.
void InvertInLanes(
  SimdLevel level, const GridLattice<double>& lattice, const InverseLaneSearch& search, InverseLaneGroup& group);

} // namespace ffd

#endif
