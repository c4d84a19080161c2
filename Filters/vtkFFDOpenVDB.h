// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file vtkFFDOpenVDB.h
 * @brief What the Filters module's translation units that include OpenVDB share (private to the module).
 *
 * OpenVDB's headers cost ~12 s per translation unit, so only vtkFFDSparseLattice.cxx (the sparse sets),
 * vtkFFDVDBWriter.cxx and vtkFFDVDBReader.cxx (the .vdb files) include them, through this header: the sorted
 * active coordinates of a tree, and the layout of the .vdb files (README, ".vdb files"), named once for the writer
 * and the reader.
 */
#ifndef vtkFFDOpenVDB_h
#define vtkFFDOpenVDB_h

#include "vtkSMPTools.h"
#include "vtkType.h"

#include <openvdb/openvdb.h>

#include <vector>

/**
 * The active voxels of `tree` as linear indices i + dims[0] (j + dims[1] k), in increasing order. The tree must
 * hold them in its leaves, without active tiles (Tree::voxelizeActiveTiles() makes it so), each coordinate within
 * [0, dims). Each leaf writes its own range of the result, in parallel, before the sort.
 */
template <typename TreeT>
std::vector<vtkTypeInt64> vtkFFDSortedIndices(const TreeT& tree, const vtkTypeInt64 dims[3])
{
  using LeafT = typename TreeT::LeafNodeType;
  std::vector<const LeafT*> leaves;
  leaves.reserve(tree.leafCount());
  tree.getNodes(leaves);
  std::vector<vtkIdType> start(leaves.size() + 1, 0);
  for (size_t l = 0; l < leaves.size(); ++l)
  {
    start[l + 1] = start[l] + vtkIdType(leaves[l]->onVoxelCount());
  }
  std::vector<vtkTypeInt64> indices(start.back());
  vtkSMPTools::For(0, vtkIdType(leaves.size()),
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType l = begin; l < end; ++l)
      {
        vtkTypeInt64* out = indices.data() + start[l];
        for (auto it = leaves[l]->cbeginValueOn(); it; ++it)
        {
          const openvdb::Coord x = it.getCoord();
          *out++ = x.x() + dims[0] * (x.y() + dims[1] * vtkTypeInt64(x.z()));
        }
      }
    });
  vtkSMPTools::Sort(indices.begin(), indices.end());
  return indices;
}

/// The grids and metadata of a VoxelFFD .vdb file (README, ".vdb files").
namespace vtkFFDVDB
{
/// The active voxels: a BoolGrid, true and active at voxel (i, j, k), whose index space puts (i, j, k) at the
/// voxel's centre.
constexpr const char* ActiveVoxelsGrid = "active_voxels";
/// The control points' displacements (point - RestPosition): a Vec3DGrid, active at each control point's
/// LatticeIndex (i, j, k), whose index space puts (i, j, k) at the control point's rest position.
constexpr const char* DisplacementGrid = "displacement";
/// The control points' positions, bit for bit: a Vec3DGrid of the same topology and transform.
constexpr const char* PositionGrid = "position";

/// Grid metadata of every grid: the frame (Vec3d each) and the divisions (Vec3i).
constexpr const char* FrameOrigin = "ffd_frame_origin";
constexpr const char* FrameS = "ffd_frame_s";
constexpr const char* FrameT = "ffd_frame_t";
constexpr const char* FrameU = "ffd_frame_u";
constexpr const char* Divisions = "ffd_divisions";
/// Grid metadata of the lattice's grids: the basis, as vtkFFDBuildLattice::GetBasisAsString() names it (string).
constexpr const char* Basis = "ffd_basis";
} // namespace vtkFFDVDB

#endif
