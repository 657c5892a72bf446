// The time profile of a wind source placed by a mobile file (spec.hpp): steady, switched on and off, or
// swelling like a vent that breathes; and the fastest wind speed a run is given.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include "aloft/spec.hpp"

namespace aloft {

double WindProfileSpec::factor(double t) const {
  if (kind == WindProfileKind::Steady) return 1;
  // Where in its cycle the source is: t' in [0, period).
  double cycle = std::fmod(t + phase, period);
  if (cycle < 0) cycle += period;
  if (kind == WindProfileKind::Swell)
    return 1 - depth * 0.5 * (1 - std::cos(2 * std::numbers::pi * cycle / period));
  // On and off: rise over [0, ramp), full until `on`, fall over [on, on + ramp), then still.
  if (ramp > 0 && cycle < ramp) return cycle / ramp;
  if (cycle < on) return 1;
  if (ramp > 0 && cycle < on + ramp) return 1 - (cycle - on) / ramp;
  return 0;
}

std::string wind_speed_rule() {
  char text[64];
  std::snprintf(text, sizeof text, "must be from 0 to %g m/s", kFastestWind);
  return std::string(text) +
         " (the cone model treats the air as incompressible, which holds below about 0.3 of the speed of sound)";
}

bool acceptable_wind_speed(double v0) { return v0 >= 0 && v0 <= kFastestWind; }

}  // namespace aloft
