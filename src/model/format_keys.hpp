#pragma once
// The keys the mobile-file parser accepts in each kind of object: the parser rejects every other key
// (with a "did you mean" hint from these lists), and the tests check that docs/mobile-format.schema.json
// lists exactly the same ones. Named after the schema's "$defs" entries.

#include <array>
#include <string_view>

namespace aloft::internal::format_keys {

inline constexpr std::array<std::string_view, 12> kMobile = {
    "name", "aloft", "gravity", "balance", "density", "damping", "contact", "timestep", "joint_tolerance",
    "components", "wind_sources", "camera"};
inline constexpr std::array<std::string_view, 2> kBalance = {"mode", "total_mass"};
inline constexpr std::array<std::string_view, 2> kDamping = {"linear", "angular"};
inline constexpr std::array<std::string_view, 3> kContact = {"restitution", "friction", "enabled"};
inline constexpr std::array<std::string_view, 9> kComponent = {
    "name", "parent", "fixed", "joint", "shapes", "color", "density", "restitution", "friction"};
inline constexpr std::array<std::string_view, 5> kShapeKinds = {"sphere", "wire", "box", "plate", "mesh"};
inline constexpr std::array<std::string_view, 6> kShape = {"sphere", "wire", "box", "plate", "mesh", "density"};
inline constexpr std::array<std::string_view, 2> kSphere = {"center", "radius"};
inline constexpr std::array<std::string_view, 3> kWire = {"from", "to", "radius"};
inline constexpr std::array<std::string_view, 3> kBox = {"center", "size", "rotation"};
inline constexpr std::array<std::string_view, 2> kRotation = {"axis", "degrees"};
// "x", "y" and "z" are the offsets of the named planes "yz", "xz" and "xy": only the one that matches
// the plate's "plane" is accepted.
inline constexpr std::array<std::string_view, 6> kPlate = {"points", "thickness", "plane", "x", "y", "z"};
inline constexpr std::array<std::string_view, 3> kPlaneFrame = {"origin", "u", "v"};
inline constexpr std::array<std::string_view, 3> kMesh = {"obj", "scale", "translate"};
// A steady wind source (a fan, an air vent) and its time profile. Of the profile's keys, only those of
// its "type" are accepted: "steady" none, "on_off" period, on, ramp, phase; "swell" period, depth, phase.
inline constexpr std::array<std::string_view, 10> kWindSource = {
    "name", "from", "to", "r0", "l0", "speed", "profile", "alpha", "beta", "seed"};
inline constexpr std::array<std::string_view, 6> kWindProfile = {"type", "period", "on", "ramp", "depth", "phase"};
// The file's camera (degrees and metres, as the --yaw, --pitch, --distance, --fov, --target flags).
inline constexpr std::array<std::string_view, 5> kCamera = {"yaw", "pitch", "distance", "fov", "target"};

}  // namespace aloft::internal::format_keys
