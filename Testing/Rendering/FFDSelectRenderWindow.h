// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDSelectRenderWindow.h
 * @brief The image tests' render window: the default one, or vtkFFDEGLRenderWindow where VOXELFFD_RENDER_WINDOW
 * is "egl" (a GPU machine without an X display, Utilities/gpu-rendering.sh), whose GL_RENDERER is then printed.
 */
#ifndef FFDSelectRenderWindow_h
#define FFDSelectRenderWindow_h

#include <cstdlib>
#include <cstring>
#include <iostream>

#ifdef VOXELFFD_HAS_EGL
#include "vtkFFDEGLRenderWindow.h"
#include "vtkNew.h"
#endif

inline void FFDSelectRenderWindow(int*, char***)
{
  const char* wanted = std::getenv("VOXELFFD_RENDER_WINDOW");
  if (!wanted || std::strcmp(wanted, "egl") != 0)
  {
    return;
  }
#ifdef VOXELFFD_HAS_EGL
  vtkFFDEGLRenderWindow::UseForNewRenderWindows();
  vtkNew<vtkFFDEGLRenderWindow> probe;
  probe->Initialize();
  std::cout << probe->ReportCapabilities() << std::flush;
#else
  std::cerr << "VOXELFFD_RENDER_WINDOW=egl: this build has no EGL render window (no EGL was found)\n";
  std::exit(EXIT_FAILURE);
#endif
}

#endif
