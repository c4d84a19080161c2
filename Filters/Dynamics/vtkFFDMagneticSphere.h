// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkFFDMagneticSphere
 * @brief   a sphere that pulls (or pushes) the control points near it: the paper's magnetic sphere (Figure 1)
 *
 * A force field for vtkFFDLatticeDynamics. A control point at distance d from the centre is accelerated along
 * the line to the centre, toward it (ATTRACT) or away from it (REPEL), by
 *   a(d) = Strength * (Radius / d)^Falloff  outside the sphere (d >= Radius),
 *   a(d) = Strength * d / Radius            inside it,
 * so that the pull is Strength at the surface, falls off with distance (Falloff 2: as the inverse square) and
 * vanishes smoothly at the centre instead of flipping there. It is an acceleration, like gravity: a point's
 * force is its mass times a(d), so the pull does not depend on how the mesh's points are shared among the
 * control points. Points farther than Range (when positive) feel nothing.
 *
 * The sphere moves along a closed path when one is set: the centre at time t is the point at parameter
 * t / Period (modulo 1) of a closed vtkParametricSpline through the path's points; otherwise it stays at Center.
 *
 * @sa vtkFFDLatticeDynamics vtkFFDSimulateLattice
 */
#ifndef vtkFFDMagneticSphere_h
#define vtkFFDMagneticSphere_h

#include "vtkFFDFiltersDynamicsModule.h" // For export macro
#include "vtkObject.h"

class vtkParametricSpline;
class vtkPoints;

class VTKFFDFILTERSDYNAMICS_EXPORT vtkFFDMagneticSphere : public vtkObject
{
public:
  static vtkFFDMagneticSphere* New();
  vtkTypeMacro(vtkFFDMagneticSphere, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  // The settings are checked where they are used (vtkFFDLatticeDynamics::CheckSettings()): a value out of its
  // range is an error there, never silently clamped.

  ///@{
  /// The centre without a path, finite (default 0, 0, 0).
  vtkSetVector3Macro(Center, double);
  vtkGetVector3Macro(Center, double);
  ///@}

  ///@{
  /// The sphere's radius, greater than 0 (default 1).
  vtkSetMacro(Radius, double);
  vtkGetMacro(Radius, double);
  ///@}

  ///@{
  /// The acceleration at the sphere's surface, at least 0 (default 1).
  vtkSetMacro(Strength, double);
  vtkGetMacro(Strength, double);
  ///@}

  ///@{
  /// The exponent of the pull's decrease with distance outside the sphere, at least 0 (default 2).
  vtkSetMacro(Falloff, double);
  vtkGetMacro(Falloff, double);
  ///@}

  ///@{
  /// The distance from the centre beyond which nothing is pulled; 0 (the default): no limit.
  vtkSetMacro(Range, double);
  vtkGetMacro(Range, double);
  ///@}

  enum Modes
  {
    ATTRACT = 0,
    REPEL = 1
  };

  ///@{
  /// Whether the sphere pulls points toward it or pushes them away (default ATTRACT).
  vtkSetClampMacro(Mode, int, ATTRACT, REPEL);
  vtkGetMacro(Mode, int);
  void SetModeToAttract() { this->SetMode(ATTRACT); }
  void SetModeToRepel() { this->SetMode(REPEL); }
  ///@}

  ///@{
  /**
   * The path: at least 2 points, through which the centre moves along a closed spline, once every Period (> 0)
   * seconds. Null (the default): the centre stays at Center.
   */
  void SetPath(vtkPoints* path);
  vtkGetObjectMacro(Path, vtkPoints);
  vtkSetMacro(Period, double);
  vtkGetMacro(Period, double);
  ///@}

  /// The centre at time t.
  void GetCenterAt(double t, double center[3]);

  /// The acceleration a(d) of a point at x at time t (see above).
  void GetAcceleration(const double x[3], double t, double acceleration[3]);

  /// The acceleration of a point at x with the sphere's centre at `center` (GetCenterAt()): for many points at
  /// one time, the centre found once.
  void GetAccelerationAround(const double center[3], const double x[3], double acceleration[3]);

  /// Includes the path's modification time.
  vtkMTimeType GetMTime() override;

protected:
  vtkFFDMagneticSphere();
  ~vtkFFDMagneticSphere() override;

  double Center[3];
  double Radius;
  double Strength;
  double Falloff;
  double Range;
  int Mode;
  vtkPoints* Path;
  double Period;

private:
  vtkFFDMagneticSphere(const vtkFFDMagneticSphere&) = delete;
  void operator=(const vtkFFDMagneticSphere&) = delete;

  vtkParametricSpline* Spline; // through Path
};

#endif
