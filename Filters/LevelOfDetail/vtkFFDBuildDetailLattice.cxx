// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDBuildDetailLattice.h"

#include "vtkDataSetAttributes.h"
#include "vtkFFDBuildLattice.h"
#include "vtkFFDDataContract.h"
#include "vtkFFDGridDeformer.h"
#include "vtkFFDLatticeQueries.h"
#include "vtkFFDMemory.h"
#include "vtkFFDSortedKeys.h"
#include "vtkFFDSparseLattice.h"
#include "vtkFFDStatistics.h"
#include "vtkFFDTetrahedralDeformer.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkIntArray.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkSmartPointer.h"
#include "vtkUnsignedCharArray.h"
#include "vtkUnstructuredGrid.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkFFDBuildDetailLattice);

namespace
{
int FloorDiv(int a, int b)
{
  return a >= 0 ? a / b : -((-a + b - 1) / b);
}

/// The voxels [first, first + count) along an axis of `voxels` voxels whose support holds control point j.
void Influence(ffd::GridBasis basis, int voxels, int j, int& first, int& count)
{
  const int step = basis == ffd::GridBasis::CubicBSpline ? 1 : ffd::BezierDegree(basis);
  const int size = ffd::SupportSize(basis, voxels);
  first = std::max(0, -FloorDiv(-(j - size + 1), step)); // ceil((j - size + 1) / step)
  count = std::min(FloorDiv(j, step), voxels - 1) - first + 1;
}

/**
 * The largest second difference (pure or mixed) of the displacements at the control points of `voxel`'s support,
 * each over the product of the spacings along its axes; neighbours outside the lattice are skipped.
 */
double SecondDifference(
  const vtkFFDGridLattice& lattice, const vtkFFDControlPointIndex& index, const double h[3], const int voxel[3])
{
  int first[3], count[3];
  for (int a = 0; a < 3; ++a)
  {
    ffd::VoxelSupport(lattice.Basis, lattice.Divisions[a], voxel[a], first[a], count[a]);
  }
  const double* d = lattice.Displacements.data();
  auto at = [&](const int p[3], int da, int a, int db, int b) -> vtkIdType
  {
    int q[3] = { p[0], p[1], p[2] };
    q[a] += da;
    q[b] += db;
    return index.Find(q[0], q[1], q[2]);
  };
  auto norm = [&](vtkIdType a, vtkIdType b, vtkIdType c, vtkIdType e, double ca, double cb, double cc, double ce)
  {
    double sum = 0;
    for (int x = 0; x < 3; ++x)
    {
      const double v = ca * d[3 * a + x] + cb * d[3 * b + x] + cc * d[3 * c + x] + ce * d[3 * e + x];
      sum += v * v;
    }
    return std::sqrt(sum);
  };
  double worst = 0;
  for (int k = first[2]; k < first[2] + count[2]; ++k)
  {
    for (int j = first[1]; j < first[1] + count[1]; ++j)
    {
      for (int i = first[0]; i < first[0] + count[0]; ++i)
      {
        const int p[3] = { i, j, k };
        const vtkIdType centre = index.Find(i, j, k);
        if (centre < 0)
        {
          continue;
        }
        for (int a = 0; a < 3; ++a)
        {
          const vtkIdType minus = at(p, -1, a, 0, a), plus = at(p, 1, a, 0, a);
          if (minus >= 0 && plus >= 0)
          {
            worst = std::max(worst, norm(plus, centre, minus, centre, 1, -2, 1, 0) / (h[a] * h[a]));
          }
          for (int b = a + 1; b < 3; ++b)
          {
            const vtkIdType pa = at(p, 1, a, 0, b), pb = at(p, 0, a, 1, b), pab = at(p, 1, a, 1, b);
            if (pa >= 0 && pb >= 0 && pab >= 0)
            {
              worst = std::max(worst, norm(pab, pa, pb, centre, 1, -1, -1, 1) / (h[a] * h[b]));
            }
          }
        }
      }
    }
  }
  return worst;
}

/// The grid lattice `input` in `reader`, and its doubled divisions (`fine`, `finePoints` control points); false,
/// said why, where the threshold or the input cannot be refined locally.
bool ReadLattice(vtkFFDBuildDetailLattice* self, vtkPointSet* input, double threshold, vtkFFDGridDeformer& reader,
  int fine[3], int finePoints[3])
{
  if (!(threshold >= 0))
  {
    vtkErrorWithObjectMacro(self, << "SecondDerivativeThreshold is " << threshold
                                  << ": give SetSecondDerivativeThreshold() a number >= 0 (0, the default: off).");
    return false;
  }
  if (vtkFFDTetrahedralDeformer::IsTetrahedralLattice(input))
  {
    vtkErrorWithObjectMacro(self, << "The input is a tetrahedral lattice: refine it with "
                                     "vtkFFDBuildTetrahedralLattice's SubdivisionLevels. This filter refines the "
                                     "grid lattices of vtkFFDBuildLattice.");
    return false;
  }
  const std::string why = reader.SetLattice(input);
  if (!why.empty())
  {
    vtkErrorWithObjectMacro(self, << "Cannot refine the input: " << why);
    return false;
  }
  const vtkFFDGridLattice& lattice = reader.GetLattice();
  if (lattice.Basis == ffd::GridBasis::Bernstein)
  {
    vtkErrorWithObjectMacro(self, << "The global BERNSTEIN basis has no local refinement (each control point moves "
                                     "every voxel): refine the whole lattice with vtkFFDRefineLattice, or use a "
                                     "local basis.");
    return false;
  }
  const std::string tooLarge =
    vtkFFDDoubledDivisions(lattice.Basis, lattice.Divisions, vtkFFDBuildLattice::SPARSE, fine, finePoints);
  if (!tooLarge.empty())
  {
    vtkErrorWithObjectMacro(self, << "Cannot refine the lattice: " << tooLarge);
    return false;
  }
  return true;
}

/// Appends the flat indices of the `voxels` (3 ints a voxel) of a lattice of `n` divisions to `selected`;
/// false, said why, where they are not voxels of it.
bool AddSelectedVoxels(
  vtkFFDBuildDetailLattice* self, vtkIntArray* voxels, const int n[3], std::vector<vtkTypeInt64>& selected)
{
  if (voxels->GetNumberOfComponents() != 3)
  {
    vtkErrorWithObjectMacro(self, << "SelectedVoxels has " << voxels->GetNumberOfComponents()
                                  << " components: give 3 ints (i, j, k) a voxel.");
    return false;
  }
  for (vtkIdType v = 0; v < voxels->GetNumberOfTuples(); ++v)
  {
    const int* ijk = voxels->GetPointer(3 * v);
    if (ijk[0] < 0 || ijk[1] < 0 || ijk[2] < 0 || ijk[0] >= n[0] || ijk[1] >= n[1] || ijk[2] >= n[2])
    {
      vtkErrorWithObjectMacro(self, << "Selected voxel " << v << ", (" << ijk[0] << ", " << ijk[1] << ", " << ijk[2]
                                    << "), lies outside the lattice's " << n[0] << "x" << n[1] << "x" << n[2]
                                    << " divisions.");
      return false;
    }
    selected.push_back(vtkFFDFlatIndex(ijk[0], ijk[1], ijk[2], n));
  }
  return true;
}

/// Appends the flat indices of the voxels of `input` (read by `reader`) that bend more than `threshold`
/// (SecondDifference()) to `selected`.
void AddBendingVoxels(
  const vtkFFDGridDeformer& reader, vtkPointSet* input, double threshold, std::vector<vtkTypeInt64>& selected)
{
  const vtkFFDGridLattice& lattice = reader.GetLattice();
  const int* n = lattice.Divisions;
  const vtkFFDControlPointIndex index(reader, input);
  double h[3];
  for (int a = 0; a < 3; ++a)
  {
    const double* axis = lattice.Frame + 3 * (a + 1);
    h[a] = std::sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]) *
      (ffd::RestParameter(lattice.Basis, n[a], 1) - ffd::RestParameter(lattice.Basis, n[a], 0));
  }
  const std::vector<int> covered = vtkFFDCoveredVoxels(reader, input);
  for (std::size_t v = 0; v < covered.size(); v += 3)
  {
    if (SecondDifference(lattice, index, h, &covered[v]) > threshold)
    {
      selected.push_back(vtkFFDFlatIndex(covered[v], covered[v + 1], covered[v + 2], n));
    }
  }
}

/// M: the fine control points (flat indices, sorted) of the halves of the `selected` voxels of a lattice of `n`
/// divisions, refined to `fine` (`finePoints` control points).
std::vector<vtkTypeInt64> MovablePoints(const std::vector<vtkTypeInt64>& selected, ffd::GridBasis basis, const int n[3],
  const int fine[3], const int finePoints[3])
{
  std::vector<int> halves;
  halves.reserve(24 * selected.size());
  for (vtkTypeInt64 key : selected)
  {
    const int v[3] = { int(key % n[0]), int(key / n[0] % n[1]), int(key / n[0] / n[1]) };
    for (int child = 0; child < 8; ++child)
    {
      halves.push_back(2 * v[0] + (child & 1));
      halves.push_back(2 * v[1] + (child >> 1 & 1));
      halves.push_back(2 * v[2] + (child >> 2));
    }
  }
  vtkFFDActiveSet movableSet;
  vtkFFDSparseLattice::MarkSupports(movableSet, basis, fine, halves.data(), vtkIdType(halves.size() / 3));
  const vtkTypeInt64 pointDims[3] = { finePoints[0], finePoints[1], finePoints[2] };
  return movableSet.TakeSortedIndices(pointDims);
}

/// C: the voxel index of every fine voxel that the `movable` points influence.
vtkSmartPointer<vtkIntArray> InfluencedVoxels(
  const std::vector<vtkTypeInt64>& movable, ffd::GridBasis basis, const int fine[3], const int finePoints[3])
{
  const vtkTypeInt64 pointDims[3] = { finePoints[0], finePoints[1], finePoints[2] };
  vtkFFDActiveSet cellSet;
  cellSet.Mark(vtkIdType(movable.size()),
    [&](vtkIdType begin, vtkIdType end, vtkFFDBoxMarker& marker)
    {
      for (vtkIdType m = begin; m < end; ++m)
      {
        const vtkTypeInt64 key = movable[m];
        const int p[3] = { int(key % pointDims[0]), int(key / pointDims[0] % pointDims[1]),
          int(key / pointDims[0] / pointDims[1]) };
        int first[3], count[3];
        for (int a = 0; a < 3; ++a)
        {
          Influence(basis, fine[a], p[a], first[a], count[a]);
        }
        marker.Mark(first, count);
      }
    });
  const vtkTypeInt64 voxelDims[3] = { fine[0], fine[1], fine[2] };
  return vtkFFDMakeVoxelIndex(cellSet.TakeSortedIndices(voxelDims), fine);
}

/// Active: the `movable` points of `output`; the ring that closes the region is hidden.
void MarkMovable(vtkUnstructuredGrid* output, const std::vector<vtkTypeInt64>& movable, const int finePoints[3])
{
  vtkIntArray* latticeIndex =
    vtkIntArray::SafeDownCast(output->GetPointData()->GetArray(vtkFFDDataContract::LatticeIndexArrayName()));
  vtkUnsignedCharArray* active =
    vtkUnsignedCharArray::SafeDownCast(output->GetPointData()->GetArray(vtkFFDDataContract::ActiveArrayName()));
  vtkNew<vtkUnsignedCharArray> ghosts;
  ghosts->SetName(vtkDataSetAttributes::GhostArrayName());
  ghosts->SetNumberOfValues(output->GetNumberOfPoints());
  const vtkFFDSortedKeys<> movableKeys(movable.data(), movable.data() + movable.size());
  for (vtkIdType p = 0; p < output->GetNumberOfPoints(); ++p)
  {
    const int* ijk = latticeIndex->GetPointer(3 * p);
    const bool isMovable = movableKeys.Find(vtkFFDFlatIndex(ijk[0], ijk[1], ijk[2], finePoints)) >= 0;
    active->SetValue(p, isMovable ? 1 : 0);
    ghosts->SetValue(p, isMovable ? 0 : vtkDataSetAttributes::HIDDENPOINT);
  }
  output->GetPointData()->AddArray(ghosts);
}
} // namespace

//------------------------------------------------------------------------------------------------------------
vtkFFDBuildDetailLattice::vtkFFDBuildDetailLattice()
  : SecondDerivativeThreshold(0)
  , NumberOfRefinedVoxels(0)
{
}

//------------------------------------------------------------------------------------------------------------
vtkFFDBuildDetailLattice::~vtkFFDBuildDetailLattice() = default;

//------------------------------------------------------------------------------------------------------------
void vtkFFDBuildDetailLattice::SetSelectedVoxels(vtkIntArray* voxels)
{
  if (this->SelectedVoxels != voxels)
  {
    this->SelectedVoxels = voxels;
    this->Modified();
  }
}

//------------------------------------------------------------------------------------------------------------
vtkIntArray* vtkFFDBuildDetailLattice::GetSelectedVoxels()
{
  return this->SelectedVoxels;
}

//------------------------------------------------------------------------------------------------------------
vtkMTimeType vtkFFDBuildDetailLattice::GetMTime()
{
  vtkMTimeType time = this->Superclass::GetMTime();
  if (this->SelectedVoxels)
  {
    time = std::max(time, this->SelectedVoxels->GetMTime());
  }
  return time;
}

//------------------------------------------------------------------------------------------------------------
int vtkFFDBuildDetailLattice::FillInputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkPointSet");
  return 1;
}

//------------------------------------------------------------------------------------------------------------
vtkTypeBool vtkFFDBuildDetailLattice::ProcessRequest(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  return vtkFFDCatchAllocationFailure(
    this, outputVector, [&] { return this->Superclass::ProcessRequest(request, inputVector, outputVector); });
}

//------------------------------------------------------------------------------------------------------------
int vtkFFDBuildDetailLattice::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkPointSet* input = vtkPointSet::GetData(inputVector[0]);
  vtkUnstructuredGrid* output = vtkUnstructuredGrid::GetData(outputVector);
  this->NumberOfRefinedVoxels = 0;
  const vtkFFDStatisticsOnReturn statistics(output,
    [this](vtkDataObject* out) { vtkFFDRecordCount(out, "NumberOfRefinedVoxels", this->NumberOfRefinedVoxels); });
  if (!input || input->GetNumberOfPoints() == 0)
  {
    return 1;
  }
  vtkFFDGridDeformer reader;
  int fine[3], finePoints[3];
  if (!ReadLattice(this, input, this->SecondDerivativeThreshold, reader, fine, finePoints))
  {
    return 0;
  }
  const vtkFFDGridLattice& lattice = reader.GetLattice();

  // The input voxels to refine: the selected ones, and those that bend more than the threshold.
  std::vector<vtkTypeInt64> selected;
  if (this->SelectedVoxels && !AddSelectedVoxels(this, this->SelectedVoxels, lattice.Divisions, selected))
  {
    return 0;
  }
  if (this->SecondDerivativeThreshold > 0)
  {
    AddBendingVoxels(reader, input, this->SecondDerivativeThreshold, selected);
  }
  std::sort(selected.begin(), selected.end());
  selected.erase(std::unique(selected.begin(), selected.end()), selected.end());
  this->NumberOfRefinedVoxels = vtkIdType(selected.size());
  if (selected.empty())
  {
    return 1; // nothing to refine: an empty lattice, which moves nothing
  }
  this->UpdateProgress(0.2);

  // M: the fine control points of the selected voxels' halves (movable); C: every fine voxel they influence.
  const std::vector<vtkTypeInt64> movable = MovablePoints(selected, lattice.Basis, lattice.Divisions, fine, finePoints);
  const vtkSmartPointer<vtkIntArray> voxelIndex = InfluencedVoxels(movable, lattice.Basis, fine, finePoints);
  std::ostringstream what;
  what << "A detail lattice over " << voxelIndex->GetNumberOfTuples() << " voxels of " << fine[0] << "x" << fine[1]
       << "x" << fine[2];
  if (!vtkFFDMakeSparseLattice(this, lattice.Frame, lattice.Basis, fine, voxelIndex, what.str(), output))
  {
    return 0;
  }
  MarkMovable(output, movable, finePoints);
  this->UpdateProgress(1.0);
  return 1;
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDBuildDetailLattice::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "SelectedVoxels: " << (this->SelectedVoxels ? this->SelectedVoxels->GetNumberOfTuples() : 0)
     << " voxels\n";
  os << indent << "SecondDerivativeThreshold: " << this->SecondDerivativeThreshold << "\n";
  os << indent << "NumberOfRefinedVoxels: " << this->NumberOfRefinedVoxels << "\n";
}
