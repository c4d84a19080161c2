// SPDX-License-Identifier: BSD-3-Clause
// The CUDA backend for tetrahedral lattices against an independent float64 reference written from the paper's
// equation 5 (barycentric weights as signed sub-volume ratios, the deformed point as the weighted sum of the
// moved nodes), on random tetrahedral meshes with fixed seeds, in float32 and float64, the deformation and its
// adjoint; device residency (an update uploads only the nodes' displacements); failures. Without a CUDA device every
// test skips but the last.
#include "FFDCudaTestSupport.h"
#include "FFDCudaTetrahedralDeformer.h"
#include "FFDTestComparisons.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

namespace
{
using ffdtest::TetrahedralMesh;

//------------------------------------------------------------------------------------------------------------
// The reference, in float64 and without the kernels' functions.

// Six times the signed volume of the tetrahedron (a, b, c, d).
double Volume6(const double* a, const double* b, const double* c, const double* d)
{
  const double u[3] = { b[0] - a[0], b[1] - a[1], b[2] - a[2] };
  const double v[3] = { c[0] - a[0], c[1] - a[1], c[2] - a[2] };
  const double w[3] = { d[0] - a[0], d[1] - a[1], d[2] - a[2] };
  return u[0] * (v[1] * w[2] - v[2] * w[1]) + u[1] * (v[2] * w[0] - v[0] * w[2]) + u[2] * (v[0] * w[1] - v[1] * w[0]);
}

// Equation 5: the barycentric weights of x in tetrahedron t, each the volume of the tetrahedron with x in place
// of that node over the tetrahedron's volume.
void Weights(const TetrahedralMesh& mesh, std::int64_t t, const double x[3], double w[4])
{
  const double* n[4] = { mesh.Node(t, 0), mesh.Node(t, 1), mesh.Node(t, 2), mesh.Node(t, 3) };
  const double volume = Volume6(n[0], n[1], n[2], n[3]);
  for (int i = 0; i < 4; ++i)
  {
    const double* m[4] = { n[0], n[1], n[2], n[3] };
    m[i] = x;
    w[i] = Volume6(m[0], m[1], m[2], m[3]) / volume;
  }
}

struct Reference
{
  double Point[3];
  double Normal[3];
  double Determinant;
  double Scale;        // |J e0| |J e1| |J e2|, the size of det J's terms
  double Conditioning; // Scale / |det J|, a bound on J's condition number
};

// The deformed point sum_i w_i (X_i + d_i); its Jacobian sum_i (X_i + d_i) grad(w_i)^T, the weights' gradients
// by differences (exact up to rounding: the weights are affine in x); the normal as (J t1) x (J t2) for the
// tangents t1, t2 with t1 x t2 = n; det J by Sarrus' rule. Unbound points keep their position and normal.
Reference ReferenceDeform(const TetrahedralMesh& mesh, const std::vector<double>& displacements, int cell,
  const double x[3], const float normal[3])
{
  Reference r;
  double j[3][3] = { { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 } };
  std::copy(x, x + 3, r.Point);
  if (cell >= 0)
  {
    double w[4];
    Weights(mesh, cell, x, w);
    double moved[4][3];
    for (int i = 0; i < 4; ++i)
    {
      const int node = mesh.Tetrahedra[4 * cell + i];
      for (int c = 0; c < 3; ++c)
      {
        moved[i][c] = mesh.Nodes[3 * node + c] + displacements[3 * node + c];
      }
    }
    for (int c = 0; c < 3; ++c)
    {
      r.Point[c] = w[0] * moved[0][c] + w[1] * moved[1][c] + w[2] * moved[2][c] + w[3] * moved[3][c];
    }
    for (int col = 0; col < 3; ++col)
    {
      double shifted[3] = { x[0], x[1], x[2] };
      shifted[col] += 1.0;
      double ws[4];
      Weights(mesh, cell, shifted, ws);
      for (int row = 0; row < 3; ++row)
      {
        j[row][col] = 0.0;
        for (int i = 0; i < 4; ++i)
        {
          j[row][col] += moved[i][row] * (ws[i] - w[i]);
        }
      }
    }
  }
  r.Determinant = j[0][0] * j[1][1] * j[2][2] + j[0][1] * j[1][2] * j[2][0] + j[0][2] * j[1][0] * j[2][1] -
    j[0][2] * j[1][1] * j[2][0] - j[0][0] * j[1][2] * j[2][1] - j[0][1] * j[1][0] * j[2][2];
  r.Scale = 1.0;
  for (int col = 0; col < 3; ++col)
  {
    r.Scale *= std::sqrt(j[0][col] * j[0][col] + j[1][col] * j[1][col] + j[2][col] * j[2][col]);
  }
  r.Conditioning = r.Scale / std::max(std::fabs(r.Determinant), 1e-300);

  auto cross = [](const double a[3], const double b[3], double out[3])
  {
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
  };
  auto normalize = [](double v[3])
  {
    const double length = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int c = 0; c < 3; ++c)
    {
      v[c] /= length;
    }
  };
  double n[3] = { normal[0], normal[1], normal[2] };
  normalize(n);
  double t1[3] = { std::fabs(n[0]) < 0.9 ? 1.0 : 0.0, std::fabs(n[0]) < 0.9 ? 0.0 : 1.0, 0.0 };
  const double along = t1[0] * n[0] + t1[1] * n[1];
  for (int c = 0; c < 3; ++c)
  {
    t1[c] -= along * n[c];
  }
  normalize(t1);
  double t2[3], jt1[3] = {}, jt2[3] = {};
  cross(n, t1, t2);
  for (int row = 0; row < 3; ++row)
  {
    for (int col = 0; col < 3; ++col)
    {
      jt1[row] += j[row][col] * t1[col];
      jt2[row] += j[row][col] * t2[col];
    }
  }
  cross(jt1, jt2, r.Normal);
  normalize(r.Normal);
  return r;
}

//------------------------------------------------------------------------------------------------------------
// A random problem: a jittered tetrahedral mesh of n^3 cubes, points bound to it (in mesh or random order; every
// 97th one outside the mesh and unbound, two non-finite ones), unit normals, node displacements of up to 0.3 of
// the spacing.
struct Problem
{
  TetrahedralMesh Mesh;
  std::vector<ffd::Frame<double>> Frames;
  std::vector<double> Points;
  std::vector<int> Cells;
  std::vector<float> Normals;
  std::vector<double> Displacements;
  double Size = 0; // the largest extent of the mesh: the scale of the tolerances

  Problem(int n, std::int64_t count, bool meshOrder, std::mt19937& rng)
    : Mesh(ffdtest::JitteredTetrahedra(n, rng))
    , Frames(Mesh.RestFrames())
  {
    ffdtest::PointsInTetrahedra(this->Mesh, count, meshOrder, rng, this->Points, this->Cells);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    for (std::int64_t i = 0; i < count; i += 97)
    {
      this->Points[3 * i] += 10.0;
      this->Cells[i] = -1;
    }
    if (count > 11)
    {
      this->Points[3 * 7] = std::numeric_limits<double>::quiet_NaN();
      this->Points[3 * 11 + 1] = std::numeric_limits<double>::infinity();
      this->Cells[7] = this->Cells[11] = -1;
    }
    for (std::int64_t i = 0; i < count; ++i)
    {
      const double v[3] = { unit(rng), unit(rng), unit(rng) };
      const double length = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) + 1e-3;
      this->Normals.insert(this->Normals.end(), { float(v[0] / length), float(v[1] / length), float(v[2] / length) });
    }
    for (int c = 0; c < 3; ++c)
    {
      double lo = 1e300, hi = -1e300;
      for (std::int64_t v = 0; v < this->Mesh.NumberOfNodes(); ++v)
      {
        lo = std::min(lo, this->Mesh.Nodes[3 * v + c]);
        hi = std::max(hi, this->Mesh.Nodes[3 * v + c]);
      }
      this->Size = std::max(this->Size, hi - lo);
    }
    for (std::int64_t v = 0; v < 3 * this->Mesh.NumberOfNodes(); ++v)
    {
      this->Displacements.push_back(0.3 * (3.0 / n) * unit(rng));
    }
  }

  std::int64_t Count() const { return std::int64_t(this->Cells.size()); }

  bool Bind(ffd::cuda::TetrahedralDeformer& gpu) const
  {
    return gpu.Bind(this->Cells.data(), this->Frames.data(), this->Mesh.Tetrahedra.data(),
      this->Mesh.NumberOfTetrahedra(), this->Mesh.NumberOfNodes());
  }
};

FFD_REAL_TYPED_TEST_SUITE(CudaTetrahedralDeformerTest);

// The device against the float64 reference, each in the precision of the points (the reference starts from the
// points as the device has them). Tolerances, relative to the mesh's size (3): positions 1e-5 in float32 (the
// issue's bound) and 1e-12 in float64; det J within the same of the size of its terms, |J e0||J e1||J e2|; unit
// normals within 1e-5 times J's conditioning in float32, and 1e-12 times it in float64 (normals are uploaded,
// transformed and downloaded in the points' precision). Kept points exactly. With and without normals and det J
// (different kernels), points in mesh and in random order; outputs poisoned first, so unwritten values are caught.
TYPED_TEST(CudaTetrahedralDeformerTest, MatchesFloat64Reference)
{
  FFD_REQUIRE_DEVICE();
  using Real = TypeParam;
  const bool single = sizeof(Real) == sizeof(float);
  const double relative = single ? 1e-5 : 1e-12;
  std::mt19937 rng(single ? 511 : 512);
  double worst = 0.0;
  for (bool meshOrder : { true, false })
  {
    const Problem p(meshOrder ? 8 : 13, 100003, meshOrder, rng); // 3072 and 13182 tetrahedra
    for (std::int64_t t = 0; t < p.Mesh.NumberOfTetrahedra(); ++t)
    {
      ASSERT_EQ(ffd::CheckTetrahedron(p.Mesh.Node(t, 0), p.Mesh.Node(t, 1), p.Mesh.Node(t, 2), p.Mesh.Node(t, 3)),
        ffd::FrameStatus::Valid);
    }
    const std::vector<Real> points(p.Points.begin(), p.Points.end());
    ffd::cuda::TetrahedralDeformer gpu;
    ASSERT_TRUE(gpu.SetPoints(points.data(), p.Count())) << gpu.GetLastError();
    const std::vector<Real> normals(p.Normals.begin(), p.Normals.end()); // in the points' precision
    ASSERT_TRUE(gpu.SetNormals(normals.data())) << gpu.GetLastError();
    ASSERT_TRUE(p.Bind(gpu)) << gpu.GetLastError();

    std::vector<Reference> expected;
    for (std::int64_t i = 0; i < p.Count(); ++i)
    {
      const double x[3] = { double(points[3 * i]), double(points[3 * i + 1]), double(points[3 * i + 2]) };
      expected.push_back(ReferenceDeform(p.Mesh, p.Displacements, p.Cells[i], x, &p.Normals[3 * i]));
    }
    for (bool withJacobian : { true, false })
    {
      const Real poison = Real(-12345.0);
      std::vector<Real> outPoints(points.size(), poison), outDeterminants(p.Count(), poison);
      std::vector<Real> outNormals(points.size(), poison);
      ASSERT_TRUE(gpu.Evaluate(p.Displacements.data(), p.Mesh.NumberOfNodes(), withJacobian, withJacobian))
        << gpu.GetLastError();
      ASSERT_TRUE(gpu.Download(
        outPoints.data(), withJacobian ? outNormals.data() : nullptr, withJacobian ? outDeterminants.data() : nullptr))
        << gpu.GetLastError();
      ffdtest::Mismatches wrong;
      const auto check = [&](const char* what, std::int64_t i, double got, double want, double tolerance)
      { wrong.Check(what, i, got, want, tolerance); };
      for (std::int64_t i = 0; i < p.Count(); ++i)
      {
        const Reference& r = expected[i];
        for (int c = 0; c < 3; ++c)
        {
          const double got = double(outPoints[3 * i + c]);
          if (p.Cells[i] < 0)
          {
            check("kept position", i, got, double(points[3 * i + c]), 0.0);
            continue;
          }
          check("position", i, got, r.Point[c], relative * p.Size);
          worst = std::max(worst, std::fabs(got - r.Point[c]) / p.Size);
          if (withJacobian)
          {
            check("normal", i, double(outNormals[3 * i + c]), r.Normal[c], (single ? 1e-5 : 1e-12) * r.Conditioning);
          }
        }
        if (withJacobian && p.Cells[i] >= 0)
        {
          check("det", i, double(outDeterminants[i]), r.Determinant, relative * std::max(1.0, r.Scale));
        }
      }
      EXPECT_EQ(wrong.Count, 0) << (meshOrder ? "mesh order" : "random order")
                                << (withJacobian ? ", with normals and det J: " : ": ") << wrong.First;
    }
  }
  std::printf("tetrahedra, %s against float64: largest position error %.2e of the mesh's size\n",
    single ? "float32" : "float64", worst);
}

// The adjoint W^T g on the device against the reference's weights (equation 5, volume ratios: independent of the
// device's frames), for every bound point. Per node, both sum the same points' terms: in float64 their weights
// differ by rounding (a few eps, conditioning included: the mesh is jittered by at most 0.1) and the sums by
// their order, |difference| <= 1e-12 (S_n + G_n), S_n the terms' sizes and G_n = sum |g| of the node's points;
// in float32 the device's weights are those of the points rounded to float (their parameters move by about
// 6e-8 |x| / h, under 1e-6 here), |difference| <= 1e-5 G_n. Then the same bits twice and on a fresh deformer, one
// plan per binding.
TYPED_TEST(CudaTetrahedralDeformerTest, AdjointMatchesReference)
{
  FFD_REQUIRE_DEVICE();
  using Real = TypeParam;
  const bool single = sizeof(Real) == sizeof(float);
  std::mt19937 rng(808);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const Problem p(5, 30011, true, rng);
  std::vector<double> g(p.Points.size());
  for (double& v : g)
  {
    v = unit(rng);
  }
  const std::int64_t nodes = p.Mesh.NumberOfNodes();
  std::vector<double> expected(3 * nodes, 0.0), sizes(nodes, 0.0), gradients(nodes, 0.0);
  for (std::int64_t i = 0; i < p.Count(); ++i)
  {
    if (p.Cells[i] < 0)
    {
      continue;
    }
    const Real rounded[3] = { Real(p.Points[3 * i]), Real(p.Points[3 * i + 1]), Real(p.Points[3 * i + 2]) };
    const double x[3] = { double(rounded[0]), double(rounded[1]), double(rounded[2]) };
    double w[4];
    Weights(p.Mesh, p.Cells[i], x, w);
    for (int k = 0; k < 4; ++k)
    {
      const int n = p.Mesh.Tetrahedra[4 * p.Cells[i] + k];
      for (int c = 0; c < 3; ++c)
      {
        expected[3 * n + c] += w[k] * g[3 * i + c];
        sizes[n] += std::fabs(w[k] * g[3 * i + c]);
        gradients[n] += std::fabs(g[3 * i + c]);
      }
    }
  }
  auto adjoint = [&](int calls, std::uint64_t* plans)
  {
    const std::vector<Real> points(p.Points.begin(), p.Points.end());
    ffd::cuda::TetrahedralDeformer gpu;
    std::vector<double> sums(3 * nodes, -12345.0); // poisoned: unwritten values show
    EXPECT_TRUE(gpu.SetPoints(points.data(), p.Count()) && p.Bind(gpu)) << gpu.GetLastError();
    for (int call = 0; call < calls; ++call)
    {
      EXPECT_TRUE(gpu.Adjoint(g.data(), nodes, sums.data())) << gpu.GetLastError();
    }
    *plans = gpu.GetCounters().AdjointPlans;
    return sums;
  };
  std::uint64_t plans = 0;
  const std::vector<double> got = adjoint(2, &plans);
  EXPECT_EQ(plans, 1u);
  ffdtest::Mismatches wrong;
  for (std::int64_t n = 0; n < nodes; ++n)
  {
    const double tolerance = single ? 1e-5 * gradients[n] : 1e-12 * (sizes[n] + gradients[n]);
    for (int c = 0; c < 3; ++c)
    {
      wrong.Check("sensitivity", n, got[3 * n + c], expected[3 * n + c], tolerance);
    }
  }
  EXPECT_EQ(wrong.Count, 0) << wrong.First;
  const std::vector<double> again = adjoint(1, &plans);
  EXPECT_EQ(std::memcmp(got.data(), again.data(), got.size() * sizeof(double)), 0) << "not the same bits";
}

// Only the nodes' displacements cross the bus on an update; moving one node moves only the points of the
// tetrahedra around it.
TEST(CudaTetrahedralDeformer, UpdatesUploadOnlyTheNodes)
{
  FFD_REQUIRE_DEVICE();
  std::mt19937 rng(77);
  const Problem p(6, 50000, true, rng);
  const std::vector<float> points(p.Points.begin(), p.Points.end());
  ffd::cuda::TetrahedralDeformer gpu;
  ASSERT_TRUE(gpu.SetPoints(points.data(), p.Count()));
  ASSERT_TRUE(p.Bind(gpu));
  std::vector<float> first(points.size(), -1.0f), second(points.size(), -1.0f);
  ASSERT_TRUE(gpu.Evaluate(p.Displacements.data(), p.Mesh.NumberOfNodes(), false, false));
  ASSERT_TRUE(gpu.Download(first.data(), nullptr, nullptr));
  const int moved = int(p.Mesh.NumberOfNodes() / 2);
  std::vector<double> displacements = p.Displacements;
  displacements[3 * moved + 1] += 0.2;
  ASSERT_TRUE(gpu.Evaluate(displacements.data(), p.Mesh.NumberOfNodes(), false, false));
  ASSERT_TRUE(gpu.Download(second.data(), nullptr, nullptr));

  const ffd::cuda::Counters& c = gpu.GetCounters();
  EXPECT_EQ(c.PointUploads, 1u);
  EXPECT_EQ(c.NormalUploads, 0u);
  EXPECT_EQ(c.Bindings, 1u);
  EXPECT_EQ(c.LatticeUploads, 2u);
  EXPECT_EQ(c.LatticeBytes, 2u * std::uint64_t(p.Mesh.NumberOfNodes()) * 3 * sizeof(double));
  EXPECT_EQ(c.Evaluations, 2u);
  EXPECT_EQ(c.BytesDownloaded, 2u * points.size() * sizeof(float));

  // A point of a tetrahedron around the moved node moves by 0.2 times its weight there: visibly in float32 where
  // that weight is above 1e-5.
  std::int64_t changed = 0, wrong = 0;
  for (std::int64_t i = 0; i < p.Count(); ++i)
  {
    const int t = p.Cells[i];
    const bool differs = std::memcmp(&first[3 * i], &second[3 * i], 3 * sizeof(float)) != 0; // NaN is NaN
    changed += differs ? 1 : 0;
    const int* nodes = &p.Mesh.Tetrahedra[4 * std::max(t, 0)];
    const int corner = t >= 0 ? int(std::find(nodes, nodes + 4, moved) - nodes) : 4;
    if (corner == 4)
    {
      wrong += differs ? 1 : 0;
      continue;
    }
    const double x[3] = { double(points[3 * i]), double(points[3 * i + 1]), double(points[3 * i + 2]) };
    double w[4];
    Weights(p.Mesh, t, x, w);
    wrong += w[corner] > 1e-5 && !differs ? 1 : 0;
  }
  EXPECT_GT(changed, 0);
  EXPECT_EQ(wrong, 0);
}

// Failures are reported, leave no device state behind, and a later use starts clean.
TEST(CudaTetrahedralDeformer, FailuresAreReportedAndRecoverable)
{
  FFD_REQUIRE_DEVICE();
  ffd::cuda::TetrahedralDeformer gpu;
  std::vector<float> out(3 * 1000);
  EXPECT_FALSE(gpu.Evaluate(nullptr, 0, false, false)); // nothing bound
  EXPECT_NE(gpu.GetLastError().find("no points bound"), std::string::npos) << gpu.GetLastError();

  // Out of device memory: 2^42 points would need 48 TiB; the allocation fails before anything is read.
  EXPECT_FALSE(gpu.SetPoints(out.data(), std::int64_t(1) << 42));
  EXPECT_NE(gpu.GetLastError().find("allocating the points"), std::string::npos) << gpu.GetLastError();

  std::mt19937 rng(9);
  Problem p(2, 1000, false, rng);
  const std::vector<float> points(p.Points.begin(), p.Points.end());
  ASSERT_TRUE(gpu.SetPoints(points.data(), p.Count())) << gpu.GetLastError();
  p.Cells[500] = int(p.Mesh.NumberOfTetrahedra()); // one past the last tetrahedron
  EXPECT_FALSE(p.Bind(gpu));
  EXPECT_NE(gpu.GetLastError().find("out of range"), std::string::npos) << gpu.GetLastError();
  EXPECT_FALSE(gpu.Evaluate(p.Displacements.data(), p.Mesh.NumberOfNodes(), false, false)); // state dropped

  p.Cells[500] = 0;
  ASSERT_TRUE(gpu.SetPoints(points.data(), p.Count())) << gpu.GetLastError();
  ASSERT_TRUE(p.Bind(gpu)) << gpu.GetLastError();
  EXPECT_FALSE(gpu.Evaluate(p.Displacements.data(), p.Mesh.NumberOfNodes() - 1, false, false)); // wrong lattice
  EXPECT_NE(gpu.GetLastError().find("do not match"), std::string::npos) << gpu.GetLastError();
  EXPECT_FALSE(gpu.Download(out.data(), nullptr, nullptr)); // the failure dropped the device state

  ASSERT_TRUE(gpu.SetPoints(points.data(), p.Count()) && p.Bind(gpu)) << gpu.GetLastError();
  ASSERT_TRUE(gpu.Evaluate(p.Displacements.data(), p.Mesh.NumberOfNodes(), false, true)) << gpu.GetLastError();
  std::vector<float> determinants(p.Count());
  EXPECT_TRUE(gpu.Download(out.data(), nullptr, determinants.data())) << gpu.GetLastError();
  EXPECT_FALSE(gpu.Download(out.data(), out.data(), nullptr)); // normals were not evaluated
  EXPECT_NE(gpu.GetLastError().find("nothing of that was evaluated"), std::string::npos) << gpu.GetLastError();
}

// Without a device the backend says so instead of crashing (this runs on machines without a GPU).
TEST(CudaTetrahedralDeformer, DeviceQueryNeverCrashes)
{
  std::string why;
  if (!ffd::cuda::DeviceAvailable(&why))
  {
    ffd::cuda::TetrahedralDeformer gpu;
    std::vector<float> points(30, 0.0f);
    EXPECT_FALSE(gpu.SetPoints(points.data(), 10));
    EXPECT_FALSE(gpu.GetLastError().empty());
    EXPECT_FALSE(gpu.Evaluate(nullptr, 0, false, false));
  }
}
} // namespace
