#include "gl_program.hpp"

#include <stdexcept>
#include <vector>

namespace aloft::render {

namespace {

GLuint compile(GLenum type, const std::string& source, const char* name) {
  const GLuint s = glCreateShader(type);
  const char* text = source.c_str();
  glShaderSource(s, 1, &text, nullptr);
  glCompileShader(s);
  GLint ok = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    GLint length = 0;
    glGetShaderiv(s, GL_INFO_LOG_LENGTH, &length);
    std::vector<char> log(static_cast<std::size_t>(std::max(length, 1)));
    glGetShaderInfoLog(s, length, nullptr, log.data());
    glDeleteShader(s);
    throw std::runtime_error(std::string("cannot compile the ") + name +
                             (type == GL_VERTEX_SHADER ? " vertex" : " fragment") + " shader: " + log.data());
  }
  return s;
}

}  // namespace

GlProgram::GlProgram(const std::string& vertex, const std::string& fragment, const char* name) {
  const GLuint vs = compile(GL_VERTEX_SHADER, vertex, name);
  GLuint fs = 0;
  try {
    fs = compile(GL_FRAGMENT_SHADER, fragment, name);
  } catch (...) {
    glDeleteShader(vs);
    throw;
  }
  id_ = glCreateProgram();
  glAttachShader(id_, vs);
  glAttachShader(id_, fs);
  glBindAttribLocation(id_, 0, "a_position");
  glBindAttribLocation(id_, 1, "a_normal");
  glLinkProgram(id_);
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint ok = 0;
  glGetProgramiv(id_, GL_LINK_STATUS, &ok);
  if (!ok) {
    GLint length = 0;
    glGetProgramiv(id_, GL_INFO_LOG_LENGTH, &length);
    std::vector<char> log(static_cast<std::size_t>(std::max(length, 1)));
    glGetProgramInfoLog(id_, length, nullptr, log.data());
    glDeleteProgram(id_);
    throw std::runtime_error(std::string("cannot link the ") + name + " shaders: " + log.data());
  }
}

GlProgram::~GlProgram() { glDeleteProgram(id_); }

GLint GlProgram::uniform(const char* name) {
  auto it = uniforms_.find(name);
  if (it != uniforms_.end()) return it->second;
  const GLint location = glGetUniformLocation(id_, name);
  uniforms_.emplace(name, location);
  return location;
}

void check_gl(const char* where) {
  const GLenum e = glGetError();
  if (e != GL_NO_ERROR) throw std::runtime_error(std::string("OpenGL error ") + std::to_string(e) + " in " + where);
}

}  // namespace aloft::render
