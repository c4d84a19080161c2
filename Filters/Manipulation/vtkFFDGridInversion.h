// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file vtkFFDGridInversion.h
 * @brief vtkFFDInverseDeform's search on grid lattices (private to the Manipulation module).
 *
 * Newton's method on the lattice's float64 evaluation, from y minus the displacement at y: the points ordered by
 * cell in cache-sized tiles (a size of the point count alone, so that results do not depend on the threads), W at
 * a time in the forward map's SIMD lanes with the basis known at compile time (FFDInversePasses.h, in FFDCpu), a
 * lane that does not converge cleanly through ffd::InvertPoint, which reports folds and unconverged points.
 */
#ifndef vtkFFDGridInversion_h
#define vtkFFDGridInversion_h

class vtkAlgorithm;
class vtkDataArray;
class vtkFFDGridDeformer;
class vtkPoints;

/// Where an inversion writes: 3 doubles a point, 3 a normal (null: no normals), an ffd::InverseStatus a point.
struct vtkFFDInverseOutput
{
  double* Points;
  double* Normals;
  unsigned char* Status;
};

/**
 * Maps every point of `points` (deformed by `deformer`'s lattice) back to its rest position, to `tolerance` times
 * the frame's diagonal in at most `maxIterations` Newton steps, with `normals` when not null. Reports progress and
 * stops when `self` is aborted; returns false then.
 */
bool vtkFFDInvertByGrid(vtkAlgorithm* self, const vtkFFDGridDeformer& deformer, vtkPoints* points,
  vtkDataArray* normals, double tolerance, int maxIterations, const vtkFFDInverseOutput& out);

#endif
