// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkFFDCellEdges
 * @brief   the edges of the visible cells of a data set, each once, as lines between the input's own points
 *
 * Draws a lattice's edges and a voxel grid's boxes. For every cell that is not hidden (HIDDENCELL in the cell
 * ghost array), the cell's edges are output as lines, each edge shared by several cells once. The output keeps the
 * input's points, in the input's order (point i of the output is point i of the input), so an edge follows its control
 * points when they move and nothing is merged: two control points dragged onto each other keep their own edges.
 *
 * It works for any cell type with edges (hexahedra of a structured lattice or of vtkFFDVoxelize's voxel grid,
 * whose cells are the active voxels, tetrahedra of an unstructured lattice); polylines give their segments;
 * vertices give nothing. Unlike vtkExtractEdges of VTK 9.1, it skips hidden cells, which a data set whose hidden
 * cells must not be drawn needs.
 *
 * A sparse lattice (a `LatticeIndex` point array, docs/pipeline-and-data-contract.md, "Data contract") gives its
 * control net instead of its cells' edges: a line between each two control points whose lattice indices differ by one
 * along one axis, the grid lines a dense lattice shows, where both points exist. (Its cells' edges would show a Bezier
 * sub-region's corners only, and a B-spline's cells, sets of points, have none.)
 *
 * @sa vtkFFDLatticeActor vtkFFDVoxelize vtkExtractEdges
 */
#ifndef vtkFFDCellEdges_h
#define vtkFFDCellEdges_h

#include "vtkFFDRenderingModule.h" // For export macro
#include "vtkPolyDataAlgorithm.h"

#include <utility> // For std::pair
#include <vector>  // For std::vector

class VTKFFDRENDERING_EXPORT vtkFFDCellEdges : public vtkPolyDataAlgorithm
{
public:
  static vtkFFDCellEdges* New();
  vtkTypeMacro(vtkFFDCellEdges, vtkPolyDataAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

protected:
  vtkFFDCellEdges() = default;
  ~vtkFFDCellEdges() override = default;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

private:
  /// The edges, sorted and each once, as the output's lines.
  static int Finish(std::vector<std::pair<vtkIdType, vtkIdType>>& edges, vtkPolyData* output);

  vtkFFDCellEdges(const vtkFFDCellEdges&) = delete;
  void operator=(const vtkFFDCellEdges&) = delete;
};

#endif
