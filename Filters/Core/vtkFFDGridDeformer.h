// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkFFDGridDeformer
 * @brief   vtkFFDDeform's path for grid lattices: reading, binding and CPU evaluation
 *
 * Private to the Filters module (not wrapped); the counterpart of vtkFFDTetrahedralDeformer for the lattices of
 * vtkFFDBuildLattice (see vtkFFDDataContract). SetLattice() reads and checks a lattice and keeps its control
 * points' displacements; Bind() finds every point's cell (ffd::BindToGrid) and lists the blocks of points
 * for the SIMD passes, unless the binding is already for these points, the same rest frame, divisions, basis and
 * policy; Evaluate() deforms the bound points on vtkSMPTools threads. docs/evaluation-design.md says how the
 * passes work.
 * A lattice is dense (a control point per lattice index) or sparse (vtkFFDSparseCells): both bind and evaluate
 * through the same passes, a sparse lattice's cells numbered in the dense lattice's order.
 */
#ifndef vtkFFDGridDeformer_h
#define vtkFFDGridDeformer_h

#include "vtkDataArray.h"
#include "vtkFFDBindingKey.h"
#include "vtkFFDSparseCells.h"
#include "vtkSmartPointer.h"
#include "vtkType.h"

#include "FFDGridBasis.h"

#include <memory>
#include <string>
#include <vector>

namespace ffd
{
template <typename Real>
struct GridLattice;
}
class vtkAlgorithm;
class vtkPoints;
class vtkPointSet;
struct vtkFFDGridBinding;

/// What vtkFFDDeform needs from a grid lattice, read and checked once per update.
struct vtkFFDGridLattice
{
  double Frame[12];
  int Divisions[3];
  ffd::GridBasis Basis;
  int ControlPointsPerAxis[3];
  // 3 per control point: point minus RestPosition, read by SetLattice() in ReadPrecision: VTK_DOUBLE into
  // Displacements (always, where the deformer keeps them: its constructor), VTK_FLOAT into FloatDisplacements, or
  // neither (0); a deformer that does not keep them reads them in the precision of its last evaluation.
  std::vector<double> Displacements;
  std::vector<float> FloatDisplacements;
  int ReadPrecision = VTK_DOUBLE;
  bool KeepDisplacements = true;
  bool Sparse = false; // the control points and cells of vtkFFDGridDeformer::GetSparseCells() only
  vtkSmartPointer<vtkDataArray> Points, RestPosition; // the lattice's (doubles, checked)
};

/// What the last check of a lattice's RestPosition against its frame passed: the arrays (RestPosition, and a sparse
/// lattice's LatticeIndex) by identity and time, and the frame, divisions and basis they were checked against.
struct vtkFFDRestCheck
{
  const void* Arrays[2] = { nullptr, nullptr };
  vtkMTimeType Times[2] = { 0, 0 };
  vtkIdType Count = -1;
  double Frame[12] = {};
  int Divisions[3] = {};
  int Basis = -1;

  bool operator==(const vtkFFDRestCheck& other) const;
};

class vtkFFDGridDeformer
{
public:
  /**
   * `keepDisplacements`: whether SetLattice() keeps the displacements in GetLattice().Displacements, as the
   * readers of a lattice need them. vtkFFDDeform, which only evaluates, does not: they are read in the evaluation's
   * precision (float points: 12 bytes a control point, not 24 kept and 12 more while evaluating), by Evaluate() at
   * the first, by SetLattice() while it checks them from the next on; the CUDA backend reads them through
   * ReadDisplacements().
   */
  explicit vtkFFDGridDeformer(bool keepDisplacements = true);
  ~vtkFFDGridDeformer();
  vtkFFDGridDeformer(const vtkFFDGridDeformer&) = delete;
  vtkFFDGridDeformer& operator=(const vtkFFDGridDeformer&) = delete;

  /**
   * Reads and checks a grid lattice per the data contract and keeps it for Bind() and Evaluate(): among others,
   * every cell's point ids (vtkFFDSparseCells), double points and RestPosition within +-vtkFFDMaxLatticeCoordinate,
   * and RestPosition where the frame puts it (checked again only when it or the frame changes). Returns an empty
   * string, or what is wrong with it.
   */
  std::string SetLattice(vtkPointSet* lattice);

  /// The lattice of the last SetLattice().
  const vtkFFDGridLattice& GetLattice() const { return this->Lattice; }

  /// The displacements of the last SetLattice()'s lattice: GetLattice().Displacements where kept, else read into
  /// `storage`.
  const double* ReadDisplacements(std::vector<double>& storage) const;

  ///@{
  /**
   * The lattice of the last SetLattice() as the CPU passes read it (FFDGridPasses.h), from `displacements` (3 per
   * control point, in the passes' precision: ReadDisplacements() or the deformer's own), with its cells in power
   * form where `withCellTable` (ffd::FillCellTable(), in parallel, into `table`, which must outlive the result).
   */
  ffd::GridLattice<float> PassLattice(const float* displacements, bool withCellTable, std::vector<float>& table) const;
  ffd::GridLattice<double> PassLattice(
    const double* displacements, bool withCellTable, std::vector<double>& table) const;
  ///@}

  /// The cells of the last SetLattice()'s lattice where it is sparse, else null.
  const vtkFFDSparseCells* GetSparseCells() const { return this->Lattice.Sparse ? &this->SparseCells : nullptr; }

  /// The cell of each point of the last Bind() (-1: it keeps its position).
  const std::vector<int>& GetCellOfPoint() const;

  /// What a binding of `points` to the lattice of SetLattice() under `outsidePolicy` is for.
  vtkFFDBindingKey KeyOf(vtkPoints* points, int outsidePolicy) const;

  /**
   * Binds the points to the lattice of SetLattice() unless the binding is already for them (KeyOf()). Progress
   * goes to `self` from `progressBegin` to `progressEnd`. Returns false when aborted (the binding is then
   * dropped); `rebound` tells whether it bound.
   */
  bool Bind(
    vtkPoints* points, int outsidePolicy, vtkAlgorithm* self, double progressBegin, double progressEnd, bool& rebound);

  /// The cell Bind() gives the point x under `outsidePolicy` (-1: it keeps its position).
  int BindPoint(const double x[3], int outsidePolicy) const;

  /**
   * Deforms the bound points into outPoints (a float or double AOS array of their count), with the normals
   * (3 components, may be null) transformed into outNormals and det J into outDeterminants (of outPoints' type)
   * when those are not null. Returns false when aborted.
   */
  bool Evaluate(vtkPoints* points, vtkDataArray* normals, vtkDataArray* outPoints, vtkDataArray* outNormals,
    vtkDataArray* outDeterminants, vtkAlgorithm* self, double progressBegin, double progressEnd);

private:
  vtkFFDGridLattice Lattice;
  vtkFFDSparseCells SparseCells;
  vtkFFDRestCheck RestChecked;    // the rest positions are checked again only when they or the frame change
  ffd::Frame<double> BindFrame{}; // the frame with its dual basis, made by SetLattice() for every BindPoint()
  std::unique_ptr<vtkFFDGridBinding> Binding;
  vtkFFDBindingKey Bound; // what Binding is for
};

#endif
