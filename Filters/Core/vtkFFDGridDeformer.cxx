// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDGridDeformer.h"

#include "vtkFFDBuildLattice.h"
#include "vtkFFDDataContract.h"
#include "vtkFFDDeform.h"
#include "vtkFFDDeformPoints.h"
#include "vtkFFDForInChunks.h"
#include "vtkFFDLatticeDisplacements.h"
#include "vtkFFDSparseLattice.h"

#include "vtkAOSDataArrayTemplate.h"
#include "vtkArrayDispatch.h"
#include "vtkDataArray.h"
#include "vtkDataArrayRange.h"
#include "vtkIntArray.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkSMPThreadLocal.h"
#include "vtkSMPTools.h"
#include "vtkStructuredGrid.h"
#include "vtkUnstructuredGrid.h"

#include "FFDCellTable.h"
#include "FFDGridPasses.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

namespace
{
using PointArrays = vtkArrayDispatch::Reals;

/// What to do about a lattice that breaks the data contract.
const std::string ContractFix = " Build the lattice with vtkFFDBuildLattice, or keep its data contract "
                                "(see vtkFFDDataContract).";

//------------------------------------------------------------------------------------------------------------
// The first point of `lattice` (of `view`) whose RestPosition lies farther than `tolerance` (per coordinate) from
// the rest position its frame gives it (vtkFFDRestPoint), or -1; `expected` is then that rest position.
vtkIdType FirstMovedRestPosition(vtkPointSet* lattice, vtkDataArray* rest, const vtkFFDGridLattice& view,
  double tolerance, ffd::Vec3<double>& expected)
{
  const vtkIdType count = lattice->GetNumberOfPoints();
  const ffd::Frame<double> frame = ffd::Frame<double>::FromArray(view.Frame);
  const int* dims = view.ControlPointsPerAxis;
  vtkIntArray* index = view.Sparse
    ? vtkIntArray::SafeDownCast(lattice->GetPointData()->GetAbstractArray(vtkFFDDataContract::LatticeIndexArrayName()))
    : nullptr; // checked by vtkFFDSparseCells::Read()
  auto restPointOf = [&](vtkIdType p)
  {
    int ijk[3] = { int(p % dims[0]), int(p / dims[0] % dims[1]), int(p / dims[0] / dims[1]) };
    if (index)
    {
      index->GetTypedTuple(p, ijk);
    }
    return vtkFFDRestPoint(frame, view.Basis, view.Divisions, ijk[0], ijk[1], ijk[2]);
  };
  std::atomic<vtkIdType> first(count);
  auto check = [&](auto* restPositions)
  {
    const auto x0 = vtk::DataArrayTupleRange<3>(restPositions);
    vtkSMPTools::For(0, count, 4096,
      [&](vtkIdType begin, vtkIdType end)
      {
        for (vtkIdType p = begin; p < end && p < first; ++p)
        {
          const ffd::Vec3<double> x = restPointOf(p);
          if (!(std::fabs(x0[p][0] - x.x) <= tolerance && std::fabs(x0[p][1] - x.y) <= tolerance &&
                std::fabs(x0[p][2] - x.z) <= tolerance))
          {
            vtkIdType seen = first.load();
            while (p < seen && !first.compare_exchange_weak(seen, p))
            {
            }
          }
        }
      });
  };
  if (!vtkArrayDispatch::DispatchByValueType<vtkArrayDispatch::Reals>::Execute(rest, check))
  {
    check(rest);
  }
  if (first == count)
  {
    return -1;
  }
  expected = restPointOf(first);
  return first;
}

//------------------------------------------------------------------------------------------------------------
// A grid lattice's rest positions are fixed by its frame (docs/pipeline-and-data-contract.md, "Data contract"). They
// leave it where a transform moved RestPosition as a vector together with the points (vtkTransformFilter's
// TransformAllInputVectors, on by default in ParaView's Transform): the lattice would then deform nothing however it
// was rotated or scaled. The check runs again only when the arrays or the frame change (`checked`).
std::string CheckRestPositions(
  vtkPointSet* lattice, vtkDataArray* rest, const vtkFFDGridLattice& view, vtkFFDRestCheck& checked)
{
  vtkAbstractArray* index =
    view.Sparse ? lattice->GetPointData()->GetAbstractArray(vtkFFDDataContract::LatticeIndexArrayName()) : nullptr;
  vtkFFDRestCheck key;
  key.Arrays[0] = rest;
  key.Times[0] = rest->GetMTime();
  key.Arrays[1] = index;
  key.Times[1] = index ? index->GetMTime() : 0;
  key.Count = lattice->GetNumberOfPoints();
  std::copy(view.Frame, view.Frame + 12, key.Frame);
  std::copy(view.Divisions, view.Divisions + 3, key.Divisions);
  key.Basis = int(view.Basis);
  if (key == checked)
  {
    return std::string();
  }
  checked = vtkFFDRestCheck();
  // 1e-9 of the frame's extent: far above the rounding of any evaluation of the formula (a few 1e-16), far below
  // what a rotation or scaling that matters moves.
  double extent = 0.0;
  for (int c = 0; c < 3; ++c)
  {
    extent = std::max(extent,
      std::fabs(view.Frame[c]) + std::fabs(view.Frame[3 + c]) + std::fabs(view.Frame[6 + c]) +
        std::fabs(view.Frame[9 + c]));
  }
  const double tolerance = 1e-9 * extent;
  ffd::Vec3<double> expected;
  const vtkIdType moved = FirstMovedRestPosition(lattice, rest, view, tolerance, expected);
  if (moved >= 0)
  {
    double x0[3];
    rest->GetTuple(moved, x0);
    std::ostringstream msg;
    msg << "The RestPosition of lattice point " << moved << ", (" << x0[0] << ", " << x0[1] << ", " << x0[2]
        << "), is not the rest position (" << expected.x << ", " << expected.y << ", " << expected.z
        << ") that the lattice's FFDFrame gives it (tolerance " << tolerance
        << ", 1e-9 of the frame's extent): the lattice's RestPosition/VoxelIndex no longer match its FFDFrame. A "
           "transform moved them as vectors (VTK's vtkTransformFilter / ParaView's Transform with "
           "TransformAllInputVectors on); transform the lattice with that option off, so that only its points move. "
           "Without a transform, rebuild the lattice with vtkFFDBuildLattice, or keep its RestPosition where the "
           "frame puts it (docs/pipeline-and-data-contract.md, \"Data contract\").";
    return msg.str();
  }
  checked = key;
  return std::string();
}

//------------------------------------------------------------------------------------------------------------
std::vector<double>& DisplacementsIn(vtkFFDGridLattice& view, double)
{
  return view.Displacements;
}

std::vector<float>& DisplacementsIn(vtkFFDGridLattice& view, float)
{
  return view.FloatDisplacements;
}

// Reads view's displacements (`count`) from its Points and RestPosition into its vector of precision Real, the other
// one freed unless it keeps doubles, or, where Real is void, only checks them. Returns what
// vtkFFDReadLatticeDisplacements() returns.
template <typename Real>
vtkIdType ReadDisplacementsAs(vtkFFDGridLattice& view, vtkIdType count)
{
  if constexpr (std::is_void<Real>::value)
  {
    std::vector<double>().swap(view.Displacements);
    std::vector<float>().swap(view.FloatDisplacements);
    return vtkFFDReadLatticeDisplacements<double>(view.Points, view.RestPosition, count, nullptr, nullptr);
  }
  else
  {
    if constexpr (std::is_same<Real, double>::value)
    {
      std::vector<float>().swap(view.FloatDisplacements);
    }
    else if (!view.KeepDisplacements)
    {
      std::vector<double>().swap(view.Displacements);
    }
    std::vector<Real>& values = DisplacementsIn(view, Real());
    values.resize(std::size_t(3 * count));
    return vtkFFDReadLatticeDisplacements(view.Points, view.RestPosition, count, values.data(), nullptr);
  }
}

// ReadDisplacementsAs() in view's ReadPrecision.
vtkIdType ReadDisplacements(vtkFFDGridLattice& view, vtkIdType count)
{
  switch (view.ReadPrecision)
  {
    case VTK_DOUBLE:
      return ReadDisplacementsAs<double>(view, count);
    case VTK_FLOAT:
      return ReadDisplacementsAs<float>(view, count);
    default:
      return ReadDisplacementsAs<void>(view, count);
  }
}

// The displacements of view in the evaluation's precision Real: those SetLattice() read in it, or read now (checked by
// SetLattice()); a deformer that does not keep doubles reads them in Real from then on.
template <typename Real>
const Real* EvaluationDisplacements(vtkFFDGridLattice& view)
{
  const int precision = std::is_same<Real, double>::value ? VTK_DOUBLE : VTK_FLOAT;
  if (view.ReadPrecision != precision)
  {
    ReadDisplacementsAs<Real>(view, view.Points->GetNumberOfTuples());
    view.ReadPrecision = view.KeepDisplacements ? VTK_DOUBLE : precision;
  }
  return DisplacementsIn(view, Real()).data();
}

//------------------------------------------------------------------------------------------------------------
// The point arrays of a lattice whose cells `view` holds: RestPosition (doubles, where the frame puts them), Active
// (where present), and the points and RestPosition, into `view` with the displacements in its ReadPrecision.
std::string ReadPointArrays(vtkPointSet* lattice, vtkFFDGridLattice& view, vtkFFDRestCheck& restChecked)
{
  const vtkIdType count = lattice->GetNumberOfPoints();
  vtkDataArray* rest = lattice->GetPointData()->GetArray(vtkFFDDataContract::RestPositionArrayName());
  if (!rest || rest->GetNumberOfComponents() != 3 || rest->GetNumberOfTuples() != count)
  {
    return "The lattice has no RestPosition point array of 3 components per point." + ContractFix;
  }
  vtkDataArray* active = lattice->GetPointData()->GetArray(vtkFFDDataContract::ActiveArrayName());
  if (active && (active->GetNumberOfComponents() != 1 || active->GetNumberOfTuples() != count))
  {
    return "The lattice's Active point array does not have one value per point: it has " +
      std::to_string(active->GetNumberOfTuples()) + " tuples of " + std::to_string(active->GetNumberOfComponents()) +
      " components for " + std::to_string(count) + " points." + ContractFix;
  }
  std::string why = vtkFFDCheckLatticePrecision(lattice, rest, "The lattice");
  if (!why.empty())
  {
    return why;
  }
  view.Points = lattice->GetPoints()->GetData();
  view.RestPosition = rest;
  const vtkIdType bad = ReadDisplacements(view, count);
  if (bad >= 0)
  {
    return vtkFFDLatticePointProblem(lattice, rest, bad, "Lattice point");
  }
  return CheckRestPositions(lattice, rest, view, restChecked);
}

//------------------------------------------------------------------------------------------------------------
// Why a dense lattice's points are not its control points in VTK structured order, or an empty string: their count,
// and a vtkStructuredGrid's dimensions, which consumers of the grid (rendering, widgets) index it by.
std::string DenseShapeProblem(vtkPointSet* lattice, const vtkFFDGridLattice& view)
{
  const int* n = view.ControlPointsPerAxis;
  const vtkIdType expected = vtkIdType(n[0]) * n[1] * n[2];
  const vtkIdType count = lattice->GetNumberOfPoints();
  std::ostringstream msg;
  if (count != expected)
  {
    msg << "The lattice has " << count << " points but its divisions " << view.Divisions[0] << "x" << view.Divisions[1]
        << "x" << view.Divisions[2] << " and basis " << vtkFFDBuildLattice::GetBasisAsString(int(view.Basis))
        << " need " << expected << ".";
    return msg.str();
  }
  int dims[3] = { n[0], n[1], n[2] };
  if (vtkStructuredGrid* grid = vtkStructuredGrid::SafeDownCast(lattice))
  {
    grid->GetDimensions(dims);
  }
  if (!std::equal(dims, dims + 3, n))
  {
    msg << "The lattice's dimensions " << dims[0] << "x" << dims[1] << "x" << dims[2] << " are not the " << n[0] << "x"
        << n[1] << "x" << n[2] << " control points that its FFDDivisions and FFDBasis give (control point (i, j, k) "
        << "is point i + nI (j + nJ k))." << ContractFix;
    return msg.str();
  }
  return std::string();
}

//------------------------------------------------------------------------------------------------------------
// Reads a lattice per the data contract; returns an empty string or what is wrong with it. Its FFDBasis holds
// vtkFFDBuildLattice's values, which vtkFFDBuildLattice.cxx asserts are ffd::GridBasis's.
std::string ReadLattice(
  vtkPointSet* lattice, vtkFFDGridLattice& view, vtkFFDSparseCells& sparseCells, vtkFFDRestCheck& restChecked)
{
  if (!lattice)
  {
    return "The lattice on input port 1 is not a vtkPointSet." + ContractFix;
  }
  if (!vtkFFDDataContract::GetFrame(lattice, view.Frame))
  {
    return "The lattice has no valid FFDFrame field array (12 finite doubles)." + ContractFix;
  }
  if (const ffd::FrameStatus status = ffd::CheckFrame(view.Frame); status != ffd::FrameStatus::Valid)
  {
    return std::string("The lattice's FFDFrame ") + ffd::DescribeFrameStatus(status) + ".";
  }
  if (!vtkFFDDataContract::GetDivisions(lattice, view.Divisions))
  {
    return "The lattice has no valid FFDDivisions field array (3 ints >= 1)." + ContractFix;
  }
  int basis;
  if (!vtkFFDDataContract::GetBasis(lattice, basis))
  {
    return "The lattice has no FFDBasis field array (1 int)." + ContractFix;
  }
  if (!ffd::IsGridBasis(basis))
  {
    return "The lattice's FFDBasis " + std::to_string(basis) + " is not a known basis." + ContractFix;
  }
  view.Basis = static_cast<ffd::GridBasis>(basis);
  // A sparse lattice holds the control points of its cells: its own count, not the whole lattice's.
  view.Sparse = lattice->GetPointData()->GetAbstractArray(vtkFFDDataContract::LatticeIndexArrayName()) != nullptr;
  vtkUnstructuredGrid* sparse = vtkUnstructuredGrid::SafeDownCast(lattice);
  if (view.Sparse && (!sparse || view.Basis == ffd::GridBasis::Bernstein))
  {
    return "The lattice has a LatticeIndex point array, so it is sparse, but it is not a vtkUnstructuredGrid of a "
           "local basis: a global Bernstein lattice is dense." +
      ContractFix;
  }
  std::string why;
  if (!vtkFFDBuildLattice::GetControlPointsPerAxis(basis, view.Divisions, view.ControlPointsPerAxis, why,
        view.Sparse ? vtkFFDBuildLattice::SPARSE : vtkFFDBuildLattice::DENSE))
  {
    return "The lattice's FFDDivisions do not fit its FFDBasis: " + why;
  }
  why = view.Sparse ? sparseCells.Read(sparse, view.Basis, view.Divisions) : DenseShapeProblem(lattice, view);
  if (!why.empty())
  {
    return why;
  }
  return ReadPointArrays(lattice, view, restChecked);
}

//------------------------------------------------------------------------------------------------------------
// Binding: the cell of every point (ffd::BindToGrid), -1 for points that keep their position.
struct BindSettings
{
  const ffd::Frame<double>& Frame;
  ffd::GridBasis Basis;
  int Voxels[3];
  bool ClampOutside;
  const vtkFFDSparseCells* SparseCells; // null for a dense lattice
};

// `frame` is the lattice's with its dual basis (ffd::Frame::FromArray()), made once per lattice: building it is most
// of the cost of binding one point.
BindSettings SettingsOf(
  const ffd::Frame<double>& frame, const vtkFFDGridLattice& lattice, const vtkFFDSparseCells* sparse, bool clampOutside)
{
  return { frame, lattice.Basis, { lattice.Divisions[0], lattice.Divisions[1], lattice.Divisions[2] }, clampOutside,
    sparse };
}

int BindOne(const BindSettings& s, const ffd::Vec3<double>& p)
{
  if (!s.SparseCells)
  {
    return ffd::BindToGrid(s.Frame, s.Basis, s.Voxels, p, s.ClampOutside);
  }
  // A sparse lattice's cell of the point's voxel, -1 where it has none.
  int v[3];
  return ffd::BindToCells(s.Frame, s.Voxels, p, s.ClampOutside, v)
    ? s.SparseCells->Find(vtkFFDFlatIndex(v[0], v[1], v[2], s.Voxels))
    : -1;
}

template <typename PointArrayT>
struct BindFunctor
{
  PointArrayT* Points;
  const BindSettings& Settings;
  int* CellOfPoint;

  void operator()(vtkIdType begin, vtkIdType end)
  {
    const auto points = vtk::DataArrayTupleRange<3>(this->Points, begin, end);
    int* cell = this->CellOfPoint + begin;
    for (const auto x : points)
    {
      *cell++ = BindOne(this->Settings, { double(x[0]), double(x[1]), double(x[2]) });
    }
  }
};

struct BindWorker
{
  template <typename PointArrayT>
  void operator()(PointArrayT* points, const BindSettings& settings, int* cells, vtkAlgorithm* self,
    double progressBegin, double progressEnd, bool& completed)
  {
    BindFunctor<PointArrayT> functor{ points, settings, cells };
    const vtkIdType n = points->GetNumberOfTuples();
    completed = vtkFFDForInChunks(self, n, vtkFFDGrain(n, 2.0), functor, progressBegin, progressEnd);
  }
};
} // namespace

//------------------------------------------------------------------------------------------------------------
// The CPU binding of the input's points to a grid lattice: kept while the points and the lattice's rest state
// stay the same (vtkFFDBindingKey).
struct vtkFFDGridBinding
{
  std::vector<int> CellOfPoint; // per input point: its cell (ffd::BindToGrid), -1 where it keeps its position
  ffd::BlockCells Blocks;       // the cells of each block of points (ffd::ListBlockCells)
  ffd::GatheredPoints Gathered; // the points of blocks not deformed in place (ffd::ListGatheredPoints)
  bool CellTable = false;       // evaluation from ffd::FillCellTable (ffd::WorthCellTable)
  // The gathered points' coordinates in their listed order (ffd::CopyGatheredPoints), in the precision of the
  // evaluations that needed them: copied from the input at the first, then read in order by every update.
  std::vector<float> ListedFloat;
  std::vector<double> ListedDouble;
  // Each thread's tile of results (ffd::DeformGathered), kept from update to update: making a vtkSMPThreadLocal
  // and zeroing its buffers at every update is a noticeable part of an update's fixed cost.
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
      vtkSMPTools::For(0, count, vtkFFDGrain(count, 1.0),
        [&](vtkIdType begin, vtkIdType end)
        { ffd::CopyGatheredPoints(inPoints, this->Gathered, begin, end, listed.data()); });
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

namespace
{
// vtkFFDGridDeformer::PassLattice() in either precision.
template <typename Real>
ffd::GridLattice<Real> PassLatticeOf(const vtkFFDGridLattice& lattice, const vtkFFDSparseCells* sparse,
  const Real* displacements, bool withCellTable, std::vector<Real>& table)
{
  ffd::GridLattice<Real> pass{ lattice.Basis, { lattice.Divisions[0], lattice.Divisions[1], lattice.Divisions[2] },
    { lattice.ControlPointsPerAxis[0], lattice.ControlPointsPerAxis[1], lattice.ControlPointsPerAxis[2] },
    displacements, ffd::Frame<Real>::FromArray(lattice.Frame), nullptr, sparse ? sparse->GetVoxels().data() : nullptr,
    sparse ? sparse->GetSupports() : nullptr };
  if (withCellTable)
  {
    const int cells =
      sparse ? sparse->GetNumberOfCells() : lattice.Divisions[0] * lattice.Divisions[1] * lattice.Divisions[2];
    table.resize(std::size_t(cells) * ffd::CellTableStride(ffd::CellDegree(lattice.Basis)));
    vtkSMPTools::For(0, cells, 256,
      [&](int begin, int end)
      {
        ffd::FillCellTable(pass.Basis, displacements, pass.Voxels, pass.Dims, pass.CellVoxels, pass.CellSupports,
          table.data(), begin, end);
      });
    pass.CellTable = table.data();
  }
  return pass;
}

// Evaluation of the points alone (no normals, no determinants) from points of the output's precision, W at a
// time in SIMD lanes (FFDGridPasses.h): first the blocks deformed in place, then the points of the other blocks,
// gathered by cell at binding, tile by tile.
template <typename Real>
struct LanesFunctor
{
  const Real* InPoints;
  Real* OutPoints;
  vtkFFDGridBinding& Binding;
  const Real* Listed; // vtkFFDGridBinding::Listed()
  ffd::GridLattice<Real> Lattice;
  bool Stream;       // non-temporal stores in the in-place pass (ffd::StreamOutput())
  bool GatheredPass; // false: over the blocks of points, true: over the tiles of Binding.Gathered

  void operator()(vtkIdType begin, vtkIdType end)
  {
    static const ffd::SimdLevel level = ffd::SimdLevelOfCpu();
    if (this->GatheredPass)
    {
      ffd::DeformGathered(level, this->Lattice, this->Listed, this->Binding.Gathered, this->OutPoints, begin, end,
        this->Binding.template Staging<Real>());
    }
    else
    {
      ffd::DeformBlocksInPlace(level, this->Lattice, this->InPoints, this->Binding.CellOfPoint.data(), this->OutPoints,
        this->Binding.Blocks, begin, end, this->Stream);
    }
  }
};

// Evaluation with the Jacobian (normals to transform, determinants), W points at a time in SIMD lanes
// (ffd::DeformWithJacobian), over blocks of ffd::BlockSize points: the last points, fewer than a lane group, are
// deformed one at a time, whatever the split among threads.
template <typename Real>
struct JacobianFunctor
{
  const Real* InPoints;
  Real* OutPoints;
  const vtkFFDGridBinding& Binding;
  vtkIdType NumberOfPoints;
  const Real* InNormals; // nullptr: no normals to transform
  Real* OutNormals;
  Real* Determinants; // nullptr: not asked for
  ffd::GridLattice<Real> Lattice;

  void operator()(vtkIdType begin, vtkIdType end)
  {
    static const ffd::SimdLevel level = ffd::SimdLevelOfCpu();
    ffd::DeformWithJacobian(level, this->Lattice, this->InPoints, this->Binding.CellOfPoint.data(),
      this->Binding.Blocks, this->InNormals, this->OutPoints, this->OutNormals, this->Determinants,
      begin * ffd::BlockSize, std::min(this->NumberOfPoints, end * ffd::BlockSize));
  }
};

template <typename Real>
struct EvaluateWorker
{
  const vtkFFDGridDeformer& Deformer;
  const Real* Displacements; // the lattice's, in Real (EvaluationDisplacements())

  template <typename PointArrayT>
  void operator()(PointArrayT* inPoints, const vtkFFDGridLattice& lattice, vtkFFDGridBinding& binding,
    vtkDataArray* inNormals, vtkDataArray* outNormals, vtkAOSDataArrayTemplate<Real>* outPoints,
    vtkAOSDataArrayTemplate<Real>* determinants, vtkAlgorithm* self, double progressBegin, double progressEnd,
    bool& completed)
  {
    std::vector<Real> cellTable;
    const ffd::GridLattice<Real> passLattice =
      this->Deformer.PassLattice(this->Displacements, binding.CellTable, cellTable);
    const vtkIdType n = inPoints->GetNumberOfTuples();
    // The work of a point: the control points it reads, and 16 for its parameters and output.
    double reads = 1.0;
    for (int a = 0; a < 3; ++a)
    {
      reads *= ffd::SupportSize(lattice.Basis, lattice.Divisions[a]);
    }
    const vtkIdType pointGrain = vtkFFDGrain(n, reads + 16.0);
    if constexpr (std::is_same<PointArrayT, vtkAOSDataArrayTemplate<Real>>::value)
    {
      if (this->InLanes(inPoints->GetPointer(0), n, passLattice, binding, inNormals, outNormals, outPoints,
            determinants, self, pointGrain, progressBegin, progressEnd, completed))
      {
        return;
      }
    }
    // Points of another type or layout (or normals of another): the same kernels one point at a time.
    ffd::WithGridDeformation(passLattice,
      [&](const auto& deformation)
      {
        completed = vtkFFDDeformPoints(inPoints, binding.CellOfPoint.data(), deformation, inNormals, outNormals,
          outPoints->GetPointer(0), determinants ? determinants->GetPointer(0) : nullptr, self, pointGrain,
          progressBegin, progressEnd);
      });
  }

  // The passes of FFDGridPasses.h over points of the output's precision; false where the normals are of
  // another type.
  bool InLanes(const Real* in, vtkIdType n, const ffd::GridLattice<Real>& lattice, vtkFFDGridBinding& binding,
    vtkDataArray* inNormals, vtkDataArray* outNormals, vtkAOSDataArrayTemplate<Real>* outPoints,
    vtkAOSDataArrayTemplate<Real>* determinants, vtkAlgorithm* self, vtkIdType pointGrain, double progressBegin,
    double progressEnd, bool& completed)
  {
    const vtkIdType blockGrain = std::max<vtkIdType>(1, pointGrain / ffd::BlockSize);
    const vtkIdType blocks = (n + ffd::BlockSize - 1) / ffd::BlockSize;
    if (!outNormals && !determinants)
    {
      LanesFunctor<Real> lanes{ in, outPoints->GetPointer(0), binding,
        binding.Gathered.Order.empty() ? nullptr : binding.Listed(in), lattice,
        ffd::StreamOutput(std::int64_t(3 * sizeof(Real)) * n), false };
      const vtkIdType gathered = vtkIdType(binding.Gathered.Order.size());
      const double middle = progressBegin + (progressEnd - progressBegin) * double(n - gathered) / double(n);
      completed = binding.Blocks.MaxCells <= 0 || // every block gathered
        vtkFFDForInChunks(self, blocks, blockGrain, lanes, progressBegin, middle);
      lanes.GatheredPass = true;
      completed = completed && vtkFFDForInChunks(self, binding.Gathered.TileCount(), 1, lanes, middle, progressEnd);
      return true;
    }
    using NormalArray = vtkAOSDataArrayTemplate<Real>;
    NormalArray* normalsIn = NormalArray::FastDownCast(inNormals);
    NormalArray* normalsOut = NormalArray::FastDownCast(outNormals);
    if (inNormals && !(normalsIn && normalsOut))
    {
      return false;
    }
    JacobianFunctor<Real> jacobian{ in, outPoints->GetPointer(0), binding, n,
      normalsIn ? normalsIn->GetPointer(0) : nullptr, normalsOut ? normalsOut->GetPointer(0) : nullptr,
      determinants ? determinants->GetPointer(0) : nullptr, lattice };
    completed = vtkFFDForInChunks(self, blocks, blockGrain, jacobian, progressBegin, progressEnd);
    return true;
  }
};
} // namespace

//------------------------------------------------------------------------------------------------------------
bool vtkFFDRestCheck::operator==(const vtkFFDRestCheck& other) const
{
  return std::equal(this->Arrays, this->Arrays + 2, other.Arrays) &&
    std::equal(this->Times, this->Times + 2, other.Times) && this->Count == other.Count &&
    std::equal(this->Frame, this->Frame + 12, other.Frame) &&
    std::equal(this->Divisions, this->Divisions + 3, other.Divisions) && this->Basis == other.Basis;
}

//------------------------------------------------------------------------------------------------------------
vtkFFDGridDeformer::vtkFFDGridDeformer(bool keepDisplacements)
  : Binding(new vtkFFDGridBinding)
{
  this->Lattice.KeepDisplacements = keepDisplacements;
  this->Lattice.ReadPrecision = keepDisplacements ? VTK_DOUBLE : 0; // else that of the last evaluation
}

vtkFFDGridDeformer::~vtkFFDGridDeformer() = default;

//------------------------------------------------------------------------------------------------------------
const double* vtkFFDGridDeformer::ReadDisplacements(std::vector<double>& storage) const
{
  const vtkFFDGridLattice& lattice = this->Lattice;
  if (lattice.ReadPrecision == VTK_DOUBLE)
  {
    return lattice.Displacements.data();
  }
  const vtkIdType count = lattice.Points->GetNumberOfTuples();
  storage.resize(std::size_t(3 * count));
  vtkFFDReadLatticeDisplacements(lattice.Points, lattice.RestPosition, count, storage.data(), nullptr);
  return storage.data();
}

//------------------------------------------------------------------------------------------------------------
std::string vtkFFDGridDeformer::SetLattice(vtkPointSet* lattice)
{
  std::string problem = ReadLattice(lattice, this->Lattice, this->SparseCells, this->RestChecked);
  if (problem.empty())
  {
    this->BindFrame = ffd::Frame<double>::FromArray(this->Lattice.Frame);
  }
  return problem;
}

//------------------------------------------------------------------------------------------------------------
vtkFFDBindingKey vtkFFDGridDeformer::KeyOf(vtkPoints* points, int outsidePolicy) const
{
  const vtkFFDSparseCells* sparse = this->GetSparseCells();
  return vtkFFDBindingKey::OfGrid(points, outsidePolicy, this->Lattice.Frame, this->Lattice.Divisions,
    static_cast<int>(this->Lattice.Basis), sparse ? sparse->GetFingerprint() : 0);
}

//------------------------------------------------------------------------------------------------------------
int vtkFFDGridDeformer::BindPoint(const double x[3], int outsidePolicy) const
{
  return BindOne(
    SettingsOf(this->BindFrame, this->Lattice, this->GetSparseCells(), outsidePolicy == vtkFFDDeform::CLAMP_TO_EDGE),
    ffd::Vec3<double>::From(x));
}

//------------------------------------------------------------------------------------------------------------
bool vtkFFDGridDeformer::Bind(
  vtkPoints* points, int outsidePolicy, vtkAlgorithm* self, double progressBegin, double progressEnd, bool& rebound)
{
  rebound = false;
  const vtkFFDBindingKey key = this->KeyOf(points, outsidePolicy);
  if (key == this->Bound)
  {
    return true;
  }
  this->Bound = vtkFFDBindingKey();
  const vtkFFDGridLattice& lattice = this->Lattice;
  vtkFFDGridBinding& binding = *this->Binding;
  const vtkIdType n = points->GetNumberOfPoints();
  binding.CellOfPoint.resize(n);
  const vtkFFDSparseCells* sparse = this->GetSparseCells();
  const BindSettings settings = SettingsOf(this->BindFrame, lattice, sparse, key.ClampsOutside());
  bool completed = false;
  BindWorker bind;
  if (!vtkArrayDispatch::DispatchByValueType<PointArrays>::Execute(
        points->GetData(), bind, settings, binding.CellOfPoint.data(), self, progressBegin, progressEnd, completed))
  {
    bind(points->GetData(), settings, binding.CellOfPoint.data(), self, progressBegin, progressEnd, completed);
  }
  if (!completed)
  {
    return false;
  }
  // A sparse lattice decides on the cell table as the dense lattice would, so that both evaluate alike; its point
  // lists are sorted by its own cells, which are in the dense lattice's order.
  std::int64_t denseCells = 1;
  for (int a = 0; a < 3; ++a)
  {
    denseCells *= ffd::BindingCells(lattice.Basis, lattice.Divisions[a]);
  }
  const int cellCount = sparse ? sparse->GetNumberOfCells() : static_cast<int>(denseCells);
  const int* cells = binding.CellOfPoint.data();
  binding.CellTable = ffd::WorthCellTable(lattice.Basis, denseCells, n);
  const int maxCellsInPlace = ffd::MaxCellsInPlace(lattice.Basis, ffd::MeanCellsPerBlock(cells, n), binding.CellTable);
  binding.Blocks = ffd::ListBlockCells(cells, n, maxCellsInPlace);
  binding.Gathered = ffd::ListGatheredPoints(cells, n, cellCount, maxCellsInPlace);
  binding.ListedFloat.clear();
  binding.ListedDouble.clear();
  this->Bound = key;
  rebound = true;
  return true;
}

//------------------------------------------------------------------------------------------------------------
bool vtkFFDGridDeformer::Evaluate(vtkPoints* points, vtkDataArray* normals, vtkDataArray* outPoints,
  vtkDataArray* outNormals, vtkDataArray* outDeterminants, vtkAlgorithm* self, double progressBegin, double progressEnd)
{
  bool completed = false;
  auto evaluate = [&](auto* out)
  {
    using RealArray = std::remove_pointer_t<decltype(out)>;
    using Real = typename RealArray::ValueType;
    EvaluateWorker<Real> worker{ *this, EvaluationDisplacements<Real>(this->Lattice) };
    auto* determinants = static_cast<RealArray*>(outDeterminants);
    if (!vtkArrayDispatch::DispatchByValueType<PointArrays>::Execute(points->GetData(), worker, this->Lattice,
          *this->Binding, normals, outNormals, out, determinants, self, progressBegin, progressEnd, completed))
    {
      worker(points->GetData(), this->Lattice, *this->Binding, normals, outNormals, out, determinants, self,
        progressBegin, progressEnd, completed);
    }
  };
  if (auto* doubles = vtkAOSDataArrayTemplate<double>::FastDownCast(outPoints))
  {
    evaluate(doubles);
  }
  else
  {
    evaluate(vtkAOSDataArrayTemplate<float>::FastDownCast(outPoints));
  }
  return completed;
}

//------------------------------------------------------------------------------------------------------------
const std::vector<int>& vtkFFDGridDeformer::GetCellOfPoint() const
{
  return this->Binding->CellOfPoint;
}

//------------------------------------------------------------------------------------------------------------
ffd::GridLattice<float> vtkFFDGridDeformer::PassLattice(
  const float* displacements, bool withCellTable, std::vector<float>& table) const
{
  return PassLatticeOf(this->Lattice, this->GetSparseCells(), displacements, withCellTable, table);
}

ffd::GridLattice<double> vtkFFDGridDeformer::PassLattice(
  const double* displacements, bool withCellTable, std::vector<double>& table) const
{
  return PassLatticeOf(this->Lattice, this->GetSparseCells(), displacements, withCellTable, table);
}
