// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkFFDVDBReader
 * @brief   reads a sparse lattice and its voxel grid from an OpenVDB file (.vdb) that vtkFFDVDBWriter wrote
 *
 * A source with two outputs, both vtkUnstructuredGrids of the data contract
 * (docs/pipeline-and-data-contract.md, "Data contract"):
 * - port 0, the sparse lattice: the lattice vtkFFDBuildLattice builds over the file's active voxels, with its
 *   points where the file puts them. A lattice written from vtkFFDBuildLattice's sparse output comes back
 *   identical: points and `RestPosition` bit for bit, `Active`, `LatticeIndex`, the cells with their types, point
 *   order and `VoxelIndex`, `FFDFrame`, `FFDDivisions` and `FFDBasis`, in the same point and cell order (cells in
 *   increasing voxel order, as vtkFFDVoxelize gives the voxels).
 * - port 1, the voxel grid of those voxels, exactly as vtkFFDVoxelize makes it.
 *
 * The file's grids and metadata are vtkFFDVDBWriter's (docs/interchange-and-files.md, ".vdb files"); the metadata, not
 * the grids' transforms, gives the frame, divisions and basis. The `displacement` grid is the deformation: a control
 * point is at the `position` grid's value where that value minus its rest position is the displacement, bit for bit,
 * as the writer leaves it, and at its rest position plus the displacement where another tool changed the
 * displacement.
 *
 * The file is read whole into memory (its size checked first against the memory the system can give) and
 * parsed by OpenVDB from there, so that no read goes past its end. OpenVDB trusts the sizes in a file, so the
 * checksum that vtkFFDVDBWriter appends (docs/interchange-and-files.md, ".vdb files") is checked before OpenVDB parses
 * a byte: a file it wrote that was changed or cut since is an error, never a crash or other data. A file without the
 * checksum (another tool's) is parsed as it is: one cut short is an error; damage inside it is OpenVDB's to find. Both
 * outputs cost memory in proportion to the active voxels and control points, checked before they are made.
 * Errors (reported with vtkErrorMacro, both outputs then empty): no FileName; a file that is missing, unreadable,
 * damaged, cut short or not a .vdb file (OpenVDB's exceptions are caught and reported); a missing grid or one of
 * another type; missing or malformed metadata, or grids that disagree on it; a flat or non-finite frame,
 * divisions below one, an unknown basis or the global BERNSTEIN one; an active voxel outside the divisions; a
 * control point of the voxels' supports without a displacement or position, or one where the lattice has no
 * control point.
 *
 * @sa vtkFFDVDBWriter vtkFFDBuildLattice vtkFFDVoxelize
 */
#ifndef vtkFFDVDBReader_h
#define vtkFFDVDBReader_h

#include "vtkFFDIOVDBModule.h" // For export macro
#include "vtkUnstructuredGridAlgorithm.h"

class VTKFFDIOVDB_EXPORT vtkFFDVDBReader : public vtkUnstructuredGridAlgorithm
{
public:
  static vtkFFDVDBReader* New();
  vtkTypeMacro(vtkFFDVDBReader, vtkUnstructuredGridAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// The .vdb file to read.
  vtkSetStringMacro(FileName);
  vtkGetStringMacro(FileName);
  ///@}

  /// The voxel grid (output port 1); GetOutput() is the lattice (port 0).
  vtkUnstructuredGrid* GetVoxelGridOutput() { return this->GetOutput(1); }

protected:
  vtkFFDVDBReader();
  ~vtkFFDVDBReader() override;

  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  /// An allocation that fails becomes an error and empty outputs, never an exception out of Update().
  vtkTypeBool ProcessRequest(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  char* FileName;

private:
  /// RequestData() without OpenVDB's exceptions: false, with the error reported, on failure.
  bool ReadFile(vtkUnstructuredGrid* lattice, vtkUnstructuredGrid* voxelGrid);

  vtkFFDVDBReader(const vtkFFDVDBReader&) = delete;
  void operator=(const vtkFFDVDBReader&) = delete;
};

#endif
