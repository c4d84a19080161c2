// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDLeastSquares.h
 * @brief Linear least squares of control-point displacements: the X that minimises |W X - B|^2.
 *
 * W is sparse, one row per sample point holding the weights of the control points that move it (a lattice's
 * basis at that point); X and B have three columns (x, y, z). The normal equations A X = W^T B, A = W^T W, are
 * solved by iterated Tikhonov regularisation: X_0 = 0, X_{k+1} = X_k + M^(-1) (W^T B - A X_k) with
 * M = A + lambda R, factored once (Eigen's SimplicialLDLT, in Jacobi-scaled unknowns so that its pivots are alike
 * whatever the basis or the points' density). R is the smoothness of the control net: the sum of the squared
 * second differences x_a - 2 x_b + x_c along the lattice's axes, plus 1e-6 I so that M is definite. Directions
 * that the points determine (eigenvalue sigma^2 >> lambda) converge to the least-squares solution by a factor
 * lambda / (sigma^2 + lambda) a step, as far as rounding allows (about cond(A) eps); directions they do not
 * determine, or barely (sigma^2 <~ lambda), keep the smoothest values, those the net's neighbours extend to them.
 * lambda = Regularization times the mean of diag(A). Unknowns that no point weighs and no difference joins are
 * zero. VTK-free.
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
  /**
   * W of `unknowns` columns in compressed rows: row r's entries are columns[rowStart[r] .. rowStart[r + 1]) with
   * those weights (a column at most once per row; fewer than 2^31 entries in all).
   */
  LeastSquares(int unknowns, std::vector<int> rowStart, std::vector<int> columns, std::vector<double> weights);

  int GetNumberOfRows() const { return int(this->RowStart.size()) - 1; }

  /// The second differences x[a] - 2 x[b] + x[c] of the smoothness R, 3 unknowns a difference (none by default).
  void SetSecondDifferences(std::vector<int> triples) { this->Triples = std::move(triples); }

  /**
   * X (3 per unknown) for B (3 per row), with lambda = `regularization` times mean(diag A), in `steps` steps.
   * False when the factorisation failed (lambda 0 and A singular).
   */
  bool Solve(const std::vector<double>& b, double regularization, int steps, std::vector<double>& x) const;

  /// W X (3 per row).
  void Apply(const std::vector<double>& x, std::vector<double>& out) const;

private:
  int Unknowns;
  std::vector<int> RowStart;
  std::vector<int> Columns;
  std::vector<double> Weights;
  std::vector<int> Triples;
};

} // namespace ffd

#endif
