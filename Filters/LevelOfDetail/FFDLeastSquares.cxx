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
bool LeastSquares::Solve(const std::vector<double>& b, double regularization, int steps, std::vector<double>& x) const
{
  const int rows = this->GetNumberOfRows(), n = this->Unknowns;
  x.assign(3 * std::size_t(n), 0.0);
  const Eigen::Map<const RowMajorMatrix> w(
    rows, n, this->RowStart.back(), this->RowStart.data(), this->Columns.data(), this->Weights.data());
  const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>> rhs(b.data(), rows, 3);

  // A, lambda R, and the Jacobi scaling S = D^(-1/2) of their sum (1 for an unknown with neither).
  Eigen::SparseMatrix<double> a = Eigen::SparseMatrix<double>(w.transpose()) * w;
  const double mean = a.diagonal().sum() / std::max(1, n);
  const double lambda = regularization * (mean > 0 ? mean : 1.0);
  std::vector<Eigen::Triplet<double>> entries;
  const int stencil[3] = { 1, -2, 1 };
  for (std::size_t t = 0; t + 2 < this->Triples.size(); t += 3)
  {
    for (int r = 0; r < 3; ++r)
    {
      for (int c = 0; c < 3; ++c)
      {
        entries.emplace_back(this->Triples[t + r], this->Triples[t + c], lambda * stencil[r] * stencil[c]);
      }
    }
  }
  for (int i = 0; i < n; ++i)
  {
    entries.emplace_back(i, i, 1e-6 * lambda);
  }
  Eigen::SparseMatrix<double> m(n, n);
  m.setFromTriplets(entries.begin(), entries.end());
  m += a;
  Eigen::VectorXd s = m.diagonal();
  for (int i = 0; i < n; ++i)
  {
    s[i] = s[i] > 0 ? 1.0 / std::sqrt(s[i]) : 1.0;
  }
  const Eigen::SparseMatrix<double> scaledA = s.asDiagonal() * a * s.asDiagonal();
  const Eigen::SparseMatrix<double> scaledM = s.asDiagonal() * m * s.asDiagonal();
  const ThreeColumns target = s.asDiagonal() * (w.transpose() * rhs);
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(scaledM);
  if (ldlt.info() != Eigen::Success)
  {
    return false;
  }
  ThreeColumns y = ThreeColumns::Zero(n, 3);
  for (int step = 0; step < steps; ++step)
  {
    y += ldlt.solve(ThreeColumns(target - scaledA * y));
  }
  if (!y.allFinite())
  {
    return false;
  }
  for (int i = 0; i < n; ++i)
  {
    for (int c = 0; c < 3; ++c)
    {
      x[3 * std::size_t(i) + c] = s[i] * y(i, c);
    }
  }
  return true;
}

} // namespace ffd
