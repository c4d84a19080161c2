// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDBuildLattice.h"

#include "vtkCellData.h"
#include "vtkDataSetAttributes.h"
#include "vtkDoubleArray.h"
#include "vtkFFDDataContract.h"
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

#include <sstream>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkFFDBuildLattice);

namespace
{
/**
 * What the filter needs to know of a basis over a voxel grid: how many control points lie along each axis,
 * where they rest, and which of them influence a voxel. Each basis fills one in MakeLayout(); the rest of the
 * filter is basis-independent, so the local bases slot in by adding their case there.
 */
struct LatticeLayout
{
  int Points[3];    ///< control points per axis
  int Intervals[3]; ///< control-point spacings across the frame per axis: point i rests at parameter i/Intervals

  /// The control points [first, last] along `axis` that influence voxel `voxel` of that axis.
  void Support(int axis, int /*voxel*/, int& first, int& last) const
  {
    // Only the global basis exists so far: its support is the whole axis.
    first = 0;
    last = this->Points[axis] - 1;
  }
};

/// The layout of `basis` over `divisions` voxels; false with the reason (and its remedy) in `why`.
bool MakeLayout(int basis, const int divisions[3], LatticeLayout& layout, std::string& why)
{
  if (basis != vtkFFDBuildLattice::BERNSTEIN)
  {
    why = std::string("basis ") + vtkFFDBuildLattice::GetBasisAsString(basis) +
      " is not implemented yet; use BERNSTEIN (SetBasisToBernstein()).";
    return false;
  }
  for (int a = 0; a < 3; ++a)
  {
    // The global lattice's degree along an axis is the number of voxels along it.
    if (divisions[a] > ffd::MaxBernsteinDegree)
    {
      std::ostringstream msg;
      msg << "the BERNSTEIN basis would have degree " << divisions[a] << " along axis " << a
          << ", above the maximum " << ffd::MaxBernsteinDegree << ": give vtkFFDVoxelize at most "
          << ffd::MaxBernsteinDegree << " divisions per axis.";
      why = msg.str();
      return false;
    }
    layout.Points[a] = divisions[a] + 1;
    layout.Intervals[a] = divisions[a];
  }
  return true;
}
} // namespace

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
      return "BERNSTEIN";
    case TRILINEAR:
      return "TRILINEAR";
    case TRIQUADRATIC_BEZIER:
      return "TRIQUADRATIC_BEZIER";
    case TRICUBIC_BEZIER:
      return "TRICUBIC_BEZIER";
    case CUBIC_BSPLINE:
      return "CUBIC_BSPLINE";
    default:
      return "UNKNOWN";
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
  LatticeLayout layout;
  std::string why;
  if (!MakeLayout(this->Basis, divisions, layout, why))
  {
    vtkErrorMacro(<< "Cannot build the lattice: " << why);
    return 0;
  }
  const int latticeExtent[6] = { 0, layout.Points[0] - 1, 0, layout.Points[1] - 1, 0, layout.Points[2] - 1 };
  outInfo->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), latticeExtent, 6);
  return 1;
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
  if (dims[0] != divisions[0] + 1 || dims[1] != divisions[1] + 1 || dims[2] != divisions[2] + 1)
  {
    vtkErrorMacro(<< "The input's dimensions (" << dims[0] << ", " << dims[1] << ", " << dims[2]
                  << ") do not match its " << vtkFFDDataContract::DivisionsArrayName() << " ("
                  << divisions[0] << ", " << divisions[1] << ", " << divisions[2]
                  << ") plus one: connect the output of vtkFFDVoxelize.");
    return 0;
  }
  if (ffd::CheckFrame(frame) != ffd::FrameStatus::Valid)
  {
    vtkErrorMacro(<< "The input's " << vtkFFDDataContract::FrameArrayName()
                  << " has (nearly) zero volume: its edge vectors S, T, U must be linearly independent; "
                     "connect the output of vtkFFDVoxelize or fix the frame.");
    return 0;
  }
  LatticeLayout layout;
  std::string why;
  if (!MakeLayout(this->Basis, divisions, layout, why))
  {
    vtkErrorMacro(<< "Cannot build the lattice: " << why);
    return 0;
  }

  // Which control points influence an active voxel: the union of the active voxels' supports. A voxel is
  // active unless the input's cell ghost array hides it. Once a support covers the whole lattice (always so
  // for a global basis) no further voxel can add to it.
  const int nI = layout.Points[0], nJ = layout.Points[1], nK = layout.Points[2];
  const vtkIdType numControlPoints = static_cast<vtkIdType>(nI) * nJ * nK;
  std::vector<unsigned char> active(static_cast<size_t>(numControlPoints), 0);
  vtkUnsignedCharArray* cellGhosts = input->GetCellGhostArray();
  if (cellGhosts && cellGhosts->GetNumberOfValues() != input->GetNumberOfCells())
  {
    vtkErrorMacro(<< "The input's cell array " << vtkDataSetAttributes::GhostArrayName() << " has "
                  << cellGhosts->GetNumberOfValues() << " values for " << input->GetNumberOfCells()
                  << " voxels: connect the output of vtkFFDVoxelize.");
    return 0;
  }
  bool covered = false;
  for (int k = 0; k < divisions[2] && !covered; ++k)
  {
    for (int j = 0; j < divisions[1] && !covered; ++j)
    {
      for (int i = 0; i < divisions[0] && !covered; ++i)
      {
        const vtkIdType voxel = i + static_cast<vtkIdType>(divisions[0]) * (j + static_cast<vtkIdType>(divisions[1]) * k);
        if (cellGhosts && (cellGhosts->GetValue(voxel) & vtkDataSetAttributes::HIDDENCELL))
        {
          continue;
        }
        int first[3], last[3];
        layout.Support(0, i, first[0], last[0]);
        layout.Support(1, j, first[1], last[1]);
        layout.Support(2, k, first[2], last[2]);
        for (int c = first[2]; c <= last[2]; ++c)
        {
          for (int b = first[1]; b <= last[1]; ++b)
          {
            for (int a = first[0]; a <= last[0]; ++a)
            {
              active[a + static_cast<size_t>(nI) * (b + static_cast<size_t>(nJ) * c)] = 1;
            }
          }
        }
        covered = first[0] == 0 && first[1] == 0 && first[2] == 0 && last[0] == nI - 1 && last[1] == nJ - 1 &&
          last[2] == nK - 1;
      }
    }
  }
  this->UpdateProgress(0.5);
  if (this->GetAbortExecute())
  {
    return 1;
  }

  // The rest positions, each computed directly from the frame (no accumulated steps).
  const ffd::Frame<double> bound = ffd::Frame<double>::FromArray(frame);
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(numControlPoints);
  vtkDoubleArray* pointArray = vtkDoubleArray::SafeDownCast(points->GetData());
  vtkSMPTools::For(0, numControlPoints, [&](vtkIdType begin, vtkIdType end) {
    for (vtkIdType id = begin; id < end; ++id)
    {
      const vtkIdType i = id % nI, j = (id / nI) % nJ, k = id / (static_cast<vtkIdType>(nI) * nJ);
      const ffd::Vec3<double> x = bound.ToWorld({ static_cast<double>(i) / layout.Intervals[0],
        static_cast<double>(j) / layout.Intervals[1], static_cast<double>(k) / layout.Intervals[2] });
      pointArray->SetTypedTuple(id, &x.x);
    }
  });

  vtkNew<vtkDoubleArray> rest;
  rest->DeepCopy(pointArray);
  rest->SetName(vtkFFDDataContract::RestPositionArrayName());
  vtkNew<vtkUnsignedCharArray> activeArray;
  activeArray->SetName(vtkFFDDataContract::ActiveArrayName());
  activeArray->SetNumberOfValues(numControlPoints);
  vtkIdType numActive = 0;
  for (vtkIdType id = 0; id < numControlPoints; ++id)
  {
    activeArray->SetValue(id, active[id]);
    numActive += active[id];
  }

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
