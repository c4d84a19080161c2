// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkFFDEGLRenderWindow
 * @brief   offscreen OpenGL rendering through EGL on a GPU device, without an X display
 *
 * Debian's VTK 9.1 renders through GLX, which needs an X server. On a GPU machine without one (a compute node, a
 * container), this window takes an EGL display of a GPU device (EGL_EXT_platform_device; the device that
 * VOXELFFD_EGL_DEVICE_INDEX names, else the first that initializes), a pbuffer surface of the window's size and
 * a desktop OpenGL context on it; VTK draws into its framebuffers as usual, and vtkWindowToImageFilter and
 * vtkTesting read them back. Always offscreen: no interactor, no cursor.
 *
 * UseForNewRenderWindows() makes vtkRenderWindow::New() return this class (an object factory override), and
 * vtkRenderWindowInteractor::New() the generic interactor (the program gives the events), so that a program or a
 * test written for any render window renders through EGL unchanged. Debian's GLEW is built for
 * GLX and reports "missing GLX display" once it has loaded the OpenGL functions: a program that renders through
 * this window links a small library ahead of GLEW that lets that one error pass (Utilities/egl-glew/, as the image
 * tests' driver does).
 */
#ifndef vtkFFDEGLRenderWindow_h
#define vtkFFDEGLRenderWindow_h

#include "vtkFFDRenderingEGLModule.h" // For export macro
#include "vtkOpenGLRenderWindow.h"

#include <memory> // For std::unique_ptr

class VTKFFDRENDERINGEGL_EXPORT vtkFFDEGLRenderWindow : public vtkOpenGLRenderWindow
{
public:
  static vtkFFDEGLRenderWindow* New();
  vtkTypeMacro(vtkFFDEGLRenderWindow, vtkOpenGLRenderWindow);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// Registers an object factory by which vtkRenderWindow::New() returns a vtkFFDEGLRenderWindow and
  /// vtkRenderWindowInteractor::New() a vtkGenericRenderWindowInteractor (once).
  static void UseForNewRenderWindows();

  void Start() override;
  void Frame() override;
  void Initialize() override;
  void Finalize() override;
  void SetSize(int width, int height) override;
  void SetSize(int a[2]) override { this->SetSize(a[0], a[1]); }
  void MakeCurrent() override;
  void ReleaseCurrent() override;
  bool IsCurrent() override;
  void SetShowWindow(bool) override {} // always offscreen
  void SetFullScreen(vtkTypeBool) override {}
  void WindowRemap() override;
  void* GetGenericDisplayId() override;
  void* GetGenericContext() override;
  int* GetScreenSize() VTK_SIZEHINT(2) override;
  const char* ReportCapabilities() override;

protected:
  vtkFFDEGLRenderWindow();
  ~vtkFFDEGLRenderWindow() override;

  void CreateAWindow() override;
  void DestroyWindow() override;

private:
  vtkFFDEGLRenderWindow(const vtkFFDEGLRenderWindow&) = delete;
  void operator=(const vtkFFDEGLRenderWindow&) = delete;

  bool OpenDisplay();
  bool CreateSurface(int width, int height);

  struct vtkInternals;
  std::unique_ptr<vtkInternals> Internals;
};

#endif
