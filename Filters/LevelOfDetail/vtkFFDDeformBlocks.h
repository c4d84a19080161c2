// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkFFDDeformBlocks
 * @brief   deforms a mesh with several lattices at once: blocks blended by a partition of unity, or levels added
 *
 * The paper's section III.C (several FFD blocks on one object: local crash damage, a cartoon squash) and
 * hierarchical B-splines. Input 0 is the mesh; input 1 takes any number of lattices (AddLatticeConnection()),
 * each evaluated as vtkFFDDeform evaluates it (its points outside the lattice keep their position), giving each
 * mesh point x a displacement d_b(x) per lattice b. The output moves x by
 *
 * - BLEND (default; grid lattices): sum_b w_b(x) d_b(x), with w_b = phi_b / sum_c phi_c over the lattices whose
 *   frame holds x and phi_b = prod_axes 4 s (1 - s) of x's parameters (s, t, u) in b's frame, a bump that is 1 at
 *   the frame's centre and 0 on its faces (equal weights where every phi is 0: x on faces only). Where one frame
 *   holds x its lattice moves it alone, exactly as vtkFFDDeform would; where frames overlap the displacements
 *   blend, continuously across each frame's faces (a lattice's weight falls to 0 there).
 * - ADD: sum_b d_b(x), for detail lattices added to a base one (vtkFFDBuildDetailLattice: hierarchical
 *   refinement) or effects that superpose. Any lattice, grid or tetrahedral.
 *
 * A point that no lattice moves keeps its coordinates bit for bit. Normals (the input's active point normals,
 * TransformNormals on) are each lattice's transformed normal, blended with the same weights (BLEND) or summed as
 * changes (ADD), renormalised: exact where one lattice moves a point, an approximation where several do.
 * Hierarchical FFD, a lattice deformed by a coarser one, needs no filter of its own: vtkFFDDeform takes a
 * lattice as its input 0 and keeps its arrays.
 *
 * @sa vtkFFDDeform vtkFFDBuildDetailLattice
 */
#ifndef vtkFFDDeformBlocks_h
#define vtkFFDDeformBlocks_h

#include "vtkFFDFiltersLevelOfDetailModule.h" // For export macro
#include "vtkPointSetAlgorithm.h"

#include <memory> // For std::unique_ptr

class VTKFFDFILTERSLEVELOFDETAIL_EXPORT vtkFFDDeformBlocks : public vtkPointSetAlgorithm
{
public:
  static vtkFFDDeformBlocks* New();
  vtkTypeMacro(vtkFFDDeformBlocks, vtkPointSetAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// The lattices (input 1, repeatable): add one, remove them all, count them.
  void AddLatticeConnection(vtkAlgorithmOutput* output) { this->AddInputConnection(1, output); }
  void AddLatticeData(vtkDataObject* lattice) { this->AddInputData(1, lattice); }
  void RemoveAllLattices() { this->SetInputConnection(1, nullptr); }
  int GetNumberOfLattices() { return this->GetNumberOfInputConnections(1); }
  ///@}

  enum Compositions
  {
    BLEND = 0,
    ADD = 1
  };

  ///@{
  /// How the lattices' displacements combine (default BLEND).
  vtkSetClampMacro(Composition, int, BLEND, ADD);
  vtkGetMacro(Composition, int);
  void SetCompositionToBlend() { this->SetComposition(BLEND); }
  void SetCompositionToAdd() { this->SetComposition(ADD); }
  ///@}

  ///@{
  /// Transform the input's point normals (default on), as vtkFFDDeform does.
  vtkSetMacro(TransformNormals, bool);
  vtkGetMacro(TransformNormals, bool);
  vtkBooleanMacro(TransformNormals, bool);
  ///@}

  ///@{
  /// The backend of every lattice's evaluation (vtkFFDDeform::Backends, default AUTOMATIC).
  vtkSetClampMacro(Backend, int, 0, 2);
  vtkGetMacro(Backend, int);
  ///@}

protected:
  vtkFFDDeformBlocks();
  ~vtkFFDDeformBlocks() override;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  /// Checks the inputs first: one clear error where one is missing or of the wrong type.
  int RequestDataObject(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  vtkTypeBool ProcessRequest(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  int Composition;
  bool TransformNormals;
  int Backend;

private:
  vtkFFDDeformBlocks(const vtkFFDDeformBlocks&) = delete;
  void operator=(const vtkFFDDeformBlocks&) = delete;

  struct Internals;
  std::unique_ptr<Internals> Internal;
};

#endif
