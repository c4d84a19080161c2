// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkFFDInverseDeform
 * @brief   maps deformed points back to their rest positions: the inverse of vtkFFDDeform
 *
 * Input 0 is any vtkPointSet of deformed points (a mesh that vtkFFDDeform deformed, or points picked in the
 * deformed space); input 1 the lattice, as vtkFFDDeform takes it. The output is a copy of input 0 whose every
 * point y is moved to the x with F(x) = y, F being vtkFFDDeform's deformation under its default outside policy
 * (KEEP_POSITION: points outside the lattice are their own image), and a `InverseStatus` point array (unsigned
 * char, ffd::InverseStatus): 0 where x was found, 1 where the deformation folds (det J <= 0, so a point can have
 * several rest positions), 2 where the search did not converge.
 *
 * Grid lattices (every basis, dense or sparse): Newton's method on the lattice's own evaluation, each iterate bound
 * to its cell again, until |F(x) - y| <= Tolerance times the frame's diagonal. The points go in tiles of consecutive
 * points, each ordered by cell, several at a time in the SIMD lanes of vtkFFDDeform's evaluation, from x = y, a
 * local basis's cells in power form. A point whose search there does not settle cleanly (det J <= 0, a residual
 * that does not fall, 8 steps) starts over alone with a backtracking line search (ffd::InvertPoint,
 * Evaluation/Kernels/FFDInverse.h) from y minus the displacement at y, which reports it. The search runs on F extended
 * beyond the lattice's cells (beyond the frame as CLAMP_TO_EDGE extends it; in a sparse lattice's voxels without
 * a cell, by the nearest cell within two voxels), where KEEP_POSITION makes F jump, so that a point pushed out of
 * the cells finds its rest position inside; a search that ends outside the cells gives y itself, its own rest
 * position there (status 2 where y is inside a cell: no rest position).
 * Tetrahedral lattices: the map is affine in each tetrahedron, so its inverse is the same kind of lattice with rest and
 * deformed positions exchanged: y is located among the deformed tetrahedra and mapped back exactly; points in a
 * tetrahedron that the deformation turned inside out are marked folded. Point normals follow the inverse map (dropped
 * where the input has none). Runs on the CPU (vtkSMPTools); a point's result never depends on the number of threads.
 *
 * @sa vtkFFDDeform
 */
#ifndef vtkFFDInverseDeform_h
#define vtkFFDInverseDeform_h

#include "vtkFFDFiltersManipulationModule.h" // For export macro
#include "vtkPointSetAlgorithm.h"

#include <string> // For the steps' problem

class vtkDataArray;
class vtkDoubleArray;
class vtkPoints;
class vtkUnsignedCharArray;
struct vtkFFDInverseOutput;

class VTKFFDFILTERSMANIPULATION_EXPORT vtkFFDInverseDeform : public vtkPointSetAlgorithm
{
public:
  static vtkFFDInverseDeform* New();
  vtkTypeMacro(vtkFFDInverseDeform, vtkPointSetAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// The lattice, on input port 1.
  void SetLatticeConnection(vtkAlgorithmOutput* output) { this->SetInputConnection(1, output); }
  void SetLatticeData(vtkDataObject* lattice) { this->SetInputData(1, lattice); }
  ///@}

  ///@{
  /// The largest residual |F(x) - y| accepted, relative to the frame's diagonal (default 1e-12).
  vtkSetClampMacro(Tolerance, double, 0.0, VTK_DOUBLE_MAX);
  vtkGetMacro(Tolerance, double);
  ///@}

  ///@{
  /// The most Newton steps per point (default 50).
  vtkSetClampMacro(MaximumNumberOfIterations, int, 1, VTK_INT_MAX);
  vtkGetMacro(MaximumNumberOfIterations, int);
  ///@}

  ///@{
  /// Precision of the output points (vtkAlgorithm::DesiredOutputPrecision); DEFAULT_PRECISION keeps the input's.
  vtkSetClampMacro(OutputPointsPrecision, int, SINGLE_PRECISION, DEFAULT_PRECISION);
  vtkGetMacro(OutputPointsPrecision, int);
  ///@}

  static const char* InverseStatusArrayName() { return "InverseStatus"; }

  ///@{
  /// The last update's points where the deformation folds, and where the search did not converge.
  vtkGetMacro(NumberOfFoldedPoints, vtkIdType);
  vtkGetMacro(NumberOfUnconvergedPoints, vtkIdType);
  ///@}

protected:
  vtkFFDInverseDeform();
  ~vtkFFDInverseDeform() override;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  /// Checks the inputs first: one clear error where one is missing or of the wrong type.
  int RequestDataObject(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  vtkTypeBool ProcessRequest(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  double Tolerance;
  int MaximumNumberOfIterations;
  int OutputPointsPrecision;
  vtkIdType NumberOfFoldedPoints;
  vtkIdType NumberOfUnconvergedPoints;

private:
  ///@{
  /// Steps of RequestData: check Tolerance and MaximumNumberOfIterations; invert the points through the lattice
  /// (false: aborted, or `problem` says what is wrong with the lattice); count the folded and unconverged points
  /// and warn of them; fill the output with the rest positions.
  bool CheckSettings();
  bool Invert(vtkPointSet* lattice, vtkPoints* points, vtkDataArray* normals, const vtkFFDInverseOutput& out,
    std::string& problem);
  void CountUnreliablePoints(vtkUnsignedCharArray* status);
  void FillOutput(vtkPointSet* input, vtkDoubleArray* rest, vtkDoubleArray* restNormals, vtkUnsignedCharArray* status,
    vtkPointSet* output);
  ///@}

  vtkFFDInverseDeform(const vtkFFDInverseDeform&) = delete;
  void operator=(const vtkFFDInverseDeform&) = delete;
};

#endif
