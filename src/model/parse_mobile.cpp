// Reading a mobile file: JSON text -> MobileSpec, with every error pointing at the JSON path, line and
// column of the offending value. The format is documented in docs/mobile-format.md; the keys accepted in
// each object are in format_keys.hpp (and docs/mobile-format.schema.json, checked against them).
//
// Steps: (1) refuse nesting deeper than kMaxNesting before anything recursive sees the text; (2) parse
// with nlohmann-json through a SAX wrapper that keeps the byte position of a syntax error; (3) locate
// every value (json_locator), refusing duplicate keys; (4) convert, checking form, types and ranges.
// All of it is linear in the size of the text (plus the OBJ files it reads).

#include <algorithm>
#include <cerrno>
#include <cctype>
#include <charconv>
#include <cstdint>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <future>
#include <numbers>
#include <optional>
#include <span>
#include <sstream>
#include <string_view>
#include <system_error>
#include <tuple>
#include <vector>

#include <nlohmann/json.hpp>

#include "aloft/geometry.hpp"
#include "aloft/spec.hpp"
#include "common/regular_file.hpp"
#include "model/format_keys.hpp"
#include "model/json_locator.hpp"

namespace aloft {

SourcePlace SourceMap::locate(const std::string& path) const {
  std::string p = path;
  while (true) {
    if (auto it = places.find(p); it != places.end()) return SourcePlace{path, it->second.line, it->second.column};
    if (p.empty()) return SourcePlace{path, 0, 0};
    const std::size_t cut = p.find_last_of(".[");
    p.resize(cut == std::string::npos ? 0 : cut);  // the parent: drop ".key" or "[i]"
  }
}

InputError MobileSpec::error_at(const std::string& path, const std::string& problem) const {
  return InputError(file, source.locate(path), problem);
}

namespace {

using json = nlohmann::json;
using Keys = std::span<const std::string_view>;
namespace format_keys = internal::format_keys;

// Deeper nesting is refused before parsing: no mobile needs more than 6 levels, and recursive consumers
// of the document must not overflow the stack.
constexpr int kMaxNesting = 64;

// ---------------------------------------------------------------------------------------------------
// Parsing: nlohmann's DOM builder behind a SAX wrapper that remembers where a syntax error happened.

// What nlohmann said about the first error, and where.
struct SyntaxError {
  std::size_t position = 0;  // characters read when it stopped, the offending one included
  std::string token;         // the last token read, as nlohmann spells it
  int id = 0;                // nlohmann's exception id: 101.. syntax, 406 number overflow
  std::string message;       // nlohmann's what()
};

class DomBuilder {
 public:
  explicit DomBuilder(json& root) : dom_(root, false) {}

  bool null() { return dom_.null(); }
  bool boolean(bool v) { return dom_.boolean(v); }
  bool number_integer(json::number_integer_t v) { return dom_.number_integer(v); }
  bool number_unsigned(json::number_unsigned_t v) { return dom_.number_unsigned(v); }
  bool number_float(json::number_float_t v, const json::string_t& s) { return dom_.number_float(v, s); }
  bool string(json::string_t& v) { return dom_.string(v); }
  bool binary(json::binary_t& v) { return dom_.binary(v); }
  bool start_object(std::size_t n) { return dom_.start_object(n); }
  bool key(json::string_t& k) { return dom_.key(k); }
  bool end_object() { return dom_.end_object(); }
  bool start_array(std::size_t n) { return dom_.start_array(n); }
  bool end_array() { return dom_.end_array(); }

  bool parse_error(std::size_t position, const std::string& token, const nlohmann::detail::exception& ex) {
    error = SyntaxError{position, token, ex.id, ex.what()};
    return false;  // stop
  }

  std::optional<SyntaxError> error;

 private:
  nlohmann::detail::json_sax_dom_parser<json> dom_;
};

// nlohmann's explanation without its "[json.exception.parse_error.101] parse error at line 1, column 5:
// syntax error while parsing object - " preamble.
std::string plain_syntax_message(const std::string& what) {
  std::string s = what;
  if (auto p = s.find(" column "); p != std::string::npos) {
    if (auto colon = s.find(": ", p); colon != std::string::npos) s = s.substr(colon + 2);
  }
  if (s.rfind("syntax error while parsing ", 0) == 0) {
    if (auto dash = s.find(" - "); dash != std::string::npos) s = s.substr(dash + 3);
  }
  return s;
}

json parse_json(const std::string& text, const std::string& file) {
  if (auto deep = internal::find_excess_nesting(text, kMaxNesting)) {
    const auto at = internal::line_column_at(text, *deep);
    throw InputError(file, SourcePlace{"", at.line, at.column},
                     "nesting deeper than " + std::to_string(kMaxNesting) + " levels of arrays and objects");
  }
  json root;
  DomBuilder builder(root);
  json::sax_parse(text, &builder, json::input_format_t::json, /*strict=*/true, /*ignore_comments=*/false);
  if (!builder.error) return root;
  const SyntaxError& e = *builder.error;

  // Where the offending token starts (nlohmann's token may hold more than the token: then use the
  // last character read).
  const std::size_t last = e.position > 0 ? e.position - 1 : 0;
  const std::size_t start = e.token.size() <= e.position ? e.position - e.token.size() : last;
  if (e.id == 406) {
    // A number too large for a double (1e999): nlohmann would make it infinite. Point at it by path.
    const auto at = internal::line_column_at(text, start);
    throw InputError(file, SourcePlace{internal::json_path_at(text, start), at.line, at.column},
                     "must be a finite number, got " + e.token.substr(0, 40));
  }
  // nlohmann reports the last character it read; for a whole token in the wrong place (`"a" "b"`),
  // point at the token's start instead.
  std::size_t where = last;
  for (const char* token : {"string", "number", "true", "false", "null"}) {
    if (e.message.find("unexpected " + std::string(token) + " literal") != std::string::npos) where = start;
  }
  const auto at = internal::line_column_at(text, where);
  throw InputError(file, SourcePlace{"", at.line, at.column}, plain_syntax_message(e.message));
}

// ---------------------------------------------------------------------------------------------------
// Small helpers for messages.

// A JSON path, built without allocating: each level refers to its parent, which outlives it (it is a
// parameter or local of a caller). Spelt out as a string only for an error or a path kept in the spec.
class Path {
 public:
  Path() = default;  // the root, ""
  Path(const Path& parent, std::string_view key) : parent_(&parent), key_(key) {}
  Path(const Path& parent, std::size_t index) : parent_(&parent), index_(index), is_index_(true) {}

  std::string str() const {
    std::string s = parent_ ? parent_->str() : std::string();
    if (!parent_) return s;
    if (is_index_) return s + "[" + std::to_string(index_) + "]";
    return s.empty() ? std::string(key_) : s + "." + std::string(key_);
  }

 private:
  const Path* parent_ = nullptr;
  std::string_view key_;
  std::size_t index_ = 0;
  bool is_index_ = false;
};

Path join(const Path& path, std::string_view key) { return Path(path, key); }
Path item(const Path& path, std::size_t i) { return Path(path, i); }

std::string format_number(double x) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, x);
  return std::string(buf, r.ptr);
}

std::string quote_json(std::string_view s) {
  constexpr std::size_t kMax = 60;
  std::string q = json(std::string(s.substr(0, kMax))).dump(-1, ' ', false, json::error_handler_t::replace);
  if (s.size() > kMax) q.insert(q.size() - 1, "...");
  return q;
}

// What a value is, for "got ..." in messages.
std::string describe(const json& v) {
  switch (v.type()) {
    case json::value_t::null: return "null";
    case json::value_t::boolean: return v.get<bool>() ? "true" : "false";
    case json::value_t::number_integer: return std::to_string(v.get<std::int64_t>());
    case json::value_t::number_unsigned: return std::to_string(v.get<std::uint64_t>());
    case json::value_t::number_float: return format_number(v.get<double>());
    case json::value_t::string: return quote_json(v.get_ref<const std::string&>());
    case json::value_t::array:
      return v.empty() ? "an empty array" : "an array of " + std::to_string(v.size()) + (v.size() == 1 ? " value" : " values");
    case json::value_t::object: return "an object";
    default: return "something else";
  }
}

std::string unit_suffix(std::string_view unit) { return unit.empty() ? "" : " (" + std::string(unit) + ")"; }

// Optimal string alignment distance (Levenshtein plus adjacent transpositions), ignoring case.
std::size_t edit_distance(std::string_view a_in, std::string_view b_in) {
  const auto lower = [](std::string_view s) {
    std::string out(s);
    for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return out;
  };
  const std::string a = lower(a_in), b = lower(b_in);
  std::vector<std::size_t> prev2(b.size() + 1), prev(b.size() + 1), cur(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) cur[j] = std::min(cur[j], prev2[j - 2] + 1);
    }
    std::swap(prev2, prev);
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

std::string key_list(Keys allowed) {
  std::string s;
  for (std::size_t i = 0; i < allowed.size(); ++i) s += (i ? ", " : "") + std::string(allowed[i]);
  return s;
}

// " (did you mean "radius"?)" for a key close to an allowed one, else a list of the allowed keys.
std::string key_hint(std::string_view key, Keys allowed) {
  std::string_view best;
  std::size_t best_distance = SIZE_MAX;
  if (key.size() <= 64) {
    for (auto candidate : allowed) {
      const std::size_t d = edit_distance(key, candidate);
      if (d < best_distance) best_distance = d, best = candidate;
    }
  }
  if (best_distance <= std::max<std::size_t>(1, best.size() / 3))
    return " (did you mean \"" + std::string(best) + "\"?)";
  return " (expected one of: " + key_list(allowed) + ")";
}

// ---------------------------------------------------------------------------------------------------
// The conversion, JSON -> MobileSpec. Every check throws InputError through MobileSpec::error_at.

class Reader {
 public:
  Reader(MobileSpec& spec, std::string base_dir) : spec_(spec), base_dir_(std::move(base_dir)) {}

  void mobile(const json& root);

 private:
  [[noreturn]] void fail(const Path& path, const std::string& problem) const {
    throw spec_.error_at(path.str(), problem);
  }

  // An error about key `key` of the object at `path`, placed at that key's value.
  [[noreturn]] void fail_key(const Path& path, std::string_view key, const std::string& problem) const {
    SourcePlace place = spec_.source.locate(join(path, key).str());
    place.path = path.str();
    throw InputError(spec_.file, place, problem);
  }

  const json& object(const json& v, const Path& path, std::string_view what) const {
    if (!v.is_object()) fail(path, "must be an object {...} (" + std::string(what) + "), got " + describe(v));
    return v;
  }

  // Refuses keys not in `allowed`; reports the first one in the file.
  void check_keys(const json& obj, const Path& path, Keys allowed) const {
    const std::string* worst = nullptr;
    SourcePlace worst_place;
    for (const auto& [key, value] : obj.items()) {
      if (std::find(allowed.begin(), allowed.end(), key) != allowed.end()) continue;
      const SourcePlace p = spec_.source.locate(join(path, key).str());
      if (!worst || std::tie(p.line, p.column) < std::tie(worst_place.line, worst_place.column)) {
        worst = &key;
        worst_place = p;
      }
    }
    if (worst) fail_key(path, *worst, "unknown key " + quote_json(*worst) + key_hint(*worst, allowed));
  }

  const json* find(const json& obj, std::string_view key) const {
    auto it = obj.find(key);
    return it == obj.end() ? nullptr : &*it;
  }

  const json& require(const json& obj, const Path& path, std::string_view key, std::string_view what) const {
    const json* v = find(obj, key);
    if (!v) fail(path, "missing key " + quote_json(key) + " (" + std::string(what) + ")");
    return *v;
  }

  double number(const json& v, const Path& path, std::string_view unit) const {
    if (!v.is_number()) fail(path, "must be a number" + unit_suffix(unit) + ", got " + describe(v));
    const double x = v.get<double>();
    if (!std::isfinite(x)) fail(path, "must be a finite number, got " + describe(v));
    return x;
  }

  double positive(const json& v, const Path& path, std::string_view unit) const {
    const double x = v.is_number() ? v.get<double>() : 0;
    if (!v.is_number() || !std::isfinite(x) || !(x > 0))
      fail(path, "must be a positive number" + unit_suffix(unit) + ", got " + describe(v));
    return x;
  }

  double non_negative(const json& v, const Path& path, std::string_view unit) const {
    const double x = v.is_number() ? v.get<double>() : -1;
    if (!v.is_number() || !std::isfinite(x) || !(x >= 0))
      fail(path, "must be a number >= 0" + unit_suffix(unit) + ", got " + describe(v));
    return x;
  }

  double fraction(const json& v, const Path& path) const {
    const double x = v.is_number() ? v.get<double>() : -1;
    if (!v.is_number() || !(x >= 0 && x <= 1)) fail(path, "must be a number from 0 to 1, got " + describe(v));
    return x;
  }

  bool boolean(const json& v, const Path& path) const {
    if (!v.is_boolean()) fail(path, "must be true or false, got " + describe(v));
    return v.get<bool>();
  }

  const std::string& text(const json& v, const Path& path) const {
    if (!v.is_string() || v.get_ref<const std::string&>().empty())
      fail(path, "must be a non-empty string, got " + describe(v));
    return v.get_ref<const std::string&>();
  }

  Vec3 vec3(const json& v, const Path& path, std::string_view unit) const {
    if (!v.is_array() || v.size() != 3)
      fail(path, "must be an array of 3 numbers [x, y, z]" + unit_suffix(unit) + ", got " + describe(v));
    return {number(v[0], item(path, 0), unit), number(v[1], item(path, 1), unit), number(v[2], item(path, 2), unit)};
  }

  Vec3 positive_vec3(const json& v, const Path& path, std::string_view unit) const {
    if (!v.is_array() || v.size() != 3)
      fail(path, "must be an array of 3 positive numbers" + unit_suffix(unit) + ", got " + describe(v));
    return {positive(v[0], item(path, 0), unit), positive(v[1], item(path, 1), unit),
            positive(v[2], item(path, 2), unit)};
  }

  Vec3 nonzero_vec3(const json& v, const Path& path) const {
    const Vec3 x = vec3(v, path, "");
    if (!(x.stableNorm() > 0)) fail(path, "must be a non-zero vector [x, y, z]");
    return x;
  }

  // A coordinate (m): a number within kLongestLength of zero.
  double coordinate(const json& v, const Path& path) const {
    const double x = number(v, path, "m");
    if (std::abs(x) > kLongestLength)
      fail(path, "must be from -" + format_number(kLongestLength) + " to " + format_number(kLongestLength) +
                     " m (no mobile is larger), got " + describe(v));
    return x;
  }

  // A length (m): a positive number of at most kLongestLength. `unit` may say what it measures.
  double length(const json& v, const Path& path, std::string_view unit = "m") const {
    const double x = positive(v, path, unit);
    if (x > kLongestLength)
      fail(path, "must be at most " + format_number(kLongestLength) + " m (no mobile is larger), got " + describe(v));
    return x;
  }

  Vec3 point(const json& v, const Path& path) const {
    if (!v.is_array() || v.size() != 3) fail(path, "must be an array of 3 numbers [x, y, z] (m), got " + describe(v));
    return {coordinate(v[0], item(path, 0)), coordinate(v[1], item(path, 1)), coordinate(v[2], item(path, 2))};
  }

  Vec3 lengths(const json& v, const Path& path) const {
    if (!v.is_array() || v.size() != 3)
      fail(path, "must be an array of 3 positive numbers (m), got " + describe(v));
    return {length(v[0], item(path, 0)), length(v[1], item(path, 1)), length(v[2], item(path, 2))};
  }

  // A density (kg/m^3) from kLeastDensity to kGreatestDensity.
  double density(const json& v, const Path& path) const {
    return in_range(v, path, kLeastDensity, kGreatestDensity, "kg/m^3");
  }

  // A number in [lo, hi] (both finite).
  double in_range(const json& v, const Path& path, double lo, double hi, std::string_view unit) const {
    const double x = v.is_number() ? v.get<double>() : lo - 1;
    if (!v.is_number() || !(x >= lo && x <= hi))
      fail(path, "must be a number from " + format_number(lo) + " to " + format_number(hi) + unit_suffix(unit) +
                     ", got " + describe(v));
    return x;
  }

  // A whole number from 0 to 2^63 - 1 (seeds).
  std::uint64_t count(const json& v, const Path& path) const {
    if (v.is_number_unsigned() && v.get<std::uint64_t>() <= static_cast<std::uint64_t>(INT64_MAX))
      return v.get<std::uint64_t>();
    fail(path, "must be a whole number from 0 to 2^63 - 1, got " + describe(v));
  }

  void balance(const json& v, const Path& path);
  void damping(const json& v, const Path& path);
  WindSourceSpec wind_source(const json& v, const Path& path, std::size_t index) const;
  WindProfileSpec wind_profile(const json& v, const Path& path) const;
  CameraSpec camera(const json& v, const Path& path) const;
  void contact(const json& v, const Path& path);
  ComponentSpec component(const json& v, const Path& path);
  Color color(const json& v, const Path& path) const;
  ShapeSpec shape(const json& v, const Path& path);
  Sphere sphere(const json& v, const Path& path) const;
  Wire wire(const json& v, const Path& path) const;
  Box box(const json& v, const Path& path) const;
  Plate plate(const json& v, const Path& path) const;
  Mesh mesh(const json& v, const Path& path) const;

  MobileSpec& spec_;
  std::string base_dir_;
};

void Reader::mobile(const json& root) {
  const Path top;
  if (!root.is_object()) fail(top, "a mobile file must hold one JSON object {...}, got " + describe(root));
  if (const json* v = find(root, "aloft")) {
    if (!v->is_number() || v->get<double>() != 1)
      fail(join(top, "aloft"), "must be 1 (the only version of the format so far), got " + describe(*v));
  }
  check_keys(root, top, format_keys::kMobile);
  spec_.name = text(require(root, top, "name", "the mobile's name, a string"), join(top, "name"));
  if (const json* v = find(root, "gravity")) {
    const Path gp = join(top, "gravity");
    if (!v->is_array() || v->size() != 3)
      fail(gp, "must be an array of 3 numbers [x, y, z] (m/s^2), got " + describe(*v));
    for (int k = 0; k < 3; ++k)
      spec_.gravity[k] = in_range((*v)[k], item(gp, k), -kStrongestGravity, kStrongestGravity, "m/s^2");
  }
  if (const json* v = find(root, "balance")) {
    balance(*v, join(top, "balance"));
  } else {
    spec_.balance = BalanceSpec{BalanceMode::None, std::nullopt};
  }
  if (const json* v = find(root, "density")) spec_.density = density(*v, join(top, "density"));
  if (const json* v = find(root, "damping")) damping(*v, join(top, "damping"));
  if (const json* v = find(root, "contact")) contact(*v, join(top, "contact"));
  if (const json* v = find(root, "timestep")) {
    const double dt = v->is_number() ? v->get<double>() : 0;
    if (!v->is_number() || !(dt >= kShortestTimestep && dt <= kLongestTimestep))
      fail(join(top, "timestep"), "must be a number of seconds from " + format_number(kShortestTimestep) + " to " +
                                      format_number(kLongestTimestep) + ", got " + describe(*v));
    spec_.timestep = dt;
  }
  if (const json* v = find(root, "joint_tolerance"))
    spec_.joint_tolerance = length(*v, join(top, "joint_tolerance"));

  const Path cp = join(top, "components");
  const json& list = require(root, top, "components", "a non-empty array of components");
  if (!list.is_array() || list.empty()) fail(cp, "must be a non-empty array of components, got " + describe(list));
  spec_.components.reserve(list.size());
  for (std::size_t i = 0; i < list.size(); ++i) spec_.components.push_back(component(list[i], item(cp, i)));

  if (const json* v = find(root, "wind_sources")) {
    const Path wp = join(top, "wind_sources");
    if (!v->is_array()) fail(wp, "must be an array of wind sources [{...}, ...], got " + describe(*v));
    for (std::size_t i = 0; i < v->size(); ++i) {
      WindSourceSpec w = wind_source((*v)[i], item(wp, i), i);
      for (const WindSourceSpec& other : spec_.wind_sources)
        if (other.name == w.name)
          fail(join(item(wp, i), "name"), "the name " + quote_json(w.name) + " is already used by " + other.path);
      spec_.wind_sources.push_back(std::move(w));
    }
  }
  if (const json* v = find(root, "camera")) spec_.camera = camera(*v, join(top, "camera"));
}

WindSourceSpec Reader::wind_source(const json& v, const Path& path, std::size_t index) const {
  object(v, path, "a wind source with \"from\", \"to\" and \"speed\"");
  check_keys(v, path, format_keys::kWindSource);
  WindSourceSpec w;
  w.path = path.str();
  w.name = "source " + std::to_string(index + 1);
  if (const json* x = find(v, "name")) w.name = text(*x, join(path, "name"));
  w.from = point(require(v, path, "from", "[x, y, z] in m: the centre of the source's disc S0"), join(path, "from"));
  w.to = point(require(v, path, "to", "[x, y, z] in m: a point it blows towards"), join(path, "to"));
  if (!((w.to - w.from).norm() > 0))
    fail(join(path, "to"), "must differ from \"from\" (the wind blows from \"from\" towards \"to\")");
  if (const json* x = find(v, "r0")) w.r0 = length(*x, join(path, "r0"), "m, the radius of the disc S0");
  if (const json* x = find(v, "l0")) w.l0 = length(*x, join(path, "l0"), "m, from the cone's vertex to S0");
  const Path sp = join(path, "speed");
  const json& speed = require(v, path, "speed", "m/s, the wind speed v0 at the disc S0");
  w.speed = speed.is_number() ? speed.get<double>() : -1;
  if (!speed.is_number() || !acceptable_wind_speed(w.speed)) fail(sp, wind_speed_rule() + ", got " + describe(speed));
  if (const json* x = find(v, "profile")) w.profile = wind_profile(*x, join(path, "profile"));
  if (const json* x = find(v, "alpha")) {  // after l0: alpha's bound is water's density times l0^4
    if (!x->is_number() || !acceptable_wind_alpha(x->get<double>(), w.l0))
      fail(join(path, "alpha"), wind_alpha_rule(w.l0) + ", got " + describe(*x));
    w.alpha = x->get<double>();
  }
  if (const json* x = find(v, "beta")) w.beta = in_range(*x, join(path, "beta"), 0, 10, "");
  if (const json* x = find(v, "seed")) w.seed = count(*x, join(path, "seed"));
  return w;
}

WindProfileSpec Reader::wind_profile(const json& v, const Path& path) const {
  object(v, path, "with \"type\": \"steady\", \"on_off\" or \"swell\"");
  check_keys(v, path, format_keys::kWindProfile);
  WindProfileSpec p;
  const Path tp = join(path, "type");
  const json& type = require(v, path, "type", "\"steady\", \"on_off\" or \"swell\"");
  std::vector<std::string_view> keys;  // the keys this type takes besides "type"
  if (type == "steady") {
    p.kind = WindProfileKind::Steady;
  } else if (type == "on_off") {
    p.kind = WindProfileKind::OnOff;
    keys = {"period", "on", "ramp", "phase"};
  } else if (type == "swell") {
    p.kind = WindProfileKind::Swell;
    keys = {"period", "depth", "phase"};
  } else {
    fail(tp, "must be \"steady\", \"on_off\" or \"swell\", got " + describe(type));
  }
  for (std::string_view key : format_keys::kWindProfile) {
    if (key != "type" && find(v, key) && std::find(keys.begin(), keys.end(), key) == keys.end())
      fail_key(path, key, "unknown key " + quote_json(key) + " (with \"type\": " + describe(type) +
                              (keys.empty() ? std::string(" there are no other keys)")
                                            : " the keys are: type, " + key_list(keys) + ")"));
  }
  if (p.kind == WindProfileKind::Steady) return p;
  p.period = positive(require(v, path, "period", "s, the length of one cycle"), join(path, "period"), "s");
  if (const json* x = find(v, "phase")) p.phase = number(*x, join(path, "phase"), "s");
  if (p.kind == WindProfileKind::Swell) {
    if (const json* x = find(v, "depth")) p.depth = fraction(*x, join(path, "depth"));
    return p;
  }
  const Path op = join(path, "on");
  p.on = positive(require(v, path, "on", "s of each period from switch-on to switch-off"), op, "s");
  if (p.on > p.period) fail(op, "must be at most \"period\" (" + format_number(p.period) + " s), got " + describe(v.at("on")));
  if (const json* x = find(v, "ramp")) {
    const Path rp = join(path, "ramp");
    p.ramp = non_negative(*x, rp, "s");
    if (p.ramp > p.on) fail(rp, "must be at most \"on\" (" + format_number(p.on) + " s): the fan spins up while on");
    if (p.on + p.ramp > p.period)
      fail(rp, "\"on\" + \"ramp\" must be at most \"period\" (" + format_number(p.period) +
                   " s): the fan runs down before the next cycle");
  }
  return p;
}

CameraSpec Reader::camera(const json& v, const Path& path) const {
  object(v, path, "with any of \"yaw\", \"pitch\", \"distance\", \"fov\", \"target\"");
  check_keys(v, path, format_keys::kCamera);
  CameraSpec c;
  if (const json* x = find(v, "yaw")) c.yaw_deg = number(*x, join(path, "yaw"), "degrees");
  if (const json* x = find(v, "pitch")) c.pitch_deg = in_range(*x, join(path, "pitch"), -85, 85, "degrees");
  if (const json* x = find(v, "distance")) c.distance = length(*x, join(path, "distance"));
  if (const json* x = find(v, "fov")) c.fov_deg = in_range(*x, join(path, "fov"), 5, 120, "degrees");
  if (const json* x = find(v, "target")) c.target = point(*x, join(path, "target"));
  return c;
}

void Reader::balance(const json& v, const Path& path) {
  object(v, path, "with \"mode\" and \"total_mass\"");
  check_keys(v, path, format_keys::kBalance);
  BalanceSpec b;  // mode "mass" unless said otherwise
  if (const json* m = find(v, "mode")) {
    const Path mp = join(path, "mode");
    if (*m == "mass") b.mode = BalanceMode::Mass;
    else if (*m == "joints") b.mode = BalanceMode::Joints;
    else if (*m == "none") b.mode = BalanceMode::None;
    else fail(mp, "must be \"mass\", \"joints\" or \"none\", got " + describe(*m));
  }
  if (const json* t = find(v, "total_mass"))
    b.total_mass = in_range(*t, join(path, "total_mass"), kLightestMobile, kHeaviestMobile, "kg");
  if (b.mode == BalanceMode::Mass && !b.total_mass)
    fail(path, "missing key \"total_mass\" (kg of the moving components: balance mode \"mass\" needs it)");
  spec_.balance = b;
}

void Reader::damping(const json& v, const Path& path) {
  object(v, path, "with \"linear\" and \"angular\" in 1/s");
  check_keys(v, path, format_keys::kDamping);
  if (const json* x = find(v, "linear"))
    spec_.damping.linear = in_range(*x, join(path, "linear"), 0, kGreatestDampingRate, "1/s");
  if (const json* x = find(v, "angular"))
    spec_.damping.angular = in_range(*x, join(path, "angular"), 0, kGreatestDampingRate, "1/s");
}

void Reader::contact(const json& v, const Path& path) {
  object(v, path, "with \"restitution\", \"friction\" and \"enabled\"");
  check_keys(v, path, format_keys::kContact);
  if (const json* x = find(v, "restitution")) spec_.contact.restitution = fraction(*x, join(path, "restitution"));
  if (const json* x = find(v, "friction")) spec_.contact.friction = non_negative(*x, join(path, "friction"), "");
  if (const json* x = find(v, "enabled")) spec_.contact.enabled = boolean(*x, join(path, "enabled"));
}

ComponentSpec Reader::component(const json& v, const Path& path) {
  object(v, path, "a component");
  check_keys(v, path, format_keys::kComponent);
  ComponentSpec c;
  c.path = path.str();
  c.name = text(require(v, path, "name", "the component's name, a string"), join(path, "name"));
  if (const json* x = find(v, "fixed")) c.fixed = boolean(*x, join(path, "fixed"));
  if (const json* x = find(v, "parent")) c.parent = text(*x, join(path, "parent"));
  if (const json* x = find(v, "joint")) c.joint = point(*x, join(path, "joint"));
  if (c.fixed) {
    if (c.parent) fail(join(path, "parent"), "a fixed component hangs from nothing: remove \"parent\" or \"fixed\"");
    if (c.joint) fail(join(path, "joint"), "a fixed component hangs from nothing: remove \"joint\" or \"fixed\"");
  } else {
    if (!c.parent)
      fail(path, "missing key \"parent\" (the name of the component this one hangs from; "
                 "the top component has \"fixed\": true instead)");
    if (!c.joint) fail(path, "missing key \"joint\" ([x, y, z] in m: the world point where it hangs from its parent)");
  }
  const Path sp = join(path, "shapes");
  const json& shapes = require(v, path, "shapes", "a non-empty array of shapes");
  if (!shapes.is_array() || shapes.empty()) fail(sp, "must be a non-empty array of shapes, got " + describe(shapes));
  c.shapes.reserve(shapes.size());
  for (std::size_t i = 0; i < shapes.size(); ++i) c.shapes.push_back(shape(shapes[i], item(sp, i)));
  if (const json* x = find(v, "color")) c.color = color(*x, join(path, "color"));
  if (const json* x = find(v, "density")) c.density = density(*x, join(path, "density"));
  if (const json* x = find(v, "restitution")) c.restitution = fraction(*x, join(path, "restitution"));
  if (const json* x = find(v, "friction")) c.friction = non_negative(*x, join(path, "friction"), "");
  return c;
}

Color Reader::color(const json& v, const Path& path) const {
  const auto bad = [&] {
    fail(path, "must be \"#rrggbb\", \"#rgb\" or [r, g, b] with each from 0 to 1, got " + describe(v));
  };
  Color c;
  if (v.is_string()) {
    const std::string& s = v.get_ref<const std::string&>();
    if ((s.size() != 4 && s.size() != 7) || s[0] != '#' ||
        !std::all_of(s.begin() + 1, s.end(), [](char ch) { return std::isxdigit(static_cast<unsigned char>(ch)); }))
      bad();
    const auto channel = [&](int i) {
      const int n = s.size() == 7 ? 2 : 1;
      const int x = std::stoi(s.substr(1 + i * n, n), nullptr, 16);
      return static_cast<float>(n == 2 ? x / 255.0 : x * 17 / 255.0);
    };
    return Color{channel(0), channel(1), channel(2)};
  }
  if (!v.is_array() || v.size() != 3) bad();
  c.r = static_cast<float>(fraction(v[0], item(path, 0)));
  c.g = static_cast<float>(fraction(v[1], item(path, 1)));
  c.b = static_cast<float>(fraction(v[2], item(path, 2)));
  return c;
}

ShapeSpec Reader::shape(const json& v, const Path& path) {
  object(v, path, "a shape: {\"sphere\": {...}} or wire, box, plate, mesh");
  check_keys(v, path, format_keys::kShape);
  std::vector<std::string_view> kinds;
  for (auto kind : format_keys::kShapeKinds)
    if (find(v, kind)) kinds.push_back(kind);
  if (kinds.size() != 1) {
    std::string found = kinds.empty() ? "none" : std::string(kinds[0]);
    for (std::size_t i = 1; i < kinds.size(); ++i) found += (i + 1 == kinds.size() ? " and " : ", ") + std::string(kinds[i]);
    fail(path, "a shape needs exactly one of sphere, wire, box, plate, mesh; found " + found);
  }
  ShapeSpec s;
  s.path = path.str();
  const Path kp = join(path, kinds[0]);
  const json& body = v.at(kinds[0]);
  if (kinds[0] == "sphere") s.shape = sphere(body, kp);
  else if (kinds[0] == "wire") s.shape = wire(body, kp);
  else if (kinds[0] == "box") s.shape = box(body, kp);
  else if (kinds[0] == "plate") s.shape = plate(body, kp);
  else s.shape = mesh(body, kp);
  if (const json* x = find(v, "density")) s.density = density(*x, join(path, "density"));
  return s;
}

Sphere Reader::sphere(const json& v, const Path& path) const {
  object(v, path, "with \"center\" and \"radius\"");
  check_keys(v, path, format_keys::kSphere);
  Sphere s;
  s.center = point(require(v, path, "center", "[x, y, z] in m"), join(path, "center"));
  s.radius = length(require(v, path, "radius", "m, a positive number"), join(path, "radius"));
  return s;
}

Wire Reader::wire(const json& v, const Path& path) const {
  object(v, path, "with \"from\", \"to\" and \"radius\"");
  check_keys(v, path, format_keys::kWire);
  Wire w;
  w.from = point(require(v, path, "from", "[x, y, z] in m"), join(path, "from"));
  w.to = point(require(v, path, "to", "[x, y, z] in m"), join(path, "to"));
  w.radius = length(require(v, path, "radius", "m, a positive number"), join(path, "radius"));
  if (!((w.to - w.from).norm() > 0)) fail(join(path, "to"), "must differ from \"from\" (a wire needs a length > 0)");
  return w;
}

Box Reader::box(const json& v, const Path& path) const {
  object(v, path, "with \"center\", \"size\" and optionally \"rotation\"");
  check_keys(v, path, format_keys::kBox);
  Box b;
  b.center = point(require(v, path, "center", "[x, y, z] in m"), join(path, "center"));
  b.size = lengths(require(v, path, "size", "[sx, sy, sz] full edge lengths in m"), join(path, "size"));
  if (const json* r = find(v, "rotation")) {
    const Path rp = join(path, "rotation");
    object(*r, rp, "with \"axis\" [x, y, z] and \"degrees\"");
    check_keys(*r, rp, format_keys::kRotation);
    const Vec3 axis = nonzero_vec3(require(*r, rp, "axis", "[x, y, z], a non-zero vector"), join(rp, "axis"));
    const double degrees = number(require(*r, rp, "degrees", "the angle in degrees"), join(rp, "degrees"), "degrees");
    b.rotation = Eigen::AngleAxisd(degrees * std::numbers::pi / 180, axis.stableNormalized()).toRotationMatrix();
  }
  return b;
}

Plate Reader::plate(const json& v, const Path& path) const {
  object(v, path, "with \"points\", \"thickness\" and \"plane\"");
  check_keys(v, path, format_keys::kPlate);
  Plate p;
  const Path pp = join(path, "points");
  const json& points = require(v, path, "points", "an array of at least 3 points [u, v] in m");
  if (!points.is_array() || points.size() < 3)
    fail(pp, "must be an array of at least 3 points [u, v] (m), got " + describe(points));
  p.points.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const json& q = points[i];
    const Path qp = item(pp, i);
    if (!q.is_array() || q.size() != 2) fail(qp, "must be a point [u, v] of 2 numbers (m), got " + describe(q));
    p.points.emplace_back(coordinate(q[0], item(qp, 0)), coordinate(q[1], item(qp, 1)));
  }
  p.thickness = length(require(v, path, "thickness", "m, a positive number"), join(path, "thickness"));

  const Path lp = join(path, "plane");
  const json& plane = require(v, path, "plane", "\"xy\", \"yz\", \"xz\" or {\"origin\", \"u\", \"v\"}");
  if (plane.is_string()) {
    // [a, b] are the two named axes in order; the offset key names the third axis.
    struct Named { std::string_view name, offset; Vec3 u, v, normal; };
    static const Named kNamed[] = {{"xy", "z", Vec3::UnitX(), Vec3::UnitY(), Vec3::UnitZ()},
                                   {"yz", "x", Vec3::UnitY(), Vec3::UnitZ(), Vec3::UnitX()},
                                   {"xz", "y", Vec3::UnitX(), Vec3::UnitZ(), Vec3::UnitY()}};
    const Named* named = nullptr;
    for (const Named& n : kNamed)
      if (plane.get_ref<const std::string&>() == n.name) named = &n;
    if (!named) fail(lp, "must be \"xy\", \"yz\", \"xz\" or {\"origin\", \"u\", \"v\"}, got " + describe(plane));
    for (std::string_view other : {"x", "y", "z"}) {
      if (other != named->offset && find(v, other))
        fail_key(path, other, "unknown key " + quote_json(other) + " (with \"plane\": " + quote_json(named->name) +
                                  " the plane's offset is \"" + std::string(named->offset) + "\")");
    }
    double offset = 0;
    if (const json* o = find(v, named->offset)) offset = coordinate(*o, join(path, named->offset));
    p.origin = offset * named->normal;
    p.u_axis = named->u;
    p.v_axis = named->v;
  } else if (plane.is_object()) {
    check_keys(plane, lp, format_keys::kPlaneFrame);
    for (std::string_view other : {"x", "y", "z"}) {
      if (find(v, other))
        fail_key(path, other, "unknown key " + quote_json(other) +
                                  " (a plane given by origin, u and v has no offset: move its origin)");
    }
    p.origin = point(require(plane, lp, "origin", "[x, y, z] in m"), join(lp, "origin"));
    const Vec3 u = nonzero_vec3(require(plane, lp, "u", "[x, y, z], the direction of the first coordinate"), join(lp, "u"));
    const Vec3 w = nonzero_vec3(require(plane, lp, "v", "[x, y, z], the direction of the second coordinate"), join(lp, "v"));
    p.u_axis = u.stableNormalized();
    Vec3 orthogonal = w - w.dot(p.u_axis) * p.u_axis;  // Gram-Schmidt
    if (!(orthogonal.stableNorm() > 1e-9 * w.stableNorm()))
      fail(join(lp, "v"), "must not be parallel to \"u\" (they span the plate's plane)");
    orthogonal = orthogonal.stableNormalized();
    p.v_axis = (orthogonal - orthogonal.dot(p.u_axis) * p.u_axis).stableNormalized();  // twice is enough
  } else {
    fail(lp, "must be \"xy\", \"yz\", \"xz\" or {\"origin\", \"u\", \"v\"}, got " + describe(plane));
  }
  if (auto problem = polygon_problem(p.points)) fail(pp, *problem);
  return p;
}

Mesh Reader::mesh(const json& v, const Path& path) const {
  namespace fs = std::filesystem;
  object(v, path, "with \"obj\" and optionally \"scale\" and \"translate\"");
  check_keys(v, path, format_keys::kMesh);
  Mesh m;
  const Path op = join(path, "obj");
  m.file = text(require(v, path, "obj", "the OBJ file's path, relative to this file"), op);
  if (m.file.find('\0') != std::string::npos) fail(op, "must be a file path, got a string with a NUL character");
  Vec3 scale = Vec3::Ones(), translate = Vec3::Zero();
  if (const json* s = find(v, "scale")) {
    const Path sp = join(path, "scale");
    if (s->is_array()) scale = positive_vec3(*s, sp, "");
    else if (s->is_number()) scale = Vec3::Constant(positive(*s, sp, ""));
    else fail(sp, "must be a positive number or [sx, sy, sz] of positive numbers, got " + describe(*s));
  }
  if (const json* t = find(v, "translate")) translate = point(*t, join(path, "translate"));

  m.opened = (fs::path(base_dir_) / fs::path(m.file)).lexically_normal().string();
  const std::string& resolved = m.opened;
  std::error_code ec;
  const fs::file_status status = fs::status(resolved, ec);
  if (!fs::exists(status)) fail(op, resolved + ": no such file");
  ObjMesh obj;
  try {
    obj = read_obj(resolved);  // "<resolved>: not a regular file" for a directory or a device
  } catch (const InputError& e) {
    fail(op, e.what());
  }
  for (Vec3& p : obj.mesh.vertices) {
    p = p.cwiseProduct(scale) + translate;  // scale, then translate
    if (!(p.cwiseAbs().maxCoeff() <= kLongestLength))  // (NaN fails too)
      fail(op, resolved + ": a vertex lies at [" + format_number(p.x()) + ", " + format_number(p.y()) + ", " +
                   format_number(p.z()) + "] m once scaled and moved, more than " + format_number(kLongestLength) +
                   " m from the origin (no mobile is larger)");
  }
  try {
    check_closed_obj_mesh(obj, resolved);
  } catch (const InputError& e) {
    fail(op, e.what());
  }
  m.mesh = std::move(obj.mesh);
  return m;
}

}  // namespace

MobileSpec parse_mobile_text(const std::string& text, const std::string& file, const std::string& base_dir) {
  MobileSpec spec;
  spec.file = file;
  // Locating and parsing are independent passes over the text, each linear: for a big file (a 65535-
  // component mobile is ~15 MB) run them at once. The locator is safe on text nlohmann then rejects.
  constexpr std::size_t kParallelFrom = 1 << 20;  // bytes
  internal::JsonLocation location;
  json root;
  if (text.size() >= kParallelFrom) {
    auto located = std::async(std::launch::async, [&text] { return internal::locate_json(text); });
    root = parse_json(text, file);  // on an error, `located`'s destructor waits for the locator
    location = located.get();
  } else {
    root = parse_json(text, file);
    location = internal::locate_json(text);
  }
  spec.source = std::move(location.map);
  if (const auto& d = location.duplicate) {
    throw InputError(file, SourcePlace{d->object_path, d->second.line, d->second.column},
                     "duplicate key " + quote_json(d->key) + " (first at line " + std::to_string(d->first.line) + ")");
  }
  Reader(spec, base_dir).mobile(root);
  return spec;
}

MobileSpec parse_mobile_file(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw InputError(path, {}, "is a directory, not a mobile file");
  require_regular_file(path);  // /dev/zero or a FIFO would be read until memory ran out
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, {}, "cannot open the file: " + std::error_code(errno, std::generic_category()).message());
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) throw InputError(path, {}, "cannot read the file");
  std::string dir = fs::path(path).parent_path().string();
  return parse_mobile_text(buffer.str(), path, dir.empty() ? "." : dir);
}

}  // namespace aloft
