// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDVoxelize.h"

#include "vtkArrayDispatch.h"
#include "vtkDataArrayRange.h"
#include "vtkDoubleArray.h"
#include "vtkFFDDistributed.h"
#include "vtkFFDInputChecks.h"
#include "vtkFFDMemory.h"
#include "vtkFFDPipelineKeys.h"
#include "vtkFFDSparseLattice.h"
#include "vtkFFDStatistics.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkIntArray.h"
#include "vtkMultiProcessController.h"
#include "vtkObjectFactory.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkUnstructuredGrid.h"

#include "FFDFrame.h"
#include "FFDGridDeformation.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <vector>

vtkStandardNewMacro(vtkFFDVoxelize);

vtkCxxSetObjectMacro(vtkFFDVoxelize, Controller, vtkMultiProcessController);

namespace
{
/// Calls fn(range) with `range` the 3-component tuple range of the points, typed for float and double point
/// arrays and going through the generic vtkDataArray API for any other type.
template <typename Fn>
void WithPointRange(vtkDataArray* points, Fn&& fn)
{
  auto worker = [&fn](auto* array) { fn(vtk::DataArrayTupleRange<3>(array)); };
  if (!vtkArrayDispatch::DispatchByValueType<vtkArrayDispatch::Reals>::Execute(points, worker))
  {
    worker(points);
  }
}

template <typename Tuple>
bool IsFinite(const Tuple& p)
{
  return std::isfinite(static_cast<double>(p[0])) && std::isfinite(static_cast<double>(p[1])) &&
    std::isfinite(static_cast<double>(p[2]));
}

/// Whether Divisions can be voxelized; else an error of `self`. RequestInformation and RequestData both check:
/// ParaView's executive still calls RequestData after RequestInformation failed.
bool CheckDivisions(vtkFFDVoxelize* self, const int n[3])
{
  if (n[0] < 1 || n[1] < 1 || n[2] < 1)
  {
    vtkErrorWithObjectMacro(self, << "Divisions (" << n[0] << ", " << n[1] << ", " << n[2]
                                  << ") must be at least 1 on every axis: set Divisions (SetDivisions()) to "
                                     "positive numbers.");
    return false;
  }
  // Voxels and corners are found by their int64 linear index i + nx (j + ny k): the corners' count must fit.
  if ((n[0] + 1.0) * (n[1] + 1.0) * (n[2] + 1.0) >= 0x1p63)
  {
    vtkErrorWithObjectMacro(self, << "Divisions (" << n[0] << ", " << n[1] << ", " << n[2]
                                  << ") have more voxel corners than a 64-bit index counts: use at most 2^21 "
                                     "divisions per axis, or fewer on the others.");
    return false;
  }
  return true;
}

/// Whether the frame of `self` can be used; else an error that names the setting to change.
bool CheckFrame(vtkFFDVoxelize* self, const double frame[12])
{
  const ffd::FrameStatus status = ffd::CheckFrame(frame);
  if (status == ffd::FrameStatus::Valid)
  {
    return true;
  }
  std::ostringstream fix;
  const double padding = self->GetPadding();
  if (self->GetFrameMode() == vtkFFDVoxelize::EXPLICIT)
  {
    fix << "give the explicit frame (SetFrame(), FrameOrigin, FrameS, FrameT, FrameU) finite, linearly independent "
           "edge vectors S, T, U.";
  }
  else if (!std::isfinite(padding) || status != ffd::FrameStatus::ZeroVolume)
  {
    fix << "Padding " << padding << " times the input's extent does not give a finite frame: set Padding "
        << "(SetPadding()) to a finite fraction such as 0.05.";
  }
  else
  {
    fix << "the input is flat; set Padding (SetPadding()) above 0 or give an explicit frame.";
  }
  vtkErrorWithObjectMacro(self, << "The " << self->GetFrameModeAsString() << " frame "
                                << ffd::DescribeFrameStatus(status) << ": " << fix.str());
  return false;
}

/// A box along three orthonormal axes: the points a + sum_c x_c axis_c with x_c in [Min_c, Max_c].
struct OrientedBox
{
  Eigen::Vector3d Anchor = Eigen::Vector3d::Zero();
  Eigen::Matrix3d Axes = Eigen::Matrix3d::Identity(); // columns: the S, T and U directions
  Eigen::Vector3d Min = Eigen::Vector3d::Constant(std::numeric_limits<double>::max());
  Eigen::Vector3d Max = Eigen::Vector3d::Constant(std::numeric_limits<double>::lowest());
  vtkIdType Count = 0; ///< finite points inside

  /// Grows the box around every finite point, in the box's axes. Serial, so the result is deterministic.
  void Enclose(vtkDataArray* points)
  {
    WithPointRange(points,
      [this](auto range)
      {
        for (const auto p : range)
        {
          if (!IsFinite(p))
          {
            continue;
          }
          const Eigen::Vector3d x(p[0], p[1], p[2]);
          const Eigen::Vector3d local = this->Axes.transpose() * (x - this->Anchor);
          this->Min = this->Min.cwiseMin(local);
          this->Max = this->Max.cwiseMax(local);
          ++this->Count;
        }
      });
  }

  /// Writes the frame of the box grown by `padding` times its largest extent on every side.
  void ToFrame(double padding, double frame[12]) const
  {
    const double pad = padding * (this->Max - this->Min).maxCoeff();
    const Eigen::Vector3d lo = this->Min.array() - pad;
    const Eigen::Vector3d hi = this->Max.array() + pad;
    const Eigen::Vector3d origin = this->Anchor + this->Axes * lo;
    for (int c = 0; c < 3; ++c)
    {
      frame[c] = origin[c];
      for (int a = 0; a < 3; ++a)
      {
        frame[3 + 3 * a + c] = (hi[a] - lo[a]) * this->Axes(c, a);
      }
    }
  }
};

/// Mean and covariance of the finite points over every process, each an exact sum rounded once (the same
/// whatever the points' order and the processes), in two passes (free of the cancellation of the one-pass
/// formula).
bool PrincipalAxes(
  vtkDataArray* points, vtkMultiProcessController* controller, Eigen::Vector3d& mean, Eigen::Matrix3d& axes)
{
  std::vector<ffd::ExactSum> sums(4); // x, y, z, count
  WithPointRange(points,
    [&](auto range)
    {
      for (const auto p : range)
      {
        if (IsFinite(p))
        {
          for (int c = 0; c < 3; ++c)
          {
            sums[c].Add(static_cast<double>(p[c]));
          }
          sums[3].Add(1.0);
        }
      }
    });
  vtkFFDSumOverProcesses(controller, sums);
  const double count = sums[3].Value();
  if (count == 0)
  {
    return false;
  }
  mean = Eigen::Vector3d(sums[0].Value(), sums[1].Value(), sums[2].Value()) / count;
  std::vector<ffd::ExactSum> products(6); // the upper triangle, row by row
  WithPointRange(points,
    [&](auto range)
    {
      for (const auto p : range)
      {
        if (IsFinite(p))
        {
          const Eigen::Vector3d d = Eigen::Vector3d(p[0], p[1], p[2]) - mean;
          for (int r = 0, e = 0; r < 3; ++r)
          {
            for (int c = r; c < 3; ++c)
            {
              products[e++].Add(d[r] * d[c]);
            }
          }
        }
      }
    });
  vtkFFDSumOverProcesses(controller, products);
  Eigen::Matrix3d covariance;
  for (int r = 0, e = 0; r < 3; ++r)
  {
    for (int c = r; c < 3; ++c)
    {
      covariance(r, c) = covariance(c, r) = products[e++].Value() / count;
    }
  }

  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
  if (solver.info() != Eigen::Success)
  {
    return false;
  }
  // Eigenvalues come in increasing order: S is the major axis, T the middle one. Each eigenvector's sign is
  // arbitrary; fixing the largest component positive makes the frame independent of the solver's choice,
  // and U = S x T makes it right-handed.
  for (int a = 0; a < 2; ++a)
  {
    Eigen::Vector3d v = solver.eigenvectors().col(2 - a);
    Eigen::Index largest;
    v.cwiseAbs().maxCoeff(&largest);
    axes.col(a) = v[largest] < 0 ? Eigen::Vector3d(-v) : v;
  }
  axes.col(2) = axes.col(0).cross(axes.col(1));
  return true;
}

/// Marks the active voxels, each thread the voxels of its points: the voxel of a point is the cell that
/// vtkFFDDeform binds it to (ffd::BindToCells, s = 1 in the last voxel). Points outside the frame and non-finite
/// ones mark none.
void MarkActiveVoxels(vtkDataArray* points, const double frame[12], const int divisions[3], vtkFFDActiveSet& active)
{
  const ffd::Frame<double> bound = ffd::Frame<double>::FromArray(frame);
  WithPointRange(points,
    [&](auto range)
    {
      active.Mark(points->GetNumberOfTuples(),
        [&](vtkIdType begin, vtkIdType end, vtkFFDBoxMarker& marker)
        {
          const int one[3] = { 1, 1, 1 };
          for (vtkIdType id = begin; id < end; ++id)
          {
            const auto p = range[id];
            int v[3];
            if (ffd::BindToCells(bound, divisions,
                  { static_cast<double>(p[0]), static_cast<double>(p[1]), static_cast<double>(p[2]) }, false, v))
            {
              marker.Mark(v, one);
            }
          }
        });
    });
}
} // namespace

//------------------------------------------------------------------------------
vtkFFDVoxelize::vtkFFDVoxelize()
  : Divisions{ 4, 4, 4 }
  , Padding(0.05)
  , FrameMode(AXIS_ALIGNED)
  , FrameOrigin{ 0.0, 0.0, 0.0 }
  , FrameS{ 1.0, 0.0, 0.0 }
  , FrameT{ 0.0, 1.0, 0.0 }
  , FrameU{ 0.0, 0.0, 1.0 }
  , NumberOfActiveVoxels(0)
  , Controller(nullptr)
{
  this->SetController(vtkMultiProcessController::GetGlobalController());
}

//------------------------------------------------------------------------------
vtkFFDVoxelize::~vtkFFDVoxelize()
{
  this->SetController(nullptr);
}

//------------------------------------------------------------------------------
void vtkFFDVoxelize::SetFrame(const double origin[3], const double s[3], const double t[3], const double u[3])
{
  this->SetFrameOrigin(origin[0], origin[1], origin[2]);
  this->SetFrameS(s[0], s[1], s[2]);
  this->SetFrameT(t[0], t[1], t[2]);
  this->SetFrameU(u[0], u[1], u[2]);
  this->SetFrameModeToExplicit();
}

//------------------------------------------------------------------------------
const char* vtkFFDVoxelize::GetFrameModeAsString()
{
  switch (this->FrameMode)
  {
    case PRINCIPAL_AXES:
      return "PrincipalAxes";
    case EXPLICIT:
      return "Explicit";
    default:
      return "AxisAligned";
  }
}

//------------------------------------------------------------------------------
int vtkFFDVoxelize::FillInputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkPointSet");
  return 1;
}

//------------------------------------------------------------------------------
int vtkFFDVoxelize::RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  if (!CheckDivisions(this, this->Divisions))
  {
    return vtkFFDEmptyOutputs(outputVector); // RequestData does not run: an earlier output would stay
  }
  outputVector->GetInformationObject(0)->Set(vtkFFDPipelineKeys::DIVISIONS(), this->Divisions, 3);
  return 1;
}

//------------------------------------------------------------------------------------------------------------
int vtkFFDVoxelize::RequestUpdateExtent(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  return vtkFFDRequestOwnPiece(this->Controller, inputVector) ||
    this->Superclass::RequestUpdateExtent(request, inputVector, outputVector);
}

//------------------------------------------------------------------------------------------------------------
vtkTypeBool vtkFFDVoxelize::ProcessRequest(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  return vtkFFDCatchAllocationFailure(
    this, outputVector, [&] { return this->Superclass::ProcessRequest(request, inputVector, outputVector); });
}

//------------------------------------------------------------------------------
bool vtkFFDVoxelize::ComputeFrame(
  vtkDataArray* points, vtkMultiProcessController* controller, vtkIdType numPoints, double frame[12])
{
  if (this->FrameMode == EXPLICIT)
  {
    std::copy(this->FrameOrigin, this->FrameOrigin + 3, frame);
    std::copy(this->FrameS, this->FrameS + 3, frame + 3);
    std::copy(this->FrameT, this->FrameT + 3, frame + 6);
    std::copy(this->FrameU, this->FrameU + 3, frame + 9);
    return true;
  }
  OrientedBox box;
  if (this->FrameMode == PRINCIPAL_AXES && !PrincipalAxes(points, controller, box.Anchor, box.Axes))
  {
    vtkErrorMacro(<< "The principal axes of the input's points could not be computed (no finite point, or "
                     "the eigen-decomposition failed): remove the NaN/Inf points or set an explicit frame.");
    return false;
  }
  box.Enclose(points);
  vtkFFDBoundsOverProcesses(controller, box.Count, box.Min.data(), box.Max.data());
  if (box.Count == 0)
  {
    vtkErrorMacro(<< "None of the input's " << numPoints
                  << " points is finite, so no automatic frame can enclose them: remove the NaN/Inf "
                     "points or give an explicit frame (FrameMode Explicit, SetFrame()).");
    return false;
  }
  if (!((box.Max - box.Min).maxCoeff() > 0.0))
  {
    vtkErrorMacro(<< "All " << box.Count
                  << " finite input points are identical, so an automatic frame has no size: "
                     "give an explicit frame (FrameMode Explicit, SetFrame()).");
    return false;
  }
  box.ToFrame(this->Padding, frame);
  return true;
}

//------------------------------------------------------------------------------
int vtkFFDVoxelize::RequestData(vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkPointSet* input = vtkPointSet::GetData(inputVector[0]);
  vtkUnstructuredGrid* output = vtkUnstructuredGrid::GetData(outputVector);
  this->NumberOfActiveVoxels = 0;
  const vtkFFDStatisticsOnReturn statistics(
    output, [this](vtkDataObject* out) { vtkFFDRecordCount(out, "NumberOfActiveVoxels", this->NumberOfActiveVoxels); });
  const vtkIdType numPoints = input ? input->GetNumberOfPoints() : 0;
  // With several processes, every one takes part in the reductions, an empty piece too.
  vtkMultiProcessController* controller = vtkFFDIsDistributed(this->Controller) ? this->Controller : nullptr;
  if (numPoints == 0 && !controller)
  {
    return 1; // an empty input gives an empty output
  }
  // A distributed mesh's points shared by pieces count once: in the principal axes' sums above all.
  const vtkSmartPointer<vtkDataArray> points = vtkFFDOwnedPoints(input);
  if (!CheckDivisions(this, this->Divisions))
  {
    return 0;
  }
  const int nx = this->Divisions[0], ny = this->Divisions[1], nz = this->Divisions[2];

  // Phase 1: the frame.
  double frame[12];
  if (!this->ComputeFrame(points, controller, numPoints, frame) || !CheckFrame(this, frame))
  {
    return 0;
  }
  this->UpdateProgress(0.1);
  if (this->GetAbortExecute())
  {
    return 1;
  }

  // Phase 2: the active voxels.
  vtkFFDActiveSet active;
  MarkActiveVoxels(points, frame, this->Divisions, active);
  const vtkIdType numVoxels = active.GetNumberOfMarked();
  this->UpdateProgress(0.4);
  if (this->GetAbortExecute())
  {
    return 1;
  }

  // Phase 3: the voxels in increasing order (8 bytes each while sorted) and their VoxelIndex (12 bytes).
  std::ostringstream request;
  request << numVoxels << " active voxels of divisions (" << nx << ", " << ny << ", " << nz << ")";
  if (!vtkFFDCheckMemory(this, "The " + request.str(), 20.0 * double(numVoxels)))
  {
    return 0;
  }
  const vtkTypeInt64 dims[3] = { nx, ny, nz };
  const std::vector<vtkTypeInt64> voxels = vtkFFDUnionOverProcesses(controller, active.TakeSortedIndices(dims));
  vtkSmartPointer<vtkIntArray> voxelIndex = vtkFFDMakeVoxelIndex(voxels, this->Divisions);
  this->UpdateProgress(0.6);
  if (this->GetAbortExecute())
  {
    return 1;
  }

  // Phase 4: the corners and the hexahedra on them.
  if (!vtkFFDMakeVoxelGrid(
        this, frame, this->Divisions, voxelIndex, "The corners and hexahedra of " + request.str(), output))
  {
    return 0;
  }
  this->NumberOfActiveVoxels = static_cast<vtkIdType>(voxels.size());
  this->UpdateProgress(1.0);
  return 1;
}

//------------------------------------------------------------------------------
void vtkFFDVoxelize::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Divisions: " << this->Divisions[0] << ", " << this->Divisions[1] << ", " << this->Divisions[2]
     << "\n";
  os << indent << "Padding: " << this->Padding << "\n";
  os << indent << "FrameMode: " << this->GetFrameModeAsString() << "\n";
  os << indent << "FrameOrigin: " << this->FrameOrigin[0] << ", " << this->FrameOrigin[1] << ", "
     << this->FrameOrigin[2] << "\n";
  os << indent << "FrameS: " << this->FrameS[0] << ", " << this->FrameS[1] << ", " << this->FrameS[2] << "\n";
  os << indent << "FrameT: " << this->FrameT[0] << ", " << this->FrameT[1] << ", " << this->FrameT[2] << "\n";
  os << indent << "FrameU: " << this->FrameU[0] << ", " << this->FrameU[1] << ", " << this->FrameU[2] << "\n";
  os << indent << "NumberOfActiveVoxels: " << this->NumberOfActiveVoxels << "\n";
  os << indent << "Controller: " << this->Controller << "\n";
}
