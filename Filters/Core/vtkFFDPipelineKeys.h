// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file vtkFFDPipelineKeys.h
 * @brief What the filters announce of a voxel grid or lattice in RequestInformation, before any data exists
 * (private to the Filters module).
 *
 * A dense lattice is a vtkStructuredGrid, whose consumers (vtkDataSetSurfaceFilter, vtkExtractEdges, ParaView's
 * representations) ask for pieces of its WHOLE_EXTENT: without one announced before execution, the executive
 * gives them an empty output. The lattice's extent follows its divisions and basis, which its data carries: so
 * vtkFFDVoxelize announces its divisions, vtkFFDBuildLattice, vtkFFDRefineLattice and vtkFFDCoarsenLattice the
 * divisions and basis of their output and, when it is dense, its WHOLE_EXTENT. The keys travel downstream through
 * any filter (ParaView puts one after every filter). Where nothing is announced (a voxel grid read from a file),
 * a dense lattice's extent is unknown until it executes, as before. A filter of two inputs announces the times of
 * both (AnnounceTimes()).
 */
#ifndef vtkFFDPipelineKeys_h
#define vtkFFDPipelineKeys_h

class vtkInformation;
class vtkInformationIntegerVectorKey;
class vtkInformationVector;

class vtkFFDPipelineKeys
{
public:
  /// The voxels per axis (3 ints) of the voxel grid or lattice that this output information describes.
  static vtkInformationIntegerVectorKey* DIVISIONS();
  /// The lattice's basis (1 int, vtkFFDBuildLattice::Bases).
  static vtkInformationIntegerVectorKey* BASIS();

  /// Announces a lattice of `basis` over `divisions` in `outInfo`, with the WHOLE_EXTENT of its control points
  /// where the output is a vtkStructuredGrid.
  static void AnnounceLattice(vtkInformation* outInfo, int basis, const int divisions[3]);
  /// Removes what `outInfo` holds of an announcement (copied from an input): the output's is unknown.
  static void Forget(vtkInformation* outInfo);
  /// The divisions and basis that `inInfo` announces, if it announces both.
  static bool AnnouncedLattice(vtkInformation* inInfo, int& basis, int divisions[3]);

  /**
   * Announces in `outInfo` the times of every connection of the first `ports` inputs (`inputs`, the filter's input
   * information vectors), as the executive does of input 0's alone: the union of their TIME_RANGEs, and of their
   * TIME_STEPS where each input that has a range has steps (else the output is continuous in time). A filter whose
   * other input varies in time (a lattice from vtkFFDSimulateLattice) then re-executes when the time changes; the
   * executive requests the time asked of the output from every input. Call it with what the executive's pass of
   * `request` returned (its REQUEST_INFORMATION passes input 0's times only), which it returns: a failed pass and
   * other requests are left alone.
   */
  static int AnnounceTimes(
    int done, vtkInformation* request, vtkInformationVector** inputs, int ports, vtkInformationVector* outputs);
};

#endif
