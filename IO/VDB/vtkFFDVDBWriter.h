// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkFFDVDBWriter
 * @brief   writes a sparse lattice into an OpenVDB file (.vdb) that Blender, Houdini and OpenVDB's tools open
 *
 * The input is a sparse lattice of a local basis (vtkFFDBuildLattice's SPARSE form, docs/pipeline-and-data-contract.md,
 * "Data contract"), its points moved or not. The file holds three grids, each with the frame and divisions as grid
 * metadata (`ffd_frame_origin`, `ffd_frame_s`, `ffd_frame_t`, `ffd_frame_u`: Vec3d; `ffd_divisions`: Vec3i), the
 * lattice's two also with the basis (`ffd_basis`: a string, GetBasisAsString()'s name):
 * - `active_voxels`, a BoolGrid, true and active at each cell's `VoxelIndex` (i, j, k); its transform puts voxel
 *   (i, j, k)'s centre, X0 + ((i + 1/2)/nx) S + ((j + 1/2)/ny) T + ((k + 1/2)/nz) U, at index (i, j, k), so that a
 *   voxel drawn as OpenVDB draws voxels is the lattice's voxel. A bool grid rather than a mask grid: Houdini's VDB
 *   primitives hold bool grids but no mask grids, and Blender reads both.
 * - `displacement`, a Vec3DGrid of each control point's point - `RestPosition`, active at its `LatticeIndex`; its
 *   transform puts index (i, j, k) at the control point's rest position (the rest parameters are linear in the
 *   index for every local basis). World-space vectors (VEC_CONTRAVARIANT_RELATIVE).
 * - `position`, a Vec3DGrid of the points themselves, same topology and transform: RestPosition + displacement
 *   does not always round back to the point, and vtkFFDVDBReader gives the lattice back bit for bit from it.
 *   World-space points (VEC_CONTRAVARIANT_ABSOLUTE).
 *
 * The file holds the voxels and the control points, not the cells: vtkFFDVDBReader rebuilds the lattice as
 * vtkFFDBuildLattice does. The input must therefore be a lattice that vtkFFDBuildLattice makes, its points moved
 * but none added, removed or reordered: its points the union of its cells' voxels' supports in increasing lattice
 * order, each with the `RestPosition` of its `LatticeIndex` under the frame. Anything else is an error that says
 * what differs, as are a dense lattice (vtkStructuredGrid: use vtkFFDBuildLattice::SetLatticeFormToSparse()), the
 * global BERNSTEIN basis (no sparse form), missing or malformed contract arrays, two cells of one voxel, no
 * FileName, and a file OpenVDB cannot write (its exception is caught and reported). Write() then returns 0, with
 * GetErrorCode() set.
 *
 * The file is written whole to a temporary file beside FileName, every write, the flush and the close checked,
 * and only then renamed over FileName (keeping an existing file's permissions): a write that fails part-way (a
 * full disk, a quota, a read-only folder) is an error that leaves the file at FileName as it was and no temporary
 * file behind. After OpenVDB's bytes comes a checksum of them (docs/interchange-and-files.md, ".vdb files"), which
 * vtkFFDVDBReader checks before parsing and other tools never read.
 *
 * @sa vtkFFDVDBReader vtkFFDBuildLattice
 */
#ifndef vtkFFDVDBWriter_h
#define vtkFFDVDBWriter_h

#include "vtkFFDIOVDBModule.h" // For export macro
#include "vtkWriter.h"

#include <string> // For WriteFileAtomically

class vtkDataObject;

class VTKFFDIOVDB_EXPORT vtkFFDVDBWriter : public vtkWriter
{
public:
  static vtkFFDVDBWriter* New();
  vtkTypeMacro(vtkFFDVDBWriter, vtkWriter);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// The .vdb file to write.
  vtkSetStringMacro(FileName);
  vtkGetStringMacro(FileName);
  ///@}

protected:
  vtkFFDVDBWriter();
  ~vtkFFDVDBWriter() override;

  /// Any vtkDataSet, so that a dense lattice gets an error that says how to make a sparse one.
  int FillInputPortInformation(int port, vtkInformation* info) override;
  void WriteData() override;

  char* FileName;

private:
  /// WriteData() without its exceptions: false, with the error reported, when nothing was written.
  bool WriteLattice(vtkDataObject* input);
  /// Writes `bytes` to FileName through a temporary file renamed over it: false, with the error and its code set,
  /// where any step fails, the temporary file then removed.
  bool WriteFileAtomically(const std::string& bytes);

  vtkFFDVDBWriter(const vtkFFDVDBWriter&) = delete;
  void operator=(const vtkFFDVDBWriter&) = delete;
};

#endif
