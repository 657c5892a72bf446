// The wind flags of `aloft simulate` and `aloft render`, and the winds they build (flags and file).

#include "wind_options.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "aloft/error.hpp"
#include "aloft/geometry.hpp"

namespace aloft::cli {

namespace {

// "x,y,z" as a point (m), or nothing.
std::optional<Vec3> read_point(const std::string& text) {
  Vec3 p;
  std::stringstream in(text);
  for (int i = 0; i < 3; ++i) {
    std::string field;
    if (!std::getline(in, field, ',')) return std::nullopt;
    const std::optional<double> coordinate = read_number(field);
    if (!coordinate || !std::isfinite(*coordinate)) return std::nullopt;
    p[i] = *coordinate;
  }
  std::string rest;
  if (std::getline(in, rest)) return std::nullopt;
  return p;
}

// A point x,y,z (m) within the mobile file's rule for coordinates (spec.hpp: kLongestLength).
CLI::Validator point_validator() {
  return CLI::Validator(
      [](std::string& input) -> std::string {
        const std::optional<Vec3> p = read_point(input);
        if (!p) return "must be a point x,y,z in metres, got \"" + input + "\"";
        if (p->cwiseAbs().maxCoeff() > kLongestLength)
          return format("must be a point x,y,z with each coordinate from -%g to %g m (no mobile is larger), got \"",
                        kLongestLength, kLongestLength) +
                 input + "\"";
        return {};
      },
      "");
}

// What needs more than one flag, checked once the command line is read:
// - the flags that place the flags' own wind, which without --wind, --wind-speed or --wind-audio would be
//   ignored without a word (the file's sources have their own from, to, r0 and l0);
// - --wind-alpha against --wind-l0 for that wind. Without one, --wind-alpha is only for the file's
//   sources, and make_file_wind checks it against theirs.
void check_wind_flags(const CLI::App& sub, const WindOptions& o) {
  if (!o.any())
    for (const char* name : {"--wind-from", "--wind-to", "--wind-r0", "--wind-l0"})
      if (sub.count(name) > 0)
        throw CLI::ValidationError(name, "places the wind of --wind, --wind-speed or --wind-audio, and none of them "
                                         "was given (a mobile file's wind sources have their own)");
  if (o.any() && o.alpha > 0 && !acceptable_wind_alpha(o.alpha, o.l0))
    throw CLI::ValidationError("--wind-alpha", wind_alpha_rule(o.l0) + ", got " + format("%g", o.alpha));
}

}  // namespace

CLI::Validator wind_speed() {
  return CLI::Validator(
      [](std::string& input) -> std::string {
        const std::optional<double> v = read_number(input);
        if (v && acceptable_wind_speed(*v)) return {};
        return wind_speed_rule() + ", got \"" + input + "\"";
      },
      "");
}

namespace {

std::string point_text(const Vec3& p) { return format("(%.3g, %.3g, %.3g)", p.x(), p.y(), p.z()); }

// The settings the flags give every wind (file sources may override alpha, beta and seed).
WindSettings settings_from_flags(const WindOptions& o) {
  WindSettings settings;
  settings.alpha = o.alpha;
  settings.beta = o.beta;
  settings.correlation_time = o.gust_time;
  settings.seed = static_cast<std::uint64_t>(o.seed);
  settings.resolution = o.resolution;
  settings.tile_pixels = std::min(o.tile, o.resolution);
  return settings;
}

std::string profile_text(const WindProfileSpec& p) {
  switch (p.kind) {
    case WindProfileKind::Steady: return "steady";
    case WindProfileKind::OnOff:
      return format("on %g s of every %g s (ramp %g s, phase %g s)", p.on, p.period, p.ramp, p.phase);
    case WindProfileKind::Swell:
      return format("swelling, down by %g %% every %g s (phase %g s)", 100 * p.depth, p.period, p.phase);
  }
  return "";
}

}  // namespace

void add_wind_options(CLI::App* sub, WindOptions& o) {
  const char* group = "Wind (the paper's cone; see docs/wind.md)";
  auto* constant = sub->add_option("--wind", o.constant,
                                   "Blow a steady wind: speed v0 at the source disc S0 (m/s, 0 to 100)")
                       ->type_name("V0")
                       ->check(wind_speed())
                       ->group(group);
  auto* speed = sub->add_option("--wind-speed", o.speed_csv,
                                "Wind speed v0 over time from a CSV of \"t,v0\" rows (s, m/s; linear in between, "
                                "held after the end)")
                    ->type_name("FILE")
                    ->group(group);
  auto* audio = sub->add_option("--wind-audio", o.audio,
                                "Wind speed from a WAV recording of someone blowing on a microphone (envelope "
                                "minus the noise floor of its first second, times --wind-gain)")
                    ->type_name("FILE")
                    ->group(group);
  constant->excludes(speed)->excludes(audio);
  speed->excludes(audio);
  sub->add_option("--wind-from", o.from,
                  format("Centre of the source disc S0 (x,y,z, m); default: %g m in front (+z) of the mobile's centre",
                         kFrontSourceDistance))
      ->type_name("X,Y,Z")
      ->check(point_validator())
      ->group(group);
  sub->add_option("--wind-to", o.to, "Where the wind blows (x,y,z, m); default: the mobile's centre")
      ->type_name("X,Y,Z")
      ->check(point_validator())
      ->group(group);
  sub->add_option("--wind-r0", o.r0,
                  format("Radius of S0 (m, > 0, up to %g); default: the cone just covers the mobile", kLongestLength))
      ->type_name("R0")
      ->check(length_in_metres())
      ->group(group);
  sub->add_option("--wind-l0", o.l0, format("Distance from the cone's vertex to S0 (m, > 0, up to %g)", kLongestLength))
      ->type_name("L0")
      ->capture_default_str()
      ->check(length_in_metres())
      ->group(group);
  sub->add_option("--wind-alpha", o.alpha,
                  format("Drag constant alpha of F = alpha A v0^2 / l1^4 cos (kg m, > 0, up to water's %g * l0^4); "
                         "default: air, %g * l0^4",
                         kDensestWind, kAirDensity))
      ->type_name("A")
      ->check(positive_number())
      ->group(group);
  sub->add_option("--wind-beta", o.beta, "Turbulence: |F_random| < beta |F_stoke| (0: none, up to 10)")
      ->type_name("B")
      ->capture_default_str()
      ->check(number_in(0.0, 10.0))
      ->group(group);
  sub->add_option("--wind-gust-time", o.gust_time, "Correlation time of the turbulence (s, >= 0)")
      ->type_name("S")
      ->capture_default_str()
      ->check(non_negative_number())
      ->group(group);
  sub->add_option("--wind-seed", o.seed, "Seed of the turbulence (same seed, same run)")
      ->type_name("N")
      ->capture_default_str()
      ->check(integer_in(0, 4000000000000000000LL))
      ->group(group);
  sub->add_option("--wind-resolution", o.resolution, "Item buffer size for occlusion (pixels per side, 8 to 8192)")
      ->type_name("PX")
      ->capture_default_str()
      ->check(integer_in(8, 8192))
      ->group(group);
  sub->add_option("--wind-tile", o.tile, "Pixels per side merged into one area element (1: every pixel)")
      ->type_name("PX")
      ->capture_default_str()
      ->check(integer_in(1, 8192))
      ->group(group);
  sub->add_option("--wind-refresh", o.refresh, "Occlusion refreshes per simulated second (Hz, > 0)")
      ->type_name("HZ")
      ->capture_default_str()
      ->check(positive_number())
      ->group(group);
  sub->add_option("--wind-gain", o.gain, "With --wind-audio: m/s of v0 per unit of RMS above the noise floor")
      ->type_name("G")
      ->capture_default_str()
      ->check(non_negative_number())
      ->needs("--wind-audio")  // else ignored without a word
      ->group(group);
  sub->add_option("--wind-noise-floor", o.noise_floor,
                  "With --wind-audio: the noise floor (RMS, 0 to 1) instead of calibrating it")
      ->type_name("RMS")
      ->check(number_in(0.0, 1.0))
      ->needs("--wind-audio")  // else ignored without a word
      ->group(group);
  sub->add_option("--wind-calibrate", o.calibrate,
                  "With --wind-audio: seconds of room sound at the start that set the noise floor (0 to 60)")
      ->type_name("S")
      ->capture_default_str()
      ->check(number_in(0.0, 60.0))
      ->needs("--wind-audio")  // else ignored without a word
      ->group(group);
  add_no_file_wind_flag(sub, o.no_file_wind);
  sub->parse_complete_callback([sub, &o] { check_wind_flags(*sub, o); });
}

void add_no_file_wind_flag(CLI::App* sub, bool& no_file_wind) {
  sub->add_flag("--no-file-wind", no_file_wind,
                "Ignore the wind sources of the mobile file (its \"wind_sources\": fans, vents)")
      ->group("Wind (the paper's cone; see docs/wind.md)");
}

std::optional<WindDriver> make_wind(const Model& model, const State& state, const WindOptions& o, double timestep) {
  if (!o.any()) return std::nullopt;
  WindDriver d;
  // Where the wind comes from: S0 at `from` blowing towards `to`, the cone just covering the mobile
  // unless r0 is given.
  const MobileSphere cover = mobile_sphere(model, state);
  const Vec3 to = o.to.empty() ? cover.center : *read_point(o.to);
  const Vec3 from = o.from.empty() ? Vec3(cover.center + Vec3(0, 0, kFrontSourceDistance)) : *read_point(o.from);
  if ((to - from).norm() < 1e-9) throw Failure("--wind-from and --wind-to must be two different points");
  const WindSettings settings = settings_from_flags(o);
  try {
    const WindSource source =
        o.r0 > 0 ? WindSource::aimed(from, to, o.r0, o.l0) : source_covering(from, to, o.l0, cover);
    d.wind = std::make_unique<Wind>(model, source, settings);
  } catch (const std::invalid_argument& e) {
    throw Failure(e.what());
  }
  d.refresh_every = occlusion_refresh_steps(o.refresh, timestep);

  std::string speed;
  if (o.constant) {
    d.constant = *o.constant;
    speed = format("v0 = %g m/s, steady", *o.constant);
  } else if (!o.speed_csv.empty()) {
    d.series = read_speed_csv(o.speed_csv);
    speed = format("v0 from %s (%zu samples over %.3g s)", o.speed_csv.c_str(), d.series.t.size(), d.series.duration());
  } else {
    const AudioClip clip = read_wav(o.audio);
    EnvelopeSettings envelope;
    envelope.gain = o.gain;
    envelope.noise_floor = o.noise_floor;
    envelope.calibration_s = o.calibrate;
    // The follower's v0 is 0 while it calibrates: a recording no longer than the calibration would be the
    // room's sound throughout, and the run would go without wind and without a word.
    const std::uint64_t calibrating = envelope.calibration_frames(clip.sample_rate);
    if (o.noise_floor < 0 && calibrating > 0 && clip.frames() <= calibrating)
      throw InputError(o.audio, {},
                       format("the recording lasts %g s, no longer than the %g s of noise-floor calibration at its "
                              "start (--wind-calibrate), so no wind would blow; give --wind-calibrate 0 (or a "
                              "shorter time) or --wind-noise-floor",
                              clip.duration(), o.calibrate));
    d.series = speed_from_audio(clip, envelope, 0.001);
    double peak = 0;
    for (double v : d.series.v0) peak = std::max(peak, v);
    speed = format("v0 from %s (%.3g s, %d Hz, %d ch; peak v0 %.3g m/s)", o.audio.c_str(), clip.duration(),
                   clip.sample_rate, clip.channels, peak);
  }
  d.description = speed + format("; S0 at %s r0 = %.3g m, l0 = %.3g m, towards %s; alpha = %.3g kg m, beta = %g; "
                                 "occlusion %d px every %d steps",
                                 point_text(from).c_str(), d.wind->source().r0, o.l0, point_text(to).c_str(),
                                 d.wind->alpha(), o.beta, o.resolution, d.refresh_every);
  return d;
}

WindDriver make_file_wind(const Model& model, const WindSourceSpec& source, std::size_t index, const WindOptions& o,
                          double timestep) {
  if (!source.alpha && o.alpha > 0 && !acceptable_wind_alpha(o.alpha, source.l0))  // the flag's, for its l0
    throw Failure(model.file + ": " + source.path + " (l0 = " + format("%g", source.l0) +
                  " m) takes --wind-alpha, which " + wind_alpha_rule(source.l0) + ", got " + format("%g", o.alpha));
  const WindSettings settings = file_source_settings(source, index, settings_from_flags(o));
  WindDriver d;
  try {
    d.wind = std::make_unique<Wind>(model, file_source_cone(source), settings);
  } catch (const std::invalid_argument& e) {
    throw Failure(model.file + ": " + source.path + ": " + e.what());
  }
  d.file_source = source;
  d.refresh_every = occlusion_refresh_steps(o.refresh, timestep);
  d.description = format("\"%s\" (file): v0 = %g m/s, %s; S0 at %s r0 = %.3g m, l0 = %.3g m, towards %s; "
                         "alpha = %.3g kg m, beta = %g",
                         source.name.c_str(), source.speed, profile_text(source.profile).c_str(),
                         point_text(source.from).c_str(), source.r0, source.l0, point_text(source.to).c_str(),
                         d.wind->alpha(), settings.beta);
  return d;
}

WindSet::WindSet(const Model& model, const MobileSpec& spec, const State& state, const WindOptions& o,
                 double timestep) {
  if (auto flags = make_wind(model, state, o, timestep)) drivers_.push_back(std::move(*flags));
  if (o.no_file_wind) return;
  for (std::size_t i = 0; i < spec.wind_sources.size(); ++i)
    drivers_.push_back(make_file_wind(model, spec.wind_sources[i], i, o, timestep));
}

void WindSet::apply(long long step, const State& state, double h, ExternalLoads& loads) {
  if (drivers_.empty()) return;
  loads.clear();
  for (WindDriver& d : drivers_) {
    if (step % d.refresh_every == 0) {
      const auto t0 = WallClock::now();
      d.wind->refresh_occlusion(state);
      occlusion_seconds_ += seconds_since(t0);
      ++refreshes_;
      elements_ += d.wind->elements().size();
    }
    d.wind->apply(state, d.v0(state.time), h, loads);  // adds to the loads
  }
}

LoadedMobile load_mobile_with_spec(const std::string& file, const std::string& balance_mode) {
  MobileSpec spec = parse_mobile_file(file);
  if (balance_mode == "mass") spec.balance.mode = BalanceMode::Mass;
  if (balance_mode == "joints") spec.balance.mode = BalanceMode::Joints;
  if (balance_mode == "none") spec.balance.mode = BalanceMode::None;
  Model model = compile(spec);
  return LoadedMobile{std::move(spec), std::move(model)};
}

}  // namespace aloft::cli
