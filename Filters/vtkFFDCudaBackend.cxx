// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDCudaBackend.h"

#include "vtkAOSDataArrayTemplate.h"
#include "vtkDataArray.h"
#include "vtkDataArrayRange.h"
#include "vtkPoints.h"

#ifdef VOXELFFD_HAS_CUDA
#include "FFDCudaGridDeformer.h"
#endif

#include <algorithm>
#include <vector>

//------------------------------------------------------------------------------------------------------------
vtkFFDBindingKey vtkFFDBindingKey::Of(
  vtkPoints* points, const double frame[12], const int divisions[3], int basis, int outsidePolicy)
{
  vtkFFDBindingKey key;
  key.Points = points;
  key.PointsMTime = points->GetMTime();
  key.NumberOfPoints = points->GetNumberOfPoints();
  std::copy(frame, frame + 12, key.Frame.begin());
  std::copy(divisions, divisions + 3, key.Divisions.begin());
  key.Basis = basis;
  key.OutsidePolicy = outsidePolicy;
  return key;
}

bool vtkFFDBindingKey::operator==(const vtkFFDBindingKey& other) const
{
  return this->Points == other.Points && this->PointsMTime == other.PointsMTime &&
    this->NumberOfPoints == other.NumberOfPoints && this->Frame == other.Frame &&
    this->Divisions == other.Divisions && this->Basis == other.Basis && this->OutsidePolicy == other.OutsidePolicy;
}

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
} // namespace

struct vtkFFDCudaBackend::vtkState
{
  ffd::cuda::GridDeformer Device;
  vtkFFDBindingKey Key;            // what the device's points and binding are for
  int PointsType = 0;              // VTK_FLOAT or VTK_DOUBLE: the precision they were uploaded in
  const vtkDataArray* Normals = nullptr; // the normals on the device, and their modification time
  vtkMTimeType NormalsMTime = 0;

  template <typename Real>
  bool Run(const vtkFFDBindingKey& key, vtkPoints* points, vtkDataArray* normals, const double* displacements,
    vtkIdType controlPoints, vtkAOSDataArrayTemplate<Real>* outPoints, vtkDataArray* outNormals,
    vtkAOSDataArrayTemplate<Real>* outDeterminants, bool& bound)
  {
    const int type = outPoints->GetDataType();
    if (key != this->Key || type != this->PointsType)
    {
      this->Key = vtkFFDBindingKey();
      this->Normals = nullptr;
      std::vector<Real> copy;
      if (!this->Device.SetPoints(Contiguous(points->GetData(), copy), key.NumberOfPoints) ||
        !this->Device.Bind(key.Frame.data(), key.Basis, key.Divisions.data(), key.OutsidePolicy != 0))
      {
        return false;
      }
      this->Key = key;
      this->PointsType = type;
      bound = true;
    }
    if (outNormals && (normals != this->Normals || normals->GetMTime() != this->NormalsMTime))
    {
      std::vector<float> copy;
      if (!this->Device.SetNormals(Contiguous(normals, copy)))
      {
        this->Key = vtkFFDBindingKey();
        return false;
      }
      this->Normals = normals;
      this->NormalsMTime = normals->GetMTime();
    }
    std::vector<float> normalsCopy;
    auto* floatNormals = outNormals ? vtkAOSDataArrayTemplate<float>::FastDownCast(outNormals) : nullptr;
    if (outNormals && !floatNormals)
    {
      normalsCopy.resize(3 * static_cast<size_t>(key.NumberOfPoints));
    }
    float* normalsTarget = floatNormals ? floatNormals->GetPointer(0) : (outNormals ? normalsCopy.data() : nullptr);
    if (!this->Device.Evaluate(displacements, controlPoints, outNormals != nullptr, outDeterminants != nullptr) ||
      !this->Device.Download(outPoints->GetPointer(0), normalsTarget,
        outDeterminants ? outDeterminants->GetPointer(0) : nullptr))
    {
      this->Key = vtkFFDBindingKey(); // the device dropped its state
      return false;
    }
    if (outNormals && !floatNormals)
    {
      auto values = vtk::DataArrayValueRange<3>(outNormals);
      std::copy(normalsCopy.begin(), normalsCopy.end(), values.begin());
    }
    return true;
  }
};
#else
struct vtkFFDCudaBackend::vtkState
{
};
#endif

//------------------------------------------------------------------------------------------------------------
vtkFFDCudaBackend::vtkFFDCudaBackend()
  : State(new vtkState)
{
}

vtkFFDCudaBackend::~vtkFFDCudaBackend() = default;

bool vtkFFDCudaBackend::IsAvailable(std::string& why)
{
#ifdef VOXELFFD_HAS_CUDA
  return ffd::cuda::DeviceAvailable(&why);
#else
  why = "VoxelFFD was built without CUDA";
  return false;
#endif
}

bool vtkFFDCudaBackend::Deform(const vtkFFDBindingKey& key, vtkPoints* points, vtkDataArray* normals,
  const double* displacements, vtkIdType controlPoints, vtkDataArray* outPoints, vtkDataArray* outNormals,
  vtkDataArray* outDeterminants, bool& bound, std::string& why)
{
  bound = false;
#ifdef VOXELFFD_HAS_CUDA
  bool ok = false;
  if (auto* out = vtkAOSDataArrayTemplate<double>::FastDownCast(outPoints))
  {
    ok = this->State->Run(key, points, normals, displacements, controlPoints, out, outNormals,
      vtkAOSDataArrayTemplate<double>::FastDownCast(outDeterminants), bound);
  }
  else if (auto* outFloat = vtkAOSDataArrayTemplate<float>::FastDownCast(outPoints))
  {
    ok = this->State->Run(key, points, normals, displacements, controlPoints, outFloat, outNormals,
      vtkAOSDataArrayTemplate<float>::FastDownCast(outDeterminants), bound);
  }
  if (!ok)
  {
    why = this->State->Device.GetLastError();
  }
  return ok;
#else
  (void)key;
  (void)points;
  (void)normals;
  (void)displacements;
  (void)controlPoints;
  (void)outPoints;
  (void)outNormals;
  (void)outDeterminants;
  why = "VoxelFFD was built without CUDA";
  return false;
#endif
}
