// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkFFDTetrahedralDeformer
 * @brief   vtkFFDDeform's path for tetrahedral lattices: reading, binding and CPU evaluation
 *
 * Private to the Filters module (not wrapped). A tetrahedral lattice (paper section III.E) is a
 * vtkUnstructuredGrid whose cells are all VTK_TETRA, with a `RestPosition` point array (3 components, one per
 * point) and without the grid lattices' `FFDFrame`; its deformation is its points minus `RestPosition`.
 *
 * Binding, once per input points and lattice rest shape (ffd::TetrahedronFrame, Evaluation/Kernels/FFDTetrahedra.h):
 * every point is located in the rest tetrahedra by the weights of equation 5 (vtkFFDTetrahedronLocator: a walk
 * across faces from a seed, VTK's vtkStaticCellLocator where a walk gives no answer). It stores one int per
 * point, the tetrahedron, or -1 for a point that keeps its position; it is kept while the points (their
 * vtkPoints, its modification time and count), the rest tetrahedra (by value) and the policy stay the same.
 * Tetrahedra without volume (ffd::CheckTetrahedron) are never bound to: points in them fall to a neighbour or to
 * the outside policy.
 * Points outside every tetrahedron keep their position (KEEP_POSITION), take the displacement of the nearest
 * point of the control mesh (CLAMP_TO_EDGE, as grid lattices do), or follow the affine map of the nearest
 * tetrahedron (EXTRAPOLATE). Non-finite points always keep theirs.
 *
 * Evaluation, at every update: each tetrahedron's affine map (ffd::MakeTetrahedronMap) from its nodes'
 * displacements, then every point through its tetrahedron's map (ffd::TetrahedronMap::Deform), with normals
 * by the map's cofactor and det J on request, on vtkSMPTools. The CUDA backend (vtkFFDCudaBackend) evaluates the
 * same binding on the device; either backend then moves the points clamped to the control mesh with
 * ApplyClampedPoints().
 *
 * The same binding serves vtkFFDBuildTetrahedralLattice, which marks the nodes of tetrahedra holding mesh points
 * `Active`.
 */
#ifndef vtkFFDTetrahedralDeformer_h
#define vtkFFDTetrahedralDeformer_h

#include "vtkFFDBindingKey.h"
#include "vtkSmartPointer.h"
#include "vtkTimeStamp.h"
#include "vtkType.h"

#include "FFDTetrahedra.h"

#include <string>
#include <vector>

class vtkAlgorithm;
class vtkDataArray;
class vtkDataObject;
class vtkFFDTetrahedronLocator;
class vtkPoints;
class vtkUnstructuredGrid;

class vtkFFDTetrahedralDeformer
{
public:
  vtkFFDTetrahedralDeformer();
  ~vtkFFDTetrahedralDeformer();
  vtkFFDTetrahedralDeformer(const vtkFFDTetrahedralDeformer&) = delete;
  vtkFFDTetrahedralDeformer& operator=(const vtkFFDTetrahedralDeformer&) = delete;

  /// Outside policies, vtkFFDDeform's values.
  enum Policies
  {
    KEEP_POSITION = 0,
    CLAMP_TO_EDGE = 1,
    EXTRAPOLATE = 2
  };

  /// The most tetrahedra a lattice may have: the binding numbers their faces (4 a tetrahedron) by int.
  static constexpr vtkIdType MaxTetrahedra = (VTK_INT_MAX - 3) / 4;

  /// Whether `lattice` is meant as a tetrahedral lattice: a vtkUnstructuredGrid without the `FFDFrame` of grid
  /// lattices (SetLattice() then says what else is wrong with it, if anything).
  static bool IsTetrahedralLattice(vtkDataObject* lattice);

  /**
   * Reads and checks a tetrahedral lattice and keeps its nodes' displacements for Evaluate(). Returns an empty
   * string, or what is wrong: cells other than tetrahedra or more than MaxTetrahedra, point ids outside the
   * lattice, no or a malformed `RestPosition`, non-finite positions, no cells.
   */
  std::string SetLattice(vtkUnstructuredGrid* lattice);

  /**
   * Binds the points to the lattice of SetLattice() unless the binding is already for them, the same rest
   * tetrahedra (by value) and the same policy. Progress goes to `self` (may be null) from
   * `progressBegin` to `progressEnd`. Returns false when aborted (the binding is then dropped); `rebound` tells
   * whether it bound.
   */
  bool Bind(
    vtkPoints* points, int outsidePolicy, vtkAlgorithm* self, double progressBegin, double progressEnd, bool& rebound);

  /**
   * Deforms the bound points into outPoints (a float or double AOS array of their count), with the normals
   * (3 components, may be null) transformed into outNormals and det J into outDeterminants (of outPoints' type)
   * when those are not null. Returns false when aborted.
   */
  bool Evaluate(vtkPoints* points, vtkDataArray* normals, vtkDataArray* outPoints, vtkDataArray* outNormals,
    vtkDataArray* outDeterminants, vtkAlgorithm* self, double progressBegin, double progressEnd);

  /**
   * Moves the points clamped to the control mesh (CLAMP_TO_EDGE) by the displacement of their nearest point
   * there, in double precision, over what the evaluation wrote for them (their position): the last step of
   * Evaluate(), and of the CUDA backend's evaluation, on the host. Arguments as Evaluate()'s.
   */
  void ApplyClampedPoints(vtkPoints* points, vtkDataArray* normals, vtkDataArray* outPoints, vtkDataArray* outNormals,
    vtkDataArray* outDeterminants) const;

  /// Whether the binding clamps any point, which ApplyClampedPoints() then moves on the host.
  bool HasClampedPoints() const { return !this->Clamped.empty(); }

  ///@{
  /// The binding: per point its tetrahedron (-1: keeps its position, or clamped, see above); per tetrahedron its
  /// rest frame (zero for tetrahedra without volume, which nothing is bound to) and its 4 nodes; when it was
  /// computed (a vtkTimeStamp: a new binding has a later time).
  const std::vector<int>& GetCellOfPoint() const { return this->CellOfPoint; }
  vtkIdType GetNumberOfTetrahedra() const { return static_cast<vtkIdType>(this->Frames.size()); }
  const std::vector<ffd::Frame<double>>& GetFrames() const { return this->Frames; }
  const std::vector<vtkIdType>& GetNodes() const { return this->Nodes; }
  vtkMTimeType GetBindTime() const { return this->BindTime.GetMTime(); }
  ///@}

  /// The lattice's nodes' displacements of the last SetLattice(): 3 per node.
  const std::vector<double>& GetDisplacements() const { return this->Displacements; }

  ///@{
  /// Tetrahedra without volume in the bound lattice, and the first of them (-1 when none).
  vtkIdType GetNumberOfDegenerateTetrahedra() const { return this->NumberOfDegenerate; }
  vtkIdType GetFirstDegenerateTetrahedron() const { return this->FirstDegenerate; }
  ///@}

  /// A point outside the control mesh clamped to it: it moves by the displacement of its nearest point there.
  struct ClampedPoint
  {
    vtkIdType Point;
    int Tetrahedron;
    ffd::Vec3<double> Closest;  ///< the nearest point of the control mesh
    ffd::Mat3<double> Gradient; ///< d(Closest)/dX (ffd::ClosestPointGradient)
  };

  /// The points of the binding clamped to the control mesh, in increasing point id (their CellOfPoint is -1).
  const std::vector<ClampedPoint>& GetClampedPoints() const { return this->Clamped; }

private:
  /// The map of a tetrahedron from its nodes' displacements (double precision).
  ffd::TetrahedronMap<double> Map(vtkIdType tetrahedron) const;
  /// Every tetrahedron's map, in the evaluation's precision.
  template <typename Real>
  void ComputeMaps(std::vector<ffd::TetrahedronMap<Real>>& maps) const;

  /// The step of SetLattice() that reads the tetrahedra's nodes, only where the connectivity changed, checking
  /// each id: an empty string, or what is wrong (`fix` ending it).
  std::string ReadNodes(vtkUnstructuredGrid* lattice, const std::string& fix);

  ///@{
  /// The steps of Bind(). The walks and VTK's locator return false when aborted.
  void ComputeRestFrames();
  bool WalkPoints(vtkPoints* points, const vtkFFDTetrahedronLocator& locator, vtkAlgorithm* self, double progressBegin,
    double progressEnd);
  bool LocateUndecidedPoints(
    vtkPoints* points, vtkFFDTetrahedronLocator& locator, vtkAlgorithm* self, double progressBegin, double progressEnd);
  void ApplyOutsidePolicy(vtkPoints* points, int outsidePolicy, vtkFFDTetrahedronLocator& locator);
  void ListUsedTetrahedra();
  ///@}

  // The lattice of SetLattice().
  vtkSmartPointer<vtkUnstructuredGrid> Lattice;
  vtkSmartPointer<vtkDataArray> RestPositions;
  std::vector<double> RestValues;    // 3 per node: RestPosition
  std::vector<double> Displacements; // 3 per node: the node minus RestPosition
  std::vector<vtkIdType> Nodes;      // 4 per tetrahedron
  const void* NodesSource = nullptr; // the cell array Nodes was read from, its and its arrays' latest
  vtkMTimeType NodesSourceMTime = 0; // modification time, and the lattice's count of nodes then
  vtkIdType NodesSourceNodeCount = 0;
  bool NodesRead = false; // Nodes were read again since the last Bind()

  // The binding and what it is for.
  vtkFFDBindingKey Bound; // the points and policy of the binding; the rest tetrahedra are compared by value
  std::vector<double> BoundRest;
  std::vector<vtkIdType> BoundNodes;
  vtkTimeStamp BindTime;
  std::vector<ffd::Frame<double>> Frames; // rest frame per tetrahedron
  std::vector<unsigned char> Degenerate;  // 1 per tetrahedron without volume
  vtkIdType NumberOfDegenerate = 0;
  vtkIdType FirstDegenerate = -1;
  std::vector<int> CellOfPoint;
  std::vector<int> Used; // the tetrahedra some point is bound to (not a clamped one: those use Map())
  std::vector<ClampedPoint> Clamped;

  // Every tetrahedron's map, in the precision of the last evaluation: kept, so that an update neither allocates
  // nor page-faults them again (8.5 MB for 71 k tetrahedra in double).
  std::vector<ffd::TetrahedronMap<float>> MapsFloat;
  std::vector<ffd::TetrahedronMap<double>> MapsDouble;
  std::vector<ffd::TetrahedronMap<float>>& MapsIn(float) { return this->MapsFloat; }
  std::vector<ffd::TetrahedronMap<double>>& MapsIn(double) { return this->MapsDouble; }
};

#endif
