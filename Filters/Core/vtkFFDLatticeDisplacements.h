// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file vtkFFDLatticeDisplacements.h
 * @brief Reads a lattice's deformation, its points minus `RestPosition` (private to the Filters module).
 */
#ifndef vtkFFDLatticeDisplacements_h
#define vtkFFDLatticeDisplacements_h

#include "vtkArrayDispatch.h"
#include "vtkDataArray.h"
#include "vtkDataArrayRange.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkSMPTools.h"

#include <atomic>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

/**
 * The largest magnitude of a lattice's coordinates (its points' and rest positions'): beyond it, the products an
 * evaluation forms (a tetrahedron's volume, the cube of its edges; a basis's derivatives times displacements)
 * could overflow to infinity and turn the whole mesh into NaN.
 */
constexpr double vtkFFDMaxLatticeCoordinate = 1e100;

/**
 * Why `lattice`'s points or its `rest` (RestPosition) break the data contract's precision, or an empty string:
 * both must be double arrays, since an integer or float RestPosition displaces the mesh by its rounding, and a float
 * lattice cannot give double-precision results. `what` names the lattice ("The lattice").
 */
inline std::string vtkFFDCheckLatticePrecision(vtkPointSet* lattice, vtkDataArray* rest, const std::string& what)
{
  if (rest->GetDataType() != VTK_DOUBLE)
  {
    return what + "'s RestPosition array holds " + rest->GetDataTypeAsString() +
      " values; the data contract asks for doubles (an integer or float RestPosition moves the mesh by its "
      "rounding). Store the rest positions as a vtkDoubleArray, as vtkFFDBuildLattice and "
      "vtkFFDBuildTetrahedralLattice do.";
  }
  vtkDataArray* points = lattice->GetPoints() ? lattice->GetPoints()->GetData() : nullptr;
  if (points && points->GetDataType() != VTK_DOUBLE)
  {
    return what + "'s points are " + points->GetDataTypeAsString() +
      "; the data contract asks for doubles (a float lattice cannot give double-precision results). Give it "
      "double points: vtkPoints::SetDataTypeToDouble(), or OutputPointsPrecision DOUBLE_PRECISION (or default) on "
      "the filter that made them.";
  }
  return std::string();
}

/**
 * The deformation of a lattice, its `points` minus `rest` (3 components, `count` tuples each): 3 values per point,
 * the difference in double rounded to Real, into `displacements`, and the rest positions into `restValues`, each
 * where not null (with neither, only the check). Returns the first point whose position or rest position is not
 * finite or beyond vtkFFDMaxLatticeCoordinate (the outputs then hold such values), or -1;
 * vtkFFDLatticePointProblem() says what is wrong with it.
 */
template <typename Real>
vtkIdType vtkFFDReadLatticeDisplacements(
  vtkDataArray* points, vtkDataArray* rest, vtkIdType count, Real* displacements, double* restValues)
{
  if (count == 0)
  {
    return -1;
  }
  std::atomic<vtkIdType> firstBad(count);
  // Read through the arrays' own types where they are float or double (vtkArrayDispatch): vtkDataArray's
  // virtual tuple access is a noticeable part of an update's fixed cost.
  auto read = [&](auto* pointValues, auto* restPositions)
  {
    const auto x = vtk::DataArrayTupleRange<3>(pointValues);
    const auto x0 = vtk::DataArrayTupleRange<3>(restPositions);
    // In parallel: a lattice of 100 k nodes, read serially, would hold up every update by a millisecond; in
    // tasks of at least 4096 nodes, so that a small lattice is read in one.
    vtkSMPTools::For(0, count, 4096,
      [&](vtkIdType begin, vtkIdType end)
      {
        for (vtkIdType p = begin; p < end; ++p)
        {
          for (int c = 0; c < 3; ++c)
          {
            const double rest0 = double(x0[p][c]);
            const double d = double(x[p][c]) - rest0;
            // Not finite or too large: NaN fails both comparisons.
            if (!(std::fabs(rest0) <= vtkFFDMaxLatticeCoordinate &&
                  std::fabs(double(x[p][c])) <= vtkFFDMaxLatticeCoordinate))
            {
              vtkIdType first = firstBad.load();
              while (p < first && !firstBad.compare_exchange_weak(first, p))
              {
              }
            }
            if (displacements)
            {
              displacements[3 * p + c] = Real(d);
            }
            if (restValues)
            {
              restValues[3 * p + c] = rest0;
            }
          }
        }
      });
  };
  if (!vtkArrayDispatch::Dispatch2ByValueType<vtkArrayDispatch::Reals, vtkArrayDispatch::Reals>::Execute(
        points, rest, read))
  {
    read(points, rest);
  }
  return firstBad == count ? -1 : firstBad.load();
}

/// vtkFFDReadLatticeDisplacements() of `lattice`'s points, into vectors (resized to 3 values per point).
inline vtkIdType vtkFFDReadLatticeDisplacements(
  vtkPointSet* lattice, vtkDataArray* rest, std::vector<double>& displacements, std::vector<double>* restValues)
{
  const vtkIdType count = lattice->GetNumberOfPoints();
  displacements.resize(3 * count);
  if (restValues)
  {
    restValues->resize(3 * count);
  }
  return vtkFFDReadLatticeDisplacements(lattice->GetPoints() ? lattice->GetPoints()->GetData() : nullptr, rest, count,
    displacements.data(), restValues ? restValues->data() : nullptr);
}

/// What is wrong with point `p` of `lattice`, found by vtkFFDReadLatticeDisplacements(); `what` names the point
/// ("Lattice point").
inline std::string vtkFFDLatticePointProblem(
  vtkPointSet* lattice, vtkDataArray* rest, vtkIdType p, const std::string& what)
{
  double x[3], x0[3];
  lattice->GetPoint(p, x);
  rest->GetTuple(p, x0);
  std::ostringstream msg;
  msg << what << " " << p << " or its RestPosition is not finite or lies beyond +-" << vtkFFDMaxLatticeCoordinate
      << ": the point is at (" << x[0] << ", " << x[1] << ", " << x[2] << "), its RestPosition at (" << x0[0] << ", "
      << x0[1] << ", " << x0[2] << "). Give every lattice point and RestPosition finite coordinates within +-"
      << vtkFFDMaxLatticeCoordinate << " (beyond, the deformation's products overflow).";
  return msg.str();
}

#endif
