// SPDX-License-Identifier: BSD-3-Clause
#include "vtkFFDEGLRenderWindow.h"

#include "vtkGenericRenderWindowInteractor.h"
#include "vtkObjectFactory.h"
#include "vtkRenderer.h"
#include "vtkRendererCollection.h"
#include "vtkVersionMacros.h"
#include "vtk_glew.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkFFDEGLRenderWindow);

struct vtkFFDEGLRenderWindow::vtkInternals
{
  EGLDisplay Display = EGL_NO_DISPLAY;
  EGLConfig Config = nullptr;
  EGLSurface Surface = EGL_NO_SURFACE;
  EGLContext Context = EGL_NO_CONTEXT;
  int ScreenSize[2] = { 1920, 1080 }; // a pbuffer has no screen: the largest default size
  std::string Capabilities;
};

namespace
{
// The EGL display of each GPU device (EGL_EXT_device_enumeration and EGL_EXT_platform_device), or none.
std::vector<EGLDisplay> DeviceDisplays()
{
  auto queryDevices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
  auto platformDisplay =
    reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
  std::vector<EGLDisplay> displays;
  EGLint count = 0;
  if (!queryDevices || !platformDisplay || !queryDevices(0, nullptr, &count) || count <= 0)
  {
    return displays;
  }
  std::vector<EGLDeviceEXT> devices(static_cast<size_t>(count));
  queryDevices(count, devices.data(), &count);
  for (EGLint d = 0; d < count; ++d)
  {
    displays.push_back(platformDisplay(EGL_PLATFORM_DEVICE_EXT, devices[d], nullptr));
  }
  return displays;
}

// vtkRenderWindow::New() answered by vtkFFDEGLRenderWindow, and vtkRenderWindowInteractor::New() by the generic
// interactor (events given by the program, no event loop): the X one would read the EGL display as an X one.
class vtkFFDEGLRenderWindowFactory : public vtkObjectFactory
{
public:
  static vtkFFDEGLRenderWindowFactory* New()
  {
    auto* factory = new vtkFFDEGLRenderWindowFactory;
    factory->InitializeObjectBase();
    return factory;
  }
  vtkTypeMacro(vtkFFDEGLRenderWindowFactory, vtkObjectFactory);
  const char* GetVTKSourceVersion() override { return VTK_SOURCE_VERSION; }
  const char* GetDescription() override { return "VoxelFFD: render windows through EGL"; }

protected:
  vtkFFDEGLRenderWindowFactory()
  {
    this->RegisterOverride("vtkRenderWindow", "vtkFFDEGLRenderWindow", "offscreen through EGL", 1,
      []() -> vtkObject* { return vtkFFDEGLRenderWindow::New(); });
    this->RegisterOverride("vtkRenderWindowInteractor", "vtkGenericRenderWindowInteractor",
      "events from the program, for an EGL window", 1,
      []() -> vtkObject* { return vtkGenericRenderWindowInteractor::New(); });
  }
};
} // namespace

//------------------------------------------------------------------------------------------------------------
vtkFFDEGLRenderWindow::vtkFFDEGLRenderWindow()
  : Internals(new vtkInternals)
{
  this->ShowWindow = false;
}

vtkFFDEGLRenderWindow::~vtkFFDEGLRenderWindow()
{
  this->Finalize();
  vtkCollectionSimpleIterator it;
  this->Renderers->InitTraversal(it);
  while (vtkRenderer* renderer = this->Renderers->GetNextRenderer(it))
  {
    renderer->SetRenderWindow(nullptr);
  }
}

void vtkFFDEGLRenderWindow::UseForNewRenderWindows()
{
  static bool registered = false;
  if (registered)
  {
    return;
  }
  registered = true;
  vtkObjectFactory::SetAllEnableFlags(0, "vtkRenderWindow");
  vtkObjectFactory::SetAllEnableFlags(0, "vtkRenderWindowInteractor");
  vtkFFDEGLRenderWindowFactory* factory = vtkFFDEGLRenderWindowFactory::New();
  vtkObjectFactory::RegisterFactory(factory);
  factory->Delete();
}

//------------------------------------------------------------------------------------------------------------
bool vtkFFDEGLRenderWindow::OpenDisplay()
{
  vtkInternals& egl = *this->Internals;
  std::vector<EGLDisplay> displays = DeviceDisplays();
  if (const char* index = std::getenv("VOXELFFD_EGL_DEVICE_INDEX"))
  {
    const size_t d = size_t(std::strtoul(index, nullptr, 10));
    displays = d < displays.size() ? std::vector<EGLDisplay>{ displays[d] } : std::vector<EGLDisplay>{};
  }
  displays.push_back(eglGetDisplay(EGL_DEFAULT_DISPLAY)); // without device enumeration
  for (EGLDisplay display : displays)
  {
    EGLint major = 0, minor = 0;
    if (display != EGL_NO_DISPLAY && eglInitialize(display, &major, &minor) &&
      (major > 1 || (major == 1 && minor >= 4)) && eglBindAPI(EGL_OPENGL_API))
    {
      egl.Display = display;
      return true;
    }
  }
  vtkErrorMacro("No EGL display of a GPU device could be initialized for desktop OpenGL (EGL 1.4 or later): "
    << "is a GPU driver with EGL installed, and its vendor file found (__EGL_VENDOR_LIBRARY_FILENAMES)?");
  return false;
}

bool vtkFFDEGLRenderWindow::CreateSurface(int width, int height)
{
  vtkInternals& egl = *this->Internals;
  if (!egl.Config)
  {
    const EGLint wanted[] = { EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RED_SIZE, 8, EGL_GREEN_SIZE, 8, EGL_BLUE_SIZE, 8,
      EGL_ALPHA_SIZE, 8, EGL_DEPTH_SIZE, 24, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE };
    EGLint count = 0;
    if (!eglChooseConfig(egl.Display, wanted, &egl.Config, 1, &count) || count == 0)
    {
      vtkErrorMacro("The EGL display has no pbuffer configuration of 8-bit RGBA, a 24-bit depth and OpenGL.");
      return false;
    }
    // VTK 9.1 draws with OpenGL 3.2 core at least, as its GLX windows ask for.
    const EGLint core[] = { EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 2, EGL_CONTEXT_OPENGL_PROFILE_MASK,
      EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE };
    egl.Context = eglCreateContext(egl.Display, egl.Config, EGL_NO_CONTEXT, core);
    if (egl.Context == EGL_NO_CONTEXT)
    {
      vtkErrorMacro(
        "EGL could not create an OpenGL 3.2 core context (EGL error 0x" << std::hex << eglGetError() << ").");
      return false;
    }
  }
  if (egl.Surface != EGL_NO_SURFACE)
  {
    eglMakeCurrent(egl.Display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroySurface(egl.Display, egl.Surface);
  }
  const EGLint size[] = { EGL_WIDTH, width, EGL_HEIGHT, height, EGL_NONE };
  egl.Surface = eglCreatePbufferSurface(egl.Display, egl.Config, size);
  if (egl.Surface == EGL_NO_SURFACE)
  {
    vtkErrorMacro("EGL could not create a pbuffer of " << width << " x " << height << " pixels.");
    return false;
  }
  this->MakeCurrent();
  return true;
}

void vtkFFDEGLRenderWindow::CreateAWindow()
{
  vtkInternals& egl = *this->Internals;
  const int width = this->Size[0] > 0 ? this->Size[0] : 300;
  const int height = this->Size[1] > 0 ? this->Size[1] : 300;
  if ((egl.Display != EGL_NO_DISPLAY || this->OpenDisplay()) && this->CreateSurface(width, height))
  {
    this->Size[0] = width;
    this->Size[1] = height;
    this->Mapped = 0;
  }
}

void vtkFFDEGLRenderWindow::DestroyWindow()
{
  vtkInternals& egl = *this->Internals;
  if (egl.Display == EGL_NO_DISPLAY)
  {
    return;
  }
  if (egl.Context != EGL_NO_CONTEXT)
  {
    this->MakeCurrent();
    this->ReleaseGraphicsResources(this);
  }
  eglMakeCurrent(egl.Display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  if (egl.Surface != EGL_NO_SURFACE)
  {
    eglDestroySurface(egl.Display, egl.Surface);
  }
  if (egl.Context != EGL_NO_CONTEXT)
  {
    eglDestroyContext(egl.Display, egl.Context);
  }
  // The display is left initialized: EGL hands every window of a device the same one.
  egl.Surface = EGL_NO_SURFACE;
  egl.Context = EGL_NO_CONTEXT;
  egl.Config = nullptr;
  egl.Display = EGL_NO_DISPLAY;
}

//------------------------------------------------------------------------------------------------------------
void vtkFFDEGLRenderWindow::Initialize()
{
  if (this->Internals->Context != EGL_NO_CONTEXT)
  {
    return;
  }
  this->CreateAWindow();
  if (this->Internals->Context == EGL_NO_CONTEXT)
  {
    return;
  }
  this->MakeCurrent();
  vtkCollectionSimpleIterator it;
  this->Renderers->InitTraversal(it);
  while (vtkRenderer* renderer = this->Renderers->GetNextRenderer(it))
  {
    renderer->SetRenderWindow(nullptr);
    renderer->SetRenderWindow(this);
  }
  this->OpenGLInit();
}

void vtkFFDEGLRenderWindow::Finalize()
{
  this->DestroyWindow();
}

void vtkFFDEGLRenderWindow::Start()
{
  this->Initialize();
  this->Superclass::Start();
}

void vtkFFDEGLRenderWindow::Frame()
{
  this->MakeCurrent();
  this->Superclass::Frame();
  if (!this->AbortRender && this->Internals->Surface != EGL_NO_SURFACE)
  {
    eglSwapBuffers(this->Internals->Display, this->Internals->Surface);
  }
}

void vtkFFDEGLRenderWindow::WindowRemap()
{
  this->Finalize();
  this->Initialize();
}

void vtkFFDEGLRenderWindow::SetSize(int width, int height)
{
  const bool changed = this->Size[0] != width || this->Size[1] != height;
  this->Superclass::SetSize(width, height);
  if (changed && this->Internals->Surface != EGL_NO_SURFACE)
  {
    this->CreateSurface(width, height);
  }
}

void vtkFFDEGLRenderWindow::MakeCurrent()
{
  vtkInternals& egl = *this->Internals;
  if (egl.Context != EGL_NO_CONTEXT && egl.Surface != EGL_NO_SURFACE &&
    !eglMakeCurrent(egl.Display, egl.Surface, egl.Surface, egl.Context))
  {
    vtkErrorMacro("eglMakeCurrent failed (EGL error 0x" << std::hex << eglGetError() << ").");
  }
}

void vtkFFDEGLRenderWindow::ReleaseCurrent()
{
  if (this->Internals->Display != EGL_NO_DISPLAY)
  {
    eglMakeCurrent(this->Internals->Display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  }
}

bool vtkFFDEGLRenderWindow::IsCurrent()
{
  return this->Internals->Context != EGL_NO_CONTEXT && eglGetCurrentContext() == this->Internals->Context;
}

void* vtkFFDEGLRenderWindow::GetGenericDisplayId()
{
  return this->Internals->Display;
}

void* vtkFFDEGLRenderWindow::GetGenericContext()
{
  return this->Internals->Context;
}

int* vtkFFDEGLRenderWindow::GetScreenSize()
{
  return this->Internals->ScreenSize;
}

const char* vtkFFDEGLRenderWindow::ReportCapabilities()
{
  vtkInternals& egl = *this->Internals;
  if (egl.Context == EGL_NO_CONTEXT)
  {
    return "no EGL context yet";
  }
  this->MakeCurrent();
  auto text = [](const unsigned char* s) { return s ? reinterpret_cast<const char*>(s) : "?"; };
  std::ostringstream report;
  report << "EGL vendor: " << text(reinterpret_cast<const unsigned char*>(eglQueryString(egl.Display, EGL_VENDOR)))
         << "\nEGL version: " << text(reinterpret_cast<const unsigned char*>(eglQueryString(egl.Display, EGL_VERSION)))
         << "\nGL_VENDOR: " << text(glGetString(GL_VENDOR)) << "\nGL_RENDERER: " << text(glGetString(GL_RENDERER))
         << "\nGL_VERSION: " << text(glGetString(GL_VERSION)) << "\n";
  egl.Capabilities = report.str();
  return egl.Capabilities.c_str();
}

void vtkFFDEGLRenderWindow::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "EGL display: " << this->Internals->Display << "\n";
  os << indent << "EGL context: " << this->Internals->Context << "\n";
}
