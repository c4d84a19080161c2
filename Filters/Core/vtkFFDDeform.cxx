// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDDeform.h"

#include "vtkFFDCudaBackend.h"
#include "vtkFFDDeformExecutive.h"
#include "vtkFFDDeviceOutput.h"
#include "vtkFFDGridDeformer.h"
#include "vtkFFDInputChecks.h"
#include "vtkFFDMemory.h"
#include "vtkFFDPipelineKeys.h"
#include "vtkFFDStatistics.h"
#include "vtkFFDTetrahedralDeformer.h"

#include "vtkAOSDataArrayTemplate.h"
#include "vtkCellData.h"
#include "vtkDataArray.h"
#include "vtkDemandDrivenPipeline.h"
#include "vtkFieldData.h"
#include "vtkInformation.h"
#include "vtkInformationIntegerKey.h"
#include "vtkInformationObjectBaseKey.h"
#include "vtkInformationVector.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkSmartPointer.h"
#include "vtkUnstructuredGrid.h"

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <string>
#include <type_traits>

vtkStandardNewMacro(vtkFFDDeform);
vtkInformationKeyMacro(vtkFFDDeform, KEEP_OUTPUT_ON_DEVICE, Integer);
vtkInformationKeyMacro(vtkFFDDeform, DEVICE_OUTPUT, ObjectBase);

namespace
{
//------------------------------------------------------------------------------------------------------------
// The arrays of one role (points, normals, determinants) of the last outputs, so that an update writes into one
// that nothing else holds any more (then nobody can see it change: not the output, which the executive emptied
// before RequestData, nor a caller) instead of a new one: reuse spares the allocation and its page faults
// (BENCHMARKS.md measures them). Two are kept: the last output's, and
// the one before it where a caller held that one (a numpy view taken at every update): once the caller takes
// a view of the new output and lets the old one go, the next update writes into the old one.
struct KeptArrays
{
  vtkSmartPointer<vtkDataArray> Last, Spare;

  /// Last or Spare where it is of the class of `like` and that size and nothing else holds it, else nullptr.
  vtkSmartPointer<vtkDataArray> Free(vtkDataArray* like, int components, vtkIdType tuples) const
  {
    for (vtkDataArray* kept : { this->Last.Get(), this->Spare.Get() })
    {
      if (kept && kept->GetReferenceCount() == 1 && std::strcmp(kept->GetClassName(), like->GetClassName()) == 0 &&
        kept->GetNumberOfComponents() == components && kept->GetNumberOfTuples() == tuples)
      {
        kept->Modified();
        return vtkSmartPointer<vtkDataArray>(kept);
      }
    }
    return nullptr;
  }

  /// Keeps the array an update wrote (nullptr: none) and, where it is not the last one (a caller held that),
  /// the last one as the spare; where it is, nobody holds views of the outputs and no spare is kept.
  void Keep(const vtkSmartPointer<vtkDataArray>& array)
  {
    this->Spare = array == this->Last ? nullptr : this->Last;
    this->Last = array;
  }
};

// An output array of `tuples` x `components` values of the class of `like`: a free one of `kept`, else a new
// one, whose values are aligned to 64 bytes (a float or double array; a kept one is, being one such), so that
// the in-place pass may write them by non-temporal stores (ffd::StreamOutput()). Its pages are not written
// here: the evaluation's threads fault them in as they write their part.
vtkSmartPointer<vtkDataArray> OutputArray(const KeptArrays& kept, vtkDataArray* like, int components, vtkIdType tuples)
{
  if (vtkSmartPointer<vtkDataArray> free = kept.Free(like, components, tuples))
  {
    return free;
  }
  const auto array = vtk::TakeSmartPointer(like->NewInstance());
  array->SetNumberOfComponents(components);
  auto allocate = [&](auto* typed)
  {
    using Real = std::remove_pointer_t<decltype(typed->GetPointer(0))>;
    const vtkIdType values = tuples * components;
    const std::size_t bytes = (std::size_t(std::max<vtkIdType>(values, 1)) * sizeof(Real) + 63) / 64 * 64;
    if (void* memory = std::aligned_alloc(64, bytes))
    {
      typed->SetArray(static_cast<Real*>(memory), values, 0, vtkAbstractArray::VTK_DATA_ARRAY_ALIGNED_FREE);
      return true;
    }
    return false;
  };
  auto* floats = vtkAOSDataArrayTemplate<float>::FastDownCast(array);
  auto* doubles = vtkAOSDataArrayTemplate<double>::FastDownCast(array);
  if (!(floats && allocate(floats)) && !(doubles && allocate(doubles)))
  {
    array->SetNumberOfTuples(tuples);
  }
  return array;
}

// A copy of an input array in a given type, made again only when the input array changes: what an output kept
// on the device shows in place of its deformed points or normals. Being the filter's own, unchanged from update
// to update, it is uploaded to a renderer's vertex buffers once, not at every update, and no other renderer
// draws it.
struct InputCopy
{
  vtkSmartPointer<vtkDataArray> Copy;
  const vtkDataArray* Source = nullptr;
  vtkMTimeType SourceMTime = 0;

  vtkDataArray* Of(vtkDataArray* source, int type)
  {
    if (!this->Copy || source != this->Source || source->GetMTime() != this->SourceMTime ||
      this->Copy->GetDataType() != type)
    {
      this->Copy = vtk::TakeSmartPointer(vtkDataArray::CreateDataArray(type));
      this->Copy->DeepCopy(source);
      this->Copy->SetName(source->GetName());
      this->Source = source;
      this->SourceMTime = source->GetMTime();
    }
    return this->Copy;
  }
};
} // namespace

//------------------------------------------------------------------------------------------------------------
// The deformers of each lattice kind, the CUDA backend, and the arrays of the update being made.
struct vtkFFDDeform::vtkInternals
{
  vtkFFDGridDeformer Grid{ false }; // it evaluates: the displacements are read in the evaluation's precision
  vtkFFDTetrahedralDeformer Tetrahedra;
  vtkFFDCudaBackend Cuda;
  // The last outputs' arrays: the next update writes into those that nothing else holds any more (OutputArray()).
  KeptArrays KeptPoints, KeptNormals, KeptDeterminants;
  // The update's outputs (normals and determinants may be null: not asked for).
  vtkSmartPointer<vtkDataArray> Points, Normals, Determinants;
  // An output kept on the device (KEEP_OUTPUT_ON_DEVICE()): the device's handle, set by the CUDA backend, and the
  // input's copies that stand in for the deformed points and normals.
  bool OnDevice = false;
  vtkSmartPointer<vtkFFDDeviceOutput> DeviceOutput;
  InputCopy PointsOnDevice, NormalsOnDevice;
  // The output's vtkPoints of the copy, kept across updates: vtkPoints::SetData() marks its array modified,
  // which would upload it to the renderer's buffers at every update.
  vtkSmartPointer<vtkPoints> PointsOfCopy;
};

//------------------------------------------------------------------------------------------------------------
vtkFFDDeform::vtkFFDDeform()
  : OutsidePolicy(KEEP_POSITION)
  , Backend(AUTOMATIC)
  , LastBackendUsed("None")
  , TransformNormals(true)
  , ComputeJacobianDeterminant(false)
  , OutputPointsPrecision(vtkAlgorithm::DEFAULT_PRECISION)
  , NumberOfBindings(0)
  , Internals(new vtkInternals)
{
  this->SetNumberOfInputPorts(2);
}

vtkFFDDeform::~vtkFFDDeform() = default;

//------------------------------------------------------------------------------------------------------------
int vtkFFDDeform::FillInputPortInformation(int port, vtkInformation* info)
{
  if (port == 1)
  {
    info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkPointSet");
    return 1;
  }
  return this->Superclass::FillInputPortInformation(port, info);
}

//------------------------------------------------------------------------------------------------------------
vtkExecutive* vtkFFDDeform::CreateDefaultExecutive()
{
  return vtkFFDDeformExecutive::New();
}

vtkFFDDeform::vtkBinding vtkFFDDeform::GetBinding()
{
  return { this->Internals->Grid, this->Internals->Tetrahedra, this->Internals->Cuda };
}

vtkTypeUInt64 vtkFFDDeform::GetLatticeBytesUploaded() const
{
  return this->Internals->Cuda.GetLatticeBytesUploaded();
}

vtkTypeUInt64 vtkFFDDeform::GetBytesDownloaded() const
{
  return this->Internals->Cuda.GetBytesDownloaded();
}

//------------------------------------------------------------------------------------------------------------
vtkTypeBool vtkFFDDeform::ProcessRequest(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  // The inputs first: vtkPointSetAlgorithm makes the output, in the first request, without a word where input 0
  // is missing or not a vtkPointSet, and the executive's message on input 1 does not say what to connect.
  if (request->Has(vtkDemandDrivenPipeline::REQUEST_DATA_OBJECT()) &&
    !(vtkFFDCheckInput(this, inputVector[0], 0, "vtkPointSet", "the mesh",
        "SetInputConnection() to the mesh to deform (a vtkPolyData, vtkUnstructuredGrid or other vtkPointSet).") &&
      vtkFFDCheckInput(this, inputVector[1], 1, "vtkPointSet", "the lattice",
        "SetLatticeConnection() to the lattice, the output of vtkFFDBuildLattice or "
        "vtkFFDBuildTetrahedralLattice.")))
  {
    return vtkFFDEmptyOutputs(outputVector); // an earlier output would show what the inputs no longer give
  }
  // A lattice that varies in time (vtkFFDSimulateLattice) must make the mesh re-execute at each time.
  return vtkFFDCatchAllocationFailure(this, outputVector,
    [&]
    {
      return vtkFFDPipelineKeys::AnnounceTimes(
        this->Superclass::ProcessRequest(request, inputVector, outputVector), request, inputVector, 2, outputVector);
    });
}

//------------------------------------------------------------------------------------------------------------
int vtkFFDDeform::RequestData(vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkPointSet* input = vtkPointSet::GetData(inputVector[0]);
  vtkPointSet* lattice = vtkPointSet::GetData(inputVector[1]);
  vtkPointSet* output = vtkPointSet::GetData(outputVector);
  if (!input || !output || !lattice)
  {
    vtkErrorMacro("Input 0 (the mesh) and input 1 (the lattice) must be vtkPointSets.");
    return 0;
  }
  output->Initialize();
  output->GetInformation()->Remove(DEVICE_OUTPUT());
  const vtkFFDStatisticsOnReturn statistics(
    output, [this](vtkDataObject* out) { vtkFFDRecordText(out, "LastBackendUsed", this->LastBackendUsed); });
  vtkPoints* points = input->GetPoints();
  if (!points || points->GetNumberOfPoints() == 0)
  {
    output->CopyStructure(input);
    output->GetPointData()->PassData(input->GetPointData());
    output->GetCellData()->PassData(input->GetCellData());
    output->GetFieldData()->PassData(input->GetFieldData());
    return 1;
  }

  vtkUnstructuredGrid* tetrahedra =
    vtkFFDTetrahedralDeformer::IsTetrahedralLattice(lattice) ? vtkUnstructuredGrid::SafeDownCast(lattice) : nullptr;
  vtkInternals& internals = *this->Internals;
  const std::string problem =
    tetrahedra ? internals.Tetrahedra.SetLattice(tetrahedra) : internals.Grid.SetLattice(lattice);
  if (!problem.empty())
  {
    vtkErrorMacro(<< problem);
    return 0;
  }
  if (!tetrahedra && this->OutsidePolicy == EXTRAPOLATE)
  {
    vtkErrorMacro("The outside policy EXTRAPOLATE needs a tetrahedral lattice; a grid lattice keeps outside "
                  "points (KEEP_POSITION) or clamps them to its frame (CLAMP_TO_EDGE).");
    return 0;
  }

  vtkDataArray* normals = this->GetNormalsToTransform(input);
  const bool keepOnDevice = outputVector->GetInformationObject(0)->Get(KEEP_OUTPUT_ON_DEVICE()) != 0 &&
    this->Backend != CPU && !this->ComputeJacobianDeterminant;
  this->MakeOutputArrays(points, normals, keepOnDevice);
  const bool completed = tetrahedra ? this->DeformByTetrahedra(points, normals) : this->DeformByGrid(points, normals);
  if (completed) // else aborted: the output stays empty
  {
    this->FillOutput(input, output);
  }
  return 1;
}

//------------------------------------------------------------------------------------------------------------
vtkDataArray* vtkFFDDeform::GetNormalsToTransform(vtkPointSet* input)
{
  vtkDataArray* normals = this->TransformNormals ? input->GetPointData()->GetNormals() : nullptr;
  const vtkIdType count = input->GetNumberOfPoints();
  if (normals && (normals->GetNumberOfComponents() != 3 || normals->GetNumberOfTuples() != count))
  {
    vtkWarningMacro("The input's point normals have " << normals->GetNumberOfTuples() << " tuples of "
                                                      << normals->GetNumberOfComponents() << " components for " << count
                                                      << " points, not one of 3 per point; they are not transformed.");
    return nullptr;
  }
  return normals;
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDDeform::MakeOutputArrays(vtkPoints* points, vtkDataArray* normals, bool onDevice)
{
  vtkInternals& internals = *this->Internals;
  internals.Points = internals.Normals = internals.Determinants = nullptr; // an aborted update's
  internals.DeviceOutput = nullptr;
  internals.OnDevice = onDevice;
  const vtkIdType count = points->GetNumberOfPoints();
  const bool useDouble = this->OutputPointsPrecision == vtkAlgorithm::DOUBLE_PRECISION ||
    (this->OutputPointsPrecision == vtkAlgorithm::DEFAULT_PRECISION && points->GetDataType() == VTK_DOUBLE);
  if (onDevice)
  {
    internals.Points = internals.PointsOnDevice.Of(points->GetData(), useDouble ? VTK_DOUBLE : VTK_FLOAT);
    internals.Normals = normals ? internals.NormalsOnDevice.Of(normals, normals->GetDataType()) : nullptr;
    return;
  }
  const auto real = vtk::TakeSmartPointer(vtkDataArray::CreateDataArray(useDouble ? VTK_DOUBLE : VTK_FLOAT));
  internals.Points = OutputArray(internals.KeptPoints, real, 3, count);
  if (normals)
  {
    internals.Normals = OutputArray(internals.KeptNormals, normals, 3, count);
    internals.Normals->SetName(normals->GetName());
  }
  if (this->ComputeJacobianDeterminant)
  {
    internals.Determinants = OutputArray(internals.KeptDeterminants, real, 1, count);
    internals.Determinants->SetName(JacobianDeterminantArrayName());
  }
}

//------------------------------------------------------------------------------------------------------------
bool vtkFFDDeform::DeformedOnCuda(const std::function<bool(std::string& why)>& deform)
{
  std::string why;
  if (this->Backend == CPU)
  {
    return false;
  }
  if (!vtkFFDCudaBackend::IsAvailable(why))
  {
    if (this->Backend == CUDA)
    {
      vtkWarningMacro("The CUDA backend cannot run (" << why << "); deforming on the CPU.");
    }
    return false;
  }
  if (!deform(why))
  {
    vtkWarningMacro("The CUDA backend failed (" << why << "); deforming on the CPU.");
    return false;
  }
  this->LastBackendUsed = "CUDA";
  this->UpdateProgress(1.0);
  return true;
}

//------------------------------------------------------------------------------------------------------------
bool vtkFFDDeform::DeformByGrid(vtkPoints* points, vtkDataArray* normals)
{
  vtkInternals& internals = *this->Internals;
  vtkFFDGridDeformer& grid = internals.Grid;
  const vtkFFDGridLattice& lattice = grid.GetLattice();
  bool rebound = false;
  vtkSmartPointer<vtkFFDDeviceOutput>* keptOnDevice = internals.OnDevice ? &internals.DeviceOutput : nullptr;
  const bool onCuda = this->DeformedOnCuda(
    [&](std::string& why)
    {
      const vtkFFDBindingKey key = grid.KeyOf(points, this->OutsidePolicy);
      if (!lattice.Sparse)
      {
        return internals.Cuda.DeformGrid(grid, key, points, normals, internals.Points, internals.Normals,
          internals.Determinants, keptOnDevice, rebound, why);
      }
      // A sparse lattice's voxels are looked up on the host: the points are bound there, then uploaded.
      bool boundOnHost = false;
      if (!grid.Bind(points, this->OutsidePolicy, this, 0.0, 0.5, boundOnHost))
      {
        why = "aborted";
        return false;
      }
      this->NumberOfBindings += boundOnHost ? 1 : 0;
      const bool deformed = internals.Cuda.DeformGrid(grid, key, points, normals, internals.Points, internals.Normals,
        internals.Determinants, keptOnDevice, rebound, why);
      rebound = false; // the upload of the host's binding, counted above
      return deformed;
    });
  this->NumberOfBindings += rebound ? 1 : 0; // on the device, also where it failed after binding
  if (onCuda)
  {
    return true;
  }
  if (internals.OnDevice) // the CPU deforms: into arrays of its own, not the input's copies
  {
    this->MakeOutputArrays(points, normals, false);
  }
  if (!grid.Bind(points, this->OutsidePolicy, this, 0.0, 0.5, rebound))
  {
    return false;
  }
  this->NumberOfBindings += rebound ? 1 : 0;
  this->UpdateProgress(0.5);
  if (!grid.Evaluate(points, normals, internals.Points, internals.Normals, internals.Determinants, this, 0.5, 1.0))
  {
    return false;
  }
  this->LastBackendUsed = "CPU";
  return true;
}

//------------------------------------------------------------------------------------------------------------
bool vtkFFDDeform::DeformByTetrahedra(vtkPoints* points, vtkDataArray* normals)
{
  // The binding needs VTK's cell locator: on the CPU for either backend, then cached.
  vtkInternals& internals = *this->Internals;
  vtkFFDTetrahedralDeformer& tetrahedra = internals.Tetrahedra;
  bool rebound = false;
  if (!tetrahedra.Bind(points, this->OutsidePolicy, this, 0.0, 0.5, rebound))
  {
    return false;
  }
  if (rebound)
  {
    ++this->NumberOfBindings;
    if (tetrahedra.GetNumberOfDegenerateTetrahedra() > 0)
    {
      vtkWarningMacro(<< tetrahedra.GetNumberOfDegenerateTetrahedra() << " of " << tetrahedra.GetNumberOfTetrahedra()
                      << " tetrahedra of the lattice have no volume (the first is cell "
                      << tetrahedra.GetFirstDegenerateTetrahedron()
                      << "); they are skipped: points in them are bound to a neighbour or follow the "
                         "outside policy.");
    }
  }
  if (internals.OnDevice && tetrahedra.HasClampedPoints()) // they are moved on the host
  {
    this->MakeOutputArrays(points, normals, false);
  }
  if (this->DeformedOnCuda(
        [&](std::string& why)
        {
          return internals.Cuda.DeformTetrahedra(tetrahedra, points, normals, internals.Points, internals.Normals,
            internals.Determinants, internals.OnDevice ? &internals.DeviceOutput : nullptr, why);
        }))
  {
    return true;
  }
  if (internals.OnDevice)
  {
    this->MakeOutputArrays(points, normals, false);
  }
  if (!tetrahedra.Evaluate(
        points, normals, internals.Points, internals.Normals, internals.Determinants, this, 0.5, 1.0))
  {
    return false;
  }
  this->LastBackendUsed = "CPU";
  return true;
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDDeform::FillOutput(vtkPointSet* input, vtkPointSet* output)
{
  vtkInternals& internals = *this->Internals;
  vtkSmartPointer<vtkPoints> outPoints = internals.OnDevice ? internals.PointsOfCopy : nullptr;
  if (!outPoints || outPoints->GetData() != internals.Points)
  {
    outPoints = vtkSmartPointer<vtkPoints>::New();
    outPoints->SetData(internals.Points);
  }
  internals.PointsOfCopy = internals.OnDevice ? outPoints : nullptr;
  output->CopyStructure(input);
  output->SetPoints(outPoints);
  output->GetPointData()->PassData(input->GetPointData());
  output->GetCellData()->PassData(input->GetCellData());
  // Field data too: a lattice deformed by a coarser one (hierarchical FFD) keeps its frame and divisions.
  output->GetFieldData()->PassData(input->GetFieldData());
  if (internals.Normals)
  {
    output->GetPointData()->SetNormals(internals.Normals);
  }
  // Cell normals cannot follow a non-affine deformation; stale ones would be silently wrong.
  output->GetCellData()->SetNormals(nullptr);
  if (internals.Determinants)
  {
    output->GetPointData()->AddArray(internals.Determinants);
  }
  if (internals.OnDevice)
  {
    output->GetInformation()->Set(DEVICE_OUTPUT(), internals.DeviceOutput);
    internals.Points = internals.Normals = nullptr;
    internals.DeviceOutput = nullptr;
    return;
  }
  internals.KeptPoints.Keep(internals.Points);
  internals.KeptNormals.Keep(internals.Normals);
  internals.KeptDeterminants.Keep(internals.Determinants);
  // Only the output and the kept arrays hold them now: a caller's view is what keeps them from reuse.
  internals.Points = internals.Normals = internals.Determinants = nullptr;
}

//------------------------------------------------------------------------------------------------------------
const char* vtkFFDDeform::GetOutsidePolicyAsString()
{
  switch (this->OutsidePolicy)
  {
    case CLAMP_TO_EDGE:
      return "ClampToEdge";
    case EXTRAPOLATE:
      return "Extrapolate";
    default:
      return "KeepPosition";
  }
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDDeform::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "OutsidePolicy: " << this->GetOutsidePolicyAsString() << "\n";
  os << indent << "Backend: " << (this->Backend == CPU ? "CPU" : (this->Backend == CUDA ? "CUDA" : "Automatic"))
     << "\n";
  os << indent << "LastBackendUsed: " << this->LastBackendUsed << "\n";
  os << indent << "TransformNormals: " << (this->TransformNormals ? "On" : "Off") << "\n";
  os << indent << "ComputeJacobianDeterminant: " << (this->ComputeJacobianDeterminant ? "On" : "Off") << "\n";
  os << indent << "OutputPointsPrecision: " << this->OutputPointsPrecision << "\n";
  os << indent << "NumberOfBindings: " << this->NumberOfBindings << "\n";
}
