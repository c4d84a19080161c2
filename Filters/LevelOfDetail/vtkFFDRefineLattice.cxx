// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDRefineLattice.h"

#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkFFDBuildLattice.h"
#include "vtkFFDDataContract.h"
#include "vtkFFDGridDeformer.h"
#include "vtkFFDInputChecks.h"
#include "vtkFFDLatticeQueries.h"
#include "vtkFFDMemory.h"
#include "vtkFFDPipelineKeys.h"
#include "vtkFFDSparseLattice.h"
#include "vtkFFDTetrahedralDeformer.h"
#include "vtkFFDWholeInput.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkIntArray.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkSMPTools.h"
#include "vtkSmartPointer.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkStructuredGrid.h"
#include "vtkUnsignedCharArray.h"
#include "vtkUnstructuredGrid.h"

#include "FFDRefinement.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkFFDRefineLattice);

namespace
{
/// sum_abc Wz Wy Wx D[id(a, b, c)], in increasing a, b, c whatever the caller, so that a fine point comes out the
/// same from a dense lattice and from any sparse cell that holds it.
template <typename Id>
void Combine(const ffd::RefinementRow rows[3], const double* displacements, Id&& id, double out[3])
{
  out[0] = out[1] = out[2] = 0;
  for (int c = 0; c < rows[2].Count; ++c)
  {
    for (int b = 0; b < rows[1].Count; ++b)
    {
      const double wzy = rows[2].W[c] * rows[1].W[b];
      for (int a = 0; a < rows[0].Count; ++a)
      {
        const double w = wzy * rows[0].W[a];
        const double* d = displacements + 3 * std::size_t(id(rows[0].First + a, rows[1].First + b, rows[2].First + c));
        out[0] += w * d[0];
        out[1] += w * d[1];
        out[2] += w * d[2];
      }
    }
  }
}

/**
 * At least the bytes that the last of `levels` refinements of `lattice` (covering `voxels` voxels, in `form`)
 * holds at once: its voxels' keys and index (20 bytes a voxel), its control points (position, RestPosition and
 * the refined copy of the positions, Active and the ghost array: 74 bytes a point; a sparse lattice has at least
 * as many as its voxels have points of their own) and a sparse lattice's cells (4 bytes a support point).
 * Counted in double: 16 levels of a large lattice overflow any integer.
 */
double LastLevelBytes(const vtkFFDGridLattice& lattice, bool sparse, double voxels, int levels, double& points)
{
  const ffd::GridBasis basis = lattice.Basis;
  const double scale = std::ldexp(1.0, levels), fineVoxels = voxels * scale * scale * scale;
  const int degree = basis == ffd::GridBasis::CubicBSpline ? 1 : ffd::BezierDegree(basis);
  points = sparse ? fineVoxels * degree * degree * degree : 1.0;
  for (int a = 0; a < 3 && !sparse; ++a)
  {
    const double divisions = lattice.Divisions[a] * scale;
    points *= basis == ffd::GridBasis::Bernstein ? divisions + 1
      : basis == ffd::GridBasis::CubicBSpline    ? divisions + 3
                                                 : degree * divisions + 1;
  }
  const double support = ffd::SupportSize(basis, lattice.Divisions[0]);
  const double cells = sparse ? 4.0 * fineVoxels * (support * support * support + 1) : 0.0;
  return 20.0 * fineVoxels + 74.0 * points + cells;
}

/// The fine voxels of a refinement to `fine` divisions: the halves of the coarse active region's voxels, in
/// increasing order; `what` names the refinement. Null, said why, where they cannot be held.
vtkSmartPointer<vtkIntArray> FineVoxels(vtkFFDRefineLattice* self, const vtkFFDGridDeformer& reader,
  vtkPointSet* coarse, const int fine[3], std::string& what)
{
  std::vector<int> parents = vtkFFDCoveredVoxels(reader, coarse);
  std::ostringstream request;
  request << "The " << vtkFFDBuildLattice::GetBasisAsString(int(reader.GetLattice().Basis)) << " lattice refined to "
          << fine[0] << "x" << fine[1] << "x" << fine[2] << " divisions (" << 8 * (parents.size() / 3) << " voxels)";
  what = request.str();
  if (!vtkFFDCheckMemory(self, what, 8.0 * 8.0 * double(parents.size() / 3)))
  {
    return nullptr;
  }
  std::vector<vtkTypeInt64> keys;
  keys.reserve(8 * (parents.size() / 3));
  for (std::size_t v = 0; v < parents.size(); v += 3)
  {
    for (int child = 0; child < 8; ++child)
    {
      keys.push_back(vtkFFDFlatIndex(
        2 * parents[v] + (child & 1), 2 * parents[v + 1] + (child >> 1 & 1), 2 * parents[v + 2] + (child >> 2), fine));
    }
  }
  parents = std::vector<int>();
  std::sort(keys.begin(), keys.end());
  return vtkFFDMakeVoxelIndex(keys, fine);
}

/// The refined lattice at rest over `voxelIndex`, as vtkFFDBuildLattice makes it (`sparse`, or dense); null,
/// said why, where it cannot be built.
vtkSmartPointer<vtkPointSet> RefinedAtRest(vtkFFDRefineLattice* self, const vtkFFDGridLattice& lattice, bool sparse,
  const int fine[3], vtkIntArray* voxelIndex, const std::string& what)
{
  if (sparse)
  {
    auto refined = vtkSmartPointer<vtkUnstructuredGrid>::New();
    if (!vtkFFDMakeSparseLattice(self, lattice.Frame, lattice.Basis, fine, voxelIndex, what, refined))
    {
      return nullptr;
    }
    return refined;
  }
  vtkNew<vtkUnstructuredGrid> voxelGrid;
  if (!vtkFFDMakeVoxelGrid(self, lattice.Frame, fine, voxelIndex, what, voxelGrid))
  {
    return nullptr;
  }
  vtkNew<vtkFFDBuildLattice> build;
  build->SetBasis(int(lattice.Basis));
  build->SetLatticeFormToDense();
  build->SetInputData(voxelGrid);
  build->Update();
  vtkSmartPointer<vtkPointSet> refined = build->GetOutput();
  if (refined->GetNumberOfPoints() == 0)
  {
    vtkErrorWithObjectMacro(self, << "Could not build the refined lattice (see the error above).");
    return nullptr;
  }
  return refined;
}

/// Adds to the control points `x` of the sparse `refined` lattice (`fine` divisions) their displacements from
/// the coarse `lattice`'s (ffd::LocalRefinementRow): each fine point from the first fine cell that holds it,
/// through that cell's parent's support. False, said why, where the refined lattice cannot be read.
bool DisplaceSparse(vtkFFDRefineLattice* self, const vtkFFDGridLattice& lattice, const vtkFFDSparseCells* cells,
  vtkPointSet* refined, const int fine[3], double* x)
{
  const ffd::GridBasis basis = lattice.Basis;
  const int* n = lattice.Divisions;
  const double* d = lattice.Displacements.data();
  vtkFFDSparseCells fineCells;
  const std::string unread = fineCells.Read(vtkUnstructuredGrid::SafeDownCast(refined), basis, fine);
  if (!unread.empty())
  {
    vtkErrorWithObjectMacro(self, << "Internal error reading the refined lattice: " << unread);
    return false;
  }
  const int m = ffd::SupportSize(basis, n[0]), m3 = m * m * m; // a local basis: the same along every axis
  std::vector<int> owner(std::size_t(refined->GetNumberOfPoints()), -1);
  for (int c = fineCells.GetNumberOfCells() - 1; c >= 0; --c)
  {
    for (int s = 0; s < m3; ++s)
    {
      owner[fineCells.GetSupports()[std::size_t(c) * m3 + s]] = c;
    }
  }
  const int* coarseSupports = cells->GetSupports();
  vtkSMPTools::For(0, fineCells.GetNumberOfCells(),
    [&](int begin, int end)
    {
      for (int c = begin; c < end; ++c)
      {
        const int* voxel = fineCells.GetVoxels().data() + 3 * std::size_t(c);
        const int* support =
          coarseSupports + std::size_t(cells->Find(vtkFFDFlatIndex(voxel[0] / 2, voxel[1] / 2, voxel[2] / 2, n))) * m3;
        int first[3], unused;
        for (int a = 0; a < 3; ++a)
        {
          ffd::VoxelSupport(basis, fine[a], voxel[a], first[a], unused);
        }
        for (int s = 0; s < m3; ++s)
        {
          const int p = fineCells.GetSupports()[std::size_t(c) * m3 + s];
          if (owner[p] != c)
          {
            continue;
          }
          const int local[3] = { s % m, s / m % m, s / (m * m) };
          ffd::RefinementRow rows[3];
          for (int a = 0; a < 3; ++a)
          {
            ffd::LocalRefinementRow(basis, n[a], voxel[a], first[a] + local[a], rows[a]);
          }
          double delta[3];
          Combine(
            rows, d, [&](int i, int j, int k) { return support[i + m * (j + m * k)]; }, delta);
          for (int a = 0; a < 3; ++a)
          {
            x[3 * p + a] += delta[a];
          }
        }
      }
    });
  return true;
}

/// Adds to the active control points `x` of the dense `refined` lattice (`finePoints` per axis) their
/// displacements from the coarse `lattice`'s (ffd::RefineRow).
void DisplaceDense(const vtkFFDGridLattice& lattice, vtkPointSet* refined, const int finePoints[3], double* x)
{
  const ffd::GridBasis basis = lattice.Basis;
  const int* n = lattice.Divisions;
  const double* d = lattice.Displacements.data();
  vtkDataArray* active = refined->GetPointData()->GetArray(vtkFFDDataContract::ActiveArrayName());
  const int* coarseDims = lattice.ControlPointsPerAxis;
  vtkSMPTools::For(0, refined->GetNumberOfPoints(),
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType p = begin; p < end; ++p)
      {
        if (active->GetComponent(p, 0) == 0)
        {
          continue;
        }
        const int index[3] = { int(p % finePoints[0]), int(p / finePoints[0] % finePoints[1]),
          int(p / finePoints[0] / finePoints[1]) };
        ffd::RefinementRow rows[3];
        for (int a = 0; a < 3; ++a)
        {
          rows[a] = ffd::RefineRow(basis, n[a], index[a]);
        }
        double delta[3];
        Combine(
          rows, d,
          [&](int i, int j, int k) { return i + vtkIdType(coarseDims[0]) * (j + vtkIdType(coarseDims[1]) * k); },
          delta);
        for (int a = 0; a < 3; ++a)
        {
          x[3 * p + a] += delta[a];
        }
      }
    });
}
} // namespace

//------------------------------------------------------------------------------------------------------------
vtkFFDRefineLattice::vtkFFDRefineLattice()
  : Levels(1)
{
}

//------------------------------------------------------------------------------------------------------------
int vtkFFDRefineLattice::ExecuteInformation(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  // The refined lattice's extent, where its input's divisions and basis are announced (vtkFFDPipelineKeys.h).
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  int basis;
  int divisions[3];
  if (!vtkFFDPipelineKeys::AnnouncedLattice(inputVector[0]->GetInformationObject(0), basis, divisions) ||
    std::max({ divisions[0], divisions[1], divisions[2] }) > (VTK_INT_MAX >> this->Levels))
  {
    vtkFFDPipelineKeys::Forget(outInfo); // unknown, or too large: the execution reports it
    return 1;
  }
  for (int& d : divisions)
  {
    d <<= this->Levels;
  }
  vtkFFDPipelineKeys::AnnounceLattice(outInfo, basis, divisions);
  return 1;
}

//------------------------------------------------------------------------------------------------------------
int vtkFFDRefineLattice::ComputeInputUpdateExtent(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector*)
{
  // Every refined control point may depend on any of the input's: ask for the whole lattice.
  vtkFFDRequestWholeInput(inputVector[0]->GetInformationObject(0));
  return 1;
}

//------------------------------------------------------------------------------------------------------------
vtkTypeBool vtkFFDRefineLattice::ProcessRequest(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  return vtkFFDCatchAllocationFailure(
    this, outputVector, [&] { return this->Superclass::ProcessRequest(request, inputVector, outputVector); });
}

//------------------------------------------------------------------------------------------------------------
int vtkFFDRefineLattice::RequestDataObject(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  if (!(vtkFFDCheckInput(this, inputVector[0], 0, "vtkPointSet", "the lattice",
        "SetInputConnection() to a grid lattice, the output of vtkFFDBuildLattice.")))
  {
    return vtkFFDEmptyOutputs(outputVector);
  }
  return this->Superclass::RequestDataObject(request, inputVector, outputVector);
}

//------------------------------------------------------------------------------------------------------------
int vtkFFDRefineLattice::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkPointSet* input = vtkPointSet::GetData(inputVector[0]);
  vtkPointSet* output = vtkPointSet::GetData(outputVector);
  if (!input || input->GetNumberOfPoints() == 0)
  {
    return 1;
  }
  if (vtkFFDTetrahedralDeformer::IsTetrahedralLattice(input))
  {
    vtkErrorMacro(<< "The input is a tetrahedral lattice: refine it with vtkFFDBuildTetrahedralLattice's "
                     "SubdivisionLevels. This filter refines the grid lattices of vtkFFDBuildLattice.");
    return 0;
  }
  if (this->Levels < 0 || this->Levels > 16)
  {
    vtkErrorMacro(<< "Levels is " << this->Levels << ": give SetLevels() 0 to 16.");
    return 0;
  }
  if (!this->CheckLastLevelFits(input))
  {
    return 0;
  }
  vtkSmartPointer<vtkPointSet> lattice = input;
  for (int level = 0; level < this->Levels; ++level)
  {
    lattice = this->RefineOnce(lattice);
    if (!lattice)
    {
      return 0;
    }
    this->UpdateProgress(double(level + 1) / this->Levels);
    if (this->GetAbortExecute())
    {
      return 1;
    }
  }
  if (output->GetDataObjectType() != lattice->GetDataObjectType())
  {
    vtkErrorMacro(<< "The output is a " << output->GetClassName() << " but the lattice a " << lattice->GetClassName());
    return 0;
  }
  output->ShallowCopy(lattice);
  return 1;
}

//------------------------------------------------------------------------------------------------------------
bool vtkFFDRefineLattice::CheckLastLevelFits(vtkPointSet* input)
{
  vtkFFDGridDeformer reader;
  if (this->Levels == 0 || !reader.SetLattice(input).empty())
  {
    return true; // nothing to refine, or RefineOnce() says why it cannot
  }
  const vtkFFDGridLattice& lattice = reader.GetLattice();
  const bool sparse = reader.GetSparseCells() != nullptr;
  const double voxels = double(vtkFFDCoveredVoxels(reader, input).size() / 3);
  double points;
  const double bytes = LastLevelBytes(lattice, sparse, voxels, this->Levels, points);
  const double available = vtkFFDAvailableMemory();
  if (bytes <= available)
  {
    return true;
  }
  int fit = this->Levels - 1;
  double unused;
  while (fit > 0 && LastLevelBytes(lattice, sparse, voxels, fit, unused) > available)
  {
    --fit;
  }
  const double scale = std::ldexp(1.0, this->Levels);
  const int* n = lattice.Divisions;
  vtkErrorMacro(<< "Levels " << this->Levels << " refine the " << n[0] << "x" << n[1] << "x" << n[2] << " "
                << vtkFFDBuildLattice::GetBasisAsString(int(lattice.Basis)) << " lattice to " << n[0] * scale << "x"
                << n[1] * scale << "x" << n[2] * scale << " divisions (" << voxels * scale * scale * scale
                << " voxels, " << points << " control points), which needs at least " << vtkFFDFormatBytes(bytes)
                << " of memory, but only " << vtkFFDFormatBytes(available) << " is available: set fewer Levels "
                << "(SetLevels(); at most " << fit << " fit here).");
  return false;
}

//------------------------------------------------------------------------------------------------------------
vtkSmartPointer<vtkPointSet> vtkFFDRefineLattice::RefineOnce(vtkPointSet* coarse)
{
  vtkFFDGridDeformer reader;
  const std::string why = reader.SetLattice(coarse);
  if (!why.empty())
  {
    vtkErrorMacro(<< "Cannot refine the input: " << why);
    return nullptr;
  }
  const vtkFFDGridLattice& lattice = reader.GetLattice();
  const vtkFFDSparseCells* cells = reader.GetSparseCells();
  int fine[3], finePoints[3];
  const std::string tooLarge = vtkFFDDoubledDivisions(
    lattice.Basis, lattice.Divisions, cells ? vtkFFDBuildLattice::SPARSE : vtkFFDBuildLattice::DENSE, fine, finePoints);
  if (!tooLarge.empty())
  {
    vtkErrorMacro(<< "Cannot refine the lattice: " << tooLarge);
    return nullptr;
  }

  // The fine voxels, and the refined lattice at rest over them.
  std::string what;
  const vtkSmartPointer<vtkIntArray> voxelIndex = FineVoxels(this, reader, coarse, fine, what);
  const vtkSmartPointer<vtkPointSet> refined =
    voxelIndex ? RefinedAtRest(this, lattice, cells != nullptr, fine, voxelIndex, what) : nullptr;
  if (!refined || this->GetAbortExecute())
  {
    return refined;
  }

  // Each fine control point's displacement from the coarse ones (ffd::RefineRow); points stay at rest where
  // they are not active.
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->DeepCopy(refined->GetPoints());
  double* x = vtkDoubleArray::SafeDownCast(points->GetData())->GetPointer(0);
  if (cells && !DisplaceSparse(this, lattice, cells, refined, fine, x))
  {
    return nullptr;
  }
  if (!cells)
  {
    DisplaceDense(lattice, refined, finePoints, x);
  }
  refined->SetPoints(points);
  return refined;
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDRefineLattice::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Levels: " << this->Levels << "\n";
}
