#pragma once
// Running the `aloft` command line from tests (its path is the macro ALOFT_CLI, set by tests/CMakeLists.txt),
// a shell-safe quote for paths, and a whole-file reader.

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace aloft::test {

struct CliResult {
  int code = -1;       // exit status; -1 when it could not run or did not exit normally
  std::string output;  // stdout and stderr together
};

// `aloft ARGUMENTS` through the shell (arguments are not quoted: quote paths with shell_quote).
inline CliResult run_aloft(const std::string& arguments) {
  const std::string command = std::string(ALOFT_CLI) + " " + arguments + " 2>&1";
  CliResult r;
  std::FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) return r;
  std::array<char, 4096> buffer;
  std::size_t n;
  while ((n = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0) r.output.append(buffer.data(), n);
  const int status = ::pclose(pipe);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

// `s` in single quotes for a POSIX shell (a quote inside becomes '\'').
inline std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// The whole file as bytes ("" when it cannot be opened).
inline std::string read_file(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace aloft::test
