// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDGridAdjoint.h"

#include "vtkFFDGridDeformer.h"
#include "vtkFFDGroupedIds.h"
#include "vtkFFDLatticeQueries.h"

#include "vtkAlgorithm.h"
#include "vtkPoints.h"
#include "vtkSMPThreadLocal.h"
#include "vtkSMPTools.h"

#include "FFDAdjoint.h"
#include "FFDAdjointPasses.h"
#include "FFDSimdLevel.h"

#include <algorithm>

//------------------------------------------------------------------------------------------------------------
bool vtkFFDGridAdjoint::Sum(const vtkFFDGridDeformer& grid, const vtkFFDBindingKey& key, vtkPoints* points,
  const double* g, double* sums, vtkAlgorithm* self)
{
  const vtkIdType controlPoints = grid.GetLattice().Points->GetNumberOfTuples();
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
      // The widest SIMD lanes this CPU runs (FFDAdjointPasses.h); point by point where there are none.
      const ffd::SimdLevel level = ffd::SimdLevelOfCpu();
      std::vector<double> noTable;
      const ffd::GridLattice<double> lattice = grid.PassLattice(static_cast<const double*>(nullptr), false, noTable);
      vtkSMPThreadLocal<std::vector<double>> scratches;
      vtkSMPTools::For(0, vtkIdType(this->Chunks.size()),
        [&](vtkIdType begin, vtkIdType end)
        {
          std::vector<double>& scratch = scratches.Local();
          scratch.resize(ffd::AdjointScratchSize(this->Terms));
          for (vtkIdType c = begin; c < end; ++c)
          {
            const Chunk& chunk = this->Chunks[c];
            const ffd::AdjointChunk lanes{ chunk.Cell, chunk.End - chunk.Begin, &this->X[3 * std::size_t(chunk.Begin)],
              &this->Order[std::size_t(chunk.Begin)], g, &this->Partials[3 * std::size_t(this->Terms) * std::size_t(c)],
              scratch.data() };
            if (!ffd::SumAdjointChunkInLanes(level, lattice, lanes))
            {
              this->SumChunk(deformation, lanes);
            }
          }
        });
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
  this->Order.assign(byCell.Order.begin(), byCell.Order.end());
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
// A chunk's partials point by point, where the CPU has no SIMD lanes: the lanes' sums (FFDAdjointPasses.h) with
// one lane.
template <typename Deformation>
void vtkFFDGridAdjoint::SumChunk(const Deformation& deformation, const ffd::AdjointChunk& chunk) const
{
  constexpr int M = Deformation::MaxWeights;
  const int* n = this->Counts;
  std::fill(chunk.Partial, chunk.Partial + 3 * std::size_t(this->Terms), 0.0);
  int cell[3];
  deformation.CellIndices(chunk.Cell, cell);
  for (std::int64_t p = 0; p < chunk.Count; ++p)
  {
    ffd::AxisWeights<M, double> axes[3];
    deformation.WeightsInCell(ffd::Vec3<double>::From(chunk.X + 3 * p), cell, axes);
    const double* g = chunk.G + 3 * chunk.Ids[p];
    double wsg[3 * M];
    for (int i = 0; i < n[0]; ++i)
    {
      for (int c = 0; c < 3; ++c)
      {
        wsg[3 * i + c] = axes[0].W[i] * g[c];
      }
    }
    for (int l = 0; l < n[2]; ++l)
    {
      for (int j = 0; j < n[1]; ++j)
      {
        const double w = axes[1].W[j] * axes[2].W[l];
        double* row = chunk.Partial + 3 * std::size_t(n[0]) * std::size_t(j + n[1] * l);
        for (int v = 0; v < 3 * n[0]; ++v)
        {
          row[v] += w * wsg[v];
        }
      }
    }
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
