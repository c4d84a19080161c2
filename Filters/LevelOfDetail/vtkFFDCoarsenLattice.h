// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkFFDCoarsenLattice
 * @brief   a coarser lattice that best reproduces a lattice's deformation over a mesh's points
 *
 * Input 0 is a grid lattice of vtkFFDBuildLattice (dense or sparse, deformed), input 1 the mesh whose points the
 * deformation is measured on. The output is a lattice of the same frame over `Divisions` voxels (default: half the
 * input's, rounded up), of the input's basis or of `Basis`, in the input's form, at rest where the mesh has no
 * points (culled as vtkFFDBuildLattice culls over the mesh's voxels), whose control points minimise
 *
 *     sum over the mesh's points p of |D(x_p) - d_p|^2,
 *
 * with d_p the input lattice's displacement of point p and D the output's (ffd::LeastSquares,
 * Filters/LevelOfDetail/FFDLeastSquares.h: eight steps of iterated Tikhonov regularisation towards the smoothest
 * control net, on a sparse factorisation of the normal equations). `Regularization` sets what counts as determined:
 * combinations of control points whose weight over the mesh's points, relative to their roughness, is below about
 * Regularization times the mean weight keep the smooth values their neighbours extend to them, instead of
 * least-squares values that can be huge (a mesh's surface barely touches some control points of the cubic bases:
 * fitting the bear's twist on a 2x2x2 cubic B-spline lattice moves control points by up to 835 units at 1e-15, 7
 * at 1e-8 and 2 at the default 1e-6, the bear being 2.2 units across, for a residual 22% larger). With 1e-12 and
 * points that determine every control point, the fit is the least-squares one: where the input is an exact
 * refinement of a coarser lattice (vtkFFDRefineLattice), the output is that coarser lattice. The residual of the
 * fit is reported (GetResidualRMS(), GetMaximumResidual()). The normal matrix costs (support size)^2 per mesh
 * point to form: 4096 for the cubic bases, (n+1)^6 for a global Bernstein lattice of degree n.
 *
 * Input 2 (optional) is the mesh deformed by any means, with the points of input 1 in the same order: the fit then
 * reproduces that deformation (d_p its point p minus input 1's) instead of the input lattice's, which gives only
 * the frame, the basis and the form; e.g. the result of vtkFFDDeformBlocks, a base lattice with its details.
 *
 * A mesh point with a NaN or infinite coordinate, at rest or deformed, has no displacement to fit: it is left out
 * of the fit and of the residuals (vtkFFDVoxelize and vtkFFDDeform leave such points out and in place too), and a
 * warning says how many there are; a mesh without any finite point is an error.
 *
 * @sa vtkFFDRefineLattice vtkFFDBuildLattice
 */
#ifndef vtkFFDCoarsenLattice_h
#define vtkFFDCoarsenLattice_h

#include "vtkFFDFiltersLevelOfDetailModule.h" // For export macro
#include "vtkPointSetAlgorithm.h"

class VTKFFDFILTERSLEVELOFDETAIL_EXPORT vtkFFDCoarsenLattice : public vtkPointSetAlgorithm
{
public:
  static vtkFFDCoarsenLattice* New();
  vtkTypeMacro(vtkFFDCoarsenLattice, vtkPointSetAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// The mesh whose points the fit runs over (input 1, required).
  void SetMeshConnection(vtkAlgorithmOutput* output) { this->SetInputConnection(1, output); }
  void SetMeshData(vtkDataObject* mesh) { this->SetInputData(1, mesh); }

  /// The mesh deformed by any means (input 2, optional): the deformation to fit instead of the input lattice's.
  void SetDeformedMeshConnection(vtkAlgorithmOutput* output) { this->SetInputConnection(2, output); }
  void SetDeformedMeshData(vtkDataObject* mesh) { this->SetInputData(2, mesh); }

  ///@{
  /// Voxels per axis of the output; any value below 1 (the default 0, 0, 0) takes half the input's, rounded up.
  vtkSetVector3Macro(Divisions, int);
  vtkGetVector3Macro(Divisions, int);
  ///@}

  ///@{
  /// The output's basis (vtkFFDBuildLattice::Bases); -1, the default, keeps the input's.
  vtkSetClampMacro(Basis, int, -1, 4);
  vtkGetMacro(Basis, int);
  ///@}

  ///@{
  /// Below what weight, relative to its roughness and to the mean weight, a combination of control points counts
  /// as undetermined and stays smooth (default 1e-6; 1e-12 for the least-squares fit; 0 is an error wherever the
  /// points leave a combination undetermined).
  vtkSetClampMacro(Regularization, double, 0.0, 1.0);
  vtkGetMacro(Regularization, double);
  ///@}

  ///@{
  /// The last fit: the root mean square and the largest distance, over the mesh's points, between the output's
  /// deformation and the input's (world units).
  vtkGetMacro(ResidualRMS, double);
  vtkGetMacro(MaximumResidual, double);
  ///@}

protected:
  vtkFFDCoarsenLattice();
  ~vtkFFDCoarsenLattice() override = default;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  int ExecuteInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int ComputeInputUpdateExtent(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  /// Checks the inputs first: one clear error where one is missing or of the wrong type.
  int RequestDataObject(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  vtkTypeBool ProcessRequest(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  int Divisions[3];
  int Basis;
  double Regularization;
  double ResidualRMS;
  double MaximumResidual;

private:
  vtkFFDCoarsenLattice(const vtkFFDCoarsenLattice&) = delete;
  void operator=(const vtkFFDCoarsenLattice&) = delete;
};

#endif
