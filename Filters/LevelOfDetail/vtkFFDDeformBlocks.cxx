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

#include <algorithm>
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

/// Appends `lattice`'s frame (lattice `b`) to `frames`; false, said why, where it has none that BLEND can use.
bool AddFrame(vtkFFDDeformBlocks* self, vtkPointSet* lattice, int b, std::vector<ffd::Frame<double>>& frames)
{
  double frame[12] = { 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1 };
  if (!lattice || vtkFFDTetrahedralDeformer::IsTetrahedralLattice(lattice))
  {
    vtkErrorWithObjectMacro(self, << "Lattice " << b << " is tetrahedral: BLEND weighs grid lattices by their "
                                  << "frames; add tetrahedral lattices with SetCompositionToAdd().");
    return false;
  }
  if (!vtkFFDDataContract::GetFrame(lattice, frame))
  {
    vtkErrorWithObjectMacro(self, << "Lattice " << b << " has no valid " << vtkFFDDataContract::FrameArrayName()
                                  << ": connect lattices of vtkFFDBuildLattice.");
    return false;
  }
  frames.push_back(ffd::Frame<double>::FromArray(frame));
  return true;
}

/// `input` deformed by `lattice` (lattice `b`) through `deform` (made where null, kept for the next update, so
/// that it keeps its binding); nullptr, said why, where it cannot be.
vtkPointSet* DeformByLattice(vtkFFDDeformBlocks* self, vtkSmartPointer<vtkFFDDeform>& deform, vtkPointSet* input,
  vtkPointSet* lattice, int b, bool transformNormals, int backend)
{
  if (!deform)
  {
    deform = vtkSmartPointer<vtkFFDDeform>::New();
  }
  deform->SetInputData(input);
  deform->SetLatticeData(lattice);
  deform->SetTransformNormals(transformNormals);
  deform->SetBackend(backend);
  deform->Update();
  vtkPointSet* moved = vtkPointSet::SafeDownCast(deform->GetOutputDataObject(0));
  if (!moved || moved->GetNumberOfPoints() != input->GetNumberOfPoints())
  {
    vtkErrorWithObjectMacro(self, << "Lattice " << b << " could not deform the input (see the error above).");
    return nullptr;
  }
  return moved;
}

/// The output's normals, where the input's are to be transformed, and each deformation's normals into
/// `movedNormals`; else nullptr. Normals of another size are passed on as they are (each vtkFFDDeform warns that
/// it cannot transform them).
vtkSmartPointer<vtkDataArray> NormalsToCombine(bool transformNormals, vtkDataArray* inNormals, vtkIdType numPoints,
  const std::vector<vtkPointSet*>& moved, std::vector<vtkDataArray*>& movedNormals)
{
  if (!(transformNormals && inNormals && inNormals->GetNumberOfComponents() == 3 &&
        inNormals->GetNumberOfTuples() == numPoints))
  {
    return nullptr;
  }
  for (std::size_t b = 0; b < moved.size(); ++b)
  {
    movedNormals[b] = moved[b] ? moved[b]->GetPointData()->GetNormals() : nullptr;
  }
  const auto outNormals = vtkSmartPointer<vtkDataArray>::Take(inNormals->NewInstance());
  outNormals->SetName(inNormals->GetName());
  outNormals->SetNumberOfComponents(3);
  outNormals->SetNumberOfTuples(numPoints);
  return outNormals;
}

/// The combination of the lattices' deformations of a mesh, point by point.
struct Combination
{
  bool Blend;
  const std::vector<vtkPointSet*>& Moved;        // each lattice's deformation (null: an empty lattice)
  const std::vector<ffd::Frame<double>>& Frames; // each lattice's frame, where blending
  vtkPoints* InPoints;
  vtkDataArray* InNormals;
  const std::vector<vtkDataArray*>& MovedNormals; // each deformation's normals, where they are combined
  vtkPoints* OutPoints;
  vtkDataArray* OutNormals; // null: normals not combined

  /// Each lattice's weight at `x` (negative: none) into `weights`, and their sum over those that hold `x`
  /// (`total`); returns how many hold it.
  int Weigh(const double x[3], std::vector<double>& weights, double& total) const
  {
    total = 0;
    int holders = 0;
    for (std::size_t b = 0; b < weights.size(); ++b)
    {
      weights[b] =
        !this->Moved[b] ? -1.0 : (this->Blend ? Bump(this->Frames[b].ToParametric({ x[0], x[1], x[2] })) : 1.0);
      holders += weights[b] >= 0;
      total += std::max(weights[b], 0.0);
    }
    return holders;
  }

  /// The output's point `p` and its normal (`weights`: room for a weight per lattice).
  void Combine(vtkIdType p, std::vector<double>& weights) const
  {
    double x[3];
    this->InPoints->GetPoint(p, x);
    double total;
    const int holders = this->Weigh(x, weights, total);
    double sum[3] = { 0, 0, 0 }, normal[3] = { 0, 0, 0 }, n0[3] = { 0, 0, 0 }, only[3] = { 0, 0, 0 };
    int movers = 0, onlyWeighsOne = 0;
    if (this->OutNormals)
    {
      this->InNormals->GetTuple(p, n0);
    }
    for (std::size_t b = 0; b < weights.size(); ++b)
    {
      double w = weights[b];
      if (this->Blend)
      {
        w = w < 0 ? 0.0 : (total > 0 ? w / total : 1.0 / holders);
      }
      if (w <= 0)
      {
        continue;
      }
      double y[3];
      this->Moved[b]->GetPoint(p, y);
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
      if (this->OutNormals && this->MovedNormals[b])
      {
        double n[3];
        this->MovedNormals[b]->GetTuple(p, n);
        for (int c = 0; c < 3; ++c)
        {
          normal[c] += this->Blend ? w * n[c] : n[c] - n0[c];
        }
      }
    }
    // One lattice alone moving the point with all its weight: its result as it is (x + (y - x) may round).
    if (movers == 1 && onlyWeighsOne)
    {
      this->OutPoints->SetPoint(p, only);
    }
    else
    {
      this->OutPoints->SetPoint(p, x[0] + sum[0], x[1] + sum[1], x[2] + sum[2]);
    }
    if (this->OutNormals)
    {
      this->SetNormal(p, normal, n0, holders);
    }
  }

  /// The output's normal at `p`: the lattices' `normal` (blended, or the sum of their changes to the input's
  /// `n0`), normalized; `n0` where there is none.
  void SetNormal(vtkIdType p, double normal[3], const double n0[3], int holders) const
  {
    if (this->Blend && holders == 0)
    {
      std::copy(n0, n0 + 3, normal);
    }
    else if (!this->Blend)
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
    this->OutNormals->SetTuple(p, length > 0 ? normal : n0);
  }
};
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
    if (lattice && lattice->GetNumberOfPoints() == 0)
    {
      const double identity[12] = { 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1 };
      frames.push_back(ffd::Frame<double>::FromArray(identity));
      continue; // an empty lattice (a detail lattice over no voxel) moves nothing
    }
    if ((this->Composition == BLEND && !AddFrame(this, lattice, b, frames)) ||
      !(moved[b] = DeformByLattice(this, deformers[b], input, lattice, b, this->TransformNormals, this->Backend)))
    {
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
  const vtkSmartPointer<vtkDataArray> outNormals =
    NormalsToCombine(this->TransformNormals, inNormals, numPoints, moved, movedNormals);
  const Combination combination{ this->Composition == BLEND, moved, frames, inPoints, inNormals, movedNormals,
    outPoints, outNormals };
  vtkSMPTools::For(0, numPoints,
    [&](vtkIdType begin, vtkIdType end)
    {
      std::vector<double> weights(static_cast<std::size_t>(count));
      for (vtkIdType p = begin; p < end; ++p)
      {
        combination.Combine(p, weights);
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
