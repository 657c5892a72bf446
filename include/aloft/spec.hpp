#pragma once
// The mobile as a person wrote it (the "spec"): what the JSON file says, checked for form and types but
// not yet for meaning. compile() (model.hpp) turns it into the immutable Model. Everything is in world
// coordinates at the designed rest pose (metres, y up).

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
  SourceMap source;

  // An InputError at `path` in this file, with its line where known.
  InputError error_at(const std::string& path, const std::string& problem) const;
};

// Parse a mobile file. Throws InputError (file, JSON path, line, problem) for unreadable files, JSON
// syntax errors, missing or unknown keys, wrong types, non-finite or non-positive sizes, bad colours,
// malformed or missing OBJ meshes (paths relative to the mobile file). Meaning across components
// (parents, cycles, the fixed component, balance) is compile()'s job.
MobileSpec parse_mobile_file(const std::string& path);

// The same for text already in memory; `file` names it in messages, `base_dir` resolves mesh paths.
MobileSpec parse_mobile_text(const std::string& text, const std::string& file = "<string>",
                             const std::string& base_dir = ".");

}  // namespace aloft
