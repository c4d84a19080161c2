// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkFFDVoxelize
 * @brief   encloses a point set in a frame, divides it into voxels and finds the voxels that hold points
 *
 * The first stage of the voxel FFD pipeline (paper section III.D). The frame is the parallelepiped
 * X0 + sS + tT + uU, s, t, u in [0, 1]:
 * - AXIS_ALIGNED (default): the bounds of the input's finite points, each side grown by Padding times the
 *   largest extent of the bounds (so flat and linear inputs still get a frame with a volume);
 * - PRINCIPAL_AXES: a box along the eigenvectors of the points' covariance (S the major axis, right-handed),
 *   tight around the points, then padded the same way;
 * - EXPLICIT: the frame set with SetFrame() (which selects this mode), any parallelepiped.
 *
 * A voxel is active when at least one input point lies in it (points on a face shared by two voxels count for the
 * one with the higher index; points outside an explicit frame count for none). The output is sparse, a
 * vtkUnstructuredGrid of the active voxels only (docs/pipeline-and-data-contract.md, "Data contract"): one
 * VTK_HEXAHEDRON per active voxel, in increasing voxel order (i fastest, then j, then k), with its (i, j, k) in the
 * `VoxelIndex` cell array (3 ints); its points are the active voxels' corners, each once, in increasing corner order,
 * corner (i, j, k) at X0 + (i/nx) S + (j/ny) T + (k/nz) U in double precision. The frame and divisions are stored as
 * the `FFDFrame` and `FFDDivisions` field arrays (vtkFFDDataContract). Any VTK filter or ParaView draws it as it is.
 *
 * Memory and time follow the input's points and the active voxels, never nx*ny*nz, so divisions of 1024^3 and
 * beyond are cheap over a small mesh: the active voxels are found in parallel with OpenVDB (a MaskTree per thread,
 * merged by topology union), and their corners and the cells' point ids by sorting and binary search (the same
 * output whatever the number of threads). The output takes about 50 bytes an active voxel and 24 bytes a corner
 * (at most 8 corners a voxel, fewer where voxels touch); that, and the 8 bytes an index that sorting takes
 * meanwhile, is checked against the memory the system can give before it is allocated.
 *
 * A mesh split among processes (MPI: pvbatch, pvserver, or a script's vtkMPIController): when Controller has more
 * than one process, the frame's bounds and principal axes are computed over every process's points and the active
 * voxels are the union of every process's, so each process outputs the same voxel grid, bit for bit the one a
 * single process makes of the whole mesh (the principal axes' sums are exact, rounded once, so their order does
 * not matter). Every process must execute the filter then, an empty piece too.
 *
 * Non-finite input points are ignored. An empty input gives an empty output without an error. Divisions below
 * one or with more corners than an int64 counts, a flat or non-finite frame, or one whose volume overflows double
 * precision (a huge Padding) are errors, checked in RequestData too.
 *
 * @sa vtkFFDBuildLattice vtkFFDDeform vtkFFDDataContract
 */
#ifndef vtkFFDVoxelize_h
#define vtkFFDVoxelize_h

#include "vtkFFDFiltersCoreModule.h" // For export macro
#include "vtkUnstructuredGridAlgorithm.h"

class vtkDataArray;
class vtkMultiProcessController;

class VTKFFDFILTERSCORE_EXPORT vtkFFDVoxelize : public vtkUnstructuredGridAlgorithm
{
public:
  static vtkFFDVoxelize* New();
  vtkTypeMacro(vtkFFDVoxelize, vtkUnstructuredGridAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// Voxels along S, T and U. Each must be at least 1 (default 4, 4, 4).
  vtkSetVector3Macro(Divisions, int);
  vtkGetVector3Macro(Divisions, int);
  ///@}

  ///@{
  /// Fraction of the largest extent added on every side of automatic frames (default 0.05).
  vtkSetClampMacro(Padding, double, 0.0, VTK_DOUBLE_MAX);
  vtkGetMacro(Padding, double);
  ///@}

  enum FrameModes
  {
    AXIS_ALIGNED = 0,
    PRINCIPAL_AXES = 1,
    EXPLICIT = 2
  };

  ///@{
  /// How the frame is chosen (default AXIS_ALIGNED).
  vtkSetClampMacro(FrameMode, int, AXIS_ALIGNED, EXPLICIT);
  vtkGetMacro(FrameMode, int);
  void SetFrameModeToAxisAligned() { this->SetFrameMode(AXIS_ALIGNED); }
  void SetFrameModeToPrincipalAxes() { this->SetFrameMode(PRINCIPAL_AXES); }
  void SetFrameModeToExplicit() { this->SetFrameMode(EXPLICIT); }
  const char* GetFrameModeAsString();
  ///@}

  ///@{
  /**
   * The frame used in EXPLICIT mode: origin X0 and edge vectors S, T, U. SetFrame() also selects EXPLICIT mode;
   * the setters of its parts (SetFrameOrigin() ...) only store them, for a mode chosen apart.
   */
  void SetFrame(const double origin[3], const double s[3], const double t[3], const double u[3]);
  vtkSetVector3Macro(FrameOrigin, double);
  vtkGetVector3Macro(FrameOrigin, double);
  vtkSetVector3Macro(FrameS, double);
  vtkGetVector3Macro(FrameS, double);
  vtkSetVector3Macro(FrameT, double);
  vtkGetVector3Macro(FrameT, double);
  vtkSetVector3Macro(FrameU, double);
  vtkGetVector3Macro(FrameU, double);
  ///@}

  /// Number of active voxels found by the last execution.
  vtkGetMacro(NumberOfActiveVoxels, vtkIdType);

  ///@{
  /// The processes among which the mesh is split (default: vtkMultiProcessController::GetGlobalController(), which
  /// pvbatch and pvserver set, and a script sets with SetGlobalController()); null or one process: this one only.
  virtual void SetController(vtkMultiProcessController*);
  vtkGetObjectMacro(Controller, vtkMultiProcessController);
  ///@}

protected:
  vtkFFDVoxelize();
  ~vtkFFDVoxelize() override;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  /// An allocation that fails becomes an error and an empty output, never an exception out of Update().
  /// With several processes, asks for this process's piece of the mesh, whatever was asked of the output.
  int RequestUpdateExtent(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  vtkTypeBool ProcessRequest(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  int Divisions[3];
  double Padding;
  int FrameMode;
  double FrameOrigin[3];
  double FrameS[3];
  double FrameT[3];
  double FrameU[3];
  vtkIdType NumberOfActiveVoxels;
  vtkMultiProcessController* Controller;

private:
  /// Phase 1 of RequestData: the explicit frame, or the box around the input's finite points (over every
  /// process) along the frame mode's axes, padded. False, after an error, where no automatic frame exists.
  bool ComputeFrame(vtkDataArray* points, vtkMultiProcessController* controller, vtkIdType numPoints, double frame[12]);

  vtkFFDVoxelize(const vtkFFDVoxelize&) = delete;
  void operator=(const vtkFFDVoxelize&) = delete;
};

#endif
