/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * Linked ahead of GLEW where VTK renders through EGL (vtkFFDEGLRenderWindow) with a GLEW built for GLX, as Debian's is:
 * GLEW's glewInit() loads the OpenGL functions, then fails with GLEW_ERROR_NO_GLX_DISPLAY because no X display
 * exists, and VTK gives up. This glewInit() calls GLEW's and lets that one error pass: the functions are loaded
 * (through libglvnd's dispatch, which serves EGL's contexts too), and only GLX's extensions are unknown, which an
 * EGL window never uses. Every other result is returned as it is.
 */
#define _GNU_SOURCE
#include <dlfcn.h>

#define FFD_GLEW_OK 0
#define FFD_GLEW_ERROR_NO_GLX_DISPLAY 4

unsigned int glewInit(void)
{
  unsigned int (*glew)(void) = (unsigned int (*)(void))dlsym(RTLD_NEXT, "glewInit");
  if (!glew)
  {
    return FFD_GLEW_ERROR_NO_GLX_DISPLAY;
  }
  const unsigned int result = glew();
  return result == FFD_GLEW_ERROR_NO_GLX_DISPLAY ? FFD_GLEW_OK : result;
}
