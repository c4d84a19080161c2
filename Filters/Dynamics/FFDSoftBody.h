// SPDX-License-Identifier: BSD-3-Clause
/**
 * ffd::SoftBody: particles joined by penalty springs and pulled toward a rigid core, advanced by backward Euler.
 *
 * The paper's control body (section II): "an interconnected set of rigid elements that can be solved using
 * iterative penalty-based constraints", "a set of deformable body elements and a rigid body core", stable under
 * large time steps. VTK-free (vtkFFDLatticeDynamics gives it a lattice's control points); Eigen stays in the
 * .cxx. Positions are rest positions X plus displacements u, and every term is computed from u, so that a body
 * at rest feels exactly no force: no drift, however many steps.
 *
 * A step minimises over the new displacements u (projective dynamics, Bouaziz et al. 2014: backward Euler for
 * these energies, solved by local/global iterations)
 *   1/(2h^2) |u - y|_M^2 + sum_springs k/2 |(u_j - u_i) - (p_ij - D_ij)|^2 + sum_i w_i/2 |u_i - (g_i - X_i)|^2
 *   + sum_springs c/(2h) |(u_j - u_i) - (u_j - u_i)_n|^2,   y = u_n + h v_n + h^2 a_ext,
 * where D_ij = X_j - X_i, p_ij is the current spring scaled to its rest length |D_ij|, and g_i = R (X_i - C0) + c
 * the particle's place on the rigid core: the rest shape under the rotation R (polar part of the shape-matching
 * matrix, Mueller et al. 2005) and translation to the current centre of mass c; w_i = kappa m_i, so the core
 * leaves momentum alone. The local step computes p and g from the current u, the global step solves the linear
 * system, whose matrix M/h^2 + (k + c/h) L + W (L the springs' graph Laplacian, W = diag w) depends only on the
 * settings and the pinned particles: it is factored once (Eigen's SimplicialLDLT) and reused by every step.
 * Pinned particles are moved to their targets and leave the system. The springs' damping acts on the relative
 * velocity of their ends: it leaves a translation alone but slows a spin too.
 */
#ifndef FFDSoftBody_h
#define FFDSoftBody_h

#include <array>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace ffd
{
struct SoftBodySettings
{
  double TimeStep = 1.0 / 60.0; ///< h (s)
  double SpringStiffness = 1.0; ///< k: a spring's force per unit of stretch
  double SpringDamping = 0.0;   ///< c: a spring's force per unit of relative velocity of its ends
  double CoreStiffness = 0.0;   ///< kappa: pull toward the rigid core per unit of mass and distance (1/s^2)
  int Iterations = 10;          ///< local/global iterations a step
};

class SoftBody
{
public:
  SoftBody();
  ~SoftBody();
  SoftBody(const SoftBody&) = delete;
  SoftBody& operator=(const SoftBody&) = delete;

  /**
   * The body: rest positions (3 a particle), masses (one a particle, each > 0) and springs (pairs of particle
   * indices, each once, their ends apart at rest). Resets the state to rest, nothing pinned. Returns an empty
   * string, or what is wrong.
   */
  std::string SetUp(
    std::vector<double> restPositions, std::vector<double> masses, std::vector<std::array<int, 2>> springs);

  /// Settings take effect at the next Step(); the state is kept.
  void SetSettings(const SoftBodySettings& settings);
  const SoftBodySettings& GetSettings() const { return this->Settings; }

  /// Pinned particles (one flag a particle, empty: none) follow the targets given to Step().
  void SetPinned(std::vector<unsigned char> pinned);

  /// The rest positions of SetUp(), 3 a particle.
  const std::vector<double>& GetRestPositions() const { return this->Rest; }

  ///@{
  /// The state: displacements from rest and velocities, 3 a particle.
  std::vector<double>& Displacements() { return this->U; }
  std::vector<double>& Velocities() { return this->V; }
  const std::vector<double>& Displacements() const { return this->U; }
  const std::vector<double>& Velocities() const { return this->V; }
  ///@}

  /**
   * Advances one time step. `acceleration`: external accelerations (3 a particle), or empty for none;
   * `targets`: each pinned particle's displacement at the end of the step (3 a particle, read at pinned ones
   * only); `constrain` (may be empty) moves the new displacements out of colliders before the velocities are
   * taken from them. Returns false, leaving the state as it was, where the system could not be factored (a
   * non-finite setting) or the new displacements are not finite.
   */
  bool Step(const std::vector<double>& acceleration, const std::vector<double>& targets,
    const std::function<void(std::vector<double>& displacements)>& constrain);

  ///@{
  /// Energies of the state: kinetic, of the springs, of the core's pull; and its linear momentum.
  double KineticEnergy() const;
  double SpringEnergy() const;
  double CoreEnergy() const;
  std::array<double, 3> Momentum() const;
  ///@}

  /**
   * The largest time step at which explicit (symplectic) Euler stays stable near rest with these masses,
   * springs and core and no damping: 2 / omega_max, omega_max^2 the largest eigenvalue of M^-1 H at rest
   * (H the Hessian of the springs and of the core's pull), from power iteration. Pinned particles count as
   * fixed. Infinite without springs or core.
   */
  double ExplicitTimeStepLimit() const;

  double GetMass(int particle) const { return this->Mass[particle]; }
  int GetNumberOfParticles() const { return static_cast<int>(this->Mass.size()); }
  int GetNumberOfSprings() const { return static_cast<int>(this->Springs.size()); }

private:
  struct Factor;
  struct Core
  {
    double Rotation[3][3]; ///< R - I (exactly zero at rest)
    double Shift[3];       ///< c - C0: the mean displacement

    /// Coordinate c of g - X, the displacement of a particle at q = X - C0 on the core.
    double Goal(const double q[3], int c) const
    {
      return this->Rotation[c][0] * q[0] + this->Rotation[c][1] * q[1] + this->Rotation[c][2] * q[2] + this->Shift[c];
    }
  };
  Core RigidCore(const std::vector<double>& u) const;
  /// Spring k's vector x_b - x_a at displacements u, from its rest vector (exactly it at rest).
  void SpringVector(const std::vector<double>& u, std::size_t k, double d[3]) const;
  bool Factorize();

  ///@{
  /// Steps of Step(). The right-hand side that stays through the iterations: inertia (u starts at the
  /// momentum's guess, pinned particles at their targets), then the springs' damping and the springs to pinned
  /// particles. The local step adds each spring's pull toward its rest length and each particle's pull toward the
  /// rigid core; the global step solves for the free particles' displacements.
  std::vector<double> InertiaRightHandSide(
    const std::vector<double>& acceleration, const std::vector<double>& targets, std::vector<double>& u) const;
  void AddDampingAndPinnedSprings(const std::vector<double>& u, std::vector<double>& fixed) const;
  void AddSpringPulls(const std::vector<double>& u, std::vector<double>& rhs) const;
  void AddCorePull(const std::vector<double>& u, std::vector<double>& rhs) const;
  void SolveGlobalStep(std::vector<double>& rhs, std::vector<double>& u);
  ///@}

  ///@{
  /// Steps of ExplicitTimeStepLimit(): y = H x at rest (zero at pinned particles), and the power iteration's start.
  void MultiplyRestHessian(const std::vector<double>& x, std::vector<double>& y) const;
  std::vector<double> PowerIterationStart() const;
  ///@}

  std::vector<double> Rest;
  std::vector<double> Mass;
  std::vector<std::array<int, 2>> Springs;
  std::vector<double> RestVector; ///< D_ij, 3 a spring
  std::vector<double> RestLength; ///< |D_ij|
  std::vector<double> Centered;   ///< X_i - C0, 3 a particle
  double TotalMass = 0;
  double InverseQQ[3][3] = {}; ///< (sum m q q^T)^-1 (pseudo-inverse for a flat body)
  std::vector<unsigned char> Pinned;
  SoftBodySettings Settings;
  std::vector<double> U, V;
  std::unique_ptr<Factor> Solver; ///< null: factor at the next Step()
};
} // namespace ffd

#endif
