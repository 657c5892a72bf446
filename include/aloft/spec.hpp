#pragma once
// The mobile as a person wrote it (the "spec"): what the JSON file says, checked for form and types but
// not yet for meaning. compile() (model.hpp) turns it into the immutable Model. Everything is in world
// coordinates at the designed rest pose (metres, y up).

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "aloft/error.hpp"
#include "aloft/shapes.hpp"

namespace aloft {

// Line and column of every JSON value by its path ("components[2].shapes[0].sphere.radius"), so that
// compile-time errors can point into the file too.
struct SourceMap {
  std::map<std::string, SourcePlace> places;
  // The place of `path`, or of its nearest ancestor present in the map, or {path, 0, 0}.
  SourcePlace locate(const std::string& path) const;
};

struct ShapeSpec {
  Shape shape;
  std::optional<double> density;            // kg/m^3; default: the component's density
  std::string path;                         // e.g. "components[2].shapes[0]"
};

struct Color {
  float r = 0.6f, g = 0.6f, b = 0.6f;      // linear 0..1 (sRGB as written)
};

struct ComponentSpec {
  std::string name;
  std::optional<std::string> parent;        // absent for the fixed component
  bool fixed = false;
  std::optional<Vec3> joint;                // world point where it hangs from its parent (rest pose)
  std::vector<ShapeSpec> shapes;
  Color color;
  std::optional<double> density;            // kg/m^3; default: the mobile's density
  std::optional<double> restitution;        // per-component contact overrides (collisions)
  std::optional<double> friction;
  std::string path;                         // e.g. "components[2]"
};

enum class BalanceMode {
  Mass,    // derive masses so the designed pose is an equilibrium, scaled to total_mass
  Joints,  // keep masses (densities), move each hanging point above what hangs from it
  None,    // masses from densities; the mobile swings from its designed pose
};

struct BalanceSpec {
  BalanceMode mode = BalanceMode::Mass;
  std::optional<double> total_mass;         // kg of all moving components; required for Mass
};

struct DampingSpec {
  double linear = 0;                        // 1/s: force -linear * m * v on every component
  double angular = 0;                       // 1/s: torque -angular * I * w
};

struct ContactSpec {
  double restitution = 0.3;                 // e, 0..1
  double friction = 0.4;                    // Coulomb mu, >= 0
  bool enabled = true;
};

// How a file wind source's speed v0 varies with time t (s, simulated, from the start of the run).
enum class WindProfileKind {
  Steady,   // v0 always
  OnOff,    // a fan switched on and off: v0 for `on` s of every `period` s, ramping over `ramp` s
  Swell,    // a vent that breathes: v0 (1 - depth (1 - cos(2 pi t' / period)) / 2), full at t' = 0
};

struct WindProfileSpec {
  WindProfileKind kind = WindProfileKind::Steady;
  double period = 10;                       // s (> 0): OnOff and Swell
  double on = 5;                            // s (0 < on <= period): OnOff, from switch-on to switch-off
  double ramp = 0;                          // s (0 <= ramp <= on, on + ramp <= period): OnOff, spin-up and
                                            // run-down time (linear); the mean factor is on / period
  double depth = 0.5;                       // 0..1: Swell, the fraction of v0 lost at the trough
  double phase = 0;                         // s: t' = t + phase (where in its cycle the source starts)

  // v0 multiplier at time t (s), in [0, 1]. OnOff: rises 0 -> 1 over [0, ramp), holds 1 until `on`,
  // falls 1 -> 0 over [on, on + ramp), then 0 until the period ends (ramp = 0: a plain switch).
  double factor(double t) const;
};

// The sizes a mobile file may give, where the arithmetic of the step and of the collision tests holds.
// Outside them no mobile is meant, and numbers far outside crash or poison the run: a hook sphere of
// radius 5.6e128 m crashed libccd's penetration test (found by fuzz_mobile_simulate), and a total mass
// of 1e300 or 1e-300 kg made the first step non-finite.
// - Lengths (m): a coordinate's distance from the origin, a size, a radius, a thickness: at most 1 km,
//   forty times the largest mobiles built (about 25 m; generated ones of 65535 components span 54 m).
//   An OBJ mesh's vertices, scaled and moved, keep to it too.
inline constexpr double kLongestLength = 1000.0;
// - total_mass (kg): from a milligram to a thousand tonnes.
inline constexpr double kLightestMobile = 1e-6;
inline constexpr double kHeaviestMobile = 1e6;
// - Densities (kg/m^3): from 1e-3 (far lighter than any solid; balancing by mass uses only their
//   ratios) to 1e6 (forty times osmium's).
inline constexpr double kLeastDensity = 1e-3;
inline constexpr double kGreatestDensity = 1e6;
// - Gravity (m/s^2): each coordinate at most 100 in size, ten times Earth's (any planet's surface has
//   less than 25; 1e300 made the balance fail with a message about something else).
inline constexpr double kStrongestGravity = 100.0;
// - Air damping rates (1/s): at most 100. The damping is an explicit force (step_workspace.hpp), stable
//   while rate * h < 2, so this holds for every timestep a file may ask (h <= 0.01 s); air gives
//   0.01-0.1 (1e300 went non-finite at step 2).
inline constexpr double kGreatestDampingRate = 100.0;
// - The fixed step (s), the file's "timestep" and the command line's --dt: from a microsecond, a
//   thousandth of the default (the step-size rule divides a step up to 256 times where a piece needs it),
//   so that the steps of the longest run are counted in 64 bits (1e-300 s made their count overflow), to
//   0.01 s, where the explicit damping and the joints' drift correction still hold.
inline constexpr double kShortestTimestep = 1e-6;
inline constexpr double kLongestTimestep = 0.01;

// The fastest wind v0 at S0 (m/s) that the mobile file, the command line and a speed series may ask for.
// The cone's continuity (eq. 2) and drag (eqs. 3-4) treat the air as incompressible, which holds to a few
// percent below about 0.3 of the speed of sound (343 m/s at 20 C: the density changes by about M^2 / 2,
// 4.5 % at M = 0.3). A breath is a few m/s, a fan 5-10 m/s, and the microphone's wind stops at 20 m/s
// (EnvelopeSettings::max_v0). Wind::apply (wind.hpp) itself takes any v0.
inline constexpr double kFastestWind = 100.0;

// Whether a wind speed from outside keeps the rule (0 <= v0 <= kFastestWind, so finite), and the rule
// worded for an error message that names where the speed came from and ends with what it was:
// "<place>: must be from 0 to 100 m/s (the cone model ...), got 150".
bool acceptable_wind_speed(double v0);
std::string wind_speed_rule();

// The distance from a wind cone's vertex to its disc S0 unless told (m): WindSource's, a file source's
// and the command line's (--wind-l0).
inline constexpr double kDefaultL0 = 1.0;

// Density of air at 20 C, sea level (kg/m^3): a wind's default alpha is kAirDensity * l0^4 (wind.hpp).
inline constexpr double kAirDensity = 1.204;

// The densest fluid a wind's alpha may stand for (kg/m^3): water's. Eq. 4's alpha is rho * l0^4 (kg m,
// docs/wind.md) and the paper leaves it a free constant, so a file or the command line may blow harder
// than air, up to 830 times air's drag. Beyond that no wind is meant: alpha 1e20 kg m made the Steel
// Fish spin past the step-size rule in its first step, and 1e300 made that step non-finite, with
// messages that did not name alpha.
inline constexpr double kDensestWind = 1000.0;

// Whether an alpha (kg m) from outside keeps the rule for a source whose vertex is l0 (m) behind S0
// (0 < alpha <= kDensestWind * l0^4), and the rule worded for an error message that names where alpha
// came from and ends with what it was: "<place>: must be a positive number of at most ..., got 1e300".
bool acceptable_wind_alpha(double alpha, double l0);
std::string wind_alpha_rule(double l0);
// The largest alpha that rule allows at l0 (m): kDensestWind * l0^4 (kg m), water's.
double largest_wind_alpha(double l0);

// A wind source the file places in the room (a fan, an air vent): the paper's cone with its disc S0
// centred at `from`, blowing towards `to`, the vertex l0 behind S0 (WindSource::aimed(from, to, r0, l0)).
struct WindSourceSpec {
  std::string name;                         // shown in summaries and the viewer; default "source N"
  Vec3 from = Vec3::Zero();                 // centre of S0, world, m
  Vec3 to = Vec3::Zero();                   // a point on its axis that it blows towards, world, m (!= from)
  double r0 = 0.25;                         // radius of S0, m (> 0)
  double l0 = kDefaultL0;                   // vertex to S0, m (> 0)
  double speed = 0;                         // v0 at S0 at full strength, m/s (0 to kFastestWind)
  WindProfileSpec profile;
  // Per-source overrides of the wind's settings (WindSettings); empty: the run's value.
  std::optional<double> alpha;              // kg m, 0 < alpha <= kDensestWind l0^4; run default: kAirDensity l0^4
  std::optional<double> beta;               // turbulence bound, 0..10
  std::optional<std::uint64_t> seed;        // of the turbulence
  std::string path;                         // e.g. "wind_sources[0]"

  double v0(double t) const { return speed * profile.factor(t); }   // m/s at time t (s)
};

// The camera a file suggests for `aloft render` and `aloft view` (command-line flags override each key).
// Same meanings and ranges as the flags (apps/aloft/view/camera_flags.hpp); empty: the framing camera's.
struct CameraSpec {
  std::optional<double> yaw_deg;           // about +y, degrees; 0 faces the wall
  std::optional<double> pitch_deg;         // above the horizontal, degrees, -85..85
  std::optional<double> distance;          // m from the target (> 0)
  std::optional<double> fov_deg;           // vertical field of view, degrees, 5..120
  std::optional<Vec3> target;              // world point it looks at, m
};

struct MobileSpec {
  std::string file;                         // path of the mobile file as opened ("" for a string)
  std::string name;
  Vec3 gravity{0, -9.81, 0};                // m/s^2, world
  BalanceSpec balance;
  double density = 7850;                    // kg/m^3 default (steel)
  DampingSpec damping;
  ContactSpec contact;
  double timestep = 0.001;                  // s, the fixed physics step
  double joint_tolerance = 0.005;           // m: a joint must lie this close to both parts it joins
  std::vector<ComponentSpec> components;
  std::vector<WindSourceSpec> wind_sources;  // steady sources placed by the file (none by default)
  std::optional<CameraSpec> camera;         // the file's camera, if it has one
  SourceMap source;

  // An InputError at `path` in this file, with its line where known.
  InputError error_at(const std::string& path, const std::string& problem) const;
};

// Parse a mobile file. Throws InputError (file, JSON path, line, problem) for unreadable files, JSON
// syntax errors, missing or unknown keys, wrong types, non-finite or non-positive sizes, bad colours,
// bad wind sources (from == to, r0 or l0 not positive, a speed outside 0 to kFastestWind, a profile out
// of range) or camera values out of range, malformed or missing OBJ meshes (paths relative to the mobile
// file). Meaning across components (parents, cycles, the fixed component, balance) is compile()'s job.
MobileSpec parse_mobile_file(const std::string& path);

// The same for text already in memory; `file` names it in messages, `base_dir` resolves mesh paths.
MobileSpec parse_mobile_text(const std::string& text, const std::string& file = "<string>",
                             const std::string& base_dir = ".");

}  // namespace aloft
