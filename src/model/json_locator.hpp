#pragma once
// A small scanner over JSON text that finds where every value is: its path in the syntax
// `components[2].shapes[0].sphere.radius` (object keys joined by '.', array indices in brackets, the root
// is "") and its 1-based line and column. nlohmann-json gives the values but not their places; this gives
// the places, so that every error can point into the file.
//
// Invariants: every function here runs in time linear in the text (plus the size of what it returns),
// uses no recursion and never reads out of bounds, whatever the bytes: the text is expected to be valid
// JSON (nlohmann has already accepted it), anything else is scanned as far as it makes sense.
// Lines are counted by '\n'; columns count UTF-8 code points, so a tab or an 'é' is one column.

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

#include "aloft/spec.hpp"

namespace aloft::internal {

struct LineColumn {
  int line = 1;    // 1-based
  int column = 1;  // 1-based, in code points
};

// Line and column of byte `offset` of `text`; an offset at or past the end gives the place just after
// the last character.
LineColumn line_column_at(std::string_view text, std::size_t offset);

// Byte offset of the first '[' or '{' (outside strings) that opens a level of nesting deeper than
// `max_depth`, or nothing. Run before a recursive consumer sees the text.
std::optional<std::size_t> find_excess_nesting(std::string_view text, int max_depth);

// A key written twice in one object (nlohmann silently keeps the last one).
struct DuplicateKey {
  std::string object_path;  // path of the object holding the key twice
  std::string key;
  LineColumn second;        // where the second occurrence of the key starts (its opening quote)
  LineColumn first;         // where the first one does
};

struct JsonLocation {
  SourceMap map;                          // every value's path -> its first character
  std::optional<DuplicateKey> duplicate;  // the first repeated key in document order
};

JsonLocation locate_json(std::string_view text);

// The path of the last value that starts at or before byte `offset` (for a scalar, the value holding
// that byte), or "" when there is none.
std::string json_path_at(std::string_view text, std::size_t offset);

}  // namespace aloft::internal
