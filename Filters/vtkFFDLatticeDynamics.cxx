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
#include <map>
#include <new>
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
  std::map<vtkIdType, std::array<double, 3>> Impulses;
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

void vtkFFDLatticeDynamics::ApplyImpulse(vtkIdType pointId, double x, double y, double z)
{
  auto& impulse = this->Internal->Impulses[pointId];
  impulse[0] += x;
  impulse[1] += y;
  impulse[2] += z;
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
int vtkFFDLatticeDynamics::Initialize()
{
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
  in.Time = 0;
  in.Impulses.clear();
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
  const std::size_t particles = in.PointOf.size();
  const std::vector<double>& restPositions = body.GetRestPositions();
  body.SetSettings(SettingsOf(*this));

  // Pins: their particles and targets (as displacements from rest).
  std::vector<unsigned char> pinned(particles, 0);
  std::vector<double> targets(3 * particles, 0.0);
  for (const auto& pin : in.Pins)
  {
    const int particle = pin.first >= 0 && pin.first < vtkIdType(in.ParticleOf.size()) ? in.ParticleOf[pin.first] : -1;
    if (particle < 0)
    {
      vtkErrorMacro(<< "Point " << pin.first << " is pinned but is not a simulated control point of the lattice.");
      return 0;
    }
    pinned[particle] = 1;
    for (int c = 0; c < 3; ++c)
    {
      targets[3 * particle + c] = pin.second[c] - restPositions[3 * particle + c];
    }
  }
  body.SetPinned(pinned);
  for (const auto& impulse : in.Impulses)
  {
    const int particle =
      impulse.first >= 0 && impulse.first < vtkIdType(in.ParticleOf.size()) ? in.ParticleOf[impulse.first] : -1;
    if (particle < 0)
    {
      vtkErrorMacro(<< "An impulse is applied to point " << impulse.first
                    << ", which is not a simulated control point of the lattice.");
      in.Impulses.clear();
      return 0;
    }
    for (int c = 0; c < 3; ++c)
    {
      body.Velocities()[3 * particle + c] += impulse.second[c] / body.GetMass(particle);
    }
  }
  in.Impulses.clear();

  // Colliders: a point inside one is moved onto its zero set by Newton's steps along the gradient.
  auto collide = [&](std::vector<double>& u)
  {
    for (const auto& collider : in.Colliders)
    {
      for (std::size_t i = 0; i < particles; ++i)
      {
        if (pinned[i])
        {
          continue;
        }
        double x[3];
        PositionOf(body, u, i, x);
        for (int newton = 0; newton < 8; ++newton)
        {
          const double f = collider->FunctionValue(x);
          if (!(f < 0))
          {
            break;
          }
          double g[3];
          collider->FunctionGradient(x, g);
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
  };

  std::vector<double> acceleration(3 * particles);
  int done = 0;
  for (int step = 0; step < steps; ++step)
  {
    const std::vector<double>& u = body.Displacements();
    for (std::size_t i = 0; i < particles; ++i)
    {
      std::copy(this->Gravity, this->Gravity + 3, &acceleration[3 * i]);
    }
    for (const auto& sphere : in.Spheres)
    {
      double center[3];
      sphere->GetCenterAt(in.Time, center);
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
    if (!body.Step(acceleration, targets, in.Colliders.empty() ? std::function<void(std::vector<double>&)>() : collide))
    {
      vtkErrorMacro("The simulation's linear system could not be factored: check that the time step, the "
                    "stiffnesses and the damping are finite.");
      break;
    }
    in.Time += this->TimeStep;
    ++done;
    if (steps >= 20 && done % (steps / 20) == 0)
    {
      double progress = double(done) / double(steps);
      this->InvokeEvent(vtkCommand::ProgressEvent, &progress);
    }
  }

  // The new positions into the lattice.
  vtkPoints* points = this->Lattice->GetPoints();
  const std::vector<double>& u = body.Displacements();
  for (std::size_t i = 0; i < particles; ++i)
  {
    double x[3];
    PositionOf(body, u, i, x);
    points->SetPoint(in.PointOf[i], x);
  }
  points->Modified();
  return done == steps ? 1 : 0;
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
