// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDLatticeBody.h"

#include "vtkFFDDataContract.h"
#include "vtkFFDFlatIndex.h"
#include "vtkFFDGridDeformer.h"
#include "vtkFFDLatticeQueries.h"
#include "vtkFFDSparseCells.h"
#include "vtkFFDTetrahedralDeformer.h"

#include "vtkDataArray.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkUnstructuredGrid.h"

#include "FFDGridBasis.h"

#include <algorithm>
#include <cstdint>

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
        const int a = particleOf[vtkFFDFlatIndex(i, j, k, dims)];
        for (int o = 0; a >= 0 && o < offsets; ++o)
        {
          const int n[3] = { i + Offsets[o][0], j + Offsets[o][1], k + Offsets[o][2] };
          if (n[0] < dims[0] && n[1] >= 0 && n[1] < dims[1] && n[2] >= 0 && n[2] < dims[2])
          {
            const int b = particleOf[vtkFFDFlatIndex(n[0], n[1], n[2], dims)];
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
  const int* supports = cells.GetSupports();
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

/// What keeps the lattice's points from being simulated at all, or an empty string.
std::string CheckLatticePoints(vtkPointSet* lattice)
{
  if (!lattice || !lattice->GetPoints() || lattice->GetNumberOfPoints() == 0)
  {
    return "No lattice to simulate: SetLattice() to the output of vtkFFDBuildLattice or "
           "vtkFFDBuildTetrahedralLattice.";
  }
  vtkDataArray* rest = lattice->GetPointData()->GetArray(vtkFFDDataContract::RestPositionArrayName());
  const vtkIdType count = lattice->GetNumberOfPoints();
  if (count > VTK_INT_MAX)
  {
    return "The lattice has " + std::to_string(count) + " points; at most " + std::to_string(VTK_INT_MAX) +
      " can be simulated.";
  }
  if (!rest || rest->GetNumberOfComponents() != 3 || rest->GetNumberOfTuples() != count)
  {
    return "The lattice has no RestPosition point array of 3 components per point.";
  }
  return std::string();
}

/// The body's particles: the lattice's active control points, with their rest positions. An empty string, or
/// what is wrong.
std::string ReadParticles(vtkPointSet* lattice, vtkFFDLatticeBody& body)
{
  const vtkIdType count = lattice->GetNumberOfPoints();
  vtkDataArray* rest = lattice->GetPointData()->GetArray(vtkFFDDataContract::RestPositionArrayName());
  body.ParticleOf.assign(std::size_t(count), -1);
  body.PointOf.clear();
  vtkDataArray* active = lattice->GetPointData()->GetArray(vtkFFDDataContract::ActiveArrayName());
  if (active && (active->GetNumberOfComponents() != 1 || active->GetNumberOfTuples() != count))
  {
    return "The lattice's Active point array does not have one value per point.";
  }
  body.RestPositions.clear();
  for (vtkIdType p = 0; p < count; ++p)
  {
    if (!active || active->GetComponent(p, 0) != 0)
    {
      body.ParticleOf[p] = static_cast<int>(body.PointOf.size());
      body.PointOf.push_back(p);
      double x[3];
      rest->GetTuple(p, x);
      body.RestPositions.insert(body.RestPositions.end(), x, x + 3);
    }
  }
  if (body.PointOf.empty())
  {
    return "The lattice has no active control point to simulate.";
  }
  return std::string();
}

/// The springs of the lattice read by `tetrahedra` (where `tetrahedral`) or by `grid`.
std::vector<Pair> LatticeSprings(bool tetrahedral, const vtkFFDTetrahedralDeformer& tetrahedra,
  const vtkFFDGridDeformer& grid, const std::vector<int>& particleOf, int offsets)
{
  if (tetrahedral)
  {
    return TetrahedronSprings(tetrahedra.GetNodes(), particleOf);
  }
  if (const vtkFFDSparseCells* cells = grid.GetSparseCells())
  {
    return SparseSprings(
      *cells, ffd::SupportSize(grid.GetLattice().Basis, grid.GetLattice().Divisions[0]), particleOf, offsets);
  }
  return DenseSprings(grid.GetLattice().ControlPointsPerAxis, particleOf, offsets);
}

/// Each particle's share of the mesh's points (none without a mesh): the sum of their weights on it.
std::vector<double> MeshShares(vtkPointSet* mesh, bool tetrahedral, vtkFFDTetrahedralDeformer& tetrahedra,
  vtkFFDGridDeformer& grid, const std::vector<int>& particleOf, std::size_t particles)
{
  std::vector<double> share(particles, 0.0);
  if (!mesh || !mesh->GetPoints() || mesh->GetNumberOfPoints() == 0)
  {
    return share;
  }
  vtkPoints* points = mesh->GetPoints();
  bool rebound = false;
  auto add = [&](vtkIdType point, double weight)
  {
    const int particle = particleOf[point];
    if (particle >= 0)
    {
      share[particle] += weight;
    }
  };
  if (tetrahedral)
  {
    tetrahedra.Bind(points, vtkFFDTetrahedralDeformer::KEEP_POSITION, nullptr, 0, 1, rebound);
    vtkFFDForEachTetrahedronWeight(tetrahedra, points, 0, mesh->GetNumberOfPoints(),
      [&](vtkIdType, vtkIdType node, double weight) { add(node, weight); });
  }
  else
  {
    grid.Bind(points, 0 /* KEEP_POSITION */, nullptr, 0, 1, rebound);
    vtkFFDForEachGridWeight(grid, points, 0, mesh->GetNumberOfPoints(),
      [&](vtkIdType, vtkIdType controlPoint, double weight) { add(controlPoint, weight); });
  }
  return share;
}
} // namespace

//------------------------------------------------------------------------------------------------------------
std::string vtkFFDLatticeBody::Read(
  vtkPointSet* lattice, vtkPointSet* mesh, int neighborhood, double totalMass, double minimumMassFraction)
{
  std::string why = CheckLatticePoints(lattice);
  if (!why.empty())
  {
    return why;
  }

  // The lattice's kind, read and checked by vtkFFDDeform's own readers; the mesh's points bound to it.
  const bool tetrahedral = vtkFFDTetrahedralDeformer::IsTetrahedralLattice(lattice);
  vtkFFDGridDeformer grid;
  vtkFFDTetrahedralDeformer tetrahedra;
  why = tetrahedral ? tetrahedra.SetLattice(vtkUnstructuredGrid::SafeDownCast(lattice)) : grid.SetLattice(lattice);
  if (!why.empty())
  {
    return "Cannot simulate the lattice: " + why;
  }

  why = ReadParticles(lattice, *this);
  if (!why.empty())
  {
    return why;
  }
  this->Springs = LatticeSprings(tetrahedral, tetrahedra, grid, this->ParticleOf, OffsetCount[neighborhood]);
  // Masses: each particle's share of the mesh's points, through their weights.
  this->Masses = ShareMass(MeshShares(mesh, tetrahedral, tetrahedra, grid, this->ParticleOf, this->PointOf.size()),
    totalMass, minimumMassFraction);
  return std::string();
}
