// SPDX-License-Identifier: BSD-3-Clause
// vtkFFDLatticeDynamics, vtkFFDMagneticSphere and vtkFFDSimulateLattice on the bear's lattices. The references
// are independent: masses from the reference basis weights (Testing/Reference), the discrete backward Euler
// translation under a uniform field, an explicit (symplectic Euler) integrator written here on springs found here,
// and the magnetic sphere's formula. Tolerances are stated where they are used, each with its bound.

#include "FFDTestErrorObserver.h"
#include "FFDTestInputChecks.h"
#include "FFDTestLattices.h"
#include "FFDTestMeshes.h"
#include "FFDTestTetrahedra.h"

#include "vtkCallbackCommand.h"
#include "vtkDataArray.h"
#include "vtkFFDBuildTetrahedralLattice.h"
#include "vtkFFDDeform.h"
#include "vtkFFDDeformBlocks.h"
#include "vtkFFDInverseDeform.h"
#include "vtkFFDLatticeDynamics.h"
#include "vtkFFDMagneticSphere.h"
#include "vtkFFDSimulateLattice.h"
#include "vtkFFDVoxelize.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkObjectFactory.h"
#include "vtkPlane.h"
#include "vtkPointData.h"
#include "vtkPointSetAlgorithm.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkUnsignedCharArray.h"
#include "vtkUnstructuredGrid.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <sstream>

namespace
{
using ffdtest::Vec;
constexpr double Epsilon = std::numeric_limits<double>::epsilon();

/// The bear in a lattice built by vtkFFDBuildLattice (divisions 5: the paper's Figure 1).
struct Scene
{
  vtkSmartPointer<vtkPolyData> Mesh;
  vtkSmartPointer<vtkPointSet> Lattice;
  double Size = 0; // the frame's diagonal
};

Scene BearScene(int basis, int form, int divisions = 5)
{
  Scene scene;
  scene.Mesh = ReadTestMesh("bear");
  vtkNew<vtkFFDVoxelize> voxelize;
  voxelize->SetInputData(scene.Mesh);
  voxelize->SetDivisions(divisions, divisions, divisions);
  vtkNew<vtkFFDBuildLattice> build;
  build->SetInputConnection(voxelize->GetOutputPort());
  build->SetBasis(basis);
  build->SetLatticeForm(form);
  build->Update();
  scene.Lattice.TakeReference(vtkPointSet::SafeDownCast(build->GetOutput()->NewInstance()));
  scene.Lattice->DeepCopy(build->GetOutput());
  scene.Size = ffdtest::Diagonal(ffdtest::FrameOf(scene.Lattice));
  return scene;
}

Scene BearTetrahedra()
{
  Scene scene;
  scene.Mesh = ReadTestMesh("bear");
  vtkNew<vtkFFDBuildTetrahedralLattice> build;
  build->SetInputData(scene.Mesh);
  build->Update();
  scene.Lattice = build->GetOutput();
  double bounds[6];
  scene.Mesh->GetBounds(bounds);
  scene.Size = std::sqrt(
    std::pow(bounds[1] - bounds[0], 2) + std::pow(bounds[3] - bounds[2], 2) + std::pow(bounds[5] - bounds[4], 2));
  return scene;
}

std::vector<Vec> PointsOf(vtkPointSet* set)
{
  std::vector<Vec> points(set->GetNumberOfPoints());
  for (vtkIdType p = 0; p < set->GetNumberOfPoints(); ++p)
  {
    set->GetPoint(p, points[p].data());
  }
  return points;
}

vtkSmartPointer<vtkFFDLatticeDynamics> MakeDynamics(const Scene& scene)
{
  auto dynamics = vtkSmartPointer<vtkFFDLatticeDynamics>::New();
  dynamics->SetLattice(scene.Lattice);
  dynamics->SetMesh(scene.Mesh);
  return dynamics;
}

double Energy(vtkFFDLatticeDynamics* dynamics)
{
  return dynamics->GetKineticEnergy() + dynamics->GetPotentialEnergy();
}

const int Forms[] = { vtkFFDBuildLattice::DENSE, vtkFFDBuildLattice::SPARSE };

/// Its input at every time, announcing the time steps (or only the range) of a reader: a mesh or a lattice that
/// varies in time. Remembers the time it was last asked for.
class TimedInput : public vtkPointSetAlgorithm
{
public:
  static TimedInput* New();
  vtkTypeMacro(TimedInput, vtkPointSetAlgorithm);
  std::vector<double> Steps;
  bool RangeOnly = false;
  double Asked = -1;

protected:
  int ExecuteInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector* outputs) override
  {
    vtkInformation* info = outputs->GetInformationObject(0);
    if (!this->RangeOnly)
    {
      info->Set(vtkStreamingDemandDrivenPipeline::TIME_STEPS(), this->Steps.data(), int(this->Steps.size()));
    }
    const double range[2] = { this->Steps.front(), this->Steps.back() };
    info->Set(vtkStreamingDemandDrivenPipeline::TIME_RANGE(), range, 2);
    return 1;
  }
  int RequestData(vtkInformation*, vtkInformationVector** inputs, vtkInformationVector* outputs) override
  {
    vtkInformation* info = outputs->GetInformationObject(0);
    this->Asked = info->Get(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP());
    vtkPointSet::GetData(info)->ShallowCopy(vtkPointSet::GetData(inputs[0]));
    return 1;
  }
};
vtkStandardNewMacro(TimedInput);

/// The TIME_STEPS (empty where none) and TIME_RANGE (none: {1, -1}) that `algorithm` announces.
std::pair<std::vector<double>, std::array<double, 2>> TimesOf(vtkAlgorithm* algorithm)
{
  algorithm->UpdateInformation();
  vtkInformation* info = algorithm->GetOutputInformation(0);
  std::pair<std::vector<double>, std::array<double, 2>> times = { {}, { 1, -1 } };
  if (const double* steps = info->Get(vtkStreamingDemandDrivenPipeline::TIME_STEPS()))
  {
    times.first.assign(steps, steps + info->Length(vtkStreamingDemandDrivenPipeline::TIME_STEPS()));
  }
  if (info->Has(vtkStreamingDemandDrivenPipeline::TIME_RANGE()))
  {
    info->Get(vtkStreamingDemandDrivenPipeline::TIME_RANGE(), times.second.data());
  }
  return times;
}

/// A simulation of the bear's lattice falling under gravity onto a plane, in the pipeline.
vtkSmartPointer<vtkFFDSimulateLattice> FallingLattice(const Scene& scene, double endTime)
{
  auto simulate = vtkSmartPointer<vtkFFDSimulateLattice>::New();
  simulate->SetInputData(scene.Lattice);
  simulate->SetMeshData(scene.Mesh);
  simulate->SetEndTime(endTime);
  simulate->GetDynamics()->SetGravity(0, 0, -9.81);
  vtkNew<vtkPlane> ground;
  ground->SetOrigin(0, 0, scene.Lattice->GetBounds()[4] - 0.2 * scene.Size);
  ground->SetNormal(0, 0, 1);
  simulate->GetDynamics()->AddCollider(ground);
  return simulate;
}
} // namespace

//------------------------------------------------------------------------------------------------------------
// Zero forces: every term is computed from the displacements, which are exactly zero at rest, so the lattice
// stays bit for bit where it is, on every kind of lattice.
TEST(FFDLatticeDynamics, RestStaysRestForTenThousandSteps)
{
  // 10,000 steps on a 3x3x3-voxel lattice, 1,000 on the paper's Figure 1 lattice, 300 on the larger others:
  // each step computes the same zeros.
  const std::pair<Scene, int> cases[] = { { BearScene(vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::DENSE, 3),
                                            10000 },
    { BearScene(vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::DENSE), 1000 },
    { BearScene(vtkFFDBuildLattice::CUBIC_BSPLINE, vtkFFDBuildLattice::SPARSE), 300 }, { BearTetrahedra(), 300 } };
  for (const auto& [scene, steps] : cases)
  {
    const std::vector<Vec> before = PointsOf(scene.Lattice);
    auto dynamics = MakeDynamics(scene);
    ASSERT_TRUE(dynamics->Step(steps));
    // The time is a sum of steps: each addition rounds by at most half an ulp of the sum.
    const double time = steps * dynamics->GetTimeStep();
    EXPECT_NEAR(dynamics->GetTime(), time, steps * Epsilon * time);
    const std::vector<Vec> after = PointsOf(scene.Lattice);
    for (std::size_t p = 0; p < before.size(); ++p)
    {
      ASSERT_EQ(before[p], after[p]) << "point " << p << " drifted";
    }
    EXPECT_EQ(dynamics->GetKineticEnergy(), 0.0);
    EXPECT_EQ(dynamics->GetPotentialEnergy(), 0.0);
  }
}

//------------------------------------------------------------------------------------------------------------
// Masses: each simulated control point's share of the bear's points, sum of its weights over them, from the
// reference basis (a lattice built by hand, every control point simulated), scaled to the total mass; the
// floor lifts the lightest. Tolerance: sums of at most 30,000 weights, each with a relative rounding of a few
// epsilon: 1e-12 relative.
TEST(FFDLatticeDynamics, MassesAreTheMeshPointsSharesThroughTheWeights)
{
  const vtkSmartPointer<vtkPolyData> mesh = ReadTestMesh("bear");
  double b[6];
  mesh->GetBounds(b);
  const ffdref::Frame f = { { b[0] - 0.01, b[2] - 0.02, b[4] - 0.03 }, { b[1] - b[0] + 0.05, 0, 0 },
    { 0, b[3] - b[2] + 0.04, 0 }, { 0, 0, b[5] - b[4] + 0.06 } };
  for (const int basis :
    { vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::CUBIC_BSPLINE, vtkFFDBuildLattice::BERNSTEIN })
  {
    const int n[3] = { 3, 4, 2 };
    vtkSmartPointer<vtkStructuredGrid> lattice = ffdtest::MakeLattice(f, basis, n);
    const ffdtest::Reference ref = ffdtest::ReferenceOf(lattice);
    const int dims[3] = { ffdtest::PointsAlongAxis(basis, n[0]), ffdtest::PointsAlongAxis(basis, n[1]),
      ffdtest::PointsAlongAxis(basis, n[2]) };
    std::vector<double> share(lattice->GetNumberOfPoints(), 0.0);
    double total = 0;
    for (vtkIdType p = 0; p < mesh->GetNumberOfPoints(); ++p)
    {
      Vec x;
      mesh->GetPoint(p, x.data());
      const Vec stu = ffdref::Parameters(f, x);
      std::vector<double> w[3];
      for (int a = 0; a < 3; ++a)
      {
        w[a] = ffdref::AxisWeights(ref.Basis, n[a], stu[a]);
      }
      for (int k = 0; k < dims[2]; ++k)
        for (int j = 0; j < dims[1]; ++j)
          for (int i = 0; i < dims[0]; ++i)
          {
            share[i + dims[0] * (j + dims[1] * k)] += w[0][i] * w[1][j] * w[2][k];
            total += w[0][i] * w[1][j] * w[2][k];
          }
    }
    vtkNew<vtkFFDLatticeDynamics> dynamics;
    dynamics->SetLattice(lattice);
    dynamics->SetMesh(mesh);
    dynamics->SetTotalMass(2.5);
    dynamics->SetMinimumMassFraction(1e-12); // no floor: the shares alone
    ASSERT_TRUE(dynamics->Initialize());
    ASSERT_EQ(dynamics->GetNumberOfSimulatedPoints(), lattice->GetNumberOfPoints());
    double least = VTK_DOUBLE_MAX, sum = 0;
    for (vtkIdType c = 0; c < lattice->GetNumberOfPoints(); ++c)
    {
      const double expected = 2.5 * share[c] / total;
      EXPECT_NEAR(dynamics->GetMass(c), expected, 1e-12 * 2.5) << "basis " << basis << " control point " << c;
      least = std::min(least, expected);
      sum += dynamics->GetMass(c);
    }
    EXPECT_NEAR(sum, 2.5, 1e-12 * 2.5);
    // A floor above the lightest: none below it, the total kept, the order of the others kept.
    const double mean = 2.5 / double(lattice->GetNumberOfPoints());
    const double fraction = std::min(1.0, 2 * least / mean + 1e-3);
    dynamics->SetMinimumMassFraction(fraction);
    ASSERT_TRUE(dynamics->Initialize());
    sum = 0;
    for (vtkIdType c = 0; c < lattice->GetNumberOfPoints(); ++c)
    {
      EXPECT_GE(dynamics->GetMass(c), fraction * mean * (1 - 1e-12));
      sum += dynamics->GetMass(c);
    }
    EXPECT_NEAR(sum, 2.5, 1e-12 * 2.5);
  }
}

//------------------------------------------------------------------------------------------------------------
// A uniform field (gravity) translates the body without deforming it: backward Euler from rest gives
// u_n = g h^2 n (n + 1) / 2 exactly in real numbers. Tolerance: the linear solve's relative error is about
// cond(A) epsilon a step, cond(A) = 1 + h^2 lambda_max(M^-1 (L + W)) = 1 + 4 (h / explicit limit)^2, below 10^3
// here; over 120 steps the error stays below 120 * 10^3 * epsilon = 3e-11 of the translation: 1e-10.
TEST(FFDLatticeDynamics, UniformFieldTranslatesTheBody)
{
  for (const int form : Forms)
  {
    Scene scene = BearScene(vtkFFDBuildLattice::TRILINEAR, form);
    const std::vector<Vec> before = PointsOf(scene.Lattice);
    auto dynamics = MakeDynamics(scene);
    dynamics->SetGravity(0, 0, -9.81);
    const int steps = 120;
    ASSERT_TRUE(dynamics->Step(steps));
    const double h = dynamics->GetTimeStep();
    const double drop = -9.81 * h * h * steps * (steps + 1) / 2.0;
    const std::vector<Vec> after = PointsOf(scene.Lattice);
    double worst = 0;
    for (std::size_t p = 0; p < before.size(); ++p)
    {
      const bool simulated = dynamics->GetMass(vtkIdType(p)) > 0;
      const Vec want = { before[p][0], before[p][1], before[p][2] + (simulated ? drop : 0.0) };
      for (int c = 0; c < 3; ++c)
      {
        worst = std::max(worst, std::abs(after[p][c] - want[c]));
      }
    }
    EXPECT_LE(worst, 1e-10 * std::abs(drop)) << "form " << form;
  }
}

//------------------------------------------------------------------------------------------------------------
// Without external forces, pins or colliders the springs and the core are internal: the momentum the impulses
// gave stays. Tolerance as above: 100 steps of at most 10^3 epsilon relative: 1e-10 of the impulses' sum.
TEST(FFDLatticeDynamics, MomentumIsConservedWithoutExternalForces)
{
  for (const int form : Forms)
  {
    Scene scene = BearScene(vtkFFDBuildLattice::TRIQUADRATIC_BEZIER, form);
    auto dynamics = MakeDynamics(scene);
    std::mt19937 rng(7);
    ffdtest::Perturb(scene.Lattice, rng, 0.02 * scene.Size);
    ASSERT_TRUE(dynamics->Initialize()); // starts from the perturbed points
    std::uniform_real_distribution<double> d(-1.0, 1.0);
    double given[3] = { 0, 0, 0 }, scale = 0;
    for (vtkIdType p = 0; p < scene.Lattice->GetNumberOfPoints(); p += 7)
    {
      if (dynamics->GetMass(p) > 0)
      {
        const double j[3] = { d(rng), d(rng), d(rng) };
        dynamics->ApplyImpulse(p, j[0], j[1], j[2]);
        for (int c = 0; c < 3; ++c)
        {
          given[c] += j[c];
          scale += std::abs(j[c]);
        }
      }
    }
    ASSERT_TRUE(dynamics->Step(100));
    double momentum[3];
    dynamics->GetMomentum(momentum);
    for (int c = 0; c < 3; ++c)
    {
      EXPECT_NEAR(momentum[c], given[c], 1e-10 * scale) << "form " << form << " axis " << c;
    }
  }
}

//------------------------------------------------------------------------------------------------------------
// Damped springs and the core take a perturbed body to rest: the energy never exceeds its start and falls
// below 1e-6 of it within 20 s of simulated time; without damping it decays more slowly (backward Euler's own
// dissipation only).
TEST(FFDLatticeDynamics, EnergyDecaysToRest)
{
  Scene scene = BearScene(vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::SPARSE);
  const std::vector<Vec> rest = PointsOf(scene.Lattice);
  double remaining[2];
  for (const double damping : { 0.0, 0.05 })
  {
    for (vtkIdType p = 0; p < scene.Lattice->GetNumberOfPoints(); ++p)
    {
      scene.Lattice->GetPoints()->SetPoint(p, rest[p].data());
    }
    auto dynamics = MakeDynamics(scene);
    dynamics->SetSpringDamping(damping);
    std::mt19937 rng(3);
    ffdtest::Perturb(scene.Lattice, rng, 0.03 * scene.Size);
    ASSERT_TRUE(dynamics->Initialize());
    const double start = Energy(dynamics);
    ASSERT_GT(start, 0.0);
    double highest = 0;
    const int steps = int(20.0 / dynamics->GetTimeStep());
    for (int s = 0; s < steps; ++s)
    {
      ASSERT_TRUE(dynamics->Step());
      highest = std::max(highest, Energy(dynamics));
    }
    EXPECT_LE(highest, start) << "damping " << damping;
    remaining[damping > 0] = Energy(dynamics) / start;
  }
  EXPECT_LT(remaining[1], 1e-6);
  EXPECT_LT(remaining[1], remaining[0]);
}

//------------------------------------------------------------------------------------------------------------
// The explicit limit is real, and backward Euler is stable far past it. An explicit (symplectic Euler)
// integrator written here, on springs found here between the dense trilinear lattice's active neighbours, with
// the simulation's masses: stable at 0.9 times GetExplicitTimeStepLimit() (its energy within 10 times the
// start: symplectic Euler's energy oscillates by at most 1 / (1 - (h omega / 2)^2) = 5.3 there), blown up at 1.5
// times (the top mode grows by more than 2 a step). The simulation at 10 times the limit stays below its
// starting energy and comes to rest.
TEST(FFDLatticeDynamics, StableAtTenTimesTheExplicitLimit)
{
  Scene scene = BearScene(vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::DENSE);
  auto dynamics = MakeDynamics(scene);
  dynamics->SetSpringDamping(0.0);
  dynamics->SetCoreStiffness(0.0);
  ASSERT_TRUE(dynamics->Initialize());
  const double limit = dynamics->GetExplicitTimeStepLimit();
  ASSERT_GT(limit, 0.0);

  // The reference: particles and springs from the lattice's structure and Active array.
  vtkStructuredGrid* grid = vtkStructuredGrid::SafeDownCast(scene.Lattice);
  ASSERT_NE(grid, nullptr);
  int dims[3];
  grid->GetDimensions(dims);
  vtkDataArray* active = grid->GetPointData()->GetArray("Active");
  const std::vector<Vec> rest = PointsOf(grid);
  std::vector<std::array<vtkIdType, 2>> springs;
  for (int k = 0; k < dims[2]; ++k)
    for (int j = 0; j < dims[1]; ++j)
      for (int i = 0; i < dims[0]; ++i)
        for (int dk = -1; dk <= 1; ++dk)
          for (int dj = -1; dj <= 1; ++dj)
            for (int di = -1; di <= 1; ++di)
            {
              const int o[3] = { i + di, j + dj, k + dk };
              const vtkIdType a = i + dims[0] * (j + dims[1] * k), b = o[0] + dims[0] * (o[1] + dims[1] * o[2]);
              if (o[0] >= 0 && o[0] < dims[0] && o[1] >= 0 && o[1] < dims[1] && o[2] >= 0 && o[2] < dims[2] && a < b &&
                active->GetComponent(a, 0) != 0 && active->GetComponent(b, 0) != 0)
              {
                springs.push_back({ a, b });
              }
            }
  ASSERT_EQ(vtkIdType(springs.size()), dynamics->GetNumberOfSprings());
  const double k = dynamics->GetSpringStiffness();
  auto explicitRun = [&](double h, int steps)
  {
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> d(-1e-4 * scene.Size, 1e-4 * scene.Size);
    std::vector<Vec> x = rest, v(rest.size(), Vec{ 0, 0, 0 });
    for (vtkIdType p = 0; p < vtkIdType(x.size()); ++p)
    {
      for (int c = 0; c < 3 && dynamics->GetMass(p) > 0; ++c)
      {
        x[p][c] += d(rng);
      }
    }
    auto energy = [&]()
    {
      double e = 0;
      for (std::size_t p = 0; p < x.size(); ++p)
      {
        e += 0.5 * dynamics->GetMass(vtkIdType(p)) * ffdtest::Length(v[p]) * ffdtest::Length(v[p]);
      }
      for (const auto& s : springs)
      {
        const double stretch =
          ffdtest::Length(ffdref::Sub(x[s[1]], x[s[0]])) - ffdtest::Length(ffdref::Sub(rest[s[1]], rest[s[0]]));
        e += 0.5 * k * stretch * stretch;
      }
      return e;
    };
    const double start = energy();
    double highest = start;
    for (int n = 0; n < steps && highest < 1e12 * start; ++n)
    {
      std::vector<Vec> force(x.size(), Vec{ 0, 0, 0 });
      for (const auto& s : springs)
      {
        const Vec d = ffdref::Sub(x[s[1]], x[s[0]]);
        const double length = ffdtest::Length(d);
        const double pull = k * (length - ffdtest::Length(ffdref::Sub(rest[s[1]], rest[s[0]]))) / length;
        for (int c = 0; c < 3; ++c)
        {
          force[s[0]][c] += pull * d[c];
          force[s[1]][c] -= pull * d[c];
        }
      }
      for (std::size_t p = 0; p < x.size(); ++p)
      {
        const double m = dynamics->GetMass(vtkIdType(p));
        for (int c = 0; c < 3 && m > 0; ++c)
        {
          v[p][c] += h * force[p][c] / m;
          x[p][c] += h * v[p][c];
        }
      }
      highest = std::max(highest, energy());
    }
    return highest / start;
  };
  EXPECT_LT(explicitRun(0.9 * limit, 3000), 10.0);
  EXPECT_GT(explicitRun(1.5 * limit, 3000), 1e6);

  dynamics->SetTimeStep(10 * limit);
  dynamics->SetSpringDamping(1.0);
  std::mt19937 rng(9);
  ffdtest::Perturb(scene.Lattice, rng, 0.03 * scene.Size);
  ASSERT_TRUE(dynamics->Initialize());
  const double start = Energy(dynamics);
  double highest = 0;
  for (int s = 0; s < 2000; ++s)
  {
    ASSERT_TRUE(dynamics->Step());
    highest = std::max(highest, Energy(dynamics));
    ASSERT_TRUE(std::isfinite(highest));
  }
  EXPECT_LE(highest, start);
  EXPECT_LT(Energy(dynamics), 1e-6 * start);
}

//------------------------------------------------------------------------------------------------------------
// Pinned points are at their targets after every step (rest + (target - rest): within an ulp or two of the
// target), under gravity and a magnetic sphere, while the others move.
TEST(FFDLatticeDynamics, PinnedPointsStayAtTheirTargets)
{
  Scene scene = BearScene(vtkFFDBuildLattice::CUBIC_BSPLINE, vtkFFDBuildLattice::SPARSE);
  auto dynamics = MakeDynamics(scene);
  dynamics->SetGravity(0, -9.81, 0);
  vtkNew<vtkFFDMagneticSphere> sphere;
  sphere->SetCenter(scene.Lattice->GetPoint(0));
  sphere->SetRadius(0.1 * scene.Size);
  sphere->SetStrength(50);
  dynamics->AddMagneticSphere(sphere);
  const vtkIdType count = scene.Lattice->GetNumberOfPoints();
  std::map<vtkIdType, Vec> targets;
  for (const vtkIdType p : { vtkIdType(3), count / 2, count - 1 })
  {
    Vec x;
    scene.Lattice->GetPoint(p, x.data());
    x[0] += 0.05 * scene.Size;
    targets[p] = x;
    dynamics->PinPoint(p, x.data());
  }
  const std::vector<Vec> before = PointsOf(scene.Lattice);
  for (int s = 0; s < 30; ++s)
  {
    ASSERT_TRUE(dynamics->Step(10));
    for (const auto& target : targets)
    {
      Vec x;
      scene.Lattice->GetPoint(target.first, x.data());
      for (int c = 0; c < 3; ++c)
      {
        // rest + (target - rest): two roundings of at most half an ulp of the larger of rest and target.
        EXPECT_NEAR(x[c], target.second[c], 2 * Epsilon * (std::abs(target.second[c]) + scene.Size));
      }
    }
  }
  EXPECT_GT(ffdtest::Length(ffdref::Sub(PointsOf(scene.Lattice)[1], before[1])), 1e-3 * scene.Size);
}

//------------------------------------------------------------------------------------------------------------
// The magnetic sphere's field against its formula, and its path.
TEST(FFDMagneticSphere, AccelerationAndPath)
{
  vtkNew<vtkFFDMagneticSphere> sphere;
  sphere->SetCenter(1, 2, 3);
  sphere->SetRadius(0.5);
  sphere->SetStrength(4);
  sphere->SetFalloff(3);
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> d(-3, 3);
  for (int i = 0; i < 100; ++i)
  {
    const double x[3] = { 1 + d(rng), 2 + d(rng), 3 + d(rng) };
    const Vec toward = { 1 - x[0], 2 - x[1], 3 - x[2] };
    const double r = ffdtest::Length(toward);
    const double magnitude = r >= 0.5 ? 4 * std::pow(0.5 / r, 3) : 4 * r / 0.5;
    for (const int mode : { vtkFFDMagneticSphere::ATTRACT, vtkFFDMagneticSphere::REPEL })
    {
      sphere->SetMode(mode);
      double a[3];
      sphere->GetAcceleration(x, 0.0, a);
      for (int c = 0; c < 3; ++c)
      {
        const double want = (mode == vtkFFDMagneticSphere::ATTRACT ? 1 : -1) * magnitude * toward[c] / r;
        EXPECT_NEAR(a[c], want, 1e-14 * magnitude);
      }
    }
  }
  sphere->SetRange(1.0);
  const double far[3] = { 3, 2, 3 };
  double a[3];
  sphere->GetAcceleration(far, 0.0, a);
  EXPECT_EQ(a[0], 0.0);

  // A closed path: a circle of 32 points, one lap every 4 s.
  vtkNew<vtkPoints> path;
  for (int i = 0; i < 32; ++i)
  {
    path->InsertNextPoint(2 * std::cos(2 * vtkMath::Pi() * i / 32), 2 * std::sin(2 * vtkMath::Pi() * i / 32), 1);
  }
  sphere->SetPath(path);
  sphere->SetPeriod(4);
  double c0[3], c1[3], c2[3];
  sphere->GetCenterAt(0.0, c0);
  sphere->GetCenterAt(4.0, c1);
  sphere->GetCenterAt(2.0, c2);
  for (int c = 0; c < 3; ++c)
  {
    EXPECT_NEAR(c0[c], path->GetPoint(0)[c], 1e-12);
    EXPECT_NEAR(c1[c], c0[c], 1e-12);
    EXPECT_NEAR(c2[c], path->GetPoint(16)[c], 1e-12); // half-way along a symmetric path
  }
  for (double t = 0; t < 4; t += 0.1)
  {
    double c[3];
    sphere->GetCenterAt(t, c);
    EXPECT_NEAR(std::hypot(c[0], c[1]), 2.0, 2e-3); // a spline through a circle's points stays on it
  }
}

//------------------------------------------------------------------------------------------------------------
// A magnetic sphere accelerates each control point by a(d) of its formula: without springs or core, one step of
// backward Euler from rest moves each by h^2 a exactly in real numbers (the system is diagonal: within a few
// ulps of the motion). With them, it pulls (or pushes) the body as a whole: its centre of mass moves toward
// (away from) the sphere.
TEST(FFDLatticeDynamics, MagneticSpherePullsThePoints)
{
  for (const int mode : { vtkFFDMagneticSphere::ATTRACT, vtkFFDMagneticSphere::REPEL })
  {
    Scene scene = BearScene(vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::DENSE);
    const std::vector<Vec> before = PointsOf(scene.Lattice);
    double bounds[6];
    scene.Lattice->GetBounds(bounds);
    const Vec centre = { bounds[1] + 0.1 * scene.Size, 0.5 * (bounds[2] + bounds[3]), 0.5 * (bounds[4] + bounds[5]) };
    const double radius = 0.1 * scene.Size, strength = 20;
    auto dynamics = MakeDynamics(scene);
    vtkNew<vtkFFDMagneticSphere> sphere;
    sphere->SetCenter(centre.data());
    sphere->SetRadius(radius);
    sphere->SetStrength(strength);
    sphere->SetMode(mode);
    dynamics->AddMagneticSphere(sphere);
    dynamics->SetSpringStiffness(0);
    dynamics->SetSpringDamping(0);
    dynamics->SetCoreStiffness(0);
    ASSERT_TRUE(dynamics->Step());
    const double h = dynamics->GetTimeStep();
    for (vtkIdType p = 0; p < vtkIdType(before.size()); ++p)
    {
      const Vec toward = ffdref::Sub(centre, before[p]);
      const double d = ffdtest::Length(toward);
      const double a = (d >= radius ? strength * std::pow(radius / d, 2.0) : strength * d / radius) *
        (mode == vtkFFDMagneticSphere::ATTRACT ? 1 : -1) * (dynamics->GetMass(p) > 0 ? 1 : 0);
      Vec x;
      scene.Lattice->GetPoint(p, x.data());
      for (int c = 0; c < 3; ++c)
      {
        EXPECT_NEAR(x[c], before[p][c] + h * h * a * toward[c] / d, 8 * Epsilon * (std::abs(x[c]) + scene.Size));
      }
    }

    dynamics->SetSpringStiffness(100);
    dynamics->SetCoreStiffness(10);
    ASSERT_TRUE(dynamics->Step(30));
    Vec shift = { 0, 0, 0 };
    for (vtkIdType p = 0; p < vtkIdType(before.size()); ++p)
    {
      Vec x;
      scene.Lattice->GetPoint(p, x.data());
      for (int c = 0; c < 3; ++c)
      {
        shift[c] += dynamics->GetMass(p) * (x[c] - before[p][c]);
      }
    }
    const double along = ffdref::Dot(shift,
      ffdref::Sub(centre,
        ffdtest::Vec{ 0.5 * (bounds[0] + bounds[1]), 0.5 * (bounds[2] + bounds[3]), 0.5 * (bounds[4] + bounds[5]) }));
    EXPECT_TRUE(mode == vtkFFDMagneticSphere::ATTRACT ? along > 0 : along < 0) << "mode " << mode;
  }
}

//------------------------------------------------------------------------------------------------------------
// A collider (a ground plane under the body) stops the falling lattice: every simulated point ends on or above
// it (Newton's projection onto a plane is exact to rounding: 1e-12 of the frame), at rest on it.
TEST(FFDLatticeDynamics, CollidersKeepPointsOut)
{
  Scene scene = BearScene(vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::SPARSE);
  double bounds[6];
  scene.Lattice->GetBounds(bounds);
  auto dynamics = MakeDynamics(scene);
  dynamics->SetGravity(0, 0, -9.81);
  vtkNew<vtkPlane> ground;
  ground->SetOrigin(0, 0, bounds[4] - 0.1 * scene.Size);
  ground->SetNormal(0, 0, 1);
  dynamics->AddCollider(ground);
  ASSERT_TRUE(dynamics->Step(600));
  double lowest = VTK_DOUBLE_MAX;
  for (vtkIdType p = 0; p < scene.Lattice->GetNumberOfPoints(); ++p)
  {
    lowest = std::min(lowest, scene.Lattice->GetPoint(p)[2]);
  }
  EXPECT_GE(lowest, ground->GetOrigin()[2] - 1e-12 * scene.Size);
  EXPECT_LT(lowest, ground->GetOrigin()[2] + 0.05 * scene.Size); // it fell onto the plane
}

//------------------------------------------------------------------------------------------------------------
// vtkFFDDeform downstream of a simulated lattice re-evaluates at each step without binding again, and its
// output is the float64 reference X + sum w D of the moved lattice (within 1e-12 of the frame's diagonal).
TEST(FFDLatticeDynamics, DeformFollowsWithoutRebinding)
{
  Scene scene = BearScene(vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::DENSE);
  auto dynamics = MakeDynamics(scene);
  vtkNew<vtkFFDMagneticSphere> sphere;
  sphere->SetCenter(scene.Lattice->GetPoint(scene.Lattice->GetNumberOfPoints() / 2));
  sphere->SetRadius(0.2 * scene.Size);
  sphere->SetStrength(30);
  dynamics->AddMagneticSphere(sphere);
  vtkNew<vtkFFDDeform> deform;
  deform->SetInputData(scene.Mesh);
  deform->SetLatticeData(scene.Lattice);
  deform->SetBackendToCPU();
  deform->Update();
  EXPECT_EQ(deform->GetNumberOfBindings(), 1);
  for (int frame = 0; frame < 5; ++frame)
  {
    ASSERT_TRUE(dynamics->Step(5));
    deform->Update();
    EXPECT_EQ(deform->GetNumberOfBindings(), 1);
    EXPECT_LE(ffdtest::MaxRelativeError(scene.Mesh, deform->GetOutput(), ffdtest::ReferenceOf(scene.Lattice)), 1e-12);
  }
}

//------------------------------------------------------------------------------------------------------------
// The pipeline form: the lattice at time t is the same whether t is asked at once, after an earlier time, or
// after a later one (which starts again); t = 0 is the input.
TEST(FFDSimulateLattice, TheLatticeAtATimeDoesNotDependOnTheRequests)
{
  Scene scene = BearScene(vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::SPARSE);
  vtkNew<vtkFFDSimulateLattice> simulate;
  simulate->SetInputData(scene.Lattice);
  simulate->SetMeshData(scene.Mesh);
  simulate->SetEndTime(2.0);
  vtkNew<vtkFFDMagneticSphere> sphere;
  vtkNew<vtkPoints> path;
  double bounds[6];
  scene.Lattice->GetBounds(bounds);
  for (int i = 0; i < 8; ++i)
  {
    const double angle = 2 * vtkMath::Pi() * i / 8;
    path->InsertNextPoint(0.5 * (bounds[0] + bounds[1]) + 0.6 * scene.Size * std::cos(angle),
      0.5 * (bounds[2] + bounds[3]) + 0.6 * scene.Size * std::sin(angle), 0.5 * (bounds[4] + bounds[5]));
  }
  sphere->SetPath(path);
  sphere->SetPeriod(2.0);
  sphere->SetRadius(0.1 * scene.Size);
  sphere->SetStrength(40);
  simulate->GetDynamics()->AddMagneticSphere(sphere);

  simulate->UpdateInformation();
  double range[2];
  simulate->GetOutputInformation(0)->Get(vtkStreamingDemandDrivenPipeline::TIME_RANGE(), range);
  EXPECT_EQ(range[0], 0.0);
  EXPECT_EQ(range[1], 2.0);

  auto at = [&](double t)
  {
    simulate->UpdateTimeStep(t);
    EXPECT_EQ(simulate->GetOutput()->GetInformation()->Get(vtkDataObject::DATA_TIME_STEP()), t);
    return PointsOf(vtkPointSet::SafeDownCast(simulate->GetOutput()));
  };
  EXPECT_EQ(at(0.0), PointsOf(scene.Lattice));
  const std::vector<Vec> direct = at(1.0);
  EXPECT_NE(direct, PointsOf(scene.Lattice));
  simulate->GetDynamics()->SetTimeStep(1.0 / 59.0); // any change starts again
  simulate->GetDynamics()->SetTimeStep(1.0 / 60.0);
  at(0.5);
  EXPECT_EQ(at(1.0), direct); // continued from 0.5
  at(1.5);
  EXPECT_EQ(at(1.0), direct); // started again
}

//------------------------------------------------------------------------------------------------------------
// Bad input: an error message each, no crash, and nothing moved.
TEST(FFDLatticeDynamics, BadInputGivesErrors)
{
  vtkNew<FFDTestErrorObserver> errors;
  vtkNew<vtkFFDLatticeDynamics> dynamics;
  errors->Watch(dynamics);
  auto saw = [&](const char* what) { return errors->Errors.find(what) != std::string::npos; };
  EXPECT_FALSE(dynamics->Step());
  EXPECT_TRUE(saw("No lattice to simulate"));
  EXPECT_FALSE(dynamics->Step(-1));
  EXPECT_TRUE(saw("cannot be negative"));

  Scene scene = BearScene(vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::DENSE);
  const std::vector<Vec> before = PointsOf(scene.Lattice);
  dynamics->SetLattice(scene.Lattice);
  dynamics->SetMesh(scene.Mesh);
  vtkIdType culled = -1;
  for (vtkIdType p = 0; p < scene.Lattice->GetNumberOfPoints() && culled < 0; ++p)
  {
    culled = scene.Lattice->GetPointData()->GetArray("Active")->GetComponent(p, 0) == 0 ? p : -1;
  }
  ASSERT_GE(culled, 0);
  dynamics->PinPoint(culled, 0, 0, 0);
  EXPECT_FALSE(dynamics->Step());
  EXPECT_TRUE(saw("is pinned but is not a simulated control point"));
  dynamics->UnpinAllPoints();
  EXPECT_FALSE(dynamics->ApplyImpulse(-4, 1, 0, 0));
  EXPECT_TRUE(saw("ApplyImpulse(-4, ...): the lattice has no point -4"));
  EXPECT_EQ(PointsOf(scene.Lattice), before);

  vtkSmartPointer<vtkDataArray> rest = scene.Lattice->GetPointData()->GetArray("RestPosition");
  scene.Lattice->GetPointData()->RemoveArray("RestPosition");
  EXPECT_FALSE(dynamics->Step());
  EXPECT_TRUE(saw("no RestPosition"));
  scene.Lattice->GetPointData()->AddArray(rest);
  vtkNew<vtkUnsignedCharArray> active;
  active->SetName("Active");
  active->SetNumberOfValues(3);
  scene.Lattice->GetPointData()->AddArray(active);
  EXPECT_FALSE(dynamics->Step());
  EXPECT_TRUE(saw("Active point array") && saw("one value per point"));
  active->SetNumberOfValues(scene.Lattice->GetNumberOfPoints());
  active->Fill(0);
  EXPECT_FALSE(dynamics->Step());
  EXPECT_TRUE(saw("no active control point"));
  EXPECT_EQ(PointsOf(scene.Lattice), before);
}

//------------------------------------------------------------------------------------------------------------
// Issue 30, item 2: bear -> lattice -> vtkFFDSimulateLattice (gravity, onto a plane) -> vtkFFDDeform. The deformed
// mesh follows the simulation: vtkFFDDeform announces the lattice's time range (before, only the static mesh's:
// none, so a time request never re-executed it) and at each time equals the mesh deformed by the lattice that the
// simulation outputs at that time, through a vtkFFDDeform of its own (the same bits) and the float64 reference
// (within 1e-12 of the frame's diagonal, as in DeformFollowsWithoutRebinding); the bear falls.
TEST(FFDSimulateLattice, DeformFollowsTheSimulationOverTime)
{
  Scene scene = BearScene(vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::DENSE);
  auto simulate = FallingLattice(scene, 1.0);
  vtkNew<vtkFFDDeform> deform;
  deform->SetInputData(scene.Mesh);
  deform->SetLatticeConnection(simulate->GetOutputPort());
  deform->SetBackendToCPU();
  const auto times = TimesOf(deform);
  EXPECT_TRUE(times.first.empty());
  EXPECT_EQ(times.second, (std::array<double, 2>{ 0.0, 1.0 }));

  std::vector<double> lowest;
  for (const double t : { 0.0, 0.25, 0.5, 1.0, 0.5 }) // the last one earlier: the simulation starts again
  {
    ASSERT_TRUE(deform->UpdateTimeStep(t));
    vtkPointSet* lattice = vtkPointSet::SafeDownCast(simulate->GetOutput());
    EXPECT_EQ(lattice->GetInformation()->Get(vtkDataObject::DATA_TIME_STEP()), t);
    auto copy = vtk::TakeSmartPointer(lattice->NewInstance());
    copy->ShallowCopy(lattice);
    vtkNew<vtkFFDDeform> alone;
    alone->SetInputData(scene.Mesh);
    alone->SetLatticeData(copy);
    alone->SetBackendToCPU();
    alone->Update();
    EXPECT_EQ(PointsOf(deform->GetOutput()), PointsOf(alone->GetOutput())) << "time " << t;
    EXPECT_LE(ffdtest::MaxRelativeError(scene.Mesh, deform->GetOutput(), ffdtest::ReferenceOf(copy)), 1e-12)
      << "time " << t;
    lowest.push_back(deform->GetOutput()->GetBounds()[4]);
  }
  EXPECT_EQ(deform->GetNumberOfBindings(), 1); // the lattice's points moved, its rest state did not
  EXPECT_EQ(lowest[0], scene.Mesh->GetBounds()[4]);
  EXPECT_LT(lowest[1], lowest[0] - 0.1 * scene.Size); // fallen
  EXPECT_EQ(lowest[4], lowest[2]);
}

//------------------------------------------------------------------------------------------------------------
// vtkFFDDeform announces the times of both inputs, as the executive alone did of input 0's: the union of their
// ranges, and of their steps where both have steps; and asks both inputs for the time asked of it.
TEST(FFDDeform, AnnouncesTheTimesOfTheMeshAndTheLattice)
{
  Scene scene = BearScene(vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::DENSE);
  vtkNew<TimedInput> mesh;
  mesh->SetInputData(scene.Mesh);
  mesh->Steps = { 0.0, 0.5, 3.0 };
  vtkNew<TimedInput> lattice;
  lattice->SetInputData(scene.Lattice);
  lattice->Steps = { 0.25, 0.5, 4.0 };
  vtkNew<vtkFFDDeform> deform;
  deform->SetInputConnection(mesh->GetOutputPort());
  deform->SetLatticeData(scene.Lattice);
  using Times = std::pair<std::vector<double>, std::array<double, 2>>;
  EXPECT_EQ(TimesOf(deform), (Times{ { 0.0, 0.5, 3.0 }, { 0.0, 3.0 } })); // the mesh's, as before
  deform->SetLatticeConnection(lattice->GetOutputPort());
  EXPECT_EQ(TimesOf(deform), (Times{ { 0.0, 0.25, 0.5, 3.0, 4.0 }, { 0.0, 4.0 } }));
  lattice->RangeOnly = true;
  lattice->Modified();
  EXPECT_EQ(TimesOf(deform), (Times{ {}, { 0.0, 4.0 } })); // continuous in time
  deform->SetInputData(scene.Mesh);
  EXPECT_EQ(TimesOf(deform), (Times{ {}, { 0.25, 4.0 } })); // the lattice's alone
  deform->SetInputConnection(mesh->GetOutputPort());
  ASSERT_TRUE(deform->UpdateTimeStep(2.0));
  EXPECT_EQ(mesh->Asked, 2.0);
  EXPECT_EQ(lattice->Asked, 2.0);
}

//------------------------------------------------------------------------------------------------------------
// The other filters with a lattice on input 1 announce its times too (before: input 0's alone, so a simulated
// lattice never re-executed them), and ask it for the time asked of them.
TEST(FFDDeform, BlocksAndInverseAnnounceTheTimesOfTheirLattices)
{
  Scene scene = BearScene(vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::DENSE);
  vtkNew<TimedInput> lattice;
  lattice->SetInputData(scene.Lattice);
  lattice->Steps = { 0.25, 0.5, 4.0 };
  vtkNew<vtkFFDDeformBlocks> blocks;
  blocks->SetInputData(scene.Mesh);
  blocks->AddLatticeConnection(lattice->GetOutputPort());
  vtkNew<vtkFFDInverseDeform> inverse;
  inverse->SetInputData(scene.Mesh);
  inverse->SetLatticeConnection(lattice->GetOutputPort());
  using Times = std::pair<std::vector<double>, std::array<double, 2>>;
  double time = 2.0; // a new time for each filter, so that the lattice executes again
  for (vtkAlgorithm* filter : { static_cast<vtkAlgorithm*>(blocks), static_cast<vtkAlgorithm*>(inverse) })
  {
    SCOPED_TRACE(filter->GetClassName());
    EXPECT_EQ(TimesOf(filter), (Times{ { 0.25, 0.5, 4.0 }, { 0.25, 4.0 } }));
    ASSERT_TRUE(filter->UpdateTimeStep(time));
    EXPECT_EQ(lattice->Asked, time);
    time += 1.0;
  }
}

//------------------------------------------------------------------------------------------------------------
// Issue 30, item 11: a time beyond EndTime is the lattice at EndTime (as a reader gives its last step), not a
// simulation of that time: 1e5 s with EndTime 1 s and steps of 0.1 s is 10 steps (before: a million, and the
// output said 1e5 s). A time before 0 is the input.
TEST(FFDSimulateLattice, TimesOutsideTheRangeAreClamped)
{
  Scene scene = BearScene(vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::SPARSE);
  auto at = [&](double t, double* dataTime = nullptr, double* simulated = nullptr)
  {
    auto simulate = FallingLattice(scene, 1.0);
    simulate->GetDynamics()->SetTimeStep(0.1);
    EXPECT_TRUE(simulate->UpdateTimeStep(t));
    if (dataTime)
    {
      *dataTime = simulate->GetOutput()->GetInformation()->Get(vtkDataObject::DATA_TIME_STEP());
      *simulated = simulate->GetDynamics()->GetTime();
    }
    return PointsOf(vtkPointSet::SafeDownCast(simulate->GetOutput()));
  };
  double dataTime = -1, simulated = -1;
  const std::vector<Vec> far = at(1e5, &dataTime, &simulated);
  EXPECT_EQ(dataTime, 1.0);
  EXPECT_NEAR(simulated, 1.0, 10 * Epsilon); // 10 additions of 0.1
  EXPECT_EQ(far, at(1.0));
  EXPECT_NE(far, PointsOf(scene.Lattice));
  EXPECT_EQ(at(-5.0, &dataTime, &simulated), PointsOf(scene.Lattice));
  EXPECT_EQ(dataTime, 0.0);
}

//------------------------------------------------------------------------------------------------------------
// An update runs at most MaximumNumberOfSteps steps: farther is an error that says how far, at once, and leaves no
// output; a later time continues from the last one. Bad EndTime and MaximumNumberOfSteps are errors in
// RequestData. A long run reports progress and stops when aborted, with an empty output.
TEST(FFDSimulateLattice, StepsPerUpdateAreBoundedAndAbortable)
{
  Scene scene = BearScene(vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::DENSE, 3);
  auto simulate = FallingLattice(scene, 1e5);
  vtkNew<FFDTestErrorObserver> errors;
  errors->WatchWithExecutive(simulate);
  errors->Watch(simulate->GetDynamics());
  auto fails = [&](double t, const std::string& message)
  {
    errors->Errors.clear();
    EXPECT_FALSE(simulate->UpdateTimeStep(t)) << t;
    EXPECT_NE(errors->Errors.find(message), std::string::npos) << errors->Errors;
    EXPECT_EQ(vtkPointSet::SafeDownCast(simulate->GetOutput())->GetNumberOfPoints(), 0);
  };
  fails(1e5,
    "Time 100000 s is 6e+06 time steps of 0.0166667 s from the last simulated time (0 s): more than the "
    "100000 an update may run. Raise SetMaximumNumberOfSteps()");
  simulate->SetMaximumNumberOfSteps(100);
  EXPECT_TRUE(simulate->UpdateTimeStep(1.0)); // 60 steps
  EXPECT_TRUE(simulate->UpdateTimeStep(2.0)); // 60 more
  fails(4.0, "Time 4 s is 120 time steps");   // from 2 s
  simulate->SetMaximumNumberOfSteps(0);
  fails(1.0, "SetMaximumNumberOfSteps(0): it must be at least 1");
  simulate->SetMaximumNumberOfSteps(100000);
  simulate->SetEndTime(std::numeric_limits<double>::quiet_NaN());
  EXPECT_EQ(TimesOf(simulate).second, (std::array<double, 2>{ 1, -1 })); // no range announced
  fails(1.0, "SetEndTime(nan): the end time (s) must be a finite number >= 0");
  simulate->SetEndTime(-1);
  fails(1.0, "SetEndTime(-1)");
  simulate->SetEndTime(1e5);
  simulate->GetDynamics()->SetTimeStep(std::numeric_limits<double>::quiet_NaN());
  fails(1.0, "SetTimeStep(nan): the time step (s) must be a finite number > 0");
  simulate->GetDynamics()->SetTimeStep(1.0 / 60.0);

  int progressEvents = 0; // during the run: the executive reports 0 before it and 1 after it
  vtkNew<vtkCallbackCommand> abort;
  abort->SetClientData(&progressEvents);
  abort->SetCallback(
    [](vtkObject* caller, unsigned long, void* clientData, void* callData)
    {
      const double progress = *static_cast<double*>(callData);
      if (progress > 0 && progress < 1)
      {
        ++*static_cast<int*>(clientData);
        vtkAlgorithm::SafeDownCast(caller)->SetAbortExecute(1);
      }
    });
  simulate->AddObserver(vtkCommand::ProgressEvent, abort);
  errors->Errors.clear();
  simulate->UpdateTimeStep(1000.0); // 60,000 steps: the first progress report, after 600, aborts
  EXPECT_EQ(errors->Errors, "");
  EXPECT_EQ(progressEvents, 1);
  EXPECT_NEAR(simulate->GetDynamics()->GetTime(), 600 / 60.0, 600 * Epsilon * 10.0);
  EXPECT_EQ(vtkPointSet::SafeDownCast(simulate->GetOutput())->GetNumberOfPoints(), 0);
}

//------------------------------------------------------------------------------------------------------------
// Issue 30, item 17: a missing or wrong-typed input is one error that names the input and what to connect, and
// leaves no output (before: only the executive's "returned failure for request").
TEST(FFDSimulateLattice, InputErrorsSayWhatToConnect)
{
  Scene scene = BearScene(vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::DENSE, 3);
  vtkNew<vtkFFDSimulateLattice> simulate;
  simulate->SetInputData(scene.Lattice);
  simulate->SetMeshData(scene.Mesh);
  ffdtest::ExpectClearInputErrors(simulate, 0, "the lattice", "SetInputConnection() to the lattice to simulate");
  ffdtest::ExpectClearInputErrors(simulate, 1, "the mesh", "SetMeshConnection()", true);
}

TEST(FFDDeform, InputErrorsSayWhatToConnect)
{
  Scene scene = BearScene(vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::DENSE, 3);
  vtkNew<vtkFFDDeform> deform;
  deform->SetInputData(scene.Mesh);
  deform->SetLatticeData(scene.Lattice);
  ffdtest::ExpectClearInputErrors(deform, 0, "the mesh", "SetInputConnection() to the mesh to deform");
  ffdtest::ExpectClearInputErrors(deform, 1, "the lattice", "SetLatticeConnection()");
}

//------------------------------------------------------------------------------------------------------------
// Issue 30, item 15: a setting that cannot be simulated (NaN, infinite, out of range) is an error naming its
// setter when Step() uses it, Step() returns false, and the lattice and the simulation's time are unchanged (before:
// NaN filled every control point and Step() succeeded; TotalMass <= 0, infinite stiffnesses and Iterations out of
// [1, 1000] were clamped silently, infinite stiffness freezing a falling body). Restoring the setting lets the
// simulation go on.
TEST(FFDLatticeDynamics, SettingsThatCannotBeSimulatedAreErrors)
{
  Scene scene = BearScene(vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::SPARSE);
  auto dynamics = MakeDynamics(scene);
  dynamics->SetGravity(0, 0, -9.81);
  vtkNew<vtkFFDMagneticSphere> sphere;
  sphere->SetCenter(scene.Lattice->GetCenter());
  dynamics->AddMagneticSphere(sphere);
  vtkNew<vtkPlane> collider;
  collider->SetOrigin(0, 0, scene.Lattice->GetBounds()[4] - scene.Size);
  dynamics->AddCollider(collider);
  vtkNew<FFDTestErrorObserver> errors;
  errors->Watch(dynamics);
  ASSERT_TRUE(dynamics->Step(3));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  struct Case
  {
    std::function<void(double)> Set;
    double Good;
    std::vector<double> Bad;
    std::string Message; // begins the error; the bad value follows it
  };
  const std::vector<Case> cases = {
    { [&](double v) { dynamics->SetTimeStep(v); }, 1.0 / 60, { nan, inf, 0, -1 }, "SetTimeStep(" },
    { [&](double v) { dynamics->SetTotalMass(v); }, 1, { nan, inf, 0, -1 }, "SetTotalMass(" },
    { [&](double v) { dynamics->SetMinimumMassFraction(v); }, 0.01, { nan, 0, 2 }, "SetMinimumMassFraction(" },
    { [&](double v) { dynamics->SetSpringStiffness(v); }, 1, { nan, inf, -1 }, "SetSpringStiffness(" },
    { [&](double v) { dynamics->SetSpringDamping(v); }, 0.01, { nan, inf, -1 }, "SetSpringDamping(" },
    { [&](double v) { dynamics->SetCoreStiffness(v); }, 10, { nan, inf, -1 }, "SetCoreStiffness(" },
    { [&](double v) { dynamics->SetIterations(int(v)); }, 10, { 0, 1001 }, "SetIterations(" },
    { [&](double v) { dynamics->SetGravity(0, v, -9.81); }, 0, { nan, inf }, "SetGravity(0, " },
    { [&](double v) { sphere->SetCenter(v, 0, 0); }, 0, { nan, -inf }, "Magnetic sphere 0: SetCenter(" },
    { [&](double v) { sphere->SetRadius(v); }, 1, { nan, 0, -1 }, "Magnetic sphere 0: SetRadius(" },
    { [&](double v) { sphere->SetStrength(v); }, 1, { nan, inf, -1 }, "Magnetic sphere 0: SetStrength(" },
    { [&](double v) { sphere->SetFalloff(v); }, 2, { nan, -1 }, "Magnetic sphere 0: SetFalloff(" },
    { [&](double v) { sphere->SetRange(v); }, 0, { nan, -1 }, "Magnetic sphere 0: SetRange(" },
    { [&](double v) { sphere->SetPeriod(v); }, 1, { nan, 0 }, "Magnetic sphere 0: SetPeriod(" },
  };
  for (const Case& c : cases)
  {
    for (const double bad : c.Bad)
    {
      std::ostringstream message;
      message << c.Message << bad;
      c.Set(bad);
      const std::vector<Vec> before = PointsOf(scene.Lattice);
      const double time = dynamics->GetTime();
      errors->Errors.clear();
      EXPECT_FALSE(dynamics->Step(2)) << message.str();
      EXPECT_NE(errors->Errors.find("): " + message.str()), std::string::npos) << errors->Errors;
      EXPECT_EQ(PointsOf(scene.Lattice), before) << message.str();
      EXPECT_EQ(dynamics->GetTime(), time) << message.str();
      c.Set(c.Good);
    }
    EXPECT_TRUE(dynamics->Step(2)) << c.Message;
  }

  // A path with a point that is not finite, a pin's target, a collider that is not a number, springs that would
  // lose the body's motion to rounding (1e300: the body froze), and gravity that overflows the positions.
  auto fails = [&](const std::string& message)
  {
    const std::vector<Vec> before = PointsOf(scene.Lattice);
    const double time = dynamics->GetTime();
    errors->Errors.clear();
    EXPECT_FALSE(dynamics->Step(2)) << message;
    EXPECT_NE(errors->Errors.find(message), std::string::npos) << errors->Errors;
    EXPECT_EQ(PointsOf(scene.Lattice), before) << message;
    EXPECT_EQ(dynamics->GetTime(), time) << message;
  };
  vtkNew<vtkPoints> path;
  path->InsertNextPoint(0, 0, 0);
  path->InsertNextPoint(nan, 1, 0);
  sphere->SetPath(path);
  fails("Magnetic sphere 0: point 1 of its path (SetPath()) is (nan, 1, 0)");
  sphere->SetPath(nullptr);
  const vtkIdType pinned = scene.Lattice->GetNumberOfPoints() / 2;
  dynamics->PinPoint(pinned, 0, inf, 0);
  fails("PinPoint(" + std::to_string(pinned) + ", 0, inf, 0): the target must be finite");
  dynamics->UnpinAllPoints();
  collider->SetNormal(nan, 0, 1);
  fails("collider 0 (of AddCollider(), counted from 0) is not a number at a control point");
  collider->SetNormal(0, 0, 1);
  dynamics->SetSpringStiffness(1e300);
  fails("The springs are too stiff for the time step and the masses");
  dynamics->SetSpringStiffness(0); // springs of a step of 1e3 s would be too stiff
  dynamics->SetSpringDamping(0);
  dynamics->RemoveAllColliders(); // which would turn the overflow into NaN
  dynamics->SetTimeStep(1e3);
  dynamics->SetGravity(0, 0, -1e306);
  fails("Step 1 of 2 (at time ");
  EXPECT_NE(errors->Errors.find("its positions are not finite"), std::string::npos);
  dynamics->SetSpringStiffness(1);
  dynamics->SetSpringDamping(0.01);
  dynamics->SetTimeStep(1.0 / 60);
  dynamics->SetGravity(0, 0, -9.81);
  EXPECT_TRUE(dynamics->Step(2));
}

//------------------------------------------------------------------------------------------------------------
// The stiffness bound lets through what the simulation solves accurately: springs of 1e6 (a ratio of about 5e6 on
// this lattice, under the bound of 1e8) fall under gravity as backward Euler's translation, to 1e-6 of the drop
// (the solve's error is about epsilon times the ratio times the neighbours: 1e-8 here).
TEST(FFDLatticeDynamics, StiffSpringsUnderTheBoundFallRightly)
{
  Scene scene = BearScene(vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::DENSE);
  const std::vector<Vec> before = PointsOf(scene.Lattice);
  auto dynamics = MakeDynamics(scene);
  dynamics->SetSpringStiffness(1e6);
  dynamics->SetGravity(0, 0, -9.81);
  ASSERT_TRUE(dynamics->Step(60));
  const double h = dynamics->GetTimeStep();
  const double drop = -9.81 * h * h * 60 * 61 / 2.0;
  for (vtkIdType p = 0; p < scene.Lattice->GetNumberOfPoints(); ++p)
  {
    const double want = before[p][2] + (dynamics->GetMass(p) > 0 ? drop : 0.0);
    EXPECT_NEAR(scene.Lattice->GetPoint(p)[2], want, 1e-6 * std::abs(drop)) << p;
  }
}

//------------------------------------------------------------------------------------------------------------
// Issue 30, item 15: impulses applied before the first step are queued and applied by it (before: the step's
// initialization discarded them), so the momentum is theirs; ids and values are checked when applied (a point the
// lattice does not have, a non-finite impulse: refused with an error), and a queued impulse on a point that is not
// simulated is an error at the step, which then leaves the lattice unchanged and drops that impulse only.
TEST(FFDLatticeDynamics, ImpulsesBeforeTheFirstStepAreQueued)
{
  Scene scene = BearScene(vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::DENSE);
  auto dynamics = MakeDynamics(scene);
  vtkNew<FFDTestErrorObserver> errors;
  errors->Watch(dynamics);
  vtkDataArray* active = scene.Lattice->GetPointData()->GetArray("Active");
  vtkIdType simulated = -1, culled = -1;
  for (vtkIdType p = 0; p < scene.Lattice->GetNumberOfPoints(); ++p)
  {
    (active->GetComponent(p, 0) != 0 ? simulated : culled) = p;
  }
  ASSERT_GE(simulated, 0);
  ASSERT_GE(culled, 0);
  const vtkIdType count = scene.Lattice->GetNumberOfPoints();
  EXPECT_FALSE(dynamics->ApplyImpulse(count, 1, 0, 0));
  EXPECT_NE(errors->Errors.find("the lattice has no point " + std::to_string(count) + " (it has " +
              std::to_string(count) + "). The impulse is ignored."),
    std::string::npos)
    << errors->Errors;
  EXPECT_FALSE(dynamics->ApplyImpulse(simulated, std::numeric_limits<double>::quiet_NaN(), 0, 0));
  EXPECT_NE(errors->Errors.find("the impulse must be finite"), std::string::npos) << errors->Errors;

  EXPECT_TRUE(dynamics->ApplyImpulse(simulated, 0.5, -0.25, 0.125));
  EXPECT_TRUE(dynamics->ApplyImpulse(culled, 1, 1, 1)); // not known to be culled until the simulation starts
  const std::vector<Vec> before = PointsOf(scene.Lattice);
  errors->Errors.clear();
  EXPECT_FALSE(dynamics->Step(10));
  EXPECT_NE(errors->Errors.find("An impulse was applied to point " + std::to_string(culled) +
              ", which is not a simulated control point of the lattice: it is dropped."),
    std::string::npos)
    << errors->Errors;
  EXPECT_EQ(PointsOf(scene.Lattice), before);
  EXPECT_EQ(dynamics->GetTime(), 0.0);
  EXPECT_FALSE(dynamics->ApplyImpulse(culled, 1, 1, 1)); // started: known now
  EXPECT_NE(errors->Errors.find("the point is not a simulated (Active) control point"), std::string::npos);

  // The momentum is the queued impulse's: no external forces (tolerance as in
  // MomentumIsConservedWithoutExternalForces: 1e-10 of the impulse).
  ASSERT_TRUE(dynamics->Step(10));
  double momentum[3];
  dynamics->GetMomentum(momentum);
  const double given[3] = { 0.5, -0.25, 0.125 };
  for (int c = 0; c < 3; ++c)
  {
    EXPECT_NEAR(momentum[c], given[c], 1e-10 * 0.875) << "axis " << c;
  }
}
