// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDGridAdjoint.h"

#include "vtkFFDGridDeformer.h"
#include "vtkFFDGroupedIds.h"
#include "vtkFFDLatticeQueries.h"

#include "vtkAlgorithm.h"
#include "vtkPoints.h"
#include "vtkSMPTools.h"

#include "FFDAdjoint.h"

#include <algorithm>
#include <cstring>

namespace
{
// row[v] += w wsg[v] for v < count (3 N where N > 0): for the local bases in pairs of doubles, the vector width
// of any x86-64, which GCC does not find by itself here.
template <int N>
inline void AddRow(double w, const double* wsg, double* row, int count)
{
  if constexpr (N > 0)
  {
    typedef double Pair __attribute__((vector_size(16)));
    const Pair wide = { w, w };
    for (int v = 0; v + 1 < 3 * N; v += 2)
    {
      Pair r, a;
      std::memcpy(&r, row + v, sizeof(Pair));
      std::memcpy(&a, wsg + v, sizeof(Pair));
      r += wide * a;
      std::memcpy(row + v, &r, sizeof(Pair));
    }
    if constexpr (3 * N % 2 == 1)
    {
      row[3 * N - 1] += w * wsg[3 * N - 1];
    }
  }
  else
  {
    for (int v = 0; v < count; ++v)
    {
      row[v] += w * wsg[v];
    }
  }
}
} // namespace

//------------------------------------------------------------------------------------------------------------
bool vtkFFDGridAdjoint::Sum(const vtkFFDGridDeformer& grid, const vtkFFDBindingKey& key, vtkPoints* points,
  const double* g, double* sums, vtkAlgorithm* self)
{
  const vtkIdType controlPoints = grid.GetLattice().Points->GetNumberOfTuples();
  const bool global = grid.GetLattice().Basis == ffd::GridBasis::Bernstein;
  vtkFFDWithGridDeformation(grid,
    [&](const auto& deformation)
    {
      if (key != this->For || controlPoints != this->ControlPoints)
      {
        this->For = vtkFFDBindingKey(); // valid again once made
        this->ControlPoints = controlPoints;
        this->MakePlan(deformation, grid, points);
        this->For = key;
        ++this->Plans;
      }
      self->UpdateProgress(0.5);
      auto sumChunks = [&](auto n)
      {
        vtkSMPTools::For(0, vtkIdType(this->Chunks.size()),
          [&](vtkIdType begin, vtkIdType end)
          {
            for (vtkIdType c = begin; c < end; ++c)
            {
              this->SumChunk<decltype(n)::value>(
                deformation, this->Chunks[c], g, &this->Partials[3 * std::size_t(this->Terms) * std::size_t(c)]);
            }
          });
      };
      // The local bases' supports unrolled: 2, 3 or 4 control points per axis; the global basis's at run time.
      switch (global ? 0 : this->Counts[0])
      {
        case 2:
          return sumChunks(std::integral_constant<int, 2>());
        case 3:
          return sumChunks(std::integral_constant<int, 3>());
        case 4:
          return sumChunks(std::integral_constant<int, 4>());
        default:
          return sumChunks(std::integral_constant<int, 0>());
      }
    });
  if (self->GetAbortExecute())
  {
    return false;
  }
  this->Gather(sums);
  return true;
}

//------------------------------------------------------------------------------------------------------------
// The plan: the bound points by cell and their float64 coordinates in that order, the chunks, and the terms'
// control points (from each chunk's first point: their First is the cell's) grouped by control point.
template <typename Deformation>
void vtkFFDGridAdjoint::MakePlan(const Deformation& deformation, const vtkFFDGridDeformer& grid, vtkPoints* points)
{
  const vtkFFDGroupedIds byCell(grid.GetCellOfPoint());
  this->Order = byCell.Order;
  const vtkIdType bound = vtkIdType(this->Order.size());
  this->X.resize(3 * std::size_t(bound));
  vtkSMPTools::For(0, bound,
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType o = begin; o < end; ++o)
      {
        points->GetPoint(this->Order[o], &this->X[3 * std::size_t(o)]);
      }
    });
  const vtkFFDGridLattice& lattice = grid.GetLattice();
  for (int a = 0; a < 3; ++a)
  {
    this->Counts[a] = ffd::SupportSize(lattice.Basis, lattice.Divisions[a]);
  }
  this->Terms = this->Counts[0] * this->Counts[1] * this->Counts[2];
  const vtkIdType chunkPoints = vtkIdType(ffd::AdjointChunkPoints(bound, this->Terms));
  this->Chunks.clear();
  for (int cell = 0; cell < byCell.Groups(); ++cell)
  {
    for (vtkIdType b = byCell.Start[cell]; b < byCell.Start[cell + 1]; b += chunkPoints)
    {
      this->Chunks.push_back({ cell, b, std::min(b + chunkPoints, byCell.Start[cell + 1]) });
    }
  }
  const int* n = this->Counts;
  std::vector<vtkIdType> controlPointOf(this->Chunks.size() * std::size_t(this->Terms));
  vtkSMPTools::For(0, vtkIdType(this->Chunks.size()),
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType c = begin; c < end; ++c)
      {
        const Chunk& chunk = this->Chunks[c];
        ffd::AxisWeights<Deformation::MaxWeights, double> axes[3];
        deformation.WeightsAt(ffd::Vec3<double>::From(&this->X[3 * std::size_t(chunk.Begin)]), chunk.Cell, axes);
        for (int k = 0; k < this->Terms; ++k)
        {
          controlPointOf[std::size_t(c) * this->Terms + k] =
            deformation.ControlPointOf(chunk.Cell, axes, k % n[0], (k / n[0]) % n[1], k / (n[0] * n[1]));
        }
      }
    });
  const vtkFFDGroupedIds byControlPoint(controlPointOf, std::size_t(this->ControlPoints));
  this->TermStart = byControlPoint.Start;
  this->TermOrder = byControlPoint.Order;
  this->Partials.assign(3 * controlPointOf.size(), 0.0);
}

//------------------------------------------------------------------------------------------------------------
// A chunk's partials: for each point in order, w_k g = (W1[j] W2[l]) (W0[i] g) added to term k = i + n0 (j + n1 l).
// N: the support's control points per axis where known at compile time (0: the global basis's, at run time).
template <int N, typename Deformation>
void vtkFFDGridAdjoint::SumChunk(
  const Deformation& deformation, const Chunk& chunk, const double* g, double* partial) const
{
  constexpr int M = Deformation::MaxWeights;
  const int n0 = N ? N : this->Counts[0], n1 = N ? N : this->Counts[1], n2 = N ? N : this->Counts[2];
  // The local bases sum into an array of their own (no aliasing: the compiler keeps the rows in vector
  // registers as it can), the global basis into the partials.
  double local[N ? 3 * N * N * N : 1] = {};
  double* sums = N ? local : partial;
  std::fill(sums, sums + 3 * std::size_t(this->Terms), 0.0);
  int cell[3];
  deformation.CellIndices(chunk.Cell, cell);
  for (vtkIdType o = chunk.Begin; o < chunk.End; ++o)
  {
    ffd::AxisWeights<M, double> axes[3];
    deformation.WeightsInCell(ffd::Vec3<double>::From(&this->X[3 * std::size_t(o)]), cell, axes);
    const double* gp = g + 3 * std::size_t(this->Order[o]);
    double wsg[3 * M];
    for (int i = 0; i < n0; ++i)
    {
      wsg[3 * i] = axes[0].W[i] * gp[0];
      wsg[3 * i + 1] = axes[0].W[i] * gp[1];
      wsg[3 * i + 2] = axes[0].W[i] * gp[2];
    }
    for (int l = 0; l < n2; ++l)
    {
      for (int j = 0; j < n1; ++j)
      {
        AddRow<N>(axes[1].W[j] * axes[2].W[l], wsg, sums + 3 * std::size_t(n0) * std::size_t(j + n1 * l), 3 * n0);
      }
    }
  }
  if (N)
  {
    std::copy(local, local + 3 * std::size_t(this->Terms), partial);
  }
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDGridAdjoint::Gather(double* sums) const
{
  vtkSMPTools::For(0, this->ControlPoints,
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType c = begin; c < end; ++c)
      {
        double sum[3] = { 0.0, 0.0, 0.0 };
        for (vtkIdType q = this->TermStart[c]; q < this->TermStart[c + 1]; ++q)
        {
          const double* partial = &this->Partials[3 * std::size_t(this->TermOrder[q])];
          sum[0] += partial[0];
          sum[1] += partial[1];
          sum[2] += partial[2];
        }
        std::copy(sum, sum + 3, sums + 3 * std::size_t(c));
      }
    });
}
