// SPDX-License-Identifier: BSD-3-Clause
// ITK's own code on the .tfm files of vtkffd.interchange (Python.test_interchange runs it):
//   FFDITKTransformPeer apply FILE.tfm POINTS_IN POINTS_OUT
//       reads the file's transform with ITK's reader and writes each point of POINTS_IN (text, "x y z" a line)
//       transformed by it (TransformPoint) to POINTS_OUT, with 17 significant digits;
//   FFDITKTransformPeer make FILE.tfm SEED OX OY OZ LX LY LZ
//       writes with ITK's writer a BSplineTransform over the box of origin O and sizes L, its grid turned by 0.5
//       radians about (1, 2, 3), 3 x 4 x 5 mesh cells, coefficients random in +-2% of the smallest size (SEED).
#include "itkBSplineTransform.h"
#include "itkTransformFileReader.h"
#include "itkTransformFileWriter.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <random>
#include <string>

namespace
{
using Transform = itk::Transform<double, 3, 3>;
using BSpline = itk::BSplineTransform<double, 3, 3>;

int Apply(const char* file, const char* in, const char* out)
{
  auto reader = itk::TransformFileReaderTemplate<double>::New();
  reader->SetFileName(file);
  reader->Update();
  const auto* transform = dynamic_cast<const Transform*>(reader->GetTransformList()->front().GetPointer());
  if (!transform)
  {
    std::cerr << file << ": not a 3-D transform\n";
    return 1;
  }
  std::ifstream points(in);
  FILE* result = std::fopen(out, "w");
  if (!points || !result)
  {
    std::cerr << "cannot open " << in << " or " << out << "\n";
    return 1;
  }
  Transform::InputPointType p;
  while (points >> p[0] >> p[1] >> p[2])
  {
    const Transform::OutputPointType q = transform->TransformPoint(p);
    std::fprintf(result, "%.17g %.17g %.17g\n", q[0], q[1], q[2]);
  }
  return std::fclose(result) == 0 ? 0 : 1;
}

int Make(const char* file, unsigned seed, const double origin[3], const double size[3])
{
  auto transform = BSpline::New();
  BSpline::OriginType domainOrigin;
  BSpline::PhysicalDimensionsType dimensions;
  BSpline::MeshSizeType mesh;
  for (int a = 0; a < 3; ++a)
  {
    domainOrigin[a] = origin[a];
    dimensions[a] = size[a];
    mesh[a] = 3 + a;
  }
  // Rodrigues' rotation by 0.5 rad about (1, 2, 3) / |(1, 2, 3)|.
  const double k[3] = { 1 / std::sqrt(14.0), 2 / std::sqrt(14.0), 3 / std::sqrt(14.0) };
  const double c = std::cos(0.5), s = std::sin(0.5);
  BSpline::DirectionType direction;
  for (int i = 0; i < 3; ++i)
  {
    for (int j = 0; j < 3; ++j)
    {
      const double cross = i == j ? 0.0 : ((j - i + 3) % 3 == 1 ? -1.0 : 1.0) * k[3 - i - j];
      direction[i][j] = (i == j ? c : 0.0) + (1 - c) * k[i] * k[j] + s * cross;
    }
  }
  transform->SetTransformDomainOrigin(domainOrigin);
  transform->SetTransformDomainPhysicalDimensions(dimensions);
  transform->SetTransformDomainDirection(direction);
  transform->SetTransformDomainMeshSize(mesh);
  const double amplitude = 0.02 * std::min({ size[0], size[1], size[2] });
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> coefficient(-amplitude, amplitude);
  BSpline::ParametersType parameters(transform->GetNumberOfParameters());
  for (unsigned i = 0; i < parameters.GetSize(); ++i)
  {
    parameters[i] = coefficient(rng);
  }
  transform->SetParametersByValue(parameters);
  auto writer = itk::TransformFileWriterTemplate<double>::New();
  writer->SetInput(transform);
  writer->SetFileName(file);
  writer->Update();
  return 0;
}
} // namespace

int main(int argc, char* argv[])
{
  try
  {
    const std::string command = argc > 1 ? argv[1] : "";
    if (command == "apply" && argc == 5)
    {
      return Apply(argv[2], argv[3], argv[4]);
    }
    if (command == "make" && argc == 10)
    {
      const double origin[3] = { std::atof(argv[4]), std::atof(argv[5]), std::atof(argv[6]) };
      const double size[3] = { std::atof(argv[7]), std::atof(argv[8]), std::atof(argv[9]) };
      return Make(argv[2], static_cast<unsigned>(std::atoi(argv[3])), origin, size);
    }
  }
  catch (const itk::ExceptionObject& e)
  {
    std::cerr << e.GetDescription() << "\n";
    return 1;
  }
  std::cerr << "usage: FFDITKTransformPeer apply FILE.tfm POINTS_IN POINTS_OUT\n"
               "       FFDITKTransformPeer make FILE.tfm SEED OX OY OZ LX LY LZ\n";
  return 2;
}
