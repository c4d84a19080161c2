// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDCudaGridDeformer.h
 * @brief The CUDA backend for grid lattices: device-resident binding and evaluation of their deformation.
 *
 * Plain C++ (no CUDA, VTK, OpenVDB or TBB header); only FFDCudaGridDeformer.cu is compiled by nvcc. The device
 * code calls the same Evaluation/Kernels functions as the CPU path (ffd::BindToGrid, ffd::GridDeformation), so both
 * compute one function. Residency, downloads and failures: ResidentPoints (FFDCudaResidentPoints.h).
 */
#ifndef FFDCudaGridDeformer_h
#define FFDCudaGridDeformer_h

#include "FFDCudaResidentPoints.h"

namespace ffd
{
namespace cuda
{

class GridDeformer : public ResidentPoints
{
public:
  GridDeformer();

  /// Binds the points to a lattice (ffd::BindToGrid): frame X0, S, T, U; basis (ffd::GridBasis value);
  /// divisions (voxels per axis). The binding stays on the device.
  bool Bind(const double frame[12], int basis, const int divisions[3], bool clampOutside);

  /**
   * Takes the binding of the points to a sparse lattice, computed on the host (its voxels' lookup needs the
   * lattice's cells): each point's cell (-1: it keeps its position), and per cell its voxel's indices (3 ints)
   * and its support's control points (SupportSize()^3 indices into the displacements, i fastest), as
   * ffd::GridDeformation's CellVoxels and CellSupports. Frame, basis and divisions as Bind(); `controlPoints`
   * is the sparse lattice's count, which Evaluate() is then given.
   */
  bool BindSparse(const double frame[12], int basis, const int divisions[3], const int* cellOfPoint,
    const int* cellVoxels, const int* cellSupports, std::int64_t cells, std::int64_t controlPoints);

  /// Uploads the displacements (3 doubles per control point, VTK order, `controlPoints` of them, as many as the
  /// basis and divisions of Bind() give, or a sparse lattice's of BindSparse()) and evaluates every point on the
  /// device, with the transformed normals (needs SetNormals()) and det(J) when asked for. The results stay on the
  /// device until Download().
  bool Evaluate(const double* displacements, std::int64_t controlPoints, bool withNormals, bool withDeterminants);

  /**
   * W^T g, the adjoint of Evaluate() (its transpose in the control points): for the gradient g of an objective at
   * the deformed points (3 doubles per point, in the points' order), the gradient at the control points into
   * `sums` (3 doubles per control point, `controlPoints` as Evaluate()). Points that keep their position add
   * nothing. Computed in the points' precision, summed in float64 without atomics, in one order set by the
   * binding (FFDCudaGridAdjoint.cuh): the same bits at every run. Its plan is made at the first call after a
   * binding (Counters::AdjointPlans).
   */
  bool Adjoint(const double* gradient, std::int64_t controlPoints, double* sums);

  /**
   * Whether Evaluate() may evaluate the triquadratic and cubic bases from a cell table (on by default): each cell's
   * polynomial in power form, built on the device at each update where WorthCellTable() says so, as the CPU path
   * does (ffd::FillCellTable(), FFDCellTable.h); the same function, rounded differently. Off, every point is the
   * weighted sum of its control points (benchmarks and tests compare the two in one run). Counters::CellTables
   * counts the evaluations that used one.
   */
  void SetCellTables(bool allowed);

  /// True where an evaluation of `points` points over `cells` cells of `basis` (ffd::GridBasis value) on the
  /// device takes a cell table: the triquadratic and cubic bases with at least 64 points a cell (a cell's table,
  /// 384 or 800 bytes in float32, is written once and read once: the traffic of 15 to 30 points).
  static bool WorthCellTable(int basis, std::int64_t cells, std::int64_t points);

private:
  struct Impl;
};

} // namespace cuda
} // namespace ffd

#endif
