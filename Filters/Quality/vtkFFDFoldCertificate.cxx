// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDFoldCertificate.h"

#include "vtkFFDDataContract.h"
#include "vtkFFDForInChunks.h"
#include "vtkFFDGridDeformer.h"
#include "vtkFFDInputChecks.h"
#include "vtkFFDLatticeQueries.h"
#include "vtkFFDMemory.h"
#include "vtkFFDTetrahedralDeformer.h"

#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkDataArray.h"
#include "vtkDataArrayRange.h"
#include "vtkIdList.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkSMPThreadLocal.h"
#include "vtkSMPThreadLocalObject.h"
#include "vtkStructuredGrid.h"
#include "vtkUnsignedCharArray.h"
#include "vtkUnstructuredGrid.h"

#include "FFDFoldCertificate.h"

#include <algorithm>
#include <cstdint>
#include <vector>

vtkStandardNewMacro(vtkFFDFoldCertificate);

namespace
{
// The 3-component values of an array as float64, tuple after tuple.
std::vector<double> AsDoubles(vtkDataArray* array)
{
  std::vector<double> values(3 * static_cast<std::size_t>(array->GetNumberOfTuples()));
  const auto range = vtk::DataArrayValueRange<3>(array);
  std::copy(range.begin(), range.end(), values.begin());
  return values;
}

// The state of each covered voxel (vtkFFDCoveredVoxels(): 3 ints each) of a grid lattice, from its control points
// (`points`, 3 doubles each): a dense lattice's by lattice index, a sparse one's through its cells' supports
// (`supports`: the covered voxels are its cells, in order).
struct VoxelCertifier
{
  const vtkFFDGridLattice& View;
  const std::vector<int>& Voxels;
  const double* Points;
  const int* Supports; // null for a dense lattice
  int Depth;
  double Orientation;
  std::vector<std::uint8_t>& States;
  vtkSMPThreadLocal<std::vector<ffd::Vec3<double>>> Scratch;

  void operator()(vtkIdType begin, vtkIdType end)
  {
    const ffd::GridBasis basis = this->View.Basis;
    const int* n = this->View.Divisions;
    const int* dims = this->View.ControlPointsPerAxis;
    const int count = ffd::SupportSize(basis, n[0]) * ffd::SupportSize(basis, n[1]) * ffd::SupportSize(basis, n[2]);
    std::vector<ffd::Vec3<double>>& scratch = this->Scratch.Local();
    scratch.resize(std::size_t(this->Depth + 1) * count);
    for (vtkIdType v = begin; v < end; ++v)
    {
      const int* voxel = this->Voxels.data() + 3 * v;
      int first[3], size[3];
      for (int a = 0; a < 3; ++a)
      {
        ffd::VoxelSupport(basis, n[a], voxel[a], first[a], size[a]);
      }
      const int* support = this->Supports ? this->Supports + std::size_t(v) * count : nullptr;
      auto pointOf = [&](int i, int j, int k)
      {
        const std::size_t id = support ? std::size_t(support[i + size[0] * (j + size[1] * k)])
                                       : std::size_t(first[0] + i) +
            std::size_t(dims[0]) * (std::size_t(first[1] + j) + std::size_t(dims[1]) * std::size_t(first[2] + k));
        return ffd::Vec3<double>::From(this->Points + 3 * id);
      };
      int order[3];
      const double largest = ffd::CellNet(basis, n, voxel, pointOf, scratch.data(), order);
      this->States[v] = std::uint8_t(ffd::CertifyNet(scratch.data(), order, this->Orientation, this->Depth, largest));
    }
  }
};

// The voxel holding lattice cell c along an axis of n voxels at rest (a dense lattice's cells lie between
// neighbouring control points), or -1 for the B-spline's cells outside the frame.
int VoxelOfLatticeCell(ffd::GridBasis basis, int n, int c)
{
  if (basis == ffd::GridBasis::CubicBSpline)
  {
    return c >= 1 && c <= n ? c - 1 : -1;
  }
  return basis == ffd::GridBasis::Bernstein ? c : c / ffd::BezierDegree(basis);
}

// The state of the voxel (i, j, k) of a lattice of `divisions` among the covered voxels' flat indices `keys`
// (increasing) and their `states`; NOT_CHECKED where it is not covered.
std::uint8_t StateOfVoxel(const int voxel[3], const int divisions[3], const std::vector<std::int64_t>& keys,
  const std::vector<std::uint8_t>& states)
{
  for (int a = 0; a < 3; ++a)
  {
    if (voxel[a] < 0 || voxel[a] >= divisions[a])
    {
      return vtkFFDFoldCertificate::NOT_CHECKED;
    }
  }
  const std::int64_t key = voxel[0] + std::int64_t(divisions[0]) * (voxel[1] + std::int64_t(divisions[1]) * voxel[2]);
  const auto found = std::lower_bound(keys.begin(), keys.end(), key);
  return found != keys.end() && *found == key ? states[found - keys.begin()] : vtkFFDFoldCertificate::NOT_CHECKED;
}

// The states of the output's cells from the covered voxels' (see the class's comment for the mapping).
void MapToCells(vtkPointSet* lattice, const vtkFFDGridLattice& view, const std::vector<int>& voxels,
  const std::vector<std::uint8_t>& states, vtkUnsignedCharArray* out)
{
  std::vector<std::int64_t> keys(states.size());
  for (std::size_t v = 0; v < keys.size(); ++v)
  {
    keys[v] = voxels[3 * v] +
      std::int64_t(view.Divisions[0]) * (voxels[3 * v + 1] + std::int64_t(view.Divisions[1]) * voxels[3 * v + 2]);
  }
  const vtkIdType cells = lattice->GetNumberOfCells();
  out->SetNumberOfValues(cells);
  vtkDataArray* voxelIndex = view.Sparse
    ? lattice->GetCellData()->GetArray(vtkFFDDataContract::VoxelIndexArrayName()) // checked by the reader
    : nullptr;
  const int cellsPerAxis[2] = { view.ControlPointsPerAxis[0] - 1, view.ControlPointsPerAxis[1] - 1 };
  vtkSMPTools::For(0, cells,
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType c = begin; c < end; ++c)
      {
        int voxel[3];
        if (voxelIndex)
        {
          for (int a = 0; a < 3; ++a)
          {
            voxel[a] = static_cast<int>(voxelIndex->GetComponent(c, a));
          }
        }
        else
        {
          const vtkIdType index[3] = { c % cellsPerAxis[0], (c / cellsPerAxis[0]) % cellsPerAxis[1],
            c / (vtkIdType(cellsPerAxis[0]) * cellsPerAxis[1]) };
          for (int a = 0; a < 3; ++a)
          {
            voxel[a] = VoxelOfLatticeCell(view.Basis, view.Divisions[a], static_cast<int>(index[a]));
          }
        }
        out->SetValue(c, StateOfVoxel(voxel, view.Divisions, keys, states));
      }
    });
}
} // namespace

//------------------------------------------------------------------------------------------------------------
struct vtkFFDFoldCertificate::vtkInternals
{
  vtkFFDGridDeformer Grid{ false }; // only the points are read, not the displacements
  vtkFFDTetrahedralDeformer Tetrahedra;
};

vtkFFDFoldCertificate::vtkFFDFoldCertificate()
  : Internals(new vtkInternals)
{
}

vtkFFDFoldCertificate::~vtkFFDFoldCertificate() = default;

int vtkFFDFoldCertificate::FillInputPortInformation(int port, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkPointSet");
  return port == 0 ? 1 : 0;
}

vtkTypeBool vtkFFDFoldCertificate::ProcessRequest(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  return vtkFFDCatchAllocationFailure(
    this, outputVector, [&] { return this->Superclass::ProcessRequest(request, inputVector, outputVector); });
}

// The output is the lattice: of the input's type.
int vtkFFDFoldCertificate::RequestDataObject(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  if (!vtkFFDCheckInput(this, inputVector[0], 0, "vtkPointSet", "the lattice",
        "SetInputConnection() to a lattice (vtkFFDBuildLattice's or vtkFFDBuildTetrahedralLattice's output, moved)."))
  {
    return vtkFFDEmptyOutputs(outputVector);
  }
  vtkDataObject* lattice = vtkDataObject::GetData(inputVector[0]);
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  vtkDataObject* output = outInfo->Get(vtkDataObject::DATA_OBJECT());
  if (!output || !output->IsA(lattice->GetClassName()))
  {
    outInfo->Set(vtkDataObject::DATA_OBJECT(), vtk::TakeSmartPointer(lattice->NewInstance()));
  }
  return 1;
}

//------------------------------------------------------------------------------------------------------------
int vtkFFDFoldCertificate::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkPointSet* lattice = vtkPointSet::GetData(inputVector[0]);
  vtkPointSet* output = vtkPointSet::GetData(outputVector);
  this->NumberOfCertifiedCells = this->NumberOfFoldedCells = this->NumberOfUndecidedCells = 0;
  if (!lattice || !output)
  {
    vtkErrorMacro("Input 0 (the lattice) must be a vtkPointSet.");
    return 0;
  }
  output->ShallowCopy(lattice);
  if (lattice->GetNumberOfPoints() == 0)
  {
    return 1; // an empty input gives an empty output
  }
  vtkNew<vtkUnsignedCharArray> states;
  states->SetName(GetFoldCertificateArrayName());
  const bool tetrahedral = vtkFFDTetrahedralDeformer::IsTetrahedralLattice(lattice);
  const bool completed = tetrahedral ? this->CertifyTetrahedra(vtkUnstructuredGrid::SafeDownCast(lattice), states)
                                     : this->CertifyGrid(lattice, states);
  if (!completed) // an error (the counts' phase never began), or aborted
  {
    output->Initialize();
    return this->GetAbortExecute() ? 1 : 0;
  }
  output->GetCellData()->AddArray(states);
  this->UpdateProgress(1.0);
  return 1;
}

//------------------------------------------------------------------------------------------------------------
bool vtkFFDFoldCertificate::CertifyGrid(vtkPointSet* lattice, vtkUnsignedCharArray* out)
{
  vtkFFDGridDeformer& deformer = this->Internals->Grid;
  const std::string problem = deformer.SetLattice(lattice);
  if (!problem.empty())
  {
    vtkErrorMacro(<< problem);
    return false;
  }
  const vtkFFDGridLattice& view = deformer.GetLattice();
  const std::vector<int> voxels = vtkFFDCoveredVoxels(deformer, lattice);
  const std::vector<double> points = AsDoubles(view.Points);
  const vtkIdType count = static_cast<vtkIdType>(voxels.size() / 3);
  std::vector<std::uint8_t> states(voxels.size() / 3);
  const vtkFFDSparseCells* cells = deformer.GetSparseCells();
  VoxelCertifier certifier{ view, voxels, points.data(), cells ? cells->GetSupports() : nullptr,
    this->MaxSubdivisionDepth, ffd::FrameOrientation(view.Frame), states, {} };
  const int support = ffd::SupportSize(view.Basis, view.Divisions[0]);
  if (!vtkFFDForInChunks(this, count, vtkFFDGrain(count, 20.0 * support * support * support), certifier, 0.0, 0.95))
  {
    return false;
  }
  for (std::uint8_t state : states)
  {
    this->NumberOfCertifiedCells += state == CERTIFIED ? 1 : 0;
    this->NumberOfFoldedCells += state == FOLDED ? 1 : 0;
    this->NumberOfUndecidedCells += state == UNDECIDED ? 1 : 0;
  }
  MapToCells(lattice, view, voxels, states, out);
  return true;
}

bool vtkFFDFoldCertificate::CertifyTetrahedra(vtkUnstructuredGrid* lattice, vtkUnsignedCharArray* out)
{
  vtkFFDTetrahedralDeformer& tetrahedra = this->Internals->Tetrahedra;
  const std::string problem = tetrahedra.SetLattice(lattice);
  if (!problem.empty())
  {
    vtkErrorMacro(<< problem);
    return false;
  }
  const std::vector<double> moved = AsDoubles(lattice->GetPoints()->GetData());
  const std::vector<double> rest =
    AsDoubles(lattice->GetPointData()->GetArray(vtkFFDDataContract::RestPositionArrayName()));
  const vtkIdType count = lattice->GetNumberOfCells();
  out->SetNumberOfValues(count);
  vtkCellArray* cells = lattice->GetCells();
  vtkSMPThreadLocalObject<vtkIdList> ids;
  auto certify = [&](vtkIdType begin, vtkIdType end)
  {
    vtkIdList* local = ids.Local();
    for (vtkIdType c = begin; c < end; ++c)
    {
      cells->GetCellAtId(c, local); // four ids: checked by SetLattice()
      const vtkIdType* nodes = local->GetPointer(0);
      ffd::Vec3<double> before[4], after[4];
      for (int p = 0; p < 4; ++p)
      {
        before[p] = ffd::Vec3<double>::From(rest.data() + 3 * nodes[p]);
        after[p] = ffd::Vec3<double>::From(moved.data() + 3 * nodes[p]);
      }
      out->SetValue(c, static_cast<unsigned char>(ffd::TetrahedronState(before, after)));
    }
  };
  if (!vtkFFDForInChunks(this, count, vtkFFDGrain(count, 64.0), certify, 0.0, 0.95))
  {
    return false;
  }
  for (vtkIdType c = 0; c < count; ++c)
  {
    this->NumberOfCertifiedCells += out->GetValue(c) == CERTIFIED ? 1 : 0;
    this->NumberOfFoldedCells += out->GetValue(c) == FOLDED ? 1 : 0;
  }
  return true;
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDFoldCertificate::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "MaxSubdivisionDepth: " << this->MaxSubdivisionDepth << "\n";
  os << indent << "NumberOfCertifiedCells: " << this->NumberOfCertifiedCells << "\n";
  os << indent << "NumberOfFoldedCells: " << this->NumberOfFoldedCells << "\n";
  os << indent << "NumberOfUndecidedCells: " << this->NumberOfUndecidedCells << "\n";
}
