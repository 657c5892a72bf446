#pragma once
// Shared pieces of the `aloft` command line: subcommand registration, errors, number formatting, CSV
// quoting, terminal detection.

#include <cstdio>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "aloft/model.hpp"
#include "aloft/wall_clock.hpp"

namespace aloft::cli {

// Exit codes.
inline constexpr int kExitOk = 0;
inline constexpr int kExitInput = 1;       // bad input file, unwritable output, ...
inline constexpr int kExitUsage = 2;       // wrong command line
inline constexpr int kExitSimulation = 3;  // the simulation failed (state not finite)

// A problem that is not in an input file (unwritable output, a directory that does not exist): printed as
// "aloft: error: <what>" with exit code 1, like an InputError.
class Failure : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A subcommand's body, run after the command line was parsed; returns the exit code.
using Runner = std::function<int()>;

// Each subcommand lives in its own file (cmd_<name>.cpp) and registers itself there, at static
// initialisation, with a function that adds it to `app` and returns what runs it:
//     static const CommandRegistration registration{"simulate", 30, add_simulate};
// `order` sets where it appears in `aloft --help` (ascending). No other file needs to change.
using AddCommand = Runner (*)(CLI::App& app);
struct CommandEntry {
  const char* name;
  int order;
  AddCommand add;
};
struct CommandRegistration {
  CommandRegistration(const char* name, int order, AddCommand add);
};
// Every registered command, sorted by order.
std::vector<CommandEntry> registered_commands();

// The --balance option shared by inspect and simulate: "file" (default: as the mobile file says), or
// "mass", "joints", "none" to override the file's balance mode.
void add_balance_option(CLI::App* sub, std::string& mode);

// parse_mobile_file + compile, with the balance mode overridden unless `balance_mode` is "file".
aloft::Model load_mobile_as(const std::string& file, const std::string& balance_mode);

// "aloft: error: <message>" on stderr.
void print_error(const std::string& message);
// "aloft: warning: <message>" on stderr: the run went on, but what it gave is not to be trusted.
void print_warning(const std::string& message);

// Shortest text that reads back as the same double (std::to_chars), e.g. "0.1", "1e-07".
std::string format_double(double value);
// Appends the same to `out`.
void append_double(std::string& out, double value);

// printf-style formatting into a std::string.
std::string format(const char* fmt, ...) __attribute__((format(printf, 1, 2)));

// A number with `decimals` digits after the point, without a minus sign on zero ("-0.000").
std::string fixed(double value, int decimals);

// A CSV field per RFC 4180: quoted (with doubled quotes) if it holds a comma, quote, CR or LF.
std::string csv_field(const std::string& text);

// Whether the stream is an interactive terminal.
bool is_terminal(std::FILE* stream);

// A whole file written at once, or a Failure naming it.
void write_file(const std::string& path, const std::string& text);

// A file a command reads or writes, and what it is: {"--out", "run.csv"}, {"the mobile file", "m.json"}.
struct NamedFile {
  std::string name;
  std::string path;  // empty: not given
};
// Throws a Failure when an output names the same file as an input (writing it would destroy the input:
// simulate m.json -o m.json) or as another output (one would overwrite the other). Same file: the same
// path once made absolute and normal, or, when both exist, the same inode (a link).
void check_outputs_apart(const std::vector<NamedFile>& inputs, const std::vector<NamedFile>& outputs);

// Directory of the source tree this program was built from (for the preset mobiles).
std::string source_dir();

// The whole of `input` read as a decimal number (aloft/decimal_number.hpp: "1e5", "inf" and "nan"
// included, "0x2" not), or nothing.
std::optional<double> read_number(const std::string& input);

// The longest time a command runs the simulation or listens for (s): 11.6 days, 1e9 steps at 1 ms. The
// steps and frames it makes are counted in 64-bit integers, which -t 1e300 overflowed: simulate ran one
// step and render wrote one frame, both without a word.
inline constexpr double kLongestDuration = 1e6;

// Validators with clear messages ("must be ..., got \"X\""), in the words the option's help uses.
CLI::Validator positive_number();          // > 0
CLI::Validator non_negative_number();      // >= 0
CLI::Validator finite_number();            // any number but inf and nan
CLI::Validator length_in_metres();         // (0, kLongestLength]: the mobile file's rule for lengths (spec.hpp)
CLI::Validator duration_in_seconds();      // (0, kLongestDuration]
CLI::Validator number_in(double lo, double hi);  // a number in [lo, hi]
CLI::Validator timestep_range();           // [kShortestTimestep, kLongestTimestep] (spec.hpp)
CLI::Validator integer_in(long long lo, long long hi);  // an integer in [lo, hi]

}  // namespace aloft::cli

namespace aloft::cli {

// A plain text table: columns padded to their widest cell, numbers right-aligned.
class Table {
 public:
  explicit Table(std::vector<std::string> header, std::vector<bool> right_aligned = {});
  void add(std::vector<std::string> row);
  std::string str(const std::string& indent = "") const;

 private:
  std::vector<std::vector<std::string>> rows_;
  std::vector<bool> right_;
};

}  // namespace aloft::cli
