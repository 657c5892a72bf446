#pragma once
// GLSL sources, written in the common subset of GLSL 3.30 core and GLSL ES 3.00 (WebGL2): the version
// line (and ES precision qualifiers) are prepended by glsl_source().

#include <string>

namespace aloft::render::shaders {

// "#version 330 core" or "#version 300 es" + precisions, then `defines` ("#define X\n" lines), then `body`.
std::string glsl_source(const std::string& body, bool gles, const std::string& defines = "");

extern const char* const kShadowFunction;   // lit_fraction(); put before the fragment shaders that use it
extern const char* const kLitVertex;
extern const char* const kLitFragment;
extern const char* const kShadowedRoomFragment;
extern const char* const kCopyFragment;
extern const char* const kDepthVertex;
extern const char* const kDepthFragment;
extern const char* const kLineVertex;
extern const char* const kLineFragment;

}  // namespace aloft::render::shaders
