// A hand-written Wavefront OBJ reader: vertices and faces only, with line and column numbers in its
// errors. It reads untrusted bytes: every token is bounds-checked, numbers are parsed with from_chars
// (no locale, no exceptions), and the work is linear in the input's length.

#include "geometry/obj_reader.hpp"

#include <cerrno>
#include <charconv>
#include <climits>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string_view>
#include <system_error>
#include <vector>

#include "aloft/error.hpp"
#include "aloft/geometry.hpp"
#include "aloft/decimal_number.hpp"
#include "common/printable.hpp"
#include "common/regular_file.hpp"

namespace aloft {
namespace {

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\v' || c == '\f'; }

// 1-based column of byte `offset` in a line; lines longer than INT_MAX bytes report INT_MAX.
int column_of(size_t offset) {
  return offset < static_cast<size_t>(INT_MAX) ? static_cast<int>(offset) + 1 : INT_MAX;
}

// A whitespace-separated word of a line and its 1-based column (in bytes).
struct Token {
  std::string_view text;
  int column = 0;
};

// The token quoted for a message: at most 40 bytes (common/printable.hpp).
std::string quoted(std::string_view s) {
  std::string out = "'";
  out += printable(s, 40);
  return out += "'";
}

// A whole token as a decimal integer (optional sign).
bool parse_integer(std::string_view s, long long& value, bool& overflow) {
  s = without_plus(s);
  const char* end = s.data() + s.size();
  const auto r = std::from_chars(s.data(), end, value);
  overflow = r.ec == std::errc::result_out_of_range && r.ptr == end;
  return !s.empty() && r.ec == std::errc() && r.ptr == end;
}

class ObjParser {
 public:
  explicit ObjParser(const std::string& file) : file_(file) {}

  ObjMesh parse(const std::string& text) {
    // UTF-16 (whose byte-order marks are FF FE and FE FF) puts a NUL beside every ASCII character, which
    // would read as lines of unknown statements and end in "file has no faces".
    if (text.size() >= 2 && ((text[0] == '\xff' && text[1] == '\xfe') || (text[0] == '\xfe' && text[1] == '\xff')))
      fail(1, 1, "the file is UTF-16 (it starts with a UTF-16 byte-order mark); OBJ files must be ASCII or UTF-8");
    // A UTF-8 byte-order mark is not part of the first line (it would make its keyword unknown).
    size_t pos = text.starts_with("\xef\xbb\xbf") ? 3 : 0;
    int line = 0;
    while (pos < text.size()) {
      // Lines end with \n, \r\n or \r.
      size_t end = pos;
      while (end < text.size() && text[end] != '\n' && text[end] != '\r') ++end;
      if (line == INT_MAX) fail(line, 0, "file has too many lines");
      ++line;
      if (const void* nul = std::memchr(text.data() + pos, '\0', end - pos))
        fail(line, column_of(static_cast<const char*>(nul) - (text.data() + pos)),
             "NUL byte: the file is UTF-16 or not text; OBJ files must be ASCII or UTF-8");
      parse_line(std::string_view(text.data() + pos, end - pos), line);
      // Skip the terminator text[end]: '\n', '\r', or the pair "\r\n".
      pos = end;
      if (pos < text.size()) {
        const bool carriage_return = text[pos] == '\r';
        ++pos;
        if (carriage_return && pos < text.size() && text[pos] == '\n') ++pos;
      }
    }
    if (obj_.mesh.triangles.empty()) fail(0, 0, "file has no faces");
    return std::move(obj_);
  }

 private:
  [[noreturn]] void fail(int line, int column, const std::string& problem) const {
    throw InputError(file_, SourcePlace{"", line, column}, problem);
  }

  // Splits the line (up to a '#' comment) into tokens_.
  void tokenize(std::string_view line) {
    tokens_.clear();
    const size_t hash = line.find('#');
    if (hash != std::string_view::npos) line = line.substr(0, hash);
    size_t i = 0;
    while (i < line.size()) {
      while (i < line.size() && is_space(line[i])) ++i;
      if (i >= line.size()) break;
      const size_t start = i;
      while (i < line.size() && !is_space(line[i])) ++i;
      tokens_.push_back({line.substr(start, i - start), column_of(start)});
    }
  }

  void parse_line(std::string_view text, int line) {
    tokenize(text);
    if (tokens_.empty()) return;
    const std::string_view keyword = tokens_[0].text;
    if (keyword == "v")
      parse_vertex(line, column_of(text.size()));
    else if (keyword == "f")
      parse_face(line);
    // Everything else (vn, vt, vp, o, g, s, usemtl, mtllib, l, p, curves...) carries nothing we use.
  }

  // "v x y z [w]" (some writers append colours "r g b": further numbers are accepted and ignored).
  void parse_vertex(int line, int end_column) {
    if (tokens_.size() < 4)
      fail(line, end_column,
           "expected 3 coordinates after 'v', got " + std::to_string(tokens_.size() - 1));
    Vec3 p;
    for (size_t k = 1; k < tokens_.size(); ++k) {
      double value = 0;
      switch (parse_double(tokens_[k].text, value)) {
        case NumberResult::ok:
          break;
        case NumberResult::not_a_number:
          fail(line, tokens_[k].column, "expected a number after 'v', got " + quoted(tokens_[k].text));
        case NumberResult::not_finite:
          fail(line, tokens_[k].column, "non-finite coordinate " + quoted(tokens_[k].text));
      }
      if (k <= 3) p[static_cast<int>(k - 1)] = value;
    }
    if (obj_.mesh.vertices.size() >= static_cast<size_t>(INT_MAX)) fail(line, 1, "too many vertices");
    obj_.mesh.vertices.push_back(p);
  }

  // One face vertex "a", "a/b", "a/b/c" or "a//c": returns the 0-based vertex index.
  int face_vertex(const Token& token, int line) {
    const std::string_view s = token.text;
    const size_t slash = s.find('/');
    const std::string_view index_text = s.substr(0, slash);
    // The texture and normal indices, if any, must be integers (or empty) but are not used.
    if (slash != std::string_view::npos) {
      std::string_view rest = s.substr(slash + 1);
      const size_t slash2 = rest.find('/');
      const std::string_view tex = rest.substr(0, slash2);
      const std::string_view normal = slash2 == std::string_view::npos ? std::string_view() : rest.substr(slash2 + 1);
      long long ignored = 0;
      bool overflow = false;
      const bool tex_ok = tex.empty() ? slash2 != std::string_view::npos : parse_integer(tex, ignored, overflow);
      const bool normal_ok = slash2 == std::string_view::npos || parse_integer(normal, ignored, overflow);
      if (!tex_ok || !normal_ok) fail(line, token.column, "malformed face vertex " + quoted(s));
    }
    long long index = 0;
    bool overflow = false;
    const long long count = static_cast<long long>(obj_.mesh.vertices.size());
    if (!parse_integer(index_text, index, overflow)) {
      if (overflow)
        fail(line, token.column,
             "face index " + quoted(index_text) + " out of range (" + std::to_string(count) + " vertices so far)");
      fail(line, token.column, "malformed face vertex " + quoted(s));
    }
    if (index == 0) fail(line, token.column, "face index 0 is invalid: OBJ indices start at 1");
    // Positive indices count from 1; negative ones back from the latest vertex (-1 is the last).
    const long long resolved = index > 0 ? index - 1 : count + index;
    if (resolved < 0 || resolved >= count)
      fail(line, token.column,
           "face index " + std::to_string(index) + " out of range (" + std::to_string(count) + " vertices so far)");
    return static_cast<int>(resolved);
  }

  void parse_face(int line) {
    if (tokens_.size() < 4)
      fail(line, tokens_[0].column,
           "face with fewer than 3 vertices (" + std::to_string(tokens_.size() - 1) + ")");
    face_.clear();
    for (size_t k = 1; k < tokens_.size(); ++k) face_.push_back(face_vertex(tokens_[k], line));
    // Fan from the first vertex: exact for convex planar polygons, the usual OBJ convention.
    for (size_t k = 1; k + 1 < face_.size(); ++k) {
      obj_.mesh.triangles.push_back({face_[0], face_[k], face_[k + 1]});
      obj_.faces.push_back({line, tokens_[0].column});
    }
  }

  const std::string& file_;
  ObjMesh obj_;
  std::vector<Token> tokens_;  // reused across lines
  std::vector<int> face_;      // reused across faces
};

}  // namespace

ObjMesh parse_obj_text(const std::string& text, const std::string& file_name_for_messages) {
  return ObjParser(file_name_for_messages).parse(text);
}

ObjMesh read_obj(const std::string& path) {
  require_regular_file(path);  // a directory, a FIFO or /dev/zero (read until memory ran out)
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    const int err = errno;
    throw InputError(path, {}, std::string("cannot open file: ") + (err ? std::strerror(err) : "unknown error"));
  }
  std::ostringstream content;
  content << in.rdbuf();
  if (in.bad()) throw InputError(path, {}, "cannot read file");
  return parse_obj_text(content.str(), path);
}

}  // namespace aloft
