#pragma once
// A linked GLSL program with named uniforms, and a GL error check that throws.

#include <string>
#include <unordered_map>

#include "aloft/render/gl.hpp"

namespace aloft::render {

class GlProgram {
 public:
  // Compiles and links; attribute 0 is "a_position", 1 is "a_normal". Throws std::runtime_error with the
  // driver's log on failure.
  GlProgram(const std::string& vertex, const std::string& fragment, const char* name);
  ~GlProgram();
  GlProgram(const GlProgram&) = delete;
  GlProgram& operator=(const GlProgram&) = delete;

  void use() const { glUseProgram(id_); }
  GLint uniform(const char* name);  // -1 when the driver optimised it away (setting it is then a no-op)

 private:
  GLuint id_ = 0;
  std::unordered_map<std::string, GLint> uniforms_;
};

// Throws std::runtime_error naming `where` if glGetError reports anything.
void check_gl(const char* where);

}  // namespace aloft::render
