// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkFFDLatticeBody
 * @brief   a lattice's active control points as the particles, masses and springs of an ffd::SoftBody
 *
 * Private to the Filters module (not wrapped): what vtkFFDLatticeDynamics simulates, read from a lattice of
 * vtkFFDBuildLattice (dense or sparse) or vtkFFDBuildTetrahedralLattice through vtkFFDDeform's own readers, and
 * from the mesh whose points share the mass (docs/dynamics.md):
 * - particles: the control points whose `Active` is not 0 (all where the lattice has no `Active`);
 * - springs: between particles one lattice step apart along an axis, a voxel face's diagonal or its body's
 *   (the first 3, 9 or 13 of the 13 half-neighbourhood offsets), found on a dense lattice's grid, within a sparse
 *   lattice's cells' supports, or along a tetrahedral lattice's edges; each once;
 * - masses: the total mass shared in proportion to each particle's sum of weights over the mesh's points bound to
 *   the lattice (ffd::GridDeformation::ForEachWeight, or a tetrahedron's barycentric weights), none below a
 *   fraction of the mean; the same for all without a mesh.
 */
#ifndef vtkFFDLatticeBody_h
#define vtkFFDLatticeBody_h

#include "vtkType.h"

#include <array>
#include <string>
#include <vector>

class vtkPointSet;

struct vtkFFDLatticeBody
{
  std::vector<vtkIdType> PointOf;          ///< per particle: its lattice point
  std::vector<int> ParticleOf;             ///< per lattice point: its particle, -1 where not simulated
  std::vector<double> RestPositions;       ///< 3 per particle: its `RestPosition`
  std::vector<double> Masses;              ///< per particle
  std::vector<std::array<int, 2>> Springs; ///< pairs of particles

  /**
   * Reads `lattice` and, where not null, the mesh. `neighborhood` is vtkFFDLatticeDynamics's SpringNeighborhood
   * (0 edges, 1 and face diagonals, 2 and body diagonals). Returns an empty string, or what is wrong.
   */
  std::string Read(
    vtkPointSet* lattice, vtkPointSet* mesh, int neighborhood, double totalMass, double minimumMassFraction);
};

#endif
