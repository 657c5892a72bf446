#include "common.hpp"

#include <algorithm>
#include <optional>

#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdarg>
#include <cstring>
#include <filesystem>
#include <limits>
#include <vector>

#include "aloft/decimal_number.hpp"

namespace aloft::cli {

void print_error(const std::string& message) {
  std::fflush(stdout);
  std::fprintf(stderr, "aloft: error: %s\n", message.c_str());
}

void print_warning(const std::string& message) {
  std::fflush(stdout);
  std::fprintf(stderr, "aloft: warning: %s\n", message.c_str());
}

void append_double(std::string& out, double value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  out.append(buffer, result.ptr);
}

std::string format_double(double value) {
  std::string s;
  append_double(s, value);
  return s;
}

std::string format(const char* fmt, ...) {
  std::va_list args;
  va_start(args, fmt);
  std::va_list copy;
  va_copy(copy, args);
  const int n = std::vsnprintf(nullptr, 0, fmt, copy);
  va_end(copy);
  std::string s(n > 0 ? static_cast<std::size_t>(n) : 0, '\0');
  if (n > 0) std::vsnprintf(s.data(), s.size() + 1, fmt, args);
  va_end(args);
  return s;
}

std::string fixed(double value, int decimals) {
  std::string s = format("%.*f", decimals, value);
  if (s[0] == '-' && s.find_first_not_of("-0.") == std::string::npos) s.erase(0, 1);
  return s;
}

std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
  std::string out = "\"";
  for (char c : text) {
    if (c == '"') out += '"';
    out += c;
  }
  out += '"';
  return out;
}

bool is_terminal(std::FILE* stream) { return ::isatty(::fileno(stream)) == 1; }

void write_file(const std::string& path, const std::string& text) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) throw Failure("cannot write " + path + ": " + std::strerror(errno));
  const std::size_t written = std::fwrite(text.data(), 1, text.size(), f);
  const int err = written == text.size() ? 0 : errno;
  if (std::fclose(f) != 0 || written != text.size())
    throw Failure("cannot write " + path + ": " + std::strerror(err ? err : EIO));
}

namespace {

bool same_file(const std::string& a, const std::string& b) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::exists(a, ec) && fs::exists(b, ec)) return fs::equivalent(a, b, ec);
  const fs::path ca = fs::weakly_canonical(fs::absolute(a, ec), ec), cb = fs::weakly_canonical(fs::absolute(b, ec), ec);
  return !ec && ca == cb;
}

}  // namespace

void check_outputs_apart(const std::vector<NamedFile>& inputs, const std::vector<NamedFile>& outputs) {
  for (std::size_t k = 0; k < outputs.size(); ++k) {
    const NamedFile& out = outputs[k];
    if (out.path.empty()) continue;
    for (const NamedFile& in : inputs)
      if (!in.path.empty() && same_file(out.path, in.path))
        throw Failure(out.name + ": " + out.path + " is " + in.name + "; writing it would destroy it");
    for (std::size_t j = 0; j < k; ++j)
      if (!outputs[j].path.empty() && same_file(out.path, outputs[j].path))
        throw Failure(out.name + ": " + out.path + " is also " + outputs[j].name + "'s file; give each its own");
  }
}

std::string source_dir() {
#ifdef ALOFT_SOURCE_DIR
  return ALOFT_SOURCE_DIR;
#else
  return ".";
#endif
}

std::optional<double> read_number(const std::string& input) {
  // As the files' readers read numbers (no hexadecimal: std::stod took "0x2" for 2); inf and nan come back
  // for the flags' checks to name.
  double value = 0;
  if (parse_double(input, value) == NumberResult::not_a_number) return std::nullopt;
  return value;
}

namespace {

// A finite number above `lo` (or at it too when `lo_allowed`) and at most `hi`; otherwise "must be <rule>,
// got X".
CLI::Validator finite_number_between(double lo, bool lo_allowed, double hi, std::string rule) {
  return CLI::Validator(
      [lo, lo_allowed, hi, rule](std::string& input) -> std::string {
        const std::optional<double> v = read_number(input);
        if (!v) return "must be a number, got \"" + input + "\"";
        if (!std::isfinite(*v) || !(*v > lo || (lo_allowed && *v == lo)) || *v > hi)
          return "must be " + rule + ", got " + input;
        return {};
      },
      "");
}

constexpr double kInfinity = std::numeric_limits<double>::infinity();

}  // namespace

CLI::Validator positive_number() { return finite_number_between(0, false, kInfinity, "a positive number"); }

CLI::Validator non_negative_number() { return finite_number_between(0, true, kInfinity, "a number >= 0"); }

CLI::Validator finite_number() { return finite_number_between(-kInfinity, false, kInfinity, "a finite number"); }

CLI::Validator length_in_metres() {
  return finite_number_between(0, false, kLongestLength,
                               format("a positive number of at most %g (m; no mobile is larger)", kLongestLength));
}

CLI::Validator duration_in_seconds() {
  return finite_number_between(0, false, kLongestDuration,
                               format("a positive number of at most %g (s, %.1f days)", kLongestDuration,
                                      kLongestDuration / 86400));
}

CLI::Validator number_in(double lo, double hi) {
  return CLI::Validator(
      [lo, hi](std::string& input) -> std::string {
        const std::optional<double> v = read_number(input);
        if (!v || !(*v >= lo && *v <= hi))  // NaN fails too
          return format("must be a number from %g to %g, got \"", lo, hi) + input + "\"";
        return {};
      },
      "");
}

CLI::Validator integer_in(long long lo, long long hi) {
  return CLI::Validator(
      [lo, hi](std::string& input) -> std::string {
        long long v = 0;
        const char* end = input.data() + input.size();
        const auto [ptr, ec] = std::from_chars(input.data(), end, v);
        if (ec != std::errc() || ptr != end || v < lo || v > hi)
          return "must be an integer from " + std::to_string(lo) + " to " + std::to_string(hi) + ", got \"" +
                 input + "\"";
        return {};
      },
      "");
}

CLI::Validator timestep_range() {
  return finite_number_between(kShortestTimestep, true, kLongestTimestep,
                               format("from %g to %g s", kShortestTimestep, kLongestTimestep));
}

}  // namespace aloft::cli

namespace aloft::cli {

namespace {
// Display width of UTF-8 text: the number of code points (no wide characters are used here).
std::size_t display_width(const std::string& s) {
  std::size_t n = 0;
  for (unsigned char c : s)
    if ((c & 0xC0) != 0x80) ++n;
  return n;
}
}  // namespace

Table::Table(std::vector<std::string> header, std::vector<bool> right_aligned) : right_(std::move(right_aligned)) {
  right_.resize(header.size(), false);
  rows_.push_back(std::move(header));
}

void Table::add(std::vector<std::string> row) {
  row.resize(rows_.front().size());
  rows_.push_back(std::move(row));
}

std::string Table::str(const std::string& indent) const {
  const std::size_t columns = rows_.front().size();
  std::vector<std::size_t> width(columns, 0);
  for (const auto& row : rows_)
    for (std::size_t c = 0; c < columns; ++c) width[c] = std::max(width[c], display_width(row[c]));
  std::string out;
  for (std::size_t r = 0; r < rows_.size(); ++r) {
    std::string line = indent;
    for (std::size_t c = 0; c < columns; ++c) {
      const std::string& cell = rows_[r][c];
      const std::string pad(width[c] - display_width(cell), ' ');
      if (c) line += "  ";
      line += right_[c] ? pad + cell : cell + (c + 1 < columns ? pad : "");
    }
    while (!line.empty() && line.back() == ' ') line.pop_back();
    out += line + "\n";
  }
  return out;
}

void add_balance_option(CLI::App* sub, std::string& mode) {
  sub->add_option("--balance", mode,
                  "Balance mode: 'file' (as the mobile file says), or override it with 'mass' (derive masses so "
                  "the drawn pose hangs still), 'joints' (move the hanging points) or 'none' (densities as "
                  "given: an unbalanced mobile swings)")
      ->type_name("MODE")
      ->capture_default_str()
      ->check(CLI::IsMember({"file", "mass", "joints", "none"}));
}

aloft::Model load_mobile_as(const std::string& file, const std::string& balance_mode) {
  aloft::MobileSpec spec = aloft::parse_mobile_file(file);
  if (balance_mode == "mass") spec.balance.mode = aloft::BalanceMode::Mass;
  if (balance_mode == "joints") spec.balance.mode = aloft::BalanceMode::Joints;
  if (balance_mode == "none") spec.balance.mode = aloft::BalanceMode::None;
  return aloft::compile(spec);
}

}  // namespace aloft::cli

namespace aloft::cli {

namespace {
// Function-local so that it exists before any registration runs (static initialisation order).
std::vector<CommandEntry>& command_registry() {
  static std::vector<CommandEntry> registry;
  return registry;
}
}  // namespace

CommandRegistration::CommandRegistration(const char* name, int order, AddCommand add) {
  command_registry().push_back({name, order, add});
}

std::vector<CommandEntry> registered_commands() {
  std::vector<CommandEntry> commands = command_registry();
  std::stable_sort(commands.begin(), commands.end(),
                   [](const CommandEntry& x, const CommandEntry& y) { return x.order < y.order; });
  return commands;
}

}  // namespace aloft::cli
