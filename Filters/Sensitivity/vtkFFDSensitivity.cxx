// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDSensitivity.h"

#include "vtkFFDCudaBackend.h"
#include "vtkFFDGridAdjoint.h"
#include "vtkFFDGridDeformer.h"
#include "vtkFFDGroupedIds.h"
#include "vtkFFDInputChecks.h"
#include "vtkFFDMemory.h"
#include "vtkFFDTetrahedralDeformer.h"

#include "vtkAOSDataArrayTemplate.h"
#include "vtkArrayDispatch.h"
#include "vtkDataArray.h"
#include "vtkDataArrayRange.h"
#include "vtkDoubleArray.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkSMPTools.h"
#include "vtkSmartPointer.h"
#include "vtkUnstructuredGrid.h"

#include <algorithm>
#include <cmath>
#include <vector>

vtkStandardNewMacro(vtkFFDSensitivity);

namespace
{
// The 3-component values of an array as float64, point after point (typed: no virtual call a value).
std::vector<double> AsDoubles(vtkDataArray* array)
{
  std::vector<double> values(3 * static_cast<std::size_t>(array->GetNumberOfTuples()));
  auto copy = [&](auto* typed)
  {
    const auto range = vtk::DataArrayValueRange<3>(typed);
    vtkSMPTools::For(0, vtkIdType(values.size()),
      [&](vtkIdType begin, vtkIdType end)
      { std::copy(range.begin() + begin, range.begin() + end, values.begin() + begin); });
  };
  if (!vtkArrayDispatch::Dispatch::Execute(array, copy))
  {
    copy(array);
  }
  return values;
}

// The gradient's values as contiguous float64 triples: the array's own where it holds them so (the usual
// vtkDoubleArray), else AsDoubles() into `copy`.
const double* GradientValues(vtkDataArray* array, std::vector<double>& copy)
{
  if (auto* doubles = vtkAOSDataArrayTemplate<double>::FastDownCast(array))
  {
    return doubles->GetPointer(0);
  }
  copy = AsDoubles(array);
  return copy.data();
}

// sums[3 c ..] += w g: a point's term for control point c.
inline void AddTerm(double* sums, int controlPoint, double w, const double* g)
{
  double* target = sums + 3 * std::size_t(controlPoint);
  target[0] += w * g[0];
  target[1] += w * g[1];
  target[2] += w * g[2];
}

// W^T g for a tetrahedral lattice. A point moves by its tetrahedron's barycentric weights at the point, or, clamped
// to the control mesh, at its nearest point there (as ApplyClampedPoints()). Each tetrahedron sums its points'
// terms in increasing id (in parallel over tetrahedra), then each node adds its tetrahedra's sums in increasing
// tetrahedron order (in parallel over nodes): one order whatever the threads.
void TetrahedralSums(
  const vtkFFDTetrahedralDeformer& tetrahedra, const std::vector<double>& x, const double* g, std::vector<double>& out)
{
  // Each weighted point, with where its weights are taken (the point, or its nearest point of the mesh).
  std::vector<int> cellOf = tetrahedra.GetCellOfPoint();
  std::vector<ffd::Vec3<double>> at(cellOf.size());
  for (std::size_t p = 0; p < cellOf.size(); ++p)
  {
    at[p] = { x[3 * p], x[3 * p + 1], x[3 * p + 2] };
  }
  for (const vtkFFDTetrahedralDeformer::ClampedPoint& clamped : tetrahedra.GetClampedPoints())
  {
    cellOf[clamped.Point] = clamped.Tetrahedron;
    at[clamped.Point] = clamped.Closest;
  }
  const vtkFFDGroupedIds byTetrahedron(cellOf);
  const vtkIdType count = tetrahedra.GetNumberOfTetrahedra();
  std::vector<double> corners(12 * std::size_t(count), 0.0); // per tetrahedron, 3 per node
  vtkSMPTools::For(0, std::min<vtkIdType>(count, byTetrahedron.Groups()),
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType t = begin; t < end; ++t)
      {
        double* sums = &corners[12 * std::size_t(t)];
        for (vtkIdType o = byTetrahedron.Start[t]; o < byTetrahedron.Start[t + 1]; ++o)
        {
          const std::size_t p = std::size_t(byTetrahedron.Order[o]);
          const ffd::Vec3<double> stu = tetrahedra.GetFrames()[t].ToParametric(at[p]);
          const double w[4] = { 1.0 - stu.x - stu.y - stu.z, stu.x, stu.y, stu.z };
          for (int k = 0; k < 4; ++k)
          {
            AddTerm(sums, k, w[k], &g[3 * p]);
          }
        }
      }
    });
  // The node's corners (4 t + i), in increasing tetrahedron order.
  const std::size_t nodeCount = out.size() / 3;
  const vtkFFDGroupedIds byNode(tetrahedra.GetNodes(), nodeCount);
  vtkSMPTools::For(0, vtkIdType(nodeCount),
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType n = begin; n < end; ++n)
      {
        for (vtkIdType k = byNode.Start[n]; k < byNode.Start[n + 1]; ++k)
        {
          for (int c = 0; c < 3; ++c)
          {
            out[3 * std::size_t(n) + c] += corners[3 * std::size_t(byNode.Order[k]) + c];
          }
        }
      }
    });
}
} // namespace

//------------------------------------------------------------------------------------------------------------
struct vtkFFDSensitivity::vtkInternals
{
  vtkNew<vtkFFDDeform> Own; // whose binding the sums use without a Deform
  vtkFFDGridAdjoint Grid;   // the CPU's plan of a grid's sums, per binding
};

vtkFFDSensitivity::vtkFFDSensitivity()
  : OutsidePolicy(vtkFFDDeform::KEEP_POSITION)
  , Backend(vtkFFDDeform::AUTOMATIC)
  , LastBackendUsed("None")
  , SensitivityArrayName(nullptr)
  , Deform(nullptr)
  , NumberOfBindings(0)
  , Internals(new vtkInternals)
{
  this->SetNumberOfInputPorts(2);
  this->SetSensitivityArrayName("Sensitivity");
}

vtkFFDSensitivity::~vtkFFDSensitivity()
{
  this->SetSensitivityArrayName(nullptr);
  this->SetDeform(nullptr);
}

vtkCxxSetObjectMacro(vtkFFDSensitivity, Deform, vtkFFDDeform);

vtkFFDDeform* vtkFFDSensitivity::Engine()
{
  return this->Deform ? this->Deform : this->Internals->Own.Get();
}

int vtkFFDSensitivity::EngineOutsidePolicy() const
{
  return this->Deform ? this->Deform->GetOutsidePolicy() : this->OutsidePolicy;
}

int vtkFFDSensitivity::FillInputPortInformation(int port, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkPointSet");
  return port <= 1 ? 1 : 0;
}

vtkTypeBool vtkFFDSensitivity::ProcessRequest(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  return vtkFFDCatchAllocationFailure(
    this, outputVector, [&] { return this->Superclass::ProcessRequest(request, inputVector, outputVector); });
}

// The output is a lattice: of input 1's type.
int vtkFFDSensitivity::RequestDataObject(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  if (!(vtkFFDCheckInput(this, inputVector[0], 0, "vtkPointSet", "the mesh",
          "SetInputConnection() to the mesh at rest (vtkFFDDeform's input 0), with the gradient as a point array.") &&
        vtkFFDCheckInput(this, inputVector[1], 1, "vtkPointSet", "the lattice",
          "SetLatticeConnection() to the lattice that vtkFFDDeform deforms the mesh with.")))
  {
    return vtkFFDEmptyOutputs(outputVector);
  }
  vtkDataObject* lattice = vtkDataObject::GetData(inputVector[1]);
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  vtkDataObject* output = outInfo->Get(vtkDataObject::DATA_OBJECT());
  if (!output || !output->IsA(lattice->GetClassName()))
  {
    auto made = vtk::TakeSmartPointer(lattice->NewInstance());
    outInfo->Set(vtkDataObject::DATA_OBJECT(), made);
  }
  return 1;
}

//------------------------------------------------------------------------------------------------------------
int vtkFFDSensitivity::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkPointSet* mesh = vtkPointSet::GetData(inputVector[0]);
  vtkPointSet* lattice = vtkPointSet::GetData(inputVector[1]);
  vtkPointSet* output = vtkPointSet::GetData(outputVector);
  if (!mesh || !lattice || !output)
  {
    vtkErrorMacro("Input 0 (the mesh) and input 1 (the lattice) must be vtkPointSets.");
    return 0;
  }
  output->ShallowCopy(lattice);
  const vtkIdType count = mesh->GetNumberOfPoints();
  vtkDataArray* gradient = this->GetInputArrayToProcess(0, inputVector);
  if (count > 0 && (!gradient || gradient->GetNumberOfComponents() != 3 || gradient->GetNumberOfTuples() != count))
  {
    vtkErrorMacro("The mesh needs the objective's gradient as a point array of 3 components, one tuple per point ("
      << count << "), named by SetInputArrayToProcess(0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, name); "
      << (gradient ? "the one named has " + std::to_string(gradient->GetNumberOfTuples()) + " tuples of " +
               std::to_string(gradient->GetNumberOfComponents()) + " components."
                   : std::string("none is named or found.")));
    output->Initialize();
    return 0;
  }
  std::vector<double> sums(3 * std::size_t(lattice->GetNumberOfPoints()), 0.0);
  const bool completed = vtkFFDTetrahedralDeformer::IsTetrahedralLattice(lattice)
    ? this->SumTetrahedral(mesh, vtkUnstructuredGrid::SafeDownCast(lattice), gradient, sums)
    : this->SumGrid(mesh, lattice, gradient, sums);
  if (!completed) // an error, or aborted
  {
    output->Initialize();
    return 1;
  }
  vtkNew<vtkDoubleArray> sensitivity;
  sensitivity->SetName(this->SensitivityArrayName ? this->SensitivityArrayName : "Sensitivity");
  sensitivity->SetNumberOfComponents(3);
  sensitivity->SetNumberOfTuples(lattice->GetNumberOfPoints());
  std::copy(sums.begin(), sums.end(), sensitivity->GetPointer(0));
  output->GetPointData()->AddArray(sensitivity);
  this->UpdateProgress(1.0);
  return 1;
}

//------------------------------------------------------------------------------------------------------------
bool vtkFFDSensitivity::SumGrid(
  vtkPointSet* mesh, vtkPointSet* lattice, vtkDataArray* gradient, std::vector<double>& sums)
{
  vtkFFDGridDeformer& grid = this->Engine()->GetBinding().Grid;
  const int policy = this->EngineOutsidePolicy();
  const std::string problem = grid.SetLattice(lattice);
  if (!problem.empty() || policy == vtkFFDDeform::EXTRAPOLATE)
  {
    vtkErrorMacro(<< (problem.empty() ? "The outside policy EXTRAPOLATE needs a tetrahedral lattice." : problem));
    return false;
  }
  if (mesh->GetNumberOfPoints() == 0)
  {
    return true;
  }
  std::vector<double> copy;
  const double* g = GradientValues(gradient, copy);
  if (this->SumGridOnCuda(mesh->GetPoints(), g, sums))
  {
    return true;
  }
  bool rebound = false;
  if (!grid.Bind(mesh->GetPoints(), policy, this, 0.0, 0.5, rebound))
  {
    return false;
  }
  this->NumberOfBindings += rebound ? 1 : 0;
  if (!this->Internals->Grid.Sum(grid, grid.KeyOf(mesh->GetPoints(), policy), mesh->GetPoints(), g, sums.data(), this))
  {
    return false;
  }
  this->LastBackendUsed = "CPU";
  return true;
}

bool vtkFFDSensitivity::CudaAllowed()
{
  const int backend = this->Deform ? this->Deform->GetBackend() : this->Backend;
  std::string why;
  if (backend == vtkFFDDeform::CPU || !vtkFFDCudaBackend::IsAvailable(why))
  {
    if (backend == vtkFFDDeform::CUDA)
    {
      vtkWarningMacro("The CUDA backend cannot run (" << why << "); summing on the CPU.");
    }
    return false;
  }
  return true;
}

int vtkFFDSensitivity::DevicePrecision(vtkPoints* points) const
{
  const int precision = this->Deform ? this->Deform->GetOutputPointsPrecision() : vtkAlgorithm::DEFAULT_PRECISION;
  return precision == vtkAlgorithm::DOUBLE_PRECISION ||
      (precision == vtkAlgorithm::DEFAULT_PRECISION && points->GetDataType() == VTK_DOUBLE)
    ? VTK_DOUBLE
    : VTK_FLOAT;
}

bool vtkFFDSensitivity::SumGridOnCuda(vtkPoints* points, const double* g, std::vector<double>& sums)
{
  if (!this->CudaAllowed())
  {
    return false;
  }
  vtkFFDDeform::vtkBinding binding = this->Engine()->GetBinding();
  const int policy = this->EngineOutsidePolicy();
  bool rebound = false;
  // A sparse lattice's voxels are looked up on the host: its binding is the host's, uploaded.
  if (binding.Grid.GetLattice().Sparse && !binding.Grid.Bind(points, policy, this, 0.0, 0.5, rebound))
  {
    return false;
  }
  bool bound = false;
  std::string why;
  const bool summed = binding.Cuda.AdjointGrid(binding.Grid, binding.Grid.KeyOf(points, policy), points,
    this->DevicePrecision(points), g, sums.data(), bound, why);
  this->NumberOfBindings += (rebound || (bound && !binding.Grid.GetLattice().Sparse)) ? 1 : 0;
  if (!summed)
  {
    vtkWarningMacro("The CUDA backend failed (" << why << "); summing on the CPU.");
    return false;
  }
  this->LastBackendUsed = "CUDA";
  return true;
}

bool vtkFFDSensitivity::SumTetrahedral(
  vtkPointSet* mesh, vtkUnstructuredGrid* lattice, vtkDataArray* gradient, std::vector<double>& sums)
{
  vtkFFDTetrahedralDeformer& tetrahedra = this->Engine()->GetBinding().Tetrahedra;
  const std::string problem = tetrahedra.SetLattice(lattice);
  if (!problem.empty())
  {
    vtkErrorMacro(<< problem);
    return false;
  }
  if (mesh->GetNumberOfPoints() == 0)
  {
    return true;
  }
  bool rebound = false;
  if (!tetrahedra.Bind(mesh->GetPoints(), this->EngineOutsidePolicy(), this, 0.0, 0.5, rebound))
  {
    return false;
  }
  this->NumberOfBindings += rebound ? 1 : 0;
  std::vector<double> copy;
  const double* g = GradientValues(gradient, copy);
  // The points clamped to the control mesh take their nearest point's weights, which the host holds.
  if (!tetrahedra.HasClampedPoints() && this->CudaAllowed())
  {
    std::string why;
    if (this->Engine()->GetBinding().Cuda.AdjointTetrahedra(
          tetrahedra, mesh->GetPoints(), this->DevicePrecision(mesh->GetPoints()), g, sums.data(), why))
    {
      this->LastBackendUsed = "CUDA";
      return true;
    }
    vtkWarningMacro("The CUDA backend failed (" << why << "); summing on the CPU.");
  }
  std::fill(sums.begin(), sums.end(), 0.0);
  TetrahedralSums(tetrahedra, AsDoubles(mesh->GetPoints()->GetData()), g, sums);
  this->LastBackendUsed = "CPU";
  return true;
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDSensitivity::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "OutsidePolicy: " << this->OutsidePolicy << "\n";
  os << indent << "SensitivityArrayName: " << (this->SensitivityArrayName ? this->SensitivityArrayName : "(none)")
     << "\n";
  os << indent << "Backend: " << this->Backend << "\n";
  os << indent << "LastBackendUsed: " << this->LastBackendUsed << "\n";
  os << indent << "Deform: " << static_cast<void*>(this->Deform) << "\n";
  os << indent << "NumberOfBindings: " << this->NumberOfBindings << "\n";
}
