// The limits of a wind given from outside (a mobile file, the command line, a speed series): the fastest
// v0 and the largest alpha, with their rules worded for error messages (spec.hpp).

#include <cmath>
#include <cstdio>
#include <string>

#include "aloft/spec.hpp"

namespace aloft {

std::string wind_speed_rule() {
  char text[64];
  std::snprintf(text, sizeof text, "must be from 0 to %g m/s", kFastestWind);
  return std::string(text) +
         " (the cone model treats the air as incompressible, which holds below about 0.3 of the speed of sound)";
}

bool acceptable_wind_speed(double v0) { return v0 >= 0 && v0 <= kFastestWind; }

double largest_wind_alpha(double l0) { return kDensestWind * std::pow(l0, 4); }

bool acceptable_wind_alpha(double alpha, double l0) {
  return alpha > 0 && alpha <= largest_wind_alpha(l0);  // NaN fails
}

std::string wind_alpha_rule(double l0) {
  char text[256];
  std::snprintf(text, sizeof text,
                "must be a positive number of at most %g kg m: alpha = rho l0^4, and with l0 = %g m that is water's "
                "density, %g kg/m^3 (air's alpha is %.4g kg m)",
                largest_wind_alpha(l0), l0, kDensestWind, kAirDensity * std::pow(l0, 4));
  return text;
}

}  // namespace aloft
