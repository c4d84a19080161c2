// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDVoxelize.h"

#include "vtkArrayDispatch.h"
#include "vtkCellData.h"
#include "vtkDataArrayRange.h"
#include "vtkDataSetAttributes.h"
#include "vtkDoubleArray.h"
#include "vtkFFDDataContract.h"
#include "vtkFFDMemory.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkObjectFactory.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkSMPTools.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkStructuredGrid.h"
#include "vtkUnsignedCharArray.h"

#include "FFDFrame.h"

#include <Eigen/Eigenvalues>

// OpenVDB is confined to this translation unit: its headers cost ~12 s to compile.
#include <openvdb/openvdb.h>
#include <openvdb/tools/PointsToMask.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>
#include <vector>

vtkStandardNewMacro(vtkFFDVoxelize);

namespace
{
using VoxelIndex = std::array<int, 3>;

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

/// Mean and covariance of the finite points, in double, two serial passes (deterministic and free of the
/// cancellation of the one-pass formula).
bool PrincipalAxes(vtkDataArray* points, Eigen::Vector3d& mean, Eigen::Matrix3d& axes)
{
  mean.setZero();
  vtkIdType count = 0;
  WithPointRange(points,
    [&](auto range)
    {
      for (const auto p : range)
      {
        if (IsFinite(p))
        {
          mean += Eigen::Vector3d(p[0], p[1], p[2]);
          ++count;
        }
      }
    });
  if (count == 0)
  {
    return false;
  }
  mean /= static_cast<double>(count);
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  WithPointRange(points,
    [&](auto range)
    {
      for (const auto p : range)
      {
        if (IsFinite(p))
        {
          const Eigen::Vector3d d = Eigen::Vector3d(p[0], p[1], p[2]) - mean;
          covariance.noalias() += d * d.transpose();
        }
      }
    });
  covariance /= static_cast<double>(count);

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

/// The point list OpenVDB's PointsToMask reads: voxel indices as index-space positions (the grid's transform
/// is the identity, and an integer position is the centre of that voxel).
struct VoxelPointList
{
  const std::vector<VoxelIndex>* Voxels;
  size_t size() const { return this->Voxels->size(); }
  void getPos(size_t n, openvdb::Vec3R& xyz) const
  {
    const VoxelIndex& v = (*this->Voxels)[n];
    xyz = openvdb::Vec3R(v[0], v[1], v[2]);
  }
};
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
{
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
  const int* n = this->Divisions;
  if (n[0] < 1 || n[1] < 1 || n[2] < 1)
  {
    vtkErrorMacro(<< "Divisions (" << n[0] << ", " << n[1] << ", " << n[2]
                  << ") must be at least 1 on every axis: call SetDivisions() with positive numbers.");
    return 0;
  }
  const int extent[6] = { 0, n[0], 0, n[1], 0, n[2] };
  outputVector->GetInformationObject(0)->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), extent, 6);
  return 1;
}

//------------------------------------------------------------------------------------------------------------
vtkTypeBool vtkFFDVoxelize::ProcessRequest(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  return vtkFFDCatchAllocationFailure(
    this, outputVector, [&] { return this->Superclass::ProcessRequest(request, inputVector, outputVector); });
}

//------------------------------------------------------------------------------
int vtkFFDVoxelize::RequestData(vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkPointSet* input = vtkPointSet::GetData(inputVector[0]);
  vtkStructuredGrid* output = vtkStructuredGrid::GetData(outputVector);
  this->NumberOfActiveVoxels = 0;
  const vtkIdType numPoints = input ? input->GetNumberOfPoints() : 0;
  if (numPoints == 0)
  {
    return 1; // an empty input gives an empty output
  }
  vtkDataArray* points = input->GetPoints()->GetData();
  const int nx = this->Divisions[0], ny = this->Divisions[1], nz = this->Divisions[2];
  // The output is dense: a corner point (24 bytes) per voxel corner and a ghost byte per voxel; the voxel of
  // each input point takes 12 bytes meanwhile.
  const double voxelCount = double(nx) * ny * nz, cornerCount = (nx + 1.0) * (ny + 1.0) * (nz + 1.0);
  std::ostringstream request;
  request << "Divisions (" << nx << ", " << ny << ", " << nz << "): a voxel grid of " << voxelCount << " voxels and "
          << cornerCount << " corner points";
  if (!vtkFFDCheckMemory(this, request.str(), 24.0 * cornerCount + voxelCount + 12.0 * double(numPoints)))
  {
    return 0;
  }

  // Phase 1: the frame.
  double frame[12];
  if (this->FrameMode == EXPLICIT)
  {
    std::copy(this->FrameOrigin, this->FrameOrigin + 3, frame);
    std::copy(this->FrameS, this->FrameS + 3, frame + 3);
    std::copy(this->FrameT, this->FrameT + 3, frame + 6);
    std::copy(this->FrameU, this->FrameU + 3, frame + 9);
  }
  else
  {
    OrientedBox box;
    if (this->FrameMode == PRINCIPAL_AXES && !PrincipalAxes(points, box.Anchor, box.Axes))
    {
      vtkErrorMacro(<< "The principal axes of the input's points could not be computed (no finite point, or "
                       "the eigen-decomposition failed): remove the NaN/Inf points or set an explicit frame.");
      return 0;
    }
    box.Enclose(points);
    if (box.Count == 0)
    {
      vtkErrorMacro(<< "None of the input's " << numPoints
                    << " points is finite, so no automatic frame can enclose them: remove the NaN/Inf "
                       "points or call SetFrameModeToExplicit() with SetFrame().");
      return 0;
    }
    if (!((box.Max - box.Min).maxCoeff() > 0.0))
    {
      vtkErrorMacro(<< "All " << box.Count
                    << " finite input points are identical, so an automatic frame has no size: "
                       "call SetFrameModeToExplicit() with SetFrame() to give the frame.");
      return 0;
    }
    box.ToFrame(this->Padding, frame);
  }
  switch (ffd::CheckFrame(frame))
  {
    case ffd::FrameStatus::NonFinite:
      vtkErrorMacro(<< "The " << this->GetFrameModeAsString()
                    << " frame has a NaN or infinite component: give SetFrame() finite numbers.");
      return 0;
    case ffd::FrameStatus::ZeroVolume:
      vtkErrorMacro(<< "The " << this->GetFrameModeAsString() << " frame has (nearly) zero volume: "
                    << (this->FrameMode == EXPLICIT
                           ? "give SetFrame() three linearly independent edge vectors S, T, U."
                           : "the input is flat; set a Padding above 0 or an explicit frame."));
      return 0;
    case ffd::FrameStatus::Valid:
      break;
  }
  this->UpdateProgress(0.1);
  if (this->GetAbortExecute())
  {
    return 1;
  }

  // Phase 2: the voxel of every point, in parallel. Points outside the frame or non-finite get {-1, -1, -1}.
  // Parameters are clamped to [0, 1], so s * nx >= 0 truncates to floor(s * nx); s = 1 (the upper face)
  // belongs to the last voxel.
  std::vector<VoxelIndex> voxels(static_cast<size_t>(numPoints));
  const ffd::Frame<double> bound = ffd::Frame<double>::FromArray(frame);
  WithPointRange(points,
    [&](auto range)
    {
      vtkSMPTools::For(0, numPoints,
        [&](vtkIdType begin, vtkIdType end)
        {
          for (vtkIdType id = begin; id < end; ++id)
          {
            const auto p = range[id];
            const ffd::Vec3<double> x{ static_cast<double>(p[0]), static_cast<double>(p[1]),
              static_cast<double>(p[2]) };
            ffd::Vec3<double> stu;
            VoxelIndex& v = voxels[id];
            if (!bound.Bind(x, stu))
            {
              v = { -1, -1, -1 };
              continue;
            }
            v = { std::min(static_cast<int>(stu.x * nx), nx - 1), std::min(static_cast<int>(stu.y * ny), ny - 1),
              std::min(static_cast<int>(stu.z * nz), nz - 1) };
          }
        });
    });
  voxels.erase(
    std::remove_if(voxels.begin(), voxels.end(), [](const VoxelIndex& v) { return v[0] < 0; }), voxels.end());
  this->UpdateProgress(0.4);
  if (this->GetAbortExecute())
  {
    return 1;
  }

  // Phase 3: the sparse set of active voxels. PointsToMask threads with TBB itself, so it is called here, in
  // the serial part, never inside vtkSMPTools.
  static const bool vdbInitialized = (openvdb::initialize(), true);
  (void)vdbInitialized;
  const openvdb::MaskGrid::Ptr mask =
    openvdb::tools::createPointMask(VoxelPointList{ &voxels }, *openvdb::math::Transform::createLinearTransform());
  this->UpdateProgress(0.7);
  if (this->GetAbortExecute())
  {
    return 1;
  }

  // Phase 4: the output. Every voxel starts hidden; the active ones (single voxels or whole tiles, whose
  // bounding box the iterator gives) are shown.
  const vtkIdType numCells = static_cast<vtkIdType>(nx) * ny * nz;
  vtkNew<vtkUnsignedCharArray> ghosts;
  ghosts->SetName(vtkDataSetAttributes::GhostArrayName());
  ghosts->SetNumberOfValues(numCells);
  ghosts->FillValue(vtkDataSetAttributes::HIDDENCELL);
  for (auto it = mask->cbeginValueOn(); it; ++it)
  {
    for (const openvdb::Coord& c : it.getBoundingBox())
    {
      ghosts->SetValue(c.x() + static_cast<vtkIdType>(nx) * (c.y() + static_cast<vtkIdType>(ny) * c.z()), 0);
    }
  }

  const vtkIdType cx = vtkIdType(nx) + 1, cy = vtkIdType(ny) + 1, numCorners = cx * cy * (vtkIdType(nz) + 1);
  vtkNew<vtkPoints> corners;
  corners->SetDataTypeToDouble();
  corners->SetNumberOfPoints(numCorners);
  vtkDoubleArray* cornerArray = vtkDoubleArray::SafeDownCast(corners->GetData());
  vtkSMPTools::For(0, numCorners,
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType id = begin; id < end; ++id)
      {
        const vtkIdType i = id % cx, j = (id / cx) % cy, k = id / (cx * cy);
        const ffd::Vec3<double> x =
          bound.ToWorld({ static_cast<double>(i) / nx, static_cast<double>(j) / ny, static_cast<double>(k) / nz });
        cornerArray->SetTypedTuple(id, &x.x);
      }
    });
  output->SetExtent(0, nx, 0, ny, 0, nz);
  output->SetPoints(corners);
  output->GetCellData()->AddArray(ghosts);
  vtkFFDDataContract::SetFrame(output, frame);
  vtkFFDDataContract::SetDivisions(output, this->Divisions);
  this->NumberOfActiveVoxels = static_cast<vtkIdType>(mask->activeVoxelCount());
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
}
