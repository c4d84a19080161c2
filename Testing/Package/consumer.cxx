// SPDX-License-Identifier: BSD-3-Clause
// The package test's consumer: voxelizes a sphere, builds a trilinear lattice, moves one control point and
// deforms; exits non-zero unless some points moved and the rest lattice left them in place.
#include "vtkFFDBuildLattice.h"
#include "vtkFFDDeform.h"
#include "vtkFFDVoxelize.h"
#include "vtkNew.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSphereSource.h"
#include "vtkStructuredGrid.h"

#include <cstdio>

int main()
{
  vtkNew<vtkSphereSource> sphere;
  sphere->Update();
  vtkNew<vtkFFDVoxelize> voxelize;
  voxelize->SetInputConnection(sphere->GetOutputPort());
  voxelize->SetDivisions(2, 2, 2);
  vtkNew<vtkFFDBuildLattice> build;
  build->SetInputConnection(voxelize->GetOutputPort());
  build->SetBasisToTrilinear();
  build->SetLatticeFormToDense();
  build->Update();
  vtkNew<vtkStructuredGrid> lattice;
  lattice->DeepCopy(build->GetOutput());
  vtkNew<vtkFFDDeform> deform;
  deform->SetInputConnection(sphere->GetOutputPort());
  deform->SetLatticeData(lattice);
  deform->Update();
  vtkPolyData* in = sphere->GetOutput();
  vtkPointSet* out = deform->GetOutput();
  for (vtkIdType id = 0; id < in->GetNumberOfPoints(); ++id)
  {
    double a[3], b[3];
    in->GetPoint(id, a);
    out->GetPoint(id, b);
    if (a[0] != b[0] || a[1] != b[1] || a[2] != b[2])
    {
      std::printf("the rest lattice moved point %lld\n", static_cast<long long>(id));
      return 1;
    }
  }
  double p[3];
  lattice->GetPoint(13, p); // the centre control point of the 3x3x3 lattice
  lattice->GetPoints()->SetPoint(13, p[0] + 0.1, p[1], p[2]);
  lattice->GetPoints()->Modified();
  deform->Update();
  vtkIdType moved = 0;
  for (vtkIdType id = 0; id < in->GetNumberOfPoints(); ++id)
  {
    double a[3], b[3];
    in->GetPoint(id, a);
    out->GetPoint(id, b);
    moved += (a[0] != b[0]) ? 1 : 0;
  }
  std::printf(
    "%lld of %lld points moved\n", static_cast<long long>(moved), static_cast<long long>(in->GetNumberOfPoints()));
  return moved > 0 ? 0 : 1;
}
