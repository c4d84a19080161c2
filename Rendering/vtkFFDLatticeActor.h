// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkFFDLatticeActor
 * @brief   draws a free-form deformation lattice: control points, lattice edges and active voxels
 *
 * A vtkAssembly of up to four parts that show a control lattice (vtkFFDBuildLattice's dense vtkStructuredGrid
 * or sparse vtkUnstructuredGrid, as it is or deformed by moving its points, or a vtkUnstructuredGrid of
 * tetrahedra with the same point arrays) and, optionally, the voxel grid it was built over:
 * - the active control points, as sphere glyphs, red by default (GetPointProperty()), or coloured by how far
 *   they have been moved from their `RestPosition` (ColorByDisplacement);
 * - the culled control points (`Active` 0: they influence no active voxel, paper section III.D), as light
 *   grey spheres of the same size (GetCulledPointProperty(); ShowCulledPoints off hides them);
 * - the lattice edges (vtkFFDCellEdges: grid lines of a dense lattice, the control net of a sparse one,
 *   tetrahedron edges of a tetrahedral one), dark grey lines of width 2 (GetEdgeProperty());
 * - the active voxels as wireframe boxes, when a voxel grid from vtkFFDVoxelize is set (SetVoxelGridData() or
 *   SetVoxelGridConnection()): its cells are the active voxels (hidden cells of another data set are not
 *   drawn); steel blue lines of width 1 by default (GetVoxelProperty()). The boxes stay where the voxel grid
 *   is: the rest frame;
 * - with ColorByFoldCertificate, the cells that the lattice's `FoldCertificate` cell array (vtkFFDFoldCertificate's
 *   output) marks folded, red lines of width 4 (GetFoldedCellProperty()), and undecided, orange
 *   (GetUndecidedCellProperty()): a dense lattice's cells' edges, a tetrahedral one's tetrahedra, a sparse one's
 *   cells as the control net of their supports.
 *
 * Every part reads its input through its own pipeline (vtkFFDControlPoints, vtkFFDCellEdges), so the actor
 * follows the lattice: moving its points (and marking them modified) or re-executing the upstream filter shows
 * at the next render.
 *
 * The sphere radius is PointRadius, or, when PointRadius is 0 (the default), a fixed fraction of the diagonal
 * of the current lattice's bounds, computed whenever the actor is rendered or asked for its bounds, so that
 * the spheres keep their size relative to the lattice as it deforms.
 *
 * A lattice without an `Active` array shows every control point as active; one without `RestPosition` has no
 * displacement to colour by (every point gets the colour of 0). Arrays of the wrong shape are reported by
 * vtkFFDControlPoints, and the point parts then show nothing.
 *
 * @sa vtkFFDBuildLattice vtkFFDVoxelize vtkFFDDeform vtkFFDControlPoints vtkFFDCellEdges
 * vtkFFDLatticeRepresentation vtkAssembly vtkGlyph3DMapper
 */
#ifndef vtkFFDLatticeActor_h
#define vtkFFDLatticeActor_h

#include "vtkAssembly.h"
#include "vtkFFDRenderingModule.h" // For export macro

#include <memory> // For std::unique_ptr

class vtkAlgorithmOutput;
class vtkDataSet;
class vtkLookupTable;
class vtkProperty;

class VTKFFDRENDERING_EXPORT vtkFFDLatticeActor : public vtkAssembly
{
public:
  static vtkFFDLatticeActor* New();
  vtkTypeMacro(vtkFFDLatticeActor, vtkAssembly);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// The lattice to draw: a pipeline connection (e.g. vtkFFDBuildLattice's output) or a data set (a
  /// vtkPointSet: structured or unstructured lattice). nullptr removes the lattice's parts.
  void SetInputConnection(vtkAlgorithmOutput* output);
  void SetInputData(vtkDataSet* lattice);
  ///@}

  ///@{
  /// The voxel grid whose active voxels are drawn as boxes (vtkFFDVoxelize's output); nullptr (the default)
  /// draws no voxels.
  void SetVoxelGridConnection(vtkAlgorithmOutput* output);
  void SetVoxelGridData(vtkDataSet* voxelGrid);
  ///@}

  ///@{
  /// Properties of the parts: active control points (default red), culled control points (default light
  /// grey), lattice edges (default dark grey, line width 2), voxel boxes (default steel blue, line width 1).
  vtkProperty* GetPointProperty();
  vtkProperty* GetCulledPointProperty();
  vtkProperty* GetEdgeProperty();
  vtkProperty* GetVoxelProperty();
  ///@}

  ///@{
  /// Whether the culled control points are drawn (default on).
  vtkSetMacro(ShowCulledPoints, bool);
  vtkGetMacro(ShowCulledPoints, bool);
  vtkBooleanMacro(ShowCulledPoints, bool);
  ///@}

  ///@{
  /// Whether the lattice edges are drawn (default on).
  vtkSetMacro(ShowEdges, bool);
  vtkGetMacro(ShowEdges, bool);
  vtkBooleanMacro(ShowEdges, bool);
  ///@}

  ///@{
  /**
   * Colour the active control points by their displacement length |point - RestPosition| through
   * GetDisplacementLookupTable() (blue for 0 to red) instead of the point property's colour (default off).
   * The colours span DisplacementRange; when its maximum is not above its minimum (the default, 0 0), they
   * span 0 to the largest displacement of the current lattice.
   */
  vtkSetMacro(ColorByDisplacement, bool);
  vtkGetMacro(ColorByDisplacement, bool);
  vtkBooleanMacro(ColorByDisplacement, bool);
  vtkSetVector2Macro(DisplacementRange, double);
  vtkGetVector2Macro(DisplacementRange, double);
  vtkLookupTable* GetDisplacementLookupTable();
  ///@}

  ///@{
  /**
   * Draw the cells that the lattice's `FoldCertificate` cell array marks folded (1) and undecided (2) over the
   * lattice edges (default off; nothing is drawn where the lattice has no such array). Connect the actor to
   * vtkFFDFoldCertificate's output.
   */
  vtkSetMacro(ColorByFoldCertificate, bool);
  vtkGetMacro(ColorByFoldCertificate, bool);
  vtkBooleanMacro(ColorByFoldCertificate, bool);
  vtkProperty* GetFoldedCellProperty();
  vtkProperty* GetUndecidedCellProperty();
  ///@}

  ///@{
  /// Radius of the control-point spheres in world units; 0 (the default) picks GetAutomaticRadiusFraction()
  /// times the diagonal of the lattice's bounds at render time.
  vtkSetClampMacro(PointRadius, double, 0.0, VTK_DOUBLE_MAX);
  vtkGetMacro(PointRadius, double);
  static double GetAutomaticRadiusFraction() { return 0.015; }
  ///@}

  /// Radius the spheres were last drawn with (the automatic one when PointRadius is 0).
  double GetRenderedPointRadius();

  ///@{
  /// Bring the parts up to date with the inputs and the settings before drawing or reporting bounds.
  int RenderOpaqueGeometry(vtkViewport* viewport) override;
  double* GetBounds() VTK_SIZEHINT(6) override;
  using vtkAssembly::GetBounds;
  ///@}

protected:
  vtkFFDLatticeActor();
  ~vtkFFDLatticeActor() override;

  /// Sets the sphere radius from PointRadius or the current input's bounds, the parts' visibility and the
  /// colouring from the settings.
  void UpdateParts();

  /// Shows the fold parts where ColorByFoldCertificate is on and the lattice has cells of their state.
  void UpdateFoldParts();

  /// Puts the lattice's parts in the assembly when there is an input, takes them out when there is none.
  void ShowLatticeParts(bool hasInput);

  double PointRadius = 0.0;
  bool ShowCulledPoints = true;
  bool ShowEdges = true;
  bool ColorByDisplacement = false;
  bool ColorByFoldCertificate = false;
  double DisplacementRange[2] = { 0.0, 0.0 };

private:
  vtkFFDLatticeActor(const vtkFFDLatticeActor&) = delete;
  void operator=(const vtkFFDLatticeActor&) = delete;

  struct vtkInternals;
  std::unique_ptr<vtkInternals> Internals;
};

#endif
