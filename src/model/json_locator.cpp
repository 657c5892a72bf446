#include "model/json_locator.hpp"

#include <iterator>
#include <map>
#include <memory>
#include <unordered_map>
#include <utility>
#include <vector>

namespace aloft::internal {
namespace {

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

// A byte that starts a code point (anything but a UTF-8 continuation byte 10xxxxxx).
bool starts_code_point(char c) { return (static_cast<unsigned char>(c) & 0xC0) != 0x80; }

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

void append_utf8(std::string& out, unsigned cp) {
  if (cp < 0x80) {
    out += static_cast<char>(cp);
  } else if (cp < 0x800) {
    out += static_cast<char>(0xC0 | (cp >> 6));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  } else if (cp < 0x10000) {
    out += static_cast<char>(0xE0 | (cp >> 12));
    out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  } else {
    out += static_cast<char>(0xF0 | (cp >> 18));
    out += static_cast<char>(0x80 | ((cp >> 12) & 0x3F));
    out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  }
}

// The keys of one open object, for finding duplicates in time linear overall: a short list searched
// linearly while the object is small (the usual case, no allocation once warm), a hash map past that.
class KeySet {
 public:
  static constexpr std::size_t kSmall = 16;

  void clear() {
    small_.clear();
    large_.reset();
  }

  // Adds `key` first seen at `place`; returns the place of an earlier occurrence if there was one.
  std::optional<LineColumn> insert(const std::string& key, LineColumn place) {
    if (large_) {
      auto [it, added] = large_->emplace(key, place);
      if (!added) return it->second;
      return std::nullopt;
    }
    for (const auto& [k, p] : small_)
      if (k == key) return p;
    small_.emplace_back(key, place);
    if (small_.size() > kSmall) {
      large_ = std::make_unique<std::unordered_map<std::string, LineColumn>>(small_.begin(), small_.end());
      small_.clear();
    }
    return std::nullopt;
  }

 private:
  std::vector<std::pair<std::string, LineColumn>> small_;
  std::unique_ptr<std::unordered_map<std::string, LineColumn>> large_;
};

// Walks the text once, calling sink.value(path, offset, place) for every value (in document order) and
// sink.duplicate(...) for every repeated key; either may return false to stop the walk.
template <class Sink>
class Scanner {
 public:
  Scanner(std::string_view text, Sink& sink) : text_(text), sink_(sink) {}

  void run() {
    bool want_value = true;  // else: just after a value
    while (true) {
      skip_space();
      if (want_value) {
        if (at_end()) return;
        if (!sink_.value(path_, pos_, here())) return;
        const char c = text_[pos_];
        if (c == '{') {
          advance();
          open(true);
          skip_space();
          if (peek() == '}') {
            advance();
            close();
            want_value = false;
          } else if (!begin_member()) {
            return;
          }
        } else if (c == '[') {
          advance();
          open(false);
          skip_space();
          if (peek() == ']') {
            advance();
            close();
            want_value = false;
          } else {
            path_ += "[0]";
          }
        } else if (c == '"') {
          skip_string();
          want_value = false;
        } else if (c == ',' || c == ':' || c == ']' || c == '}') {
          return;  // not JSON
        } else {
          skip_scalar();  // consumes at least c
          want_value = false;
        }
      } else {
        if (depth_ == 0 || at_end()) return;
        Frame& top = frames_[depth_ - 1];
        path_.resize(top.path_length);
        const char c = text_[pos_];
        if (c == ',') {
          advance();
          if (top.is_object) {
            if (!begin_member()) return;
          } else {
            ++top.index;
            path_ += '[';
            path_ += std::to_string(top.index);
            path_ += ']';
          }
          want_value = true;
        } else if (c == (top.is_object ? '}' : ']')) {
          advance();
          close();
        } else {
          return;  // not JSON
        }
      }
    }
  }

 private:
  struct Frame {
    bool is_object = false;
    std::size_t index = 0;        // of the current array element
    std::size_t path_length = 0;  // of the container's own path
    KeySet keys;
  };

  bool at_end() const { return pos_ >= text_.size(); }
  char peek() const { return at_end() ? '\0' : text_[pos_]; }
  LineColumn here() const { return {line_, column_}; }

  void advance() {
    const char c = text_[pos_++];
    if (c == '\n') {
      ++line_;
      column_ = 1;
    } else if (pos_ < text_.size() ? starts_code_point(text_[pos_]) : true) {
      // The column moves once the whole code point has been passed.
      ++column_;
    }
  }

  void skip_space() {
    while (!at_end() && is_space(text_[pos_])) advance();
  }

  void skip_scalar() {
    do advance();
    while (!at_end() && !is_space(text_[pos_]) && text_[pos_] != ',' && text_[pos_] != ']' &&
           text_[pos_] != '}' && text_[pos_] != ':' && text_[pos_] != '"' && text_[pos_] != '[' &&
           text_[pos_] != '{');
  }

  void skip_string() {
    advance();  // the opening quote
    while (!at_end()) {
      const char c = text_[pos_];
      advance();
      if (c == '"') return;
      if (c == '\\' && !at_end()) advance();
    }
  }

  // Reads four hex digits after "\u"; -1 if they are not there.
  long read_hex4() {
    if (text_.size() - pos_ < 4) return -1;
    long v = 0;
    for (int i = 0; i < 4; ++i) {
      const int d = hex_digit(text_[pos_ + i]);
      if (d < 0) return -1;
      v = v * 16 + d;
    }
    for (int i = 0; i < 4; ++i) advance();
    return v;
  }

  // Decodes the string starting at the opening quote under the cursor (as nlohmann does).
  std::string read_string() {
    std::string out;
    advance();
    while (!at_end()) {
      const char c = text_[pos_];
      advance();
      if (c == '"') break;
      if (c != '\\') {
        out += c;
        continue;
      }
      if (at_end()) break;
      const char e = text_[pos_];
      advance();
      switch (e) {
        case 'b': out += '\b'; break;
        case 'f': out += '\f'; break;
        case 'n': out += '\n'; break;
        case 'r': out += '\r'; break;
        case 't': out += '\t'; break;
        case 'u': {
          long cp = read_hex4();
          if (cp < 0) break;
          if (cp >= 0xD800 && cp <= 0xDBFF && text_.substr(pos_, 2) == "\\u") {
            const std::size_t save_pos = pos_;
            const int save_line = line_, save_column = column_;
            advance();
            advance();
            const long low = read_hex4();
            if (low >= 0xDC00 && low <= 0xDFFF) {
              cp = 0x10000 + ((cp - 0xD800) << 10) + (low - 0xDC00);
            } else {
              pos_ = save_pos;
              line_ = save_line;
              column_ = save_column;
            }
          }
          append_utf8(out, static_cast<unsigned>(cp));
          break;
        }
        default: out += e;  // '"', '\\', '/'
      }
    }
    return out;
  }

  void open(bool is_object) {
    if (depth_ == frames_.size()) frames_.emplace_back();
    Frame& f = frames_[depth_++];
    f.is_object = is_object;
    f.index = 0;
    f.path_length = path_.size();
    f.keys.clear();
  }

  void close() {
    --depth_;
    path_.resize(frames_[depth_].path_length);
  }

  // At the first key of an object member (after '{' or ','): reads `"key" :` and extends the path.
  bool begin_member() {
    skip_space();
    if (peek() != '"') return false;
    const LineColumn key_place = here();
    std::string key = read_string();
    skip_space();
    if (peek() != ':') return false;
    advance();
    Frame& top = frames_[depth_ - 1];
    if (auto first = top.keys.insert(key, key_place)) {
      if (!sink_.duplicate(path_, key, key_place, *first)) return false;
    }
    if (!path_.empty()) path_ += '.';
    path_ += key;
    return true;
  }

  std::string_view text_;
  Sink& sink_;
  std::size_t pos_ = 0;
  int line_ = 1;
  int column_ = 1;
  std::string path_;
  std::vector<Frame> frames_;  // frames_[0 .. depth_) are open; the rest are kept for reuse
  std::size_t depth_ = 0;
};

struct MapSink {
  JsonLocation& out;
  std::map<std::string, SourcePlace>::iterator last = out.map.places.end();
  bool value(const std::string& path, std::size_t, LineColumn at) {
    // Document order is often sorted order for a few values in a row (an array's elements, a key and
    // what is under it): hint "just after the previous one". The place's own path is left empty, since
    // it is the map's key (SourceMap::locate fills it in); that halves the allocations on big files.
    auto& places = out.map.places;
    last = places.emplace_hint(last == places.end() ? last : std::next(last), path, SourcePlace{{}, at.line, at.column});
    return true;
  }
  bool duplicate(const std::string& object_path, const std::string& key, LineColumn second,
                 LineColumn first) {
    if (!out.duplicate) out.duplicate = DuplicateKey{object_path, key, second, first};
    return true;
  }
};

struct PathAtSink {
  std::size_t offset;
  std::string path;
  bool value(const std::string& p, std::size_t at, LineColumn) {
    if (at > offset) return false;
    path = p;
    return true;
  }
  bool duplicate(const std::string&, const std::string&, LineColumn, LineColumn) { return true; }
};

}  // namespace

LineColumn line_column_at(std::string_view text, std::size_t offset) {
  LineColumn lc;
  const std::size_t end = offset < text.size() ? offset : text.size();
  for (std::size_t i = 0; i < end; ++i) {
    if (text[i] == '\n') {
      ++lc.line;
      lc.column = 1;
    } else if (i + 1 < text.size() ? starts_code_point(text[i + 1]) : true) {
      ++lc.column;
    }
  }
  return lc;
}

std::optional<std::size_t> find_excess_nesting(std::string_view text, int max_depth) {
  int depth = 0;
  bool in_string = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\') ++i;
      else if (c == '"') in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > max_depth) return i;
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  return std::nullopt;
}

JsonLocation locate_json(std::string_view text) {
  JsonLocation out;
  MapSink sink{out};
  Scanner<MapSink>(text, sink).run();
  return out;
}

std::string json_path_at(std::string_view text, std::size_t offset) {
  PathAtSink sink{offset, {}};
  Scanner<PathAtSink>(text, sink).run();
  return sink.path;
}

}  // namespace aloft::internal
