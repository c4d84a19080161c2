// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkFFDLatticeDynamics
 * @brief   simulates a lattice's active control points as a soft body and moves them in the lattice
 *
 * The paper's dynamic control body (section II): a lattice of vtkFFDBuildLattice (dense or sparse, any basis) or
 * vtkFFDBuildTetrahedralLattice becomes particles joined by penalty springs, pulled toward a rigid core, pushed by
 * gravity, magnetic spheres and impulses, held by pinned points and kept out of colliders. Each Step() writes the
 * new control point positions into the lattice's points, so a vtkFFDDeform downstream re-evaluates the mesh
 * without binding it again.
 *
 * - **Particles**: the active control points (`Active` 1; every point of a sparse lattice; every node of a
 *   tetrahedral lattice without `Active`). Culled control points are not simulated and never move.
 * - **Masses** from the mesh (SetMesh()): a control point's mass is TotalMass times its share of the mesh's points,
 *   sum over the points bound to the lattice of the control point's weight in their deformation, so a control point
 *   near no vertex is light. Each mass is at least MinimumMassFraction times the mean, so that no particle is
 *   weightless. Without a mesh every particle weighs the same.
 * - **Springs** of stiffness SpringStiffness and damping SpringDamping, at rest at their rest length: between
 *   control points one lattice step apart, and, with SpringNeighborhood, across the lattice's face and body
 *   diagonals; along the tetrahedra's edges for a tetrahedral lattice.
 * - **Rigid core**: each particle is pulled toward its place on the rest lattice moved by the best rigid motion of
 *   the current one (shape matching), with CoreStiffness per unit of mass: the body keeps its shape and can be
 *   pushed as a whole.
 * - **Time step**: backward Euler (ffd::SoftBody, Filters/Dynamics/FFDSoftBody.h, has the equations), stable far beyond
 *   the explicit limit (GetExplicitTimeStepLimit()); damping and the integrator take the energy to rest.
 *
 * Initialize() reads the lattice and the mesh and starts from the lattice's current points at rest (velocity 0,
 * time 0); Step() calls it when it has not run, or the lattice, the mesh, their rest state or the mass and spring
 * settings changed. Other settings (time step, stiffness, damping, forces, pins) take effect at the next step and
 * keep the state. Between steps the simulation owns the simulated points' positions: move a point by pinning it.
 *
 * @sa vtkFFDMagneticSphere vtkFFDSimulateLattice vtkFFDDeform
 */
#ifndef vtkFFDLatticeDynamics_h
#define vtkFFDLatticeDynamics_h

#include "vtkFFDFiltersDynamicsModule.h" // For export macro
#include "vtkObject.h"

#include <memory> // For std::unique_ptr

class vtkFFDMagneticSphere;
class vtkImplicitFunction;
class vtkPointSet;

class VTKFFDFILTERSDYNAMICS_EXPORT vtkFFDLatticeDynamics : public vtkObject
{
public:
  static vtkFFDLatticeDynamics* New();
  vtkTypeMacro(vtkFFDLatticeDynamics, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// The lattice to simulate; its points are moved by Step().
  virtual void SetLattice(vtkPointSet* lattice);
  vtkGetObjectMacro(Lattice, vtkPointSet);
  ///@}

  ///@{
  /// The mesh the lattice deforms, whose points give the masses (optional).
  virtual void SetMesh(vtkPointSet* mesh);
  vtkGetObjectMacro(Mesh, vtkPointSet);
  ///@}

  // Every setting below is checked where it is used (CheckSettings(), at each Initialize() and Step()): a value
  // out of its range is an error, never silently clamped.

  ///@{
  /// The time step h in seconds, > 0 (default 1/60).
  vtkSetMacro(TimeStep, double);
  vtkGetMacro(TimeStep, double);
  ///@}

  ///@{
  /// The mass of the whole body, > 0 (default 1).
  vtkSetMacro(TotalMass, double);
  vtkGetMacro(TotalMass, double);
  ///@}

  ///@{
  /// The least mass of a particle, as a fraction of the mean, in (0, 1] (default 0.01).
  vtkSetMacro(MinimumMassFraction, double);
  vtkGetMacro(MinimumMassFraction, double);
  ///@}

  ///@{
  /// A spring's force per unit of stretch, >= 0 (default 1).
  vtkSetMacro(SpringStiffness, double);
  vtkGetMacro(SpringStiffness, double);
  ///@}

  ///@{
  /// A spring's force per unit of relative velocity of its ends, >= 0 (default 0.01).
  vtkSetMacro(SpringDamping, double);
  vtkGetMacro(SpringDamping, double);
  ///@}

  ///@{
  /// The pull toward the rigid core per unit of mass and of distance, in 1/s^2, >= 0 (default 10; 0: no core).
  vtkSetMacro(CoreStiffness, double);
  vtkGetMacro(CoreStiffness, double);
  ///@}

  ///@{
  /// Local/global iterations of a step, from 1 to 1000 (default 10): more follow backward Euler more closely.
  vtkSetMacro(Iterations, int);
  vtkGetMacro(Iterations, int);
  ///@}

  ///@{
  /// Gravity, an acceleration, finite (default 0, 0, 0).
  vtkSetVector3Macro(Gravity, double);
  vtkGetVector3Macro(Gravity, double);
  ///@}

  enum SpringNeighborhoods
  {
    EDGES = 0,
    FACE_DIAGONALS = 1,
    BODY_DIAGONALS = 2
  };

  ///@{
  /**
   * Which control points of a grid lattice are joined: one step apart along an axis (EDGES), also across the
   * faces of a voxel (FACE_DIAGONALS), also across its body (BODY_DIAGONALS, the default: all 26 neighbours).
   * Tetrahedral lattices are joined along their edges.
   */
  vtkSetClampMacro(SpringNeighborhood, int, EDGES, BODY_DIAGONALS);
  vtkGetMacro(SpringNeighborhood, int);
  void SetSpringNeighborhoodToEdges() { this->SetSpringNeighborhood(EDGES); }
  void SetSpringNeighborhoodToFaceDiagonals() { this->SetSpringNeighborhood(FACE_DIAGONALS); }
  void SetSpringNeighborhoodToBodyDiagonals() { this->SetSpringNeighborhood(BODY_DIAGONALS); }
  ///@}

  ///@{
  /// Magnetic spheres that pull the control points (vtkFFDMagneticSphere).
  void AddMagneticSphere(vtkFFDMagneticSphere* sphere);
  void RemoveAllMagneticSpheres();
  int GetNumberOfMagneticSpheres();
  ///@}

  ///@{
  /**
   * Colliders: the control points are kept where the implicit function is >= 0 (outside a vtkSphere, in front
   * of a vtkPlane), moved onto its zero set along its gradient at the end of each step.
   */
  void AddCollider(vtkImplicitFunction* collider);
  void RemoveAllColliders();
  int GetNumberOfColliders();
  ///@}

  ///@{
  /**
   * Pinned points follow their targets (positions, moved at each step's end) whatever the forces: points dragged
   * in the lattice widget, for example. A pinned point must be simulated (Step() says which is not).
   */
  void PinPoint(vtkIdType pointId, double x, double y, double z);
  void PinPoint(vtkIdType pointId, const double target[3]) { this->PinPoint(pointId, target[0], target[1], target[2]); }
  void UnpinPoint(vtkIdType pointId);
  void UnpinAllPoints();
  int GetNumberOfPinnedPoints();
  ///@}

  /**
   * Changes a simulated point's momentum by an impulse at the next Step() (its velocity by impulse / mass),
   * whether or not the simulation has started: impulses are queued until a step applies them. Returns 1 when
   * queued, or 0 with an error where the impulse is not finite or the id is not a point of the lattice (or, once
   * the simulation has started, not a simulated one). A queued impulse that the next Step() finds on a point that
   * is not simulated is an error there and is dropped.
   */
  int ApplyImpulse(vtkIdType pointId, double x, double y, double z);

  /**
   * Reports the first setting that cannot be simulated (not finite, or out of its range: the time step, the
   * masses, the stiffnesses and damping, gravity, the magnetic spheres' settings and paths, the pins' targets) as
   * an error naming its setter. Returns 1 where every one can be. Initialize() and Step() call it.
   */
  int CheckSettings();

  /// Reads the lattice and the mesh and starts at rest from the lattice's points. Returns 1, or 0 after an error.
  int Initialize();

  /**
   * Advances `steps` (>= 0) time steps (ProgressEvents every 5 % of them from 20 steps). Returns 1, or 0 after an
   * error, which leaves the lattice's points and the simulation's state as they were before the call: a setting
   * that cannot be simulated, springs too stiff for the time step and the masses (their stiffness, plus damping
   * over the time step, times the time step squared over the lightest particle's mass above 1e8: the step's
   * linear solve would lose the body's motion to rounding), or a step whose positions are not finite (a force or
   * a collider too large or not finite there).
   */
  int Step(int steps = 1);

  ///@{
  /// The state: its time (s), particles and springs, energies and momentum.
  double GetTime();
  vtkIdType GetNumberOfSimulatedPoints();
  vtkIdType GetNumberOfSprings();
  double GetKineticEnergy();
  /// The springs' and the core's energy (gravity's and the spheres' potentials are left out).
  double GetPotentialEnergy();
  void GetMomentum(double momentum[3]);
  /// A point's mass, 0 where the point is not simulated.
  double GetMass(vtkIdType pointId);
  ///@}

  /// The largest stable time step of explicit Euler near rest (ffd::SoftBody::ExplicitTimeStepLimit()).
  double GetExplicitTimeStepLimit();

  /// Includes the magnetic spheres' and the colliders' modification times.
  vtkMTimeType GetMTime() override;

protected:
  vtkFFDLatticeDynamics();
  ~vtkFFDLatticeDynamics() override;

  vtkPointSet* Lattice;
  vtkPointSet* Mesh;
  double TimeStep;
  double TotalMass;
  double MinimumMassFraction;
  double SpringStiffness;
  double SpringDamping;
  double CoreStiffness;
  int Iterations;
  double Gravity[3];
  int SpringNeighborhood;

private:
  vtkFFDLatticeDynamics(const vtkFFDLatticeDynamics&) = delete;
  void operator=(const vtkFFDLatticeDynamics&) = delete;

  struct Internals;
  std::unique_ptr<Internals> Internal;
  int InitializeBody(); // Initialize() and Step() but for the allocations that fail
  int StepBody(int steps);
};

#endif
