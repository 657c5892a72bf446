// The time profile of a wind source placed by a mobile file (spec.hpp): steady, switched on and off, or
// swelling like a vent that breathes.

#include <cmath>
#include <numbers>

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

}  // namespace aloft
