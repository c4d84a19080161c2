// SPDX-License-Identifier: BSD-3-Clause
// vtkFFDVDBWriter and vtkFFDVDBReader (docs/interchange-and-files.md, ".vdb files"): for every local basis, the bear's
// sparse lattice, its points moved at random, written and read back identical bit for bit (every array, the cells, the
// field data), with the voxel grid vtkFFDVoxelize makes and the same deformation; OpenVDB's own vdb_print reads the
// file; a displacement that another tool changed is the deformation read back; every bad input and every malformed file
// (made here with OpenVDB) gives an error and empty outputs, never a crash; every byte flipped and every cut of a
// written file is an error or the file read back identical, in a child process under an address-space limit; a write
// that fails part-way leaves the old file as it was. File size and times are printed.

#include "FFDTestErrorObserver.h"
#include "FFDTestLattices.h"
#include "FFDTestMeshes.h"

#include "vtkCallbackCommand.h"
#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkErrorCode.h"
#include "vtkExecutive.h"
#include "vtkFFDBuildLattice.h"
#include "vtkFFDBuildTetrahedralLattice.h"
#include "vtkFFDDeform.h"
#include "vtkFFDVDBReader.h"
#include "vtkFFDVDBWriter.h"
#include "vtkFFDVoxelize.h"
#include "vtkFieldData.h"
#include "vtkIntArray.h"
#include "vtkUnsignedCharArray.h"
#include "vtkUnstructuredGrid.h"

#include <openvdb/openvdb.h>

#include <gtest/gtest.h>

#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <iterator>
#include <map>
#include <random>
#include <regex>
#include <string>
#include <vector>

namespace
{
const int LocalBases[] = { vtkFFDBuildLattice::TRILINEAR, vtkFFDBuildLattice::TRIQUADRATIC_BEZIER,
  vtkFFDBuildLattice::TRICUBIC_BEZIER, vtkFFDBuildLattice::CUBIC_BSPLINE };

/// A path in the temporary folder, distinct per test process (ctest runs tests side by side).
std::string TempPath(const std::string& name)
{
  return (std::filesystem::temp_directory_path() / ("voxelffd_" + std::to_string(getpid()) + "_" + name)).string();
}

/// Removes the file at the end of the scope.
struct TempFile
{
  explicit TempFile(const std::string& name)
    : Path(TempPath(name))
  {
  }
  ~TempFile() { std::remove(this->Path.c_str()); }
  const std::string Path;
};

/// The same type, components, tuples and bytes.
::testing::AssertionResult SameArray(vtkAbstractArray* got, vtkAbstractArray* want)
{
  if (!got || got->GetDataType() != want->GetDataType() ||
    got->GetNumberOfComponents() != want->GetNumberOfComponents() ||
    got->GetNumberOfTuples() != want->GetNumberOfTuples())
  {
    return ::testing::AssertionFailure() << "array \"" << (want->GetName() ? want->GetName() : "")
                                         << "\": missing, or of another type or size";
  }
  const size_t bytes = size_t(want->GetNumberOfValues()) * size_t(want->GetDataTypeSize());
  if (bytes > 0 && std::memcmp(got->GetVoidPointer(0), want->GetVoidPointer(0), bytes) != 0)
  {
    return ::testing::AssertionFailure() << "array \"" << (want->GetName() ? want->GetName() : "") << "\": other bytes";
  }
  return ::testing::AssertionSuccess();
}

/// The same arrays, by name, each SameArray().
::testing::AssertionResult SameArrays(vtkFieldData* got, vtkFieldData* want, const char* where)
{
  if (got->GetNumberOfArrays() != want->GetNumberOfArrays())
  {
    return ::testing::AssertionFailure() << where << ": " << got->GetNumberOfArrays() << " arrays, not "
                                         << want->GetNumberOfArrays();
  }
  for (int a = 0; a < want->GetNumberOfArrays(); ++a)
  {
    vtkAbstractArray* w = want->GetAbstractArray(a);
    const ::testing::AssertionResult same = SameArray(got->GetAbstractArray(w->GetName()), w);
    if (!same)
    {
      return ::testing::AssertionFailure() << where << ": " << same.message();
    }
  }
  return ::testing::AssertionSuccess();
}

/// The same points, cells (types, offsets, point ids) and point, cell and field arrays, bit for bit.
::testing::AssertionResult SameGrid(vtkUnstructuredGrid* got, vtkUnstructuredGrid* want)
{
  ::testing::AssertionResult same = SameArray(got->GetPoints()->GetData(), want->GetPoints()->GetData());
  if (!same)
  {
    return ::testing::AssertionFailure() << "points: " << same.message();
  }
  vtkCellArray* g = got->GetCells();
  vtkCellArray* w = want->GetCells();
  const std::pair<vtkAbstractArray*, vtkAbstractArray*> cells[] = { { got->GetCellTypesArray(),
                                                                      want->GetCellTypesArray() },
    { g->GetOffsetsArray(), w->GetOffsetsArray() }, { g->GetConnectivityArray(), w->GetConnectivityArray() } };
  for (const auto& arrays : cells)
  {
    same = SameArray(arrays.first, arrays.second);
    if (!same)
    {
      return ::testing::AssertionFailure() << "cells: " << same.message();
    }
  }
  same = SameArrays(got->GetPointData(), want->GetPointData(), "point data");
  if (same)
  {
    same = SameArrays(got->GetCellData(), want->GetCellData(), "cell data");
  }
  if (same)
  {
    same = SameArrays(got->GetFieldData(), want->GetFieldData(), "field data");
  }
  return same;
}

/// The sparse lattice of `basis` over the voxel grid, a copy of vtkFFDBuildLattice's output.
vtkSmartPointer<vtkUnstructuredGrid> SparseLattice(vtkAlgorithm* voxelize, int basis)
{
  vtkNew<vtkFFDBuildLattice> build;
  build->SetInputConnection(voxelize->GetOutputPort());
  build->SetBasis(basis);
  build->SetLatticeFormToSparse();
  build->Update();
  auto lattice = vtkSmartPointer<vtkUnstructuredGrid>::New();
  lattice->DeepCopy(build->GetOutput());
  return lattice;
}

/// Writes `data` to `path` with vtkFFDVDBWriter: Write()'s result; its errors in `errors` when given.
int Write(vtkDataObject* data, const std::string& path, std::string* errors = nullptr)
{
  vtkNew<vtkFFDVDBWriter> writer;
  vtkNew<FFDTestErrorObserver> observer;
  observer->WatchWithExecutive(writer);
  writer->SetInputData(data);
  writer->SetFileName(path.c_str());
  const int written = writer->Write();
  if (errors)
  {
    *errors = observer->Errors;
  }
  else
  {
    EXPECT_EQ(observer->Errors, "");
  }
  return written;
}

/// A reader of `path`, updated, with its errors in `observer`: the update's result.
int Read(vtkFFDVDBReader* reader, const std::string& path, FFDTestErrorObserver* observer)
{
  observer->WatchWithExecutive(reader);
  reader->SetFileName(path.c_str());
  return reader->GetExecutive()->Update();
}

/// The bear voxelized into n^3 voxels.
vtkSmartPointer<vtkFFDVoxelize> VoxelizedBear(vtkPolyData* bear, int n)
{
  auto voxelize = vtkSmartPointer<vtkFFDVoxelize>::New();
  voxelize->SetInputData(bear);
  voxelize->SetDivisions(n, n, n);
  voxelize->Update();
  return voxelize;
}

/// The deformed points of `mesh` by `lattice`.
vtkSmartPointer<vtkDataArray> Deformed(vtkPolyData* mesh, vtkUnstructuredGrid* lattice)
{
  vtkNew<vtkFFDDeform> deform;
  deform->SetInputData(mesh);
  deform->SetLatticeData(lattice);
  deform->Update();
  return vtkPointSet::SafeDownCast(deform->GetOutputDataObject(0))->GetPoints()->GetData();
}

/// Reads the grids of `good` with OpenVDB, lets `change` edit them and writes them to `path`.
void Rewrite(const std::string& good, const std::string& path, const std::function<void(openvdb::GridPtrVec&)>& change)
{
  openvdb::initialize();
  openvdb::io::File in(good);
  in.open(false);
  openvdb::GridPtrVecPtr grids = in.getGrids();
  in.close();
  change(*grids);
  openvdb::io::File(path).write(*grids);
}

/// The grid `name` of `grids`.
template <typename GridT>
typename GridT::Ptr GridNamed(openvdb::GridPtrVec& grids, const std::string& name)
{
  return openvdb::gridPtrCast<GridT>(openvdb::findGridByName(grids, name));
}

/// The bytes of the file at `path`.
std::string FileBytes(const std::string& path)
{
  std::ifstream file(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>());
}

void WriteBytes(const std::string& path, const std::string& bytes)
{
  std::ofstream(path, std::ios::binary | std::ios::trunc).write(bytes.data(), std::streamsize(bytes.size()));
}

/// What reading a damaged file gave (ReadInChild()).
enum Outcome
{
  Identical = 0, ///< both outputs identical to what was written
  Damaged = 1,   ///< the checksum's error ("is damaged"), outputs empty
  Refused = 2,   ///< another error, outputs empty
  Wrong = 3,     ///< read without error, but other data: silently wrong
  NotEmpty = 4,  ///< an error, but an output is not empty
  NoMemory = 5,  ///< an allocation failed under the address-space limit
  Crashed = 6    ///< the child died of a signal (SIGABRT, SIGSEGV; SIGALRM: it hung)
};

/**
 * Reads `path` with vtkFFDVDBReader in a forked child, whose address space may grow by 1 GiB at most (RLIMIT_AS,
 * so that an unbounded allocation fails there rather than meeting the OOM killer) and which has 30 s: the Outcome,
 * comparing the outputs with `lattice` and `voxels`. The test runner survives whatever the reader does.
 */
Outcome ReadInChild(const std::string& path, vtkUnstructuredGrid* lattice, vtkUnstructuredGrid* voxels)
{
  std::fflush(nullptr);
  const pid_t child = fork();
  if (child == 0)
  {
    long pages = 0;
    std::ifstream("/proc/self/statm") >> pages;
    const rlim_t limit = rlim_t(pages) * rlim_t(sysconf(_SC_PAGESIZE)) + (rlim_t(1) << 30);
    const rlimit bound = { limit, limit };
    setrlimit(RLIMIT_AS, &bound);
    alarm(30);
    vtkNew<vtkFFDVDBReader> reader;
    vtkNew<FFDTestErrorObserver> observer;
    const int read = Read(reader, path, observer);
    Outcome outcome = Identical;
    if (observer->Errors.find("Out of memory") != std::string::npos)
    {
      outcome = NoMemory;
    }
    else if (read)
    {
      outcome = SameGrid(reader->GetOutput(), lattice) && SameGrid(reader->GetVoxelGridOutput(), voxels) &&
          observer->Errors.empty()
        ? Identical
        : Wrong;
    }
    else if (reader->GetOutput()->GetNumberOfPoints() > 0 || reader->GetVoxelGridOutput()->GetNumberOfPoints() > 0)
    {
      outcome = NotEmpty;
    }
    else
    {
      outcome = observer->Errors.find(" is damaged: ") != std::string::npos ? Damaged : Refused;
    }
    if (outcome >= Wrong)
    {
      std::cerr << observer->Errors;
    }
    _exit(outcome);
  }
  int status = 0;
  if (child < 0 || waitpid(child, &status, 0) != child)
  {
    ADD_FAILURE() << "fork() or waitpid() failed: " << std::strerror(errno);
    return Crashed;
  }
  return WIFEXITED(status) ? Outcome(WEXITSTATUS(status)) : Crashed;
}

/// A folder of its own, removed with what it holds at the end of the scope.
struct TempFolder
{
  explicit TempFolder(const std::string& name)
    : Path(TempPath(name))
  {
    std::filesystem::create_directories(this->Path);
  }
  ~TempFolder()
  {
    std::filesystem::permissions(this->Path, std::filesystem::perms::owner_all);
    std::filesystem::remove_all(this->Path);
  }
  /// The names of the files in the folder.
  std::vector<std::string> Files() const
  {
    std::vector<std::string> names;
    for (const auto& entry : std::filesystem::directory_iterator(this->Path))
    {
      names.push_back(entry.path().filename().string());
    }
    std::sort(names.begin(), names.end());
    return names;
  }
  const std::string Path;
};
} // namespace

TEST(vtkFFDVDB, RoundTripOfTheBearIsIdenticalForEveryLocalBasis)
{
  vtkSmartPointer<vtkPolyData> bear = ReadTestMesh("bear");
  vtkSmartPointer<vtkFFDVoxelize> voxelize = VoxelizedBear(bear, 12);
  std::mt19937 rng(20250917);
  for (int basis : LocalBases)
  {
    SCOPED_TRACE(vtkFFDBuildLattice::GetBasisAsString(basis));
    vtkSmartPointer<vtkUnstructuredGrid> lattice = SparseLattice(voxelize, basis);
    ffdtest::Perturb(lattice, rng, 0.02 * ffdtest::Diagonal(ffdtest::FrameOf(lattice)));
    TempFile file("roundtrip.vdb");
    ASSERT_EQ(Write(lattice, file.Path), 1);

    vtkNew<vtkFFDVDBReader> reader;
    vtkNew<FFDTestErrorObserver> observer;
    ASSERT_EQ(Read(reader, file.Path, observer), 1) << observer->Errors;
    EXPECT_EQ(observer->Errors, "");
    ASSERT_GT(lattice->GetNumberOfPoints(), 0);
    EXPECT_TRUE(SameGrid(reader->GetOutput(), lattice));
    EXPECT_TRUE(SameGrid(reader->GetVoxelGridOutput(), voxelize->GetOutput()));
    EXPECT_TRUE(SameArray(Deformed(bear, reader->GetOutput()), Deformed(bear, lattice)));
  }
}

TEST(vtkFFDVDB, VdbPrintListsTheGridsAndTheirActiveVoxels)
{
  if (std::system("command -v vdb_print > /dev/null 2>&1") != 0)
  {
    GTEST_SKIP() << "vdb_print is not installed (Debian's libopenvdb-tools; Utilities/setup.sh installs it)";
  }
  vtkSmartPointer<vtkPolyData> bear = ReadTestMesh("bear");
  vtkSmartPointer<vtkFFDVoxelize> voxelize = VoxelizedBear(bear, 12);
  vtkSmartPointer<vtkUnstructuredGrid> lattice = SparseLattice(voxelize, vtkFFDBuildLattice::CUBIC_BSPLINE);
  TempFile file("vdb_print.vdb");
  ASSERT_EQ(Write(lattice, file.Path), 1);
  FILE* pipe = popen(("vdb_print -l '" + file.Path + "' 2>&1").c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string printed;
  char buffer[4096];
  for (size_t n; (n = std::fread(buffer, 1, sizeof(buffer), pipe)) > 0;)
  {
    printed.append(buffer, n);
  }
  ASSERT_EQ(pclose(pipe), 0) << printed;
  // One section per grid, from its "Name:" line to the next, with its tree's type and active voxel count.
  const std::map<std::string, std::pair<std::string, vtkIdType>> expected = {
    { "active_voxels", { "Tree_bool_5_4_3", lattice->GetNumberOfCells() } },
    { "displacement", { "Tree_vec3d_5_4_3", lattice->GetNumberOfPoints() } },
    { "position", { "Tree_vec3d_5_4_3", lattice->GetNumberOfPoints() } },
  };
  const std::regex section(R"(Name: (\w+)\n[\s\S]*?Type: (\w+)[\s\S]*?Number of active voxels: +([\d,]+))");
  std::map<std::string, std::pair<std::string, vtkIdType>> listed;
  for (std::sregex_iterator it(printed.begin(), printed.end(), section), end; it != end; ++it)
  {
    const std::string count = std::regex_replace((*it)[3].str(), std::regex(","), "");
    listed[(*it)[1]] = { (*it)[2], std::stoll(count) };
  }
  EXPECT_EQ(listed, expected) << printed;
  EXPECT_NE(printed.find("ffd_basis: CubicBSpline"), std::string::npos) << printed;
  EXPECT_NE(printed.find("ffd_divisions: [12, 12, 12]"), std::string::npos) << printed;
}

TEST(vtkFFDVDB, EmptyLatticeRoundTrip)
{
  // A frame without any point in it: no voxel, no control point, but the frame, divisions and basis.
  vtkNew<vtkFFDVoxelize> voxelize;
  voxelize->SetInputData(PointCloud({ { 5.0, 5.0, 5.0 } }));
  const double origin[3] = { 0, 0, 0 }, s[3] = { 1, 0, 0 }, t[3] = { 0, 2, 0 }, u[3] = { 0, 0, 3 };
  voxelize->SetFrame(origin, s, t, u);
  voxelize->SetDivisions(3, 4, 5);
  voxelize->Update();
  vtkSmartPointer<vtkUnstructuredGrid> lattice = SparseLattice(voxelize, vtkFFDBuildLattice::TRICUBIC_BEZIER);
  ASSERT_EQ(lattice->GetNumberOfPoints(), 0);
  TempFile file("empty.vdb");
  ASSERT_EQ(Write(lattice, file.Path), 1);
  vtkNew<vtkFFDVDBReader> reader;
  vtkNew<FFDTestErrorObserver> observer;
  ASSERT_EQ(Read(reader, file.Path, observer), 1) << observer->Errors;
  EXPECT_TRUE(SameGrid(reader->GetOutput(), lattice));
  EXPECT_TRUE(SameGrid(reader->GetVoxelGridOutput(), voxelize->GetOutput()));
}

TEST(vtkFFDVDB, AnEditedDisplacementIsTheDeformationReadBack)
{
  // Another tool (Houdini, Blender's geometry nodes) changes the displacement grid but not the position grid:
  // the changed control point is at its rest position plus the new displacement, the others where they were.
  vtkSmartPointer<vtkPolyData> bear = ReadTestMesh("bear");
  vtkSmartPointer<vtkFFDVoxelize> voxelize = VoxelizedBear(bear, 6);
  vtkSmartPointer<vtkUnstructuredGrid> lattice = SparseLattice(voxelize, vtkFFDBuildLattice::TRIQUADRATIC_BEZIER);
  std::mt19937 rng(77);
  ffdtest::Perturb(lattice, rng, 0.01);
  TempFile file("written.vdb"), edited("edited.vdb");
  ASSERT_EQ(Write(lattice, file.Path), 1);
  const vtkIdType moved = lattice->GetNumberOfPoints() / 2;
  const int* ijk =
    vtkIntArray::SafeDownCast(lattice->GetPointData()->GetArray(vtkFFDDataContract::LatticeIndexArrayName()))
      ->GetPointer(3 * moved);
  const openvdb::Vec3d change(0.125, -0.25, 0.0625);
  Rewrite(file.Path, edited.Path,
    [&](openvdb::GridPtrVec& grids)
    {
      openvdb::Vec3DGrid::Accessor d = GridNamed<openvdb::Vec3DGrid>(grids, "displacement")->getAccessor();
      d.setValue(openvdb::Coord(ijk), d.getValue(openvdb::Coord(ijk)) + change);
    });
  vtkNew<vtkFFDVDBReader> reader;
  vtkNew<FFDTestErrorObserver> observer;
  ASSERT_EQ(Read(reader, edited.Path, observer), 1) << observer->Errors;
  vtkUnstructuredGrid* read = reader->GetOutput();
  vtkDataArray* rest = lattice->GetPointData()->GetArray(vtkFFDDataContract::RestPositionArrayName());
  for (vtkIdType p = 0; p < lattice->GetNumberOfPoints(); ++p)
  {
    double got[3], want[3], r[3];
    read->GetPoint(p, got);
    lattice->GetPoint(p, want);
    if (p == moved)
    {
      rest->GetTuple(p, r);
      for (int c = 0; c < 3; ++c)
      {
        want[c] = r[c] + ((want[c] - r[c]) + change[c]);
      }
    }
    ASSERT_TRUE(ffdtest::VectorEqual(got, want, "point")) << p;
  }
}

TEST(vtkFFDVDB, ReaderReportsProgress)
{
  vtkSmartPointer<vtkPolyData> bear = ReadTestMesh("bear");
  vtkSmartPointer<vtkFFDVoxelize> voxelize = VoxelizedBear(bear, 8);
  TempFile file("progress.vdb");
  ASSERT_EQ(Write(SparseLattice(voxelize, vtkFFDBuildLattice::TRILINEAR), file.Path), 1);
  std::vector<double> progress;
  vtkNew<vtkCallbackCommand> onProgress;
  onProgress->SetClientData(&progress);
  onProgress->SetCallback([](vtkObject* caller, unsigned long, void* data, void*)
    { static_cast<std::vector<double>*>(data)->push_back(static_cast<vtkAlgorithm*>(caller)->GetProgress()); });
  vtkNew<vtkFFDVDBReader> reader;
  reader->AddObserver(vtkCommand::ProgressEvent, onProgress);
  vtkNew<FFDTestErrorObserver> observer;
  ASSERT_EQ(Read(reader, file.Path, observer), 1) << observer->Errors;
  ASSERT_GE(progress.size(), 4u);
  EXPECT_TRUE(std::is_sorted(progress.begin(), progress.end()));
  EXPECT_GT(progress[1], 0.0);
  EXPECT_EQ(progress.back(), 1.0);
}

TEST(vtkFFDVDB, WriterRefusesWhatItCannotWriteOrReadBack)
{
  // Each bad input gives an error that names it, Write() 0 with an error code, and no file.
  vtkSmartPointer<vtkPolyData> bear = ReadTestMesh("bear");
  vtkSmartPointer<vtkFFDVoxelize> voxelize = VoxelizedBear(bear, 5);
  // A full 3x3x3 block: the centre voxel's trilinear support is covered by its neighbours'.
  std::vector<std::array<double, 3>> centres;
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i)
        centres.push_back({ i + 0.5, j + 0.5, k + 0.5 });
  vtkNew<vtkFFDVoxelize> block;
  block->SetInputData(PointCloud(centres));
  const double origin[3] = { 0, 0, 0 }, s[3] = { 3, 0, 0 }, t[3] = { 0, 3, 0 }, u[3] = { 0, 0, 3 };
  block->SetFrame(origin, s, t, u);
  block->SetDivisions(3, 3, 3);
  block->Update();

  auto sparse = [&](vtkAlgorithm* grid, int basis,
                  const std::function<void(vtkUnstructuredGrid*)>& change) -> vtkSmartPointer<vtkDataObject>
  {
    vtkSmartPointer<vtkUnstructuredGrid> lattice = SparseLattice(grid, basis);
    change(lattice);
    return lattice;
  };
  auto voxelIndex = [](vtkUnstructuredGrid* l)
  { return vtkIntArray::SafeDownCast(l->GetCellData()->GetArray(vtkFFDDataContract::VoxelIndexArrayName())); };
  auto latticeIndex = [](vtkUnstructuredGrid* l)
  { return vtkIntArray::SafeDownCast(l->GetPointData()->GetArray(vtkFFDDataContract::LatticeIndexArrayName())); };

  vtkNew<vtkFFDBuildLattice> dense;
  dense->SetInputConnection(voxelize->GetOutputPort());
  dense->SetBasisToTrilinear();
  dense->SetLatticeFormToDense();
  dense->Update();
  vtkNew<vtkFFDBuildTetrahedralLattice> tetrahedra;
  tetrahedra->SetInputData(bear);
  tetrahedra->Update();

  const int trilinear = vtkFFDBuildLattice::TRILINEAR;
  const std::vector<std::pair<std::string, vtkSmartPointer<vtkDataObject>>> cases = {
    { "SetLatticeFormToSparse()", dense->GetOutput() },
    { "FFDFrame", tetrahedra->GetOutput() },
    { "global BERNSTEIN basis",
      sparse(voxelize, trilinear, [](vtkUnstructuredGrid* l) { vtkFFDDataContract::SetBasis(l, 0); }) },
    { "RestPosition point array",
      sparse(voxelize, trilinear,
        [](vtkUnstructuredGrid* l) { l->GetPointData()->RemoveArray(vtkFFDDataContract::RestPositionArrayName()); }) },
    { "LatticeIndex point array",
      sparse(voxelize, trilinear,
        [](vtkUnstructuredGrid* l) { l->GetPointData()->RemoveArray(vtkFFDDataContract::LatticeIndexArrayName()); }) },
    { "VoxelIndex cell array",
      sparse(voxelize, trilinear,
        [](vtkUnstructuredGrid* l) { l->GetCellData()->RemoveArray(vtkFFDDataContract::VoxelIndexArrayName()); }) },
    { "VoxelIndex of cell 0 lies outside",
      sparse(voxelize, trilinear, [&](vtkUnstructuredGrid* l) { voxelIndex(l)->SetTypedComponent(0, 2, 5); }) },
    { "LatticeIndex of point 1 lies outside",
      sparse(voxelize, trilinear, [&](vtkUnstructuredGrid* l) { latticeIndex(l)->SetTypedComponent(1, 0, -1); }) },
    { "the supports of its cells' voxels have",
      sparse(voxelize, vtkFFDBuildLattice::CUBIC_BSPLINE,
        [&](vtkUnstructuredGrid* l)
        {
          int far[3] = { 4, 4, 4 }; // a voxel the bear does not reach at 5^3, whose support adds points
          for (vtkIdType c = 0; c < l->GetNumberOfCells(); ++c)
          {
            const int* v = voxelIndex(l)->GetPointer(3 * c);
            far[0] = v[0] == 4 && v[1] == 4 && v[2] == 4 ? 0 : far[0];
          }
          voxelIndex(l)->SetTypedTuple(0, far);
        }) },
    { "where vtkFFDBuildLattice puts another control point",
      sparse(voxelize, trilinear,
        [&](vtkUnstructuredGrid* l)
        {
          int first[3], second[3];
          latticeIndex(l)->GetTypedTuple(0, first);
          latticeIndex(l)->GetTypedTuple(1, second);
          latticeIndex(l)->SetTypedTuple(0, second);
          latticeIndex(l)->SetTypedTuple(1, first);
        }) },
    { "The RestPosition of point 3 differs",
      sparse(voxelize, vtkFFDBuildLattice::TRICUBIC_BEZIER,
        [](vtkUnstructuredGrid* l)
        {
          vtkDataArray* rest = l->GetPointData()->GetArray(vtkFFDDataContract::RestPositionArrayName());
          rest->SetComponent(3, 1, std::nextafter(rest->GetComponent(3, 1), 1e9));
        }) },
    { "distinct voxels",
      sparse(block, trilinear,
        [&](vtkUnstructuredGrid* l)
        {
          const int corner[3] = { 0, 0, 0 };
          voxelIndex(l)->SetTypedTuple(13, corner); // the centre voxel (1, 1, 1) becomes a second (0, 0, 0)
        }) },
  };
  for (const auto& c : cases)
  {
    SCOPED_TRACE(c.first);
    TempFile file("refused.vdb");
    std::string errors;
    EXPECT_EQ(Write(c.second, file.Path, &errors), 0);
    EXPECT_NE(errors.find(c.first), std::string::npos) << errors;
    EXPECT_FALSE(std::ifstream(file.Path).good());
  }

  vtkNew<vtkFFDVDBWriter> writer;
  vtkNew<FFDTestErrorObserver> observer;
  observer->WatchWithExecutive(writer);
  writer->SetInputData(SparseLattice(voxelize, trilinear));
  EXPECT_EQ(writer->Write(), 0);
  EXPECT_EQ(writer->GetErrorCode(), vtkErrorCode::NoFileNameError);
  EXPECT_NE(observer->Errors.find("No FileName"), std::string::npos) << observer->Errors;
  observer->Errors.clear();
  writer->SetFileName("/nonexistent-folder/lattice.vdb");
  EXPECT_EQ(writer->Write(), 0);
  EXPECT_EQ(writer->GetErrorCode(), vtkErrorCode::CannotOpenFileError);
  EXPECT_NE(observer->Errors.find("check that its folder exists"), std::string::npos) << observer->Errors;
}

TEST(vtkFFDVDB, ReaderRefusesMissingAndMalformedFiles)
{
  // Each defect gives an error that names it and two empty outputs; none crashes.
  vtkSmartPointer<vtkPolyData> bear = ReadTestMesh("bear");
  vtkSmartPointer<vtkUnstructuredGrid> lattice = SparseLattice(VoxelizedBear(bear, 5), vtkFFDBuildLattice::TRILINEAR);
  TempFile good("good.vdb"), text("text.vdb"), bad("bad.vdb");
  ASSERT_EQ(Write(lattice, good.Path), 1);
  std::ofstream(text.Path) << "not a VDB file\n";
  int first[3];
  vtkIntArray::SafeDownCast(lattice->GetPointData()->GetArray(vtkFFDDataContract::LatticeIndexArrayName()))
    ->GetTypedTuple(0, first);

  using Change = std::function<void(openvdb::GridPtrVec&)>;
  auto metadata = [](const char* key, const openvdb::Metadata& value, const std::vector<std::string>& names) -> Change
  {
    const openvdb::Metadata::Ptr copy = value.copy();
    return [=](openvdb::GridPtrVec& grids)
    {
      for (const std::string& name : names)
      {
        openvdb::findGridByName(grids, name)->removeMeta(key);
        openvdb::findGridByName(grids, name)->insertMeta(key, *copy);
      }
    };
  };
  const std::vector<std::string> all = { "active_voxels", "displacement", "position" };
  const std::vector<std::pair<std::string, Change>> defects = {
    { "no grid named \"position\"", [](openvdb::GridPtrVec& grids) { grids.erase(grids.begin() + 2); } },
    { "holds float values, not bool ones",
      [](openvdb::GridPtrVec& grids)
      {
        openvdb::FloatGrid::Ptr floats = openvdb::FloatGrid::create();
        floats->setName("active_voxels");
        grids[0] = floats;
      } },
    { "no metadata ffd_divisions (a Vec3i)",
      [](openvdb::GridPtrVec& grids) { openvdb::findGridByName(grids, "displacement")->removeMeta("ffd_divisions"); } },
    { "disagree on the frame",
      metadata("ffd_frame_origin", openvdb::Vec3DMetadata(openvdb::Vec3d(1, 2, 3)), { "position" }) },
    { "gives the basis \"Quintic\"",
      metadata("ffd_basis", openvdb::StringMetadata("Quintic"), { "displacement", "position" }) },
    { "gives the basis \"Bernstein\"",
      metadata("ffd_basis", openvdb::StringMetadata("Bernstein"), { "displacement", "position" }) },
    { "(nearly) zero volume", metadata("ffd_frame_u", openvdb::Vec3DMetadata(openvdb::Vec3d(0, 0, 0)), all) },
    { "gives the divisions (5, 0, 5)",
      metadata("ffd_divisions", openvdb::Vec3IMetadata(openvdb::Vec3i(5, 0, 5)), all) },
    { "beyond its divisions (5, 5, 5)",
      [](openvdb::GridPtrVec& grids)
      { GridNamed<openvdb::BoolGrid>(grids, "active_voxels")->tree().setValueOn(openvdb::Coord(5, 0, 0), true); } },
    { "has a value at (-5, 0, 2), which is not a control point",
      [](openvdb::GridPtrVec& grids)
      { GridNamed<openvdb::Vec3DGrid>(grids, "displacement")->tree().setValueOn(openvdb::Coord(-5, 0, 2)); } },
    { "has a value at (0, 0, 0), which is not a control point",
      [](openvdb::GridPtrVec& grids)
      { GridNamed<openvdb::Vec3DGrid>(grids, "position")->tree().setValueOn(openvdb::Coord(0, 0, 0)); } },
    { "has no value in the grid \"displacement\"",
      [&](openvdb::GridPtrVec& grids)
      { GridNamed<openvdb::Vec3DGrid>(grids, "displacement")->tree().setValueOff(openvdb::Coord(first)); } },
    { "has no value in the grid \"position\"",
      [&](openvdb::GridPtrVec& grids)
      { GridNamed<openvdb::Vec3DGrid>(grids, "position")->tree().setValueOff(openvdb::Coord(first)); } },
  };
  std::vector<std::pair<std::string, std::string>> files = {
    { "No FileName", "" },
    { "No such file or directory", TempPath("missing.vdb") },
    { "not a regular file", std::filesystem::temp_directory_path().string() },
    { "OpenVDB cannot read", text.Path },
  };
  for (const auto& defect : defects)
  {
    files.push_back({ defect.first, TempPath(std::to_string(files.size()) + ".vdb") });
    Rewrite(good.Path, files.back().second, defect.second);
  }
  for (const auto& f : files)
  {
    SCOPED_TRACE(f.first);
    vtkNew<vtkFFDVDBReader> reader;
    vtkNew<FFDTestErrorObserver> observer;
    EXPECT_EQ(Read(reader, f.second, observer), 0);
    EXPECT_NE(observer->Errors.find(f.first), std::string::npos) << observer->Errors;
    for (vtkUnstructuredGrid* output : { reader->GetOutput(), reader->GetVoxelGridOutput() })
    {
      EXPECT_EQ(output->GetNumberOfPoints(), 0);
      EXPECT_EQ(output->GetNumberOfCells(), 0);
      EXPECT_EQ(output->GetFieldData()->GetNumberOfArrays(), 0);
    }
  }
  for (size_t f = 4; f < files.size(); ++f)
  {
    std::remove(files[f].second.c_str());
  }
}

TEST(vtkFFDVDB, EveryFlippedByteOrCutIsAnErrorOrTheSameLattice)
{
  // OpenVDB trusts the sizes in a file: one flipped byte aborted the process, a cut to 4,096 bytes allocated until
  // the OOM killer came. Now every byte of OpenVDB's part flipped is the checksum's error, before OpenVDB parses
  // it; a flip in the trailer's mark leaves an intact file of another tool; a cut is an error unless it cuts only
  // the trailer. Never a crash, an unbounded allocation or other data without an error.
  vtkSmartPointer<vtkPolyData> bear = ReadTestMesh("bear");
  vtkSmartPointer<vtkFFDVoxelize> voxelize = VoxelizedBear(bear, 6);
  vtkSmartPointer<vtkUnstructuredGrid> lattice = SparseLattice(voxelize, vtkFFDBuildLattice::CUBIC_BSPLINE);
  std::mt19937 rng(20251129);
  ffdtest::Perturb(lattice, rng, 0.01);
  TempFile good("sweep_good.vdb"), damaged("sweep_damaged.vdb");
  ASSERT_EQ(Write(lattice, good.Path), 1);
  const std::string bytes = FileBytes(good.Path);
  const size_t size = bytes.size(), payload = size - 24; // the trailer: length, checksum, mark (8 bytes each)
  ASSERT_GT(payload, 4096u + 1024u) << "a file long enough to cut at 4,096 bytes inside its grids";
  EXPECT_EQ(bytes.substr(payload + 16), "VoxFFDv1");

  std::vector<size_t> flips; // the header, the trailer and fixed-seed random positions
  for (size_t b = 0; b < 128; ++b)
  {
    flips.push_back(b);
  }
  for (size_t b = payload; b < size; ++b)
  {
    flips.push_back(b);
  }
  std::uniform_int_distribution<size_t> anywhere(0, size - 1);
  for (int n = 0; n < 160; ++n)
  {
    flips.push_back(anywhere(rng));
  }
  std::uniform_int_distribution<int> mask(1, 255);
  for (size_t at : flips)
  {
    std::string changed = bytes;
    changed[at] = char(changed[at] ^ mask(rng));
    WriteBytes(damaged.Path, changed);
    const Outcome outcome = ReadInChild(damaged.Path, lattice, voxelize->GetOutput());
    EXPECT_EQ(outcome, at < size - 8 ? Damaged : Identical) << "byte " << at << " of " << size << " flipped";
  }

  std::vector<size_t> cuts = { 0, 1, 7, 8, 57, 100, 4096, payload - 1, payload, payload + 1, size - 1 };
  for (int n = 0; n < 40; ++n)
  {
    cuts.push_back(anywhere(rng));
  }
  for (size_t length : cuts)
  {
    WriteBytes(damaged.Path, bytes.substr(0, length));
    const Outcome outcome = ReadInChild(damaged.Path, lattice, voxelize->GetOutput());
    EXPECT_EQ(outcome, length < payload ? Refused : Identical) << "cut to " << length << " of " << size << " bytes";
  }

  // The same grids written by OpenVDB itself, without the checksum, as another tool writes them: every read stays
  // within the file, so each cut is an error too.
  TempFile foreign("sweep_foreign.vdb");
  Rewrite(good.Path, foreign.Path, [](openvdb::GridPtrVec&) {});
  const std::string theirs = FileBytes(foreign.Path);
  for (size_t length : cuts)
  {
    length = std::min(length, theirs.size());
    WriteBytes(damaged.Path, theirs.substr(0, length));
    const Outcome outcome = ReadInChild(damaged.Path, lattice, voxelize->GetOutput());
    EXPECT_EQ(outcome, length < theirs.size() ? Refused : Identical)
      << "OpenVDB's file cut to " << length << " of " << theirs.size() << " bytes";
  }
}

TEST(vtkFFDVDB, AFailedWriteLeavesTheFileAsItWasAndNoTemporaryFile)
{
  // The writer truncated its file in place: a write that failed part-way (a full disk, here a file size limit)
  // left a 4,096-byte file and Write() returned 1. Now it writes a temporary file and renames it over the target.
  vtkSmartPointer<vtkPolyData> bear = ReadTestMesh("bear");
  vtkSmartPointer<vtkFFDVoxelize> voxelize = VoxelizedBear(bear, 8);
  vtkSmartPointer<vtkUnstructuredGrid> lattice = SparseLattice(voxelize, vtkFFDBuildLattice::CUBIC_BSPLINE);
  TempFolder folder("atomic");
  const std::string path = folder.Path + "/lattice.vdb";
  ASSERT_EQ(Write(lattice, path), 1);
  const std::string before = FileBytes(path);
  ASSERT_GT(before.size(), 8192u);
  std::mt19937 rng(5);
  ffdtest::Perturb(lattice, rng, 0.01); // another lattice, so that a write that went through would show

  // `hinder(true)` before the write, `hinder(false)` after it, where given.
  auto writeFailing = [&](const std::string& target, unsigned long code, const std::string& message,
                        const std::vector<std::string>& files = { "lattice.vdb" },
                        const std::function<void(bool)>& hinder = nullptr)
  {
    vtkNew<vtkFFDVDBWriter> writer;
    vtkNew<FFDTestErrorObserver> observer;
    observer->WatchWithExecutive(writer);
    writer->SetInputData(lattice);
    writer->SetFileName(target.c_str());
    if (hinder)
    {
      hinder(true);
    }
    const int written = writer->Write();
    if (hinder)
    {
      hinder(false);
    }
    EXPECT_EQ(written, 0);
    EXPECT_EQ(writer->GetErrorCode(), code) << vtkErrorCode::GetStringFromErrorCode(writer->GetErrorCode());
    EXPECT_NE(observer->Errors.find(message), std::string::npos) << observer->Errors;
    const std::string after = FileBytes(path);
    EXPECT_TRUE(after == before) << "the file changed: " << after.size() << " bytes, " << before.size() << " before";
    EXPECT_EQ(folder.Files(), files);
  };
  {
    SCOPED_TRACE("a file size limit of 4,096 bytes: the write fails part-way, as on a full disk");
    rlimit old;
    ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &old), 0);
    void (*handler)(int) = nullptr;
    auto limit = [&](bool on) // the test's own output goes to files too: limited only during the write
    {
      const rlimit small = { 4096, old.rlim_max };
      setrlimit(RLIMIT_FSIZE, on ? &small : &old);
      handler = std::signal(SIGXFSZ, on ? SIG_IGN : handler); // a failed write, not a killed process
    };
    writeFailing(path, vtkErrorCode::OutOfDiskSpaceError, "writing it failed (File too large); the file is left",
      { "lattice.vdb" }, limit);
  }
  {
    SCOPED_TRACE("the target is a folder: the rename fails");
    std::filesystem::create_directory(folder.Path + "/sub.vdb");
    writeFailing(folder.Path + "/sub.vdb", vtkErrorCode::UnknownError,
      "renaming it over the file failed (Is a directory)", { "lattice.vdb", "sub.vdb" });
    std::filesystem::remove(folder.Path + "/sub.vdb");
  }
  {
    SCOPED_TRACE("a read-only folder: no temporary file can be made");
    std::filesystem::permissions(folder.Path, std::filesystem::perms::owner_read | std::filesystem::perms::owner_exec);
    if (std::ofstream(folder.Path + "/probe"))
    {
      std::filesystem::remove(folder.Path + "/probe"); // root writes anyway
    }
    else
    {
      writeFailing(path, vtkErrorCode::CannotOpenFileError, "check that its folder exists and is writable");
    }
    std::filesystem::permissions(folder.Path, std::filesystem::perms::owner_all);
  }
  // The same write, unhindered, replaces the file, with the permissions it had.
  std::filesystem::permissions(path,
    std::filesystem::perms::owner_read | std::filesystem::perms::owner_write | std::filesystem::perms::group_read);
  ASSERT_EQ(Write(lattice, path), 1);
  EXPECT_EQ(folder.Files(), std::vector<std::string>{ "lattice.vdb" });
  EXPECT_EQ(std::filesystem::status(path).permissions() & std::filesystem::perms::all,
    std::filesystem::perms::owner_read | std::filesystem::perms::owner_write | std::filesystem::perms::group_read);
  vtkNew<vtkFFDVDBReader> reader;
  vtkNew<FFDTestErrorObserver> observer;
  ASSERT_EQ(Read(reader, path, observer), 1) << observer->Errors;
  EXPECT_TRUE(SameGrid(reader->GetOutput(), lattice));

  // Through a symbolic link: the file it names is replaced, the link stays.
  const std::string link = folder.Path + "/link.vdb";
  std::filesystem::create_symlink("lattice.vdb", link);
  ffdtest::Perturb(lattice, rng, 0.01);
  ASSERT_EQ(Write(lattice, link), 1);
  EXPECT_TRUE(std::filesystem::is_symlink(link));
  EXPECT_EQ(folder.Files(), (std::vector<std::string>{ "lattice.vdb", "link.vdb" }));
  vtkNew<vtkFFDVDBReader> again;
  ASSERT_EQ(Read(again, path, observer), 1) << observer->Errors;
  EXPECT_TRUE(SameGrid(again->GetOutput(), lattice));
}

TEST(vtkFFDVDB, FileSizeAndTimesOfTheBear)
{
  // Printed for the record (docs/interchange-and-files.md, ".vdb files"); the bounds only catch a file or a time out of
  // proportion.
  vtkSmartPointer<vtkPolyData> bear = ReadTestMesh("bear");
  std::mt19937 rng(512);
  for (int n : { 12, 256 })
  {
    vtkSmartPointer<vtkFFDVoxelize> voxelize = VoxelizedBear(bear, n);
    vtkSmartPointer<vtkUnstructuredGrid> lattice = SparseLattice(voxelize, vtkFFDBuildLattice::CUBIC_BSPLINE);
    ffdtest::Perturb(lattice, rng, 1e-3);
    TempFile file("size.vdb");
    const auto start = std::chrono::steady_clock::now();
    ASSERT_EQ(Write(lattice, file.Path), 1);
    const auto written = std::chrono::steady_clock::now();
    vtkNew<vtkFFDVDBReader> reader;
    vtkNew<FFDTestErrorObserver> observer;
    ASSERT_EQ(Read(reader, file.Path, observer), 1) << observer->Errors;
    const auto read = std::chrono::steady_clock::now();
    const double bytes = double(std::filesystem::file_size(file.Path));
    const double points = double(lattice->GetNumberOfPoints()), voxels = double(lattice->GetNumberOfCells());
    std::cout << "bear, CubicBSpline at " << n << "^3: " << voxels << " voxels, " << points << " control points, "
              << bytes / 1e6 << " MB (" << bytes / points << " bytes a control point), write "
              << std::chrono::duration<double>(written - start).count() << " s, read "
              << std::chrono::duration<double>(read - written).count() << " s\n";
    // Two vectors of doubles a control point (48 bytes), a few bits a voxel and 8^3-voxel leaves' headers.
    EXPECT_LT(bytes, 64.0 * points + 100000.0);
    EXPECT_LT(std::chrono::duration<double>(read - start).count(), 5.0);
  }
}
