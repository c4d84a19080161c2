// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDBuildLattice.h"

#include "vtkCellData.h"
#include "vtkDataSetAttributes.h"
#include "vtkDoubleArray.h"
#include "vtkFFDDataContract.h"
#include "vtkFFDMemory.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkSMPTools.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkStructuredGrid.h"
#include "vtkUnsignedCharArray.h"

#include "FFDBernstein.h"
#include "FFDFrame.h"
#include "FFDGridBasis.h"

#include <algorithm>
#include <sstream>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkFFDBuildLattice);

// The filter's enum and the kernels' enum name the same bases: the `FFDBasis` field array holds either.
static_assert(int(ffd::GridBasis::Bernstein) == vtkFFDBuildLattice::BERNSTEIN &&
    int(ffd::GridBasis::Trilinear) == vtkFFDBuildLattice::TRILINEAR &&
    int(ffd::GridBasis::TriquadraticBezier) == vtkFFDBuildLattice::TRIQUADRATIC_BEZIER &&
    int(ffd::GridBasis::TricubicBezier) == vtkFFDBuildLattice::TRICUBIC_BEZIER &&
    int(ffd::GridBasis::CubicBSpline) == vtkFFDBuildLattice::CUBIC_BSPLINE,
  "vtkFFDBuildLattice::Bases and ffd::GridBasis disagree");

//------------------------------------------------------------------------------
// The per-basis formulas (points per axis, rest parameters, supports) live in FFDGridBasis.h, shared with the
// deformation kernels, so that the lattice and its evaluation cannot disagree.
bool vtkFFDBuildLattice::GetControlPointsPerAxis(int basis, const int divisions[3], int points[3], std::string& why)
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
  // The deformation's kernels index control points by int.
  if (double(points[0]) * points[1] * points[2] > double(VTK_INT_MAX))
  {
    std::ostringstream msg;
    msg << "the " << GetBasisAsString(basis) << " lattice over " << divisions[0] << "x" << divisions[1] << "x"
        << divisions[2] << " voxels would have more than 2^31 - 1 control points.";
    why = msg.str();
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
vtkFFDBuildLattice::vtkFFDBuildLattice()
  : Basis(BERNSTEIN)
  , NumberOfActiveControlPoints(0)
{
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
int vtkFFDBuildLattice::RequestInformation(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkInformation* inInfo = inputVector[0]->GetInformationObject(0);
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  int extent[6];
  inInfo->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), extent);
  const int divisions[3] = { extent[1] - extent[0], extent[3] - extent[2], extent[5] - extent[4] };
  if (divisions[0] < 1 || divisions[1] < 1 || divisions[2] < 1)
  {
    // No voxel: an empty input (empty output) or not a voxel grid (RequestData says so).
    outInfo->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), extent, 6);
    return 1;
  }
  int points[3];
  std::string why;
  if (!GetControlPointsPerAxis(this->Basis, divisions, points, why))
  {
    vtkErrorMacro(<< "Cannot build the lattice: " << why);
    return 0;
  }
  const int latticeExtent[6] = { 0, points[0] - 1, 0, points[1] - 1, 0, points[2] - 1 };
  outInfo->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), latticeExtent, 6);
  return 1;
}

//------------------------------------------------------------------------------
int vtkFFDBuildLattice::RequestUpdateExtent(vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector*)
{
  // The lattice's extent is not the voxel grid's (a quadratic lattice has 2n + 1 points per axis, a B-spline
  // lattice n + 3), and every control point depends on the whole grid through the culling: ask for all of it
  // rather than the pipeline's default, which would copy the lattice's extent upstream.
  vtkInformation* inInfo = inputVector[0]->GetInformationObject(0);
  if (inInfo->Has(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT()))
  {
    inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_EXTENT(),
      inInfo->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT()), 6);
  }
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
  vtkStructuredGrid* input = vtkStructuredGrid::GetData(inputVector[0]);
  vtkStructuredGrid* output = vtkStructuredGrid::GetData(outputVector);
  this->NumberOfActiveControlPoints = 0;
  if (!input || input->GetNumberOfPoints() == 0)
  {
    return 1; // an empty input gives an empty output
  }

  double frame[12];
  if (!vtkFFDDataContract::GetFrame(input, frame))
  {
    vtkErrorMacro(<< "The input has no valid " << vtkFFDDataContract::FrameArrayName()
                  << " field array (12 finite doubles): connect the output of vtkFFDVoxelize.");
    return 0;
  }
  int divisions[3];
  if (!vtkFFDDataContract::GetDivisions(input, divisions))
  {
    vtkErrorMacro(<< "The input has no valid " << vtkFFDDataContract::DivisionsArrayName()
                  << " field array (3 ints >= 1): connect the output of vtkFFDVoxelize.");
    return 0;
  }
  int dims[3];
  input->GetDimensions(dims);
  bool dimsMatch = input->GetNumberOfPoints() == vtkIdType(dims[0]) * dims[1] * dims[2];
  for (int a = 0; a < 3; ++a)
  {
    dimsMatch = dimsMatch && vtkIdType(dims[a]) == vtkIdType(divisions[a]) + 1;
  }
  if (!dimsMatch)
  {
    vtkErrorMacro(<< "The input's dimensions (" << dims[0] << ", " << dims[1] << ", " << dims[2] << ") and "
                  << input->GetNumberOfPoints() << " points do not match its "
                  << vtkFFDDataContract::DivisionsArrayName() << " (" << divisions[0] << ", " << divisions[1] << ", "
                  << divisions[2] << ") plus one: connect the output of vtkFFDVoxelize.");
    return 0;
  }
  if (ffd::CheckFrame(frame) != ffd::FrameStatus::Valid)
  {
    vtkErrorMacro(<< "The input's " << vtkFFDDataContract::FrameArrayName()
                  << " has (nearly) zero volume: its edge vectors S, T, U must be linearly independent; "
                     "connect the output of vtkFFDVoxelize or fix the frame.");
    return 0;
  }
  int pointsPerAxis[3];
  std::string why;
  if (!GetControlPointsPerAxis(this->Basis, divisions, pointsPerAxis, why))
  {
    vtkErrorMacro(<< "Cannot build the lattice: " << why);
    return 0;
  }
  const ffd::GridBasis basis = static_cast<ffd::GridBasis>(this->Basis);

  // Which control points influence an active voxel: the union of the active voxels' supports (paper section
  // III.D). A voxel is active unless the input's cell ghost array hides it. The cost is that of visiting the
  // active voxels' supports; once a support covers the whole lattice (always so for the global basis) no
  // further voxel can add to it.
  const int nI = pointsPerAxis[0], nJ = pointsPerAxis[1], nK = pointsPerAxis[2];
  const vtkIdType numControlPoints = static_cast<vtkIdType>(nI) * nJ * nK;
  // Per control point: its position and RestPosition (24 bytes each), Active and the ghost array (1 each).
  std::ostringstream request;
  request << "A " << GetBasisAsString(this->Basis) << " lattice over " << divisions[0] << "x" << divisions[1] << "x"
          << divisions[2] << " voxels (" << nI << "x" << nJ << "x" << nK << " control points)";
  if (!vtkFFDCheckMemory(this, request.str(), 50.0 * double(numControlPoints)))
  {
    return 0;
  }
  vtkUnsignedCharArray* cellGhosts = input->GetCellGhostArray();
  if (cellGhosts && cellGhosts->GetNumberOfValues() != input->GetNumberOfCells())
  {
    vtkErrorMacro(<< "The input's cell array " << vtkDataSetAttributes::GhostArrayName() << " has "
                  << cellGhosts->GetNumberOfValues() << " values for " << input->GetNumberOfCells()
                  << " voxels: connect the output of vtkFFDVoxelize.");
    return 0;
  }
  vtkNew<vtkUnsignedCharArray> activeArray;
  activeArray->SetName(vtkFFDDataContract::ActiveArrayName());
  activeArray->SetNumberOfValues(numControlPoints);
  unsigned char* active = activeArray->GetPointer(0);
  std::fill(active, active + numControlPoints, static_cast<unsigned char>(0));
  const unsigned char* voxelGhosts = cellGhosts ? cellGhosts->GetPointer(0) : nullptr;
  bool covered = false;
  vtkIdType voxel = 0;
  for (int k = 0; k < divisions[2] && !covered; ++k)
  {
    for (int j = 0; j < divisions[1] && !covered; ++j)
    {
      for (int i = 0; i < divisions[0] && !covered; ++i, ++voxel)
      {
        if (voxelGhosts && (voxelGhosts[voxel] & vtkDataSetAttributes::HIDDENCELL))
        {
          continue;
        }
        int first[3], count[3];
        ffd::VoxelSupport(basis, divisions[0], i, first[0], count[0]);
        ffd::VoxelSupport(basis, divisions[1], j, first[1], count[1]);
        ffd::VoxelSupport(basis, divisions[2], k, first[2], count[2]);
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
    }
  }
  this->UpdateProgress(0.5);
  if (this->GetAbortExecute())
  {
    return 1;
  }

  // The rest positions, each computed directly from the frame (no accumulated steps); the B-spline's outer
  // ring has parameters outside [0, 1].
  std::vector<double> restParameters[3];
  for (int a = 0; a < 3; ++a)
  {
    for (int i = 0; i < pointsPerAxis[a]; ++i)
    {
      restParameters[a].push_back(ffd::RestParameter(basis, divisions[a], i));
    }
  }
  const ffd::Frame<double> bound = ffd::Frame<double>::FromArray(frame);
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(numControlPoints);
  vtkNew<vtkDoubleArray> rest;
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
        const vtkIdType i = id % nI, j = (id / nI) % nJ, k = id / (static_cast<vtkIdType>(nI) * nJ);
        const ffd::Vec3<double> x = bound.ToWorld({ restParameters[0][i], restParameters[1][j], restParameters[2][k] });
        for (int c = 0; c < 3; ++c)
        {
          pointValues[3 * id + c] = restValues[3 * id + c] = x[c];
        }
      }
    });

  const vtkIdType numActive = std::count(active, active + numControlPoints, static_cast<unsigned char>(1));

  output->SetExtent(0, nI - 1, 0, nJ - 1, 0, nK - 1);
  output->SetPoints(points);
  output->GetPointData()->AddArray(rest);
  output->GetPointData()->AddArray(activeArray);
  if (numActive < numControlPoints)
  {
    // Culled control points are hidden; the ghost array exists only when some are.
    vtkNew<vtkUnsignedCharArray> pointGhosts;
    pointGhosts->SetName(vtkDataSetAttributes::GhostArrayName());
    pointGhosts->SetNumberOfValues(numControlPoints);
    for (vtkIdType id = 0; id < numControlPoints; ++id)
    {
      pointGhosts->SetValue(id, active[id] ? 0 : vtkDataSetAttributes::HIDDENPOINT);
    }
    output->GetPointData()->AddArray(pointGhosts);
  }
  vtkFFDDataContract::SetFrame(output, frame);
  vtkFFDDataContract::SetDivisions(output, divisions);
  vtkFFDDataContract::SetBasis(output, this->Basis);
  this->NumberOfActiveControlPoints = numActive;
  this->UpdateProgress(1.0);
  return 1;
}

//------------------------------------------------------------------------------
void vtkFFDBuildLattice::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Basis: " << this->GetBasisAsString() << "\n";
  os << indent << "NumberOfActiveControlPoints: " << this->NumberOfActiveControlPoints << "\n";
}
