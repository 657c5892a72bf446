// libFuzzer target: arbitrary bytes as an OBJ file, then the closed-mesh check on what was read. The only
// acceptable failure is an InputError.

#include <cstddef>
#include <cstdint>
#include <string>

#include "aloft/error.hpp"
#include "aloft/geometry.hpp"
#include "geometry/obj_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const aloft::ObjMesh obj = aloft::parse_obj_text(text, "fuzz.obj");
    (void)aloft::closed_mesh_problem(obj.mesh);
    aloft::check_closed_obj_mesh(obj, "fuzz.obj");
  } catch (const aloft::InputError&) {
  }
  return 0;
}
