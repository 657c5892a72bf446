// v0(t) as a series of samples: interpolation, and the "t,v0" CSV reader.

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>

#include "aloft/audio.hpp"
#include "aloft/error.hpp"
#include "aloft/spec.hpp"
#include "aloft/decimal_number.hpp"
#include "common/printable.hpp"
#include "common/regular_file.hpp"

namespace aloft {

double SpeedSeries::at(double time) const {
  if (t.empty()) return 0;
  if (time <= t.front()) return v0.front();
  if (time >= t.back()) return v0.back();
  const auto upper = std::upper_bound(t.begin(), t.end(), time);
  const std::size_t i = static_cast<std::size_t>(upper - t.begin());
  const double f = (time - t[i - 1]) / (t[i] - t[i - 1]);
  return v0[i - 1] + f * (v0[i] - v0[i - 1]);
}

namespace {

std::string trim(const std::string& s) {
  const auto first = s.find_first_not_of(" \t\r");
  if (first == std::string::npos) return "";
  return s.substr(first, s.find_last_not_of(" \t\r") - first + 1);
}

// What is wrong with a field that is not a plain decimal number, beyond its not being one: hexadecimal
// (std::strtod read "0x10" as 16) or not finite ("inf", "nan", "1e400"); empty when nothing more is known.
std::string number_problem(const std::string& field, NumberResult result, const char* name) {
  const std::string text = trim(field);
  if (result == NumberResult::not_finite) return std::string(name) + " must be a finite number, got " + printable(text);
  std::string_view digits = without_plus(text);
  if (!digits.empty() && digits[0] == '-') digits.remove_prefix(1);
  if (digits.size() > 1 && digits[0] == '0' && (digits[1] == 'x' || digits[1] == 'X'))
    return std::string(name) + " must be a decimal number, got the hexadecimal " + printable(text);
  return "";
}

}  // namespace

SpeedSeries read_speed_csv(const std::string& path) {
  require_regular_file(path);  // /dev/zero or a FIFO was read until memory ran out
  std::ifstream in(path);
  if (!in) throw InputError(path, {}, std::string("cannot open the speed series: ") + std::strerror(errno));
  SpeedSeries series;
  std::string line, previous_t;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    // A UTF-8 byte order mark (what some spreadsheets write first) is no part of the first row.
    if (number == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);
    const std::string text = trim(line);
    if (text.empty() || text[0] == '#') continue;
    const auto comma = text.find(',');
    auto fail = [&](const std::string& problem) { throw InputError(path, SourcePlace{"", number, 0}, problem); };
    if (comma == std::string::npos)
      fail("expected \"t,v0\" (time in s, speed in m/s), got \"" + printable(text) + "\"");
    double t = 0, v = 0;
    const NumberResult t_read = parse_double(trim(text.substr(0, comma)), t);
    const NumberResult v_read = parse_double(trim(text.substr(comma + 1)), v);
    const std::string t_problem = number_problem(text.substr(0, comma), t_read, "the time t");
    const std::string v_problem = number_problem(text.substr(comma + 1), v_read, "the speed v0");
    if (!t_problem.empty()) fail(t_problem);
    if (!v_problem.empty()) fail(v_problem);
    if (t_read != NumberResult::ok || v_read != NumberResult::ok) {
      // A header line such as "t,v0": neither field a number.
      if (series.t.empty() && t_read != NumberResult::ok && v_read != NumberResult::ok) continue;
      fail("expected two numbers \"t,v0\", got \"" + printable(text) + "\"");
    }
    if (!acceptable_wind_speed(v)) fail("the speed v0 " + wind_speed_rule() + ", got " + trim(text.substr(comma + 1)));
    if (!series.t.empty() && t <= series.t.back())
      fail("times must increase: " + trim(text.substr(0, comma)) + " s after " + previous_t + " s");
    series.t.push_back(t);
    series.v0.push_back(v);
    previous_t = trim(text.substr(0, comma));
  }
  if (in.bad()) throw InputError(path, {}, "cannot read the speed series");
  if (series.t.empty()) throw InputError(path, {}, "no \"t,v0\" rows");
  return series;
}

}  // namespace aloft
