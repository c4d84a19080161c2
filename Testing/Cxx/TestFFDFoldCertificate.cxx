// SPDX-License-Identifier: BSD-3-Clause
// vtkFFDFoldCertificate: a rest lattice is certified in every active voxel, for every basis, dense and sparse; a
// control point pushed through its neighbour folds its voxels; never certified where the float64 reference
// (FFDReference.h's Jacobian, sampled at 8^3 points a voxel) finds det J <= 0; dense and sparse forms of one
// lattice agree voxel by voxel and the array maps to the lattice's cells as documented; tetrahedral lattices
// against the reference's signed volumes; bad input. The kernel's own test (Kernels.FoldCertificate.*) covers
// thousands of random lattices; this one covers the filter's reading and mapping.
#include "FFDTestErrorObserver.h"
#include "FFDTestInputChecks.h"
#include "FFDTestLattices.h"
#include "FFDTestMeshes.h"
#include "FFDTestTetrahedra.h"

#include "vtkCallbackCommand.h"
#include "vtkCellData.h"
#include "vtkDataArray.h"
#include "vtkFFDBuildLattice.h"
#include "vtkFFDDataContract.h"
#include "vtkFFDFoldCertificate.h"
#include "vtkIdList.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkStructuredGrid.h"
#include "vtkUnsignedCharArray.h"
#include "vtkUnstructuredGrid.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <random>

namespace
{
using ffdtest::Vec;

const int Bases[] = { vtkFFDBuildLattice::BERNSTEIN, vtkFFDBuildLattice::TRILINEAR,
  vtkFFDBuildLattice::TRIQUADRATIC_BEZIER, vtkFFDBuildLattice::TRICUBIC_BEZIER, vtkFFDBuildLattice::CUBIC_BSPLINE };

/// The certificate's output for `lattice` (the filter kept in `filter` for its counts).
vtkUnsignedCharArray* Certify(vtkFFDFoldCertificate* filter, vtkPointSet* lattice)
{
  filter->SetInputData(lattice);
  filter->Update();
  vtkPointSet* output = vtkPointSet::SafeDownCast(filter->GetOutputDataObject(0));
  return vtkUnsignedCharArray::SafeDownCast(
    output->GetCellData()->GetArray(vtkFFDFoldCertificate::GetFoldCertificateArrayName()));
}

/// Each voxel's state, from a dense lattice's array (its cells' states, VoxelOfCell() of each cell; all the cells
/// of a voxel must agree) or a sparse one's (`VoxelIndex`).
std::map<std::array<int, 3>, int> VoxelStates(vtkPointSet* lattice, vtkUnsignedCharArray* states, int basis)
{
  std::map<std::array<int, 3>, int> voxels;
  vtkDataArray* index = lattice->GetCellData()->GetArray(vtkFFDDataContract::VoxelIndexArrayName());
  vtkStructuredGrid* dense = vtkStructuredGrid::SafeDownCast(lattice);
  int dims[3] = { 0, 0, 0 };
  if (dense)
  {
    dense->GetDimensions(dims);
  }
  const int degree = basis == vtkFFDBuildLattice::BERNSTEIN || basis == vtkFFDBuildLattice::CUBIC_BSPLINE ? 1 : basis;
  for (vtkIdType c = 0; c < lattice->GetNumberOfCells(); ++c)
  {
    std::array<int, 3> voxel;
    for (int a = 0; a < 3; ++a)
    {
      if (dense) // written out from the lattice's rest geometry (docs/fold-certificate.md)
      {
        const vtkIdType cells[3] = { dims[0] - 1, dims[1] - 1, dims[2] - 1 };
        const vtkIdType ijk[3] = { c % cells[0], (c / cells[0]) % cells[1], c / (cells[0] * cells[1]) };
        voxel[a] = basis == vtkFFDBuildLattice::CUBIC_BSPLINE ? int(ijk[a]) - 1 : int(ijk[a]) / degree;
      }
      else
      {
        voxel[a] = int(index->GetComponent(c, a));
      }
    }
    const int state = states->GetValue(c);
    if (state == vtkFFDFoldCertificate::NOT_CHECKED)
    {
      continue;
    }
    auto inserted = voxels.emplace(voxel, state);
    EXPECT_EQ(inserted.first->second, state) << "two cells of one voxel disagree";
  }
  return voxels;
}

/// The smallest det J over 8^3 points inside voxel `voxel` by the reference (its Jacobian in the displacement
/// form, summed over every control point of the lattice).
double SampledMinimum(const ffdtest::Reference& ref, const std::array<int, 3>& voxel)
{
  std::vector<Vec> d(ref.P.size());
  for (std::size_t p = 0; p < d.size(); ++p)
  {
    d[p] = ffdref::Sub(ref.P[p], ref.Rest[p]);
  }
  double smallest = 1e300;
  for (int c = 0; c < 8; ++c)
    for (int b = 0; b < 8; ++b)
      for (int a = 0; a < 8; ++a)
      {
        const int q[3] = { a, b, c };
        Vec stu;
        for (int axis = 0; axis < 3; ++axis)
        {
          stu[axis] = (voxel[axis] + (q[axis] + 0.5) / 8.0) / ref.N[axis];
        }
        smallest = std::min(
          smallest, ffdtest::Det(ffdref::JacobianLocal(ref.Basis, ref.F, ref.N, d, stu, voxel, { true, true, true })));
      }
  return smallest;
}

/// Rest position plus a smooth bend and a ripple, the same for the dense and the sparse form of a lattice.
void Bend(vtkPointSet* lattice, double amplitude)
{
  vtkDataArray* rest = lattice->GetPointData()->GetArray(vtkFFDDataContract::RestPositionArrayName());
  for (vtkIdType p = 0; p < lattice->GetNumberOfPoints(); ++p)
  {
    double x[3];
    rest->GetTuple(p, x);
    lattice->GetPoints()->SetPoint(p, x[0] + amplitude * std::sin(7.0 * x[1] + 3.0 * x[2]),
      x[1] + amplitude * std::cos(5.0 * x[0]), x[2] + 0.5 * amplitude * std::sin(9.0 * x[0] * x[1]));
  }
  lattice->GetPoints()->Modified();
}
} // namespace

TEST(vtkFFDFoldCertificate, RestLatticeIsCertifiedEverywhere)
{
  vtkSmartPointer<vtkPolyData> bear = ReadTestMesh("bear");
  std::mt19937 rng(1);
  const int n[3] = { 3, 4, 3 };
  for (int basis : Bases)
  {
    for (int form : { vtkFFDBuildLattice::DENSE, vtkFFDBuildLattice::SPARSE })
    {
      if (basis == vtkFFDBuildLattice::BERNSTEIN && form == vtkFFDBuildLattice::SPARSE)
      {
        continue;
      }
      vtkSmartPointer<vtkPointSet> lattice = ffdtest::MovedLattice(bear, basis, n, form, rng, 0.0);
      vtkNew<vtkFFDFoldCertificate> certificate;
      vtkUnsignedCharArray* states = Certify(certificate, lattice);
      ASSERT_NE(states, nullptr);
      ASSERT_EQ(states->GetNumberOfValues(), lattice->GetNumberOfCells());
      EXPECT_GT(certificate->GetNumberOfCertifiedCells(), 0);
      EXPECT_EQ(certificate->GetNumberOfFoldedCells(), 0) << basis << " " << form;
      EXPECT_EQ(certificate->GetNumberOfUndecidedCells(), 0) << basis << " " << form;
      const auto voxels = VoxelStates(lattice, states, basis);
      EXPECT_EQ(vtkIdType(voxels.size()), certificate->GetNumberOfCertifiedCells()) << basis << " " << form;
      if (form == vtkFFDBuildLattice::SPARSE)
      {
        EXPECT_EQ(certificate->GetNumberOfCertifiedCells(), lattice->GetNumberOfCells());
      }
    }
  }
}

// The same bent lattice, dense and sparse: the same state for every active voxel, and the array maps to the cells
// as documented (VoxelStates() checks that the cells of one voxel agree). Every certified voxel has det J > 0 at
// every sample of the reference; the bends are strong enough to fold some voxels.
TEST(vtkFFDFoldCertificate, DenseAndSparseAgreeAndNeverCertifyAFold)
{
  vtkSmartPointer<vtkPolyData> bear = ReadTestMesh("bear");
  std::mt19937 rng(2);
  const int n[3] = { 3, 3, 3 };
  int folded = 0;
  for (int basis : Bases)
  {
    for (double amplitude : { 0.02, 0.25 })
    {
      std::map<std::array<int, 3>, int> forms[2];
      for (int form : { vtkFFDBuildLattice::DENSE, vtkFFDBuildLattice::SPARSE })
      {
        if (basis == vtkFFDBuildLattice::BERNSTEIN && form == vtkFFDBuildLattice::SPARSE)
        {
          continue;
        }
        vtkSmartPointer<vtkPointSet> lattice = ffdtest::MovedLattice(bear, basis, n, form, rng, 0.0);
        Bend(lattice, amplitude);
        vtkNew<vtkFFDFoldCertificate> certificate;
        forms[form == vtkFFDBuildLattice::SPARSE] = VoxelStates(lattice, Certify(certificate, lattice), basis);
        folded += int(certificate->GetNumberOfFoldedCells());
        if (form == vtkFFDBuildLattice::SPARSE)
        {
          continue; // the same deformation as the dense form's, whose states it must have (below)
        }
        const ffdtest::Reference ref = ffdtest::ReferenceOf(lattice);
        for (const auto& voxel : forms[0])
        {
          if (voxel.second == vtkFFDFoldCertificate::CERTIFIED)
          {
            EXPECT_GT(SampledMinimum(ref, voxel.first), 0.0) << basis << " " << amplitude;
          }
        }
      }
      if (basis != vtkFFDBuildLattice::BERNSTEIN)
      {
        EXPECT_EQ(forms[0], forms[1]) << basis << " " << amplitude;
      }
    }
  }
  EXPECT_GT(folded, 0);
}

// A control point pushed along S far beyond its neighbours: voxel (1, 1, 1), on its +S side, turns inside out,
// on the reference's word too; in a frame of either orientation (U reversed: det(S, T, U) < 0, whose rest state
// the certificate must read as unfolded).
TEST(vtkFFDFoldCertificate, PushedControlPointFoldsItsVoxels)
{
  const ffdref::Frame frames[2] = { { { 0, 0, 0 }, { 3, 0, 0 }, { 0, 3, 0 }, { 0, 0, 3 } },
    { { 0, 0, 3 }, { 3, 0, 0 }, { 0, 3, 0 }, { 0, 0, -3 } } };
  const int n[3] = { 3, 3, 3 };
  for (int basis : { vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::CUBIC_BSPLINE })
    for (const ffdref::Frame& f : frames)
    {
      vtkSmartPointer<vtkStructuredGrid> lattice = ffdtest::MakeLattice(f, basis, n);
      vtkNew<vtkFFDFoldCertificate> atRest;
      Certify(atRest, lattice);
      EXPECT_EQ(atRest->GetNumberOfCertifiedCells(), 27) << basis;
      // Trilinear: the low corner of voxel (1, 1, 1), point 1; the B-spline's: its second, point 2, 6 spacings on.
      const int dims = ffdtest::PointsAlongAxis(basis, 3), low = basis == vtkFFDBuildLattice::TRILINEAR ? 1 : 2;
      const vtkIdType pushed = low + dims * (low + dims * low);
      double x[3];
      lattice->GetPoint(pushed, x);
      lattice->GetPoints()->SetPoint(pushed, x[0] + 6.0, x[1], x[2]);
      vtkNew<vtkFFDFoldCertificate> certificate;
      const auto voxels = VoxelStates(lattice, Certify(certificate, lattice), basis);
      EXPECT_EQ(voxels.size(), 27u);
      EXPECT_GT(certificate->GetNumberOfFoldedCells(), 0);
      const ffdtest::Reference ref = ffdtest::ReferenceOf(lattice);
      EXPECT_EQ(voxels.at({ 1, 1, 1 }), vtkFFDFoldCertificate::FOLDED) << basis;
      EXPECT_LE(SampledMinimum(ref, { 1, 1, 1 }), 0.0) << basis;
      for (const auto& voxel : voxels)
      {
        if (voxel.second == vtkFFDFoldCertificate::CERTIFIED)
        {
          EXPECT_GT(SampledMinimum(ref, voxel.first), 0.0) << basis;
        }
      }
    }
}

// Each tetrahedron against the sign of the reference's signed volumes, rest and moved; inverted rest tetrahedra
// are certified while they keep their orientation; one node dragged through the opposite face folds.
TEST(vtkFFDFoldCertificate, TetrahedraBySignedVolume)
{
  const double bounds[6] = { 0, 1, 0, 1, 0, 1 };
  vtkSmartPointer<vtkUnstructuredGrid> lattice = ffdtest::KuhnBoxLattice(2, bounds, 0.2, true);
  vtkNew<vtkFFDFoldCertificate> certificate;
  Certify(certificate, lattice);
  EXPECT_EQ(certificate->GetNumberOfCertifiedCells(), lattice->GetNumberOfCells());
  std::mt19937 rng(5);
  ffdtest::Perturb(lattice, rng, 0.3);
  vtkUnsignedCharArray* states = Certify(certificate, lattice);
  vtkDataArray* rest = lattice->GetPointData()->GetArray(vtkFFDDataContract::RestPositionArrayName());
  vtkIdType folded = 0;
  vtkNew<vtkIdList> ids;
  for (vtkIdType c = 0; c < lattice->GetNumberOfCells(); ++c)
  {
    lattice->GetCellPoints(c, ids);
    std::array<Vec, 4> before, after;
    for (int p = 0; p < 4; ++p)
    {
      rest->GetTuple(ids->GetId(p), before[p].data());
      lattice->GetPoint(ids->GetId(p), after[p].data());
    }
    const double v0 = ffdref::SignedVolume(before[0], before[1], before[2], before[3]);
    const double v1 = ffdref::SignedVolume(after[0], after[1], after[2], after[3]);
    const int expected = v0 * v1 > 0 ? vtkFFDFoldCertificate::CERTIFIED : vtkFFDFoldCertificate::FOLDED;
    EXPECT_EQ(states->GetValue(c), expected) << c;
    folded += expected == vtkFFDFoldCertificate::FOLDED;
  }
  EXPECT_GT(folded, 0);
  EXPECT_EQ(certificate->GetNumberOfFoldedCells(), folded);
  EXPECT_EQ(certificate->GetNumberOfCertifiedCells() + folded, lattice->GetNumberOfCells());
}

TEST(vtkFFDFoldCertificate, BadInputIsAnErrorAndAnEmptyOutput)
{
  const ffdref::Frame f{ { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 } };
  const int n[3] = { 2, 2, 2 };
  vtkSmartPointer<vtkStructuredGrid> lattice = ffdtest::MakeLattice(f, vtkFFDBuildLattice::TRILINEAR, n);
  vtkNew<vtkFFDFoldCertificate> certificate;
  certificate->SetInputData(lattice);
  ffdtest::ExpectClearInputErrors(certificate, 0, "the lattice", "SetInputConnection() to a lattice");

  vtkNew<vtkStructuredGrid> noRest;
  noRest->DeepCopy(lattice);
  noRest->GetPointData()->RemoveArray(vtkFFDDataContract::RestPositionArrayName());
  vtkNew<vtkStructuredGrid> offFrame;
  offFrame->DeepCopy(lattice);
  offFrame->GetPointData()->GetArray(vtkFFDDataContract::RestPositionArrayName())->SetComponent(4, 0, 0.7);
  for (vtkPointSet* bad : { static_cast<vtkPointSet*>(noRest), static_cast<vtkPointSet*>(offFrame) })
  {
    vtkNew<vtkFFDFoldCertificate> filter;
    vtkNew<FFDTestErrorObserver> errors;
    errors->WatchWithExecutive(filter);
    filter->SetInputData(bad);
    filter->Update();
    EXPECT_NE(errors->Errors.find("RestPosition"), std::string::npos) << errors->Errors;
    EXPECT_EQ(vtkPointSet::SafeDownCast(filter->GetOutputDataObject(0))->GetNumberOfPoints(), 0);
    EXPECT_EQ(filter->GetNumberOfCertifiedCells(), 0);
  }
  vtkNew<vtkUnstructuredGrid> empty;
  certificate->SetInputData(empty);
  EXPECT_EQ(ffdtest::UpdateErrors(certificate), "");
  EXPECT_EQ(vtkPointSet::SafeDownCast(certificate->GetOutputDataObject(0))->GetNumberOfPoints(), 0);
}

// Progress reaches 1 through the filter's own reports; an abort asked for at the start (the executive's report of 0)
// leaves an empty output and no error.
TEST(vtkFFDFoldCertificate, ProgressAndAbort)
{
  const ffdref::Frame f{ { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 } };
  const int n[3] = { 4, 4, 4 };
  vtkSmartPointer<vtkStructuredGrid> lattice = ffdtest::MakeLattice(f, vtkFFDBuildLattice::CUBIC_BSPLINE, n);
  struct Seen
  {
    std::vector<double> Progress;
    bool Abort = false;
  } seen;
  vtkNew<vtkCallbackCommand> observer;
  observer->SetClientData(&seen);
  observer->SetCallback(
    [](vtkObject* caller, unsigned long, void* clientData, void* callData)
    {
      Seen& s = *static_cast<Seen*>(clientData);
      s.Progress.push_back(*static_cast<double*>(callData));
      if (s.Abort)
      {
        vtkAlgorithm::SafeDownCast(caller)->SetAbortExecute(1);
      }
    });
  vtkNew<vtkFFDFoldCertificate> certificate;
  certificate->AddObserver(vtkCommand::ProgressEvent, observer);
  vtkNew<FFDTestErrorObserver> errors;
  errors->WatchWithExecutive(certificate);
  certificate->SetInputData(lattice);
  certificate->Update();
  EXPECT_TRUE(std::find_if(seen.Progress.begin(), seen.Progress.end(), [](double p) { return p > 0 && p < 1; }) !=
    seen.Progress.end());
  EXPECT_EQ(certificate->GetNumberOfCertifiedCells(), 64);
  seen.Abort = true;
  certificate->Modified();
  certificate->Update();
  EXPECT_EQ(errors->Errors, "");
  EXPECT_EQ(vtkPointSet::SafeDownCast(certificate->GetOutputDataObject(0))->GetNumberOfPoints(), 0);
}
