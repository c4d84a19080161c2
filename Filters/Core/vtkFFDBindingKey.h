// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file vtkFFDBindingKey.h
 * @brief What a binding of points to a lattice was computed for, so that it is kept while that stays the same
 * (private to the VoxelFFD modules).
 *
 * The points are compared by identity, modification time and count (a new vtkPoints at a recycled address has a
 * newer MTime); a grid lattice's rest state by value (frame, divisions, basis), so that a rebuilt but identical
 * lattice keeps the binding. A tetrahedral lattice's rest state is compared by its deformer, by value too.
 */
#ifndef vtkFFDBindingKey_h
#define vtkFFDBindingKey_h

#include "vtkType.h"

#include <array>
#include <cstdint>

class vtkPoints;

struct vtkFFDBindingKey
{
  const vtkPoints* Points = nullptr;
  vtkMTimeType PointsMTime = 0;
  vtkIdType NumberOfPoints = -1;
  int OutsidePolicy = -1; // vtkFFDDeform's
  // Grid lattices only:
  std::array<double, 12> Frame{};
  std::array<int, 3> Divisions{};
  int Basis = -1;
  std::uint64_t SparseCells = 0; // a sparse lattice's vtkFFDSparseCells::GetFingerprint(), 0 for a dense one

  /// The key of a binding of `points` under `outsidePolicy` (a tetrahedral lattice's).
  static vtkFFDBindingKey Of(vtkPoints* points, int outsidePolicy);
  /// The key of a binding of `points` to a grid lattice of that rest frame, divisions and basis.
  static vtkFFDBindingKey OfGrid(vtkPoints* points, int outsidePolicy, const double frame[12], const int divisions[3],
    int basis, std::uint64_t sparseCells);

  /// Whether points outside the lattice are clamped to it (vtkFFDDeform::CLAMP_TO_EDGE).
  bool ClampsOutside() const;

  bool operator==(const vtkFFDBindingKey& other) const;
  bool operator!=(const vtkFFDBindingKey& other) const { return !(*this == other); }
};

#endif
