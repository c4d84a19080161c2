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

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <new>
#include <sstream>
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

/// The input's sparse lattice, as far as it has been checked: what the grids are made of.
struct LatticeView
{
  vtkUnstructuredGrid* Lattice = nullptr;
  double Frame[12];
  int Divisions[3];
  int Basis = -1;
  int PointsPerAxis[3];
  vtkIdType NumPoints = 0;
  vtkIdType NumCells = 0;
  const int* Voxels = nullptr;  // VoxelIndex, 3 ints a cell
  const int* Indices = nullptr; // LatticeIndex, 3 ints a point
  const double* Rest = nullptr; // RestPosition, 3 doubles a point
};

/// The input as a sparse lattice of a local basis, with its frame, divisions and basis, in `view`: false, with
/// the error reported, where it is not one.
bool CheckDescription(vtkAlgorithm* self, vtkDataObject* input, LatticeView& view)
{
  view.Lattice = vtkUnstructuredGrid::SafeDownCast(input);
  if (!view.Lattice)
  {
    vtkErrorWithObjectMacro(self, << "The input is a " << (input ? input->GetClassName() : "null data object")
                                  << (vtkStructuredGrid::SafeDownCast(input) ? " (a dense lattice)" : "")
                                  << ", not a sparse lattice (a vtkUnstructuredGrid): .vdb files hold sparse "
                                     "lattices; build it with vtkFFDBuildLattice::SetLatticeFormToSparse().");
    return false;
  }
  if (!vtkFFDDataContract::GetFrame(view.Lattice, view.Frame) ||
    ffd::CheckFrame(view.Frame) != ffd::FrameStatus::Valid ||
    !vtkFFDDataContract::GetDivisions(view.Lattice, view.Divisions) ||
    !vtkFFDDataContract::GetBasis(view.Lattice, view.Basis))
  {
    vtkErrorWithObjectMacro(self, << "The input has no valid " << vtkFFDDataContract::FrameArrayName() << ", "
                                  << vtkFFDDataContract::DivisionsArrayName() << " or "
                                  << vtkFFDDataContract::BasisArrayName()
                                  << " field array (a tetrahedral lattice has none, and no .vdb form): write the "
                                     "output of vtkFFDBuildLattice with SetLatticeFormToSparse().");
    return false;
  }
  if (view.Basis == vtkFFDBuildLattice::BERNSTEIN)
  {
    vtkErrorWithObjectMacro(self, << "The input's basis is the global BERNSTEIN basis, which has no sparse form (each "
                                     "of its control points influences every voxel) and so no .vdb form: use a "
                                     "local basis, e.g. vtkFFDBuildLattice::SetBasisToCubicBSpline().");
    return false;
  }
  std::string why;
  if (!vtkFFDBuildLattice::GetControlPointsPerAxis(
        view.Basis, view.Divisions, view.PointsPerAxis, why, vtkFFDBuildLattice::SPARSE))
  {
    vtkErrorWithObjectMacro(self, << "The input is not a valid lattice: " << why);
    return false;
  }
  return true;
}

/// The contract's arrays of a sparse lattice in `view`, their indices within the lattice: false, with the error
/// reported, where one is missing, malformed or out of range.
bool FindArrays(vtkAlgorithm* self, LatticeView& view)
{
  vtkUnstructuredGrid* lattice = view.Lattice;
  view.NumPoints = lattice->GetNumberOfPoints();
  view.NumCells = lattice->GetNumberOfCells();
  vtkDoubleArray* rest =
    TupleArray<vtkDoubleArray>(lattice->GetPointData(), vtkFFDDataContract::RestPositionArrayName(), view.NumPoints);
  vtkIntArray* latticeIndex =
    TupleArray<vtkIntArray>(lattice->GetPointData(), vtkFFDDataContract::LatticeIndexArrayName(), view.NumPoints);
  vtkIntArray* voxelIndex =
    TupleArray<vtkIntArray>(lattice->GetCellData(), vtkFFDDataContract::VoxelIndexArrayName(), view.NumCells);
  if (!rest || !latticeIndex || !voxelIndex)
  {
    vtkErrorWithObjectMacro(self, << "The input lacks "
                                  << (!rest              ? "the RestPosition point array (3 doubles a point)"
                                         : !latticeIndex ? "the LatticeIndex point array (3 ints a point)"
                                                         : "the VoxelIndex cell array (3 ints a cell)")
                                  << " of a sparse lattice: write the output of vtkFFDBuildLattice with "
                                     "SetLatticeFormToSparse().");
    return false;
  }
  view.Voxels = voxelIndex->GetPointer(0);
  view.Indices = latticeIndex->GetPointer(0);
  view.Rest = rest->GetPointer(0);
  const vtkIdType badVoxel = FirstOutside(view.Voxels, view.NumCells, view.Divisions);
  const vtkIdType badIndex = FirstOutside(view.Indices, view.NumPoints, view.PointsPerAxis);
  if (badVoxel >= 0 || badIndex >= 0)
  {
    vtkErrorWithObjectMacro(self, << "The input's "
                                  << (badVoxel >= 0 ? "VoxelIndex of cell " : "LatticeIndex of point ")
                                  << (badVoxel >= 0 ? badVoxel : badIndex) << " lies outside its "
                                  << (badVoxel >= 0 ? "FFDDivisions" : "control points per axis")
                                  << ": write the output of vtkFFDBuildLattice with SetLatticeFormToSparse().");
    return false;
  }
  return true;
}

/**
 * The file holds the voxels and the points, and the reader rebuilds the lattice as vtkFFDBuildLattice does: false,
 * with the error reported, unless the points are the union of the voxels' supports, in increasing lattice order,
 * each with the rest position of its LatticeIndex.
 */
bool CheckPoints(vtkAlgorithm* self, const LatticeView& view)
{
  const ffd::GridBasis grid = static_cast<ffd::GridBasis>(view.Basis);
  vtkFFDActiveSet supports;
  vtkFFDSparseLattice::MarkSupports(supports, grid, view.Divisions, view.Voxels, view.NumCells);
  if (supports.GetNumberOfMarked() != view.NumPoints)
  {
    vtkErrorWithObjectMacro(self, << "The input has " << view.NumPoints
                                  << " points, but the supports of its cells' voxels have "
                                  << supports.GetNumberOfMarked()
                                  << " control points: write a lattice as vtkFFDBuildLattice makes it "
                                     "(SetLatticeFormToSparse()), its points moved but none added or removed.");
    return false;
  }
  if (!vtkFFDCheckMemory(
        self, "Checking the " + std::to_string(view.NumPoints) + " points of the lattice", 8.0 * view.NumPoints))
  {
    return false;
  }
  const vtkTypeInt64 dims[3] = { view.PointsPerAxis[0], view.PointsPerAxis[1], view.PointsPerAxis[2] };
  const std::vector<vtkTypeInt64> sorted = supports.TakeSortedIndices(dims);
  const ffd::Frame<double> bound = ffd::Frame<double>::FromArray(view.Frame);
  for (vtkIdType p = 0; p < view.NumPoints; ++p)
  {
    const int* ijk = view.Indices + 3 * p;
    if (vtkFFDFlatIndex(ijk[0], ijk[1], ijk[2], dims) != sorted[p])
    {
      vtkErrorWithObjectMacro(self, << "Point " << p << " of the input has LatticeIndex (" << ijk[0] << ", " << ijk[1]
                                    << ", " << ijk[2] << "), where vtkFFDBuildLattice puts another control point: "
                                    << "write a lattice as vtkFFDBuildLattice makes it, its points moved but none "
                                       "reordered.");
      return false;
    }
    const ffd::Vec3<double> x = vtkFFDRestPoint(bound, grid, view.Divisions, ijk[0], ijk[1], ijk[2]);
    if (std::memcmp(&x.x, view.Rest + 3 * p, 3 * sizeof(double)) != 0)
    {
      vtkErrorWithObjectMacro(self, << "The RestPosition of point " << p
                                    << " differs from the rest position of its LatticeIndex (" << ijk[0] << ", "
                                    << ijk[1] << ", " << ijk[2]
                                    << ") in the frame: the file keeps the frame, not the rest positions; move the "
                                       "points, not RestPosition, or rebuild the lattice with vtkFFDBuildLattice.");
      return false;
    }
  }
  return true;
}

/// The file's three grids (docs/interchange-and-files.md, ".vdb files"): empty, with the error reported, where two
/// cells share a voxel.
openvdb::GridCPtrVec MakeGrids(vtkAlgorithm* self, const LatticeView& view)
{
  openvdb::initialize();
  const ffd::GridBasis grid = static_cast<ffd::GridBasis>(view.Basis);
  const double voxelSteps[3] = { 1.0 / view.Divisions[0], 1.0 / view.Divisions[1], 1.0 / view.Divisions[2] };
  double voxelOffsets[3], pointSteps[3], pointOffsets[3];
  for (int a = 0; a < 3; ++a)
  {
    voxelOffsets[a] = 0.5 * voxelSteps[a];
    pointOffsets[a] = ffd::RestParameter(grid, view.Divisions[a], 0);
    pointSteps[a] = ffd::RestParameter(grid, view.Divisions[a], 1) - pointOffsets[a];
  }
  openvdb::BoolGrid::Ptr activeVoxels = openvdb::BoolGrid::create(false);
  {
    openvdb::BoolGrid::Accessor accessor = activeVoxels->getAccessor();
    for (vtkIdType c = 0; c < view.NumCells; ++c)
    {
      accessor.setValueOn(openvdb::Coord(view.Voxels + 3 * c), true);
    }
  }
  if (vtkIdType(activeVoxels->activeVoxelCount()) != view.NumCells)
  {
    vtkErrorWithObjectMacro(self, << "The input's " << view.NumCells << " cells name only "
                                  << activeVoxels->activeVoxelCount()
                                  << " distinct voxels in VoxelIndex: give each active voxel one cell, as "
                                     "vtkFFDBuildLattice does.");
    return {};
  }
  activeVoxels->setName(vtkFFDVDB::ActiveVoxelsGrid);
  activeVoxels->setTransform(AffineTransform(view.Frame, voxelSteps, voxelOffsets));
  SetDescription(*activeVoxels, view.Frame, view.Divisions, -1);

  openvdb::Vec3DGrid::Ptr displacement = openvdb::Vec3DGrid::create(openvdb::Vec3d(0.0));
  openvdb::Vec3DGrid::Ptr position = openvdb::Vec3DGrid::create(openvdb::Vec3d(0.0));
  {
    openvdb::Vec3DGrid::Accessor displacements = displacement->getAccessor();
    openvdb::Vec3DGrid::Accessor positions = position->getAccessor();
    vtkPoints* points = view.Lattice->GetPoints();
    for (vtkIdType p = 0; p < view.NumPoints; ++p)
    {
      const openvdb::Coord ijk(view.Indices + 3 * p);
      const double* r = view.Rest + 3 * p;
      openvdb::Vec3d x;
      points->GetPoint(p, x.asPointer());
      positions.setValueOn(ijk, x);
      displacements.setValueOn(ijk, openvdb::Vec3d(x[0] - r[0], x[1] - r[1], x[2] - r[2]));
    }
  }
  const openvdb::math::Transform::Ptr pointTransform = AffineTransform(view.Frame, pointSteps, pointOffsets);
  displacement->setName(vtkFFDVDB::DisplacementGrid);
  displacement->setVectorType(openvdb::VEC_CONTRAVARIANT_RELATIVE);
  position->setName(vtkFFDVDB::PositionGrid);
  position->setVectorType(openvdb::VEC_CONTRAVARIANT_ABSOLUTE);
  for (const openvdb::Vec3DGrid::Ptr& vectors : { displacement, position })
  {
    vectors->setTransform(pointTransform->copy());
    vectors->setIsInWorldSpace(true);
    SetDescription(*vectors, view.Frame, view.Divisions, view.Basis);
  }
  return { activeVoxels, displacement, position };
}

/// OpenVDB's bytes of `grids` as io::File lays them out (with grid offsets, so that tools read one grid without the
/// others), then the checksum trailer (vtkFFDOpenVDB.h). Into memory: io::File writes through its own stream and
/// does not report a failed write.
class MemoryArchive : public openvdb::io::Archive
{
public:
  std::string Bytes(const openvdb::GridCPtrVec& grids) const
  {
    std::ostringstream stream(std::ios::binary);
    this->Archive::write(stream, grids, /*seekable=*/true);
    std::string bytes = stream.str();
    bytes += vtkFFDVDB::Trailer(bytes.data(), bytes.size());
    return bytes;
  }
};
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
  LatticeView view;
  if (!CheckDescription(this, input, view) || !FindArrays(this, view) || !CheckPoints(this, view))
  {
    return false;
  }
  this->UpdateProgress(0.3);
  const openvdb::GridCPtrVec grids = MakeGrids(this, view);
  if (grids.empty())
  {
    return false;
  }
  this->UpdateProgress(0.6);
  if (!this->WriteFileAtomically(MemoryArchive().Bytes(grids)))
  {
    return false;
  }
  this->UpdateProgress(1.0);
  return true;
}

//------------------------------------------------------------------------------------------------------------
bool vtkFFDVDBWriter::WriteFileAtomically(const std::string& bytes)
{
  // A symbolic link stays: the file it names is replaced.
  std::string target = this->FileName;
  struct stat existing;
  if (lstat(target.c_str(), &existing) == 0 && S_ISLNK(existing.st_mode))
  {
    if (char* resolved = realpath(target.c_str(), nullptr))
    {
      target = resolved;
      std::free(resolved);
    }
  }
  const bool exists = stat(target.c_str(), &existing) == 0;
  // The temporary file lies beside the target, so that rename() replaces the target in one step: a reader sees
  // the old file or the new one, never part of one.
  static std::atomic<unsigned> written(0);
  std::string temporary;
  int fd = -1;
  for (int attempt = 0; fd < 0 && attempt < 16; ++attempt)
  {
    temporary = target + ".tmp" + std::to_string(getpid()) + "-" + std::to_string(written++);
    fd = open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0 && errno != EEXIST)
    {
      break;
    }
  }
  if (fd < 0)
  {
    vtkErrorMacro(<< "Cannot write " << target << ": no temporary file can be made beside it (" << std::strerror(errno)
                  << "): check that its folder exists and is writable.");
    this->SetErrorCode(vtkErrorCode::CannotOpenFileError);
    return false;
  }
  // Every step checked: a write, flush or close can fail on a full disk, a quota or a file size limit.
  const char* failed = nullptr;
  int error = 0;
  auto check = [&](bool done, const char* step)
  {
    if (!failed && !done)
    {
      failed = step;
      error = errno;
    }
  };
  for (size_t done = 0; !failed && done < bytes.size();)
  {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    check(n > 0 || (n < 0 && errno == EINTR), "writing it");
    done += n > 0 ? size_t(n) : 0;
  }
  check(failed || !exists || fchmod(fd, existing.st_mode & 07777) == 0, "keeping its permissions");
  check(failed || fsync(fd) == 0, "flushing it");
  check(close(fd) == 0, "closing it");
  check(failed || std::rename(temporary.c_str(), target.c_str()) == 0, "renaming it over the file");
  if (failed)
  {
    std::remove(temporary.c_str());
    vtkErrorMacro(<< "Cannot write " << target << ": " << failed << " failed (" << std::strerror(error) << "); "
                  << (exists ? "the file is left as it was." : "no file was written."));
    this->SetErrorCode(error == ENOSPC || error == EDQUOT || error == EFBIG ? vtkErrorCode::OutOfDiskSpaceError
                                                                            : vtkErrorCode::UnknownError);
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDVDBWriter::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FileName: " << (this->FileName ? this->FileName : "(none)") << "\n";
}
