// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDCudaTetrahedralDeformer.h
 * @brief The CUDA backend for tetrahedral lattices (paper section III.E): device-resident evaluation of a
 * binding computed on the host.
 *
 * Plain C++ (no CUDA, VTK, OpenVDB or TBB header); only FFDCudaTetrahedralDeformer.cu is compiled by nvcc.
 *
 * The binding (each point's tetrahedron) needs VTK's cell locator, so the host computes it and uploads it once
 * (Bind()), with each tetrahedron's rest frame and nodes. An update uploads only the nodes' displacements
 * (24 bytes a node, some 5 times fewer nodes than tetrahedra), builds every tetrahedron's map on the device
 * (ffd::MakeTetrahedronMap in double, rounded to the points' precision, as the CPU does) and deforms every point
 * through its tetrahedron's map (ffd::TetrahedronMap::Deform, Jacobian, ffd::TransformNormal): the same
 * Evaluation/Kernels functions as the CPU path. Uploading the maps themselves would move 60 (float) or 120
 * (double) bytes a tetrahedron per update, and need them computed on the host first (BENCHMARKS.md compares).
 * Residency, downloads and failures: ResidentPoints (FFDCudaResidentPoints.h).
 */
#ifndef FFDCudaTetrahedralDeformer_h
#define FFDCudaTetrahedralDeformer_h

#include "FFDCudaResidentPoints.h"

namespace ffd
{
template <typename Real>
struct Frame;

namespace cuda
{

class TetrahedralDeformer : public ResidentPoints
{
public:
  TetrahedralDeformer();

  /**
   * Uploads a binding computed on the host: per point of SetPoints() its tetrahedron, or -1 where it keeps its
   * position; per tetrahedron its rest frame (ffd::TetrahedronFrame; any finite frame for one that no point is
   * bound to) and its 4 nodes A, B, C, D, indices below `nodes`. They stay on the device until the next Bind()
   * or SetPoints(). Indices out of range are refused.
   */
  bool Bind(const int* tetrahedronOfPoint, const ffd::Frame<double>* restFrames, const int* tetrahedronNodes,
    std::int64_t tetrahedra, std::int64_t nodes);

  /// Uploads the nodes' displacements (3 doubles per node, `nodes` of them, as in Bind()) and evaluates every
  /// point on the device, with the transformed normals (needs SetNormals()) and det(J) when asked for. The results
  /// stay on the device until Download().
  bool Evaluate(const double* displacements, std::int64_t nodes, bool withNormals, bool withDeterminants);

  /**
   * W^T g, the adjoint of Evaluate() in the nodes: for the gradient g of an objective at the deformed points (3
   * doubles per point), the gradient at the nodes into `sums` (3 doubles per node, `nodes` as Evaluate()), each
   * point's term its barycentric weights in its tetrahedron in float64 (the points the host clamps to the control
   * mesh are not the device's: a binding with any is summed on the host). Summed without atomics in one order
   * set by the binding: the same bits at every run. Its plan is made at the first call after a binding.
   */
  bool Adjoint(const double* gradient, std::int64_t nodes, double* sums);

private:
  struct Impl;
};

} // namespace cuda
} // namespace ffd

#endif
