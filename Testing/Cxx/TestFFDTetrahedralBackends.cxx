// SPDX-License-Identifier: BSD-3-Clause
// Tetrahedral lattices under vtkFFDDeform's backends, with the rules of grid lattices: AUTOMATIC takes CUDA only
// where a device is present; CUDA asked for where it cannot run falls back to the CPU with a warning and the very
// same output; GetLastBackendUsed() names what ran; the binding (computed on the CPU for both) is counted once.
// Where a device runs (never on the CPU-only machines of CI) its float32 result must match the CPU's within 1e-5
// of the lattice's diagonal, points clamped to the control mesh included (the same host code moves them).
#include "vtkFFDBuildTetrahedralLattice.h"
#include "vtkFFDDeform.h"

#include "FFDTestErrorObserver.h"
#include "FFDTestLattices.h"
#include "FFDTestMeshes.h"

#include "vtkDataArray.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkTransform.h"
#include "vtkTransformFilter.h"
#include "vtkUnstructuredGrid.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

namespace
{
using ffdtest::Perturb;

// The largest difference between two arrays of the same shape, over all components.
double LargestDifference(vtkDataArray* a, vtkDataArray* b)
{
  double worst = 0.0;
  for (vtkIdType t = 0; t < a->GetNumberOfTuples(); ++t)
  {
    for (int c = 0; c < a->GetNumberOfComponents(); ++c)
    {
      worst = std::max(worst, std::fabs(a->GetComponent(t, c) - b->GetComponent(t, c)));
    }
  }
  return worst;
}

TEST(vtkFFDDeformTetrahedral, BackendChoiceAndCpuFallback)
{
  std::mt19937 rng(23);
  vtkSmartPointer<vtkPolyData> mesh = ReadTestMesh("bear");
  vtkSmartPointer<vtkPolyData> withNormals = ffdtest::WithPointNormals(mesh); // the same points as the mesh

  // The control mesh of the bear shrunk by 10 % about its centre: the points it leaves outside are clamped.
  double center[3];
  mesh->GetCenter(center);
  vtkNew<vtkTransform> shrink;
  shrink->Translate(center);
  shrink->Scale(0.9, 0.9, 0.9);
  shrink->Translate(-center[0], -center[1], -center[2]);
  vtkNew<vtkTransformFilter> shrunk;
  shrunk->SetInputData(mesh);
  shrunk->SetTransform(shrink);
  vtkNew<vtkFFDBuildTetrahedralLattice> build;
  build->SetInputConnection(shrunk->GetOutputPort());
  build->SetSubdivisionLevels(1);
  build->Update();
  vtkNew<vtkUnstructuredGrid> lattice;
  lattice->DeepCopy(build->GetOutput());
  const double diagonal = lattice->GetLength();
  Perturb(lattice, rng, 0.02 * diagonal);

  vtkNew<vtkFFDDeform> deform;
  deform->SetInputData(withNormals);
  deform->SetLatticeData(lattice);
  deform->SetOutsidePolicyToClampToEdge();
  deform->ComputeJacobianDeterminantOn();
  deform->SetBackendToCPU();
  deform->Update();
  EXPECT_STREQ(deform->GetLastBackendUsed(), "CPU");
  vtkNew<vtkPolyData> cpu;
  cpu->DeepCopy(deform->GetOutput());
  const double moved = LargestDifference(cpu->GetPoints()->GetData(), mesh->GetPoints()->GetData());
  EXPECT_GT(moved, 1e-3 * diagonal);

  for (int backend : { vtkFFDDeform::AUTOMATIC, vtkFFDDeform::CUDA })
  {
    deform->SetBackend(backend);
    vtkNew<FFDTestErrorObserver> observer;
    observer->Watch(deform);
    deform->Update();
    EXPECT_TRUE(observer->Errors.empty()) << observer->Errors;
    vtkPointSet* output = deform->GetOutput();
    const double points = LargestDifference(cpu->GetPoints()->GetData(), output->GetPoints()->GetData());
    const double unitNormals =
      LargestDifference(cpu->GetPointData()->GetNormals(), output->GetPointData()->GetNormals());
    const double determinants =
      LargestDifference(cpu->GetPointData()->GetArray(vtkFFDDeform::JacobianDeterminantArrayName()),
        output->GetPointData()->GetArray(vtkFFDDeform::JacobianDeterminantArrayName()));
    const std::string used = deform->GetLastBackendUsed();
    if (used == "CUDA")
    {
      EXPECT_LE(points / diagonal, 1e-5);
      EXPECT_LE(unitNormals, 1e-5);
      EXPECT_LE(determinants, 1e-5);
    }
    else
    {
      EXPECT_EQ(used, "CPU");
      EXPECT_EQ(points, 0.0); // the very same CPU computation
      EXPECT_EQ(unitNormals, 0.0);
      EXPECT_EQ(determinants, 0.0);
      if (backend == vtkFFDDeform::CUDA)
      {
        EXPECT_NE(observer->Warnings.find("CUDA backend cannot run"), std::string::npos) << observer->Warnings;
      }
      else
      {
        EXPECT_TRUE(observer->Warnings.empty()) << observer->Warnings; // AUTOMATIC falls back silently
      }
    }
    // The lattice moved again: only the evaluation runs, on the same binding.
    Perturb(lattice, rng, 0.01 * diagonal);
    deform->SetBackendToCPU();
    deform->Update();
    cpu->DeepCopy(deform->GetOutput());
  }
  EXPECT_EQ(deform->GetNumberOfBindings(), 1);
}
} // namespace
