// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDCoarsenLattice.h"

#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkFFDBuildLattice.h"
#include "vtkFFDDataContract.h"
#include "vtkFFDDeform.h"
#include "vtkFFDGridDeformer.h"
#include "vtkFFDInputChecks.h"
#include "vtkFFDLatticeQueries.h"
#include "vtkFFDMemory.h"
#include "vtkFFDPipelineKeys.h"
#include "vtkFFDStatistics.h"
#include "vtkFFDTetrahedralDeformer.h"
#include "vtkFFDVoxelize.h"
#include "vtkFFDWholeInput.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkSMPTools.h"
#include "vtkSmartPointer.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include "FFDFrame.h"
#include "FFDLeastSquares.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkFFDCoarsenLattice);

namespace
{
/// Iterated Tikhonov steps (ffd::LeastSquares): a direction whose eigenvalue is 10 lambda keeps 0.1^8 of the
/// regularisation's bias.
constexpr int SolveSteps = 8;

/// The smoothness of the lattice's control net: x_a - 2 x_b + x_c for every active control point b whose two
/// neighbours a, c along an axis are active too.
std::vector<int> SecondDifferences(const vtkFFDGridDeformer& reader, vtkPointSet* lattice)
{
  const vtkFFDControlPointIndex index(reader, lattice);
  const int* dims = reader.GetLattice().ControlPointsPerAxis;
  vtkDataArray* active = lattice->GetPointData()->GetArray(vtkFFDDataContract::ActiveArrayName());
  vtkDataArray* latticeIndex = lattice->GetPointData()->GetArray(vtkFFDDataContract::LatticeIndexArrayName());
  auto isActive = [&](vtkIdType p) { return p >= 0 && (!active || active->GetComponent(p, 0) != 0); };
  std::vector<int> triples;
  for (vtkIdType p = 0; p < lattice->GetNumberOfPoints(); ++p)
  {
    if (!isActive(p))
    {
      continue;
    }
    int ijk[3];
    for (int a = 0; a < 3; ++a)
    {
      ijk[a] = reader.GetSparseCells()
        ? int(latticeIndex->GetComponent(p, a))
        : int(a == 0 ? p % dims[0] : (a == 1 ? p / dims[0] % dims[1] : p / dims[0] / dims[1]));
    }
    for (int a = 0; a < 3; ++a)
    {
      int before[3] = { ijk[0], ijk[1], ijk[2] }, after[3] = { ijk[0], ijk[1], ijk[2] };
      --before[a];
      ++after[a];
      const vtkIdType q = index.Find(before[0], before[1], before[2]), r = index.Find(after[0], after[1], after[2]);
      if (isActive(q) && isActive(r))
      {
        triples.insert(triples.end(), { int(q), int(p), int(r) });
      }
    }
  }
  return triples;
}

bool IsFinite(const double x[3])
{
  return std::isfinite(x[0]) && std::isfinite(x[1]) && std::isfinite(x[2]);
}

/// 1 for each point whose rest (`mesh`) and deformed (`target`) positions are both finite, else 0; `first` is
/// the first point that is not (-1: none), `inside` how many of those that are lie in `frame` at rest.
std::vector<char> FinitePoints(
  vtkPointSet* mesh, vtkPointSet* target, const ffd::Frame<double>& frame, vtkIdType& first, vtkIdType& inside)
{
  std::vector<char> finite(std::size_t(mesh->GetNumberOfPoints()));
  first = -1;
  inside = 0;
  for (vtkIdType p = 0; p < mesh->GetNumberOfPoints(); ++p)
  {
    double x[3], y[3];
    mesh->GetPoint(p, x);
    target->GetPoint(p, y);
    finite[p] = IsFinite(x) && IsFinite(y);
    if (!finite[p] && first < 0)
    {
      first = p;
    }
    ffd::Vec3<double> stu;
    inside += finite[p] && frame.Bind(ffd::Vec3<double>::From(x), stu);
  }
  return finite;
}

/// The fine lattice in `reader`; false, said why, where the inputs or the regularization cannot be coarsened.
bool CheckInputs(
  vtkFFDCoarsenLattice* self, vtkPointSet* input, vtkPointSet* mesh, double regularization, vtkFFDGridDeformer& reader)
{
  if (vtkFFDTetrahedralDeformer::IsTetrahedralLattice(input))
  {
    vtkErrorWithObjectMacro(self, << "The input is a tetrahedral lattice: this filter coarsens the grid lattices of "
                                     "vtkFFDBuildLattice.");
    return false;
  }
  if (!mesh || !mesh->GetPoints() || mesh->GetNumberOfPoints() == 0)
  {
    vtkErrorWithObjectMacro(self, << "No mesh points to fit the deformation on: SetMeshConnection() (input 1) to "
                                     "the mesh the lattice deforms.");
    return false;
  }
  const std::string why = reader.SetLattice(input);
  if (!why.empty())
  {
    vtkErrorWithObjectMacro(self, << "Cannot coarsen the input: " << why);
    return false;
  }
  if (!(regularization >= 0 && regularization <= 1))
  {
    vtkErrorWithObjectMacro(self, << "Regularization is " << regularization
                                  << ": give SetRegularization() a number from 0 to 1 (default 1e-6).");
    return false;
  }
  return true;
}

/// The coarse lattice's divisions and basis: those set, else half the fine lattice's divisions and its basis;
/// false, said why, where a sparse lattice would get the BERNSTEIN basis.
bool CoarseShape(vtkFFDCoarsenLattice* self, const vtkFFDGridLattice& fine, const int setDivisions[3], int setBasis,
  int divisions[3], int& basis)
{
  const bool halve = setDivisions[0] < 1 || setDivisions[1] < 1 || setDivisions[2] < 1;
  for (int a = 0; a < 3; ++a)
  {
    divisions[a] = halve ? (fine.Divisions[a] + 1) / 2 : setDivisions[a];
  }
  basis = setBasis < 0 ? int(fine.Basis) : setBasis;
  if (fine.Sparse && basis == vtkFFDBuildLattice::BERNSTEIN)
  {
    vtkErrorWithObjectMacro(self, << "The input is sparse and a BERNSTEIN lattice cannot be: coarsen a dense lattice "
                                     "into the BERNSTEIN basis, or choose a local basis.");
    return false;
  }
  return true;
}

/// The deformation to reproduce: `deformed` (input 2) where given, else the mesh deformed by the input lattice
/// (by `deform`, which holds it); nullptr, said why, where neither gives the mesh's points.
vtkPointSet* DeformationToFit(
  vtkFFDCoarsenLattice* self, vtkPointSet* deformed, vtkPointSet* input, vtkPointSet* mesh, vtkFFDDeform* deform)
{
  if (deformed && deformed->GetNumberOfPoints() != mesh->GetNumberOfPoints())
  {
    vtkErrorWithObjectMacro(self, << "The deformed mesh (input 2) has " << deformed->GetNumberOfPoints()
                                  << " points, the mesh " << mesh->GetNumberOfPoints()
                                  << ": give the same points, deformed, in the same order.");
    return nullptr;
  }
  if (deformed)
  {
    return deformed;
  }
  deform->SetInputData(mesh);
  deform->SetLatticeData(input);
  deform->SetTransformNormals(false);
  deform->SetOutputPointsPrecision(vtkAlgorithm::DOUBLE_PRECISION);
  deform->Update();
  vtkPointSet* target = vtkPointSet::SafeDownCast(deform->GetOutputDataObject(0));
  if (!target || target->GetNumberOfPoints() != mesh->GetNumberOfPoints())
  {
    vtkErrorWithObjectMacro(self, << "Could not deform the mesh by the input lattice (see the error above).");
    return nullptr;
  }
  return target;
}

/// FinitePoints() in the fine lattice's frame, and how many; false, said why, where none lies in the frame. A
/// point without a finite rest or deformed position has no displacement to fit: it is left out, and said so.
bool FindFinitePoints(vtkFFDCoarsenLattice* self, vtkPointSet* mesh, vtkPointSet* target, const vtkFFDGridLattice& fine,
  std::vector<char>& finite, vtkIdType& numFinite)
{
  vtkIdType firstNotFinite, inside;
  finite = FinitePoints(mesh, target, ffd::Frame<double>::FromArray(fine.Frame), firstNotFinite, inside);
  numFinite = std::count(finite.begin(), finite.end(), 1);
  if (inside == 0)
  {
    vtkErrorWithObjectMacro(
      self, << "None of the mesh's " << mesh->GetNumberOfPoints() << " points "
            << (numFinite == 0 ? "has a finite position, at rest and deformed" : "lies in the lattice's frame")
            << ": there is nothing to fit. SetMeshConnection() to the mesh that the lattice "
               "deforms.");
    return false;
  }
  if (firstNotFinite >= 0)
  {
    vtkWarningWithObjectMacro(self, << mesh->GetNumberOfPoints() - numFinite << " of the mesh's "
                                    << mesh->GetNumberOfPoints() << " points (the first: point " << firstNotFinite
                                    << ") have a NaN or infinite coordinate at "
                                    << "rest or deformed: the fit and its residuals leave them out.");
  }
  return true;
}

/// The coarse lattice at rest over the mesh's voxels, in the fine lattice's frame; nullptr, said why, where it
/// cannot be built or is not of the output's type.
vtkSmartPointer<vtkPointSet> BuildCoarse(vtkFFDCoarsenLattice* self, vtkPointSet* mesh, const vtkFFDGridLattice& fine,
  int divisions[3], int basis, vtkPointSet* output)
{
  vtkNew<vtkFFDVoxelize> voxelize;
  voxelize->SetInputData(mesh);
  voxelize->SetFrame(fine.Frame, fine.Frame + 3, fine.Frame + 6, fine.Frame + 9);
  voxelize->SetDivisions(divisions);
  vtkNew<vtkFFDBuildLattice> build;
  build->SetInputConnection(voxelize->GetOutputPort());
  build->SetBasis(basis);
  build->SetLatticeForm(fine.Sparse ? vtkFFDBuildLattice::SPARSE : vtkFFDBuildLattice::DENSE);
  build->Update();
  vtkSmartPointer<vtkPointSet> coarse = vtkPointSet::SafeDownCast(build->GetOutputDataObject(0));
  if (!coarse || coarse->GetNumberOfPoints() == 0)
  {
    vtkErrorWithObjectMacro(self, << "Could not build the coarse lattice (see the error above).");
    return nullptr;
  }
  if (output->GetDataObjectType() != coarse->GetDataObjectType())
  {
    vtkErrorWithObjectMacro(
      self, << "The output is a " << output->GetClassName() << " but the lattice a " << coarse->GetClassName());
    return nullptr;
  }
  return coarse;
}

/// The mesh's `points` bound to the `coarse` lattice by `coarseReader`; false, said why, where they cannot be.
bool BindToCoarse(vtkFFDCoarsenLattice* self, vtkPointSet* coarse, vtkPoints* points, vtkFFDGridDeformer& coarseReader)
{
  const std::string why = coarseReader.SetLattice(coarse);
  bool rebound = false;
  if (!why.empty() || !coarseReader.Bind(points, vtkFFDDeform::KEEP_POSITION, self, 0.1, 0.2, rebound))
  {
    vtkErrorWithObjectMacro(self, << "Could not bind the mesh to the coarse lattice. " << why);
    return false;
  }
  return true;
}

/// The least-squares fit of the displacements `b` (3 a row: target - rest) of the finite mesh points bound to
/// the coarse lattice, with the smoothness of its control net. W: a row of weights per such point, over every
/// control point of the coarse lattice (culled ones get no weight and stay at rest). Null, said why, where W is
/// too large.
std::unique_ptr<ffd::LeastSquares> AssembleFit(vtkFFDCoarsenLattice* self, const vtkFFDGridDeformer& coarseReader,
  vtkPointSet* coarse, vtkPoints* points, vtkPointSet* target, const std::vector<char>& finite, std::vector<double>& b)
{
  const std::vector<int>& cellOf = coarseReader.GetCellOfPoint();
  std::vector<vtkIdType> rowPoint;
  for (vtkIdType p = 0; p < points->GetNumberOfPoints(); ++p)
  {
    if (cellOf[p] >= 0 && finite[p])
    {
      rowPoint.push_back(p);
    }
  }
  const double perPoint = vtkFFDGridWeightsPerPoint(coarseReader);
  const double entries = perPoint * double(rowPoint.size());
  std::ostringstream request;
  request << "A least-squares fit of " << rowPoint.size() << " points with " << perPoint << " weights each";
  if (entries >= double(VTK_INT_MAX))
  {
    vtkErrorWithObjectMacro(
      self, << request.str() << " has more than 2^31 - 1 weights: fit fewer points or a coarser basis.");
    return nullptr;
  }
  // W, W^T and W^T W (at most perPoint^2 / 8 entries a point, sorted by Eigen's sparse product).
  if (!vtkFFDCheckMemory(self, request.str(), 3.0 * 12.0 * entries + 12.0 * entries * perPoint / 8.0))
  {
    return nullptr;
  }
  std::vector<int> rowStart(rowPoint.size() + 1);
  for (std::size_t r = 0; r <= rowPoint.size(); ++r)
  {
    rowStart[r] = int(r * std::size_t(perPoint));
  }
  std::vector<int> columns(static_cast<std::size_t>(entries));
  std::vector<double> weights(static_cast<std::size_t>(entries));
  b.resize(3 * rowPoint.size());
  vtkSMPTools::For(0, vtkIdType(rowPoint.size()),
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType r = begin; r < end; ++r)
      {
        std::size_t slot = std::size_t(rowStart[r]);
        const vtkIdType p = rowPoint[r];
        vtkFFDForEachGridWeight(coarseReader, points, p, p + 1,
          [&](vtkIdType, vtkIdType controlPoint, double weight)
          {
            columns[slot] = int(controlPoint);
            weights[slot++] = weight;
          });
        double x[3], y[3];
        points->GetPoint(p, x);
        target->GetPoint(p, y);
        for (int c = 0; c < 3; ++c)
        {
          b[3 * r + c] = y[c] - x[c];
        }
      }
    });
  auto fit = std::make_unique<ffd::LeastSquares>(
    int(coarse->GetNumberOfPoints()), std::move(rowStart), std::move(columns), std::move(weights));
  fit->SetSecondDifferences(SecondDifferences(coarseReader, coarse));
  return fit;
}

/// The coarse lattice's points moved by `x` (3 per control point), in double precision.
vtkSmartPointer<vtkPoints> MovedPoints(vtkPointSet* coarse, const std::vector<double>& x)
{
  vtkNew<vtkPoints> moved;
  moved->SetDataTypeToDouble();
  moved->DeepCopy(coarse->GetPoints());
  double* position = vtkDoubleArray::SafeDownCast(moved->GetData())->GetPointer(0);
  for (std::size_t i = 0; i < x.size(); ++i)
  {
    position[i] += x[i];
  }
  return moved.Get();
}

/// The RMS and the maximum of the residual of the fit (`fitted`, 3 per row of W) over every finite mesh point:
/// those outside the coarse lattice keep their place.
void Residuals(const std::vector<int>& cellOf, vtkPoints* points, vtkPointSet* target, const std::vector<char>& finite,
  vtkIdType numFinite, const std::vector<double>& fitted, double& rms, double& maximum)
{
  double sum = 0, worst = 0;
  std::size_t r = 0;
  for (vtkIdType p = 0; p < points->GetNumberOfPoints(); ++p)
  {
    if (!finite[p])
    {
      continue;
    }
    double from[3], to[3], e2 = 0;
    points->GetPoint(p, from);
    target->GetPoint(p, to);
    const bool bound = cellOf[p] >= 0;
    for (int c = 0; c < 3; ++c)
    {
      const double e = (to[c] - from[c]) - (bound ? fitted[3 * r + c] : 0.0);
      e2 += e * e;
    }
    r += bound;
    sum += e2;
    worst = std::max(worst, e2);
  }
  rms = std::sqrt(sum / double(numFinite));
  maximum = std::sqrt(worst);
}
} // namespace

//------------------------------------------------------------------------------------------------------------
vtkFFDCoarsenLattice::vtkFFDCoarsenLattice()
  : Divisions{ 0, 0, 0 }
  , Basis(-1)
  , Regularization(1e-6)
  , ResidualRMS(0)
  , MaximumResidual(0)
{
  this->SetNumberOfInputPorts(3);
}

//------------------------------------------------------------------------------------------------------------
int vtkFFDCoarsenLattice::FillInputPortInformation(int port, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkPointSet");
  if (port == 2)
  {
    info->Set(vtkAlgorithm::INPUT_IS_OPTIONAL(), 1);
  }
  return 1;
}

//------------------------------------------------------------------------------------------------------------
int vtkFFDCoarsenLattice::ExecuteInformation(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  // The coarse lattice's extent, where its input's divisions and basis are announced (vtkFFDPipelineKeys.h), by
  // the rules of RequestData.
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  int basis;
  int divisions[3];
  if (!vtkFFDPipelineKeys::AnnouncedLattice(inputVector[0]->GetInformationObject(0), basis, divisions))
  {
    vtkFFDPipelineKeys::Forget(outInfo);
    return 1;
  }
  const bool halve = this->Divisions[0] < 1 || this->Divisions[1] < 1 || this->Divisions[2] < 1;
  for (int a = 0; a < 3; ++a)
  {
    divisions[a] = halve ? (divisions[a] + 1) / 2 : this->Divisions[a];
  }
  vtkFFDPipelineKeys::AnnounceLattice(outInfo, this->Basis < 0 ? basis : this->Basis, divisions);
  return 1;
}

//------------------------------------------------------------------------------------------------------------
int vtkFFDCoarsenLattice::ComputeInputUpdateExtent(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector*)
{
  // The fit needs the whole lattice and every point of the mesh.
  for (int port = 0; port < 3; ++port)
  {
    vtkFFDRequestWholeInput(inputVector[port]->GetInformationObject(0));
  }
  return 1;
}

//------------------------------------------------------------------------------------------------------------
vtkTypeBool vtkFFDCoarsenLattice::ProcessRequest(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  return vtkFFDCatchAllocationFailure(
    this, outputVector, [&] { return this->Superclass::ProcessRequest(request, inputVector, outputVector); });
}

//------------------------------------------------------------------------------------------------------------
int vtkFFDCoarsenLattice::RequestDataObject(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  if (!(vtkFFDCheckInput(this, inputVector[0], 0, "vtkPointSet", "the lattice",
          "SetInputConnection() to a grid lattice, the output of vtkFFDBuildLattice.") &&
        vtkFFDCheckInput(this, inputVector[1], 1, "vtkPointSet", "the mesh",
          "SetMeshConnection() to the mesh whose points the fit runs over.") &&
        vtkFFDCheckInput(this, inputVector[2], 2, "vtkPointSet", "the deformed mesh",
          "SetDeformedMeshConnection() to the mesh deformed, or to nothing.", true)))
  {
    return vtkFFDEmptyOutputs(outputVector);
  }
  return this->Superclass::RequestDataObject(request, inputVector, outputVector);
}

//------------------------------------------------------------------------------------------------------------
int vtkFFDCoarsenLattice::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkPointSet* input = vtkPointSet::GetData(inputVector[0]);
  vtkPointSet* mesh = vtkPointSet::GetData(inputVector[1]);
  vtkPointSet* output = vtkPointSet::GetData(outputVector);
  this->ResidualRMS = this->MaximumResidual = 0;
  const vtkFFDStatisticsOnReturn statistics(output,
    [this](vtkDataObject* out)
    {
      vtkFFDRecordValue(out, "ResidualRMS", this->ResidualRMS);
      vtkFFDRecordValue(out, "MaximumResidual", this->MaximumResidual);
    });
  if (!input || input->GetNumberOfPoints() == 0)
  {
    return 1;
  }
  vtkFFDGridDeformer reader;
  int divisions[3], basis;
  if (!CheckInputs(this, input, mesh, this->Regularization, reader) ||
    !CoarseShape(this, reader.GetLattice(), this->Divisions, this->Basis, divisions, basis))
  {
    return 0;
  }
  const vtkFFDGridLattice& fine = reader.GetLattice();
  vtkNew<vtkFFDDeform> deform;
  vtkPointSet* target = DeformationToFit(this, vtkPointSet::GetData(inputVector[2]), input, mesh, deform);
  std::vector<char> finite;
  vtkIdType numFinite = 0;
  if (!target || !FindFinitePoints(this, mesh, target, fine, finite, numFinite))
  {
    return 0;
  }
  this->UpdateProgress(0.1);

  const vtkSmartPointer<vtkPointSet> coarse = BuildCoarse(this, mesh, fine, divisions, basis, output);
  vtkFFDGridDeformer coarseReader;
  vtkPoints* points = mesh->GetPoints();
  if (!coarse || !BindToCoarse(this, coarse, points, coarseReader))
  {
    return 0;
  }
  std::vector<double> b;
  const std::unique_ptr<ffd::LeastSquares> fit = AssembleFit(this, coarseReader, coarse, points, target, finite, b);
  if (!fit)
  {
    return 0;
  }
  this->UpdateProgress(0.3);
  std::vector<double> x;
  if (!fit->Solve(b, this->Regularization, SolveSteps, x))
  {
    vtkErrorMacro(<< "The mesh's points leave some combination of the coarse lattice's control points "
                     "undetermined and Regularization is 0: set it above 0 (the default 1e-6 keeps those smooth).");
    return 0;
  }
  this->UpdateProgress(0.9);

  // The output: the coarse lattice moved by X, and the fit's residuals.
  const vtkSmartPointer<vtkPoints> moved = MovedPoints(coarse, x);
  std::vector<double> fitted;
  fit->Apply(x, fitted);
  Residuals(
    coarseReader.GetCellOfPoint(), points, target, finite, numFinite, fitted, this->ResidualRMS, this->MaximumResidual);
  output->ShallowCopy(coarse);
  output->SetPoints(moved);
  this->UpdateProgress(1.0);
  return 1;
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDCoarsenLattice::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Divisions: " << this->Divisions[0] << " " << this->Divisions[1] << " " << this->Divisions[2] << "\n";
  os << indent << "Basis: " << this->Basis << "\n";
  os << indent << "Regularization: " << this->Regularization << "\n";
  os << indent << "ResidualRMS: " << this->ResidualRMS << "\n";
  os << indent << "MaximumResidual: " << this->MaximumResidual << "\n";
}
