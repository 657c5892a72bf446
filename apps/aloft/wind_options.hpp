#pragma once
// The wind flags of `aloft simulate` and `aloft render` (--wind, --wind-speed, --wind-audio, the source,
// the model's constants, --no-file-wind) and what they build: the winds of a run, each a Wind (its own
// cone and occlusion) and its v0(t): the one from the flags and every steady source of the mobile file.

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "aloft/audio.hpp"
#include "aloft/spec.hpp"
#include "aloft/wind.hpp"
#include "common.hpp"

namespace aloft::cli {

struct WindOptions {
  std::optional<double> constant;      // --wind V (m/s)
  std::string speed_csv;               // --wind-speed FILE
  std::string audio;                   // --wind-audio FILE
  std::string from, to;                // --wind-from, --wind-to "x,y,z" (m, world)
  double r0 = 0;                       // m; 0: wide enough to cover the mobile
  double l0 = kDefaultL0;              // m
  double alpha = -1;                   // kg m; < 0: kAirDensity * l0^4
  double beta = 0.3;
  double gust_time = 0.4;              // s
  long long seed = 1;
  int resolution = 256;
  int tile = 8;
  double refresh = kOcclusionRefreshRate;  // Hz
  double gain = EnvelopeSettings{}.gain;
  double noise_floor = -1;             // RMS; < 0: calibrate from the first --wind-calibrate seconds
  double calibrate = 1.0;              // s
  bool no_file_wind = false;           // --no-file-wind: ignore the mobile file's "wind_sources"
  bool any() const { return constant || !speed_csv.empty() || !audio.empty(); }
};

// Adds the wind flags to `sub`, and the checks that need several of them (--wind-alpha against --wind-l0;
// no source placed without a wind) as `sub`'s parse_complete_callback (CLI11 keeps one; `sub` must not
// set its own).
void add_wind_options(CLI::App* sub, WindOptions& o);
// A steady wind speed v0 (m/s) the cone model takes (aloft/spec.hpp: kFastestWind), as --wind checks it.
CLI::Validator wind_speed();
// Only --no-file-wind (for `aloft view`, whose own wind has other controls).
void add_no_file_wind_flag(CLI::App* sub, bool& no_file_wind);

// One wind of a run: a Wind, v0(t), how often occlusion is refreshed.
struct WindDriver {
  std::unique_ptr<Wind> wind;
  std::optional<double> constant;      // the flags' steady --wind
  SpeedSeries series;                  // the flags' --wind-speed or --wind-audio
  std::optional<WindSourceSpec> file_source;  // a source of the mobile file: v0 from its speed and profile
  int refresh_every = 17;              // steps between occlusion refreshes
  std::string description;             // for the summary
  double v0(double t) const {
    if (file_source) return file_source->v0(t);
    return constant ? *constant : series.at(t);
  }
};

// The wind from the flags. Nothing when no wind flag was given. Throws InputError (bad files) or Failure
// (bad flags).
std::optional<WindDriver> make_wind(const Model& model, const State& state, const WindOptions& o, double timestep);

// A Wind for a source of the mobile file. Its alpha, beta and seed come from the file when given, else
// from the flags (--wind-alpha, --wind-beta; the seed is --wind-seed + 1 + its index, so that two sources
// do not gust in step); resolution, tile, gust time and refresh rate always from the flags.
WindDriver make_file_wind(const Model& model, const WindSourceSpec& source, std::size_t index, const WindOptions& o,
                          double timestep);

// Every wind of a run: the flags' first (if any), then the file's sources (unless --no-file-wind).
class WindSet {
 public:
  WindSet(const Model& model, const MobileSpec& spec, const State& state, const WindOptions& o, double timestep);
  bool empty() const { return drivers_.empty(); }
  const std::vector<WindDriver>& drivers() const { return drivers_; }

  // Before physics step number `step` (0, 1, ...) from `state`: refresh each wind's occlusion when due,
  // then set `loads` to the sum of every wind's force and torque at v0(state.time), advancing their
  // turbulence by h (s). Does nothing (and leaves `loads` alone) when there is no wind.
  void apply(long long step, const State& state, double h, ExternalLoads& loads);

  // Occlusion statistics, summed over the winds: refreshes, their wall time (s) and elements found.
  long long refreshes() const { return refreshes_; }
  double occlusion_seconds() const { return occlusion_seconds_; }
  std::size_t elements() const { return elements_; }

 private:
  std::vector<WindDriver> drivers_;
  long long refreshes_ = 0;
  double occlusion_seconds_ = 0;
  std::size_t elements_ = 0;
};

// The mobile file read once: its spec (for the wind sources and camera) and its compiled model, with the
// balance mode overridden unless `balance_mode` is "file" (as load_mobile_as).
struct LoadedMobile {
  MobileSpec spec;
  Model model;
};
LoadedMobile load_mobile_with_spec(const std::string& file, const std::string& balance_mode);

}  // namespace aloft::cli
