#pragma once
// The wind flags of `aloft simulate` (--wind, --wind-speed, --wind-audio, the source and the model's
// constants) and what they build: a Wind and v0(t).

#include <memory>
#include <optional>
#include <string>

#include "aloft/audio.hpp"
#include "aloft/wind.hpp"
#include "common.hpp"

namespace aloft::cli {

struct WindOptions {
  std::optional<double> constant;      // --wind V (m/s)
  std::string speed_csv;               // --wind-speed FILE
  std::string audio;                   // --wind-audio FILE
  std::string from, to;                // --wind-from, --wind-to "x,y,z" (m, world)
  double r0 = 0;                       // m; 0: wide enough to cover the mobile
  double l0 = 1.0;                     // m
  double alpha = -1;                   // kg m; < 0: kAirDensity * l0^4
  double beta = 0.3;
  double gust_time = 0.4;              // s
  long long seed = 1;
  int resolution = 256;
  int tile = 8;
  double refresh = 60;                 // Hz
  double gain = EnvelopeSettings{}.gain;
  double noise_floor = -1;             // RMS; < 0: calibrate from the first --wind-calibrate seconds
  double calibrate = 1.0;              // s
  bool any() const { return constant || !speed_csv.empty() || !audio.empty(); }
};

void add_wind_options(CLI::App* sub, WindOptions& o);

// The wind for a run: the source and settings from the flags, v0(t), how often occlusion is refreshed.
struct WindDriver {
  std::unique_ptr<Wind> wind;
  std::optional<double> constant;
  SpeedSeries series;
  int refresh_every = 17;              // steps between occlusion refreshes
  std::string description;             // for the summary
  double v0(double t) const { return constant ? *constant : series.at(t); }
};

// Nothing when no wind flag was given. Throws InputError (bad files) or Failure (bad flags).
std::optional<WindDriver> make_wind(const Model& model, const State& state, const WindOptions& o, double timestep);

}  // namespace aloft::cli
