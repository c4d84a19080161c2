// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDVDBReader.h"

#include "vtkDoubleArray.h"
#include "vtkFFDBuildLattice.h"
#include "vtkFFDDataContract.h"
#include "vtkFFDMemory.h"
#include "vtkFFDSparseLattice.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkIntArray.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkSMPTools.h"
#include "vtkUnstructuredGrid.h"

#include "FFDFrame.h"
#include "FFDGridBasis.h"

#include "vtkFFDOpenVDB.h"

#include <sys/stat.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <sstream>
#include <string>

vtkStandardNewMacro(vtkFFDVDBReader);

namespace
{
/// What a grid's metadata says (vtkFFDVDBWriter's keys, vtkFFDOpenVDB.h).
struct Description
{
  double Frame[12];
  int Divisions[3];
  std::string Basis; // the lattice's grids only

  bool operator==(const Description& other) const
  {
    return std::equal(this->Frame, this->Frame + 12, other.Frame) &&
      std::equal(this->Divisions, this->Divisions + 3, other.Divisions) && this->Basis == other.Basis;
  }
};

/// Reads the description of `grid`, with the basis where `withBasis`: an empty string, or the key it lacks.
std::string ReadDescription(const openvdb::GridBase& grid, bool withBasis, Description& description)
{
  const char* frameKeys[4] = { vtkFFDVDB::FrameOrigin, vtkFFDVDB::FrameS, vtkFFDVDB::FrameT, vtkFFDVDB::FrameU };
  for (int v = 0; v < 4; ++v)
  {
    const openvdb::Vec3DMetadata::ConstPtr vector = grid.getMetadata<openvdb::Vec3DMetadata>(frameKeys[v]);
    if (!vector)
    {
      return std::string(frameKeys[v]) + " (a Vec3d)";
    }
    std::copy(vector->value().asPointer(), vector->value().asPointer() + 3, description.Frame + 3 * v);
  }
  const openvdb::Vec3IMetadata::ConstPtr divisions = grid.getMetadata<openvdb::Vec3IMetadata>(vtkFFDVDB::Divisions);
  if (!divisions)
  {
    return std::string(vtkFFDVDB::Divisions) + " (a Vec3i)";
  }
  std::copy(divisions->value().asPointer(), divisions->value().asPointer() + 3, description.Divisions);
  if (withBasis)
  {
    const openvdb::StringMetadata::ConstPtr basis = grid.getMetadata<openvdb::StringMetadata>(vtkFFDVDB::Basis);
    if (!basis)
    {
      return std::string(vtkFFDVDB::Basis) + " (a string)";
    }
    description.Basis = basis->value();
  }
  return std::string();
}

/// The basis that vtkFFDBuildLattice::GetBasisAsString() names `name`, or -1.
int BasisNamed(const std::string& name)
{
  for (int basis = vtkFFDBuildLattice::BERNSTEIN; basis <= vtkFFDBuildLattice::CUBIC_BSPLINE; ++basis)
  {
    if (name == vtkFFDBuildLattice::GetBasisAsString(basis))
    {
      return basis;
    }
  }
  return -1;
}

std::string Ijk(const openvdb::Coord& x)
{
  std::ostringstream text;
  text << "(" << x.x() << ", " << x.y() << ", " << x.z() << ")";
  return text.str();
}
} // namespace

//------------------------------------------------------------------------------------------------------------
vtkFFDVDBReader::vtkFFDVDBReader()
  : FileName(nullptr)
{
  this->SetNumberOfInputPorts(0);
  this->SetNumberOfOutputPorts(2);
}

vtkFFDVDBReader::~vtkFFDVDBReader()
{
  this->SetFileName(nullptr);
}

//------------------------------------------------------------------------------------------------------------
vtkTypeBool vtkFFDVDBReader::ProcessRequest(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  return vtkFFDCatchAllocationFailure(
    this, outputVector, [&] { return this->Superclass::ProcessRequest(request, inputVector, outputVector); });
}

//------------------------------------------------------------------------------------------------------------
int vtkFFDVDBReader::RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkUnstructuredGrid* lattice = vtkUnstructuredGrid::GetData(outputVector, 0);
  vtkUnstructuredGrid* voxelGrid = vtkUnstructuredGrid::GetData(outputVector, 1);
  bool read = false;
  try
  {
    read = this->ReadFile(lattice, voxelGrid);
  }
  catch (const openvdb::Exception& e)
  {
    vtkErrorMacro(<< "OpenVDB cannot read " << this->FileName << " (" << e.what()
                  << "): give a .vdb file that vtkFFDVDBWriter wrote.");
  }
  if (!read)
  {
    lattice->Initialize();
    voxelGrid->Initialize();
    return 0;
  }
  this->UpdateProgress(1.0);
  return 1;
}

//------------------------------------------------------------------------------------------------------------
bool vtkFFDVDBReader::ReadFile(vtkUnstructuredGrid* lattice, vtkUnstructuredGrid* voxelGrid)
{
  if (!this->FileName || !*this->FileName)
  {
    vtkErrorMacro(<< "No FileName: call SetFileName() with the .vdb file to read.");
    return false;
  }
  struct stat status;
  const bool found = stat(this->FileName, &status) == 0;
  if (!found || !S_ISREG(status.st_mode))
  {
    vtkErrorMacro(<< "Cannot read " << this->FileName << ": " << (found ? "not a regular file" : std::strerror(errno))
                  << ". Check FileName.");
    return false;
  }
  openvdb::initialize();
  openvdb::io::File file(this->FileName);
  file.open(false); // read the grids whole, not memory-mapped

  // The grids' metadata first: their types, the lattice's description, and what the grids take in memory.
  const char* names[3] = { vtkFFDVDB::ActiveVoxelsGrid, vtkFFDVDB::DisplacementGrid, vtkFFDVDB::PositionGrid };
  Description descriptions[3];
  double gridBytes = 0.0;
  for (int g = 0; g < 3; ++g)
  {
    if (!file.hasGrid(names[g]))
    {
      vtkErrorMacro(<< this->FileName << " has no grid named \"" << names[g]
                    << "\": a VoxelFFD .vdb file has the grids \"" << vtkFFDVDB::ActiveVoxelsGrid << "\", \""
                    << vtkFFDVDB::DisplacementGrid << "\" and \"" << vtkFFDVDB::PositionGrid
                    << "\"; write it with vtkFFDVDBWriter.");
      return false;
    }
    const openvdb::GridBase::ConstPtr grid = file.readGridMetadata(names[g]);
    const bool typed = g == 0 ? grid->isType<openvdb::BoolGrid>() : grid->isType<openvdb::Vec3DGrid>();
    if (!typed)
    {
      vtkErrorMacro(<< "The grid \"" << names[g] << "\" of " << this->FileName << " holds " << grid->valueType()
                    << " values, not " << (g == 0 ? "bool" : "vec3d") << " ones: write the file with vtkFFDVDBWriter.");
      return false;
    }
    const std::string missing = ReadDescription(*grid, g > 0, descriptions[g]);
    if (!missing.empty())
    {
      vtkErrorMacro(<< "The grid \"" << names[g] << "\" of " << this->FileName << " has no metadata " << missing
                    << ": write the file with vtkFFDVDBWriter, or add it (README, \".vdb files\").");
      return false;
    }
    if (const openvdb::Int64Metadata::ConstPtr bytes =
          grid->getMetadata<openvdb::Int64Metadata>(openvdb::GridBase::META_FILE_MEM_BYTES))
    {
      gridBytes += double(bytes->value());
    }
  }
  descriptions[0].Basis = descriptions[1].Basis; // the voxels have no basis
  if (!(descriptions[1] == descriptions[0]) || !(descriptions[2] == descriptions[0]))
  {
    vtkErrorMacro(<< "The grids of " << this->FileName
                  << " disagree on the frame, divisions or basis in their metadata: write the file with "
                     "vtkFFDVDBWriter, or give each grid the same ffd_ metadata.");
    return false;
  }
  const Description& description = descriptions[0];
  const double* frame = description.Frame;
  const int* divisions = description.Divisions;
  const int basis = BasisNamed(description.Basis);
  std::ostringstream where;
  where << "The metadata of " << this->FileName;
  if (ffd::CheckFrame(frame) != ffd::FrameStatus::Valid)
  {
    vtkErrorMacro(<< where.str()
                  << " gives a frame that is not finite or has (nearly) zero volume: its edge vectors ffd_frame_s, "
                     "ffd_frame_t and ffd_frame_u must be finite and linearly independent.");
    return false;
  }
  if (basis < 0 || basis == vtkFFDBuildLattice::BERNSTEIN)
  {
    vtkErrorMacro(<< where.str() << " gives the basis \"" << description.Basis
                  << "\": a .vdb lattice has one of the local bases Trilinear, TriquadraticBezier, TricubicBezier "
                     "and CubicBSpline.");
    return false;
  }
  int pointsPerAxis[3];
  std::string why;
  if (divisions[0] < 1 || divisions[1] < 1 || divisions[2] < 1 ||
    !vtkFFDBuildLattice::GetControlPointsPerAxis(basis, divisions, pointsPerAxis, why, vtkFFDBuildLattice::SPARSE))
  {
    vtkErrorMacro(<< where.str() << " gives the divisions (" << divisions[0] << ", " << divisions[1] << ", "
                  << divisions[2] << "): " << (why.empty() ? "each must be at least 1." : why));
    return false;
  }
  if (!vtkFFDCheckMemory(this, "Reading the grids of " + std::string(this->FileName), gridBytes))
  {
    return false;
  }

  // The voxels: in increasing order, within the divisions.
  const openvdb::BoolGrid::Ptr activeVoxels =
    openvdb::gridPtrCast<openvdb::BoolGrid>(file.readGrid(vtkFFDVDB::ActiveVoxelsGrid));
  const openvdb::Vec3DGrid::Ptr displacement =
    openvdb::gridPtrCast<openvdb::Vec3DGrid>(file.readGrid(vtkFFDVDB::DisplacementGrid));
  const openvdb::Vec3DGrid::Ptr position =
    openvdb::gridPtrCast<openvdb::Vec3DGrid>(file.readGrid(vtkFFDVDB::PositionGrid));
  file.close();
  this->UpdateProgress(0.2);
  activeVoxels->tree().voxelizeActiveTiles(); // another tool may have merged voxels into tiles
  const openvdb::CoordBBox box = activeVoxels->evalActiveVoxelBoundingBox();
  if (!activeVoxels->empty() &&
    (box.min().x() < 0 || box.min().y() < 0 || box.min().z() < 0 || box.max().x() >= divisions[0] ||
      box.max().y() >= divisions[1] || box.max().z() >= divisions[2]))
  {
    vtkErrorMacro(<< "The active voxels of " << this->FileName << " span " << Ijk(box.min()) << " to " << Ijk(box.max())
                  << ", beyond its divisions (" << divisions[0] << ", " << divisions[1] << ", " << divisions[2]
                  << "): each index must be in [0, divisions); write the file with vtkFFDVDBWriter.");
    return false;
  }
  const vtkIdType numVoxels = vtkIdType(activeVoxels->activeVoxelCount());
  std::ostringstream request;
  request << "The " << numVoxels << " active voxels of " << this->FileName;
  // The sorted indices (8 bytes a voxel) and VoxelIndex (12).
  if (!vtkFFDCheckMemory(this, request.str(), 20.0 * double(numVoxels)))
  {
    return false;
  }
  const vtkTypeInt64 voxelDims[3] = { divisions[0], divisions[1], divisions[2] };
  const vtkSmartPointer<vtkIntArray> voxelIndex =
    vtkFFDMakeVoxelIndex(vtkFFDSortedIndices(activeVoxels->tree(), voxelDims), divisions);
  if (!vtkFFDMakeVoxelGrid(this, frame, divisions, voxelIndex, request.str() + ": their voxel grid", voxelGrid))
  {
    return false;
  }
  this->UpdateProgress(0.4);

  // The lattice at rest, by vtkFFDBuildLattice's code (its progress mapped to 0.4 .. 0.7 of ours).
  this->SetProgressShiftScale(0.4, 0.3);
  const bool built = vtkFFDMakeSparseLattice(this, frame, static_cast<ffd::GridBasis>(basis), divisions, voxelIndex,
    request.str() + ": their " + description.Basis + " lattice", lattice);
  this->SetProgressShiftScale(0.0, 1.0);
  if (!built || this->GetAbortExecute())
  {
    return built;
  }
  this->UpdateProgress(0.7);

  // The points: each control point's displacement and position, which both grids must hold, and nothing else.
  const vtkIdType numPoints = lattice->GetNumberOfPoints();
  const int* indices =
    vtkIntArray::SafeDownCast(lattice->GetPointData()->GetArray(vtkFFDDataContract::LatticeIndexArrayName()))
      ->GetPointer(0);
  const double* rest =
    vtkDoubleArray::SafeDownCast(lattice->GetPointData()->GetArray(vtkFFDDataContract::RestPositionArrayName()))
      ->GetPointer(0);
  double* points = vtkDoubleArray::SafeDownCast(lattice->GetPoints()->GetData())->GetPointer(0);
  std::atomic<vtkIdType> firstMissing(numPoints);
  vtkSMPTools::For(0, numPoints,
    [&](vtkIdType begin, vtkIdType end)
    {
      // Accessors of this chunk: a tree is read by many threads, each through its own accessor.
      openvdb::Vec3DGrid::ConstAccessor displacements = displacement->getConstAccessor();
      openvdb::Vec3DGrid::ConstAccessor positions = position->getConstAccessor();
      for (vtkIdType p = begin; p < end && p < firstMissing; ++p)
      {
        const openvdb::Coord ijk(indices + 3 * p);
        openvdb::Vec3d d, x;
        if (!displacements.probeValue(ijk, d) || !positions.probeValue(ijk, x))
        {
          vtkIdType seen = firstMissing.load();
          while (p < seen && !firstMissing.compare_exchange_weak(seen, p))
          {
          }
          break;
        }
        const double* r = rest + 3 * p;
        const bool kept = x[0] - r[0] == d[0] && x[1] - r[1] == d[1] && x[2] - r[2] == d[2];
        for (int c = 0; c < 3; ++c)
        {
          points[3 * p + c] = kept ? x[c] : r[c] + d[c];
        }
      }
    });
  if (firstMissing < numPoints)
  {
    const openvdb::Coord ijk(indices + 3 * firstMissing);
    vtkErrorMacro(<< "Control point " << Ijk(ijk) << " of the active voxels' supports has no value in the grid \""
                  << (displacement->tree().isValueOn(ijk) ? vtkFFDVDB::PositionGrid : vtkFFDVDB::DisplacementGrid)
                  << "\" of " << this->FileName
                  << ": the grids must hold every control point of the lattice; write the file with vtkFFDVDBWriter.");
    return false;
  }
  for (const openvdb::Vec3DGrid::Ptr& vectors : { displacement, position })
  {
    if (vtkIdType(vectors->activeVoxelCount()) == numPoints)
    {
      continue; // it holds every control point, so nothing else
    }
    // A value where the lattice has no control point: the first one, found in the increasing LatticeIndex.
    const vtkTypeInt64 nI = pointsPerAxis[0], nJ = pointsPerAxis[1];
    auto key = [&](const int* ijk) { return ijk[0] + nI * (ijk[1] + nJ * vtkTypeInt64(ijk[2])); };
    vectors->tree().voxelizeActiveTiles();
    for (auto it = vectors->cbeginValueOn(); it; ++it)
    {
      const openvdb::Coord x = it.getCoord();
      const bool inside = x.x() >= 0 && x.y() >= 0 && x.z() >= 0 && x.x() < pointsPerAxis[0] &&
        x.y() < pointsPerAxis[1] && x.z() < pointsPerAxis[2];
      const vtkTypeInt64 wanted = key(x.asPointer());
      vtkIdType low = 0, high = numPoints;
      while (low < high)
      {
        const vtkIdType middle = low + (high - low) / 2;
        if (key(indices + 3 * middle) < wanted)
        {
          low = middle + 1;
        }
        else
        {
          high = middle;
        }
      }
      if (!inside || low == numPoints || key(indices + 3 * low) != wanted)
      {
        vtkErrorMacro(<< "The grid \"" << vectors->getName() << "\" of " << this->FileName << " has a value at "
                      << Ijk(x) << ", which is not a control point of the "
                      << vtkFFDBuildLattice::GetBasisAsString(basis)
                      << " lattice over its active voxels: the grids hold the lattice's control points only; write "
                         "the file with vtkFFDVDBWriter.");
        return false;
      }
    }
  }
  lattice->GetPoints()->Modified();
  return true;
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDVDBReader::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FileName: " << (this->FileName ? this->FileName : "(none)") << "\n";
}
