// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkFFDLatticeActor
 * @brief   draws a free-form deformation lattice: control points as spheres, grid lines between neighbours
 *
 * A vtkAssembly of two parts that show a control lattice (the vtkStructuredGrid from vtkFFDBuildLattice, as
 * it is or deformed by moving its points):
 * - the control points, as sphere glyphs (vtkGlyph3DMapper over a vtkSphereSource), red by default;
 * - the lattice edges, the grid lines between neighbouring control points (vtkExtractEdges), dark grey lines
 *   of width 2 by default.
 *
 * Both parts read the lattice through their own pipelines, so the actor follows the lattice: moving its
 * points (and marking them modified) or re-executing the upstream filter shows at the next render.
 *
 * The sphere radius is PointRadius, or, when PointRadius is 0 (the default), a fixed fraction of the diagonal
 * of the current lattice's bounds, computed whenever the actor is rendered or asked for its bounds, so that
 * the spheres keep their size relative to the lattice as it deforms.
 *
 * The input may be any vtkDataSet whose cells join neighbouring control points (a structured grid of
 * control points gives the grid lines). Colouring by the `Active` array and showing active voxels are not done
 * here yet; the point and edge parts take no colours from the input's scalars.
 *
 * @sa vtkFFDBuildLattice vtkFFDDeform vtkAssembly vtkGlyph3DMapper vtkExtractEdges
 */
#ifndef vtkFFDLatticeActor_h
#define vtkFFDLatticeActor_h

#include "vtkAssembly.h"
#include "vtkFFDRenderingModule.h" // For export macro

#include <memory> // For std::unique_ptr

class vtkAlgorithmOutput;
class vtkDataSet;
class vtkProperty;

class VTKFFDRENDERING_EXPORT vtkFFDLatticeActor : public vtkAssembly
{
public:
  static vtkFFDLatticeActor* New();
  vtkTypeMacro(vtkFFDLatticeActor, vtkAssembly);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// The lattice to draw: a pipeline connection (e.g. vtkFFDBuildLattice's output) or a data set.
  void SetInputConnection(vtkAlgorithmOutput* output);
  void SetInputData(vtkDataSet* lattice);
  ///@}

  ///@{
  /// Properties of the control-point spheres (default red) and of the lattice edges (default dark grey,
  /// line width 2).
  vtkProperty* GetPointProperty();
  vtkProperty* GetEdgeProperty();
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
  /// Bring the point radius up to date with the input before drawing or reporting bounds.
  int RenderOpaqueGeometry(vtkViewport* viewport) override;
  double* GetBounds() VTK_SIZEHINT(6) override;
  using vtkAssembly::GetBounds;
  ///@}

protected:
  vtkFFDLatticeActor();
  ~vtkFFDLatticeActor() override;

  /// Sets the sphere radius from PointRadius or the current input's bounds.
  void UpdatePointRadius();

  /// Puts the parts in the assembly when there is an input, takes them out when there is none.
  void ShowParts(bool hasInput);

  double PointRadius;

private:
  vtkFFDLatticeActor(const vtkFFDLatticeActor&) = delete;
  void operator=(const vtkFFDLatticeActor&) = delete;

  struct vtkInternals;
  std::unique_ptr<vtkInternals> Internals;
};

#endif
