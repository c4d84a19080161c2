// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDDeform.h"

#include "vtkFFDBuildLattice.h"
#include "vtkFFDDataContract.h"

#include "vtkAOSDataArrayTemplate.h"
#include "vtkArrayDispatch.h"
#include "vtkCellData.h"
#include "vtkDataArray.h"
#include "vtkDataArrayRange.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkSMPTools.h"
#include "vtkSmartPointer.h"

#include "FFDFrame.h"
#include "FFDGlobalBernstein.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkFFDDeform);

namespace
{
//------------------------------------------------------------------------------------------------------------
// What the filter needs from a lattice, read and checked once per update.
struct LatticeView
{
  double Frame[12];
  int Divisions[3];
  int Basis;
  int Dims[3];                       // control points per axis
  std::vector<double> Displacements; // 3 per control point: point minus RestPosition
};

// Reads a lattice per the data contract; returns an empty string or what is wrong with it.
std::string ReadLattice(vtkPointSet* lattice, LatticeView& view)
{
  const std::string fix = " Build the lattice with vtkFFDBuildLattice, or keep its data contract "
                          "(see vtkFFDDataContract).";
  if (!lattice)
  {
    return "The lattice on input port 1 is not a vtkPointSet." + fix;
  }
  if (!vtkFFDDataContract::GetFrame(lattice, view.Frame))
  {
    return "The lattice has no valid FFDFrame field array (12 finite doubles)." + fix;
  }
  if (ffd::CheckFrame(view.Frame) != ffd::FrameStatus::Valid)
  {
    return "The lattice's FFDFrame has no volume: its edge vectors S, T, U are (nearly) linearly dependent.";
  }
  if (!vtkFFDDataContract::GetDivisions(lattice, view.Divisions))
  {
    return "The lattice has no valid FFDDivisions field array (3 ints >= 1)." + fix;
  }
  if (!vtkFFDDataContract::GetBasis(lattice, view.Basis))
  {
    return "The lattice has no FFDBasis field array (1 int)." + fix;
  }
  if (view.Basis != vtkFFDBuildLattice::BERNSTEIN)
  {
    return std::string("The lattice's basis ") + vtkFFDBuildLattice::GetBasisAsString(view.Basis) +
      " is not supported by vtkFFDDeform yet; use BERNSTEIN.";
  }
  for (int a = 0; a < 3; ++a)
  {
    if (view.Divisions[a] > ffd::MaxBernsteinDegree)
    {
      return "The lattice's Bernstein degree " + std::to_string(view.Divisions[a]) + " exceeds the maximum " +
        std::to_string(ffd::MaxBernsteinDegree) + ".";
    }
    view.Dims[a] = view.Divisions[a] + 1;
  }
  const vtkIdType expected = vtkIdType(view.Dims[0]) * view.Dims[1] * view.Dims[2];
  const vtkIdType count = lattice->GetNumberOfPoints();
  if (count != expected)
  {
    std::ostringstream msg;
    msg << "The lattice has " << count << " points but its divisions " << view.Divisions[0] << "x"
        << view.Divisions[1] << "x" << view.Divisions[2] << " need " << expected << ".";
    return msg.str();
  }
  vtkDataArray* rest = lattice->GetPointData()->GetArray(vtkFFDDataContract::RestPositionArrayName());
  if (!rest || rest->GetNumberOfComponents() != 3 || rest->GetNumberOfTuples() != count)
  {
    return "The lattice has no RestPosition point array of 3 components per point." + fix;
  }
  view.Displacements.resize(3 * count);
  for (vtkIdType p = 0; p < count; ++p)
  {
    double x[3], x0[3];
    lattice->GetPoint(p, x);
    rest->GetTuple(p, x0);
    for (int c = 0; c < 3; ++c)
    {
      const double d = x[c] - x0[c];
      if (!std::isfinite(d))
      {
        return "Lattice point " + std::to_string(p) + " or its RestPosition is not finite.";
      }
      view.Displacements[3 * p + c] = d;
    }
  }
  return std::string();
}

//------------------------------------------------------------------------------------------------------------
// Runs functor(begin, end) over [0, n) as a few vtkSMPTools::For calls, so that progress is reported and abort
// honoured between them (never from inside an SMP body). Returns false when aborted.
template <typename Functor>
bool ForInChunks(vtkAlgorithm* self, vtkIdType n, Functor& functor, double progressBegin, double progressEnd)
{
  const vtkIdType chunks = std::max<vtkIdType>(1, std::min<vtkIdType>(10, n / 65536));
  for (vtkIdType c = 0; c < chunks; ++c)
  {
    if (self->GetAbortExecute())
    {
      return false;
    }
    vtkSMPTools::For(n * c / chunks, n * (c + 1) / chunks, functor);
    self->UpdateProgress(progressBegin + (progressEnd - progressBegin) * double(c + 1) / double(chunks));
  }
  return true;
}

//------------------------------------------------------------------------------------------------------------
// Binding: the parameters (s, t, u) of every point in the frame (equation 2), NaN for points that stay put.
template <typename PointArrayT>
struct BindFunctor
{
  PointArrayT* Points;
  ffd::Frame<double> Frame;
  double* Parameters;

  void operator()(vtkIdType begin, vtkIdType end)
  {
    const auto points = vtk::DataArrayTupleRange<3>(this->Points, begin, end);
    double* stuOut = this->Parameters + 3 * begin;
    for (const auto x : points)
    {
      ffd::Vec3<double> stu;
      if (!this->Frame.Bind({ double(x[0]), double(x[1]), double(x[2]) }, stu))
      {
        stu = { std::numeric_limits<double>::quiet_NaN(), 0.0, 0.0 };
      }
      stuOut[0] = stu.x;
      stuOut[1] = stu.y;
      stuOut[2] = stu.z;
      stuOut += 3;
    }
  }
};

struct BindWorker
{
  template <typename PointArrayT>
  void operator()(PointArrayT* points, const ffd::Frame<double>& frame, double* parameters, vtkAlgorithm* self,
    bool& completed)
  {
    BindFunctor<PointArrayT> functor{ points, frame, parameters };
    completed = ForInChunks(self, points->GetNumberOfTuples(), functor, 0.0, 0.5);
  }
};

//------------------------------------------------------------------------------------------------------------
// Evaluation in the precision Real of the output points.
template <typename Real, typename PointArrayT>
struct EvaluateFunctor
{
  PointArrayT* InPoints;
  Real* OutPoints;
  const double* Parameters;
  const Real* Displacements;
  int Dims[3];
  ffd::Frame<Real> Frame;
  vtkDataArray* InNormals;  // nullptr: no normals to transform
  vtkDataArray* OutNormals;
  Real* Determinants;       // nullptr: not asked for

  void operator()(vtkIdType begin, vtkIdType end)
  {
    const auto inPoints = vtk::DataArrayTupleRange<3>(this->InPoints, begin, end);
    const bool needJacobian = this->OutNormals || this->Determinants;
    vtkIdType id = begin;
    for (const auto x : inPoints)
    {
      const ffd::Vec3<Real> xr = { Real(x[0]), Real(x[1]), Real(x[2]) };
      const double* stuIn = this->Parameters + 3 * id;
      ffd::Vec3<Real> y = xr;
      ffd::Mat3<Real> jacobian = ffd::Mat3<Real>::Identity();
      if (!std::isnan(stuIn[0]))
      {
        const ffd::Vec3<Real> stu = ffd::Vec3<Real>::From(stuIn);
        if (needJacobian)
        {
          ffd::Mat3<Real> gradient;
          y = xr + ffd::EvaluateBernsteinWithGradient(this->Displacements, this->Dims, stu, gradient);
          jacobian = ffd::DeformationJacobian(gradient, this->Frame);
        }
        else
        {
          y = xr + ffd::EvaluateBernstein(this->Displacements, this->Dims, stu);
        }
      }
      Real* out = this->OutPoints + 3 * id;
      out[0] = y.x;
      out[1] = y.y;
      out[2] = y.z;
      if (this->OutNormals)
      {
        this->TransformNormal(id, jacobian);
      }
      if (this->Determinants)
      {
        this->Determinants[id] = ffd::Determinant(jacobian);
      }
      ++id;
    }
  }

  void TransformNormal(vtkIdType id, const ffd::Mat3<Real>& jacobian)
  {
    double n[3];
    this->InNormals->GetTuple(id, n);
    const ffd::Vec3<Real> m = ffd::Cofactor(jacobian) * ffd::Vec3<Real>::From(n);
    const double length = std::sqrt(double(ffd::Dot(m, m)));
    if (length > 0.0)
    {
      n[0] = m.x / length;
      n[1] = m.y / length;
      n[2] = m.z / length;
    }
    this->OutNormals->SetTuple(id, n);
  }
};

template <typename Real>
struct EvaluateWorker
{
  template <typename PointArrayT>
  void operator()(PointArrayT* inPoints, const LatticeView& lattice, const double* parameters,
    vtkDataArray* inNormals, vtkDataArray* outNormals, vtkAOSDataArrayTemplate<Real>* outPoints,
    vtkAOSDataArrayTemplate<Real>* determinants, vtkAlgorithm* self, double progressBegin, bool& completed)
  {
    const std::vector<Real> displacements(lattice.Displacements.begin(), lattice.Displacements.end());
    EvaluateFunctor<Real, PointArrayT> functor{ inPoints, outPoints->GetPointer(0), parameters,
      displacements.data(), { lattice.Dims[0], lattice.Dims[1], lattice.Dims[2] },
      ffd::Frame<Real>::FromArray(lattice.Frame), inNormals, outNormals,
      determinants ? determinants->GetPointer(0) : nullptr };
    completed = ForInChunks(self, inPoints->GetNumberOfTuples(), functor, progressBegin, 1.0);
  }
};

using PointArrays = vtkArrayDispatch::Reals;
} // namespace

//------------------------------------------------------------------------------------------------------------
// The cached binding and what it was computed for.
struct vtkFFDDeform::vtkInternals
{
  std::vector<double> Parameters; // (s, t, u) per input point; s is NaN where the point keeps its position
  const vtkPoints* BoundPoints = nullptr;
  vtkMTimeType BoundPointsMTime = 0;
  vtkIdType BoundNumberOfPoints = -1;
  std::array<double, 12> BoundFrame{};
  std::array<int, 3> BoundDivisions{};
  int BoundBasis = -1;

  // Whether the binding is still that of these points in this lattice. Points are compared by identity and
  // modification time (a new vtkPoints at a recycled address has a newer MTime); the lattice by the values of
  // its rest frame and shape, so that a rebuilt but identical lattice keeps the binding.
  bool IsValidFor(vtkPoints* points, const LatticeView& lattice) const
  {
    return points == this->BoundPoints && points->GetMTime() == this->BoundPointsMTime &&
      points->GetNumberOfPoints() == this->BoundNumberOfPoints &&
      std::equal(this->BoundFrame.begin(), this->BoundFrame.end(), lattice.Frame) &&
      std::equal(this->BoundDivisions.begin(), this->BoundDivisions.end(), lattice.Divisions) &&
      this->BoundBasis == lattice.Basis;
  }

  void Remember(vtkPoints* points, const LatticeView& lattice)
  {
    this->BoundPoints = points;
    this->BoundPointsMTime = points->GetMTime();
    this->BoundNumberOfPoints = points->GetNumberOfPoints();
    std::copy(lattice.Frame, lattice.Frame + 12, this->BoundFrame.begin());
    std::copy(lattice.Divisions, lattice.Divisions + 3, this->BoundDivisions.begin());
    this->BoundBasis = lattice.Basis;
  }

  void Forget() { this->BoundPoints = nullptr; }
};

//------------------------------------------------------------------------------------------------------------
vtkFFDDeform::vtkFFDDeform()
  : TransformNormals(true)
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
int vtkFFDDeform::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkPointSet* input = vtkPointSet::GetData(inputVector[0]);
  vtkPointSet* lattice = vtkPointSet::GetData(inputVector[1]);
  vtkPointSet* output = vtkPointSet::GetData(outputVector);
  if (!input || !output)
  {
    vtkErrorMacro("Input 0 must be a vtkPointSet.");
    return 0;
  }
  output->Initialize();

  vtkPoints* inPoints = input->GetPoints();
  const vtkIdType numberOfPoints = inPoints ? inPoints->GetNumberOfPoints() : 0;
  if (numberOfPoints == 0)
  {
    output->CopyStructure(input);
    output->GetPointData()->PassData(input->GetPointData());
    output->GetCellData()->PassData(input->GetCellData());
    return 1;
  }

  LatticeView view;
  const std::string problem = ReadLattice(lattice, view);
  if (!problem.empty())
  {
    vtkErrorMacro(<< problem);
    return 0;
  }

  // Binding, only when the points or the lattice's rest frame or shape changed.
  vtkInternals& internals = *this->Internals;
  if (!internals.IsValidFor(inPoints, view))
  {
    internals.Forget();
    internals.Parameters.resize(3 * numberOfPoints);
    const ffd::Frame<double> frame = ffd::Frame<double>::FromArray(view.Frame);
    bool completed = false;
    BindWorker bind;
    if (!vtkArrayDispatch::DispatchByValueType<PointArrays>::Execute(
          inPoints->GetData(), bind, frame, internals.Parameters.data(), this, completed))
    {
      bind(inPoints->GetData(), frame, internals.Parameters.data(), this, completed);
    }
    if (!completed)
    {
      return 1; // aborted: the output stays empty
    }
    internals.Remember(inPoints, view);
    ++this->NumberOfBindings;
  }
  this->UpdateProgress(0.5);

  // Evaluation, in the precision of the output points.
  const bool useDouble = this->OutputPointsPrecision == vtkAlgorithm::DOUBLE_PRECISION ||
    (this->OutputPointsPrecision == vtkAlgorithm::DEFAULT_PRECISION && inPoints->GetDataType() == VTK_DOUBLE);
  vtkDataArray* inNormals = this->TransformNormals ? input->GetPointData()->GetNormals() : nullptr;
  if (inNormals && inNormals->GetNumberOfComponents() != 3)
  {
    vtkWarningMacro("The input's point normals do not have 3 components; they are not transformed.");
    inNormals = nullptr;
  }
  vtkSmartPointer<vtkDataArray> outNormals;
  if (inNormals)
  {
    outNormals = vtk::TakeSmartPointer(inNormals->NewInstance());
    outNormals->SetName(inNormals->GetName());
    outNormals->SetNumberOfComponents(3);
    outNormals->SetNumberOfTuples(numberOfPoints);
  }

  vtkNew<vtkPoints> outPoints;
  vtkSmartPointer<vtkDataArray> determinants;
  bool completed = false;
  auto evaluate = [&](auto realTag) {
    using Real = decltype(realTag);
    vtkNew<vtkAOSDataArrayTemplate<Real>> points;
    points->SetNumberOfComponents(3);
    points->SetNumberOfTuples(numberOfPoints);
    vtkSmartPointer<vtkAOSDataArrayTemplate<Real>> det;
    if (this->ComputeJacobianDeterminant)
    {
      det = vtkSmartPointer<vtkAOSDataArrayTemplate<Real>>::New();
      det->SetName(JacobianDeterminantArrayName());
      det->SetNumberOfTuples(numberOfPoints);
    }
    EvaluateWorker<Real> worker;
    if (!vtkArrayDispatch::DispatchByValueType<PointArrays>::Execute(inPoints->GetData(), worker, view,
          internals.Parameters.data(), inNormals, outNormals.Get(), points.Get(), det.Get(), this, 0.5,
          completed))
    {
      worker(inPoints->GetData(), view, internals.Parameters.data(), inNormals, outNormals.Get(), points.Get(),
        det.Get(), this, 0.5, completed);
    }
    outPoints->SetData(points);
    determinants = det;
  };
  if (useDouble)
  {
    evaluate(double());
  }
  else
  {
    evaluate(float());
  }
  if (!completed)
  {
    return 1; // aborted: the output stays empty
  }

  output->CopyStructure(input);
  output->SetPoints(outPoints);
  output->GetPointData()->PassData(input->GetPointData());
  output->GetCellData()->PassData(input->GetCellData());
  if (outNormals)
  {
    output->GetPointData()->SetNormals(outNormals);
  }
  // Cell normals cannot follow a non-affine deformation; stale ones would be silently wrong.
  output->GetCellData()->SetNormals(nullptr);
  if (determinants)
  {
    output->GetPointData()->AddArray(determinants);
  }
  return 1;
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDDeform::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "TransformNormals: " << (this->TransformNormals ? "On" : "Off") << "\n";
  os << indent << "ComputeJacobianDeterminant: " << (this->ComputeJacobianDeterminant ? "On" : "Off") << "\n";
  os << indent << "OutputPointsPrecision: " << this->OutputPointsPrecision << "\n";
  os << indent << "NumberOfBindings: " << this->NumberOfBindings << "\n";
}
