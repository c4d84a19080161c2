// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkFFDDeformExecutive
 * @brief   vtkFFDDeform's executive: host points on demand when its output was kept on the device
 *
 * Private to the VoxelFFD modules. While vtkFFDDeform's output is kept on the CUDA device for a renderer
 * (vtkFFDDeform::DEVICE_OUTPUT() on the output data object: its points are not the deformed ones), any update
 * that does not carry vtkFFDDeform::KEEP_OUTPUT_ON_DEVICE() (another consumer's, or the caller's Update()) makes
 * it execute again, so that it downloads the deformed points; otherwise it behaves as vtkCompositeDataPipeline.
 */
#ifndef vtkFFDDeformExecutive_h
#define vtkFFDDeformExecutive_h

#include "vtkCompositeDataPipeline.h"
#include "vtkFFDFiltersCoreModule.h" // For export macro

class VTKFFDFILTERSCORE_EXPORT vtkFFDDeformExecutive : public vtkCompositeDataPipeline
{
public:
  static vtkFFDDeformExecutive* New();
  vtkTypeMacro(vtkFFDDeformExecutive, vtkCompositeDataPipeline);

protected:
  vtkFFDDeformExecutive() = default;
  ~vtkFFDDeformExecutive() override = default;

  int NeedToExecuteData(int outputPort, vtkInformationVector** inInfoVec, vtkInformationVector* outInfoVec) override;

private:
  vtkFFDDeformExecutive(const vtkFFDDeformExecutive&) = delete;
  void operator=(const vtkFFDDeformExecutive&) = delete;
};

#endif
