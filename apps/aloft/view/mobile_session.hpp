#pragma once
// What the viewer shows, without any window or GL: the mobile file, its spec and compiled model, the
// running simulation, the settings a visitor changes (mass, balance, contact, damping, wind), the mouse
// spring, and the pacing of physics against the wall clock. Reloading a file that has become broken
// keeps the old mobile running and records the error for the window to show.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "aloft/contact_tally.hpp"
#include "aloft/model.hpp"
#include "aloft/simulation.hpp"
#include "aloft/spec.hpp"

#if ALOFT_HAVE_WIND
#include "aloft/wind.hpp"
#endif

namespace aloft::view {

// The mouse spring: a point of a component pulled towards a target point.
struct Grab {
  int component = -1;
  Vec3 point_body = Vec3::Zero();     // body frame, m
  Vec3 target = Vec3::Zero();         // world, m
  Vec3 point_world(const State& s) const { return s.position[component] + s.orientation[component] * point_body; }
};

// Settings that need the model compiled again when they change.
struct BuildSettings {
  std::optional<BalanceMode> balance;         // empty: as the file says
  std::optional<double> total_mass;           // kg; empty: as the file says (balance mode "mass" only)
  std::optional<double> restitution;          // empty: as the file says
  std::optional<double> friction;
  std::optional<bool> contact_enabled;
};

// The strongest steady breeze the viewer offers (m/s at S0): the limit of `aloft view --breeze` and of
// the panel's breeze slider, and the full scale of its speed bar.
inline constexpr double kStrongestBreeze = 20.0;

#if ALOFT_HAVE_WIND
// The wind as the viewer drives it: a source aimed at the mobile, a steady breeze, gusts and the
// microphone's speed added together.
struct WindControl {
  bool enabled = true;
  bool follow_camera = true;          // the source sits on the viewer's side until the user aims it
  Vec3 along = Vec3(0, 0, -1);        // unit, where it blows
  double distance = 2.5;              // m from the mobile's centre to S0
  double r0 = 0.0;                    // m; 0: wide enough to cover the mobile (source_facing_mobile)
  double l0 = 1.0;                    // m
  double breeze = 0.0;                // m/s: steady v0 (0 to kStrongestBreeze)
  double mic_v0 = 0.0;                // m/s from the microphone (set by the window layer)
  double gust_peak = 4.0;             // m/s added by a gust at its start, decaying
  double gust_time = 0.7;             // s, decay time constant of a gust
  WindSettings settings;
};

// A wind source of the mobile file ("wind_sources": a fan, a vent) as the viewer blows it: its own Wind
// (cone and occlusion), switched on and off in the panel. The window's wind switch (W) stops it too.
struct FileWind {
  WindSourceSpec source;              // as the file says
  bool enabled = true;
  std::unique_ptr<Wind> wind;         // null when it could not be built (error() says why)
  double since_refresh = 1e9;         // simulated s since its last occlusion refresh
};
#endif

class MobileSession {
 public:
  // Loads `path`. Throws InputError for a bad file (there is no old mobile to keep yet).
  explicit MobileSession(const std::string& path, BuildSettings build = {});
  ~MobileSession();

  // Load another file (drag and drop) or the same one again. On success the new mobile replaces the old,
  // from its rest pose, and error() is cleared; on failure the old one keeps running, error() says why
  // and false is returned.
  bool load(const std::string& path);
  // Reload when the file on disk changed since it was last read (its modification time or size).
  // Returns whether a reload was attempted.
  bool reload_if_changed();

  const std::string& path() const { return path_; }
  const std::string& error() const { return error_; }
  void clear_error() { error_.clear(); }
  const MobileSpec& spec() const { return *spec_; }
  const Model& model() const { return *model_; }
  Simulation& simulation() { return *sim_; }
  const Simulation& simulation() const { return *sim_; }
  // Increases whenever model() is a new object (the renderer must upload its meshes again).
  int model_generation() const { return generation_; }

  // Compile again with new settings. The state is kept when the geometry did not move (a mass change),
  // otherwise the mobile restarts from rest. On a compile error the old model stays, error() says why.
  bool rebuild(const BuildSettings& build);
  const BuildSettings& build_settings() const { return build_; }
  // Rates out of the mobile file's range (0 to kGreatestDampingRate, 1/s) are refused: false, error() says
  // why, the old damping stays.
  bool set_damping(const DampingSpec& damping);
  const DampingSpec& damping() const { return damping_; }

  void reset();                 // to the designed pose at rest
  bool failed() const { return sim_->failure().has_value(); }

  // Physics pacing. Advance the simulation by `wall_seconds` x time_scale (the wall time is clamped to
  // 0.1 s, so a stall does not cause a jump), spending at most `budget_seconds` of compute; what cannot be
  // done in the budget is dropped (slow motion rather than a spiral). Returns the simulated seconds done.
  double advance(double wall_seconds, double budget_seconds);
  // Exactly one physics step (the viewer's single step when paused).
  void single_step();
  double time_scale = 1.0;      // 1: real time; < 1: slow motion
  bool paused = false;

  // The mouse spring (a stiffness per kilogram of the whole mobile, critically damped on the component).
  void grab(const Grab& grab) { grab_ = grab; }
  void move_grab(const Vec3& target) { if (grab_) grab_->target = target; }
  void release() { grab_.reset(); }
  const std::optional<Grab>& grabbed() const { return grab_; }
  Vec3 grab_force() const;      // N, world: the spring's pull now (0 without a grab)

  // The pairs of components that touched since the mobile was loaded, rebuilt or reset (or
  // clear_contacts()), counted at every step (include/aloft/contact_tally.hpp); the last step's end time,
  // to tell the pairs touching now (Pair::last equal to it).
  const ContactTally& contact_tally() const { return contacts_; }
  double last_step_time() const { return sim_->state().time; }
  void clear_contacts() { contacts_ = ContactTally{}; }
  // Per component: 1 when it touched another at the last step (a pair of contact_tally() with `last` at
  // last_step_time()), else 0. Resized to the component count; all 0 with collisions off.
  void touching_now(std::vector<std::uint8_t>& touching) const;

  // Compute time of the last advance(), s: physics (solver) and wind (occlusion and forces).
  double last_physics_seconds() const { return physics_seconds_; }
  double last_wind_seconds() const { return wind_seconds_; }

#if ALOFT_HAVE_WIND
  WindControl wind_control;
  void gust() { gust_level_ = wind_control.gust_peak; }
  double v0() const;                                   // m/s now: breeze + gust + microphone
  const Wind* wind() const { return wind_.get(); }
  // Apply wind_control's source and settings (after a slider moved). A set alpha beyond water's for l0
  // (kDensestWind l0^4, the files' rule) is brought down to it. Returns false with error() set when they
  // are invalid.
  bool update_wind(const Vec3& camera_forward);

  // The file's wind sources, in file order (rebuilt with every new model; a source keeps its on/off
  // state across a reload of the same file while its name stays). They use wind_control.settings' resolution, tile and
  // gust time, and the file's alpha, beta and seed where it gives them (else air for its l0, 0.3, and
  // wind_control.settings.seed + 1 + index, as `aloft simulate` does).
  const std::vector<FileWind>& file_winds() const { return file_winds_; }
  void set_file_wind_enabled(std::size_t index, bool on);
  // Whether a newly loaded file's sources start on (false: `aloft view --no-file-wind`).
  void set_file_winds_on_load(bool on) { file_winds_on_load_ = on; }
  double file_wind_v0(std::size_t index) const;       // m/s now (0 when off or the wind is off)
#endif

 private:
  // keep_switches: the same file again (a reload or rebuild): its wind sources keep their switches.
  void install(std::unique_ptr<MobileSpec> spec, std::unique_ptr<Model> model, bool keep_state, bool keep_switches);
  void step_once();
  std::filesystem::file_time_type file_time() const;
  std::uintmax_t file_size() const;

  std::string path_;
  std::string error_;
  BuildSettings build_;
  std::unique_ptr<MobileSpec> spec_;
  std::unique_ptr<Model> model_;
  std::unique_ptr<Simulation> sim_;    // refers to *model_: destroyed first
  int generation_ = 0;
  DampingSpec damping_;
  std::filesystem::file_time_type loaded_time_{};
  std::uintmax_t loaded_size_ = 0;
  double debt_ = 0;                    // simulated seconds owed to the wall clock
  std::optional<Grab> grab_;
  double physics_seconds_ = 0, wind_seconds_ = 0;
  ContactTally contacts_;
#if ALOFT_HAVE_WIND
  void build_file_winds(const std::vector<FileWind>& before);
  std::unique_ptr<Wind> wind_;
  std::vector<FileWind> file_winds_;   // refer to *model_: cleared before it changes
  bool file_winds_on_load_ = true;
  double gust_level_ = 0;
  double since_refresh_ = 1e9;         // simulated s since the last occlusion refresh
#endif
};

// parse + compile with the settings applied (throws InputError).
std::unique_ptr<Model> compile_with(const MobileSpec& spec, const BuildSettings& build);

}  // namespace aloft::view
