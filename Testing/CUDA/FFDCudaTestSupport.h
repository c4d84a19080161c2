// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDCudaTestSupport.h
 * @brief What the GPU tests and BenchmarkFFDCuda share: the device check of the tests, the count of GPU values
 * that differ from the CPU's or the reference's, and random tetrahedral control meshes with points bound to them
 * (no VTK: the GPU machine has none).
 */
#ifndef FFDCudaTestSupport_h
#define FFDCudaTestSupport_h

#include "FFDCudaResidentPoints.h"
#include "FFDTetrahedra.h"

#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

/// Skips the current GoogleTest test, with the reason, where no CUDA device can be used.
#define FFD_REQUIRE_DEVICE()                                                                                           \
  do                                                                                                                   \
  {                                                                                                                    \
    std::string why;                                                                                                   \
    if (!ffd::cuda::DeviceAvailable(&why))                                                                             \
    {                                                                                                                  \
      GTEST_SKIP() << why;                                                                                             \
    }                                                                                                                  \
  } while (false)

namespace ffdtest
{
/// Whether a GPU value matches the expected one: both NaN, the same infinity, or within `tolerance`.
inline bool Same(double a, double b, double tolerance)
{
  return (std::isnan(a) && std::isnan(b)) || (std::isinf(a) && a == b) || std::fabs(a - b) <= tolerance;
}

/// The values of a comparison over many points that did not match, and a description of the first five.
struct Mismatches
{
  std::int64_t Count = 0;
  std::string First; ///< "<where>: got vs expected; " for each of the first five

  /// Records a value that did not match.
  void Add(const std::string& where, double got, double expected)
  {
    if (this->Count++ < 5)
    {
      this->First += where + ": " + std::to_string(got) + " vs " + std::to_string(expected) + "; ";
    }
  }

  /// Records `what` of point i unless Same(got, expected, tolerance).
  void Check(const char* what, std::int64_t i, double got, double expected, double tolerance)
  {
    if (!Same(got, expected, tolerance))
    {
      this->Add(std::string(what) + " of point " + std::to_string(i), got, expected);
    }
  }
};

/// A tetrahedral control mesh: rest nodes (3 doubles each) and tetrahedra (4 node indices each).
struct TetrahedralMesh
{
  std::vector<double> Nodes;
  std::vector<int> Tetrahedra;

  std::int64_t NumberOfNodes() const { return std::int64_t(this->Nodes.size() / 3); }
  std::int64_t NumberOfTetrahedra() const { return std::int64_t(this->Tetrahedra.size() / 4); }
  const double* Node(std::int64_t tetrahedron, int corner) const
  {
    return this->Nodes.data() + 3 * this->Tetrahedra[4 * tetrahedron + corner];
  }

  /// Each tetrahedron's rest frame (ffd::TetrahedronFrame), as the host's binding gives it.
  std::vector<ffd::Frame<double>> RestFrames() const
  {
    std::vector<ffd::Frame<double>> frames;
    for (std::int64_t t = 0; t < this->NumberOfTetrahedra(); ++t)
    {
      frames.push_back(ffd::TetrahedronFrame(this->Node(t, 0), this->Node(t, 1), this->Node(t, 2), this->Node(t, 3)));
    }
    return frames;
  }
};

/**
 * n^3 cubes, each split into the 6 tetrahedra around its main diagonal (Kuhn's triangulation, conforming between
 * neighbours), whose inner nodes are moved at random by up to `jitter` of the spacing (0.1 flips none: the
 * tests check every volume), then sheared and moved away from the origin, as a control mesh around a real model
 * would be. Tetrahedra come cube by cube, cubes in x, y, z order.
 */
inline TetrahedralMesh JitteredTetrahedra(int n, std::mt19937& rng, double jitter = 0.1)
{
  TetrahedralMesh mesh;
  std::uniform_real_distribution<double> u(-jitter, jitter);
  const double h = 3.0 / n;
  for (int k = 0; k <= n; ++k)
  {
    for (int j = 0; j <= n; ++j)
    {
      for (int i = 0; i <= n; ++i)
      {
        const bool inner = i > 0 && i < n && j > 0 && j < n && k > 0 && k < n;
        const double x = h * (i + (inner ? u(rng) : 0.0)), y = h * (j + (inner ? u(rng) : 0.0)),
                     z = h * (k + (inner ? u(rng) : 0.0));
        mesh.Nodes.insert(mesh.Nodes.end(), { -1.0 + x + 0.3 * y, -2.0 + 0.9 * y + 0.2 * z, 0.5 + 0.5 * z - 0.1 * x });
      }
    }
  }
  auto node = [n](int i, int j, int k) { return i + (n + 1) * (j + (n + 1) * k); };
  const int permutations[6][3] = { { 0, 1, 2 }, { 0, 2, 1 }, { 1, 0, 2 }, { 1, 2, 0 }, { 2, 0, 1 }, { 2, 1, 0 } };
  for (int k = 0; k < n; ++k)
  {
    for (int j = 0; j < n; ++j)
    {
      for (int i = 0; i < n; ++i)
      {
        for (const auto& axes : permutations)
        {
          int c[3] = { i, j, k };
          mesh.Tetrahedra.push_back(node(c[0], c[1], c[2]));
          for (int step = 0; step < 3; ++step)
          {
            ++c[axes[step]];
            mesh.Tetrahedra.push_back(node(c[0], c[1], c[2]));
          }
        }
      }
    }
  }
  return mesh;
}

/**
 * `count` points bound to the mesh's tetrahedra, each at random barycentric weights (uniform over its
 * tetrahedron) in the tetrahedron `cells[i]`: in mesh order (point i in tetrahedron i T / count, consecutive
 * points in the same or neighbouring tetrahedra, as consecutive vertices of a model are), or in random ones.
 */
inline void PointsInTetrahedra(const TetrahedralMesh& mesh, std::int64_t count, bool meshOrder, std::mt19937& rng,
  std::vector<double>& points, std::vector<int>& cells)
{
  std::exponential_distribution<double> e(1.0);
  std::uniform_int_distribution<std::int64_t> anyTetrahedron(0, mesh.NumberOfTetrahedra() - 1);
  points.resize(3 * count);
  cells.resize(count);
  for (std::int64_t i = 0; i < count; ++i)
  {
    const std::int64_t t = meshOrder ? i * mesh.NumberOfTetrahedra() / count : anyTetrahedron(rng);
    double w[4], sum = 0.0;
    for (double& v : w)
    {
      v = e(rng);
      sum += v;
    }
    for (int c = 0; c < 3; ++c)
    {
      double x = 0.0;
      for (int corner = 0; corner < 4; ++corner)
      {
        x += w[corner] / sum * mesh.Node(t, corner)[c];
      }
      points[3 * i + c] = x;
    }
    cells[i] = int(t);
  }
}
} // namespace ffdtest

#endif
