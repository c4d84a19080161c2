// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkFFDSparseCells
 * @brief   a sparse lattice's cells, read and checked: each one's voxel and support, and the cell of a voxel
 *
 * Private to the Filters module (not wrapped). A sparse lattice (docs/pipeline-and-data-contract.md, "Data contract")
 * is a vtkUnstructuredGrid of control points with their `LatticeIndex` and a cell per active voxel with its
 * `VoxelIndex`. Read() turns its cells into what ffd::GridDeformation evaluates: the cells ordered by their
 * voxel's flat index i + nx (j + ny k) (the order of the dense lattice's cells, so that both deform bit for bit
 * alike), each with its voxel's indices and the point ids of its support in support order (i fastest), each point
 * placed by its `LatticeIndex`, whatever its place in the cell. The cells are read again only when the lattice's
 * cells or indices change, not when its points move. Where the lattice's connectivity already is that (the cells of
 * vtkFFDBuildLattice's CUBIC_BSPLINE lattice: 32-bit ids, in voxel order, each in support order), the supports are
 * that array itself, held, not a copy of it (4 bytes per id: 100 MB at 1024^3 voxels).
 */
#ifndef vtkFFDSparseCells_h
#define vtkFFDSparseCells_h

#include "vtkDataArray.h"
#include "vtkFFDSortedKeys.h"
#include "vtkSmartPointer.h"
#include "vtkType.h"

#include "FFDGridBasis.h"

#include <cstdint>
#include <string>
#include <vector>

class vtkUnstructuredGrid;

class vtkFFDSparseCells
{
public:
  /**
   * Reads the cells of `lattice`, a sparse lattice of a local `basis` over `divisions` voxels, unless they are
   * those of the last Read(). Returns an empty string, or what is wrong with the lattice.
   */
  std::string Read(vtkUnstructuredGrid* lattice, ffd::GridBasis basis, const int divisions[3]);

  /// The cells: their number, each one's voxel (3 ints) and support (SupportCount()^3 point ids).
  int GetNumberOfCells() const { return static_cast<int>(this->Keys.GetSize()); }
  const std::vector<int>& GetVoxels() const { return this->Voxels; }
  const int* GetSupports() const { return this->Supports; }

  /// The cell of the voxel whose flat index is `key` (i + nx (j + ny k)), or -1 where the lattice has none.
  int Find(std::int64_t key) const;

  /// A hash of the cells' voxels and supports: the same for the same cells (the binding's key).
  std::uint64_t GetFingerprint() const { return this->Fingerprint; }

private:
  vtkFFDSortedKeys<> Keys; // each cell's voxel's flat index, increasing
  std::vector<int> Voxels;
  const int* Supports = nullptr;              // SupportCount()^3 a cell: into one of the two below
  std::vector<int> SupportsCopy;              // where the lattice's connectivity is not them
  vtkSmartPointer<vtkDataArray> Connectivity; // where it is: the lattice's own, held
  std::uint64_t Fingerprint = 0;
  // What the cells were read from: the lattice's cells, indices and points, by identity and time.
  const void* Source[3] = { nullptr, nullptr, nullptr };
  vtkMTimeType SourceTime[3] = { 0, 0, 0 };
  vtkIdType SourcePoints = -1;
  ffd::GridBasis SourceBasis = ffd::GridBasis::Bernstein;
  int SourceDivisions[3] = { 0, 0, 0 };
};

#endif
