#include "mobile_session.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <stdexcept>

#include "aloft/error.hpp"
#include "aloft/wall_clock.hpp"

namespace aloft::view {

namespace {

using Clock = WallClock;

// The mouse spring: stiffness per kilogram of the whole mobile (N/m per kg), so that a pull of 10 cm
// on any mobile gives an acceleration of about 6 m/s^2 to the whole; damped critically on the grabbed
// component alone. With h = 1 ms and the lightest preset component (~20 g) the spring's frequency stays
// far below the step's stability limit 2/h.
constexpr double kGrabStiffnessPerKg = 60;

// Wind occlusion is refreshed at this rate of simulated time (kOcclusionRefreshRate, wind.hpp): the
// mobile moves little in 1/60 s, and between refreshes the elements follow their components.
constexpr double kOcclusionInterval = 1.0 / kOcclusionRefreshRate;

bool same_pose(const Model& a, const Model& b) {
  if (a.count != b.count) return false;
  for (int i = 0; i < a.count; ++i) {
    // Positions to a micrometre and orientations to a microradian: a recompile with another total mass
    // reproduces them to rounding; any real edit moves something far more.
    if ((a.rest_position[i] - b.rest_position[i]).norm() > 1e-6) return false;
    if (a.rest_orientation[i].angularDistance(b.rest_orientation[i]) > 1e-6) return false;
  }
  return true;
}

double moving_mass(const Model& m) { return std::accumulate(m.mass.begin() + 1, m.mass.end(), 0.0); }

// "<what> must be a number from <lo> to <hi> (<unit>)", the unit left out when empty.
std::string range_text(const char* what, double lo, double hi, const char* unit) {
  char text[160];
  std::snprintf(text, sizeof text, "%s must be a number from %g to %g%s%s%s", what, lo, hi, *unit ? " (" : "", unit,
                *unit ? ")" : "");
  return text;
}

}  // namespace

std::unique_ptr<Model> compile_with(const MobileSpec& spec_in, const BuildSettings& build) {
  MobileSpec spec = spec_in;
  if (build.balance) spec.balance.mode = *build.balance;
  // The mobile file's rules (parse_mobile.cpp, spec.hpp), for settings that come from the window instead.
  if (build.total_mass) {
    if (!(*build.total_mass >= kLightestMobile && *build.total_mass <= kHeaviestMobile))
      throw std::invalid_argument(range_text("the total mass", kLightestMobile, kHeaviestMobile, "kg"));
    spec.balance.total_mass = *build.total_mass;
  }
  if (build.restitution) {
    if (!(*build.restitution >= 0 && *build.restitution <= 1))
      throw std::invalid_argument(range_text("the restitution", 0, 1, ""));
    spec.contact.restitution = *build.restitution;
  }
  if (build.friction) {
    if (!(std::isfinite(*build.friction) && *build.friction >= 0))
      throw std::invalid_argument("the friction coefficient must be a number >= 0");
    spec.contact.friction = *build.friction;
  }
  if (build.contact_enabled) spec.contact.enabled = *build.contact_enabled;
  if (spec.balance.mode == BalanceMode::Mass && !spec.balance.total_mass) {
    // A file in another mode switched to "mass" in the window: keep the mass it has now.
    MobileSpec as_is = spec;
    as_is.balance.mode = BalanceMode::None;
    spec.balance.total_mass = moving_mass(compile(as_is));
  }
  return std::make_unique<Model>(compile(spec));
}

MobileSession::MobileSession(const std::string& path, BuildSettings build) : path_(path), build_(build) {
  auto spec = std::make_unique<MobileSpec>(parse_mobile_file(path));
  auto model = compile_with(*spec, build_);
  loaded_time_ = file_time();
  loaded_size_ = file_size();
  install(std::move(spec), std::move(model), false, false);
}

MobileSession::~MobileSession() {
#if ALOFT_HAVE_WIND
  wind_.reset();
  file_winds_.clear();
#endif
  sim_.reset();
}

std::filesystem::file_time_type MobileSession::file_time() const {
  std::error_code ec;
  const auto t = std::filesystem::last_write_time(path_, ec);
  return ec ? std::filesystem::file_time_type{} : t;
}

std::uintmax_t MobileSession::file_size() const {
  std::error_code ec;
  const auto s = std::filesystem::file_size(path_, ec);
  return ec ? 0 : s;
}

void MobileSession::install(std::unique_ptr<MobileSpec> spec, std::unique_ptr<Model> model, bool keep_state,
                            bool keep_switches) {
  std::optional<State> kept;
  if (keep_state && sim_ && !failed() && same_pose(*model_, *model)) kept = sim_->state();
#if ALOFT_HAVE_WIND
  wind_.reset();  // refers to the old model
  std::vector<FileWind> file_winds_before = std::move(file_winds_);
  file_winds_.clear();
  for (FileWind& w : file_winds_before) w.wind.reset();  // so do these
  if (!keep_switches) file_winds_before.clear();
#endif
  sim_.reset();
  spec_ = std::move(spec);
  model_ = std::move(model);
#if ALOFT_HAVE_WIND
  build_file_winds(file_winds_before);
#endif
  sim_ = kept ? std::make_unique<Simulation>(*model_, *kept) : std::make_unique<Simulation>(*model_);
  if (!keep_state) damping_ = model_->damping;
  sim_->set_damping(damping_);
  sim_->loads().resize(model_->count);
  grab_.reset();
  debt_ = 0;
  contacts_ = ContactTally{};
  ++generation_;
}

bool MobileSession::load(const std::string& path) {
  try {
    auto spec = std::make_unique<MobileSpec>(parse_mobile_file(path));
    auto model = compile_with(*spec, build_);
    const bool same_file = path == path_;
    path_ = path;
    loaded_time_ = file_time();
    loaded_size_ = file_size();
    install(std::move(spec), std::move(model), false, same_file);
    error_.clear();
    return true;
  } catch (const std::exception& e) {
    // Remember the file as read, so a broken file is not re-read every poll until it changes again.
    if (path == path_) {
      loaded_time_ = file_time();
      loaded_size_ = file_size();
    }
    error_ = e.what();
    return false;
  }
}

bool MobileSession::reload_if_changed() {
  if (file_time() == loaded_time_ && file_size() == loaded_size_) return false;
  load(path_);
  return true;
}

bool MobileSession::rebuild(const BuildSettings& build) {
  try {
    auto model = compile_with(*spec_, build);
    build_ = build;
    install(std::make_unique<MobileSpec>(*spec_), std::move(model), true, true);
    error_.clear();
    return true;
  } catch (const std::exception& e) {
    error_ = e.what();
    return false;
  }
}

bool MobileSession::set_damping(const DampingSpec& damping) {
  const auto in_range = [](double rate) { return rate >= 0 && rate <= kGreatestDampingRate; };  // NaN fails
  if (!in_range(damping.linear) || !in_range(damping.angular)) {
    error_ = range_text("the damping rates", 0, kGreatestDampingRate, "1/s");
    return false;
  }
  damping_ = damping;
  sim_->set_damping(damping);
  return true;
}

void MobileSession::reset() {
  sim_->mutable_state() = rest_state(*model_);
  // A failed simulation cannot continue: start a fresh one from rest.
  if (failed()) {
    sim_ = std::make_unique<Simulation>(*model_);
    sim_->set_damping(damping_);
    sim_->loads().resize(model_->count);
  }
  grab_.reset();
  debt_ = 0;
  contacts_ = ContactTally{};
#if ALOFT_HAVE_WIND
  since_refresh_ = 1e9;
  for (FileWind& w : file_winds_) w.since_refresh = 1e9;
#endif
}

Vec3 MobileSession::grab_force() const {
  if (!grab_ || grab_->component <= 0 || grab_->component >= model_->count) return Vec3::Zero();
  const State& s = sim_->state();
  const int c = grab_->component;
  const Vec3 arm = s.orientation[c] * grab_->point_body;
  const Vec3 point = s.position[c] + arm;
  const Vec3 velocity = s.velocity[c] + s.angular[c].cross(arm);
  const double k = kGrabStiffnessPerKg * std::max(moving_mass(*model_), 1e-3);
  const double damping = 2 * std::sqrt(k * model_->mass[c]);
  return k * (grab_->target - point) - damping * velocity;
}

#if ALOFT_HAVE_WIND
double MobileSession::v0() const {
  if (!wind_control.enabled) return 0;
  return wind_control.breeze + gust_level_ + wind_control.mic_v0;
}

bool MobileSession::update_wind(const Vec3& camera_forward) {
  WindControl& w = wind_control;
  if (w.follow_camera) {
    // From the viewer's side: along the camera's view, level with the floor so it does not blow down.
    Vec3 along(camera_forward.x(), 0, camera_forward.z());
    if (along.norm() > 1e-6) w.along = along.normalized();
  }
  // A set alpha keeps the files' rule at this l0 (at most water's, kDensestWind l0^4): a shorter l0
  // takes it down with it.
  w.settings.alpha = std::min(w.settings.alpha, largest_wind_alpha(w.l0));
  try {
    WindSource source = source_facing_mobile(*model_, sim_->state(), w.along, w.distance, w.l0);
    if (w.r0 > 0) source.r0 = w.r0;
    else w.r0 = source.r0;
    source.validate();
    w.settings.validate();
    if (!wind_) {
      wind_ = std::make_unique<Wind>(*model_, source, w.settings);
      since_refresh_ = 1e9;
    } else {
      wind_->set_source(source);
      const WindSettings& now = wind_->settings();
      if (now.alpha != w.settings.alpha || now.beta != w.settings.beta || now.resolution != w.settings.resolution ||
          now.tile_pixels != w.settings.tile_pixels || now.correlation_time != w.settings.correlation_time)
        wind_->set_settings(w.settings);
    }
    return true;
  } catch (const std::exception& e) {
    error_ = std::string("wind: ") + e.what();
    return false;
  }
}

void MobileSession::build_file_winds(const std::vector<FileWind>& before) {
  file_winds_.reserve(spec_->wind_sources.size());
  for (std::size_t i = 0; i < spec_->wind_sources.size(); ++i) {
    FileWind w;
    w.source = spec_->wind_sources[i];
    w.enabled = file_winds_on_load_;
    for (const FileWind& old : before)
      if (old.source.name == w.source.name) w.enabled = old.enabled;  // a reload keeps the switch
    // The window's resolution, tile, gust time and seed; air for the source's own l0 and the default
    // turbulence unless the file says.
    WindSettings run = wind_control.settings;
    run.alpha = -1;
    run.beta = WindSettings{}.beta;
    try {
      w.wind = std::make_unique<Wind>(*model_, file_source_cone(w.source), file_source_settings(w.source, i, run));
    } catch (const std::exception& e) {
      error_ = "wind source \"" + w.source.name + "\": " + e.what();
    }
    file_winds_.push_back(std::move(w));
  }
}

void MobileSession::set_file_wind_enabled(std::size_t index, bool on) {
  if (index < file_winds_.size()) file_winds_[index].enabled = on;
}

double MobileSession::file_wind_v0(std::size_t index) const {
  if (index >= file_winds_.size() || !wind_control.enabled || !file_winds_[index].enabled) return 0;
  return file_winds_[index].source.v0(sim_->state().time);
}
#endif

void MobileSession::step_once() {
  ExternalLoads& loads = sim_->loads();
  loads.clear();
  const double h = sim_->timestep();
#if ALOFT_HAVE_WIND
  if (wind_ && wind_control.enabled) {
    const auto t0 = Clock::now();
    if (since_refresh_ >= kOcclusionInterval) {
      wind_->refresh_occlusion(sim_->state());
      since_refresh_ = 0;
    }
    wind_->apply(sim_->state(), v0(), h, loads);
    since_refresh_ += h;
    wind_seconds_ += seconds_since(t0);
  }
  {
    const auto t0 = Clock::now();
    for (FileWind& w : file_winds_) {
      if (!wind_control.enabled || !w.enabled || !w.wind) {
        w.since_refresh = 1e9;  // switched on again: see the pose of then, not of when it stopped
        continue;
      }
      if (w.since_refresh >= kOcclusionInterval) {
        w.wind->refresh_occlusion(sim_->state());
        w.since_refresh = 0;
      }
      w.wind->apply(sim_->state(), w.source.v0(sim_->state().time), h, loads);
      w.since_refresh += h;
    }
    wind_seconds_ += seconds_since(t0);
  }
  gust_level_ *= std::exp(-h / wind_control.gust_time);
#endif
  if (grab_) {
    const State& s = sim_->state();
    const int c = grab_->component;
    const Vec3 f = grab_force();
    loads.force[c] += f;
    loads.torque[c] += (s.orientation[c] * grab_->point_body).cross(f);
  }
  const auto t0 = Clock::now();
  const bool stepped = sim_->step();
  physics_seconds_ += seconds_since(t0);
  if (stepped && sim_->collisions()) contacts_.add_step(sim_->contacts(), sim_->pushed_pairs(), sim_->state().time);
}

double MobileSession::advance(double wall_seconds, double budget_seconds) {
  physics_seconds_ = wind_seconds_ = 0;
  if (paused || failed()) {
    debt_ = 0;
    return 0;
  }
  debt_ += std::clamp(wall_seconds, 0.0, 0.1) * time_scale;
  const double h = sim_->timestep();
  const double start_time = sim_->state().time;
  const auto start = Clock::now();
  while (debt_ >= h * (1 - 1e-9) && !failed()) {  // (a whole step owed, to rounding of the sums)
    step_once();
    debt_ -= h;
    if (seconds_since(start) > budget_seconds) {
      debt_ = std::fmod(debt_, h);  // cannot keep up: drop the rest (slow motion, no spiral)
      break;
    }
  }
  if (failed()) error_ = sim_->failure()->message + " (press R to reset)";
  return sim_->state().time - start_time;
}

void MobileSession::touching_now(std::vector<std::uint8_t>& touching) const {
  contacts_.components_touching_since(last_step_time(), model_->count, touching);
}

void MobileSession::single_step() {
  physics_seconds_ = wind_seconds_ = 0;
  if (!failed()) step_once();
  if (failed()) error_ = sim_->failure()->message + " (press R to reset)";
}

}  // namespace aloft::view
