#pragma once
// Internal: the Wavefront OBJ parser behind read_obj(), callable on text in memory (for the fuzzer and
// tests).

#include <string>

#include "aloft/geometry.hpp"

namespace aloft {

// Parses OBJ text: "v x y z [w ...]" vertices and "f a b c ..." faces (a, a/b, a/b/c or a//c, negative
// indices relative to the vertices so far), faces of more than 3 vertices fanned from their first vertex.
// Other statements, comments and blank lines are ignored. Lines end with \n, \r\n or \r. The text is
// ASCII or UTF-8 (a leading UTF-8 byte-order mark is skipped); UTF-16 (its byte-order mark at 1:1, or
// a NUL byte where it is) is refused.
// Throws InputError(file_name_for_messages, {"", line, column}, problem) on malformed input; never
// crashes or hangs on arbitrary bytes. Runs in time linear in the text's length. Each triangle's place
// (ObjMesh::faces) is that of its face's 'f'.
ObjMesh parse_obj_text(const std::string& text, const std::string& file_name_for_messages);

}  // namespace aloft
