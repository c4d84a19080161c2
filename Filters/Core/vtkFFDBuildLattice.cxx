// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDBuildLattice.h"

#include "vtkCellData.h"
#include "vtkDataSet.h"
#include "vtkDataSetAttributes.h"
#include "vtkDoubleArray.h"
#include "vtkFFDDataContract.h"
#include "vtkFFDMemory.h"
#include "vtkFFDPipelineKeys.h"
#include "vtkFFDSparseLattice.h"
#include "vtkFFDStatistics.h"
#include "vtkFFDWholeInput.h"
#include "vtkFieldData.h"
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

#include "FFDBernstein.h"
#include "FFDFrame.h"
#include "FFDGridBasis.h"

#include <algorithm>
#include <sstream>
#include <string>

vtkStandardNewMacro(vtkFFDBuildLattice);

// The filter's enum and the kernels' enum name the same bases: the `FFDBasis` field array holds either.
static_assert(int(ffd::GridBasis::Bernstein) == vtkFFDBuildLattice::BERNSTEIN &&
    int(ffd::GridBasis::Trilinear) == vtkFFDBuildLattice::TRILINEAR &&
    int(ffd::GridBasis::TriquadraticBezier) == vtkFFDBuildLattice::TRIQUADRATIC_BEZIER &&
    int(ffd::GridBasis::TricubicBezier) == vtkFFDBuildLattice::TRICUBIC_BEZIER &&
    int(ffd::GridBasis::CubicBSpline) == vtkFFDBuildLattice::CUBIC_BSPLINE,
  "vtkFFDBuildLattice::Bases and ffd::GridBasis disagree");

namespace
{
/// Whether `form` makes a sparse lattice of `basis`.
bool IsSparse(int form, int basis)
{
  return form == vtkFFDBuildLattice::SPARSE ||
    (form == vtkFFDBuildLattice::AUTOMATIC && basis != vtkFFDBuildLattice::BERNSTEIN);
}

/// Which control points influence an active voxel: the union of the active voxels' supports (paper section
/// III.D), 1 at each. Once a support covers the whole lattice (always so for the global basis) no further voxel
/// can add to it.
vtkSmartPointer<vtkUnsignedCharArray> MarkActiveControlPoints(
  ffd::GridBasis basis, const int divisions[3], const int pointsPerAxis[3], vtkIntArray* voxels)
{
  const int nI = pointsPerAxis[0], nJ = pointsPerAxis[1], nK = pointsPerAxis[2];
  const vtkIdType numControlPoints = static_cast<vtkIdType>(nI) * nJ * nK;
  auto activeArray = vtkSmartPointer<vtkUnsignedCharArray>::New();
  activeArray->SetName(vtkFFDDataContract::ActiveArrayName());
  activeArray->SetNumberOfValues(numControlPoints);
  unsigned char* active = activeArray->GetPointer(0);
  std::fill(active, active + numControlPoints, static_cast<unsigned char>(0));
  const int* ijk = voxels->GetPointer(0);
  bool covered = false;
  for (vtkIdType v = 0; v < voxels->GetNumberOfTuples() && !covered; ++v)
  {
    int first[3], count[3];
    for (int a = 0; a < 3; ++a)
    {
      ffd::VoxelSupport(basis, divisions[a], ijk[3 * v + a], first[a], count[a]);
    }
    for (int c = first[2]; c < first[2] + count[2]; ++c)
    {
      for (int b = first[1]; b < first[1] + count[1]; ++b)
      {
        unsigned char* row = active + static_cast<size_t>(nI) * (b + static_cast<size_t>(nJ) * c);
        std::fill(row + first[0], row + first[0] + count[0], static_cast<unsigned char>(1));
      }
    }
    covered = count[0] == nI && count[1] == nJ && count[2] == nK;
  }
  return activeArray;
}

/// The control points' positions and RestPosition array, each computed directly from the frame (no accumulated
/// steps); the B-spline's outer ring has parameters outside [0, 1].
void ComputeRestPositions(const double frame[12], ffd::GridBasis basis, const int divisions[3],
  const int pointsPerAxis[3], vtkPoints* points, vtkDoubleArray* rest)
{
  const int nI = pointsPerAxis[0], nJ = pointsPerAxis[1], nK = pointsPerAxis[2];
  const vtkIdType numControlPoints = static_cast<vtkIdType>(nI) * nJ * nK;
  const ffd::Frame<double> bound = ffd::Frame<double>::FromArray(frame);
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(numControlPoints);
  rest->SetName(vtkFFDDataContract::RestPositionArrayName());
  rest->SetNumberOfComponents(3);
  rest->SetNumberOfTuples(numControlPoints);
  double* pointValues = vtkDoubleArray::SafeDownCast(points->GetData())->GetPointer(0);
  double* restValues = rest->GetPointer(0);
  vtkSMPTools::For(0, numControlPoints,
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType id = begin; id < end; ++id)
      {
        const ffd::Vec3<double> x = vtkFFDRestPoint(
          bound, basis, divisions, int(id % nI), int((id / nI) % nJ), int(id / (static_cast<vtkIdType>(nI) * nJ)));
        for (int c = 0; c < 3; ++c)
        {
          pointValues[3 * id + c] = restValues[3 * id + c] = x[c];
        }
      }
    });
}

/// Hides the culled control points: the ghost array exists only when some are.
void AddPointGhosts(vtkUnsignedCharArray* activeArray, vtkPointData* pointData)
{
  const vtkIdType numControlPoints = activeArray->GetNumberOfValues();
  const unsigned char* active = activeArray->GetPointer(0);
  vtkNew<vtkUnsignedCharArray> pointGhosts;
  pointGhosts->SetName(vtkDataSetAttributes::GhostArrayName());
  pointGhosts->SetNumberOfValues(numControlPoints);
  for (vtkIdType id = 0; id < numControlPoints; ++id)
  {
    pointGhosts->SetValue(id, active[id] ? 0 : vtkDataSetAttributes::HIDDENPOINT);
  }
  pointData->AddArray(pointGhosts);
}
} // namespace

//------------------------------------------------------------------------------
// The per-basis formulas (points per axis, rest parameters, supports) live in FFDGridBasis.h, shared with the
// deformation kernels, so that the lattice and its evaluation cannot disagree.
bool vtkFFDBuildLattice::GetControlPointsPerAxis(
  int basis, const int divisions[3], int points[3], std::string& why, int form)
{
  if (!ffd::IsGridBasis(basis))
  {
    std::ostringstream msg;
    msg << "unknown basis " << basis << ": use one of BERNSTEIN (" << BERNSTEIN << ") to CUBIC_BSPLINE ("
        << CUBIC_BSPLINE << ").";
    why = msg.str();
    return false;
  }
  const ffd::GridBasis grid = static_cast<ffd::GridBasis>(basis);
  for (int a = 0; a < 3; ++a)
  {
    // The global lattice's degree along an axis is the number of voxels along it.
    if (grid == ffd::GridBasis::Bernstein && divisions[a] > ffd::MaxBernsteinDegree)
    {
      std::ostringstream msg;
      msg << "the BERNSTEIN basis would have degree " << divisions[a] << " along axis " << a << ", above the maximum "
          << ffd::MaxBernsteinDegree << ": use at most " << ffd::MaxBernsteinDegree
          << " divisions per axis, or a local basis (e.g. TRILINEAR).";
      why = msg.str();
      return false;
    }
    if (divisions[a] > (VTK_INT_MAX - 1) / 3)
    {
      why = "the divisions " + std::to_string(divisions[a]) + " along axis " + std::to_string(a) +
        " is too large: more control points than an int counts.";
      return false;
    }
    points[a] = ffd::ControlPointsAlongAxis(grid, divisions[a]);
  }
  // The dense deformation's kernels index control points by int; a sparse lattice's points are found by their
  // linear index i + nI*(j + nJ*k), an int64.
  const double count = double(points[0]) * points[1] * points[2];
  if (form == SPARSE ? count >= 0x1p63 : count > double(VTK_INT_MAX))
  {
    std::ostringstream msg;
    msg << "the " << GetBasisAsString(basis) << " lattice over " << divisions[0] << "x" << divisions[1] << "x"
        << divisions[2] << " voxels would have more than "
        << (form == SPARSE ? "2^63 - 1 control points: use fewer divisions."
                           : "2^31 - 1 control points: use fewer divisions, or a SPARSE lattice of a local basis.");
    why = msg.str();
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
vtkFFDBuildLattice::vtkFFDBuildLattice()
  : Basis(BERNSTEIN)
  , LatticeForm(AUTOMATIC)
  , NumberOfActiveControlPoints(0)
{
}

//------------------------------------------------------------------------------
const char* vtkFFDBuildLattice::GetLatticeFormAsString()
{
  switch (this->LatticeForm)
  {
    case DENSE:
      return "Dense";
    case SPARSE:
      return "Sparse";
    default:
      return "Automatic";
  }
}

//------------------------------------------------------------------------------
const char* vtkFFDBuildLattice::GetBasisAsString(int basis)
{
  switch (basis)
  {
    case BERNSTEIN:
      return "Bernstein";
    case TRILINEAR:
      return "Trilinear";
    case TRIQUADRATIC_BEZIER:
      return "TriquadraticBezier";
    case TRICUBIC_BEZIER:
      return "TricubicBezier";
    case CUBIC_BSPLINE:
      return "CubicBSpline";
    default:
      return "Unknown";
  }
}

//------------------------------------------------------------------------------
int vtkFFDBuildLattice::FillInputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkDataSet");
  return 1;
}

//------------------------------------------------------------------------------
int vtkFFDBuildLattice::RequestDataObject(vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  vtkDataObject* output = vtkDataObject::GetData(outInfo);
  if (IsSparse(this->LatticeForm, this->Basis))
  {
    if (!vtkUnstructuredGrid::SafeDownCast(output))
    {
      outInfo->Set(vtkDataObject::DATA_OBJECT(), vtkSmartPointer<vtkUnstructuredGrid>::New());
    }
  }
  else if (!vtkStructuredGrid::SafeDownCast(output))
  {
    outInfo->Set(vtkDataObject::DATA_OBJECT(), vtkSmartPointer<vtkStructuredGrid>::New());
  }
  return 1;
}

//------------------------------------------------------------------------------
int vtkFFDBuildLattice::ExecuteInformation(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  // The lattice's extent follows the voxel grid's divisions, which vtkFFDVoxelize announces (vtkFFDPipelineKeys.h
  // says why it matters); else it is unknown until RequestData. The executive copied the input's WHOLE_EXTENT, if
  // any (a structured voxel grid's), which is not the lattice's.
  vtkInformation* inInfo = inputVector[0]->GetInformationObject(0);
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  if (inInfo && inInfo->Has(vtkFFDPipelineKeys::DIVISIONS()))
  {
    vtkFFDPipelineKeys::AnnounceLattice(outInfo, this->Basis, inInfo->Get(vtkFFDPipelineKeys::DIVISIONS()));
  }
  else
  {
    vtkFFDPipelineKeys::Forget(outInfo);
  }
  return 1;
}

//------------------------------------------------------------------------------
int vtkFFDBuildLattice::ComputeInputUpdateExtent(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector*)
{
  // Every control point depends on the whole voxel grid through the culling and the supports: ask for all of it,
  // one piece without ghost levels (and the whole extent of a structured one) rather than a share of the
  // lattice's request.
  vtkFFDRequestWholeInput(inputVector[0]->GetInformationObject(0));
  return 1;
}

//------------------------------------------------------------------------------------------------------------
vtkTypeBool vtkFFDBuildLattice::ProcessRequest(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  return vtkFFDCatchAllocationFailure(
    this, outputVector, [&] { return this->Superclass::ProcessRequest(request, inputVector, outputVector); });
}

//------------------------------------------------------------------------------
int vtkFFDBuildLattice::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkDataSet* input = vtkDataSet::GetData(inputVector[0]);
  vtkDataObject* output = vtkDataObject::GetData(outputVector);
  this->NumberOfActiveControlPoints = 0;
  const vtkFFDStatisticsOnReturn statistics(output,
    [this](vtkDataObject* out)
    { vtkFFDRecordCount(out, "NumberOfActiveControlPoints", this->NumberOfActiveControlPoints); });
  if (!input ||
    (input->GetNumberOfCells() == 0 && !input->GetFieldData()->GetAbstractArray(vtkFFDDataContract::FrameArrayName())))
  {
    return 1; // an empty input gives an empty output (a voxel grid without active voxels still has its frame)
  }

  double frame[12];
  int divisions[3];
  if (!this->ReadFrameAndDivisions(input, frame, divisions))
  {
    return 0;
  }
  const bool sparse = IsSparse(this->LatticeForm, this->Basis);
  int pointsPerAxis[3];
  if (!this->CheckForm(sparse, divisions, pointsPerAxis))
  {
    return 0;
  }
  vtkIntArray* voxels = this->GetActiveVoxels(input, divisions);
  if (!voxels)
  {
    return 0;
  }

  const int built = sparse
    ? this->BuildSparse(frame, divisions, voxels, vtkUnstructuredGrid::SafeDownCast(output))
    : this->BuildDense(frame, divisions, pointsPerAxis, voxels, vtkStructuredGrid::SafeDownCast(output));
  if (!built)
  {
    return 0;
  }
  this->UpdateProgress(1.0);
  return 1;
}

//------------------------------------------------------------------------------
bool vtkFFDBuildLattice::ReadFrameAndDivisions(vtkDataSet* input, double frame[12], int divisions[3])
{
  if (!vtkFFDDataContract::GetFrame(input, frame))
  {
    vtkErrorMacro(<< "The input has no valid " << vtkFFDDataContract::FrameArrayName()
                  << " field array (12 finite doubles): connect the output of vtkFFDVoxelize.");
    return false;
  }
  if (!vtkFFDDataContract::GetDivisions(input, divisions))
  {
    vtkErrorMacro(<< "The input has no valid " << vtkFFDDataContract::DivisionsArrayName()
                  << " field array (3 ints >= 1): connect the output of vtkFFDVoxelize.");
    return false;
  }
  if (const ffd::FrameStatus status = ffd::CheckFrame(frame); status != ffd::FrameStatus::Valid)
  {
    vtkErrorMacro(<< "The input's " << vtkFFDDataContract::FrameArrayName() << " " << ffd::DescribeFrameStatus(status)
                  << ": connect the output of vtkFFDVoxelize or fix the frame.");
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
bool vtkFFDBuildLattice::CheckForm(bool sparse, const int divisions[3], int pointsPerAxis[3])
{
  if (sparse && this->Basis == BERNSTEIN)
  {
    vtkErrorMacro(<< "A SPARSE lattice of the global BERNSTEIN basis is not possible: each of its control points "
                     "influences every voxel. Set LatticeForm to Dense or Automatic (SetLatticeFormToDense()), or "
                     "choose a local Basis.");
    return false;
  }
  std::string why;
  if (!GetControlPointsPerAxis(this->Basis, divisions, pointsPerAxis, why, sparse ? SPARSE : DENSE))
  {
    vtkErrorMacro(<< "Cannot build the lattice: " << why);
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
vtkIntArray* vtkFFDBuildLattice::GetActiveVoxels(vtkDataSet* input, const int divisions[3])
{
  // The active voxels: one (i, j, k) per cell, each within the divisions, each once.
  vtkIntArray* voxels =
    vtkIntArray::SafeDownCast(input->GetCellData()->GetAbstractArray(vtkFFDDataContract::VoxelIndexArrayName()));
  const vtkIdType numVoxels = input->GetNumberOfCells();
  if (!voxels || voxels->GetNumberOfComponents() != 3 || voxels->GetNumberOfTuples() != numVoxels)
  {
    vtkErrorMacro(<< "The input has no " << vtkFFDDataContract::VoxelIndexArrayName()
                  << " cell array of 3 ints (a vtkIntArray) per cell, the (i, j, k) of each active voxel: "
                     "connect the output of vtkFFDVoxelize.");
    return nullptr;
  }
  const int* ijk = voxels->GetPointer(0);
  for (vtkIdType v = 0; v < numVoxels; ++v)
  {
    const int* x = ijk + 3 * v;
    if (x[0] < 0 || x[0] >= divisions[0] || x[1] < 0 || x[1] >= divisions[1] || x[2] < 0 || x[2] >= divisions[2])
    {
      vtkErrorMacro(<< "The input's " << vtkFFDDataContract::VoxelIndexArrayName() << " of cell " << v << ", (" << x[0]
                    << ", " << x[1] << ", " << x[2] << "), lies outside its "
                    << vtkFFDDataContract::DivisionsArrayName() << " (" << divisions[0] << ", " << divisions[1] << ", "
                    << divisions[2] << "): each index must be in [0, divisions); connect the output of "
                    << "vtkFFDVoxelize or fix the voxel grid.");
      return nullptr;
    }
  }
  vtkFFDActiveSet distinct;
  distinct.Mark(numVoxels,
    [ijk](vtkIdType begin, vtkIdType end, vtkFFDBoxMarker& marker)
    {
      const int one[3] = { 1, 1, 1 };
      for (vtkIdType v = begin; v < end; ++v)
      {
        marker.Mark(ijk + 3 * v, one);
      }
    });
  if (distinct.GetNumberOfMarked() != numVoxels)
  {
    vtkErrorMacro(<< "The input's " << numVoxels << " cells name only " << distinct.GetNumberOfMarked()
                  << " distinct voxels in " << vtkFFDDataContract::VoxelIndexArrayName()
                  << ": give each active voxel one cell, as vtkFFDVoxelize does.");
    return nullptr;
  }
  return voxels;
}

//------------------------------------------------------------------------------
int vtkFFDBuildLattice::BuildDense(const double frame[12], const int divisions[3], const int pointsPerAxis[3],
  vtkIntArray* voxels, vtkStructuredGrid* output)
{
  const ffd::GridBasis basis = static_cast<ffd::GridBasis>(this->Basis);
  const int nI = pointsPerAxis[0], nJ = pointsPerAxis[1], nK = pointsPerAxis[2];
  const vtkIdType numControlPoints = static_cast<vtkIdType>(nI) * nJ * nK;
  // Per control point: its position and RestPosition (24 bytes each), Active and the ghost array (1 each).
  std::ostringstream request;
  request << "A dense " << GetBasisAsString(this->Basis) << " lattice over " << divisions[0] << "x" << divisions[1]
          << "x" << divisions[2] << " voxels (" << nI << "x" << nJ << "x" << nK << " control points)";
  if (!vtkFFDCheckMemory(this, request.str(), 50.0 * double(numControlPoints)))
  {
    return 0;
  }

  const vtkSmartPointer<vtkUnsignedCharArray> activeArray =
    MarkActiveControlPoints(basis, divisions, pointsPerAxis, voxels);
  this->UpdateProgress(0.5);
  if (this->GetAbortExecute())
  {
    return 1;
  }
  vtkNew<vtkPoints> points;
  vtkNew<vtkDoubleArray> rest;
  ComputeRestPositions(frame, basis, divisions, pointsPerAxis, points, rest);

  const unsigned char* active = activeArray->GetPointer(0);
  const vtkIdType numActive = std::count(active, active + numControlPoints, static_cast<unsigned char>(1));
  output->SetExtent(0, nI - 1, 0, nJ - 1, 0, nK - 1);
  output->SetPoints(points);
  output->GetPointData()->AddArray(rest);
  output->GetPointData()->AddArray(activeArray);
  if (numActive < numControlPoints)
  {
    AddPointGhosts(activeArray, output->GetPointData());
  }
  vtkFFDDataContract::SetFrame(output, frame);
  vtkFFDDataContract::SetDivisions(output, divisions);
  vtkFFDDataContract::SetBasis(output, this->Basis);
  this->NumberOfActiveControlPoints = numActive;
  return 1;
}

//------------------------------------------------------------------------------
int vtkFFDBuildLattice::BuildSparse(
  const double frame[12], const int divisions[3], vtkIntArray* voxels, vtkUnstructuredGrid* output)
{
  std::ostringstream request;
  request << "A sparse " << GetBasisAsString(this->Basis) << " lattice over " << voxels->GetNumberOfTuples()
          << " active voxels of " << divisions[0] << "x" << divisions[1] << "x" << divisions[2];
  if (!vtkFFDMakeSparseLattice(
        this, frame, static_cast<ffd::GridBasis>(this->Basis), divisions, voxels, request.str(), output))
  {
    return 0;
  }
  this->NumberOfActiveControlPoints = output->GetNumberOfPoints();
  return 1;
}

//------------------------------------------------------------------------------
void vtkFFDBuildLattice::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Basis: " << this->GetBasisAsString() << "\n";
  os << indent << "LatticeForm: " << this->GetLatticeFormAsString() << "\n";
  os << indent << "NumberOfActiveControlPoints: " << this->NumberOfActiveControlPoints << "\n";
}
