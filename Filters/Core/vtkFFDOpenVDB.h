// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file vtkFFDOpenVDB.h
 * @brief What the Filters module's translation units that include OpenVDB share (private to the module).
 *
 * OpenVDB's headers cost ~12 s per translation unit, so only vtkFFDSparseLattice.cxx (the sparse sets),
 * vtkFFDVDBWriter.cxx and vtkFFDVDBReader.cxx (the .vdb files) include them, through this header: the sorted
 * active coordinates of a tree, and the layout of the .vdb files (docs/interchange-and-files.md, ".vdb files") with
 * their checksum trailer, named once for the writer and the reader.
 */
#ifndef vtkFFDOpenVDB_h
#define vtkFFDOpenVDB_h

#include "vtkFFDFlatIndex.h"
#include "vtkSMPTools.h"
#include "vtkType.h"

#include <openvdb/openvdb.h>

#include <algorithm>
#include <string>
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
          *out++ = vtkFFDFlatIndex(x.x(), x.y(), x.z(), dims);
        }
      }
    });
  vtkSMPTools::Sort(indices.begin(), indices.end());
  return indices;
}

/// The grids and metadata of a VoxelFFD .vdb file (docs/interchange-and-files.md, ".vdb files").
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

/**
 * The trailer vtkFFDVDBWriter appends to OpenVDB's bytes (the payload): the payload's length and its FNV-1a
 * 64-bit hash, both little-endian, then TrailerMark. OpenVDB's readers stop after the last grid, so other tools
 * never see it. OpenVDB trusts every size in a file, so vtkFFDVDBReader checks the hash before OpenVDB parses a
 * byte: any one changed byte changes FNV-1a (each step is a bijection of the hash), so damage cannot pass.
 */
constexpr char TrailerMark[8] = { 'V', 'o', 'x', 'F', 'F', 'D', 'v', '1' };
constexpr size_t TrailerSize = 24;

inline vtkTypeUInt64 Checksum(const char* bytes, size_t count)
{
  vtkTypeUInt64 hash = 14695981039346656037ull;
  for (size_t b = 0; b < count; ++b)
  {
    hash = (hash ^ static_cast<unsigned char>(bytes[b])) * 1099511628211ull;
  }
  return hash;
}

/// The trailer of `count` payload bytes.
inline std::string Trailer(const char* payload, size_t count)
{
  const vtkTypeUInt64 words[2] = { count, Checksum(payload, count) };
  std::string trailer(TrailerSize, '\0');
  for (int w = 0; w < 2; ++w)
  {
    for (int b = 0; b < 8; ++b)
    {
      trailer[8 * w + b] = char((words[w] >> (8 * b)) & 0xff);
    }
  }
  std::copy(TrailerMark, TrailerMark + 8, trailer.begin() + 16);
  return trailer;
}

enum class TrailerStatus
{
  None,   ///< no trailer: a file that another tool wrote or edited
  Valid,  ///< the payload is what vtkFFDVDBWriter wrote
  Damaged ///< a trailer whose length or hash the payload does not match
};

/// What the trailer of `bytes` says; `payload` is the length of OpenVDB's bytes before it (all where None).
inline TrailerStatus CheckTrailer(const char* bytes, size_t count, size_t& payload)
{
  payload = count;
  if (count < TrailerSize || !std::equal(TrailerMark, TrailerMark + 8, bytes + count - 8))
  {
    return TrailerStatus::None;
  }
  vtkTypeUInt64 words[2] = { 0, 0 };
  for (int w = 0; w < 2; ++w)
  {
    for (int b = 0; b < 8; ++b)
    {
      words[w] |= vtkTypeUInt64(static_cast<unsigned char>(bytes[count - TrailerSize + 8 * w + b])) << (8 * b);
    }
  }
  payload = count - TrailerSize;
  return words[0] == payload && words[1] == Checksum(bytes, payload) ? TrailerStatus::Valid : TrailerStatus::Damaged;
}
} // namespace vtkFFDVDB

#endif
