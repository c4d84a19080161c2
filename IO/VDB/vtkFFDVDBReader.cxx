// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDVDBReader.h"

#include "vtkDoubleArray.h"
#include "vtkFFDBuildLattice.h"
#include "vtkFFDDataContract.h"
#include "vtkFFDMemory.h"
#include "vtkFFDSortedKeys.h"
#include "vtkFFDSparseLattice.h"
#include "vtkFFDStatistics.h"
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

#include <openvdb/io/Stream.h>

#include <sys/stat.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <istream>
#include <sstream>
#include <streambuf>
#include <string>
#include <vector>

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

/// A read-only, seekable stream buffer over bytes in memory: OpenVDB parses the file from it, so that no read
/// goes past the bytes the file has, whatever size the file states.
class MemoryBuffer : public std::streambuf
{
public:
  MemoryBuffer(char* begin, size_t size) { this->setg(begin, begin, begin + size); }

protected:
  pos_type seekoff(off_type offset, std::ios_base::seekdir way, std::ios_base::openmode which) override
  {
    char* from = way == std::ios_base::beg ? this->eback() : way == std::ios_base::cur ? this->gptr() : this->egptr();
    if (!(which & std::ios_base::in) || offset < this->eback() - from || offset > this->egptr() - from)
    {
      return pos_type(off_type(-1));
    }
    this->setg(this->eback(), from + offset, this->egptr());
    return pos_type(off_type(this->gptr() - this->eback()));
  }
  pos_type seekpos(pos_type position, std::ios_base::openmode which) override
  {
    return this->seekoff(off_type(position), std::ios_base::beg, which);
  }
};

/// The grids of a VoxelFFD .vdb file and what their metadata says, checked.
struct Grids
{
  openvdb::BoolGrid::Ptr ActiveVoxels;
  openvdb::Vec3DGrid::Ptr Displacement;
  openvdb::Vec3DGrid::Ptr Position;
  Description Lattice;
  int Basis = -1;
  int PointsPerAxis[3];
};

/**
 * The file's bytes, whole, in `bytes`, and the length of OpenVDB's part of them in `payload`: false, with the
 * error reported, where the file is missing, cannot be held in memory, or fails its checksum.
 */
bool ReadBytes(vtkFFDVDBReader* self, std::vector<char>& bytes, size_t& payload)
{
  const char* fileName = self->GetFileName();
  struct stat status;
  const bool found = stat(fileName, &status) == 0;
  if (!found || !S_ISREG(status.st_mode))
  {
    vtkErrorWithObjectMacro(self, << "Cannot read " << fileName << ": "
                                  << (found ? "not a regular file" : std::strerror(errno)) << ". Check FileName.");
    return false;
  }
  if (!vtkFFDCheckMemory(self, "Reading " + std::string(fileName), double(status.st_size)))
  {
    return false;
  }
  bytes.resize(size_t(status.st_size));
  std::ifstream file(fileName, std::ios::binary);
  if (!file.read(bytes.data(), std::streamsize(bytes.size())) || file.peek() != std::ifstream::traits_type::eof())
  {
    vtkErrorWithObjectMacro(
      self, << "Cannot read " << fileName << ": reading failed, or the file changed size while being read.");
    return false;
  }
  if (vtkFFDVDB::CheckTrailer(bytes.data(), bytes.size(), payload) == vtkFFDVDB::TrailerStatus::Damaged)
  {
    vtkErrorWithObjectMacro(self, << fileName
                                  << " is damaged: its bytes do not match the checksum vtkFFDVDBWriter wrote at its "
                                     "end (the file was changed or cut since). Write it again with vtkFFDVDBWriter.");
    return false;
  }
  return true;
}

/**
 * OpenVDB's grids of the first `payload` bytes, or null with the error reported. A read past them fails at once
 * (an exception, rather than values OpenVDB never got), so a cut file is an error rather than a parse of garbage.
 */
openvdb::GridPtrVecPtr ParseGrids(vtkFFDVDBReader* self, std::vector<char>& bytes, size_t payload)
{
  MemoryBuffer buffer(bytes.data(), payload);
  std::istream stream(&buffer);
  stream.exceptions(std::ios::eofbit | std::ios::failbit | std::ios::badbit);
  try
  {
    return openvdb::io::Stream(stream, /*delayLoad=*/false).getGrids();
  }
  catch (const std::bad_alloc&)
  {
    throw; // out of memory: vtkFFDCatchAllocationFailure()'s error
  }
  catch (const std::exception& e)
  {
    vtkErrorWithObjectMacro(self, << "OpenVDB cannot read " << self->GetFileName() << " ("
                                  << (dynamic_cast<const std::ios_base::failure*>(&e) ? "it ends too soon" : e.what())
                                  << "): it is cut short, damaged or not a .vdb file; give a .vdb file that "
                                     "vtkFFDVDBWriter wrote.");
  }
  return nullptr;
}

/// The three grids of `grids` with their metadata in `found`: false, with the error reported, where one is
/// missing, of another type, without its metadata, or the grids disagree on it.
bool FindGrids(vtkFFDVDBReader* self, const openvdb::GridPtrVec& grids, Grids& found)
{
  const char* names[3] = { vtkFFDVDB::ActiveVoxelsGrid, vtkFFDVDB::DisplacementGrid, vtkFFDVDB::PositionGrid };
  Description descriptions[3];
  for (int g = 0; g < 3; ++g)
  {
    const openvdb::GridBase::Ptr grid = openvdb::findGridByName(grids, names[g]);
    if (!grid)
    {
      vtkErrorWithObjectMacro(self, << self->GetFileName() << " has no grid named \"" << names[g]
                                    << "\": a VoxelFFD .vdb file has the grids \"" << vtkFFDVDB::ActiveVoxelsGrid
                                    << "\", \"" << vtkFFDVDB::DisplacementGrid << "\" and \"" << vtkFFDVDB::PositionGrid
                                    << "\"; write it with vtkFFDVDBWriter.");
      return false;
    }
    const bool typed = g == 0 ? grid->isType<openvdb::BoolGrid>() : grid->isType<openvdb::Vec3DGrid>();
    if (!typed)
    {
      vtkErrorWithObjectMacro(self, << "The grid \"" << names[g] << "\" of " << self->GetFileName() << " holds "
                                    << grid->valueType() << " values, not " << (g == 0 ? "bool" : "vec3d")
                                    << " ones: write the file with vtkFFDVDBWriter.");
      return false;
    }
    const std::string missing = ReadDescription(*grid, g > 0, descriptions[g]);
    if (!missing.empty())
    {
      vtkErrorWithObjectMacro(
        self, << "The grid \"" << names[g] << "\" of " << self->GetFileName() << " has no metadata " << missing
              << ": write the file with vtkFFDVDBWriter, or add it (docs/interchange-and-files.md, \".vdb files\").");
      return false;
    }
  }
  descriptions[0].Basis = descriptions[1].Basis; // the voxels have no basis
  if (!(descriptions[1] == descriptions[0]) || !(descriptions[2] == descriptions[0]))
  {
    vtkErrorWithObjectMacro(self, << "The grids of " << self->GetFileName()
                                  << " disagree on the frame, divisions or basis in their metadata: write the file "
                                     "with vtkFFDVDBWriter, or give each grid the same ffd_ metadata.");
    return false;
  }
  found.ActiveVoxels = openvdb::gridPtrCast<openvdb::BoolGrid>(openvdb::findGridByName(grids, names[0]));
  found.Displacement = openvdb::gridPtrCast<openvdb::Vec3DGrid>(openvdb::findGridByName(grids, names[1]));
  found.Position = openvdb::gridPtrCast<openvdb::Vec3DGrid>(openvdb::findGridByName(grids, names[2]));
  found.Lattice = descriptions[0];
  return true;
}

/// The metadata's frame, basis and divisions checked, and the control points per axis of `found` set: false,
/// with the error reported, where they describe no sparse lattice.
bool CheckDescription(vtkFFDVDBReader* self, Grids& found)
{
  const Description& description = found.Lattice;
  const int* divisions = description.Divisions;
  found.Basis = BasisNamed(description.Basis);
  const std::string where = "The metadata of " + std::string(self->GetFileName());
  if (ffd::CheckFrame(description.Frame) != ffd::FrameStatus::Valid)
  {
    vtkErrorWithObjectMacro(self, << where
                                  << " gives a frame that is not finite or has (nearly) zero volume: its edge vectors "
                                     "ffd_frame_s, ffd_frame_t and ffd_frame_u must be finite and linearly "
                                     "independent.");
    return false;
  }
  if (found.Basis < 0 || found.Basis == vtkFFDBuildLattice::BERNSTEIN)
  {
    vtkErrorWithObjectMacro(self, << where << " gives the basis \"" << description.Basis
                                  << "\": a .vdb lattice has one of the local bases Trilinear, TriquadraticBezier, "
                                     "TricubicBezier and CubicBSpline.");
    return false;
  }
  std::string why;
  if (divisions[0] < 1 || divisions[1] < 1 || divisions[2] < 1 ||
    !vtkFFDBuildLattice::GetControlPointsPerAxis(
      found.Basis, divisions, found.PointsPerAxis, why, vtkFFDBuildLattice::SPARSE))
  {
    vtkErrorWithObjectMacro(self, << where << " gives the divisions (" << divisions[0] << ", " << divisions[1] << ", "
                                  << divisions[2] << "): " << (why.empty() ? "each must be at least 1." : why));
    return false;
  }
  return true;
}

/// The VoxelIndex of the active voxels, in increasing order, and their voxel grid: null, with the error reported,
/// where a voxel lies outside the divisions or the outputs cannot be had.
vtkSmartPointer<vtkIntArray> MakeVoxels(vtkFFDVDBReader* self, const Grids& found, vtkUnstructuredGrid* voxelGrid)
{
  const int* divisions = found.Lattice.Divisions;
  openvdb::BoolGrid& activeVoxels = *found.ActiveVoxels;
  activeVoxels.tree().voxelizeActiveTiles(); // another tool may have merged voxels into tiles
  const openvdb::CoordBBox box = activeVoxels.evalActiveVoxelBoundingBox();
  if (!activeVoxels.empty() &&
    (box.min().x() < 0 || box.min().y() < 0 || box.min().z() < 0 || box.max().x() >= divisions[0] ||
      box.max().y() >= divisions[1] || box.max().z() >= divisions[2]))
  {
    vtkErrorWithObjectMacro(self, << "The active voxels of " << self->GetFileName() << " span " << Ijk(box.min())
                                  << " to " << Ijk(box.max()) << ", beyond its divisions (" << divisions[0] << ", "
                                  << divisions[1] << ", " << divisions[2]
                                  << "): each index must be in [0, divisions); write the file with vtkFFDVDBWriter.");
    return nullptr;
  }
  const vtkIdType numVoxels = vtkIdType(activeVoxels.activeVoxelCount());
  const std::string request =
    "The " + std::to_string(numVoxels) + " active voxels of " + std::string(self->GetFileName());
  // The sorted indices (8 bytes a voxel) and VoxelIndex (12).
  if (!vtkFFDCheckMemory(self, request, 20.0 * double(numVoxels)))
  {
    return nullptr;
  }
  const vtkTypeInt64 voxelDims[3] = { divisions[0], divisions[1], divisions[2] };
  vtkSmartPointer<vtkIntArray> voxelIndex =
    vtkFFDMakeVoxelIndex(vtkFFDSortedIndices(activeVoxels.tree(), voxelDims), divisions);
  if (!vtkFFDMakeVoxelGrid(self, found.Lattice.Frame, divisions, voxelIndex, request + ": their voxel grid", voxelGrid))
  {
    return nullptr;
  }
  return voxelIndex;
}

/**
 * Puts each point of `lattice` (at rest, with its LatticeIndex) where the grids say: at the position where the
 * position minus the rest position is the displacement, bit for bit, else at the rest position plus the
 * displacement. False, with the error reported, where a control point lacks a value in either grid.
 */
bool PlacePoints(vtkFFDVDBReader* self, const Grids& found, vtkUnstructuredGrid* lattice)
{
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
      openvdb::Vec3DGrid::ConstAccessor displacements = found.Displacement->getConstAccessor();
      openvdb::Vec3DGrid::ConstAccessor positions = found.Position->getConstAccessor();
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
    vtkErrorWithObjectMacro(
      self, << "Control point " << Ijk(ijk) << " of the active voxels' supports has no value in the grid \""
            << (found.Displacement->tree().isValueOn(ijk) ? vtkFFDVDB::PositionGrid : vtkFFDVDB::DisplacementGrid)
            << "\" of " << self->GetFileName()
            << ": the grids must hold every control point of the lattice; write the file with "
               "vtkFFDVDBWriter.");
    return false;
  }
  lattice->GetPoints()->Modified();
  return true;
}

/// False, with the error reported, where a grid holds a value at a coordinate that is no control point of
/// `lattice` (whose points PlacePoints() found in both grids).
bool CheckNoOtherValues(vtkFFDVDBReader* self, const Grids& found, vtkUnstructuredGrid* lattice)
{
  const vtkIdType numPoints = lattice->GetNumberOfPoints();
  const int* indices =
    vtkIntArray::SafeDownCast(lattice->GetPointData()->GetArray(vtkFFDDataContract::LatticeIndexArrayName()))
      ->GetPointer(0);
  const int* perAxis = found.PointsPerAxis;
  vtkFFDSortedKeys<> keys; // the points' flat indices, in their (increasing) order: made where needed
  for (const openvdb::Vec3DGrid::Ptr& vectors : { found.Displacement, found.Position })
  {
    if (vtkIdType(vectors->activeVoxelCount()) == numPoints)
    {
      continue; // it holds every control point, so nothing else
    }
    if (keys.GetSize() == 0)
    {
      // Only on the way to an error (PlacePoints() found every point, so the grid holds more), and 8 bytes a
      // point, which the lattice's builder held too (since freed): the peak does not grow.
      std::vector<vtkTypeInt64> flat(static_cast<size_t>(numPoints));
      vtkSMPTools::For(0, numPoints,
        [&](vtkIdType begin, vtkIdType end)
        {
          for (vtkIdType p = begin; p < end; ++p)
          {
            flat[p] = vtkFFDFlatIndex(indices[3 * p], indices[3 * p + 1], indices[3 * p + 2], perAxis);
          }
        });
      keys = vtkFFDSortedKeys<>(std::move(flat));
    }
    // A value where the lattice has no control point: the first one, found in the increasing LatticeIndex.
    vectors->tree().voxelizeActiveTiles();
    for (auto it = vectors->cbeginValueOn(); it; ++it)
    {
      const openvdb::Coord x = it.getCoord();
      const bool inside =
        x.x() >= 0 && x.y() >= 0 && x.z() >= 0 && x.x() < perAxis[0] && x.y() < perAxis[1] && x.z() < perAxis[2];
      if (!inside || keys.Find(vtkFFDFlatIndex(x.x(), x.y(), x.z(), perAxis)) < 0)
      {
        vtkErrorWithObjectMacro(self, << "The grid \"" << vectors->getName() << "\" of " << self->GetFileName()
                                      << " has a value at " << Ijk(x) << ", which is not a control point of the "
                                      << vtkFFDBuildLattice::GetBasisAsString(found.Basis)
                                      << " lattice over its active voxels: the grids hold the lattice's control "
                                         "points only; write the file with vtkFFDVDBWriter.");
        return false;
      }
    }
  }
  return true;
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
  catch (const openvdb::Exception& e) // from the grids read, not their parse (ParseGrids() reports those)
  {
    vtkErrorMacro(<< "OpenVDB failed on the grids of " << this->FileName << " (" << e.what()
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
  // The file whole, its checksum checked, then parsed by OpenVDB from memory: OpenVDB trusts the sizes in a file.
  std::vector<char> bytes;
  size_t payload = 0;
  if (!ReadBytes(this, bytes, payload))
  {
    return false;
  }
  openvdb::initialize();
  const openvdb::GridPtrVecPtr grids = ParseGrids(this, bytes, payload);
  std::vector<char>().swap(bytes);
  Grids found;
  if (!grids || !FindGrids(this, *grids, found) || !CheckDescription(this, found))
  {
    return false;
  }
  this->UpdateProgress(0.2);
  const vtkSmartPointer<vtkIntArray> voxelIndex = MakeVoxels(this, found, voxelGrid);
  if (!voxelIndex)
  {
    return false;
  }
  this->UpdateProgress(0.4);

  // The lattice at rest, by vtkFFDBuildLattice's code (its progress mapped to 0.4 .. 0.7 of ours).
  this->SetProgressShiftScale(0.4, 0.3);
  const bool built = vtkFFDMakeSparseLattice(this, found.Lattice.Frame, static_cast<ffd::GridBasis>(found.Basis),
    found.Lattice.Divisions, voxelIndex,
    "The " + std::to_string(voxelIndex->GetNumberOfTuples()) + " active voxels of " + this->FileName + ": their " +
      found.Lattice.Basis + " lattice",
    lattice);
  this->SetProgressShiftScale(0.0, 1.0);
  if (!built || this->GetAbortExecute())
  {
    return built;
  }
  // The statistics vtkFFDVoxelize and vtkFFDBuildLattice record (vtkFFDStatistics.h), the lattice passing its
  // voxel grid's as the pipeline does.
  for (vtkUnstructuredGrid* output : { voxelGrid, lattice })
  {
    vtkFFDRecordCount(output, "NumberOfActiveVoxels", voxelIndex->GetNumberOfTuples());
  }
  vtkFFDRecordCount(lattice, "NumberOfActiveControlPoints", lattice->GetNumberOfPoints());
  this->UpdateProgress(0.7);
  return PlacePoints(this, found, lattice) && CheckNoOtherValues(this, found, lattice);
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDVDBReader::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FileName: " << (this->FileName ? this->FileName : "(none)") << "\n";
}
