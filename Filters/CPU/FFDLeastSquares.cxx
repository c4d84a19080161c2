// SPDX-License-Identifier: BSD-3-Clause
#include "FFDLeastSquares.h"

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <algorithm>
#include <cmath>

namespace ffd
{

namespace
{
using RowMajorMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor, int>;
using ThreeColumns = Eigen::Matrix<double, Eigen::Dynamic, 3>;
constexpr int RefinementSteps = 3;
} // namespace

//------------------------------------------------------------------------------------------------------------
LeastSquares::LeastSquares(
  int unknowns, std::vector<int> rowStart, std::vector<int> columns, std::vector<double> weights)
  : Unknowns(unknowns)
  , RowStart(std::move(rowStart))
  , Columns(std::move(columns))
  , Weights(std::move(weights))
{
}

//------------------------------------------------------------------------------------------------------------
void LeastSquares::Apply(const std::vector<double>& x, std::vector<double>& out) const
{
  out.assign(3 * std::size_t(this->GetNumberOfRows()), 0.0);
  for (int r = 0; r < this->GetNumberOfRows(); ++r)
  {
    for (int e = this->RowStart[r]; e < this->RowStart[r + 1]; ++e)
    {
      for (int c = 0; c < 3; ++c)
      {
        out[3 * std::size_t(r) + c] += this->Weights[e] * x[3 * std::size_t(this->Columns[e]) + c];
      }
    }
  }
}

//------------------------------------------------------------------------------------------------------------
LeastSquares::Result LeastSquares::Solve(
  const std::vector<double>& b, double regularization, std::vector<double>& x) const
{
  Result result;
  const int rows = this->GetNumberOfRows(), n = this->Unknowns;
  x.assign(3 * std::size_t(n), 0.0);
  const Eigen::Map<const RowMajorMatrix> w(
    rows, n, this->RowStart.back(), this->RowStart.data(), this->Columns.data(), this->Weights.data());
  const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>> rhs(b.data(), rows, 3);

  // The scaled normal equations: A_s = S A S with S = D^(-1/2), the right-hand side S W^T B.
  Eigen::SparseMatrix<double> scaled = Eigen::SparseMatrix<double>(w.transpose()) * w;
  Eigen::VectorXd s = scaled.diagonal();
  for (int i = 0; i < n; ++i)
  {
    s[i] = s[i] > 0 ? 1.0 / std::sqrt(s[i]) : 0.0;
  }
  for (int k = 0; k < scaled.outerSize(); ++k)
  {
    for (Eigen::SparseMatrix<double>::InnerIterator it(scaled, k); it; ++it)
    {
      it.valueRef() *= s[it.row()] * s[it.col()];
    }
  }
  const ThreeColumns target = s.asDiagonal() * (w.transpose() * rhs);

  // lambda I, and I alone for the unknowns no point weighs (they stay zero).
  Eigen::SparseMatrix<double> shifted = scaled;
  for (int i = 0; i < n; ++i)
  {
    shifted.coeffRef(i, i) += s[i] > 0 ? regularization : 1.0;
  }
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(shifted);
  if (ldlt.info() != Eigen::Success)
  {
    return result;
  }
  ThreeColumns y = ldlt.solve(target);
  for (int step = 0; step < RefinementSteps; ++step)
  {
    y += ldlt.solve(ThreeColumns(target - scaled * y));
  }
  if (!y.allFinite())
  {
    return result;
  }
  const ThreeColumns residual = target - scaled * y;
  for (int c = 0; c < 3; ++c)
  {
    const double norm = target.col(c).norm();
    result.RelativeResidual = std::max(result.RelativeResidual, norm > 0 ? residual.col(c).norm() / norm : 0.0);
  }
  for (int i = 0; i < n; ++i)
  {
    for (int c = 0; c < 3; ++c)
    {
      x[3 * std::size_t(i) + c] = s[i] * y(i, c);
    }
  }
  result.Solved = true;
  return result;
}

} // namespace ffd
