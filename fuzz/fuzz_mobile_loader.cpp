// libFuzzer target: arbitrary bytes as a mobile file, parsed and compiled. The only acceptable failure is
// an InputError; anything else (a crash, a sanitizer report, another exception, a hang) is a bug.
// Mesh paths resolve against a directory that does not exist, so a relative "obj" never reads a file.

#include <cstddef>
#include <cstdint>
#include <string>

#include "aloft/error.hpp"
#include "aloft/model.hpp"
#include "aloft/spec.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const aloft::MobileSpec spec = aloft::parse_mobile_text(text, "fuzz.json", "/nonexistent-aloft-fuzz-dir");
    (void)aloft::compile(spec);
  } catch (const aloft::InputError&) {
  }
  return 0;
}
