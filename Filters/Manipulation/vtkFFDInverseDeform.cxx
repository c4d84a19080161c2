// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDInverseDeform.h"

#include "vtkCellData.h"
#include "vtkDoubleArray.h"
#include "vtkFFDDataContract.h"
#include "vtkFFDDeform.h"
#include "vtkFFDGridDeformer.h"
#include "vtkFFDGridInversion.h"
#include "vtkFFDInputChecks.h"
#include "vtkFFDLatticeDisplacements.h"
#include "vtkFFDLatticeQueries.h"
#include "vtkFFDMemory.h"
#include "vtkFFDPipelineKeys.h"
#include "vtkFFDSparseLattice.h"
#include "vtkFFDStatistics.h"
#include "vtkFFDTetrahedralDeformer.h"
#include "vtkIdList.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkSMPTools.h"
#include "vtkUnsignedCharArray.h"
#include "vtkUnstructuredGrid.h"

#include "FFDInverse.h"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

vtkStandardNewMacro(vtkFFDInverseDeform);

namespace
{
using ffd::InverseStatus;

// The signed volume's sign of each tetrahedron of `tetrahedra` whose corners are `corners`.
std::vector<int> Orientations(vtkUnstructuredGrid* tetrahedra, vtkDataArray* corners)
{
  std::vector<int> signs(tetrahedra->GetNumberOfCells());
  vtkNew<vtkIdList> ids;
  for (vtkIdType t = 0; t < tetrahedra->GetNumberOfCells(); ++t)
  {
    tetrahedra->GetCellPoints(t, ids);
    double c[4][3];
    for (int i = 0; i < 4; ++i)
    {
      corners->GetTuple(ids->GetId(i), c[i]);
    }
    const ffd::Vec3<double> a = ffd::Vec3<double>::From(c[0]);
    const double volume = ffd::Dot(ffd::Vec3<double>::From(c[1]) - a,
      ffd::Cross(ffd::Vec3<double>::From(c[2]) - a, ffd::Vec3<double>::From(c[3]) - a));
    signs[t] = (volume > 0) - (volume < 0);
  }
  return signs;
}

// Tetrahedral lattices: the lattice with its points and rest positions exchanged deforms y to x exactly, through
// vtkFFDTetrahedralDeformer; a point in a tetrahedron turned inside out (or flattened) is folded.
bool InvertByTetrahedra(vtkAlgorithm* self, vtkUnstructuredGrid* lattice, vtkPoints* points, vtkDataArray* normals,
  const vtkFFDInverseOutput& out, std::string& problem)
{
  vtkDataArray* rest = lattice->GetPointData()->GetArray(vtkFFDDataContract::RestPositionArrayName());
  if (!rest || rest->GetNumberOfComponents() != 3 || rest->GetNumberOfTuples() != lattice->GetNumberOfPoints() ||
    !lattice->GetPoints())
  {
    problem = "The tetrahedral lattice has no RestPosition point array of 3 components per point.";
    return false;
  }
  // Checked before the exchange below turns both into doubles.
  problem = vtkFFDCheckLatticePrecision(lattice, rest, "The tetrahedral lattice");
  if (!problem.empty())
  {
    return false;
  }
  vtkNew<vtkUnstructuredGrid> exchanged;
  exchanged->ShallowCopy(lattice);
  vtkNew<vtkPoints> restPoints;
  restPoints->SetDataTypeToDouble();
  restPoints->GetData()->DeepCopy(rest);
  vtkNew<vtkDoubleArray> deformed;
  deformed->DeepCopy(lattice->GetPoints()->GetData());
  deformed->SetName(vtkFFDDataContract::RestPositionArrayName());
  exchanged->SetPoints(restPoints);
  exchanged->GetPointData()->AddArray(deformed);

  vtkFFDTetrahedralDeformer deformer;
  problem = deformer.SetLattice(exchanged);
  bool rebound = false;
  if (!problem.empty() || !deformer.Bind(points, vtkFFDTetrahedralDeformer::KEEP_POSITION, self, 0.0, 0.5, rebound))
  {
    return false;
  }
  const vtkIdType n = points->GetNumberOfPoints();
  vtkNew<vtkDoubleArray> outPoints;
  outPoints->SetNumberOfComponents(3);
  outPoints->SetArray(out.Points, 3 * n, 1);
  vtkNew<vtkDoubleArray> outNormals;
  outNormals->SetNumberOfComponents(3);
  if (out.Normals)
  {
    outNormals->SetArray(out.Normals, 3 * n, 1);
  }
  if (!deformer.Evaluate(points, out.Normals ? normals : nullptr, outPoints, out.Normals ? outNormals.Get() : nullptr,
        nullptr, self, 0.5, 1.0))
  {
    return false;
  }
  const std::vector<int> before = Orientations(lattice, rest);
  const std::vector<int> after = Orientations(lattice, lattice->GetPoints()->GetData());
  const std::vector<int>& cellOf = deformer.GetCellOfPoint();
  for (vtkIdType p = 0; p < n; ++p)
  {
    const int t = cellOf[p];
    out.Status[p] =
      static_cast<unsigned char>(t >= 0 && before[t] != after[t] ? InverseStatus::Folded : InverseStatus::Converged);
  }
  return true;
}

/// The input's point normals where they are 3-component with one tuple a point, else null: none to invert.
vtkDataArray* PointNormals(vtkPointSet* input, vtkIdType n)
{
  vtkDataArray* normals = input->GetPointData()->GetNormals();
  return normals && normals->GetNumberOfComponents() == 3 && normals->GetNumberOfTuples() == n ? normals : nullptr;
}

/// The arrays the inversion writes: rest positions, rest normals (only where the input has normals) and status.
struct RestArrays
{
  vtkNew<vtkDoubleArray> Points;
  vtkSmartPointer<vtkDoubleArray> Normals;
  vtkNew<vtkUnsignedCharArray> Status;

  RestArrays(vtkIdType n, vtkDataArray* normals)
  {
    this->Points->SetNumberOfComponents(3);
    this->Points->SetNumberOfTuples(n);
    if (normals)
    {
      this->Normals = vtkSmartPointer<vtkDoubleArray>::New();
      this->Normals->SetName(normals->GetName());
      this->Normals->SetNumberOfComponents(3);
      this->Normals->SetNumberOfTuples(n);
    }
    this->Status->SetName(vtkFFDInverseDeform::InverseStatusArrayName());
    this->Status->SetNumberOfTuples(n);
  }

  vtkFFDInverseOutput Output() const
  {
    return { this->Points->GetPointer(0), this->Normals ? this->Normals->GetPointer(0) : nullptr,
      this->Status->GetPointer(0) };
  }
};
} // namespace

//------------------------------------------------------------------------------------------------------------
vtkFFDInverseDeform::vtkFFDInverseDeform()
  : Tolerance(1e-12)
  , MaximumNumberOfIterations(50)
  , OutputPointsPrecision(DEFAULT_PRECISION)
  , NumberOfFoldedPoints(0)
  , NumberOfUnconvergedPoints(0)
{
  this->SetNumberOfInputPorts(2);
}

//------------------------------------------------------------------------------------------------------------
vtkFFDInverseDeform::~vtkFFDInverseDeform() = default;

//------------------------------------------------------------------------------------------------------------
int vtkFFDInverseDeform::FillInputPortInformation(int port, vtkInformation* info)
{
  if (port == 1)
  {
    info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkPointSet");
    return 1;
  }
  return this->Superclass::FillInputPortInformation(port, info);
}

//------------------------------------------------------------------------------------------------------------
vtkTypeBool vtkFFDInverseDeform::ProcessRequest(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  // A lattice that varies in time (vtkFFDSimulateLattice) must make the mesh re-execute at each time.
  return vtkFFDCatchAllocationFailure(this, outputVector,
    [&]
    {
      return vtkFFDPipelineKeys::AnnounceTimes(
        this->Superclass::ProcessRequest(request, inputVector, outputVector), request, inputVector, 2, outputVector);
    });
}

//------------------------------------------------------------------------------------------------------------
int vtkFFDInverseDeform::RequestDataObject(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  if (!(vtkFFDCheckInput(this, inputVector[0], 0, "vtkPointSet", "the deformed points",
          "SetInputConnection() to the deformed mesh or points (a vtkPolyData, vtkUnstructuredGrid or other "
          "vtkPointSet).") &&
        vtkFFDCheckInput(this, inputVector[1], 1, "vtkPointSet", "the lattice",
          "SetLatticeConnection() to the lattice that deformed them.")))
  {
    return vtkFFDEmptyOutputs(outputVector);
  }
  return this->Superclass::RequestDataObject(request, inputVector, outputVector);
}

//------------------------------------------------------------------------------------------------------------
int vtkFFDInverseDeform::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkPointSet* input = vtkPointSet::GetData(inputVector[0]);
  vtkPointSet* lattice = vtkPointSet::GetData(inputVector[1]);
  vtkPointSet* output = vtkPointSet::GetData(outputVector);
  this->NumberOfFoldedPoints = this->NumberOfUnconvergedPoints = 0;
  const vtkFFDStatisticsOnReturn statistics(output,
    [this](vtkDataObject* out)
    {
      vtkFFDRecordCount(out, "NumberOfFoldedPoints", this->NumberOfFoldedPoints);
      vtkFFDRecordCount(out, "NumberOfUnconvergedPoints", this->NumberOfUnconvergedPoints);
    });
  if (!input || !output)
  {
    vtkErrorMacro("Input 0 must be a vtkPointSet.");
    return 0;
  }
  output->Initialize();
  if (!this->CheckSettings())
  {
    return 0;
  }
  vtkPoints* points = input->GetPoints();
  if (!points || points->GetNumberOfPoints() == 0)
  {
    output->ShallowCopy(input);
    return 1;
  }
  if (!lattice)
  {
    vtkErrorMacro("No lattice: SetLatticeConnection() (input 1) to the lattice that deformed the points.");
    return 0;
  }

  vtkDataArray* normals = PointNormals(input, points->GetNumberOfPoints());
  const RestArrays rest(points->GetNumberOfPoints(), normals);
  std::string problem;
  const bool completed = this->Invert(lattice, points, normals, rest.Output(), problem);
  if (!problem.empty())
  {
    vtkErrorMacro(<< problem);
    return 0;
  }
  if (!completed) // aborted: the output stays empty
  {
    return 1;
  }
  this->CountUnreliablePoints(rest.Status);
  this->FillOutput(input, rest.Points, rest.Normals, rest.Status, output);
  return 1;
}

//------------------------------------------------------------------------------------------------------------
bool vtkFFDInverseDeform::CheckSettings()
{
  if (!std::isfinite(this->Tolerance) || this->Tolerance < 0)
  {
    vtkErrorMacro(<< "Tolerance is " << this->Tolerance
                  << ": give SetTolerance() a finite number >= 0 (default 1e-12, relative to the frame's diagonal).");
    return false;
  }
  if (this->MaximumNumberOfIterations < 1)
  {
    vtkErrorMacro(<< "MaximumNumberOfIterations is " << this->MaximumNumberOfIterations
                  << ": give SetMaximumNumberOfIterations() 1 or more (default 50).");
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------------------------------------
bool vtkFFDInverseDeform::Invert(
  vtkPointSet* lattice, vtkPoints* points, vtkDataArray* normals, const vtkFFDInverseOutput& out, std::string& problem)
{
  if (vtkFFDTetrahedralDeformer::IsTetrahedralLattice(lattice))
  {
    return InvertByTetrahedra(this, vtkUnstructuredGrid::SafeDownCast(lattice), points, normals, out, problem);
  }
  vtkFFDGridDeformer deformer;
  problem = deformer.SetLattice(lattice);
  return problem.empty() &&
    vtkFFDInvertByGrid(this, deformer, points, normals, this->Tolerance, this->MaximumNumberOfIterations, out);
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDInverseDeform::CountUnreliablePoints(vtkUnsignedCharArray* status)
{
  const vtkIdType n = status->GetNumberOfTuples();
  const unsigned char* s = status->GetPointer(0);
  this->NumberOfFoldedPoints = std::count(s, s + n, static_cast<unsigned char>(InverseStatus::Folded));
  this->NumberOfUnconvergedPoints = std::count(s, s + n, static_cast<unsigned char>(InverseStatus::NotConverged));
  if (this->NumberOfFoldedPoints + this->NumberOfUnconvergedPoints > 0)
  {
    vtkWarningMacro(<< this->NumberOfFoldedPoints + this->NumberOfUnconvergedPoints << " of " << n
                    << " points have no reliable rest position: " << this->NumberOfFoldedPoints
                    << " where the deformation folds (det J <= 0), " << this->NumberOfUnconvergedPoints
                    << " where Newton's method did not converge. The " << InverseStatusArrayName()
                    << " point array marks them (1 folded, 2 not converged); they keep the best position found.");
  }
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDInverseDeform::FillOutput(vtkPointSet* input, vtkDoubleArray* rest, vtkDoubleArray* restNormals,
  vtkUnsignedCharArray* status, vtkPointSet* output)
{
  const bool single = this->OutputPointsPrecision == SINGLE_PRECISION ||
    (this->OutputPointsPrecision == DEFAULT_PRECISION && input->GetPoints()->GetDataType() == VTK_FLOAT);
  vtkNew<vtkPoints> outPoints;
  if (single)
  {
    outPoints->SetDataTypeToFloat();
    outPoints->GetData()->DeepCopy(rest);
  }
  else
  {
    outPoints->SetData(rest);
  }
  output->CopyStructure(input);
  output->SetPoints(outPoints);
  output->GetPointData()->PassData(input->GetPointData());
  output->GetCellData()->PassData(input->GetCellData());
  output->GetFieldData()->PassData(input->GetFieldData());
  output->GetPointData()->SetNormals(restNormals);
  output->GetCellData()->SetNormals(nullptr); // cell normals cannot follow a non-affine map
  output->GetPointData()->AddArray(status);
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDInverseDeform::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Tolerance: " << this->Tolerance << "\n";
  os << indent << "MaximumNumberOfIterations: " << this->MaximumNumberOfIterations << "\n";
  os << indent << "OutputPointsPrecision: " << this->OutputPointsPrecision << "\n";
  os << indent << "NumberOfFoldedPoints: " << this->NumberOfFoldedPoints << "\n";
  os << indent << "NumberOfUnconvergedPoints: " << this->NumberOfUnconvergedPoints << "\n";
}
