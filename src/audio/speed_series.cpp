// v0(t) as a series of samples: interpolation, and the "t,v0" CSV reader.

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>

#include "aloft/audio.hpp"
#include "aloft/error.hpp"
#include "aloft/spec.hpp"

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

// A whole field as a finite double, or nothing.
bool parse_number(const std::string& field, double& out) {
  const std::string text = trim(field);
  if (text.empty()) return false;
  char* end = nullptr;
  errno = 0;
  out = std::strtod(text.c_str(), &end);
  return end == text.c_str() + text.size() && errno == 0 && std::isfinite(out);
}

}  // namespace

SpeedSeries read_speed_csv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path, {}, std::string("cannot open the speed series: ") + std::strerror(errno));
  SpeedSeries series;
  std::string line, previous_t;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    const std::string text = trim(line);
    if (text.empty() || text[0] == '#') continue;
    const auto comma = text.find(',');
    auto fail = [&](const std::string& problem) { throw InputError(path, SourcePlace{"", number, 0}, problem); };
    if (comma == std::string::npos) fail("expected \"t,v0\" (time in s, speed in m/s), got \"" + text + "\"");
    double t = 0, v = 0;
    const bool t_ok = parse_number(text.substr(0, comma), t);
    const bool v_ok = parse_number(text.substr(comma + 1), v);
    if (!t_ok || !v_ok) {
      if (series.t.empty() && !t_ok && !v_ok) continue;  // a header line such as "t,v0"
      fail("expected two numbers \"t,v0\", got \"" + text + "\"");
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
