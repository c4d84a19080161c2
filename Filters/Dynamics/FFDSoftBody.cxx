// SPDX-License-Identifier: BSD-3-Clause
#include "FFDSoftBody.h"

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <algorithm>
#include <cmath>
#include <limits>

namespace ffd
{
namespace
{
/// The same norm for rest and current springs, so that a spring at rest is exactly at its rest length.
double Norm(const double d[3])
{
  return std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
}
} // namespace

/**
 * The factored matrix of the free particles, P A P^T = L D L^T (Eigen's SimplicialLDLT), kept as plain arrays so
 * that a solve runs the three coordinates of a row together, reading each entry of L once for x, y and z
 * (Eigen's solve reads L once per column of the right-hand side).
 */
struct SoftBody::Factor
{
  std::vector<int> Row; ///< per particle: its row, -1 where pinned
  int Rows = 0;
  double Coupling = 0;            ///< k + c/h: minus a spring's off-diagonal entry
  std::vector<int> Permuted;      ///< row r of A is row Permuted[r] of P A P^T
  std::vector<int> ColumnStart;   ///< L's strictly lower part, by columns
  std::vector<int> LowerRow;      ///< its entries' rows
  std::vector<double> LowerValue; ///< and values
  std::vector<double> InverseD;   ///< 1 / D
  std::vector<double> Work;       ///< 3 per row

  /// x = A^-1 b for 3 values a row (b and x may be the same).
  void Solve(const double* b, double* x)
  {
    double* y = this->Work.data();
    for (int r = 0; r < this->Rows; ++r)
    {
      std::copy(b + 3 * r, b + 3 * r + 3, y + 3 * this->Permuted[r]);
    }
    for (int j = 0; j < this->Rows; ++j) // L y' = y
    {
      const double* yj = y + 3 * j;
      for (int p = this->ColumnStart[j]; p < this->ColumnStart[j + 1]; ++p)
      {
        double* yi = y + 3 * this->LowerRow[p];
        const double l = this->LowerValue[p];
        yi[0] -= l * yj[0];
        yi[1] -= l * yj[1];
        yi[2] -= l * yj[2];
      }
    }
    for (int j = 0; j < this->Rows; ++j) // D y'' = y'
    {
      for (int c = 0; c < 3; ++c)
      {
        y[3 * j + c] *= this->InverseD[j];
      }
    }
    for (int j = this->Rows - 1; j >= 0; --j) // L^T y''' = y''
    {
      double* yj = y + 3 * j;
      for (int p = this->ColumnStart[j]; p < this->ColumnStart[j + 1]; ++p)
      {
        const double* yi = y + 3 * this->LowerRow[p];
        const double l = this->LowerValue[p];
        yj[0] -= l * yi[0];
        yj[1] -= l * yi[1];
        yj[2] -= l * yi[2];
      }
    }
    for (int r = 0; r < this->Rows; ++r)
    {
      std::copy(y + 3 * this->Permuted[r], y + 3 * this->Permuted[r] + 3, x + 3 * r);
    }
  }
};

SoftBody::SoftBody() = default;
SoftBody::~SoftBody() = default;

//------------------------------------------------------------------------------------------------------------
std::string SoftBody::SetUp(
  std::vector<double> restPositions, std::vector<double> masses, std::vector<std::array<int, 2>> springs)
{
  const std::size_t n = masses.size();
  if (restPositions.size() != 3 * n)
  {
    return "The rest positions are not 3 a particle.";
  }
  for (const double m : masses)
  {
    if (!(m > 0) || !std::isfinite(m))
    {
      return "A particle's mass is not a positive number.";
    }
  }
  std::vector<double> restVector(3 * springs.size()), restLength(springs.size());
  for (std::size_t s = 0; s < springs.size(); ++s)
  {
    const int a = springs[s][0], b = springs[s][1];
    if (a < 0 || b < 0 || std::size_t(a) >= n || std::size_t(b) >= n || a == b)
    {
      return "Spring " + std::to_string(s) + " does not join two particles.";
    }
    double* d = &restVector[3 * s];
    for (int c = 0; c < 3; ++c)
    {
      d[c] = restPositions[3 * b + c] - restPositions[3 * a + c];
    }
    restLength[s] = Norm(d);
    if (!(restLength[s] > 0) || !std::isfinite(restLength[s]))
    {
      return "The ends of spring " + std::to_string(s) + " are at the same place at rest.";
    }
  }
  this->TotalMass = 0;
  double centre[3] = { 0, 0, 0 };
  for (std::size_t i = 0; i < n; ++i)
  {
    this->TotalMass += masses[i];
    for (int c = 0; c < 3; ++c)
    {
      centre[c] += masses[i] * restPositions[3 * i + c];
    }
  }
  Eigen::Matrix3d qq = Eigen::Matrix3d::Zero();
  this->Centered.assign(3 * n, 0.0);
  for (std::size_t i = 0; i < n; ++i)
  {
    Eigen::Vector3d q;
    for (int c = 0; c < 3; ++c)
    {
      q[c] = this->Centered[3 * i + c] = restPositions[3 * i + c] - centre[c] / this->TotalMass;
    }
    qq += masses[i] * q * q.transpose();
  }
  // A flat or single-particle body has a singular qq: its pseudo-inverse matches what there is to match.
  const Eigen::Matrix3d inverse = qq.completeOrthogonalDecomposition().pseudoInverse();
  for (int r = 0; r < 3; ++r)
  {
    for (int c = 0; c < 3; ++c)
    {
      this->InverseQQ[r][c] = inverse(r, c);
    }
  }
  this->Rest = std::move(restPositions);
  this->Mass = std::move(masses);
  this->Springs = std::move(springs);
  this->RestVector = std::move(restVector);
  this->RestLength = std::move(restLength);
  this->Pinned.assign(n, 0);
  this->U.assign(3 * n, 0.0);
  this->V.assign(3 * n, 0.0);
  this->Solver.reset();
  return std::string();
}

//------------------------------------------------------------------------------------------------------------
void SoftBody::SetSettings(const SoftBodySettings& settings)
{
  const SoftBodySettings& old = this->Settings;
  if (settings.TimeStep != old.TimeStep || settings.SpringStiffness != old.SpringStiffness ||
    settings.SpringDamping != old.SpringDamping || settings.CoreStiffness != old.CoreStiffness)
  {
    this->Solver.reset();
  }
  this->Settings = settings;
}

//------------------------------------------------------------------------------------------------------------
void SoftBody::SetPinned(std::vector<unsigned char> pinned)
{
  pinned.resize(this->Mass.size(), 0);
  if (pinned != this->Pinned)
  {
    this->Pinned = std::move(pinned);
    this->Solver.reset();
  }
}

//------------------------------------------------------------------------------------------------------------
bool SoftBody::Factorize()
{
  const SoftBodySettings& s = this->Settings;
  const double h = s.TimeStep;
  auto factor = std::make_unique<Factor>();
  factor->Row.assign(this->Mass.size(), -1);
  for (std::size_t i = 0; i < this->Mass.size(); ++i)
  {
    if (!this->Pinned[i])
    {
      factor->Row[i] = factor->Rows++;
    }
  }
  factor->Coupling = s.SpringStiffness + s.SpringDamping / h;
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(this->Mass.size() + 4 * this->Springs.size());
  for (std::size_t i = 0; i < this->Mass.size(); ++i)
  {
    if (factor->Row[i] >= 0)
    {
      const double m = this->Mass[i];
      entries.emplace_back(factor->Row[i], factor->Row[i], m / (h * h) + s.CoreStiffness * m);
    }
  }
  for (const auto& spring : this->Springs)
  {
    const int a = factor->Row[spring[0]], b = factor->Row[spring[1]];
    for (const int r : { a, b })
    {
      if (r >= 0)
      {
        entries.emplace_back(r, r, factor->Coupling);
      }
    }
    if (a >= 0 && b >= 0)
    {
      entries.emplace_back(a, b, -factor->Coupling);
      entries.emplace_back(b, a, -factor->Coupling);
    }
  }
  Eigen::SparseMatrix<double> matrix(factor->Rows, factor->Rows);
  matrix.setFromTriplets(entries.begin(), entries.end());
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(matrix);
  if (ldlt.info() != Eigen::Success)
  {
    return false;
  }
  // P b scatters b[r] to row indices()[r] (Eigen's PermutationMatrix); L holds its strictly lower part (unit
  // diagonal) in compressed columns.
  const auto& permutation = ldlt.permutationP().indices();
  factor->Permuted.assign(permutation.data(), permutation.data() + factor->Rows);
  const Eigen::SparseMatrix<double>& lower = ldlt.matrixL().nestedExpression();
  factor->ColumnStart.assign(1, 0);
  for (int j = 0; j < lower.outerSize(); ++j)
  {
    for (Eigen::SparseMatrix<double>::InnerIterator entry(lower, j); entry; ++entry)
    {
      if (entry.row() > j)
      {
        factor->LowerRow.push_back(int(entry.row()));
        factor->LowerValue.push_back(entry.value());
      }
    }
    factor->ColumnStart.push_back(int(factor->LowerRow.size()));
  }
  factor->InverseD.resize(factor->Rows);
  for (int j = 0; j < factor->Rows; ++j)
  {
    factor->InverseD[j] = 1.0 / ldlt.vectorD()[j];
  }
  factor->Work.assign(3 * std::size_t(factor->Rows), 0.0);
  this->Solver = std::move(factor);
  return true;
}

//------------------------------------------------------------------------------------------------------------
SoftBody::Core SoftBody::RigidCore(const std::vector<double>& u) const
{
  const std::size_t n = this->Mass.size();
  Core core{};
  for (std::size_t i = 0; i < n; ++i)
  {
    for (int c = 0; c < 3; ++c)
    {
      core.Shift[c] += this->Mass[i] * u[3 * i + c];
    }
  }
  for (double& shift : core.Shift)
  {
    shift /= this->TotalMass;
  }
  // The shape-matching matrix I + sum m (u - mean u) q^T (sum m q q^T)^-1, kept as its difference from I, whose
  // rotation R = U V^T (of its SVD U S V^T) is exactly I at rest.
  Eigen::Matrix3d pq = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < n; ++i)
  {
    const Eigen::Vector3d du(u[3 * i] - core.Shift[0], u[3 * i + 1] - core.Shift[1], u[3 * i + 2] - core.Shift[2]);
    const Eigen::Vector3d q(this->Centered[3 * i], this->Centered[3 * i + 1], this->Centered[3 * i + 2]);
    pq += this->Mass[i] * du * q.transpose();
  }
  Eigen::Matrix3d inverseQQ;
  for (int r = 0; r < 3; ++r)
  {
    for (int c = 0; c < 3; ++c)
    {
      inverseQQ(r, c) = this->InverseQQ[r][c];
    }
  }
  const Eigen::Matrix3d shape = Eigen::Matrix3d::Identity() + pq * inverseQQ;
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(shape, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d left = svd.matrixU();
  if ((left * svd.matrixV().transpose()).determinant() < 0)
  {
    left.col(2) = -left.col(2); // a rotation, not a reflection
  }
  const Eigen::Matrix3d rotation = left * svd.matrixV().transpose() - Eigen::Matrix3d::Identity();
  for (int r = 0; r < 3; ++r)
  {
    for (int c = 0; c < 3; ++c)
    {
      core.Rotation[r][c] = rotation(r, c);
    }
  }
  return core;
}

//------------------------------------------------------------------------------------------------------------
void SoftBody::SpringVector(const std::vector<double>& u, std::size_t k, double d[3]) const
{
  const int a = this->Springs[k][0], b = this->Springs[k][1];
  for (int c = 0; c < 3; ++c)
  {
    d[c] = this->RestVector[3 * k + c] + (u[3 * b + c] - u[3 * a + c]);
  }
}

//------------------------------------------------------------------------------------------------------------
std::vector<double> SoftBody::InertiaRightHandSide(
  const std::vector<double>& acceleration, const std::vector<double>& targets, std::vector<double>& u) const
{
  const double h = this->Settings.TimeStep;
  const std::size_t n = this->Mass.size();
  const bool accelerated = acceleration.size() == 3 * n;
  const Factor& factor = *this->Solver;
  std::vector<double> fixed(3 * std::size_t(factor.Rows));
  u = this->U;
  for (std::size_t i = 0; i < n; ++i)
  {
    const int r = factor.Row[i];
    for (int c = 0; c < 3; ++c)
    {
      const double y =
        this->U[3 * i + c] + h * this->V[3 * i + c] + (accelerated ? h * h * acceleration[3 * i + c] : 0);
      if (r >= 0)
      {
        fixed[3 * r + c] = this->Mass[i] / (h * h) * y;
        u[3 * i + c] = y; // the iterations start from the momentum's guess
      }
      else
      {
        u[3 * i + c] = targets[3 * i + c];
      }
    }
  }
  return fixed;
}

void SoftBody::AddDampingAndPinnedSprings(const std::vector<double>& u, std::vector<double>& fixed) const
{
  const Factor& factor = *this->Solver;
  const double damping = this->Settings.SpringDamping / this->Settings.TimeStep;
  for (const auto& spring : this->Springs)
  {
    const int a = spring[0], b = spring[1];
    const int ra = factor.Row[a], rb = factor.Row[b];
    for (int c = 0; c < 3; ++c)
    {
      const double relative = damping * (this->U[3 * b + c] - this->U[3 * a + c]);
      if (ra >= 0)
      {
        fixed[3 * ra + c] -= relative - (rb < 0 ? factor.Coupling * u[3 * b + c] : 0.0);
      }
      if (rb >= 0)
      {
        fixed[3 * rb + c] += relative + (ra < 0 ? factor.Coupling * u[3 * a + c] : 0.0);
      }
    }
  }
}

void SoftBody::AddSpringPulls(const std::vector<double>& u, std::vector<double>& rhs) const
{
  const Factor& factor = *this->Solver;
  for (std::size_t k = 0; k < this->Springs.size(); ++k)
  {
    const int a = this->Springs[k][0], b = this->Springs[k][1];
    const double* rest = &this->RestVector[3 * k];
    double d[3];
    this->SpringVector(u, k, d);
    const double length = Norm(d);
    if (!(length > 0))
    {
      continue; // no direction to restore: the spring pulls toward its rest vector, k (p - D) = 0
    }
    const double scale = this->RestLength[k] / length;
    const int ra = factor.Row[a], rb = factor.Row[b];
    for (int c = 0; c < 3; ++c)
    {
      const double pull = this->Settings.SpringStiffness * (d[c] * scale - rest[c]); // k (p - D)
      if (ra >= 0)
      {
        rhs[3 * ra + c] -= pull;
      }
      if (rb >= 0)
      {
        rhs[3 * rb + c] += pull;
      }
    }
  }
}

void SoftBody::AddCorePull(const std::vector<double>& u, std::vector<double>& rhs) const
{
  const Factor& factor = *this->Solver;
  const Core core = this->RigidCore(u);
  for (std::size_t i = 0; i < this->Mass.size(); ++i)
  {
    const int r = factor.Row[i];
    if (r < 0)
    {
      continue;
    }
    for (int c = 0; c < 3; ++c)
    {
      rhs[3 * r + c] += this->Settings.CoreStiffness * this->Mass[i] * core.Goal(&this->Centered[3 * i], c);
    }
  }
}

void SoftBody::SolveGlobalStep(std::vector<double>& rhs, std::vector<double>& u)
{
  Factor& factor = *this->Solver;
  factor.Solve(rhs.data(), rhs.data());
  for (std::size_t i = 0; i < this->Mass.size(); ++i)
  {
    const int r = factor.Row[i];
    if (r >= 0)
    {
      std::copy(&rhs[3 * r], &rhs[3 * r] + 3, &u[3 * i]);
    }
  }
}

//------------------------------------------------------------------------------------------------------------
bool SoftBody::Step(const std::vector<double>& acceleration, const std::vector<double>& targets,
  const std::function<void(std::vector<double>&)>& constrain)
{
  if (!this->Solver && !this->Factorize())
  {
    return false;
  }
  const SoftBodySettings& s = this->Settings;
  const double h = s.TimeStep;
  const std::size_t n = this->Mass.size();

  // The parts of the right-hand side that stay through the iterations: inertia, the springs' damping, and the
  // springs to pinned particles (at their targets). 3 values a row.
  std::vector<double> u;
  std::vector<double> fixed = this->InertiaRightHandSide(acceleration, targets, u);
  this->AddDampingAndPinnedSprings(u, fixed);

  std::vector<double> rhs(fixed.size());
  for (int iteration = 0; iteration < std::max(1, s.Iterations); ++iteration)
  {
    rhs = fixed;
    // Local step: each spring scaled to its rest length, each particle's place on the rigid core.
    this->AddSpringPulls(u, rhs);
    if (s.CoreStiffness > 0)
    {
      this->AddCorePull(u, rhs);
    }
    this->SolveGlobalStep(rhs, u);
  }
  if (constrain)
  {
    constrain(u);
  }
  if (!std::all_of(u.begin(), u.end(), [](double value) { return std::isfinite(value); }))
  {
    return false; // the state stays as it was
  }
  for (std::size_t j = 0; j < 3 * n; ++j)
  {
    this->V[j] = (u[j] - this->U[j]) / h;
  }
  this->U = std::move(u);
  return true;
}

//------------------------------------------------------------------------------------------------------------
double SoftBody::KineticEnergy() const
{
  double energy = 0;
  for (std::size_t i = 0; i < this->Mass.size(); ++i)
  {
    const double* v = &this->V[3 * i];
    energy += 0.5 * this->Mass[i] * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  }
  return energy;
}

double SoftBody::SpringEnergy() const
{
  double energy = 0;
  for (std::size_t k = 0; k < this->Springs.size(); ++k)
  {
    double d[3];
    this->SpringVector(this->U, k, d);
    const double stretch = Norm(d) - this->RestLength[k];
    energy += 0.5 * this->Settings.SpringStiffness * stretch * stretch;
  }
  return energy;
}

double SoftBody::CoreEnergy() const
{
  if (this->Settings.CoreStiffness <= 0 || this->Mass.empty())
  {
    return 0;
  }
  const Core core = this->RigidCore(this->U);
  double energy = 0;
  for (std::size_t i = 0; i < this->Mass.size(); ++i)
  {
    double squared = 0;
    for (int c = 0; c < 3; ++c)
    {
      const double off = this->U[3 * i + c] - core.Goal(&this->Centered[3 * i], c);
      squared += off * off;
    }
    energy += 0.5 * this->Settings.CoreStiffness * this->Mass[i] * squared;
  }
  return energy;
}

std::array<double, 3> SoftBody::Momentum() const
{
  std::array<double, 3> p = { 0, 0, 0 };
  for (std::size_t i = 0; i < this->Mass.size(); ++i)
  {
    for (int c = 0; c < 3; ++c)
    {
      p[c] += this->Mass[i] * this->V[3 * i + c];
    }
  }
  return p;
}

//------------------------------------------------------------------------------------------------------------
void SoftBody::MultiplyRestHessian(const std::vector<double>& x, std::vector<double>& y) const
{
  // H x at rest: each spring k D^ D^T (x_b - x_a) (its stiffness along itself), and kappa m x for the core.
  const std::size_t n = this->Mass.size();
  const SoftBodySettings& s = this->Settings;
  for (std::size_t i = 0; i < n; ++i)
  {
    for (int c = 0; c < 3; ++c)
    {
      y[3 * i + c] = s.CoreStiffness * this->Mass[i] * x[3 * i + c];
    }
  }
  for (std::size_t k = 0; k < this->Springs.size(); ++k)
  {
    const int a = this->Springs[k][0], b = this->Springs[k][1];
    const double* d = &this->RestVector[3 * k];
    const double l2 = this->RestLength[k] * this->RestLength[k];
    double along = 0;
    for (int c = 0; c < 3; ++c)
    {
      along += d[c] * (x[3 * b + c] - x[3 * a + c]);
    }
    for (int c = 0; c < 3; ++c)
    {
      const double f = s.SpringStiffness * along * d[c] / l2;
      y[3 * a + c] -= f;
      y[3 * b + c] += f;
    }
  }
  for (std::size_t i = 0; i < n; ++i)
  {
    for (int c = 0; c < 3; ++c)
    {
      y[3 * i + c] = this->Pinned[i] ? 0.0 : y[3 * i + c];
    }
  }
}

std::vector<double> SoftBody::PowerIterationStart() const
{
  // Fixed and pseudo-random, so that the limit is the same every call; zero at pinned particles.
  std::vector<double> x(3 * this->Mass.size());
  std::uint32_t seed = 12345u;
  for (std::size_t j = 0; j < x.size(); ++j)
  {
    seed = seed * 1664525u + 1013904223u;
    x[j] = this->Pinned[j / 3] ? 0.0 : double(seed >> 8) / double(1u << 24) - 0.5;
  }
  return x;
}

double SoftBody::ExplicitTimeStepLimit() const
{
  const std::size_t n = this->Mass.size();
  // Power iteration on M^-1 H (self-adjoint for the M inner product) from a fixed pseudo-random start.
  std::vector<double> x = this->PowerIterationStart(), y(3 * n);
  double lambda = 0;
  for (int iteration = 0; iteration < 1000; ++iteration)
  {
    double norm = 0;
    for (std::size_t j = 0; j < 3 * n; ++j)
    {
      norm += this->Mass[j / 3] * x[j] * x[j];
    }
    if (!(norm > 0))
    {
      break;
    }
    norm = std::sqrt(norm);
    for (double& value : x)
    {
      value /= norm;
    }
    this->MultiplyRestHessian(x, y);
    double rayleigh = 0;
    for (std::size_t j = 0; j < 3 * n; ++j)
    {
      rayleigh += x[j] * y[j];
    }
    for (std::size_t j = 0; j < 3 * n; ++j)
    {
      x[j] = y[j] / this->Mass[j / 3];
    }
    const bool converged = std::abs(rayleigh - lambda) <= 1e-9 * rayleigh;
    lambda = rayleigh;
    if (converged && iteration > 10)
    {
      break;
    }
  }
  return lambda > 0 ? 2.0 / std::sqrt(lambda) : std::numeric_limits<double>::infinity();
}
} // namespace ffd
