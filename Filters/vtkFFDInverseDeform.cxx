// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDInverseDeform.h"

#include "vtkCellData.h"
#include "vtkDoubleArray.h"
#include "vtkFFDDataContract.h"
#include "vtkFFDDeform.h"
#include "vtkFFDForInChunks.h"
#include "vtkFFDGridDeformer.h"
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
#include "vtkUnsignedCharArray.h"
#include "vtkUnstructuredGrid.h"

#include "FFDInverse.h"

#include <algorithm>
#include <cmath>

vtkStandardNewMacro(vtkFFDInverseDeform);

namespace
{
using ffd::InverseStatus;

// Where the inversion writes: 3 doubles a point, 3 a normal (null: no normals), a status a point.
struct InverseOutput
{
  double* Points;
  double* Normals;
  unsigned char* Status;
};

// The cell whose evaluation extends F to x for the search: Bind()'s under CLAMP_TO_EDGE (beyond the frame, F as
// CLAMP_TO_EDGE extends it) and, for a sparse lattice's point in a voxel without a cell, the nearest cell within
// two voxels (its evaluation clamps x's local coordinates to that cell: F extended across the cell's faces). Under
// KEEP_POSITION, F jumps wherever the lattice's border or a sparse lattice's last cells moved: a mesh point pushed
// out of the cells would otherwise be found at its own place, which F keeps.
int SearchCell(const vtkFFDGridDeformer& deformer, const ffd::Frame<double>& frame, const ffd::Vec3<double>& x)
{
  const double p[3] = { x.x, x.y, x.z };
  const int cell = deformer.BindPoint(p, vtkFFDDeform::CLAMP_TO_EDGE);
  const vtkFFDSparseCells* sparse = deformer.GetSparseCells();
  const int* n = deformer.GetLattice().Divisions;
  int v[3];
  if (cell >= 0 || !sparse || !ffd::BindToCells(frame, n, x, true, v))
  {
    return cell;
  }
  const ffd::Vec3<double> stu = frame.ToParametric(x);
  const double q[3] = { stu.x * n[0], stu.y * n[1], stu.z * n[2] }; // in voxels
  double nearest = VTK_DOUBLE_MAX;
  int found = -1;
  for (int k = std::max(v[2] - 2, 0); k <= std::min(v[2] + 2, n[2] - 1); ++k)
  {
    for (int j = std::max(v[1] - 2, 0); j <= std::min(v[1] + 2, n[1] - 1); ++j)
    {
      for (int i = std::max(v[0] - 2, 0); i <= std::min(v[0] + 2, n[0] - 1); ++i)
      {
        const int c = sparse->Find(vtkFFDFlatIndex(i, j, k, n));
        if (c < 0)
        {
          continue;
        }
        const int w[3] = { i, j, k };
        double distance2 = 0;
        for (int a = 0; a < 3; ++a)
        {
          const double outside = std::max({ w[a] - q[a], 0.0, q[a] - (w[a] + 1) });
          distance2 += outside * outside;
        }
        if (distance2 < nearest || (distance2 == nearest && c < found))
        {
          nearest = distance2;
          found = c;
        }
      }
    }
  }
  return found;
}

// Grid lattices: ffd::InvertPoint on the lattice's float64 evaluation. A normal m at y goes back by the inverse's
// cofactor, det(J^-1) J^T: as J^T m, renormalised.
bool InvertByGrid(vtkAlgorithm* self, const vtkFFDGridDeformer& deformer, vtkPoints* points, vtkDataArray* normals,
  double tolerance, int maxIterations, const InverseOutput& out)
{
  const double* f = deformer.GetLattice().Frame;
  const double diagonal = std::hypot(f[3] + f[6] + f[9], f[4] + f[7] + f[10], f[5] + f[8] + f[11]);
  const double absolute = tolerance * diagonal;
  bool completed = false;
  vtkFFDWithGridDeformation(deformer,
    [&](const auto& deformation)
    {
      const ffd::Frame<double> frame = ffd::Frame<double>::FromArray(deformer.GetLattice().Frame);
      const auto bind = [&](const ffd::Vec3<double>& x) { return SearchCell(deformer, frame, x); };
      auto invert = [&](vtkIdType begin, vtkIdType end)
      {
        for (vtkIdType p = begin; p < end; ++p)
        {
          double y[3];
          points->GetPoint(p, y);
          ffd::Vec3<double> x = ffd::Vec3<double>::From(y);
          ffd::Mat3<double> jacobian = ffd::Mat3<double>::Identity();
          InverseStatus status = InverseStatus::Converged;
          if (std::isfinite(y[0]) && std::isfinite(y[1]) && std::isfinite(y[2])) // else kept, as F keeps them
          {
            status =
              ffd::InvertPoint(deformation, bind, ffd::Vec3<double>::From(y), absolute, maxIterations, x, jacobian);
            const double found[3] = { x.x, x.y, x.z };
            if (deformer.BindPoint(found, vtkFFDDeform::KEEP_POSITION) < 0)
            {
              // Outside the lattice's cells F is the identity: y is its own rest position there, and has none
              // inside.
              const bool outside = deformer.BindPoint(y, vtkFFDDeform::KEEP_POSITION) < 0;
              x = ffd::Vec3<double>::From(y);
              jacobian = ffd::Mat3<double>::Identity();
              status = outside ? InverseStatus::Converged : InverseStatus::NotConverged;
            }
          }
          std::copy_n(&x.x, 3, out.Points + 3 * p);
          out.Status[p] = static_cast<unsigned char>(status);
          if (out.Normals)
          {
            double m[3];
            normals->GetTuple(p, m);
            double n[3];
            for (int a = 0; a < 3; ++a)
            {
              n[a] = jacobian.M[0][a] * m[0] + jacobian.M[1][a] * m[1] + jacobian.M[2][a] * m[2];
            }
            const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
            for (int a = 0; a < 3; ++a)
            {
              out.Normals[3 * p + a] = length > 0 ? n[a] / length : m[a];
            }
          }
        }
      };
      const vtkIdType n = points->GetNumberOfPoints();
      completed =
        vtkFFDForInChunks(self, n, vtkFFDGrain(n, 8.0 * vtkFFDGridWeightsPerPoint(deformer)), invert, 0.0, 1.0);
    });
  return completed;
}

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
  const InverseOutput& out, std::string& problem)
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
  return vtkFFDCatchAllocationFailure(this, outputVector,
    [&]
    {
      const vtkTypeBool done = this->Superclass::ProcessRequest(request, inputVector, outputVector);
      // A lattice that varies in time (vtkFFDSimulateLattice) must make the mesh re-execute at each time.
      if (done)
      {
        vtkFFDPipelineKeys::AnnounceTimes(request, inputVector, 2, outputVector);
      }
      return done;
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
  if (!std::isfinite(this->Tolerance) || this->Tolerance < 0)
  {
    vtkErrorMacro(<< "Tolerance is " << this->Tolerance
                  << ": give SetTolerance() a finite number >= 0 (default 1e-12, relative to the frame's diagonal).");
    return 0;
  }
  if (this->MaximumNumberOfIterations < 1)
  {
    vtkErrorMacro(<< "MaximumNumberOfIterations is " << this->MaximumNumberOfIterations
                  << ": give SetMaximumNumberOfIterations() 1 or more (default 50).");
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

  const vtkIdType n = points->GetNumberOfPoints();
  vtkNew<vtkDoubleArray> rest;
  rest->SetNumberOfComponents(3);
  rest->SetNumberOfTuples(n);
  vtkDataArray* normals = input->GetPointData()->GetNormals();
  if (normals && (normals->GetNumberOfComponents() != 3 || normals->GetNumberOfTuples() != n))
  {
    normals = nullptr;
  }
  vtkSmartPointer<vtkDoubleArray> restNormals;
  if (normals)
  {
    restNormals = vtkSmartPointer<vtkDoubleArray>::New();
    restNormals->SetName(normals->GetName());
    restNormals->SetNumberOfComponents(3);
    restNormals->SetNumberOfTuples(n);
  }
  vtkNew<vtkUnsignedCharArray> status;
  status->SetName(InverseStatusArrayName());
  status->SetNumberOfTuples(n);
  const InverseOutput out{ rest->GetPointer(0), restNormals ? restNormals->GetPointer(0) : nullptr,
    status->GetPointer(0) };

  std::string problem;
  bool completed = false;
  if (vtkFFDTetrahedralDeformer::IsTetrahedralLattice(lattice))
  {
    completed = InvertByTetrahedra(this, vtkUnstructuredGrid::SafeDownCast(lattice), points, normals, out, problem);
  }
  else
  {
    vtkFFDGridDeformer deformer;
    problem = deformer.SetLattice(lattice);
    completed = problem.empty() &&
      InvertByGrid(this, deformer, points, normals, this->Tolerance, this->MaximumNumberOfIterations, out);
  }
  if (!problem.empty())
  {
    vtkErrorMacro(<< problem);
    return 0;
  }
  if (!completed) // aborted: the output stays empty
  {
    return 1;
  }

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

  const bool single = this->OutputPointsPrecision == SINGLE_PRECISION ||
    (this->OutputPointsPrecision == DEFAULT_PRECISION && points->GetDataType() == VTK_FLOAT);
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
  return 1;
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
