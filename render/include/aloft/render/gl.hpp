#pragma once
// OpenGL declarations for the renderer. Functions are called directly (GL_GLEXT_PROTOTYPES, linked
// against libglvnd's libOpenGL): Mesa exports every core entry point, so no loader is needed. Only the
// OpenGL 3.3 core / OpenGL ES 3.0 common subset is used (the WebGL2 feature set): no geometry shaders,
// no explicit uniform locations, no glPolygonMode, no double-precision attributes.

#ifndef GL_GLEXT_PROTOTYPES
#define GL_GLEXT_PROTOTYPES 1
#endif
#include <GL/glcorearb.h>
