// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDLatticeDynamics.h"

#include "vtkFFDDataContract.h"
#include "vtkFFDGridDeformer.h"
#include "vtkFFDMagneticSphere.h"
#include "vtkFFDSparseCells.h"
#include "vtkFFDTetrahedralDeformer.h"

#include "vtkCommand.h"
#include "vtkDataArray.h"
#include "vtkImplicitFunction.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkSmartPointer.h"
#include "vtkUnstructuredGrid.h"

#include "FFDGridDeformation.h"
#include "FFDSoftBody.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <new>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkFFDLatticeDynamics);
vtkCxxSetObjectMacro(vtkFFDLatticeDynamics, Lattice, vtkPointSet);
vtkCxxSetObjectMacro(vtkFFDLatticeDynamics, Mesh, vtkPointSet);

namespace
{
using Pair = std::array<int, 2>;

/// Half of the 26 lattice neighbours, by SpringNeighborhood: the 3 edges, then 6 face and 4 body diagonals.
constexpr int Offsets[13][3] = { { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 }, { 1, 1, 0 }, { 1, -1, 0 }, { 1, 0, 1 },
  { 1, 0, -1 }, { 0, 1, 1 }, { 0, 1, -1 }, { 1, 1, 1 }, { 1, 1, -1 }, { 1, -1, 1 }, { 1, -1, -1 } };
constexpr int OffsetCount[3] = { 3, 9, 13 };

/// The springs of a dense grid lattice: neighbours both simulated.
std::vector<Pair> DenseSprings(const int dims[3], const std::vector<int>& particleOf, int offsets)
{
  std::vector<Pair> springs;
  for (int k = 0; k < dims[2]; ++k)
  {
    for (int j = 0; j < dims[1]; ++j)
    {
      for (int i = 0; i < dims[0]; ++i)
      {
        const int a = particleOf[i + dims[0] * (j + dims[1] * k)];
        for (int o = 0; a >= 0 && o < offsets; ++o)
        {
          const int n[3] = { i + Offsets[o][0], j + Offsets[o][1], k + Offsets[o][2] };
          if (n[0] < dims[0] && n[1] >= 0 && n[1] < dims[1] && n[2] >= 0 && n[2] < dims[2])
          {
            const int b = particleOf[n[0] + dims[0] * (n[1] + dims[1] * n[2])];
            if (b >= 0)
            {
              springs.push_back({ a, b });
            }
          }
        }
      }
    }
  }
  return springs;
}

/// The springs of a sparse lattice: neighbours within a cell's support (every neighbour pair of the lattice
/// lies in some support), each pair once, told by its first point and offset.
std::vector<Pair> SparseSprings(
  const vtkFFDSparseCells& cells, int supportCount, const std::vector<int>& particleOf, int offsets)
{
  std::vector<Pair> springs;
  std::vector<std::uint16_t> done(particleOf.size(), 0); // per point, a bit per offset already joined
  const int n = supportCount;
  const int* supports = cells.GetSupports().data();
  for (int cell = 0; cell < cells.GetNumberOfCells(); ++cell)
  {
    const int* support = supports + std::size_t(cell) * std::size_t(n * n * n);
    for (int k = 0; k < n; ++k)
    {
      for (int j = 0; j < n; ++j)
      {
        for (int i = 0; i < n; ++i)
        {
          const int p = support[i + n * (j + n * k)];
          for (int o = 0; o < offsets; ++o)
          {
            const int m[3] = { i + Offsets[o][0], j + Offsets[o][1], k + Offsets[o][2] };
            if (m[0] >= n || m[1] < 0 || m[1] >= n || m[2] < 0 || m[2] >= n || (done[p] >> o & 1))
            {
              continue;
            }
            done[p] |= std::uint16_t(1u << o);
            const int a = particleOf[p], b = particleOf[support[m[0] + n * (m[1] + n * m[2])]];
            if (a >= 0 && b >= 0)
            {
              springs.push_back({ a, b });
            }
          }
        }
      }
    }
  }
  return springs;
}

/// The springs of a tetrahedral lattice: its edges between simulated nodes, each once.
std::vector<Pair> TetrahedronSprings(const std::vector<vtkIdType>& nodes, const std::vector<int>& particleOf)
{
  std::vector<Pair> springs;
  for (std::size_t t = 0; t + 3 < nodes.size(); t += 4)
  {
    for (int e = 0; e < 4; ++e)
    {
      for (int f = e + 1; f < 4; ++f)
      {
        const int a = particleOf[nodes[t + e]], b = particleOf[nodes[t + f]];
        if (a >= 0 && b >= 0 && a != b)
        {
          springs.push_back({ std::min(a, b), std::max(a, b) });
        }
      }
    }
  }
  std::sort(springs.begin(), springs.end());
  springs.erase(std::unique(springs.begin(), springs.end()), springs.end());
  return springs;
}
/**
 * TotalMass shared among the particles in proportion to `share`, none below minimumFraction of the mean: those
 * that would be are set to it and the others share the rest, until no other falls below (the largest share
 * never does). Without shares (no mesh, or no point bound), the same mass for all.
 */
std::vector<double> ShareMass(const std::vector<double>& share, double totalMass, double minimumFraction)
{
  const std::size_t n = share.size();
  const double mean = totalMass / double(n), least = minimumFraction * mean;
  std::vector<double> masses(n, mean);
  std::vector<unsigned char> floored(n, 0);
  for (bool changed = true; changed;)
  {
    changed = false;
    double remaining = totalMass, shared = 0;
    for (std::size_t i = 0; i < n; ++i)
    {
      remaining -= floored[i] ? least : 0.0;
      shared += floored[i] ? 0.0 : share[i];
    }
    if (!(shared > 0))
    {
      return std::vector<double>(n, mean);
    }
    for (std::size_t i = 0; i < n; ++i)
    {
      masses[i] = floored[i] ? least : remaining * (share[i] / shared);
      if (masses[i] < least)
      {
        floored[i] = 1;
        changed = true;
      }
    }
  }
  return masses;
}
} // namespace

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
  vtkPointSet* lattice = this->Lattice;
  if (!lattice || !lattice->GetPoints() || lattice->GetNumberOfPoints() == 0)
  {
    vtkErrorMacro("No lattice to simulate: SetLattice() to the output of vtkFFDBuildLattice or "
                  "vtkFFDBuildTetrahedralLattice.");
    return 0;
  }
  vtkDataArray* rest = lattice->GetPointData()->GetArray(vtkFFDDataContract::RestPositionArrayName());
  const vtkIdType count = lattice->GetNumberOfPoints();
  if (count > VTK_INT_MAX)
  {
    vtkErrorMacro(<< "The lattice has " << count << " points; at most " << VTK_INT_MAX << " can be simulated.");
    return 0;
  }
  if (!rest || rest->GetNumberOfComponents() != 3 || rest->GetNumberOfTuples() != count)
  {
    vtkErrorMacro("The lattice has no RestPosition point array of 3 components per point.");
    return 0;
  }

  // The lattice's kind, read and checked by vtkFFDDeform's own readers; the mesh's points bound to it.
  const bool tetrahedral = vtkFFDTetrahedralDeformer::IsTetrahedralLattice(lattice);
  vtkFFDGridDeformer grid;
  vtkFFDTetrahedralDeformer tetrahedra;
  std::string why =
    tetrahedral ? tetrahedra.SetLattice(vtkUnstructuredGrid::SafeDownCast(lattice)) : grid.SetLattice(lattice);
  if (!why.empty())
  {
    vtkErrorMacro(<< "Cannot simulate the lattice: " << why);
    return 0;
  }

  // Particles: the active control points.
  in.ParticleOf.assign(std::size_t(count), -1);
  in.PointOf.clear();
  vtkDataArray* active = lattice->GetPointData()->GetArray(vtkFFDDataContract::ActiveArrayName());
  if (active && (active->GetNumberOfComponents() != 1 || active->GetNumberOfTuples() != count))
  {
    vtkErrorMacro("The lattice's Active point array does not have one value per point.");
    return 0;
  }
  std::vector<double> restPositions;
  for (vtkIdType p = 0; p < count; ++p)
  {
    if (!active || active->GetComponent(p, 0) != 0)
    {
      in.ParticleOf[p] = static_cast<int>(in.PointOf.size());
      in.PointOf.push_back(p);
      double x[3];
      rest->GetTuple(p, x);
      restPositions.insert(restPositions.end(), x, x + 3);
    }
  }
  if (in.PointOf.empty())
  {
    vtkErrorMacro("The lattice has no active control point to simulate.");
    return 0;
  }

  // Springs.
  std::vector<Pair> springs;
  const int offsets = OffsetCount[this->SpringNeighborhood];
  if (tetrahedral)
  {
    springs = TetrahedronSprings(tetrahedra.GetNodes(), in.ParticleOf);
  }
  else if (const vtkFFDSparseCells* cells = grid.GetSparseCells())
  {
    springs = SparseSprings(*cells, ffd::CellDegree(grid.GetLattice().Basis) + 1, in.ParticleOf, offsets);
  }
  else
  {
    springs = DenseSprings(grid.GetLattice().ControlPointsPerAxis, in.ParticleOf, offsets);
  }

  // Masses: each particle's share of the mesh's points, through their weights.
  const std::size_t particles = in.PointOf.size();
  std::vector<double> share(particles, 0.0);
  vtkPointSet* mesh = this->Mesh;
  if (mesh && mesh->GetPoints() && mesh->GetNumberOfPoints() > 0)
  {
    vtkPoints* points = mesh->GetPoints();
    bool rebound = false;
    auto add = [&](vtkIdType point, double weight)
    {
      const int particle = in.ParticleOf[point];
      if (particle >= 0)
      {
        share[particle] += weight;
      }
    };
    if (tetrahedral)
    {
      tetrahedra.Bind(points, vtkFFDTetrahedralDeformer::KEEP_POSITION, nullptr, 0, 1, rebound);
      const std::vector<int>& cellOf = tetrahedra.GetCellOfPoint();
      const std::vector<vtkIdType>& nodes = tetrahedra.GetNodes();
      for (vtkIdType p = 0; p < mesh->GetNumberOfPoints(); ++p)
      {
        const int t = cellOf[p];
        if (t >= 0)
        {
          double x[3];
          points->GetPoint(p, x);
          const ffd::Vec3<double> stu = tetrahedra.GetFrames()[t].ToParametric({ x[0], x[1], x[2] });
          const double weights[4] = { 1.0 - stu.x - stu.y - stu.z, stu.x, stu.y, stu.z };
          for (int corner = 0; corner < 4; ++corner)
          {
            add(nodes[4 * std::size_t(t) + corner], weights[corner]);
          }
        }
      }
    }
    else
    {
      grid.Bind(points, 0 /* KEEP_POSITION */, nullptr, 0, 1, rebound);
      const std::vector<int>& cellOf = grid.GetCellOfPoint();
      const vtkFFDGridLattice& view = grid.GetLattice();
      const vtkFFDSparseCells* cells = grid.GetSparseCells();
      ffd::WithStaticBasis(view.Basis,
        [&](auto maxCount, auto)
        {
          const ffd::GridDeformation<decltype(maxCount)::value, double> deformation{ view.Basis,
            { view.Divisions[0], view.Divisions[1], view.Divisions[2] },
            { view.ControlPointsPerAxis[0], view.ControlPointsPerAxis[1], view.ControlPointsPerAxis[2] },
            view.Displacements.data(), ffd::Frame<double>::FromArray(view.Frame), nullptr,
            cells ? cells->GetVoxels().data() : nullptr, cells ? cells->GetSupports().data() : nullptr };
          for (vtkIdType p = 0; p < mesh->GetNumberOfPoints(); ++p)
          {
            if (cellOf[p] >= 0)
            {
              double x[3];
              points->GetPoint(p, x);
              deformation.ForEachWeight({ x[0], x[1], x[2] }, cellOf[p], add);
            }
          }
        });
    }
  }
  std::vector<double> masses = ShareMass(share, this->TotalMass, this->MinimumMassFraction);

  why = in.Body.SetUp(std::move(restPositions), std::move(masses), std::move(springs));
  if (!why.empty())
  {
    vtkErrorMacro(<< "Cannot simulate the lattice: " << why);
    return 0;
  }
  // The state: the lattice's current points, at rest.
  std::vector<double>& u = in.Body.Displacements();
  for (std::size_t i = 0; i < particles; ++i)
  {
    double x[3], x0[3];
    lattice->GetPoint(in.PointOf[i], x);
    rest->GetTuple(in.PointOf[i], x0);
    for (int c = 0; c < 3; ++c)
    {
      u[3 * i + c] = x[c] - x0[c];
    }
  }
  in.Time = 0;
  in.Impulses.clear();
  in.Lattice = lattice;
  in.Mesh = mesh;
  in.LatticePoints = count;
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
  rest = this->Lattice->GetPointData()->GetArray(vtkFFDDataContract::RestPositionArrayName());
  ffd::SoftBody& body = in.Body;
  const std::size_t particles = in.PointOf.size();
  ffd::SoftBodySettings settings;
  settings.TimeStep = this->TimeStep;
  settings.SpringStiffness = this->SpringStiffness;
  settings.SpringDamping = this->SpringDamping;
  settings.CoreStiffness = this->CoreStiffness;
  settings.Iterations = this->Iterations;
  body.SetSettings(settings);

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
    double x0[3];
    rest->GetTuple(pin.first, x0);
    for (int c = 0; c < 3; ++c)
    {
      targets[3 * particle + c] = pin.second[c] - x0[c];
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
    const double m = this->GetMass(impulse.first);
    for (int c = 0; c < 3; ++c)
    {
      body.Velocities()[3 * particle + c] += impulse.second[c] / m;
    }
  }
  in.Impulses.clear();

  std::vector<double> restPositions(3 * particles);
  for (std::size_t i = 0; i < particles; ++i)
  {
    rest->GetTuple(in.PointOf[i], &restPositions[3 * i]);
  }
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
        for (int c = 0; c < 3; ++c)
        {
          x[c] = restPositions[3 * i + c] + u[3 * i + c];
        }
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
      double* a = &acceleration[3 * i];
      std::copy(this->Gravity, this->Gravity + 3, a);
      const double x[3] = { restPositions[3 * i] + u[3 * i], restPositions[3 * i + 1] + u[3 * i + 1],
        restPositions[3 * i + 2] + u[3 * i + 2] };
      for (const auto& sphere : in.Spheres)
      {
        double pull[3];
        sphere->GetAcceleration(x, in.Time, pull);
        for (int c = 0; c < 3; ++c)
        {
          a[c] += pull[c];
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
    const double x[3] = { restPositions[3 * i] + u[3 * i], restPositions[3 * i + 1] + u[3 * i + 1],
      restPositions[3 * i + 2] + u[3 * i + 2] };
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
  ffd::SoftBodySettings settings = this->Internal->Body.GetSettings();
  settings.SpringStiffness = this->SpringStiffness;
  settings.CoreStiffness = this->CoreStiffness;
  this->Internal->Body.SetSettings(settings);
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
  ffd::SoftBodySettings settings = this->Internal->Body.GetSettings();
  settings.SpringStiffness = this->SpringStiffness;
  settings.CoreStiffness = this->CoreStiffness;
  this->Internal->Body.SetSettings(settings);
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
