// One include for OpenGL 4.5 core. GL_GLEXT_PROTOTYPES is defined by the build: with glvnd,
// libOpenGL exports every GL 4.5 entry point on Mesa and NVIDIA alike, so no loader is needed.
#pragma once
#include <GL/gl.h>
#include <GL/glext.h>
