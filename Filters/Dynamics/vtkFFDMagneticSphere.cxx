// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDMagneticSphere.h"

#include "vtkObjectFactory.h"
#include "vtkParametricSpline.h"
#include "vtkPoints.h"

#include <algorithm>
#include <cmath>

vtkStandardNewMacro(vtkFFDMagneticSphere);
vtkCxxSetObjectMacro(vtkFFDMagneticSphere, Path, vtkPoints);

//------------------------------------------------------------------------------------------------------------
vtkFFDMagneticSphere::vtkFFDMagneticSphere()
  : Center{ 0, 0, 0 }
  , Radius(1.0)
  , Strength(1.0)
  , Falloff(2.0)
  , Range(0.0)
  , Mode(ATTRACT)
  , Path(nullptr)
  , Period(1.0)
  , Spline(vtkParametricSpline::New())
{
  this->Spline->ClosedOn();
  this->Spline->ParameterizeByLengthOn();
}

vtkFFDMagneticSphere::~vtkFFDMagneticSphere()
{
  this->SetPath(nullptr);
  this->Spline->Delete();
}

//------------------------------------------------------------------------------------------------------------
vtkMTimeType vtkFFDMagneticSphere::GetMTime()
{
  vtkMTimeType time = this->Superclass::GetMTime();
  return this->Path ? std::max(time, this->Path->GetMTime()) : time;
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDMagneticSphere::GetCenterAt(double t, double center[3])
{
  if (!this->Path || this->Path->GetNumberOfPoints() < 2)
  {
    std::copy(this->Center, this->Center + 3, center);
    return;
  }
  if (this->Spline->GetPoints() != this->Path)
  {
    this->Spline->SetPoints(this->Path); // the spline refits itself when the points change
  }
  double phase = t / this->Period;
  phase -= std::floor(phase);
  double u[3] = { phase, 0, 0 };
  this->Spline->Evaluate(u, center, nullptr);
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDMagneticSphere::GetAcceleration(const double x[3], double t, double acceleration[3])
{
  double center[3];
  this->GetCenterAt(t, center);
  this->GetAccelerationAround(center, x, acceleration);
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDMagneticSphere::GetAccelerationAround(const double center[3], const double x[3], double acceleration[3])
{
  const double toward[3] = { center[0] - x[0], center[1] - x[1], center[2] - x[2] };
  const double d = std::sqrt(toward[0] * toward[0] + toward[1] * toward[1] + toward[2] * toward[2]);
  double magnitude = 0; // divided by d below: a(d) along the unit vector toward / d
  if (d > 0 && !(this->Range > 0 && d > this->Range))
  {
    magnitude = d >= this->Radius ? this->Strength * std::pow(this->Radius / d, this->Falloff) / d
                                  : this->Strength / this->Radius;
  }
  if (this->Mode == REPEL)
  {
    magnitude = -magnitude;
  }
  for (int c = 0; c < 3; ++c)
  {
    acceleration[c] = magnitude * toward[c];
  }
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDMagneticSphere::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Center: (" << this->Center[0] << ", " << this->Center[1] << ", " << this->Center[2] << ")\n";
  os << indent << "Radius: " << this->Radius << "\n";
  os << indent << "Strength: " << this->Strength << "\n";
  os << indent << "Falloff: " << this->Falloff << "\n";
  os << indent << "Range: " << this->Range << "\n";
  os << indent << "Mode: " << (this->Mode == ATTRACT ? "ATTRACT" : "REPEL") << "\n";
  os << indent << "Path: " << this->Path << "\n";
  os << indent << "Period: " << this->Period << "\n";
}
