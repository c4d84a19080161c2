// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDDeformBlocks.h"

#include "vtkCellData.h"
#include "vtkDataArray.h"
#include "vtkFFDDataContract.h"
#include "vtkFFDDeform.h"
#include "vtkFFDInputChecks.h"
#include "vtkFFDMemory.h"
#include "vtkFFDPipelineKeys.h"
#include "vtkFFDTetrahedralDeformer.h"
#include "vtkFieldData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkSMPTools.h"
#include "vtkSmartPointer.h"

#include "FFDFrame.h"

#include <cmath>
#include <vector>

vtkStandardNewMacro(vtkFFDDeformBlocks);

struct vtkFFDDeformBlocks::Internals
{
  // One vtkFFDDeform per lattice, kept across updates so that each keeps its binding.
  std::vector<vtkSmartPointer<vtkFFDDeform>> Deformers;
};

namespace
{
/// phi_b of the class comment at parameters stu; negative outside the frame.
double Bump(const ffd::Vec3<double>& stu)
{
  double phi = 1;
  for (int a = 0; a < 3; ++a)
  {
    if (!(stu[a] >= 0 && stu[a] <= 1))
    {
      return -1;
    }
    phi *= 4 * stu[a] * (1 - stu[a]);
  }
  return phi;
}
} // namespace

//------------------------------------------------------------------------------------------------------------
vtkFFDDeformBlocks::vtkFFDDeformBlocks()
  : Composition(BLEND)
  , TransformNormals(true)
  , Backend(vtkFFDDeform::AUTOMATIC)
  , Internal(new Internals)
{
  this->SetNumberOfInputPorts(2);
}

//------------------------------------------------------------------------------------------------------------
vtkFFDDeformBlocks::~vtkFFDDeformBlocks() = default;

//------------------------------------------------------------------------------------------------------------
int vtkFFDDeformBlocks::FillInputPortInformation(int port, vtkInformation* info)
{
  if (port == 1)
  {
    info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkPointSet");
    info->Set(vtkAlgorithm::INPUT_IS_REPEATABLE(), 1);
    return 1;
  }
  return this->Superclass::FillInputPortInformation(port, info);
}

//------------------------------------------------------------------------------------------------------------
vtkTypeBool vtkFFDDeformBlocks::ProcessRequest(
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
int vtkFFDDeformBlocks::RequestDataObject(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  if (!(vtkFFDCheckInput(this, inputVector[0], 0, "vtkPointSet", "the mesh",
          "SetInputConnection() to the mesh to deform (a vtkPolyData, vtkUnstructuredGrid or other vtkPointSet).") &&
        vtkFFDCheckInput(
          this, inputVector[1], 1, "vtkPointSet", "the lattices", "AddLatticeConnection() for each lattice.")))
  {
    return vtkFFDEmptyOutputs(outputVector);
  }
  return this->Superclass::RequestDataObject(request, inputVector, outputVector);
}

//------------------------------------------------------------------------------------------------------------
int vtkFFDDeformBlocks::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkPointSet* input = vtkPointSet::GetData(inputVector[0]);
  vtkPointSet* output = vtkPointSet::GetData(outputVector);
  if (!input)
  {
    return 1;
  }
  output->CopyStructure(input);
  output->GetPointData()->PassData(input->GetPointData());
  output->GetCellData()->PassData(input->GetCellData());
  output->GetFieldData()->PassData(input->GetFieldData());
  const int count = inputVector[1]->GetNumberOfInformationObjects();
  const vtkIdType numPoints = input->GetNumberOfPoints();
  if (numPoints == 0 || count == 0)
  {
    return 1;
  }

  // Each lattice's deformation of the mesh, and its frame where the blend needs it.
  std::vector<vtkSmartPointer<vtkFFDDeform>>& deformers = this->Internal->Deformers;
  deformers.resize(std::size_t(count));
  std::vector<vtkPointSet*> moved(static_cast<std::size_t>(count));
  std::vector<ffd::Frame<double>> frames;
  for (int b = 0; b < count; ++b)
  {
    vtkPointSet* lattice = vtkPointSet::GetData(inputVector[1], b);
    double frame[12] = { 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1 };
    if (lattice && lattice->GetNumberOfPoints() == 0)
    {
      frames.push_back(ffd::Frame<double>::FromArray(frame));
      continue; // an empty lattice (a detail lattice over no voxel) moves nothing
    }
    if (this->Composition == BLEND)
    {
      if (!lattice || vtkFFDTetrahedralDeformer::IsTetrahedralLattice(lattice))
      {
        vtkErrorMacro(<< "Lattice " << b << " is tetrahedral: BLEND weighs grid lattices by their frames; add "
                      << "tetrahedral lattices with SetCompositionToAdd().");
        output->Initialize();
        return 0;
      }
      if (!vtkFFDDataContract::GetFrame(lattice, frame))
      {
        vtkErrorMacro(<< "Lattice " << b << " has no valid " << vtkFFDDataContract::FrameArrayName()
                      << ": connect lattices of vtkFFDBuildLattice.");
        output->Initialize();
        return 0;
      }
      frames.push_back(ffd::Frame<double>::FromArray(frame));
    }
    if (!deformers[b])
    {
      deformers[b] = vtkSmartPointer<vtkFFDDeform>::New();
    }
    vtkFFDDeform* deform = deformers[b];
    deform->SetInputData(input);
    deform->SetLatticeData(lattice);
    deform->SetTransformNormals(this->TransformNormals);
    deform->SetBackend(this->Backend);
    deform->Update();
    moved[b] = vtkPointSet::SafeDownCast(deform->GetOutputDataObject(0));
    if (!moved[b] || moved[b]->GetNumberOfPoints() != numPoints)
    {
      vtkErrorMacro(<< "Lattice " << b << " could not deform the input (see the error above).");
      output->Initialize();
      return 0;
    }
    this->UpdateProgress(0.9 * (b + 1) / count);
  }

  // Their combination, point by point.
  vtkPoints* inPoints = input->GetPoints();
  vtkSmartPointer<vtkPoints> outPoints = vtkSmartPointer<vtkPoints>::New();
  outPoints->SetDataType(inPoints->GetDataType());
  outPoints->SetNumberOfPoints(numPoints);
  vtkDataArray* inNormals = input->GetPointData()->GetNormals();
  std::vector<vtkDataArray*> movedNormals(static_cast<std::size_t>(count), nullptr);
  vtkSmartPointer<vtkDataArray> outNormals;
  // Normals of another size are passed on as they are (each vtkFFDDeform warns that it cannot transform them).
  if (this->TransformNormals && inNormals && inNormals->GetNumberOfComponents() == 3 &&
    inNormals->GetNumberOfTuples() == numPoints)
  {
    for (int b = 0; b < count; ++b)
    {
      movedNormals[b] = moved[b] ? moved[b]->GetPointData()->GetNormals() : nullptr;
    }
    outNormals = vtkSmartPointer<vtkDataArray>::Take(inNormals->NewInstance());
    outNormals->SetName(inNormals->GetName());
    outNormals->SetNumberOfComponents(3);
    outNormals->SetNumberOfTuples(numPoints);
  }
  const bool blend = this->Composition == BLEND;
  vtkSMPTools::For(0, numPoints,
    [&](vtkIdType begin, vtkIdType end)
    {
      std::vector<double> weights(static_cast<std::size_t>(count));
      for (vtkIdType p = begin; p < end; ++p)
      {
        double x[3];
        inPoints->GetPoint(p, x);
        double total = 0;
        int holders = 0;
        for (int b = 0; b < count; ++b)
        {
          weights[b] = !moved[b] ? -1.0 : (blend ? Bump(frames[b].ToParametric({ x[0], x[1], x[2] })) : 1.0);
          holders += weights[b] >= 0;
          total += std::max(weights[b], 0.0);
        }
        double sum[3] = { 0, 0, 0 }, normal[3] = { 0, 0, 0 }, n0[3] = { 0, 0, 0 }, only[3] = { 0, 0, 0 };
        int movers = 0, onlyWeighsOne = 0;
        if (outNormals)
        {
          inNormals->GetTuple(p, n0);
        }
        for (int b = 0; b < count; ++b)
        {
          double w = weights[b];
          if (blend)
          {
            w = w < 0 ? 0.0 : (total > 0 ? w / total : 1.0 / holders);
          }
          if (w <= 0)
          {
            continue;
          }
          double y[3];
          moved[b]->GetPoint(p, y);
          if (y[0] != x[0] || y[1] != x[1] || y[2] != x[2])
          {
            ++movers;
            onlyWeighsOne = w == 1;
            std::copy(y, y + 3, only);
          }
          for (int c = 0; c < 3; ++c)
          {
            sum[c] += w * (y[c] - x[c]);
          }
          if (outNormals && movedNormals[b])
          {
            double n[3];
            movedNormals[b]->GetTuple(p, n);
            for (int c = 0; c < 3; ++c)
            {
              normal[c] += blend ? w * n[c] : n[c] - n0[c];
            }
          }
        }
        // One lattice alone moving the point with all its weight: its result as it is (x + (y - x) may round).
        if (movers == 1 && onlyWeighsOne)
        {
          outPoints->SetPoint(p, only);
        }
        else
        {
          outPoints->SetPoint(p, x[0] + sum[0], x[1] + sum[1], x[2] + sum[2]);
        }
        if (outNormals)
        {
          if (blend && holders == 0)
          {
            std::copy(n0, n0 + 3, normal);
          }
          else if (!blend)
          {
            for (int c = 0; c < 3; ++c)
            {
              normal[c] += n0[c];
            }
          }
          const double length = std::sqrt(normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]);
          for (int c = 0; c < 3 && length > 0; ++c)
          {
            normal[c] /= length;
          }
          outNormals->SetTuple(p, length > 0 ? normal : n0);
        }
      }
    });
  output->SetPoints(outPoints);
  if (outNormals)
  {
    output->GetPointData()->SetNormals(outNormals);
  }
  this->UpdateProgress(1.0);
  return 1;
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDDeformBlocks::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Composition: " << (this->Composition == BLEND ? "Blend" : "Add") << "\n";
  os << indent << "TransformNormals: " << this->TransformNormals << "\n";
  os << indent << "Backend: " << this->Backend << "\n";
}
