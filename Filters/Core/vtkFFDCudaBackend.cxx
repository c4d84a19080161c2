// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDCudaBackend.h"

#include "vtkAOSDataArrayTemplate.h"
#include "vtkDataArray.h"
#include "vtkDataArrayRange.h"
#include "vtkPoints.h"

#ifdef VOXELFFD_HAS_CUDA
#include "FFDCudaGridDeformer.h"
#include "FFDCudaTetrahedralDeformer.h"
#include "vtkFFDDeviceOutput.h"
#include "vtkFFDGridDeformer.h"
#include "vtkFFDTetrahedralDeformer.h"
#endif

#include <algorithm>
#include <type_traits>
#include <vector>

#ifdef VOXELFFD_HAS_CUDA
namespace
{
// The values of a 3-component array as a contiguous buffer of T: the array's own memory when it already is one,
// else a converted copy held in `copy`.
template <typename T>
const T* Contiguous(vtkDataArray* array, std::vector<T>& copy)
{
  if (auto* aos = vtkAOSDataArrayTemplate<T>::FastDownCast(array))
  {
    return aos->GetPointer(0);
  }
  copy.resize(3 * static_cast<size_t>(array->GetNumberOfTuples()));
  const auto values = vtk::DataArrayValueRange<3>(array);
  std::copy(values.begin(), values.end(), copy.begin());
  return copy.data();
}

// The normals a device holds: which array, at which modification time.
struct NormalsOnDevice
{
  const vtkDataArray* Array = nullptr;
  vtkMTimeType MTime = 0;
};

// The input's points uploaded in the precision Real when `uploadPoints` (which drops the device's binding and
// normals), then bind() when `rebind`. False on any failure, after which the device holds nothing.
template <typename Real, typename Bind>
bool UploadAndBind(ffd::cuda::ResidentPoints& device, NormalsOnDevice& normalsOnDevice, bool uploadPoints, bool rebind,
  vtkPoints* points, Bind&& bind)
{
  if (uploadPoints)
  {
    normalsOnDevice = NormalsOnDevice();
    std::vector<Real> copy;
    if (!device.SetPoints(Contiguous(points->GetData(), copy), points->GetNumberOfPoints()))
    {
      return false;
    }
  }
  return !rebind || bind();
}

// The steps both lattices share, in the evaluation's precision Real: UploadAndBind(), the normals uploaded when
// they changed, evaluate(withNormals, withDeterminants), the download into the output arrays unless the results
// are `keptOnDevice` (a handle sharing `owner`, the device's state). False on any failure, after which the device
// holds nothing.
template <typename Real, typename Bind, typename Evaluate>
bool Run(ffd::cuda::ResidentPoints& device, const std::shared_ptr<void>& owner, NormalsOnDevice& normalsOnDevice,
  bool uploadPoints, bool rebind, vtkPoints* points, vtkDataArray* normals, vtkAOSDataArrayTemplate<Real>* outPoints,
  vtkDataArray* outNormals, vtkAOSDataArrayTemplate<Real>* outDeterminants,
  vtkSmartPointer<vtkFFDDeviceOutput>* keptOnDevice, Bind&& bind, Evaluate&& evaluate)
{
  if (!UploadAndBind<Real>(device, normalsOnDevice, uploadPoints, rebind, points, bind))
  {
    return false;
  }
  if (outNormals && (normals != normalsOnDevice.Array || normals->GetMTime() != normalsOnDevice.MTime))
  {
    normalsOnDevice = NormalsOnDevice();
    std::vector<Real> copy; // in the evaluation's precision, as the CPU transforms them
    if (!device.SetNormals(Contiguous(normals, copy)))
    {
      return false;
    }
    normalsOnDevice = { normals, normals->GetMTime() };
  }
  if (keptOnDevice)
  {
    double bounds[6];
    if (!evaluate(outNormals != nullptr, false) || !device.ComputeBounds(bounds))
    {
      return false;
    }
    *keptOnDevice = vtkSmartPointer<vtkFFDDeviceOutput>::New();
    (*keptOnDevice)
      ->SetDevice(std::shared_ptr<ffd::cuda::ResidentPoints>(owner, &device), points->GetNumberOfPoints(),
        outNormals != nullptr, bounds);
    return true;
  }
  std::vector<Real> normalsCopy;
  auto* realNormals = outNormals ? vtkAOSDataArrayTemplate<Real>::FastDownCast(outNormals) : nullptr;
  if (outNormals && !realNormals)
  {
    normalsCopy.resize(3 * static_cast<size_t>(points->GetNumberOfPoints()));
  }
  Real* normalsTarget = realNormals ? realNormals->GetPointer(0) : (outNormals ? normalsCopy.data() : nullptr);
  if (!evaluate(outNormals != nullptr, outDeterminants != nullptr) ||
    !device.Download(
      outPoints->GetPointer(0), normalsTarget, outDeterminants ? outDeterminants->GetPointer(0) : nullptr))
  {
    return false;
  }
  if (outNormals && !realNormals)
  {
    auto values = vtk::DataArrayValueRange<3>(outNormals);
    std::copy(normalsCopy.begin(), normalsCopy.end(), values.begin());
  }
  return true;
}
} // namespace

struct vtkFFDCudaBackend::vtkState : std::enable_shared_from_this<vtkFFDCudaBackend::vtkState>
{
  ffd::cuda::GridDeformer Grid;
  vtkFFDBindingKey GridKey; // what the grid device's points and binding are for
  int GridType = 0;         // VTK_FLOAT or VTK_DOUBLE: the precision they were uploaded in
  NormalsOnDevice GridNormals;

  ffd::cuda::TetrahedralDeformer Tetrahedra;
  const vtkPoints* TetrahedraPoints = nullptr; // the tetrahedral device's points, their time and precision
  vtkMTimeType TetrahedraPointsMTime = 0;
  int TetrahedraType = 0;
  vtkMTimeType TetrahedraBindTime = 0; // vtkFFDTetrahedralDeformer::GetBindTime() of its binding
  NormalsOnDevice TetrahedraNormals;

  // `sparse`: the host's binding to a sparse lattice, null for a dense one (bound on the device).
  template <typename Real>
  bool RunGrid(const vtkFFDBindingKey& key, const vtkFFDGridDeformer* sparse, vtkPoints* points, vtkDataArray* normals,
    const double* displacements, vtkIdType controlPoints, vtkAOSDataArrayTemplate<Real>* outPoints,
    vtkDataArray* outNormals, vtkAOSDataArrayTemplate<Real>* outDeterminants,
    vtkSmartPointer<vtkFFDDeviceOutput>* keptOnDevice, bool& bound)
  {
    const int type = outPoints->GetDataType();
    const bool rebind = key != this->GridKey || type != this->GridType;
    this->GridKey = vtkFFDBindingKey(); // valid again once everything succeeded
    if (!Run(
          this->Grid, this->shared_from_this(), this->GridNormals, rebind, rebind, points, normals, outPoints,
          outNormals, outDeterminants, keptOnDevice, [&] { return this->BindGrid(key, sparse, controlPoints); },
          [&](bool withNormals, bool withDeterminants)
          { return this->Grid.Evaluate(displacements, controlPoints, withNormals, withDeterminants); }))
    {
      return false;
    }
    this->GridKey = key;
    this->GridType = type;
    bound = rebind;
    return true;
  }

  // Binds the device's points per `key`: on the device for a dense lattice, the host's binding uploaded for a
  // sparse one (`sparse`).
  bool BindGrid(const vtkFFDBindingKey& key, const vtkFFDGridDeformer* sparse, vtkIdType controlPoints)
  {
    if (!sparse)
    {
      return this->Grid.Bind(key.Frame.data(), key.Basis, key.Divisions.data(), key.ClampsOutside());
    }
    const vtkFFDSparseCells& cells = *sparse->GetSparseCells();
    return this->Grid.BindSparse(key.Frame.data(), key.Basis, key.Divisions.data(), sparse->GetCellOfPoint().data(),
      cells.GetVoxels().data(), cells.GetSupports(), cells.GetNumberOfCells(), controlPoints);
  }

  // W^T g on the device's binding for `key`, made (with the points uploaded in the precision Real) where the
  // device's is for something else.
  template <typename Real>
  bool AdjointGrid(const vtkFFDBindingKey& key, const vtkFFDGridDeformer* sparse, vtkPoints* points,
    vtkIdType controlPoints, const double* gradient, double* sums, bool& bound)
  {
    const int type = std::is_same<Real, double>::value ? VTK_DOUBLE : VTK_FLOAT;
    const bool rebind = key != this->GridKey || type != this->GridType;
    this->GridKey = vtkFFDBindingKey(); // valid again once everything succeeded
    if (!UploadAndBind<Real>(this->Grid, this->GridNormals, rebind, rebind, points,
          [&] { return this->BindGrid(key, sparse, controlPoints); }) ||
      !this->Grid.Adjoint(gradient, controlPoints, sums))
    {
      return false;
    }
    this->GridKey = key;
    this->GridType = type;
    bound = rebind;
    return true;
  }

  template <typename Real>
  bool RunTetrahedra(const vtkFFDTetrahedralDeformer& tetrahedra, vtkPoints* points, vtkDataArray* normals,
    vtkAOSDataArrayTemplate<Real>* outPoints, vtkDataArray* outNormals, vtkAOSDataArrayTemplate<Real>* outDeterminants,
    vtkSmartPointer<vtkFFDDeviceOutput>* keptOnDevice)
  {
    const int type = outPoints->GetDataType();
    const bool uploadPoints = points != this->TetrahedraPoints || points->GetMTime() != this->TetrahedraPointsMTime ||
      type != this->TetrahedraType;
    const bool rebind = uploadPoints || tetrahedra.GetBindTime() != this->TetrahedraBindTime;
    this->TetrahedraPoints = nullptr; // valid again once everything succeeded
    const vtkIdType nodes = static_cast<vtkIdType>(tetrahedra.GetDisplacements().size() / 3);
    auto bind = [&] { return this->BindTetrahedra(tetrahedra); };
    auto evaluate = [&](bool withNormals, bool withDeterminants)
    { return this->Tetrahedra.Evaluate(tetrahedra.GetDisplacements().data(), nodes, withNormals, withDeterminants); };
    if (!Run(this->Tetrahedra, this->shared_from_this(), this->TetrahedraNormals, uploadPoints, rebind, points, normals,
          outPoints, outNormals, outDeterminants, keptOnDevice, bind, evaluate))
    {
      return false;
    }
    this->TetrahedraPoints = points;
    this->TetrahedraPointsMTime = points->GetMTime();
    this->TetrahedraType = type;
    this->TetrahedraBindTime = tetrahedra.GetBindTime();
    if (!keptOnDevice)
    {
      tetrahedra.ApplyClampedPoints(points, normals, outPoints, outNormals, outDeterminants);
    }
    return true;
  }

  // Uploads the host's binding of `tetrahedra`.
  bool BindTetrahedra(const vtkFFDTetrahedralDeformer& tetrahedra)
  {
    const std::vector<vtkIdType>& ids = tetrahedra.GetNodes();
    const std::vector<int> nodeIds(ids.begin(), ids.end());
    return this->Tetrahedra.Bind(tetrahedra.GetCellOfPoint().data(), tetrahedra.GetFrames().data(), nodeIds.data(),
      tetrahedra.GetNumberOfTetrahedra(), static_cast<vtkIdType>(tetrahedra.GetDisplacements().size() / 3));
  }

  // W^T g on the device's binding of `tetrahedra`, uploaded (with the points, in the precision Real) where the
  // device holds another.
  template <typename Real>
  bool AdjointTetrahedra(
    const vtkFFDTetrahedralDeformer& tetrahedra, vtkPoints* points, const double* gradient, double* sums)
  {
    const int type = std::is_same<Real, double>::value ? VTK_DOUBLE : VTK_FLOAT;
    const bool uploadPoints = points != this->TetrahedraPoints || points->GetMTime() != this->TetrahedraPointsMTime ||
      type != this->TetrahedraType;
    const bool rebind = uploadPoints || tetrahedra.GetBindTime() != this->TetrahedraBindTime;
    this->TetrahedraPoints = nullptr; // valid again once everything succeeded
    if (!UploadAndBind<Real>(this->Tetrahedra, this->TetrahedraNormals, uploadPoints, rebind, points,
          [&] { return this->BindTetrahedra(tetrahedra); }) ||
      !this->Tetrahedra.Adjoint(gradient, vtkIdType(tetrahedra.GetDisplacements().size() / 3), sums))
    {
      return false;
    }
    this->TetrahedraPoints = points;
    this->TetrahedraPointsMTime = points->GetMTime();
    this->TetrahedraType = type;
    this->TetrahedraBindTime = tetrahedra.GetBindTime();
    return true;
  }

  // Calls run(outPoints, outDeterminants) with the output arrays of the evaluation's precision; false when they
  // are of neither float nor double.
  template <typename RunT>
  static bool WithOutputs(vtkDataArray* outPoints, vtkDataArray* outDeterminants, RunT&& run)
  {
    if (auto* out = vtkAOSDataArrayTemplate<double>::FastDownCast(outPoints))
    {
      return run(out, vtkAOSDataArrayTemplate<double>::FastDownCast(outDeterminants));
    }
    if (auto* out = vtkAOSDataArrayTemplate<float>::FastDownCast(outPoints))
    {
      return run(out, vtkAOSDataArrayTemplate<float>::FastDownCast(outDeterminants));
    }
    return false;
  }
};
#else
struct vtkFFDCudaBackend::vtkState
{
};
#endif

//------------------------------------------------------------------------------------------------------------
vtkFFDCudaBackend::vtkFFDCudaBackend()
  : State(std::make_shared<vtkState>())
{
}

vtkFFDCudaBackend::~vtkFFDCudaBackend() = default;

#ifdef VOXELFFD_HAS_CUDA
bool vtkFFDCudaBackend::IsAvailable(std::string& why)
{
  return ffd::cuda::DeviceAvailable(&why);
}

bool vtkFFDCudaBackend::DeformGrid(const vtkFFDGridDeformer& grid, const vtkFFDBindingKey& key, vtkPoints* points,
  vtkDataArray* normals, vtkDataArray* outPoints, vtkDataArray* outNormals, vtkDataArray* outDeterminants,
  vtkSmartPointer<vtkFFDDeviceOutput>* keptOnDevice, bool& bound, std::string& why)
{
  bound = false;
  std::vector<double> storage;
  const double* displacements = grid.ReadDisplacements(storage);
  const vtkIdType controlPoints = grid.GetLattice().Points->GetNumberOfTuples();
  const bool ok = vtkState::WithOutputs(outPoints, outDeterminants,
    [&](auto* out, auto* determinants)
    {
      return this->State->RunGrid(key, grid.GetSparseCells() ? &grid : nullptr, points, normals, displacements,
        controlPoints, out, outNormals, determinants, keptOnDevice, bound);
    });
  if (!ok)
  {
    why = this->State->Grid.GetLastError();
  }
  return ok;
}

bool vtkFFDCudaBackend::AdjointGrid(const vtkFFDGridDeformer& grid, const vtkFFDBindingKey& key, vtkPoints* points,
  int precision, const double* gradient, double* sums, bool& bound, std::string& why)
{
  bound = false;
  vtkState& state = *this->State;
  const int type = key == state.GridKey ? state.GridType : precision;
  const vtkFFDGridDeformer* sparse = grid.GetSparseCells() ? &grid : nullptr;
  const vtkIdType controlPoints = grid.GetLattice().Points->GetNumberOfTuples();
  const bool ok = type == VTK_DOUBLE
    ? state.AdjointGrid<double>(key, sparse, points, controlPoints, gradient, sums, bound)
    : state.AdjointGrid<float>(key, sparse, points, controlPoints, gradient, sums, bound);
  if (!ok)
  {
    why = state.Grid.GetLastError();
  }
  return ok;
}

bool vtkFFDCudaBackend::AdjointTetrahedra(const vtkFFDTetrahedralDeformer& tetrahedra, vtkPoints* points, int precision,
  const double* gradient, double* sums, std::string& why)
{
  vtkState& state = *this->State;
  const bool resident = points == state.TetrahedraPoints && points->GetMTime() == state.TetrahedraPointsMTime;
  const int type = resident ? state.TetrahedraType : precision;
  const bool ok = type == VTK_DOUBLE ? state.AdjointTetrahedra<double>(tetrahedra, points, gradient, sums)
                                     : state.AdjointTetrahedra<float>(tetrahedra, points, gradient, sums);
  if (!ok)
  {
    why = state.Tetrahedra.GetLastError();
  }
  return ok;
}

bool vtkFFDCudaBackend::DeformTetrahedra(const vtkFFDTetrahedralDeformer& tetrahedra, vtkPoints* points,
  vtkDataArray* normals, vtkDataArray* outPoints, vtkDataArray* outNormals, vtkDataArray* outDeterminants,
  vtkSmartPointer<vtkFFDDeviceOutput>* keptOnDevice, std::string& why)
{
  const bool ok = vtkState::WithOutputs(outPoints, outDeterminants,
    [&](auto* out, auto* determinants)
    { return this->State->RunTetrahedra(tetrahedra, points, normals, out, outNormals, determinants, keptOnDevice); });
  if (!ok)
  {
    why = this->State->Tetrahedra.GetLastError();
  }
  return ok;
}

vtkTypeUInt64 vtkFFDCudaBackend::GetLatticeBytesUploaded() const
{
  return this->State->Grid.GetCounters().LatticeBytes + this->State->Tetrahedra.GetCounters().LatticeBytes;
}

vtkTypeUInt64 vtkFFDCudaBackend::GetBytesDownloaded() const
{
  return this->State->Grid.GetCounters().BytesDownloaded + this->State->Tetrahedra.GetCounters().BytesDownloaded;
}
#else
// Built without CUDA: the backend is never available, and says so.
bool vtkFFDCudaBackend::IsAvailable(std::string& why)
{
  why = "VoxelFFD was built without CUDA";
  return false;
}

bool vtkFFDCudaBackend::DeformGrid(const vtkFFDGridDeformer&, const vtkFFDBindingKey&, vtkPoints*, vtkDataArray*,
  vtkDataArray*, vtkDataArray*, vtkDataArray*, vtkSmartPointer<vtkFFDDeviceOutput>*, bool& bound, std::string& why)
{
  bound = false;
  return vtkFFDCudaBackend::IsAvailable(why);
}

bool vtkFFDCudaBackend::AdjointGrid(const vtkFFDGridDeformer&, const vtkFFDBindingKey&, vtkPoints*, int, const double*,
  double*, bool& bound, std::string& why)
{
  bound = false;
  return vtkFFDCudaBackend::IsAvailable(why);
}

bool vtkFFDCudaBackend::AdjointTetrahedra(
  const vtkFFDTetrahedralDeformer&, vtkPoints*, int, const double*, double*, std::string& why)
{
  return vtkFFDCudaBackend::IsAvailable(why);
}

bool vtkFFDCudaBackend::DeformTetrahedra(const vtkFFDTetrahedralDeformer&, vtkPoints*, vtkDataArray*, vtkDataArray*,
  vtkDataArray*, vtkDataArray*, vtkSmartPointer<vtkFFDDeviceOutput>*, std::string& why)
{
  return vtkFFDCudaBackend::IsAvailable(why);
}

vtkTypeUInt64 vtkFFDCudaBackend::GetLatticeBytesUploaded() const
{
  return 0;
}

vtkTypeUInt64 vtkFFDCudaBackend::GetBytesDownloaded() const
{
  return 0;
}
#endif
