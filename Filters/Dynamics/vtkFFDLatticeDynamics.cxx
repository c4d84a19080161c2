// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDLatticeDynamics.h"

#include "vtkFFDDataContract.h"
#include "vtkFFDLatticeBody.h"
#include "vtkFFDMagneticSphere.h"

#include "vtkCommand.h"
#include "vtkDataArray.h"
#include "vtkImplicitFunction.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkSmartPointer.h"

#include "FFDSoftBody.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <new>
#include <sstream>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkFFDLatticeDynamics);
vtkCxxSetObjectMacro(vtkFFDLatticeDynamics, Lattice, vtkPointSet);
vtkCxxSetObjectMacro(vtkFFDLatticeDynamics, Mesh, vtkPointSet);

//------------------------------------------------------------------------------------------------------------
struct vtkFFDLatticeDynamics::Internals
{
  ffd::SoftBody Body;
  bool Ready = false;
  std::vector<vtkIdType> PointOf; // per particle: its lattice point
  std::vector<int> ParticleOf;    // per lattice point: its particle, -1 where not simulated
  double Time = 0;
  // What the body was built from (NeedsInitialize()).
  vtkPointSet* Lattice = nullptr;
  vtkPointSet* Mesh = nullptr;
  vtkIdType LatticePoints = -1;
  const void* Rest = nullptr;
  vtkMTimeType RestTime = 0;
  vtkMTimeType MeshTime = 0;
  double TotalMass = 0, MinimumMassFraction = 0;
  int SpringNeighborhood = -1;

  std::vector<vtkSmartPointer<vtkFFDMagneticSphere>> Spheres;
  std::vector<vtkSmartPointer<vtkImplicitFunction>> Colliders;
  std::map<vtkIdType, std::array<double, 3>> Pins;
  std::map<vtkIdType, std::array<double, 3>> Impulses; // queued until a step applies them

  /// The particle of lattice point `id`, -1 where it is not simulated (or not a point of the lattice).
  int ParticleOfPoint(vtkIdType id) const
  {
    return id >= 0 && id < vtkIdType(this->ParticleOf.size()) ? this->ParticleOf[id] : -1;
  }
  std::string PinnedParticles(std::vector<unsigned char>& pinned, std::vector<double>& targets) const;
  std::string ApplyImpulses();
  std::string SpringsTooStiff(const ffd::SoftBodySettings& settings) const;
  /// Advances `steps` steps; ProgressEvents on `owner`. An empty string, or why a step failed.
  std::string Advance(int steps, const double gravity[3], const std::vector<unsigned char>& pinned,
    const std::vector<double>& targets, vtkObject* owner);
  /// Moves the unpinned particles of displacements `u` out of the colliders; `notFinite`: the first collider (if
  /// less than it) whose value is not a number at a particle.
  void Collide(std::vector<double>& u, const std::vector<unsigned char>& pinned, std::size_t& notFinite) const;
};

namespace
{
/// The soft body's settings from the dynamics' own.
ffd::SoftBodySettings SettingsOf(vtkFFDLatticeDynamics& dynamics)
{
  ffd::SoftBodySettings settings;
  settings.TimeStep = dynamics.GetTimeStep();
  settings.SpringStiffness = dynamics.GetSpringStiffness();
  settings.SpringDamping = dynamics.GetSpringDamping();
  settings.CoreStiffness = dynamics.GetCoreStiffness();
  settings.Iterations = dynamics.GetIterations();
  return settings;
}

/// Where `value` is not finite or outside its range ([least, inf), or (least, inf) where `exclusive`, up to `most`):
/// an error naming the `setter` and what the value is; else an empty string.
std::string OutOfRange(const std::string& setter, double value, const char* what, double least, bool exclusive,
  double most = std::numeric_limits<double>::max())
{
  if (std::isfinite(value) && (exclusive ? value > least : value >= least) && value <= most)
  {
    return std::string();
  }
  std::ostringstream why;
  why << setter << "(" << value << "): " << what << " must be a finite number " << (exclusive ? "> " : ">= ") << least;
  if (most < std::numeric_limits<double>::max())
  {
    why << " and <= " << most;
  }
  why << ".";
  return why.str();
}

/// Where a vector is not finite: an error naming the `setter` (called with `before` its first arguments).
std::string NotFinite(const std::string& setter, const std::string& before, const double x[3], const char* what)
{
  if (std::isfinite(x[0]) && std::isfinite(x[1]) && std::isfinite(x[2]))
  {
    return std::string();
  }
  std::ostringstream why;
  why << setter << "(" << before << x[0] << ", " << x[1] << ", " << x[2] << "): " << what << " must be finite.";
  return why.str();
}

/// Adds to `problems` those of the settings of magnetic sphere `index`.
void CheckSphere(vtkFFDMagneticSphere* sphere, std::size_t index, std::vector<std::string>& problems)
{
  const std::string of = "Magnetic sphere " + std::to_string(index) + ": ";
  problems.push_back(NotFinite(of + "SetCenter", "", sphere->GetCenter(), "its centre"));
  problems.push_back(OutOfRange(of + "SetRadius", sphere->GetRadius(), "its radius", 0, true));
  problems.push_back(OutOfRange(of + "SetStrength", sphere->GetStrength(), "its strength", 0, false));
  problems.push_back(OutOfRange(of + "SetFalloff", sphere->GetFalloff(), "its falloff", 0, false));
  problems.push_back(OutOfRange(of + "SetRange", sphere->GetRange(), "its range", 0, false));
  problems.push_back(OutOfRange(of + "SetPeriod", sphere->GetPeriod(), "its period", 0, true));
  vtkPoints* path = sphere->GetPath();
  if (path && path->GetNumberOfPoints() < 2)
  {
    problems.push_back(of + "its path (SetPath()) has " + std::to_string(path->GetNumberOfPoints()) +
      " point(s): a path needs at least 2, or none (SetPath(nullptr)) for a sphere that stays at its centre.");
    return;
  }
  for (vtkIdType p = 0; path && p < path->GetNumberOfPoints(); ++p)
  {
    const double* x = path->GetPoint(p);
    if (!(std::isfinite(x[0]) && std::isfinite(x[1]) && std::isfinite(x[2])))
    {
      std::ostringstream why;
      why << of << "point " << p << " of its path (SetPath()) is (" << x[0] << ", " << x[1] << ", " << x[2]
          << "): every point of the path must be finite.";
      problems.push_back(why.str());
      return;
    }
  }
}

/// Particle i's position, its rest position plus its displacement in u.
void PositionOf(const ffd::SoftBody& body, const std::vector<double>& u, std::size_t i, double x[3])
{
  for (int c = 0; c < 3; ++c)
  {
    x[c] = body.GetRestPositions()[3 * i + c] + u[3 * i + c];
  }
}
} // namespace

//------------------------------------------------------------------------------------------------------------
vtkFFDLatticeDynamics::vtkFFDLatticeDynamics()
  : Lattice(nullptr)
  , Mesh(nullptr)
  , TimeStep(1.0 / 60.0)
  , TotalMass(1.0)
  , MinimumMassFraction(0.01)
  , SpringStiffness(1.0)
  , SpringDamping(0.01)
  , CoreStiffness(10.0)
  , Iterations(10)
  , Gravity{ 0, 0, 0 }
  , SpringNeighborhood(BODY_DIAGONALS)
  , Internal(new Internals)
{
}

vtkFFDLatticeDynamics::~vtkFFDLatticeDynamics()
{
  this->SetLattice(nullptr);
  this->SetMesh(nullptr);
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDLatticeDynamics::AddMagneticSphere(vtkFFDMagneticSphere* sphere)
{
  if (sphere)
  {
    this->Internal->Spheres.emplace_back(sphere);
    this->Modified();
  }
}

void vtkFFDLatticeDynamics::RemoveAllMagneticSpheres()
{
  this->Internal->Spheres.clear();
  this->Modified();
}

int vtkFFDLatticeDynamics::GetNumberOfMagneticSpheres()
{
  return static_cast<int>(this->Internal->Spheres.size());
}

void vtkFFDLatticeDynamics::AddCollider(vtkImplicitFunction* collider)
{
  if (collider)
  {
    this->Internal->Colliders.emplace_back(collider);
    this->Modified();
  }
}

void vtkFFDLatticeDynamics::RemoveAllColliders()
{
  this->Internal->Colliders.clear();
  this->Modified();
}

int vtkFFDLatticeDynamics::GetNumberOfColliders()
{
  return static_cast<int>(this->Internal->Colliders.size());
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDLatticeDynamics::PinPoint(vtkIdType pointId, double x, double y, double z)
{
  this->Internal->Pins[pointId] = { x, y, z };
  this->Modified();
}

void vtkFFDLatticeDynamics::UnpinPoint(vtkIdType pointId)
{
  if (this->Internal->Pins.erase(pointId))
  {
    this->Modified();
  }
}

void vtkFFDLatticeDynamics::UnpinAllPoints()
{
  if (!this->Internal->Pins.empty())
  {
    this->Internal->Pins.clear();
    this->Modified();
  }
}

int vtkFFDLatticeDynamics::GetNumberOfPinnedPoints()
{
  return static_cast<int>(this->Internal->Pins.size());
}

int vtkFFDLatticeDynamics::ApplyImpulse(vtkIdType pointId, double x, double y, double z)
{
  const double impulse[3] = { x, y, z };
  std::string why = NotFinite("ApplyImpulse", std::to_string(pointId) + ", ", impulse, "the impulse");
  const Internals& in = *this->Internal;
  const vtkIdType points = this->Lattice ? this->Lattice->GetNumberOfPoints() : VTK_ID_MAX;
  const bool started = in.Ready && in.Lattice == this->Lattice && in.LatticePoints == points;
  if (why.empty() && (pointId < 0 || pointId >= points))
  {
    why = "ApplyImpulse(" + std::to_string(pointId) + ", ...): the lattice has no point " + std::to_string(pointId) +
      (this->Lattice ? " (it has " + std::to_string(points) + ")." : ".");
  }
  else if (why.empty() && started && in.ParticleOfPoint(pointId) < 0)
  {
    why = "ApplyImpulse(" + std::to_string(pointId) + ", ...): the point is not a simulated (Active) control point.";
  }
  if (!why.empty())
  {
    vtkErrorMacro(<< why << " The impulse is ignored.");
    return 0;
  }
  auto& queued = this->Internal->Impulses[pointId];
  for (int c = 0; c < 3; ++c)
  {
    queued[c] += impulse[c];
  }
  return 1;
}

//------------------------------------------------------------------------------------------------------------
vtkMTimeType vtkFFDLatticeDynamics::GetMTime()
{
  vtkMTimeType time = this->Superclass::GetMTime();
  for (const auto& sphere : this->Internal->Spheres)
  {
    time = std::max(time, sphere->GetMTime());
  }
  for (const auto& collider : this->Internal->Colliders)
  {
    time = std::max(time, collider->GetMTime());
  }
  return time;
}

//------------------------------------------------------------------------------------------------------------
int vtkFFDLatticeDynamics::CheckSettings()
{
  std::vector<std::string> problems = {
    OutOfRange("SetTimeStep", this->TimeStep, "the time step (s)", 0, true),
    OutOfRange("SetTotalMass", this->TotalMass, "the mass of the whole body", 0, true),
    OutOfRange(
      "SetMinimumMassFraction", this->MinimumMassFraction, "the least mass, a fraction of the mean,", 0, true, 1),
    OutOfRange("SetSpringStiffness", this->SpringStiffness, "the springs' stiffness", 0, false),
    OutOfRange("SetSpringDamping", this->SpringDamping, "the springs' damping", 0, false),
    OutOfRange("SetCoreStiffness", this->CoreStiffness, "the core's stiffness", 0, false),
    OutOfRange("SetIterations", this->Iterations, "the iterations of a step", 1, false, 1000),
    NotFinite("SetGravity", "", this->Gravity, "gravity"),
  };
  for (std::size_t i = 0; i < this->Internal->Spheres.size(); ++i)
  {
    CheckSphere(this->Internal->Spheres[i], i, problems);
  }
  for (const auto& pin : this->Internal->Pins)
  {
    problems.push_back(NotFinite("PinPoint", std::to_string(pin.first) + ", ", pin.second.data(), "the target"));
  }
  for (const std::string& why : problems)
  {
    if (!why.empty())
    {
      vtkErrorMacro(<< why);
      return 0;
    }
  }
  return 1;
}

//------------------------------------------------------------------------------------------------------------
int vtkFFDLatticeDynamics::Initialize()
{
  if (!this->CheckSettings())
  {
    this->Internal->Ready = false;
    return 0;
  }
  try
  {
    return this->InitializeBody();
  }
  catch (const std::bad_alloc&)
  {
    this->Internal->Ready = false;
    vtkErrorMacro(
      "Not enough memory to simulate the lattice's " << this->Lattice->GetNumberOfPoints() << " control points.");
    return 0;
  }
}

//------------------------------------------------------------------------------------------------------------
int vtkFFDLatticeDynamics::InitializeBody()
{
  Internals& in = *this->Internal;
  in.Ready = false;
  vtkFFDLatticeBody body;
  std::string why =
    body.Read(this->Lattice, this->Mesh, this->SpringNeighborhood, this->TotalMass, this->MinimumMassFraction);
  if (why.empty())
  {
    why = in.Body.SetUp(std::move(body.RestPositions), std::move(body.Masses), std::move(body.Springs));
  }
  if (!why.empty())
  {
    vtkErrorMacro(<< why);
    return 0;
  }
  in.PointOf = std::move(body.PointOf);
  in.ParticleOf = std::move(body.ParticleOf);
  // The state: the lattice's current points, at rest.
  vtkPointSet* lattice = this->Lattice;
  vtkPointSet* mesh = this->Mesh;
  vtkDataArray* rest = lattice->GetPointData()->GetArray(vtkFFDDataContract::RestPositionArrayName());
  std::vector<double>& u = in.Body.Displacements();
  for (std::size_t i = 0; i < in.PointOf.size(); ++i)
  {
    double x[3];
    lattice->GetPoint(in.PointOf[i], x);
    for (int c = 0; c < 3; ++c)
    {
      u[3 * i + c] = x[c] - in.Body.GetRestPositions()[3 * i + c];
    }
  }
  in.Time = 0; // queued impulses stay for the next step
  in.Lattice = lattice;
  in.Mesh = mesh;
  in.LatticePoints = lattice->GetNumberOfPoints();
  in.Rest = rest;
  in.RestTime = rest->GetMTime();
  in.MeshTime = mesh && mesh->GetPoints() ? mesh->GetPoints()->GetMTime() : 0;
  in.TotalMass = this->TotalMass;
  in.MinimumMassFraction = this->MinimumMassFraction;
  in.SpringNeighborhood = this->SpringNeighborhood;
  in.Ready = true;
  return 1;
}

//------------------------------------------------------------------------------------------------------------
int vtkFFDLatticeDynamics::Step(int steps)
{
  if (steps < 0)
  {
    vtkErrorMacro(<< "Step(" << steps << "): the number of steps cannot be negative.");
    return 0;
  }
  try
  {
    return this->StepBody(steps);
  }
  catch (const std::bad_alloc&)
  {
    vtkErrorMacro("Not enough memory to simulate the lattice: its linear system (springs between "
      << this->GetNumberOfSimulatedPoints() << " control points) does not fit. Fewer control points or "
      << "SetSpringNeighborhoodToEdges() need less.");
    this->Internal->Ready = false;
    return 0;
  }
}

//------------------------------------------------------------------------------------------------------------
int vtkFFDLatticeDynamics::StepBody(int steps)
{
  if (!this->CheckSettings())
  {
    return 0;
  }
  Internals& in = *this->Internal;
  vtkDataArray* rest =
    this->Lattice ? this->Lattice->GetPointData()->GetArray(vtkFFDDataContract::RestPositionArrayName()) : nullptr;
  const bool stale = !in.Ready || !rest || in.Lattice != this->Lattice || in.Mesh != this->Mesh ||
    in.LatticePoints != this->Lattice->GetNumberOfPoints() || in.Rest != rest || in.RestTime != rest->GetMTime() ||
    in.MeshTime != (this->Mesh && this->Mesh->GetPoints() ? this->Mesh->GetPoints()->GetMTime() : 0) ||
    in.TotalMass != this->TotalMass || in.MinimumMassFraction != this->MinimumMassFraction ||
    in.SpringNeighborhood != this->SpringNeighborhood;
  if (stale && !this->Initialize())
  {
    return 0;
  }
  ffd::SoftBody& body = in.Body;
  const ffd::SoftBodySettings settings = SettingsOf(*this);
  std::vector<unsigned char> pinned;
  std::vector<double> targets;
  std::string why = in.SpringsTooStiff(settings);
  if (why.empty())
  {
    why = in.PinnedParticles(pinned, targets);
  }
  if (!why.empty())
  {
    vtkErrorMacro(<< why);
    return 0;
  }
  body.SetSettings(settings);
  body.SetPinned(pinned);

  // A failed step leaves the state as it was before this call (and the impulses queued), the lattice unchanged.
  const std::vector<double> displacements = body.Displacements(), velocities = body.Velocities();
  const double time = in.Time;
  why = in.ApplyImpulses();
  if (why.empty())
  {
    why = in.Advance(steps, this->Gravity, pinned, targets, this);
  }
  if (!why.empty())
  {
    body.Displacements() = displacements;
    body.Velocities() = velocities;
    in.Time = time;
    vtkErrorMacro(<< why << " The lattice is left as it was.");
    return 0;
  }
  in.Impulses.clear();

  // The new positions into the lattice.
  vtkPoints* points = this->Lattice->GetPoints();
  const std::vector<double>& u = body.Displacements();
  for (std::size_t i = 0; i < in.PointOf.size(); ++i)
  {
    double x[3];
    PositionOf(body, u, i, x);
    points->SetPoint(in.PointOf[i], x);
  }
  points->Modified();
  return 1;
}

//------------------------------------------------------------------------------------------------------------
std::string vtkFFDLatticeDynamics::Internals::SpringsTooStiff(const ffd::SoftBodySettings& settings) const
{
  // The step's matrix M/h^2 + (k + c/h) L + W is nearly singular along the body's rigid motions (L's null space)
  // where the springs outweigh the inertia: the solve's relative error there is about epsilon times their ratio
  // times the neighbours (1e-5 at 1e8 on the bear's lattice, 1e-3 at 1e10), and the body freezes or jumps.
  if (this->Body.GetNumberOfSprings() == 0)
  {
    return std::string();
  }
  double lightest = std::numeric_limits<double>::infinity();
  for (int i = 0; i < this->Body.GetNumberOfParticles(); ++i)
  {
    lightest = std::min(lightest, this->Body.GetMass(i));
  }
  const double h = settings.TimeStep;
  const double ratio = (settings.SpringStiffness + settings.SpringDamping / h) * h * h / lightest;
  if (ratio <= 1e8)
  {
    return std::string();
  }
  std::ostringstream why;
  why << "The springs are too stiff for the time step and the masses: (SpringStiffness + SpringDamping / TimeStep) "
      << "x TimeStep^2 / the lightest particle's mass is " << ratio << ", above 1e8, where the step's linear solve "
      << "loses the body's motion to rounding (it would freeze or jump). Lower SetSpringStiffness() or "
      << "SetSpringDamping(), shorten SetTimeStep(), or raise SetTotalMass() or SetMinimumMassFraction().";
  return why.str();
}

//------------------------------------------------------------------------------------------------------------
std::string vtkFFDLatticeDynamics::Internals::PinnedParticles(
  std::vector<unsigned char>& pinned, std::vector<double>& targets) const
{
  const std::size_t particles = this->PointOf.size();
  pinned.assign(particles, 0);
  targets.assign(3 * particles, 0.0); // as displacements from rest
  for (const auto& pin : this->Pins)
  {
    const int particle = this->ParticleOfPoint(pin.first);
    if (particle < 0)
    {
      return "Point " + std::to_string(pin.first) +
        " is pinned but is not a simulated control point of the lattice: UnpinPoint() it.";
    }
    pinned[particle] = 1;
    for (int c = 0; c < 3; ++c)
    {
      targets[3 * particle + c] = pin.second[c] - this->Body.GetRestPositions()[3 * particle + c];
    }
  }
  return std::string();
}

//------------------------------------------------------------------------------------------------------------
std::string vtkFFDLatticeDynamics::Internals::ApplyImpulses()
{
  std::string why;
  for (auto impulse = this->Impulses.begin(); impulse != this->Impulses.end();)
  {
    const int particle = this->ParticleOfPoint(impulse->first);
    if (particle < 0)
    {
      why += std::string(why.empty() ? "" : " ") + "An impulse was applied to point " + std::to_string(impulse->first) +
        ", which is not a simulated control point of the lattice: it is dropped.";
      impulse = this->Impulses.erase(impulse);
      continue;
    }
    for (int c = 0; c < 3; ++c)
    {
      this->Body.Velocities()[3 * particle + c] += impulse->second[c] / this->Body.GetMass(particle);
    }
    ++impulse;
  }
  return why;
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDLatticeDynamics::Internals::Collide(
  std::vector<double>& u, const std::vector<unsigned char>& pinned, std::size_t& notFinite) const
{
  // A point inside a collider is moved onto its zero set by Newton's steps along the gradient.
  const std::vector<double>& restPositions = this->Body.GetRestPositions();
  for (std::size_t k = 0; k < this->Colliders.size(); ++k)
  {
    for (std::size_t i = 0; i < this->PointOf.size(); ++i)
    {
      if (pinned[i])
      {
        continue;
      }
      double x[3];
      PositionOf(this->Body, u, i, x);
      for (int newton = 0; newton < 8; ++newton)
      {
        const double f = this->Colliders[k]->FunctionValue(x);
        notFinite = std::isnan(f) ? std::min(notFinite, k) : notFinite;
        if (!(f < 0))
        {
          break;
        }
        double g[3];
        this->Colliders[k]->FunctionGradient(x, g);
        const double g2 = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
        if (!(g2 > 0))
        {
          break;
        }
        for (int c = 0; c < 3; ++c)
        {
          x[c] -= f * g[c] / g2;
        }
      }
      for (int c = 0; c < 3; ++c)
      {
        u[3 * i + c] = x[c] - restPositions[3 * i + c];
      }
    }
  }
}

//------------------------------------------------------------------------------------------------------------
std::string vtkFFDLatticeDynamics::Internals::Advance(int steps, const double gravity[3],
  const std::vector<unsigned char>& pinned, const std::vector<double>& targets, vtkObject* owner)
{
  ffd::SoftBody& body = this->Body;
  const std::size_t particles = this->PointOf.size();
  std::size_t notFinite = this->Colliders.size(); // the first collider whose value is NaN
  auto collide = [&](std::vector<double>& u) { this->Collide(u, pinned, notFinite); };

  std::vector<double> acceleration(3 * particles);
  for (int step = 0; step < steps; ++step)
  {
    const std::vector<double>& u = body.Displacements();
    for (std::size_t i = 0; i < particles; ++i)
    {
      std::copy(gravity, gravity + 3, &acceleration[3 * i]);
    }
    for (const auto& sphere : this->Spheres)
    {
      double center[3];
      sphere->GetCenterAt(this->Time, center);
      for (std::size_t i = 0; i < particles; ++i)
      {
        double x[3], pull[3];
        PositionOf(body, u, i, x);
        sphere->GetAccelerationAround(center, x, pull);
        for (int c = 0; c < 3; ++c)
        {
          acceleration[3 * i + c] += pull[c];
        }
      }
    }
    const bool stepped =
      body.Step(acceleration, targets, this->Colliders.empty() ? std::function<void(std::vector<double>&)>() : collide);
    if (!stepped || notFinite < this->Colliders.size())
    {
      std::ostringstream why;
      why << "Step " << step + 1 << " of " << steps << " (at time " << this->Time << " s) failed: ";
      if (notFinite < this->Colliders.size())
      {
        why << "collider " << notFinite << " (of AddCollider(), counted from 0) is not a number at a control point: "
            << "check its parameters (a plane's normal, a sphere's radius).";
      }
      else
      {
        why << "its positions are not finite (a force, gravity or a magnetic sphere's pull, too large there).";
      }
      return why.str();
    }
    this->Time += body.GetSettings().TimeStep;
    if (steps >= 20 && (step + 1) % (steps / 20) == 0)
    {
      double progress = double(step + 1) / double(steps);
      owner->InvokeEvent(vtkCommand::ProgressEvent, &progress);
    }
  }
  return std::string();
}

//------------------------------------------------------------------------------------------------------------
double vtkFFDLatticeDynamics::GetTime()
{
  return this->Internal->Time;
}

vtkIdType vtkFFDLatticeDynamics::GetNumberOfSimulatedPoints()
{
  return this->Internal->Ready ? vtkIdType(this->Internal->PointOf.size()) : 0;
}

vtkIdType vtkFFDLatticeDynamics::GetNumberOfSprings()
{
  return this->Internal->Ready ? this->Internal->Body.GetNumberOfSprings() : 0;
}

double vtkFFDLatticeDynamics::GetKineticEnergy()
{
  return this->Internal->Ready ? this->Internal->Body.KineticEnergy() : 0.0;
}

double vtkFFDLatticeDynamics::GetPotentialEnergy()
{
  if (!this->Internal->Ready)
  {
    return 0.0;
  }
  this->Internal->Body.SetSettings(SettingsOf(*this));
  return this->Internal->Body.SpringEnergy() + this->Internal->Body.CoreEnergy();
}

void vtkFFDLatticeDynamics::GetMomentum(double momentum[3])
{
  const std::array<double, 3> p =
    this->Internal->Ready ? this->Internal->Body.Momentum() : std::array<double, 3>{ 0, 0, 0 };
  std::copy(p.begin(), p.end(), momentum);
}

double vtkFFDLatticeDynamics::GetMass(vtkIdType pointId)
{
  const Internals& in = *this->Internal;
  if (!in.Ready || pointId < 0 || pointId >= vtkIdType(in.ParticleOf.size()) || in.ParticleOf[pointId] < 0)
  {
    return 0.0;
  }
  return in.Body.GetMass(in.ParticleOf[pointId]);
}

double vtkFFDLatticeDynamics::GetExplicitTimeStepLimit()
{
  if (!this->Internal->Ready && !this->Initialize())
  {
    return 0.0;
  }
  this->Internal->Body.SetSettings(SettingsOf(*this));
  return this->Internal->Body.ExplicitTimeStepLimit();
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDLatticeDynamics::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Lattice: " << this->Lattice << "\n";
  os << indent << "Mesh: " << this->Mesh << "\n";
  os << indent << "TimeStep: " << this->TimeStep << "\n";
  os << indent << "TotalMass: " << this->TotalMass << "\n";
  os << indent << "MinimumMassFraction: " << this->MinimumMassFraction << "\n";
  os << indent << "SpringStiffness: " << this->SpringStiffness << "\n";
  os << indent << "SpringDamping: " << this->SpringDamping << "\n";
  os << indent << "CoreStiffness: " << this->CoreStiffness << "\n";
  os << indent << "Iterations: " << this->Iterations << "\n";
  os << indent << "Gravity: (" << this->Gravity[0] << ", " << this->Gravity[1] << ", " << this->Gravity[2] << ")\n";
  os << indent << "SpringNeighborhood: " << this->SpringNeighborhood << "\n";
  os << indent << "MagneticSpheres: " << this->Internal->Spheres.size() << "\n";
  os << indent << "Colliders: " << this->Internal->Colliders.size() << "\n";
  os << indent << "PinnedPoints: " << this->Internal->Pins.size() << "\n";
  os << indent << "Time: " << this->Internal->Time << "\n";
}
