// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkFFDControlPoints
 * @brief   the control points of a lattice as vertices, active or culled ones, with their displacement length
 *
 * Turns a control lattice (any vtkPointSet: vtkFFDBuildLattice's dense or sparse form, or a vtkUnstructuredGrid
 * of tetrahedra that keeps the same point arrays) into a vtkPolyData of vertices, one per selected control
 * point, for glyphing and picking:
 * - SelectionToActive() keeps the points whose `Active` value is not 0, SelectionToCulled() those whose value
 *   is 0, SelectionToAll() every point. A lattice without an `Active` array counts every point as active.
 * - The output's point data holds `LatticePointId` (vtkIdType: the point's id in the lattice, so that a pick
 *   on the output can move the lattice's point) and `DisplacementLength` (double, the active scalars:
 *   |point - RestPosition|, the distance the control point has been dragged). A lattice without a
 *   `RestPosition` array has displacements 0.
 *
 * The lattice's ghost array is not passed: culled points carry HIDDENPOINT, which would hide them from the
 * very glyphs that are meant to show them greyed out.
 *
 * An `Active` array that is not a one-component array, or a `RestPosition` array that is not a
 * three-component array of the lattice's length, is an error (the data contract is broken, see
 * vtkFFDDataContract).
 *
 * @sa vtkFFDLatticeActor vtkFFDLatticeRepresentation vtkFFDBuildLattice
 */
#ifndef vtkFFDControlPoints_h
#define vtkFFDControlPoints_h

#include "vtkFFDRenderingModule.h" // For export macro
#include "vtkPolyDataAlgorithm.h"

class VTKFFDRENDERING_EXPORT vtkFFDControlPoints : public vtkPolyDataAlgorithm
{
public:
  static vtkFFDControlPoints* New();
  vtkTypeMacro(vtkFFDControlPoints, vtkPolyDataAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  enum Selections
  {
    ACTIVE = 0,
    CULLED = 1,
    ALL = 2
  };

  ///@{
  /// Which control points to output (default ACTIVE).
  vtkSetClampMacro(Selection, int, ACTIVE, ALL);
  vtkGetMacro(Selection, int);
  void SetSelectionToActive() { this->SetSelection(ACTIVE); }
  void SetSelectionToCulled() { this->SetSelection(CULLED); }
  void SetSelectionToAll() { this->SetSelection(ALL); }
  const char* GetSelectionAsString();
  ///@}

  ///@{
  /// Names of the output's point arrays.
  static const char* LatticePointIdArrayName() { return "LatticePointId"; }
  static const char* DisplacementLengthArrayName() { return "DisplacementLength"; }
  ///@}

protected:
  vtkFFDControlPoints() = default;
  ~vtkFFDControlPoints() override = default;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  int Selection = ACTIVE;

private:
  vtkFFDControlPoints(const vtkFFDControlPoints&) = delete;
  void operator=(const vtkFFDControlPoints&) = delete;
};

#endif
