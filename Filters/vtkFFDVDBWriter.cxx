// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDVDBWriter.h"

#include "vtkCellData.h"
#include "vtkDoubleArray.h"
#include "vtkErrorCode.h"
#include "vtkFFDBuildLattice.h"
#include "vtkFFDDataContract.h"
#include "vtkFFDMemory.h"
#include "vtkFFDSparseLattice.h"
#include "vtkInformation.h"
#include "vtkIntArray.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkStructuredGrid.h"
#include "vtkUnstructuredGrid.h"

#include "FFDFrame.h"
#include "FFDGridBasis.h"

#include "vtkFFDOpenVDB.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <new>
#include <string>

vtkStandardNewMacro(vtkFFDVDBWriter);

namespace
{
/// The transform whose index (i, j, k) is X0 + (a0 i + b0) S + (a1 j + b1) T + (a2 k + b2) U: OpenVDB's matrices
/// act on row vectors, so the rows are the index axes' world steps and the translation.
openvdb::math::Transform::Ptr AffineTransform(const double frame[12], const double a[3], const double b[3])
{
  openvdb::math::Mat4d m = openvdb::math::Mat4d::identity();
  for (int c = 0; c < 3; ++c)
  {
    for (int axis = 0; axis < 3; ++axis)
    {
      m(axis, c) = a[axis] * frame[3 + 3 * axis + c];
    }
    m(3, c) = frame[c] + b[0] * frame[3 + c] + b[1] * frame[6 + c] + b[2] * frame[9 + c];
  }
  return openvdb::math::Transform::createLinearTransform(m);
}

/// The frame and divisions as grid metadata, and the basis where `basis` is a basis (the lattice's grids).
void SetDescription(openvdb::GridBase& grid, const double frame[12], const int divisions[3], int basis)
{
  const char* frameKeys[4] = { vtkFFDVDB::FrameOrigin, vtkFFDVDB::FrameS, vtkFFDVDB::FrameT, vtkFFDVDB::FrameU };
  for (int v = 0; v < 4; ++v)
  {
    grid.insertMeta(
      frameKeys[v], openvdb::Vec3DMetadata(openvdb::Vec3d(frame[3 * v], frame[3 * v + 1], frame[3 * v + 2])));
  }
  grid.insertMeta(vtkFFDVDB::Divisions, openvdb::Vec3IMetadata(openvdb::Vec3i(divisions)));
  if (basis >= 0)
  {
    grid.insertMeta(vtkFFDVDB::Basis, openvdb::StringMetadata(vtkFFDBuildLattice::GetBasisAsString(basis)));
  }
}

/// The 3-component array `name` of `data`, of type ArrayT, with `count` tuples, or null.
template <typename ArrayT>
ArrayT* TupleArray(vtkFieldData* data, const char* name, vtkIdType count)
{
  ArrayT* array = ArrayT::SafeDownCast(data->GetAbstractArray(name));
  return array && array->GetNumberOfComponents() == 3 && array->GetNumberOfTuples() == count ? array : nullptr;
}

/// The first (i, j, k) of `count` in `index` outside [0, limits) per axis, or -1.
vtkIdType FirstOutside(const int* index, vtkIdType count, const int limits[3])
{
  for (vtkIdType t = 0; t < count; ++t)
  {
    for (int a = 0; a < 3; ++a)
    {
      if (index[3 * t + a] < 0 || index[3 * t + a] >= limits[a])
      {
        return t;
      }
    }
  }
  return -1;
}
} // namespace

//------------------------------------------------------------------------------------------------------------
vtkFFDVDBWriter::vtkFFDVDBWriter()
  : FileName(nullptr)
{
}

vtkFFDVDBWriter::~vtkFFDVDBWriter()
{
  this->SetFileName(nullptr);
}

//------------------------------------------------------------------------------------------------------------
int vtkFFDVDBWriter::FillInputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkDataSet");
  return 1;
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDVDBWriter::WriteData()
{
  if (!this->FileName || !*this->FileName)
  {
    vtkErrorMacro(<< "No FileName: call SetFileName() with the .vdb file to write.");
    this->SetErrorCode(vtkErrorCode::NoFileNameError);
    return;
  }
  // OpenVDB reports failures by exceptions, and the lattice's size may exhaust the memory: neither may leave
  // Write().
  std::string failure;
  try
  {
    if (!this->WriteLattice(this->GetInput()) && this->GetErrorCode() == vtkErrorCode::NoError)
    {
      this->SetErrorCode(vtkErrorCode::UnknownError);
    }
    return;
  }
  catch (const openvdb::Exception& e)
  {
    failure = std::string("OpenVDB failed (") + e.what() + ").";
  }
  catch (const std::bad_alloc&)
  {
    failure = "out of memory: write a smaller lattice or free memory.";
  }
  this->SetErrorCode(vtkErrorCode::UnknownError);
  vtkErrorMacro(<< "Cannot write " << this->FileName << ": " << failure);
}

//------------------------------------------------------------------------------------------------------------
bool vtkFFDVDBWriter::WriteLattice(vtkDataObject* input)
{
  // What the input is: a sparse lattice of a local basis, with the data contract's arrays.
  vtkUnstructuredGrid* lattice = vtkUnstructuredGrid::SafeDownCast(input);
  if (!lattice)
  {
    vtkErrorMacro(<< "The input is a " << (input ? input->GetClassName() : "null data object")
                  << (vtkStructuredGrid::SafeDownCast(input) ? " (a dense lattice)" : "")
                  << ", not a sparse lattice (a vtkUnstructuredGrid): .vdb files hold sparse lattices; build it with "
                     "vtkFFDBuildLattice::SetLatticeFormToSparse().");
    return false;
  }
  double frame[12];
  int divisions[3], basis = -1;
  if (!vtkFFDDataContract::GetFrame(lattice, frame) || ffd::CheckFrame(frame) != ffd::FrameStatus::Valid ||
    !vtkFFDDataContract::GetDivisions(lattice, divisions) || !vtkFFDDataContract::GetBasis(lattice, basis))
  {
    vtkErrorMacro(<< "The input has no valid " << vtkFFDDataContract::FrameArrayName() << ", "
                  << vtkFFDDataContract::DivisionsArrayName() << " or " << vtkFFDDataContract::BasisArrayName()
                  << " field array (a tetrahedral lattice has none, and no .vdb form): write the output of "
                     "vtkFFDBuildLattice with SetLatticeFormToSparse().");
    return false;
  }
  if (basis == vtkFFDBuildLattice::BERNSTEIN)
  {
    vtkErrorMacro(<< "The input's basis is the global BERNSTEIN basis, which has no sparse form (each of its control "
                     "points influences every voxel) and so no .vdb form: use a local basis, e.g. "
                     "vtkFFDBuildLattice::SetBasisToCubicBSpline().");
    return false;
  }
  int pointsPerAxis[3];
  std::string why;
  if (!vtkFFDBuildLattice::GetControlPointsPerAxis(basis, divisions, pointsPerAxis, why, vtkFFDBuildLattice::SPARSE))
  {
    vtkErrorMacro(<< "The input is not a valid lattice: " << why);
    return false;
  }
  const vtkIdType numPoints = lattice->GetNumberOfPoints();
  const vtkIdType numCells = lattice->GetNumberOfCells();
  vtkDoubleArray* restArray =
    TupleArray<vtkDoubleArray>(lattice->GetPointData(), vtkFFDDataContract::RestPositionArrayName(), numPoints);
  vtkIntArray* latticeIndex =
    TupleArray<vtkIntArray>(lattice->GetPointData(), vtkFFDDataContract::LatticeIndexArrayName(), numPoints);
  vtkIntArray* voxelIndex =
    TupleArray<vtkIntArray>(lattice->GetCellData(), vtkFFDDataContract::VoxelIndexArrayName(), numCells);
  if (!restArray || !latticeIndex || !voxelIndex)
  {
    vtkErrorMacro(<< "The input lacks "
                  << (!restArray         ? "the RestPosition point array (3 doubles a point)"
                         : !latticeIndex ? "the LatticeIndex point array (3 ints a point)"
                                         : "the VoxelIndex cell array (3 ints a cell)")
                  << " of a sparse lattice: write the output of vtkFFDBuildLattice with SetLatticeFormToSparse().");
    return false;
  }
  const int* voxels = voxelIndex->GetPointer(0);
  const int* indices = latticeIndex->GetPointer(0);
  const double* rest = restArray->GetPointer(0);
  const vtkIdType badVoxel = FirstOutside(voxels, numCells, divisions);
  const vtkIdType badIndex = FirstOutside(indices, numPoints, pointsPerAxis);
  if (badVoxel >= 0 || badIndex >= 0)
  {
    vtkErrorMacro(<< "The input's " << (badVoxel >= 0 ? "VoxelIndex of cell " : "LatticeIndex of point ")
                  << (badVoxel >= 0 ? badVoxel : badIndex) << " lies outside its "
                  << (badVoxel >= 0 ? "FFDDivisions" : "control points per axis")
                  << ": write the output of vtkFFDBuildLattice with SetLatticeFormToSparse().");
    return false;
  }

  // The file holds the voxels and the points, and the reader rebuilds the lattice as vtkFFDBuildLattice does: the
  // points must be the union of the voxels' supports, in increasing lattice order, at their rest positions.
  const ffd::GridBasis grid = static_cast<ffd::GridBasis>(basis);
  vtkFFDActiveSet supports;
  vtkFFDSparseLattice::MarkSupports(supports, grid, divisions, voxels, numCells);
  if (supports.GetNumberOfMarked() != numPoints)
  {
    vtkErrorMacro(<< "The input has " << numPoints << " points, but the supports of its cells' voxels have "
                  << supports.GetNumberOfMarked()
                  << " control points: write a lattice as vtkFFDBuildLattice makes it (SetLatticeFormToSparse()), "
                     "its points moved but none added or removed.");
    return false;
  }
  if (!vtkFFDCheckMemory(this, "Checking the " + std::to_string(numPoints) + " points of the lattice", 8.0 * numPoints))
  {
    return false;
  }
  const vtkTypeInt64 dims[3] = { pointsPerAxis[0], pointsPerAxis[1], pointsPerAxis[2] };
  const std::vector<vtkTypeInt64> sorted = supports.TakeSortedIndices(dims);
  const ffd::Frame<double> bound = ffd::Frame<double>::FromArray(frame);
  for (vtkIdType p = 0; p < numPoints; ++p)
  {
    const int* ijk = indices + 3 * p;
    if (ijk[0] + dims[0] * (ijk[1] + dims[1] * ijk[2]) != sorted[p])
    {
      vtkErrorMacro(<< "Point " << p << " of the input has LatticeIndex (" << ijk[0] << ", " << ijk[1] << ", " << ijk[2]
                    << "), where vtkFFDBuildLattice puts another control point: write a lattice as "
                    << "vtkFFDBuildLattice makes it, its points moved but none reordered.");
      return false;
    }
    const ffd::Vec3<double> x = vtkFFDRestPoint(bound, grid, divisions, ijk[0], ijk[1], ijk[2]);
    if (std::memcmp(&x.x, rest + 3 * p, 3 * sizeof(double)) != 0)
    {
      vtkErrorMacro(<< "The RestPosition of point " << p << " differs from the rest position of its LatticeIndex ("
                    << ijk[0] << ", " << ijk[1] << ", " << ijk[2]
                    << ") in the frame: the file keeps the frame, not the rest positions; move the points, not "
                       "RestPosition, or rebuild the lattice with vtkFFDBuildLattice.");
      return false;
    }
  }
  this->UpdateProgress(0.3);

  // The grids.
  openvdb::initialize();
  const double voxelSteps[3] = { 1.0 / divisions[0], 1.0 / divisions[1], 1.0 / divisions[2] };
  double voxelOffsets[3], pointSteps[3], pointOffsets[3];
  for (int a = 0; a < 3; ++a)
  {
    voxelOffsets[a] = 0.5 * voxelSteps[a];
    pointOffsets[a] = ffd::RestParameter(grid, divisions[a], 0);
    pointSteps[a] = ffd::RestParameter(grid, divisions[a], 1) - pointOffsets[a];
  }
  openvdb::BoolGrid::Ptr activeVoxels = openvdb::BoolGrid::create(false);
  {
    openvdb::BoolGrid::Accessor accessor = activeVoxels->getAccessor();
    for (vtkIdType c = 0; c < numCells; ++c)
    {
      accessor.setValueOn(openvdb::Coord(voxels + 3 * c), true);
    }
  }
  if (vtkIdType(activeVoxels->activeVoxelCount()) != numCells)
  {
    vtkErrorMacro(<< "The input's " << numCells << " cells name only " << activeVoxels->activeVoxelCount()
                  << " distinct voxels in VoxelIndex: give each active voxel one cell, as vtkFFDBuildLattice does.");
    return false;
  }
  activeVoxels->setName(vtkFFDVDB::ActiveVoxelsGrid);
  activeVoxels->setTransform(AffineTransform(frame, voxelSteps, voxelOffsets));
  SetDescription(*activeVoxels, frame, divisions, -1);

  openvdb::Vec3DGrid::Ptr displacement = openvdb::Vec3DGrid::create(openvdb::Vec3d(0.0));
  openvdb::Vec3DGrid::Ptr position = openvdb::Vec3DGrid::create(openvdb::Vec3d(0.0));
  {
    openvdb::Vec3DGrid::Accessor displacements = displacement->getAccessor();
    openvdb::Vec3DGrid::Accessor positions = position->getAccessor();
    vtkPoints* points = lattice->GetPoints();
    for (vtkIdType p = 0; p < numPoints; ++p)
    {
      const openvdb::Coord ijk(indices + 3 * p);
      const double* r = rest + 3 * p;
      openvdb::Vec3d x;
      points->GetPoint(p, x.asPointer());
      positions.setValueOn(ijk, x);
      displacements.setValueOn(ijk, openvdb::Vec3d(x[0] - r[0], x[1] - r[1], x[2] - r[2]));
    }
  }
  const openvdb::math::Transform::Ptr pointTransform = AffineTransform(frame, pointSteps, pointOffsets);
  displacement->setName(vtkFFDVDB::DisplacementGrid);
  displacement->setVectorType(openvdb::VEC_CONTRAVARIANT_RELATIVE);
  position->setName(vtkFFDVDB::PositionGrid);
  position->setVectorType(openvdb::VEC_CONTRAVARIANT_ABSOLUTE);
  for (const openvdb::Vec3DGrid::Ptr& vectors : { displacement, position })
  {
    vectors->setTransform(pointTransform->copy());
    vectors->setIsInWorldSpace(true);
    SetDescription(*vectors, frame, divisions, basis);
  }
  this->UpdateProgress(0.6);

  // OpenVDB opens (and empties) the file itself: opening it here first tells an unwritable path, whose file is
  // left as it is, from a failure while writing, whose partial file is removed.
  if (!std::ofstream(this->FileName, std::ios::binary | std::ios::app))
  {
    vtkErrorMacro(<< "Cannot open " << this->FileName << " for writing (" << std::strerror(errno)
                  << "): check that its folder exists and is writable.");
    this->SetErrorCode(vtkErrorCode::CannotOpenFileError);
    return false;
  }
  const openvdb::GridCPtrVec grids{ activeVoxels, displacement, position };
  try
  {
    openvdb::io::File(this->FileName).write(grids);
  }
  catch (...)
  {
    std::remove(this->FileName);
    throw;
  }
  this->UpdateProgress(1.0);
  return true;
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDVDBWriter::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FileName: " << (this->FileName ? this->FileName : "(none)") << "\n";
}
