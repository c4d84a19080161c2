// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDLeastSquares.h
 * @brief Linear least squares of control-point displacements: the X that minimises |W X - B|^2.
 *
 * W is sparse, one row per sample point holding the weights of the control points that move it (a lattice's
 * basis at that point); X and B have three columns (x, y, z). The normal equations A X = W^T B, A = W^T W, are
 * solved in Jacobi-scaled unknowns y = D^(1/2) x (D = diag A), where A's rows are alike whatever the basis or the
 * points' density, by a sparse LDL^T factorisation (Eigen's SimplicialLDLT) of D^(-1/2) A D^(-1/2) + lambda I
 * followed by three steps of iterated Tikhonov refinement y += (...)^(-1) (r) with the unregularised residual r:
 * determined directions (scaled eigenvalue sigma^2 >> lambda) converge to the least-squares solution, as far as
 * rounding allows (about cond(D^(-1/2) A D^(-1/2)) eps); directions the points do not determine (sigma^2 <~
 * lambda) stay near zero, the minimum-norm choice. Unknowns that no point weighs are zero. VTK-free.
 */
#ifndef FFDLeastSquares_h
#define FFDLeastSquares_h

#include <cstddef>
#include <vector>

namespace ffd
{

class LeastSquares
{
public:
  struct Result
  {
    bool Solved = false;         ///< false when the factorisation failed (lambda 0 and A singular)
    double RelativeResidual = 0; ///< the largest column's |D^(-1/2) (W^T B - A X)| / |D^(-1/2) W^T B|
  };

  /**
   * W of `unknowns` columns in compressed rows: row r's entries are columns[rowStart[r] .. rowStart[r + 1]) with
   * those weights (a column at most once per row; fewer than 2^31 entries in all).
   */
  LeastSquares(int unknowns, std::vector<int> rowStart, std::vector<int> columns, std::vector<double> weights);

  int GetNumberOfRows() const { return int(this->RowStart.size()) - 1; }

  /// X (3 per unknown) for B (3 per row), with lambda = `regularization` (default of the filters: 1e-8).
  Result Solve(const std::vector<double>& b, double regularization, std::vector<double>& x) const;

  /// W X (3 per row).
  void Apply(const std::vector<double>& x, std::vector<double>& out) const;

private:
  int Unknowns;
  std::vector<int> RowStart;
  std::vector<int> Columns;
  std::vector<double> Weights;
};

} // namespace ffd

#endif
