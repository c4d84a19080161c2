// SPDX-License-Identifier: BSD-3-Clause
// vtkFFDDeform with sparse lattices (docs/pipeline-and-data-contract.md, "Data contract"): built here by hand from a
// dense lattice and the voxels of the mesh's points, with cells and points in random order, so that these tests depend
// neither on vtkFFDVoxelize nor on vtkFFDBuildLattice. A sparse lattice deforms a mesh bit for bit as the dense lattice
// does (positions, normals, det J, every outside policy); a point in a voxel without a cell keeps its position;
// malformed sparse lattices are refused with an error.

#include "FFDTestErrorObserver.h"
#include "FFDTestLattices.h"
#include "FFDTestMeshes.h"

#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkFFDBuildDetailLattice.h"
#include "vtkFFDDeform.h"
#include "vtkFFDDeformBlocks.h"
#include "vtkFFDDirectManipulation.h"
#include "vtkFFDInverseDeform.h"
#include "vtkFFDLatticeDynamics.h"
#include "vtkIdList.h"
#include "vtkIdTypeArray.h"
#include "vtkIntArray.h"
#include "vtkStringOutputWindow.h"
#include "vtkTransform.h"
#include "vtkUnsignedCharArray.h"
#include "vtkUnstructuredGrid.h"

#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <cstring>
#include <functional>
#include <map>
#include <numeric>
#include <set>

namespace
{
using ffdtest::Vec;
using Voxel = std::array<int, 3>;

const int LocalBases[] = { vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::TRIQUADRATIC_BEZIER,
  vtkFFDBuildLattice::TRICUBIC_BEZIER, vtkFFDBuildLattice::CUBIC_BSPLINE };

/// The voxels of the points inside frame f of n divisions: floor(s n) along each axis, s = 1 in the last voxel.
std::set<Voxel> VoxelsOf(vtkPointSet* mesh, const ffdref::Frame& f, const int n[3])
{
  std::set<Voxel> voxels;
  for (vtkIdType i = 0; i < mesh->GetNumberOfPoints(); ++i)
  {
    Vec x;
    mesh->GetPoint(i, x.data());
    const Vec stu = ffdref::Parameters(f, x);
    Voxel v;
    bool inside = true;
    for (int a = 0; a < 3; ++a)
    {
      inside = inside && stu[a] >= 0.0 && stu[a] <= 1.0;
      v[a] = std::min(int(std::floor(stu[a] * n[a])), n[a] - 1);
    }
    if (inside)
    {
      voxels.insert(v);
    }
  }
  return voxels;
}

/// The support of voxel v along an axis of n voxels, from the bases' definitions.
void Support(int basis, int v, int& first, int& count)
{
  switch (basis)
  {
    case vtkFFDBuildLattice::TRILINEAR:
      first = v, count = 2;
      break;
    case vtkFFDBuildLattice::TRIQUADRATIC_BEZIER:
      first = 2 * v, count = 3;
      break;
    case vtkFFDBuildLattice::TRICUBIC_BEZIER:
      first = 3 * v, count = 4;
      break;
    default: // the cubic B-spline
      first = v, count = 4;
      break;
  }
}

/**
 * The sparse form of the dense lattice `dense` over `voxels`: the control points of their supports (with their
 * positions, RestPosition and LatticeIndex), one VTK_POLY_VERTEX cell per voxel with its VoxelIndex. Cells and
 * the points of each cell come in a random order.
 */
vtkSmartPointer<vtkUnstructuredGrid> SparseOf(
  vtkStructuredGrid* dense, const std::set<Voxel>& voxels, std::mt19937& rng)
{
  int basis, n[3], dims[3];
  vtkFFDDataContract::GetBasis(dense, basis);
  vtkFFDDataContract::GetDivisions(dense, n);
  dense->GetDimensions(dims);
  std::vector<Voxel> cells(voxels.begin(), voxels.end());
  std::shuffle(cells.begin(), cells.end(), rng);
  std::vector<vtkIdType> sparseOf(size_t(dense->GetNumberOfPoints()), -1);
  auto lattice = vtkSmartPointer<vtkUnstructuredGrid>::New();
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  vtkNew<vtkDoubleArray> rest;
  rest->SetName(vtkFFDDataContract::RestPositionArrayName());
  rest->SetNumberOfComponents(3);
  vtkNew<vtkIntArray> index;
  index->SetName(vtkFFDDataContract::LatticeIndexArrayName());
  index->SetNumberOfComponents(3);
  vtkNew<vtkIntArray> voxelIndex;
  voxelIndex->SetName(vtkFFDDataContract::VoxelIndexArrayName());
  voxelIndex->SetNumberOfComponents(3);
  vtkDataArray* denseRest = dense->GetPointData()->GetArray(vtkFFDDataContract::RestPositionArrayName());
  lattice->Allocate(vtkIdType(cells.size()));
  for (const Voxel& v : cells)
  {
    int first[3], count[3];
    for (int a = 0; a < 3; ++a)
    {
      Support(basis, v[a], first[a], count[a]);
    }
    std::vector<vtkIdType> ids;
    for (int k = first[2]; k < first[2] + count[2]; ++k)
    {
      for (int j = first[1]; j < first[1] + count[1]; ++j)
      {
        for (int i = first[0]; i < first[0] + count[0]; ++i)
        {
          const vtkIdType d = i + vtkIdType(dims[0]) * (j + vtkIdType(dims[1]) * k);
          if (sparseOf[d] < 0)
          {
            sparseOf[d] = points->InsertNextPoint(dense->GetPoint(d));
            rest->InsertNextTuple(denseRest->GetTuple3(d));
            index->InsertNextTuple3(i, j, k);
          }
          ids.push_back(sparseOf[d]);
        }
      }
    }
    std::shuffle(ids.begin(), ids.end(), rng);
    lattice->InsertNextCell(VTK_POLY_VERTEX, vtkIdType(ids.size()), ids.data());
    voxelIndex->InsertNextTuple3(v[0], v[1], v[2]);
  }
  lattice->SetPoints(points);
  lattice->GetPointData()->AddArray(rest);
  lattice->GetPointData()->AddArray(index);
  lattice->GetCellData()->AddArray(voxelIndex);
  lattice->GetFieldData()->ShallowCopy(dense->GetFieldData());
  return lattice;
}

/// A frame around the mesh's bounds, padded by 5 % of the largest extent.
ffdref::Frame FrameAround(vtkPointSet* mesh)
{
  double b[6];
  mesh->GetBounds(b);
  const double pad = 0.05 * std::max({ b[1] - b[0], b[3] - b[2], b[5] - b[4] });
  return { { b[0] - pad, b[2] - pad, b[4] - pad }, { b[1] - b[0] + 2 * pad, 0, 0 }, { 0, b[3] - b[2] + 2 * pad, 0 },
    { 0, 0, b[5] - b[4] + 2 * pad } };
}

/// The outputs of vtkFFDDeform of `mesh` by `lattice` on `backend`: points, then normals, then det J, as raw
/// bytes, and the backend that ran them.
std::vector<char> DeformedBytes(vtkPointSet* mesh, vtkPointSet* lattice, int policy, int backend, std::string& ran)
{
  vtkNew<vtkFFDDeform> deform;
  deform->SetInputData(mesh);
  deform->SetLatticeData(lattice);
  deform->SetBackend(backend);
  deform->SetOutsidePolicy(policy);
  deform->TransformNormalsOn();
  deform->ComputeJacobianDeterminantOn();
  deform->Update();
  vtkPointSet* out = vtkPointSet::SafeDownCast(deform->GetOutputDataObject(0));
  std::vector<char> bytes;
  auto append = [&](vtkDataArray* a)
  {
    EXPECT_NE(a, nullptr);
    if (a)
    {
      const char* p = static_cast<const char*>(a->GetVoidPointer(0));
      bytes.insert(bytes.end(), p, p + a->GetDataSize() * a->GetDataTypeSize());
    }
  };
  append(out->GetPoints()->GetData());
  append(out->GetPointData()->GetNormals());
  append(out->GetPointData()->GetArray(vtkFFDDeform::JacobianDeterminantArrayName()));
  ran = deform->GetLastBackendUsed();
  return bytes;
}

/// The errors of VTK objects without an observer (a filter's inner vtkFFDDeform) while it lives.
class OutputWindowCapture
{
public:
  OutputWindowCapture()
    : Previous(vtkOutputWindow::GetInstance())
  {
    vtkOutputWindow::SetInstance(this->Window);
  }
  ~OutputWindowCapture() { vtkOutputWindow::SetInstance(this->Previous); }
  std::string Text() { return this->Window->GetOutput(); }

private:
  vtkSmartPointer<vtkOutputWindow> Previous;
  vtkNew<vtkStringOutputWindow> Window;
};

/// The lattice with the first point id of cell 0 replaced by `id`.
void SetFirstId(vtkUnstructuredGrid* lattice, vtkIdType id)
{
  vtkNew<vtkIdList> ids;
  lattice->GetCells()->GetCellAtId(0, ids);
  ids->SetId(0, id);
  lattice->GetCells()->ReplaceCellAtId(0, ids);
}

/// The lattice without its last `removed` points (and their point data), its cells unchanged.
void RemoveLastPoints(vtkUnstructuredGrid* lattice, vtkIdType removed)
{
  const vtkIdType kept = lattice->GetNumberOfPoints() - removed;
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(kept);
  for (vtkIdType p = 0; p < kept; ++p)
  {
    points->SetPoint(p, lattice->GetPoint(p));
  }
  lattice->SetPoints(points);
  for (int a = 0; a < lattice->GetPointData()->GetNumberOfArrays(); ++a)
  {
    lattice->GetPointData()->GetAbstractArray(a)->SetNumberOfTuples(kept);
  }
}

/// What a run of a filter on a malformed lattice gave: every error (its own, its executive's, its inner filters')
/// and the number of output points.
struct Refusal
{
  std::string Errors;
  vtkIdType OutputPoints = 0;
};

Refusal RunRefusing(vtkAlgorithm* filter)
{
  OutputWindowCapture window;
  vtkNew<FFDTestErrorObserver> observer;
  observer->WatchWithExecutive(filter);
  filter->Update();
  vtkPointSet* out = vtkPointSet::SafeDownCast(filter->GetOutputDataObject(0));
  return { observer->Errors + window.Text(), out ? out->GetNumberOfPoints() : -1 };
}

/// Every filter that reads a lattice's cells, run on `lattice` and `mesh` (with point normals).
std::vector<std::pair<std::string, Refusal>> RunEveryFilter(vtkUnstructuredGrid* lattice, vtkPolyData* mesh)
{
  std::vector<std::pair<std::string, Refusal>> runs;
  for (int options = 0; options < 3; ++options)
  {
    vtkNew<vtkFFDDeform> deform;
    deform->SetInputData(mesh);
    deform->SetLatticeData(lattice);
    deform->SetTransformNormals(options == 1);
    deform->SetComputeJacobianDeterminant(options == 2);
    runs.push_back(
      { options == 0 ? "Deform" : (options == 1 ? "Deform, normals" : "Deform, det J"), RunRefusing(deform) });
  }
  vtkNew<vtkFFDInverseDeform> inverse;
  inverse->SetInputData(mesh);
  inverse->SetLatticeData(lattice);
  runs.push_back({ "InverseDeform", RunRefusing(inverse) });
  vtkNew<vtkFFDDeformBlocks> blocks;
  blocks->SetInputData(mesh);
  blocks->AddLatticeData(lattice);
  runs.push_back({ "DeformBlocks", RunRefusing(blocks) });
  vtkNew<vtkIntArray> selected;
  selected->SetNumberOfComponents(3);
  selected->InsertNextTypedTuple(
    vtkIntArray::SafeDownCast(lattice->GetCellData()->GetArray(vtkFFDDataContract::VoxelIndexArrayName()))
      ->GetPointer(0));
  vtkNew<vtkFFDBuildDetailLattice> detail;
  detail->SetInputData(lattice);
  detail->SetSelectedVoxels(selected);
  runs.push_back({ "BuildDetailLattice", RunRefusing(detail) });
  vtkNew<vtkIdTypeArray> targetIds;
  targetIds->InsertNextValue(0);
  vtkNew<vtkPoints> targets;
  targets->SetDataTypeToDouble();
  const double* x = mesh->GetPoint(0);
  targets->InsertNextPoint(x[0] + 0.01, x[1], x[2]);
  vtkNew<vtkFFDDirectManipulation> manipulate;
  manipulate->SetInputData(lattice);
  manipulate->SetMeshData(mesh);
  manipulate->SetTargetPointIds(targetIds);
  manipulate->SetTargetPositions(targets);
  runs.push_back({ "DirectManipulation", RunRefusing(manipulate) });
  vtkNew<vtkFFDLatticeDynamics> dynamics;
  dynamics->SetLattice(lattice);
  dynamics->SetMesh(mesh);
  vtkNew<FFDTestErrorObserver> observer;
  observer->Watch(dynamics);
  const int initialized = dynamics->Initialize();
  runs.push_back({ "LatticeDynamics", { observer->Errors, initialized ? 1 : 0 } });
  return runs;
}
} // namespace

TEST(vtkFFDDeformSparse, DeformsAsTheDenseLatticeBitForBit)
{
  // Real meshes (double and float points), every local basis, a perturbed lattice of 5x6x7 voxels, both outside
  // policies of grid lattices, on the CPU and on the automatic backend (CUDA where a device is): the sparse lattice
  // over the mesh's voxels gives the dense lattice's output bytes on the same backend.
  std::mt19937 rng(1717);
  int compared = 0;
  for (const char* name : { "bear", "elephant" })
  {
    const vtkSmartPointer<vtkPolyData> mesh = ffdtest::WithPointNormals(ReadTestMesh(name));
    const vtkSmartPointer<vtkPolyData> floatMesh = WithFloatPoints(mesh);
    const ffdref::Frame f = FrameAround(mesh);
    const int n[3] = { 5, 6, 7 };
    const std::set<Voxel> voxels = VoxelsOf(mesh, f, n);
    for (int basis : LocalBases)
    {
      const vtkSmartPointer<vtkStructuredGrid> dense = ffdtest::MakeLattice(f, basis, n);
      ffdtest::Perturb(dense, rng, 0.03 * ffdtest::Diagonal(f));
      const vtkSmartPointer<vtkUnstructuredGrid> sparse = SparseOf(dense, voxels, rng);
      ASSERT_LT(sparse->GetNumberOfPoints(), dense->GetNumberOfPoints()) << name;
      for (vtkPointSet* input : { static_cast<vtkPointSet*>(mesh), static_cast<vtkPointSet*>(floatMesh) })
      {
        for (int policy : { vtkFFDDeform::KEEP_POSITION, vtkFFDDeform::CLAMP_TO_EDGE })
        {
          for (int backend : { vtkFFDDeform::CPU, vtkFFDDeform::AUTOMATIC })
          {
            std::string ranDense, ranSparse;
            const std::vector<char> want = DeformedBytes(input, dense, policy, backend, ranDense);
            ASSERT_GT(want.size(), 0u);
            ASSERT_TRUE(want == DeformedBytes(input, sparse, policy, backend, ranSparse))
              << name << " basis " << basis << " policy " << policy << " points of type "
              << input->GetPoints()->GetDataType() << " on " << ranSparse;
            ASSERT_EQ(ranDense, ranSparse);
            ++compared;
          }
        }
      }
    }
  }
  EXPECT_EQ(compared, 2 * 4 * 2 * 2 * 2);
}

TEST(vtkFFDDeformSparse, PointsInVoxelsWithoutACellKeepTheirPosition)
{
  // A trilinear 4x4x4 lattice with random displacements and cells in half of its voxels; 2000 random points of
  // the frame: a point whose voxel has a cell moves as with the dense lattice (bit for bit), the others keep
  // their position exactly.
  std::mt19937 rng(1718);
  const ffdref::Frame f = { { -1, 0.5, 2 }, { 2, 0.1, 0 }, { 0, 1.5, 0.2 }, { 0.1, 0, 1 } };
  const int n[3] = { 4, 4, 4 };
  std::set<Voxel> voxels;
  std::bernoulli_distribution half(0.5);
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i)
        if (half(rng))
          voxels.insert({ i, j, k });
  const vtkSmartPointer<vtkStructuredGrid> dense = ffdtest::MakeLattice(f, vtkFFDBuildLattice::TRILINEAR, n);
  ffdtest::Perturb(dense, rng, 0.2);
  const vtkSmartPointer<vtkUnstructuredGrid> sparse = SparseOf(dense, voxels, rng);
  vtkNew<vtkPolyData> cloud;
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int p = 0; p < 2000; ++p)
  {
    points->InsertNextPoint(ffdtest::At(f, unit(rng), unit(rng), unit(rng)).data());
  }
  cloud->SetPoints(points);
  auto deformed = [&](vtkPointSet* lattice)
  {
    vtkNew<vtkFFDDeform> deform;
    deform->SetInputData(cloud);
    deform->SetLatticeData(lattice);
    deform->Update();
    auto out = vtkSmartPointer<vtkPoints>::New();
    out->SetDataTypeToDouble();
    out->DeepCopy(vtkPointSet::SafeDownCast(deform->GetOutputDataObject(0))->GetPoints());
    return out;
  };
  const vtkSmartPointer<vtkPoints> onDense = deformed(dense), onSparse = deformed(sparse);
  int kept = 0, moved = 0;
  for (vtkIdType p = 0; p < points->GetNumberOfPoints(); ++p)
  {
    Vec x, want, got;
    points->GetPoint(p, x.data());
    const Vec stu = ffdref::Parameters(f, x);
    const Voxel v = { std::min(int(stu[0] * 4), 3), std::min(int(stu[1] * 4), 3), std::min(int(stu[2] * 4), 3) };
    onSparse->GetPoint(p, got.data());
    if (voxels.count(v))
    {
      onDense->GetPoint(p, want.data());
      ++moved;
    }
    else
    {
      want = x;
      ++kept;
    }
    ASSERT_EQ(0, std::memcmp(want.data(), got.data(), sizeof(want))) << "point " << p;
  }
  EXPECT_GT(kept, 100);
  EXPECT_GT(moved, 100);
}

TEST(vtkFFDDeformSparse, MalformedSparseLatticesAreRefused)
{
  // Each defect of a sparse lattice gives an error naming it, and an empty output; no crash.
  std::mt19937 rng(1719);
  const ffdref::Frame f = { { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 } };
  const int n[3] = { 3, 3, 3 };
  const std::set<Voxel> voxels = { { 0, 0, 0 }, { 1, 0, 0 }, { 2, 2, 2 } };
  vtkNew<vtkPolyData> cloud;
  vtkNew<vtkPoints> points;
  points->InsertNextPoint(0.1, 0.1, 0.1);
  cloud->SetPoints(points);
  struct Defect
  {
    const char* Expected;
    void (*Apply)(vtkUnstructuredGrid*);
  };
  const Defect defects[] = {
    { "LatticeIndex point array",
      [](vtkUnstructuredGrid* l)
      {
        vtkNew<vtkDoubleArray> wrong; // of doubles, not ints
        wrong->SetName(vtkFFDDataContract::LatticeIndexArrayName());
        wrong->SetNumberOfComponents(3);
        wrong->SetNumberOfTuples(l->GetNumberOfPoints());
        l->GetPointData()->AddArray(wrong);
      } },
    { "VoxelIndex cell array",
      [](vtkUnstructuredGrid* l) { l->GetCellData()->RemoveArray(vtkFFDDataContract::VoxelIndexArrayName()); } },
    { "outside the lattice's FFDDivisions",
      [](vtkUnstructuredGrid* l)
      {
        vtkIntArray::SafeDownCast(l->GetCellData()->GetArray(vtkFFDDataContract::VoxelIndexArrayName()))
          ->SetTypedComponent(0, 0, 3);
      } },
    { "outside the lattice's control points per axis",
      [](vtkUnstructuredGrid* l)
      {
        vtkIntArray::SafeDownCast(l->GetPointData()->GetArray(vtkFFDDataContract::LatticeIndexArrayName()))
          ->SetTypedComponent(0, 2, -1);
      } },
    { "the same VoxelIndex",
      [](vtkUnstructuredGrid* l)
      {
        auto* v = vtkIntArray::SafeDownCast(l->GetCellData()->GetArray(vtkFFDDataContract::VoxelIndexArrayName()));
        v->SetTypedTuple(1, v->GetPointer(0));
      } },
    { "outside the voxel's support",
      [](vtkUnstructuredGrid* l)
      {
        auto* v = vtkIntArray::SafeDownCast(l->GetCellData()->GetArray(vtkFFDDataContract::VoxelIndexArrayName()));
        for (vtkIdType c = 0; c < v->GetNumberOfTuples(); ++c)
        {
          if (v->GetTypedComponent(c, 0) == 2)
          {
            v->SetTypedComponent(c, 0, 1); // voxel (1, 2, 2), whose support is not the cell's points
            v->SetTypedComponent(c, 1, 2);
          }
        }
      } },
    { "has 7 points",
      [](vtkUnstructuredGrid* l)
      {
        vtkNew<vtkCellArray> cells; // cell 0 without its last point
        vtkNew<vtkIdList> ids;
        for (vtkIdType c = 0; c < l->GetNumberOfCells(); ++c)
        {
          l->GetCellPoints(c, ids);
          cells->InsertNextCell(c == 0 ? 7 : ids->GetNumberOfIds(), ids->GetPointer(0));
        }
        l->SetCells(VTK_POLY_VERTEX, cells);
      } },
    { "two points of the same LatticeIndex",
      [](vtkUnstructuredGrid* l)
      {
        vtkNew<vtkIdList> ids;
        l->GetCellPoints(0, ids);
        ids->SetId(1, ids->GetId(0));
        l->ReplaceCell(0, 8, ids->GetPointer(0));
      } },
  };
  for (const Defect& defect : defects)
  {
    const vtkSmartPointer<vtkStructuredGrid> dense = ffdtest::MakeLattice(f, vtkFFDBuildLattice::TRILINEAR, n);
    const vtkSmartPointer<vtkUnstructuredGrid> sparse = SparseOf(dense, voxels, rng);
    defect.Apply(sparse);
    vtkNew<vtkFFDDeform> deform;
    deform->SetInputData(cloud);
    deform->SetLatticeData(sparse);
    vtkNew<FFDTestErrorObserver> errors;
    errors->WatchWithExecutive(deform);
    deform->Update();
    EXPECT_NE(errors->Errors.find(defect.Expected), std::string::npos) << defect.Expected << ": " << errors->Errors;
    EXPECT_EQ(vtkPointSet::SafeDownCast(deform->GetOutputDataObject(0))->GetNumberOfPoints(), 0) << defect.Expected;
  }
}

TEST(vtkFFDDeformSparse, MovingControlPointsReevaluatesWithoutRebinding)
{
  // The binding to a sparse lattice is kept while only its points move (an update re-reads neither its cells nor
  // the points' voxels), and redone when its cells change.
  std::mt19937 rng(1720);
  const vtkSmartPointer<vtkPolyData> mesh = ReadTestMesh("bear");
  const ffdref::Frame f = FrameAround(mesh);
  const int n[3] = { 6, 6, 6 };
  const std::set<Voxel> voxels = VoxelsOf(mesh, f, n);
  const vtkSmartPointer<vtkStructuredGrid> dense = ffdtest::MakeLattice(f, vtkFFDBuildLattice::CUBIC_BSPLINE, n);
  const vtkSmartPointer<vtkUnstructuredGrid> sparse = SparseOf(dense, voxels, rng);
  vtkNew<vtkFFDDeform> deform;
  deform->SetInputData(mesh);
  deform->SetLatticeData(sparse);
  deform->Update();
  EXPECT_EQ(deform->GetNumberOfBindings(), 1);
  ffdtest::Perturb(sparse, rng, 0.01 * ffdtest::Diagonal(f));
  deform->Update();
  EXPECT_EQ(deform->GetNumberOfBindings(), 1);
  EXPECT_GT(ffdtest::MaxRelativeMotion(mesh, vtkPointSet::SafeDownCast(deform->GetOutputDataObject(0)), f), 1e-4);
  std::set<Voxel> fewer = voxels;
  fewer.erase(fewer.begin());
  deform->SetLatticeData(SparseOf(dense, fewer, rng));
  deform->Update();
  EXPECT_EQ(deform->GetNumberOfBindings(), 2);
}

TEST(vtkFFDDeformSparse, WholePipelineAt1024CubedMatchesReference)
{
  // The elephant (2,775 points) through vtkFFDVoxelize, vtkFFDBuildLattice (sparse, the default) and vtkFFDDeform
  // at 1024^3 voxels, whose dense lattices (1025^3 or 1027^3 control points, 25 GB and more) could not be
  // allocated: every control point moved at random, each mesh point against the float64 reference
  // X + sum_ijk w_i(s) w_j(t) w_k(u) D_ijk (ffdref::AxisWeights over all control points of an axis, D read by
  // LatticeIndex), within 1e-12 of the frame's diagonal (a sum of at most 64 terms of double rounding).
  const auto start = std::chrono::steady_clock::now();
  std::mt19937 rng(1721);
  const vtkSmartPointer<vtkPolyData> mesh = ReadTestMesh("elephant");
  for (int basis : { vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::CUBIC_BSPLINE })
  {
    vtkNew<vtkFFDVoxelize> voxelize;
    voxelize->SetInputData(mesh);
    voxelize->SetDivisions(1024, 1024, 1024);
    vtkNew<vtkFFDBuildLattice> build;
    build->SetInputConnection(voxelize->GetOutputPort());
    build->SetBasis(basis);
    build->Update();
    auto lattice = vtkSmartPointer<vtkUnstructuredGrid>::New();
    lattice->DeepCopy(build->GetOutputDataObject(0));
    ASSERT_GT(lattice->GetNumberOfPoints(), 0);
    const ffdref::Frame f = ffdtest::FrameOf(lattice);
    ffdtest::Perturb(lattice, rng, 1e-4 * ffdtest::Diagonal(f));
    std::map<std::array<int, 3>, Vec> displacement;
    vtkDataArray* rest = lattice->GetPointData()->GetArray(vtkFFDDataContract::RestPositionArrayName());
    vtkDataArray* index = lattice->GetPointData()->GetArray(vtkFFDDataContract::LatticeIndexArrayName());
    for (vtkIdType p = 0; p < lattice->GetNumberOfPoints(); ++p)
    {
      Vec x, x0;
      lattice->GetPoint(p, x.data());
      rest->GetTuple(p, x0.data());
      const double* ijk = index->GetTuple3(p);
      displacement[{ int(ijk[0]), int(ijk[1]), int(ijk[2]) }] = ffdref::Sub(x, x0);
    }
    vtkNew<vtkFFDDeform> deform;
    deform->SetInputData(mesh);
    deform->SetLatticeData(lattice);
    deform->Update();
    vtkPointSet* out = vtkPointSet::SafeDownCast(deform->GetOutputDataObject(0));
    ASSERT_EQ(out->GetNumberOfPoints(), mesh->GetNumberOfPoints());
    const ffdref::Basis b = ffdtest::RefBasis(basis);
    double worst = 0.0;
    for (vtkIdType p = 0; p < mesh->GetNumberOfPoints(); ++p)
    {
      Vec x, y;
      mesh->GetPoint(p, x.data());
      out->GetPoint(p, y.data());
      const Vec stu = ffdref::Parameters(f, x);
      std::vector<double> w[3];
      for (int a = 0; a < 3; ++a)
      {
        w[a] = ffdref::AxisWeights(b, 1024, std::min(1.0, std::max(0.0, stu[a])));
      }
      Vec want = x;
      for (size_t k = 0; k < w[2].size(); ++k)
        for (size_t j = 0; w[2][k] != 0.0 && j < w[1].size(); ++j)
          for (size_t i = 0; w[1][j] != 0.0 && i < w[0].size(); ++i)
          {
            if (w[0][i] == 0.0)
            {
              continue;
            }
            const auto d = displacement.find({ int(i), int(j), int(k) });
            ASSERT_NE(d, displacement.end()) << "point " << p << " needs a control point the lattice lacks";
            for (int c = 0; c < 3; ++c)
            {
              want[c] += w[0][i] * w[1][j] * w[2][k] * d->second[c];
            }
          }
      worst = std::max(worst, ffdtest::Length(ffdref::Sub(y, want)));
    }
    EXPECT_LE(worst, 1e-12 * ffdtest::Diagonal(f)) << vtkFFDBuildLattice::GetBasisAsString(basis);
    EXPECT_GT(ffdtest::MaxRelativeMotion(mesh, out, f), 1e-6);
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ::testing::Test::RecordProperty("seconds", std::to_string(seconds)); // about 2 s on 2 cores: not asserted
}

TEST(vtkFFDDeformSparse, CellsNamingPointsTheLatticeLacksAreRefusedByEveryFilter)
{
  // A cell naming a point id the lattice does not have (the first id past its points, a negative id, the largest
  // int), and a lattice whose last points were taken away while its cells still name them: vtkFFDSparseCells,
  // which every reader of a grid lattice goes through, refuses the ids before it reads anything through them.
  // Every filter gives the error and an empty output (the dynamics fail to initialize), for a local basis of two
  // and of four points per axis. Before, the first ones crashed Deform and the others, and the removed points
  // were read past the arrays' ends: silently wrong output, and a crash of the dynamics.
  std::mt19937 rng(1722);
  const vtkSmartPointer<vtkPolyData> mesh = ffdtest::WithPointNormals(ReadTestMesh("bear"));
  const int n[3] = { 5, 5, 5 };
  for (int basis : { vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::CUBIC_BSPLINE })
  {
    const vtkSmartPointer<vtkPointSet> built =
      ffdtest::MovedLattice(mesh, basis, n, vtkFFDBuildLattice::SPARSE, rng, 0.02);
    const vtkIdType count = built->GetNumberOfPoints();
    const std::string has = "but the lattice has ";
    const std::vector<std::pair<std::string, std::function<void(vtkUnstructuredGrid*)>>> defects = {
      { "names point " + std::to_string(count) + ", " + has + std::to_string(count) + " points",
        [count](vtkUnstructuredGrid* l) { SetFirstId(l, count); } },
      { "names point -1, " + has, [](vtkUnstructuredGrid* l) { SetFirstId(l, -1); } },
      { "names point 2147483647, " + has, [](vtkUnstructuredGrid* l) { SetFirstId(l, VTK_INT_MAX); } },
      { has + std::to_string(count - 10) + " points", [](vtkUnstructuredGrid* l) { RemoveLastPoints(l, 10); } },
    };
    for (const auto& defect : defects)
    {
      auto lattice = vtkSmartPointer<vtkUnstructuredGrid>::New();
      lattice->DeepCopy(built);
      defect.second(lattice);
      for (const auto& run : RunEveryFilter(lattice, mesh))
      {
        const std::string what = run.first + ", " + vtkFFDBuildLattice::GetBasisAsString(basis) + ": " + defect.first;
        EXPECT_NE(run.second.Errors.find(defect.first), std::string::npos) << what << "\n" << run.second.Errors;
        EXPECT_EQ(run.second.OutputPoints, 0) << what;
      }
    }
  }
}

TEST(vtkFFDDeformSparse, TransformedLatticesFollowOrSayWhatTheTransformDid)
{
  // vtkTransformFilter with TransformAllInputVectors on (ParaView's Transform's default) transforms a sparse
  // lattice's LatticeIndex, VoxelIndex and RestPosition as vectors: the error says so and what to do, for a
  // rotation and a scaling and every local basis (before, it said only that the lattice was not built by
  // vtkFFDBuildLattice). With the option off, a rigid rotation of the lattice about a point rotates the mesh:
  // within 1e-12 of the diagonal of the float64 rotation of each input point (Rodrigues' formula, FFDTestLattices.h;
  // partition of unity and linear precision, rounding of sums of at most 64 terms of the diagonal's size).
  std::mt19937 rng(1723);
  const vtkSmartPointer<vtkPolyData> mesh = ReadTestMesh("bear");
  const int n[3] = { 6, 5, 4 };
  const Vec centre = { 0.1, 0.2, -0.3 }, axis = { -1.0, 0.5, 2.0 };
  vtkNew<vtkTransform> rotation;
  rotation->Translate(centre.data());
  rotation->RotateWXYZ(40, axis.data());
  rotation->Translate(-centre[0], -centre[1], -centre[2]);
  vtkNew<vtkTransform> scaling;
  scaling->Scale(2.0, 1.5, 0.5);
  for (int basis : LocalBases)
  {
    const std::string name = vtkFFDBuildLattice::GetBasisAsString(basis);
    const vtkSmartPointer<vtkPointSet> lattice =
      ffdtest::MovedLattice(mesh, basis, n, vtkFFDBuildLattice::SPARSE, rng, 0.0);
    for (vtkAbstractTransform* transform :
      { static_cast<vtkAbstractTransform*>(rotation.Get()), static_cast<vtkAbstractTransform*>(scaling.Get()) })
    {
      vtkNew<vtkFFDDeform> deform;
      deform->SetInputData(mesh);
      deform->SetLatticeData(ffdtest::TransformedLattice(lattice, transform, true));
      const Refusal refusal = RunRefusing(deform);
      EXPECT_NE(refusal.Errors.find("VoxelIndex no longer match its FFDFrame"), std::string::npos)
        << name << ": " << refusal.Errors;
      EXPECT_NE(refusal.Errors.find("with TransformAllInputVectors on); transform the lattice with that option off"),
        std::string::npos)
        << name;
      EXPECT_EQ(refusal.OutputPoints, 0) << name;
    }
    vtkNew<vtkFFDDeform> deform;
    deform->SetInputData(mesh);
    deform->SetLatticeData(ffdtest::TransformedLattice(lattice, rotation, false));
    deform->Update();
    const double error = ffdtest::MaxScaledDistance(
      mesh, vtkPointSet::SafeDownCast(deform->GetOutputDataObject(0)),
      [&](const Vec& x) { return ffdtest::RotatedAbout(x, centre, axis, 40); },
      ffdtest::Diagonal(ffdtest::FrameOf(lattice)));
    EXPECT_LE(error, 1e-12) << name;
  }
}

TEST(vtkFFDDeformSparse, BuiltBSplineLatticeDeformsAsItsOtherFormsBitForBit)
{
  // vtkFFDBuildLattice's sparse cubic B-spline lattice is evaluated from its own connectivity (each cell already
  // is its voxel's support, in order, in 32-bit ids), where the same lattice with one cell's points in another
  // order, or its ids in 64 bits, is evaluated from a copy: all three give the dense lattice's output bytes, the
  // same displacements at the same LatticeIndex, for double and float points, both outside policies.
  std::mt19937 rng(1722);
  const vtkSmartPointer<vtkPolyData> mesh = ffdtest::WithPointNormals(ReadTestMesh("bear"));
  const vtkSmartPointer<vtkPolyData> floatMesh = WithFloatPoints(mesh);
  vtkNew<vtkFFDVoxelize> voxelize;
  voxelize->SetInputData(mesh);
  voxelize->SetDivisions(12, 13, 14);
  vtkNew<vtkFFDBuildLattice> build;
  build->SetInputConnection(voxelize->GetOutputPort());
  build->SetBasis(vtkFFDBuildLattice::CUBIC_BSPLINE);
  build->SetLatticeForm(vtkFFDBuildLattice::DENSE);
  build->Update();
  auto dense = vtkSmartPointer<vtkStructuredGrid>::New();
  dense->DeepCopy(build->GetOutputDataObject(0));
  build->SetLatticeForm(vtkFFDBuildLattice::SPARSE);
  build->Update();
  vtkUnstructuredGrid* built = vtkUnstructuredGrid::SafeDownCast(build->GetOutputDataObject(0));
  ASSERT_NE(built, nullptr);
  ASSERT_FALSE(built->GetCells()->IsStorage64Bit());
  ASSERT_LT(built->GetNumberOfPoints(), dense->GetNumberOfPoints());

  // The same random displacement at each LatticeIndex in both forms.
  int dims[3];
  dense->GetDimensions(dims);
  auto sparse = vtkSmartPointer<vtkUnstructuredGrid>::New();
  sparse->ShallowCopy(built);
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->DeepCopy(built->GetPoints());
  sparse->SetPoints(points);
  vtkDataArray* index = sparse->GetPointData()->GetArray(vtkFFDDataContract::LatticeIndexArrayName());
  std::uniform_real_distribution<double> move(-0.03, 0.03);
  const double diagonal = ffdtest::Diagonal(ffdtest::FrameOf(sparse));
  for (vtkIdType p = 0; p < sparse->GetNumberOfPoints(); ++p)
  {
    const double* ijk = index->GetTuple3(p);
    const vtkIdType d = vtkIdType(ijk[0]) + dims[0] * (vtkIdType(ijk[1]) + dims[1] * vtkIdType(ijk[2]));
    double x[3], y[3];
    points->GetPoint(p, x);
    dense->GetPoint(d, y);
    for (int c = 0; c < 3; ++c)
    {
      const double shift = move(rng) * diagonal;
      x[c] += shift;
      y[c] += shift;
    }
    points->SetPoint(p, x);
    dense->GetPoints()->SetPoint(d, y);
  }

  // One cell's points reversed, its ids still 32-bit and the cells in voxel order; and every id in 64 bits.
  auto reversed = vtkSmartPointer<vtkUnstructuredGrid>::New();
  reversed->DeepCopy(sparse);
  vtkNew<vtkIdList> ids;
  reversed->GetCells()->GetCellAtId(3, ids);
  std::reverse(ids->GetPointer(0), ids->GetPointer(0) + ids->GetNumberOfIds());
  reversed->GetCells()->ReplaceCellAtId(3, ids);
  ASSERT_FALSE(reversed->GetCells()->IsStorage64Bit());
  auto wide = vtkSmartPointer<vtkUnstructuredGrid>::New();
  wide->DeepCopy(sparse);
  ASSERT_TRUE(wide->GetCells()->ConvertTo64BitStorage());

  int compared = 0;
  for (vtkPointSet* input : { static_cast<vtkPointSet*>(mesh), static_cast<vtkPointSet*>(floatMesh) })
  {
    for (int policy : { vtkFFDDeform::KEEP_POSITION, vtkFFDDeform::CLAMP_TO_EDGE })
    {
      std::string ran;
      const std::vector<char> want = DeformedBytes(input, dense, policy, vtkFFDDeform::CPU, ran);
      ASSERT_GT(want.size(), 0u);
      for (vtkUnstructuredGrid* lattice : { sparse.Get(), reversed.Get(), wide.Get() })
      {
        ASSERT_TRUE(want == DeformedBytes(input, lattice, policy, vtkFFDDeform::CPU, ran))
          << "policy " << policy << " points of type " << input->GetPoints()->GetDataType() << " lattice "
          << (lattice == sparse        ? "as built"
                 : lattice == reversed ? "with a cell reversed"
                                       : "of 64-bit ids");
        ++compared;
      }
    }
  }
  EXPECT_EQ(compared, 2 * 2 * 3);
  vtkNew<vtkFFDDeform> deform; // the displacements move the mesh
  deform->SetInputData(mesh);
  deform->SetLatticeData(sparse);
  deform->Update();
  EXPECT_GT(ffdtest::MaxRelativeMotion(
              mesh, vtkPointSet::SafeDownCast(deform->GetOutputDataObject(0)), ffdtest::FrameOf(sparse)),
    1e-3);
}

TEST(vtkFFDDeformSparse, ReupdatesInEitherPrecisionGiveAFreshFiltersBytes)
{
  // vtkFFDDeform reads a lattice's displacements in the precision of its last evaluation: one filter updated in
  // turn with float and double points, its lattice moved in between, gives at every update the bytes of a new
  // filter, for a dense and a sparse lattice, with and without normals and det J.
  std::mt19937 rng(1723);
  const vtkSmartPointer<vtkPolyData> mesh = ffdtest::WithPointNormals(ReadTestMesh("bear"));
  const vtkSmartPointer<vtkPolyData> floatMesh = WithFloatPoints(mesh);
  const ffdref::Frame f = FrameAround(mesh);
  const int n[3] = { 5, 6, 7 };
  const vtkSmartPointer<vtkStructuredGrid> dense = ffdtest::MakeLattice(f, vtkFFDBuildLattice::CUBIC_BSPLINE, n);
  const vtkSmartPointer<vtkUnstructuredGrid> sparse = SparseOf(dense, VoxelsOf(mesh, f, n), rng);
  auto bytesOf = [](vtkFFDDeform* deform)
  {
    vtkPointSet* out = vtkPointSet::SafeDownCast(deform->GetOutputDataObject(0));
    std::vector<char> bytes;
    for (vtkDataArray* a : { out->GetPoints()->GetData(), out->GetPointData()->GetNormals(),
           out->GetPointData()->GetArray(vtkFFDDeform::JacobianDeterminantArrayName()) })
    {
      if (a)
      {
        const char* p = static_cast<const char*>(a->GetVoidPointer(0));
        bytes.insert(bytes.end(), p, p + a->GetDataSize() * a->GetDataTypeSize());
      }
    }
    return bytes;
  };
  int compared = 0;
  for (vtkPointSet* lattice : { static_cast<vtkPointSet*>(dense), static_cast<vtkPointSet*>(sparse) })
  {
    for (bool withJacobian : { false, true })
    {
      vtkNew<vtkFFDDeform> reused;
      reused->SetLatticeData(lattice);
      reused->SetBackend(vtkFFDDeform::CPU);
      reused->SetTransformNormals(withJacobian);
      reused->SetComputeJacobianDeterminant(withJacobian);
      for (vtkPointSet* input :
        { static_cast<vtkPointSet*>(floatMesh), static_cast<vtkPointSet*>(floatMesh), static_cast<vtkPointSet*>(mesh),
          static_cast<vtkPointSet*>(mesh), static_cast<vtkPointSet*>(floatMesh), static_cast<vtkPointSet*>(mesh) })
      {
        ffdtest::Perturb(lattice, rng, 0.01 * ffdtest::Diagonal(f));
        reused->SetInputData(input);
        reused->Update();
        vtkNew<vtkFFDDeform> fresh;
        fresh->SetInputData(input);
        fresh->SetLatticeData(lattice);
        fresh->SetBackend(vtkFFDDeform::CPU);
        fresh->SetTransformNormals(withJacobian);
        fresh->SetComputeJacobianDeterminant(withJacobian);
        fresh->Update();
        const std::vector<char> want = bytesOf(fresh);
        ASSERT_GT(want.size(), 0u);
        ASSERT_TRUE(want == bytesOf(reused))
          << "update " << compared << " points of type " << input->GetPoints()->GetDataType();
        ++compared;
      }
    }
  }
  EXPECT_EQ(compared, 2 * 2 * 6);
}
