// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDBuildTetrahedralLattice.h"

#include "vtkFFDDataContract.h"
#include "vtkFFDDistributed.h"
#include "vtkFFDMemory.h"
#include "vtkFFDStatistics.h"
#include "vtkFFDTetrahedralDeformer.h"

#include "vtkCellArray.h"
#include "vtkCellType.h"
#include "vtkDataSetAttributes.h"
#include "vtkDoubleArray.h"
#include "vtkIdTypeArray.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkMultiProcessController.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkSmartPointer.h"
#include "vtkUnsignedCharArray.h"
#include "vtkUnstructuredGrid.h"

#include "FFDTetrahedra.h"

#include <libqhull_r/libqhull_r.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <unordered_map>
#include <vector>

vtkStandardNewMacro(vtkFFDBuildTetrahedralLattice);
vtkCxxSetObjectMacro(vtkFFDBuildTetrahedralLattice, Controller, vtkMultiProcessController);

namespace
{
// The weight above which a node influences a point (vtkFFDBuildTetrahedralLattice's `Active`).
constexpr double ActiveWeight = 1e-9;

// A control mesh under construction: 3 coordinates per node, 4 node ids per tetrahedron.
struct TetrahedralMesh
{
  std::vector<double> Nodes;
  std::vector<vtkIdType> Tetrahedra;

  const double* Node(vtkIdType id) const { return this->Nodes.data() + 3 * id; }

  double SignedVolume6(const vtkIdType t[4]) const
  {
    const ffd::Vec3<double> a = ffd::Vec3<double>::From(this->Node(t[0]));
    return ffd::Dot(
      ffd::Cross(ffd::Vec3<double>::From(this->Node(t[1])) - a, ffd::Vec3<double>::From(this->Node(t[2])) - a),
      ffd::Vec3<double>::From(this->Node(t[3])) - a);
  }

  /// Adds the tetrahedron, positively oriented.
  void Add(vtkIdType a, vtkIdType b, vtkIdType c, vtkIdType d)
  {
    vtkIdType t[4] = { a, b, c, d };
    if (this->SignedVolume6(t) < 0.0)
    {
      std::swap(t[2], t[3]);
    }
    this->Tetrahedra.insert(this->Tetrahedra.end(), t, t + 4);
  }
};

// The triangles of the convex hull of `count` points (3 doubles each), as point indices, by Qhull (option Qt:
// triangulated output). Returns an empty string, or Qhull's message.
std::string ConvexHull(std::vector<double>& coordinates, std::vector<std::array<int, 3>>& triangles)
{
  qhT context;
  qhT* qh = &context;
  QHULL_LIB_CHECK
  FILE* errors = std::tmpfile();
  qh_zero(qh, errors);
  char options[] = "qhull Qt";
  const int count = static_cast<int>(coordinates.size() / 3);
  const int exitCode = qh_new_qhull(qh, 3, count, coordinates.data(), False, options, nullptr, errors);
  std::string message;
  if (exitCode == 0)
  {
    facetT* facet;
    vertexT *vertex, **vertexp;
    FORALLfacets
    {
      std::array<int, 3> triangle;
      int n = 0;
      FOREACHvertex_(facet->vertices)
      {
        if (n < 3)
        {
          triangle[n] = qh_pointid(qh, vertex->point);
        }
        ++n;
      }
      if (n == 3)
      {
        triangles.push_back(triangle);
      }
    }
  }
  else if (errors)
  {
    std::rewind(errors);
    char line[512];
    while (std::fgets(line, sizeof(line), errors) && message.size() < 2000)
    {
      message += line;
    }
    if (message.empty())
    {
      message = "Qhull failed with exit code " + std::to_string(exitCode);
    }
  }
  qh_freeqhull(qh, !qh_ALL);
  int curlong, totlong;
  qh_memfreeshort(qh, &curlong, &totlong);
  if (errors)
  {
    std::fclose(errors);
  }
  return message;
}

// The points (3 doubles each) in increasing lexicographic order, each once.
void SortPoints(std::vector<double>& coordinates)
{
  if (coordinates.empty())
  {
    return;
  }
  std::vector<std::array<double, 3>> points(coordinates.size() / 3);
  std::copy(coordinates.begin(), coordinates.end(), points.front().data());
  std::sort(points.begin(), points.end());
  points.erase(std::unique(points.begin(), points.end()), points.end());
  coordinates.assign(points.front().data(), points.front().data() + 3 * points.size());
}

// Splits every tetrahedron into eight: four at its corners, four around the shortest diagonal of the inner
// octahedron; the midpoint of an edge shared by several tetrahedra is one node.
TetrahedralMesh Subdivide(const TetrahedralMesh& coarse)
{
  TetrahedralMesh fine;
  fine.Nodes = coarse.Nodes;
  fine.Tetrahedra.reserve(8 * coarse.Tetrahedra.size());
  std::unordered_map<unsigned long long, vtkIdType> midpoints;
  auto midpoint = [&](vtkIdType a, vtkIdType b)
  {
    const unsigned long long key =
      (static_cast<unsigned long long>(std::min(a, b)) << 32) | static_cast<unsigned long long>(std::max(a, b));
    const auto found = midpoints.find(key);
    if (found != midpoints.end())
    {
      return found->second;
    }
    const vtkIdType id = static_cast<vtkIdType>(fine.Nodes.size() / 3);
    for (int c = 0; c < 3; ++c)
    {
      fine.Nodes.push_back(0.5 * (coarse.Nodes[3 * a + c] + coarse.Nodes[3 * b + c]));
    }
    midpoints.emplace(key, id);
    return id;
  };
  for (size_t t = 0; t < coarse.Tetrahedra.size(); t += 4)
  {
    const vtkIdType* v = coarse.Tetrahedra.data() + t;
    vtkIdType m[4][4];
    for (int i = 0; i < 4; ++i)
    {
      for (int j = i + 1; j < 4; ++j)
      {
        m[i][j] = m[j][i] = midpoint(v[i], v[j]);
      }
    }
    fine.Add(v[0], m[0][1], m[0][2], m[0][3]);
    fine.Add(m[0][1], v[1], m[1][2], m[1][3]);
    fine.Add(m[0][2], m[1][2], v[2], m[2][3]);
    fine.Add(m[0][3], m[1][3], m[2][3], v[3]);
    // The octahedron's three diagonals join the midpoints of opposite edges; around each, the other four
    // midpoints form a ring.
    const vtkIdType diagonals[3][2] = { { m[0][1], m[2][3] }, { m[0][2], m[1][3] }, { m[0][3], m[1][2] } };
    const vtkIdType rings[3][4] = { { m[0][2], m[0][3], m[1][3], m[1][2] }, { m[0][1], m[1][2], m[2][3], m[0][3] },
      { m[0][1], m[0][2], m[2][3], m[1][3] } };
    int shortest = 0;
    double shortestLength = std::numeric_limits<double>::infinity();
    for (int d = 0; d < 3; ++d)
    {
      const ffd::Vec3<double> e =
        ffd::Vec3<double>::From(fine.Node(diagonals[d][1])) - ffd::Vec3<double>::From(fine.Node(diagonals[d][0]));
      if (ffd::Dot(e, e) < shortestLength)
      {
        shortestLength = ffd::Dot(e, e);
        shortest = d;
      }
    }
    for (int k = 0; k < 4; ++k)
    {
      fine.Add(diagonals[shortest][0], diagonals[shortest][1], rings[shortest][k], rings[shortest][(k + 1) % 4]);
    }
  }
  return fine;
}

/// The input's finite points (`coordinates`, 3 a point) and their centroid, an exact sum over every process
/// rounded once; a distributed mesh's points shared by pieces (marked as copies in its ghost array) count once.
/// False, said why, where there are fewer than 4 in all.
bool FinitePointsAndCentroid(vtkFFDBuildTetrahedralLattice* self, vtkPointSet* input,
  vtkMultiProcessController* controller, std::vector<double>& coordinates, double centroid[3])
{
  const vtkSmartPointer<vtkDataArray> owned = vtkFFDOwnedPoints(input);
  const vtkIdType numberOfOwned = owned->GetNumberOfTuples();
  coordinates.reserve(3 * numberOfOwned);
  std::vector<ffd::ExactSum> sums(4); // x, y, z, count
  for (vtkIdType id = 0; id < numberOfOwned; ++id)
  {
    double x[3];
    owned->GetTuple(id, x);
    if (std::isfinite(x[0]) && std::isfinite(x[1]) && std::isfinite(x[2]))
    {
      coordinates.insert(coordinates.end(), x, x + 3);
      for (int c = 0; c < 3; ++c)
      {
        sums[c].Add(x[c]);
      }
      sums[3].Add(1.0);
    }
  }
  vtkFFDSumOverProcesses(controller, sums);
  const double finite = sums[3].Value();
  if (finite < 4)
  {
    vtkErrorWithObjectMacro(self,
      "The input has " << finite << " finite points; a tetrahedral lattice needs at "
                       << "least 4 that are not coplanar.");
    return false;
  }
  for (int c = 0; c < 3; ++c)
  {
    centroid[c] = sums[c].Value() / finite;
  }
  return true;
}

/// The hull of every process's points in lexicographic order, into `coordinates` (all of them) and
/// `triangles`: the same however the points are ordered and split (Qhull's handling of nearly coplanar points
/// depends on the points it is given and their order, so each process takes all of them, 24 bytes a point).
/// False, said why, where it cannot be computed.
bool HullOverProcesses(vtkFFDBuildTetrahedralLattice* self, vtkMultiProcessController* controller,
  std::vector<double>& coordinates, std::vector<std::array<int, 3>>& triangles)
{
  coordinates = vtkFFDGatherOverProcesses(controller, coordinates);
  SortPoints(coordinates);
  const std::string qhullMessage = ConvexHull(coordinates, triangles);
  if (!qhullMessage.empty() || triangles.empty())
  {
    vtkErrorWithObjectMacro(self,
      "The convex hull of the input's points cannot be computed (are they coplanar?). Qhull says: " << qhullMessage);
    return false;
  }
  return true;
}

/// One tetrahedron per hull triangle and the centroid (node 0); the hull's nodes moved out by `padding`.
TetrahedralMesh HullFan(const double centroid[3], const std::vector<double>& coordinates,
  const std::vector<std::array<int, 3>>& triangles, double padding)
{
  TetrahedralMesh mesh;
  mesh.Nodes.assign(centroid, centroid + 3);
  std::unordered_map<int, vtkIdType> nodeOfPoint;
  auto node = [&](int point)
  {
    const auto found = nodeOfPoint.find(point);
    if (found != nodeOfPoint.end())
    {
      return found->second;
    }
    const vtkIdType id = static_cast<vtkIdType>(mesh.Nodes.size() / 3);
    for (int c = 0; c < 3; ++c)
    {
      mesh.Nodes.push_back(centroid[c] + (1.0 + padding) * (coordinates[3 * point + c] - centroid[c]));
    }
    nodeOfPoint.emplace(point, id);
    return id;
  };
  for (const auto& triangle : triangles)
  {
    const vtkIdType a = node(triangle[0]), b = node(triangle[1]), c = node(triangle[2]);
    // Qhull's triangulation of a facet with coplanar points may add triangles of no area: no volume either.
    if (ffd::CheckTetrahedron(mesh.Node(0), mesh.Node(a), mesh.Node(b), mesh.Node(c)) == ffd::FrameStatus::Valid)
    {
      mesh.Add(0, a, b, c);
    }
  }
  return mesh;
}

/// False, said why, where `levels` subdivisions of `hullFaces` tetrahedra would be too many or too large.
bool CheckSubdivisions(vtkFFDBuildTetrahedralLattice* self, vtkIdType hullFaces, int levels)
{
  // A tetrahedron of the result costs about 300 bytes in all: its ids while subdividing (twice 32), the output's
  // cell arrays (41), the binding of the input's points and the maps of the deformation (about 130), and its
  // share of the nodes (at most one node per tetrahedron, 3 copies of 24 bytes and the midpoints' index).
  const double finalTetrahedra = double(hullFaces) * std::pow(8.0, levels);
  std::ostringstream request;
  request << "SubdivisionLevels " << levels << " (" << hullFaces << " hull faces, so " << finalTetrahedra
          << " tetrahedra)";
  if (finalTetrahedra > double(vtkFFDTetrahedralDeformer::MaxTetrahedra))
  {
    vtkErrorWithObjectMacro(self, << request.str() << " exceeds the " << vtkFFDTetrahedralDeformer::MaxTetrahedra
                                  << " tetrahedra a lattice may have: choose fewer levels.");
    return false;
  }
  return vtkFFDCheckMemory(self, request.str(), 300.0 * finalTetrahedra);
}

/// The output: the mesh's nodes at rest, its tetrahedra, RestPosition.
void FillLattice(const TetrahedralMesh& mesh, vtkUnstructuredGrid* output)
{
  const vtkIdType numberOfNodes = static_cast<vtkIdType>(mesh.Nodes.size() / 3);
  const vtkIdType numberOfTetrahedra = static_cast<vtkIdType>(mesh.Tetrahedra.size() / 4);
  vtkNew<vtkDoubleArray> nodes;
  nodes->SetNumberOfComponents(3);
  nodes->SetNumberOfTuples(numberOfNodes);
  std::copy(mesh.Nodes.begin(), mesh.Nodes.end(), nodes->GetPointer(0));
  vtkNew<vtkPoints> points;
  points->SetData(nodes);
  vtkNew<vtkDoubleArray> rest;
  rest->DeepCopy(nodes);
  rest->SetName(vtkFFDDataContract::RestPositionArrayName());
  vtkNew<vtkIdTypeArray> offsets;
  offsets->SetNumberOfValues(numberOfTetrahedra + 1);
  for (vtkIdType t = 0; t <= numberOfTetrahedra; ++t)
  {
    offsets->SetValue(t, 4 * t);
  }
  vtkNew<vtkIdTypeArray> connectivity;
  connectivity->SetNumberOfValues(4 * numberOfTetrahedra);
  std::copy(mesh.Tetrahedra.begin(), mesh.Tetrahedra.end(), connectivity->GetPointer(0));
  vtkNew<vtkCellArray> cells;
  cells->SetData(offsets, connectivity);
  output->SetPoints(points);
  output->SetCells(VTK_TETRA, cells);
  output->GetPointData()->AddArray(rest);
}

/// The nodes with a weight for some input point (`points`) in its tetrahedron, as `binding` bound it (1, else
/// 0). A point on a face has a weight of (nearly) zero for the opposite node, which it does not move.
vtkSmartPointer<vtkUnsignedCharArray> ActiveNodes(
  const vtkFFDTetrahedralDeformer& binding, vtkPoints* points, const TetrahedralMesh& mesh, vtkIdType numberOfNodes)
{
  vtkNew<vtkUnsignedCharArray> active;
  active->SetName(vtkFFDDataContract::ActiveArrayName());
  active->SetNumberOfValues(numberOfNodes);
  active->FillValue(0);
  const std::vector<int>& bound = binding.GetCellOfPoint();
  for (vtkIdType id = 0; id < points->GetNumberOfPoints(); ++id)
  {
    if (bound[id] < 0)
    {
      continue;
    }
    const vtkIdType* nodes = mesh.Tetrahedra.data() + 4 * bound[id];
    double x[3];
    points->GetPoint(id, x);
    const ffd::Vec3<double> stu = binding.GetFrames()[bound[id]].ToParametric(ffd::Vec3<double>::From(x));
    const double weights[4] = { 1.0 - stu.x - stu.y - stu.z, stu.x, stu.y, stu.z };
    for (int i = 0; i < 4; ++i)
    {
      if (weights[i] > ActiveWeight)
      {
        active->SetValue(nodes[i], 1);
      }
    }
  }
  return active.Get();
}

/// Hides the nodes that are not `active`: the ghost array exists only where some are not.
void HideCulledNodes(vtkUnstructuredGrid* output, vtkUnsignedCharArray* active)
{
  const vtkIdType numberOfNodes = active->GetNumberOfValues();
  vtkNew<vtkUnsignedCharArray> ghosts;
  ghosts->SetName(vtkDataSetAttributes::GhostArrayName());
  ghosts->SetNumberOfValues(numberOfNodes);
  for (vtkIdType id = 0; id < numberOfNodes; ++id)
  {
    ghosts->SetValue(id, active->GetValue(id) ? 0 : vtkDataSetAttributes::HIDDENPOINT);
  }
  output->GetPointData()->AddArray(ghosts);
}
} // namespace

//------------------------------------------------------------------------------------------------------------
vtkFFDBuildTetrahedralLattice::vtkFFDBuildTetrahedralLattice()
  : Padding(0.05)
  , SubdivisionLevels(0)
  , NumberOfHullFaces(0)
  , NumberOfActiveNodes(0)
  , Controller(nullptr)
{
  this->SetController(vtkMultiProcessController::GetGlobalController());
}

//------------------------------------------------------------------------------------------------------------
vtkFFDBuildTetrahedralLattice::~vtkFFDBuildTetrahedralLattice()
{
  this->SetController(nullptr);
}

//------------------------------------------------------------------------------------------------------------
int vtkFFDBuildTetrahedralLattice::FillInputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkPointSet");
  return 1;
}

//------------------------------------------------------------------------------------------------------------
int vtkFFDBuildTetrahedralLattice::RequestUpdateExtent(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  return vtkFFDRequestOwnPiece(this->Controller, inputVector) ||
    this->Superclass::RequestUpdateExtent(request, inputVector, outputVector);
}

//------------------------------------------------------------------------------------------------------------
vtkTypeBool vtkFFDBuildTetrahedralLattice::ProcessRequest(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  return vtkFFDCatchAllocationFailure(
    this, outputVector, [&] { return this->Superclass::ProcessRequest(request, inputVector, outputVector); });
}

//------------------------------------------------------------------------------------------------------------
int vtkFFDBuildTetrahedralLattice::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkPointSet* input = vtkPointSet::GetData(inputVector[0]);
  vtkUnstructuredGrid* output = vtkUnstructuredGrid::GetData(outputVector);
  this->NumberOfHullFaces = 0;
  this->NumberOfActiveNodes = 0;
  const vtkFFDStatisticsOnReturn statistics(output,
    [this](vtkDataObject* out)
    {
      vtkFFDRecordCount(out, "NumberOfHullFaces", this->NumberOfHullFaces);
      vtkFFDRecordCount(out, "NumberOfActiveNodes", this->NumberOfActiveNodes);
    });
  // With several processes, every one takes part in the reductions, an empty piece too.
  vtkMultiProcessController* controller = vtkFFDIsDistributed(this->Controller) ? this->Controller : nullptr;
  if (!input || (input->GetNumberOfPoints() == 0 && !controller))
  {
    return 1; // an empty input gives an empty output
  }
  if (!(this->Padding >= 0.0)) // the clamp of SetPadding() lets NaN through
  {
    vtkErrorMacro(<< "Padding " << this->Padding << " is not a number: set Padding (SetPadding()) to a fraction "
                  << "such as 0.05.");
    return 0;
  }
  std::vector<double> coordinates;
  double centroid[3];
  std::vector<std::array<int, 3>> triangles;
  if (!FinitePointsAndCentroid(this, input, controller, coordinates, centroid) ||
    !HullOverProcesses(this, controller, coordinates, triangles))
  {
    return 0;
  }
  this->UpdateProgress(0.3);

  TetrahedralMesh mesh = HullFan(centroid, coordinates, triangles, this->Padding);
  this->NumberOfHullFaces = static_cast<vtkIdType>(mesh.Tetrahedra.size() / 4);
  if (!CheckSubdivisions(this, this->NumberOfHullFaces, this->SubdivisionLevels))
  {
    return 0;
  }
  for (int level = 0; level < this->SubdivisionLevels; ++level)
  {
    mesh = Subdivide(mesh);
  }
  this->UpdateProgress(0.5);
  FillLattice(mesh, output);

  // Active nodes: those with a weight for some input point in its tetrahedron, as vtkFFDDeform binds it.
  vtkFFDTetrahedralDeformer binding;
  const std::string problem = binding.SetLattice(output);
  bool rebound = false;
  vtkNew<vtkPoints> none; // an empty piece
  vtkPoints* inputPoints = input->GetPoints() ? input->GetPoints() : none.Get();
  if (!problem.empty() || !binding.Bind(inputPoints, vtkFFDTetrahedralDeformer::KEEP_POSITION, this, 0.5, 1.0, rebound))
  {
    if (!problem.empty())
    {
      vtkErrorMacro(<< problem);
    }
    output->Initialize();
    return problem.empty() ? 1 : 0; // aborted, or an internal inconsistency
  }
  const vtkIdType numberOfNodes = static_cast<vtkIdType>(mesh.Nodes.size() / 3);
  const vtkSmartPointer<vtkUnsignedCharArray> active = ActiveNodes(binding, inputPoints, mesh, numberOfNodes);
  vtkFFDAnyOverProcesses(controller, active->GetPointer(0), numberOfNodes);
  output->GetPointData()->AddArray(active);
  this->NumberOfActiveNodes = std::count(active->GetPointer(0), active->GetPointer(0) + numberOfNodes, 1);
  if (this->NumberOfActiveNodes < numberOfNodes)
  {
    HideCulledNodes(output, active);
  }
  this->UpdateProgress(1.0);
  return 1;
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDBuildTetrahedralLattice::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Padding: " << this->Padding << "\n";
  os << indent << "SubdivisionLevels: " << this->SubdivisionLevels << "\n";
  os << indent << "NumberOfHullFaces: " << this->NumberOfHullFaces << "\n";
  os << indent << "NumberOfActiveNodes: " << this->NumberOfActiveNodes << "\n";
  os << indent << "Controller: " << this->Controller << "\n";
}
