// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDDeform.h"

#include "vtkFFDBuildLattice.h"
#include "vtkFFDCudaBackend.h"
#include "vtkFFDDataContract.h"
#include "vtkFFDForInChunks.h"
#include "vtkFFDLatticeDisplacements.h"
#include "vtkFFDMemory.h"
#include "vtkFFDTetrahedralDeformation.h"

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
#include "vtkSMPThreadLocal.h"
#include "vtkSmartPointer.h"
#include "vtkUnstructuredGrid.h"

#include "FFDGridLanes.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <string>
#include <type_traits>
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
  ffd::GridBasis Basis;
  int Dims[3];                       // control points per axis
  std::vector<double> Displacements; // 3 per control point: point minus RestPosition
};

static_assert(int(ffd::GridBasis::Bernstein) == vtkFFDBuildLattice::BERNSTEIN &&
    int(ffd::GridBasis::Trilinear) == vtkFFDBuildLattice::TRILINEAR &&
    int(ffd::GridBasis::TriquadraticBezier) == vtkFFDBuildLattice::TRIQUADRATIC_BEZIER &&
    int(ffd::GridBasis::TricubicBezier) == vtkFFDBuildLattice::TRICUBIC_BEZIER &&
    int(ffd::GridBasis::CubicBSpline) == vtkFFDBuildLattice::CUBIC_BSPLINE,
  "the kernels' basis values are the FFDBasis values");

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
  int basis;
  if (!vtkFFDDataContract::GetBasis(lattice, basis))
  {
    return "The lattice has no FFDBasis field array (1 int)." + fix;
  }
  if (!ffd::IsGridBasis(basis))
  {
    return "The lattice's FFDBasis " + std::to_string(basis) + " is not a known basis." + fix;
  }
  view.Basis = static_cast<ffd::GridBasis>(basis);
  std::string why;
  if (!vtkFFDBuildLattice::GetControlPointsPerAxis(basis, view.Divisions, view.Dims, why))
  {
    return "The lattice's FFDDivisions do not fit its FFDBasis: " + why;
  }
  const vtkIdType expected = vtkIdType(view.Dims[0]) * view.Dims[1] * view.Dims[2];
  const vtkIdType count = lattice->GetNumberOfPoints();
  if (count != expected)
  {
    std::ostringstream msg;
    msg << "The lattice has " << count << " points but its divisions " << view.Divisions[0] << "x"
        << view.Divisions[1] << "x" << view.Divisions[2] << " and basis "
        << vtkFFDBuildLattice::GetBasisAsString(basis) << " need " << expected << ".";
    return msg.str();
  }
  vtkDataArray* rest = lattice->GetPointData()->GetArray(vtkFFDDataContract::RestPositionArrayName());
  if (!rest || rest->GetNumberOfComponents() != 3 || rest->GetNumberOfTuples() != count)
  {
    return "The lattice has no RestPosition point array of 3 components per point." + fix;
  }
  const vtkIdType notFinite = vtkFFDReadLatticeDisplacements(lattice, rest, view.Displacements, nullptr);
  if (notFinite >= 0)
  {
    return "Lattice point " + std::to_string(notFinite) + " or its RestPosition is not finite.";
  }
  return std::string();
}

//------------------------------------------------------------------------------------------------------------
// Binding: the cell of every point (ffd::BindToGrid), -1 for points that keep their position.
struct BindSettings
{
  ffd::Frame<double> Frame;
  ffd::GridBasis Basis;
  int Voxels[3];
  bool ClampOutside;
};

template <typename PointArrayT>
struct BindFunctor
{
  PointArrayT* Points;
  const BindSettings& Settings;
  int* Cells;

  void operator()(vtkIdType begin, vtkIdType end)
  {
    const auto points = vtk::DataArrayTupleRange<3>(this->Points, begin, end);
    int* cell = this->Cells + begin;
    for (const auto x : points)
    {
      *cell++ = ffd::BindToGrid(this->Settings.Frame, this->Settings.Basis, this->Settings.Voxels,
        { double(x[0]), double(x[1]), double(x[2]) }, this->Settings.ClampOutside);
    }
  }
};

struct BindWorker
{
  template <typename PointArrayT>
  void operator()(
    PointArrayT* points, const BindSettings& settings, int* cells, vtkAlgorithm* self, bool& completed)
  {
    BindFunctor<PointArrayT> functor{ points, settings, cells };
    const vtkIdType n = points->GetNumberOfTuples();
    completed = vtkFFDForInChunks(self, n, vtkFFDGrain(n, 2.0), functor, 0.0, 0.5);
  }
};

//------------------------------------------------------------------------------------------------------------
// The CPU binding of the input's points to a grid lattice: kept while the points and the lattice's rest state
// stay the same (vtkFFDBindingKey).
struct GridBinding
{
  std::vector<int> Cells;      // per input point: its cell (ffd::BindToGrid), -1 where it keeps its position
  ffd::BlockCells Blocks;      // the cells of each block of points (ffd::ListBlockCells)
  ffd::GatheredPoints Gathered; // the points of blocks not deformed in place (ffd::ListGatheredPoints)
  bool CellTable = false;      // evaluation from ffd::FillCellTable (ffd::WorthCellTable)
  // The gathered points' coordinates in their listed order (ffd::CopyGatheredPoints), in the precision of the
  // evaluations that needed them: copied from the input at the first, then read in order by every update.
  std::vector<float> ListedFloat;
  std::vector<double> ListedDouble;
  // Each thread's tile of results (ffd::DeformGathered), kept from update to update: making a vtkSMPThreadLocal
  // and zeroing its buffers at every update cost 8 to 10 us, a tenth of the fixed cost of an update.
  vtkSMPThreadLocal<std::vector<float>> StagingFloat;
  vtkSMPThreadLocal<std::vector<double>> StagingDouble;

  template <typename Real>
  const Real* Listed(const Real* inPoints)
  {
    std::vector<Real>& listed = this->ListedOf(Real());
    const vtkIdType count = vtkIdType(this->Gathered.Order.size());
    if (listed.size() != std::size_t(3 * count))
    {
      listed.resize(std::size_t(3 * count));
      vtkSMPTools::For(0, count, vtkFFDGrain(count, 1.0), [&](vtkIdType begin, vtkIdType end) {
        ffd::CopyGatheredPoints(inPoints, this->Gathered, begin, end, listed.data());
      });
    }
    return listed.data();
  }

  /// The calling thread's staging buffer of ffd::GatherStaging Real values (ffd::DeformGathered).
  template <typename Real>
  Real* Staging()
  {
    std::vector<Real>& staging = this->StagingOf(Real()).Local();
    staging.resize(ffd::GatherStaging);
    return staging.data();
  }

private:
  std::vector<float>& ListedOf(float) { return this->ListedFloat; }
  std::vector<double>& ListedOf(double) { return this->ListedDouble; }
  vtkSMPThreadLocal<std::vector<float>>& StagingOf(float) { return this->StagingFloat; }
  vtkSMPThreadLocal<std::vector<double>>& StagingOf(double) { return this->StagingDouble; }
};

//------------------------------------------------------------------------------------------------------------
// Evaluation in the precision Real of the output points, by a ffd::GridDeformation, one point at a time: for
// points of another type than the output's, or normals of another type than the points'.
template <typename Deformer, typename Real, typename PointArrayT>
struct EvaluateFunctor
{
  PointArrayT* InPoints;
  Real* OutPoints;
  const int* Cells;
  Deformer Deformation;
  vtkDataArray* InNormals; // nullptr: no normals to transform
  vtkDataArray* OutNormals;
  Real* Determinants; // nullptr: not asked for

  void operator()(vtkIdType begin, vtkIdType end)
  {
    const bool needJacobian = this->OutNormals || this->Determinants;
    const auto inPoints = vtk::DataArrayTupleRange<3>(this->InPoints, begin, end);
    vtkIdType id = begin;
    for (const auto x : inPoints)
    {
      const ffd::Vec3<Real> xr = { Real(x[0]), Real(x[1]), Real(x[2]) };
      const int cell = this->Cells[id];
      ffd::Vec3<Real> y = xr;
      ffd::Mat3<Real> jacobian = ffd::Mat3<Real>::Identity();
      if (cell >= 0)
      {
        y = needJacobian ? this->Deformation.Deform(xr, cell, jacobian) : this->Deformation.Deform(xr, cell);
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
    const ffd::Vec3<Real> m = ffd::TransformNormal(jacobian, ffd::Vec3<Real>::From(n));
    this->OutNormals->SetTuple3(id, m.x, m.y, m.z);
  }
};

// Evaluation of the points alone (no normals, no determinants) from points of the output's precision, W at a
// time in SIMD lanes (FFDGridLanes.h): first the blocks deformed in place, then the points of the other blocks,
// gathered by cell at binding, tile by tile.
template <typename Deformer, typename Real>
struct LanesFunctor
{
  const Real* InPoints;
  Real* OutPoints;
  GridBinding& Binding;
  const Real* Listed; // GridBinding::Listed()
  Deformer Deformation;
  bool Stream;       // non-temporal stores in the in-place pass (ffd::StreamOutput())
  bool GatheredPass; // false: over the blocks of points, true: over the tiles of Binding.Gathered

  void operator()(vtkIdType begin, vtkIdType end)
  {
    static const ffd::SimdLevel level = ffd::SimdLevelOfCpu();
    if (this->GatheredPass)
    {
      ffd::DeformGathered(level, this->Deformation, this->Listed, this->Binding.Gathered, this->OutPoints, begin,
        end, this->Binding.template Staging<Real>());
    }
    else
    {
      ffd::DeformBlocksInPlace(level, this->Deformation, this->InPoints, this->Binding.Cells.data(),
        this->OutPoints, this->Binding.Blocks, begin, end, this->Stream);
    }
  }
};

// Evaluation with the Jacobian (normals to transform, determinants), W points at a time in SIMD lanes
// (ffd::DeformWithJacobian), over blocks of ffd::BlockSize points: the last points, fewer than a lane group, are
// deformed one at a time, whatever the split among threads.
template <typename Deformer, typename Real>
struct JacobianFunctor
{
  const Real* InPoints;
  Real* OutPoints;
  const GridBinding& Binding;
  vtkIdType NumberOfPoints;
  const Real* InNormals; // nullptr: no normals to transform
  Real* OutNormals;
  Real* Determinants; // nullptr: not asked for
  Deformer Deformation;

  void operator()(vtkIdType begin, vtkIdType end)
  {
    static const ffd::SimdLevel level = ffd::SimdLevelOfCpu();
    ffd::DeformWithJacobian(level, this->Deformation, this->InPoints, this->Binding.Cells.data(),
      this->Binding.Blocks, this->InNormals, this->OutPoints, this->OutNormals, this->Determinants,
      begin * ffd::BlockSize, std::min(this->NumberOfPoints, end * ffd::BlockSize));
  }
};

template <typename Real>
struct EvaluateWorker
{
  template <typename PointArrayT>
  void operator()(PointArrayT* inPoints, const LatticeView& lattice, GridBinding& binding,
    vtkDataArray* inNormals, vtkDataArray* outNormals, vtkAOSDataArrayTemplate<Real>* outPoints,
    vtkAOSDataArrayTemplate<Real>* determinants, vtkAlgorithm* self, double progressBegin, bool& completed)
  {
    const std::vector<Real> displacements(lattice.Displacements.begin(), lattice.Displacements.end());
    std::vector<Real> cellTable;
    if (binding.CellTable)
    {
      const int cells = lattice.Divisions[0] * lattice.Divisions[1] * lattice.Divisions[2];
      cellTable.resize(std::size_t(cells) * ffd::CellTableStride(ffd::CellDegree(lattice.Basis)));
      vtkSMPTools::For(0, cells, 256, [&](int begin, int end) {
        ffd::FillCellTable(
          lattice.Basis, displacements.data(), lattice.Divisions, lattice.Dims, cellTable.data(), begin, end);
      });
    }
    // One instantiation per basis (see ffd::GridDeformation's StaticBasis). The global basis sums over every
    // control point of an axis, a local one over at most 4.
    auto run = [&](auto maxCount, auto basis, auto withCellTable) {
      this->Run<decltype(maxCount)::value, decltype(basis)::value, decltype(withCellTable)::value>(inPoints,
        lattice, displacements.data(), cellTable.data(), binding, inNormals, outNormals, outPoints, determinants,
        self, progressBegin, completed);
    };
    using NoTable = std::false_type;
    using Local = std::integral_constant<int, 4>;
    // A local basis, with or without its cell table as the binding chose.
    auto runLocal = [&](auto basis) {
      if (binding.CellTable)
      {
        run(Local(), basis, std::true_type());
      }
      else
      {
        run(Local(), basis, NoTable());
      }
    };
    using ffd::GridBasis;
    switch (lattice.Basis)
    {
      case GridBasis::Bernstein:
        run(std::integral_constant<int, ffd::MaxBernsteinDegree + 1>(),
          std::integral_constant<int, int(GridBasis::Bernstein)>(), NoTable());
        break;
      case GridBasis::Trilinear:
        runLocal(std::integral_constant<int, int(GridBasis::Trilinear)>());
        break;
      case GridBasis::TriquadraticBezier:
        runLocal(std::integral_constant<int, int(GridBasis::TriquadraticBezier)>());
        break;
      case GridBasis::TricubicBezier: // never a cell table (ffd::WorthCellTable)
        run(Local(), std::integral_constant<int, int(GridBasis::TricubicBezier)>(), NoTable());
        break;
      case GridBasis::CubicBSpline:
        runLocal(std::integral_constant<int, int(GridBasis::CubicBSpline)>());
        break;
    }
  }

  template <int MaxCount, int StaticBasis, bool WithCellTable, typename PointArrayT>
  void Run(PointArrayT* inPoints, const LatticeView& lattice, const Real* displacements, const Real* cellTable,
    GridBinding& binding, vtkDataArray* inNormals, vtkDataArray* outNormals,
    vtkAOSDataArrayTemplate<Real>* outPoints, vtkAOSDataArrayTemplate<Real>* determinants, vtkAlgorithm* self,
    double progressBegin, bool& completed)
  {
    using Deformation = ffd::GridDeformation<MaxCount, Real, StaticBasis, Real, WithCellTable>;
    const Deformation deformation{ lattice.Basis,
      { lattice.Divisions[0], lattice.Divisions[1], lattice.Divisions[2] },
      { lattice.Dims[0], lattice.Dims[1], lattice.Dims[2] }, displacements,
      ffd::Frame<Real>::FromArray(lattice.Frame), cellTable };
    const vtkIdType n = inPoints->GetNumberOfTuples();
    // The work of a point: the control points it reads, and 16 for its parameters and output.
    double reads = 1.0;
    for (int a = 0; a < 3; ++a)
    {
      reads *= ffd::SupportSize(lattice.Basis, lattice.Divisions[a]);
    }
    const double cost = reads + 16.0;
    const vtkIdType pointGrain = vtkFFDGrain(n, cost);
    const vtkIdType blockGrain = std::max<vtkIdType>(1, pointGrain / ffd::BlockSize);
    if constexpr (std::is_same<PointArrayT, vtkAOSDataArrayTemplate<Real>>::value)
    {
      if (!outNormals && !determinants)
      {
        const Real* in = inPoints->GetPointer(0);
        LanesFunctor<Deformation, Real> lanes{ in, outPoints->GetPointer(0), binding,
          binding.Gathered.Order.empty() ? nullptr : binding.Listed(in), deformation,
          ffd::StreamOutput(std::int64_t(3 * sizeof(Real)) * n), false };
        const vtkIdType blocks = (n + ffd::BlockSize - 1) / ffd::BlockSize;
        const vtkIdType gathered = vtkIdType(binding.Gathered.Order.size());
        const double middle = progressBegin + (1.0 - progressBegin) * double(n - gathered) / double(n);
        completed = binding.Blocks.MaxCells <= 0 || // every block gathered
          vtkFFDForInChunks(self, blocks, blockGrain, lanes, progressBegin, middle);
        lanes.GatheredPass = true;
        completed = completed && vtkFFDForInChunks(self, binding.Gathered.TileCount(), 1, lanes, middle, 1.0);
        return;
      }
      using NormalArray = vtkAOSDataArrayTemplate<Real>;
      NormalArray* normalsIn = NormalArray::FastDownCast(inNormals);
      NormalArray* normalsOut = NormalArray::FastDownCast(outNormals);
      if (!inNormals || (normalsIn && normalsOut))
      {
        JacobianFunctor<Deformation, Real> jacobian{ inPoints->GetPointer(0), outPoints->GetPointer(0), binding,
          n, normalsIn ? normalsIn->GetPointer(0) : nullptr, normalsOut ? normalsOut->GetPointer(0) : nullptr,
          determinants ? determinants->GetPointer(0) : nullptr, deformation };
        completed = vtkFFDForInChunks(
          self, (n + ffd::BlockSize - 1) / ffd::BlockSize, blockGrain, jacobian, progressBegin, 1.0);
        return;
      }
    }
    EvaluateFunctor<Deformation, Real, PointArrayT> functor{ inPoints, outPoints->GetPointer(0),
      binding.Cells.data(), deformation, inNormals, outNormals, determinants ? determinants->GetPointer(0) : nullptr };
    completed = vtkFFDForInChunks(self, n, pointGrain, functor, progressBegin, 1.0);
  }
};

using PointArrays = vtkArrayDispatch::Reals;

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
  auto allocate = [&](auto* typed) {
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
} // namespace

//------------------------------------------------------------------------------------------------------------
// The CPU binding and what it was computed for, and the CUDA backend's state.
struct vtkFFDDeform::vtkInternals
{
  GridBinding Grid;          // the binding to a grid lattice
  vtkFFDBindingKey Bound;    // what Grid is for
  vtkFFDCudaBackend Cuda;
  vtkFFDTetrahedralDeformation Tetrahedra; // the binding and evaluation of tetrahedral lattices
  // The last outputs' arrays: the next update writes into those that nothing else holds any more (OutputArray()).
  KeptArrays Points, Normals, Determinants;
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
vtkTypeBool vtkFFDDeform::ProcessRequest(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  return vtkFFDCatchAllocationFailure(
    this, outputVector, [&] { return this->Superclass::ProcessRequest(request, inputVector, outputVector); });
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
  vtkInternals& internals = *this->Internals;

  vtkPoints* inPoints = input->GetPoints();
  const vtkIdType numberOfPoints = inPoints ? inPoints->GetNumberOfPoints() : 0;
  if (numberOfPoints == 0)
  {
    output->CopyStructure(input);
    output->GetPointData()->PassData(input->GetPointData());
    output->GetCellData()->PassData(input->GetCellData());
    return 1;
  }

  vtkUnstructuredGrid* tetrahedra = vtkFFDTetrahedralDeformation::IsTetrahedralLattice(lattice)
    ? vtkUnstructuredGrid::SafeDownCast(lattice)
    : nullptr;
  LatticeView view;
  const std::string problem = tetrahedra ? internals.Tetrahedra.SetLattice(tetrahedra) : ReadLattice(lattice, view);
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

  // The outputs, in the precision of the evaluation; either backend fills them.
  const bool useDouble = this->OutputPointsPrecision == vtkAlgorithm::DOUBLE_PRECISION ||
    (this->OutputPointsPrecision == vtkAlgorithm::DEFAULT_PRECISION && inPoints->GetDataType() == VTK_DOUBLE);
  const int realType = useDouble ? VTK_DOUBLE : VTK_FLOAT;
  vtkDataArray* inNormals = this->TransformNormals ? input->GetPointData()->GetNormals() : nullptr;
  if (inNormals && (inNormals->GetNumberOfComponents() != 3 || inNormals->GetNumberOfTuples() != numberOfPoints))
  {
    vtkWarningMacro("The input's point normals have " << inNormals->GetNumberOfTuples() << " tuples of "
                                                      << inNormals->GetNumberOfComponents() << " components for "
                                                      << numberOfPoints
                                                      << " points, not one of 3 per point; they are not transformed.");
    inNormals = nullptr;
  }
  vtkSmartPointer<vtkDataArray> outNormals;
  if (inNormals)
  {
    outNormals = OutputArray(internals.Normals, inNormals, 3, numberOfPoints);
    outNormals->SetName(inNormals->GetName());
  }
  const vtkSmartPointer<vtkDataArray> realArray = vtk::TakeSmartPointer(vtkDataArray::CreateDataArray(realType));
  const auto pointsArray = OutputArray(internals.Points, realArray, 3, numberOfPoints);
  vtkSmartPointer<vtkDataArray> determinants;
  if (this->ComputeJacobianDeterminant)
  {
    determinants = OutputArray(internals.Determinants, realArray, 1, numberOfPoints);
    determinants->SetName(JacobianDeterminantArrayName());
  }

  // On the GPU where the Backend setting and a device allow it: true when `deform(why)` deformed there; false when
  // the CPU must, with a warning where CUDA was asked for and cannot run, or failed.
  auto deformedOnCuda = [this](auto&& deform) {
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
  };

  if (tetrahedra)
  {
    // The binding needs VTK's cell locator: on the CPU for either backend, then cached.
    bool rebound = false;
    if (!internals.Tetrahedra.Bind(inPoints, this->OutsidePolicy, this, 0.0, 0.5, rebound))
    {
      return 1; // aborted: the output stays empty
    }
    if (rebound)
    {
      ++this->NumberOfBindings;
      if (internals.Tetrahedra.GetNumberOfDegenerateTetrahedra() > 0)
      {
        vtkWarningMacro(<< internals.Tetrahedra.GetNumberOfDegenerateTetrahedra() << " of "
                        << internals.Tetrahedra.GetNumberOfTetrahedra()
                        << " tetrahedra of the lattice have no volume (the first is cell "
                        << internals.Tetrahedra.GetFirstDegenerateTetrahedron()
                        << "); they are skipped: points in them are bound to a neighbour or follow the "
                           "outside policy.");
      }
    }
    if (!deformedOnCuda([&](std::string& why) {
          return internals.Cuda.DeformTetrahedra(
            internals.Tetrahedra, inPoints, inNormals, pointsArray, outNormals, determinants, why);
        }))
    {
      if (!internals.Tetrahedra.Evaluate(
            inPoints, inNormals, pointsArray, outNormals, determinants, this, 0.5, 1.0))
      {
        return 1; // aborted: the output stays empty
      }
      this->LastBackendUsed = "CPU";
    }
    this->FillOutput(input, output, pointsArray, outNormals, determinants);
    return 1;
  }

  const vtkFFDBindingKey key = vtkFFDBindingKey::Of(
    inPoints, view.Frame, view.Divisions, static_cast<int>(view.Basis), this->OutsidePolicy);
  bool bound = false;
  const bool done = deformedOnCuda([&](std::string& why) {
    return internals.Cuda.Deform(key, inPoints, inNormals, view.Displacements.data(),
      vtkIdType(view.Displacements.size() / 3), pointsArray, outNormals, determinants, bound, why);
  });
  this->NumberOfBindings += bound ? 1 : 0;
  if (!done)
  {
    // CPU binding, only when the points or the lattice's rest frame or shape or the policy changed.
    if (key != internals.Bound)
    {
      internals.Bound = vtkFFDBindingKey();
      internals.Grid.Cells.resize(numberOfPoints);
      const BindSettings settings{ ffd::Frame<double>::FromArray(view.Frame), view.Basis,
        { view.Divisions[0], view.Divisions[1], view.Divisions[2] }, this->OutsidePolicy == CLAMP_TO_EDGE };
      bool completed = false;
      BindWorker bind;
      if (!vtkArrayDispatch::DispatchByValueType<PointArrays>::Execute(
            inPoints->GetData(), bind, settings, internals.Grid.Cells.data(), this, completed))
      {
        bind(inPoints->GetData(), settings, internals.Grid.Cells.data(), this, completed);
      }
      if (!completed)
      {
        return 1; // aborted: the output stays empty
      }
      int cellCount = 1;
      for (int a = 0; a < 3; ++a)
      {
        cellCount *= ffd::BindingCells(view.Basis, view.Divisions[a]);
      }
      GridBinding& grid = internals.Grid;
      grid.CellTable = ffd::WorthCellTable(view.Basis, cellCount, numberOfPoints);
      const int maxCellsInPlace = ffd::MaxCellsInPlace(
        view.Basis, ffd::MeanCellsPerBlock(grid.Cells.data(), numberOfPoints), grid.CellTable);
      grid.Blocks = ffd::ListBlockCells(grid.Cells.data(), numberOfPoints, maxCellsInPlace);
      grid.Gathered = ffd::ListGatheredPoints(grid.Cells.data(), numberOfPoints, cellCount, maxCellsInPlace);
      grid.ListedFloat.clear();
      grid.ListedDouble.clear();
      internals.Bound = key;
      ++this->NumberOfBindings;
    }
    this->UpdateProgress(0.5);

    bool completed = false;
    auto evaluate = [&](auto realTag) {
      using Real = decltype(realTag);
      using RealArray = vtkAOSDataArrayTemplate<Real>;
      EvaluateWorker<Real> worker;
      auto* points = static_cast<RealArray*>(pointsArray.Get());
      auto* det = static_cast<RealArray*>(determinants.Get());
      if (!vtkArrayDispatch::DispatchByValueType<PointArrays>::Execute(inPoints->GetData(), worker, view,
            internals.Grid, inNormals, outNormals.Get(), points, det, this, 0.5, completed))
      {
        worker(inPoints->GetData(), view, internals.Grid, inNormals, outNormals.Get(), points, det, this, 0.5,
          completed);
      }
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
    this->LastBackendUsed = "CPU";
  }

  this->FillOutput(input, output, pointsArray, outNormals, determinants);
  return 1;
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDDeform::FillOutput(vtkPointSet* input, vtkPointSet* output, vtkDataArray* pointsArray,
  vtkDataArray* outNormals, vtkDataArray* determinants)
{
  vtkNew<vtkPoints> outPoints;
  outPoints->SetData(pointsArray);
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
  this->Internals->Points.Keep(pointsArray);
  this->Internals->Normals.Keep(outNormals);
  this->Internals->Determinants.Keep(determinants);
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
