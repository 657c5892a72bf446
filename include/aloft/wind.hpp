#pragma once
// The paper's virtual wind (Lee, Bae, Kim et al. 2001, eqs. 1-5; method-notes section 6): a cone of air
// from a disc S0, drag on every surface element seen from the cone's vertex, and correlated turbulence.
//
//   vertex ----- l0 ----- S0 (disc, radius r0, centre = vertex + l0 * direction) ----> the cone goes on
//
// - Continuity (eq. 2): the speed at distance l1 >= l0 from the vertex is v1 = v0 (l0 / l1)^2.
// - Drag (eqs. 3-4) on an element of area A, unit normal n_a, wind direction n_v (the ray from the vertex):
//     F = rho A v1^2 (n_v . n_a) n_a = alpha A v0^2 / l1^4 (n_v . n_a) n_a,   alpha = rho * l0^4 (kg m)
//   (docs/wind.md: rho v1^2 times the projected area A cos, pushed along the normal, so the part along the
//   wind goes as cos^2; a normal-force coefficient of 2 against rho v^2 / 2). The sign of n_a does not
//   matter; F pushes along the wind.
// - Turbulence (eq. 5): per component, F_random = beta |F_stoke| r(t), r(t) a random vector with |r| < 1
//   that wanders with a correlation time (Ornstein-Uhlenbeck), so it reads as gusts, not hiss.
// - Occlusion: only surface seen from the vertex, inside the cone and beyond S0 feels the wind. An item
//   buffer (32-bit ids, one per triangle) is rasterized on the CPU from the vertex onto the S0 plane
//   (the square circumscribing the S0 disc, resolution x resolution pixels); every covered pixel inside
//   the S0 circle is a sample of known solid angle, so the visible area of a face is the sum of its pixels'
//   solid angle * l1^2 / |cos|. Pixels are then merged per (tile of tile_pixels^2 pixels, component,
//   plane) into area elements: exact summed area, acting at the area-weighted centroid (docs/wind.md).
//
// Usage (a simulation at 1 ms steps, occlusion refreshed at 60 Hz):
//     Wind wind(model, WindSource::aimed(from, to, r0, l0), WindSettings{});
//     for each step: if (time to refresh) wind.refresh_occlusion(sim.state());
//                    sim.loads().clear();                            // apply() adds to the loads
//                    wind.apply(sim.state(), v0, dt, sim.loads());   // then sim.step()
// Elements are kept in body frames, so between refreshes they follow their components; apply() re-checks
// each element against the cone with the current pose. No allocation in apply().

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "aloft/model.hpp"
#include "aloft/simulation.hpp"
#include "aloft/state.hpp"

namespace aloft {

namespace internal {
class ItemRasterizer;
}

// The cone of wind. S0 is the disc of radius r0, centred at vertex + l0 * direction, facing `direction`.
struct WindSource {
  Vec3 vertex = Vec3(0, 1.8, 3.0);     // cone vertex, world, m
  Vec3 direction = Vec3(0, 0, -1);     // unit, world: where the wind blows
  double r0 = 0.25;                    // radius of S0, m (> 0)
  double l0 = kDefaultL0;              // distance from the vertex to S0, m (> 0)

  // A source whose disc S0 is centred at `from` and blows towards `to` (vertex l0 behind `from`).
  static WindSource aimed(const Vec3& from, const Vec3& to, double r0, double l0);
  Vec3 disc_center() const { return vertex + l0 * direction; }
  double half_angle() const;           // atan(r0 / l0), rad
  // Throws std::invalid_argument when r0 or l0 is not a positive finite number or direction is zero.
  void validate() const;
};

// How often the occlusion is refreshed unless asked otherwise (Hz of simulated time): the command
// line's --wind-refresh, the viewer and the benchmarks' blown steps. The mobile moves little in 1/60 s.
inline constexpr double kOcclusionRefreshRate = 60;

// Steps between occlusion refreshes at `rate` (Hz) with steps of h (s): 1 / (rate h) rounded, at least 1
// and at most INT_MAX (a rate so low that the occlusion is looked at only once, at the first step).
int occlusion_refresh_steps(double rate, double h);

// A sphere around the whole mobile at `state`: centred on the world box of every shape's corners, its
// radius the box's half diagonal (m). What the sources below are sized to cover.
struct MobileSphere {
  Vec3 center;    // world, m
  double radius;  // m
};
MobileSphere mobile_sphere(const Model& model, const State& state);

// A source whose disc S0 is centred at `from` and blows towards `to` (as WindSource::aimed), its r0
// wide enough that the cone covers `cover` as seen `|cover.center - from| + l0` from the vertex (the
// half angle capped at 72 degrees). Throws std::invalid_argument as aimed does.
WindSource source_covering(const Vec3& from, const Vec3& to, double l0, const MobileSphere& cover);

// A source placed in front of the whole mobile at rest: S0 centred `distance` (m) from the mobile's
// bounding-box centre along -along (the wind blows along `along`), radius chosen so that the cone covers
// the whole mobile at the box centre's distance, l0 = `l0`. The viewer's default is along the camera's
// view direction; the command line's default is along -z (from the front).
WindSource source_facing_mobile(const Model& model, const State& state, const Vec3& along, double distance,
                                double l0);

// The command line's wind unless told otherwise, and the one the benchmarks and tests blow: S0
// kFrontSourceDistance in front (+z) of the mobile's centre, blowing along -z
// (source_facing_mobile(model, state, -z, kFrontSourceDistance, l0)).
inline constexpr double kFrontSourceDistance = 1.5;  // m
WindSource source_in_front(const Model& model, const State& state, double l0 = kDefaultL0);

struct WindSettings {
  double alpha = -1;          // drag constant of eq. 4, kg m; < 0: kAirDensity * l0^4 (physical, docs/wind.md)
  double beta = 0.3;          // turbulence bound of eq. 5, |F_random| < beta |F_stoke|; 0: deterministic
  double correlation_time = 0.4;  // s, of the turbulence process (gusts)
  std::uint64_t seed = 1;     // of the turbulence process
  int resolution = 256;       // item buffer width = height, pixels (>= 8)
  int tile_pixels = 8;        // pixels merged into one area element per side (>= 1); 1: per-pixel elements
  int round_segments = 12;    // sides of the polygons approximating spheres and wires in the item buffer
  void validate() const;      // throws std::invalid_argument naming the bad setting
};

// A wind source of the mobile file (spec.hpp) as the command line, the viewer and fuzz_mobile_simulate
// blow it: its cone, WindSource::aimed(from, to, r0, l0) (which throws as aimed does), and its settings:
// `run`'s, with the file's alpha, beta and seed where it gives them. A source without a seed takes
// run.seed + 1 + index (its place in the file), so that two sources do not gust in step.
WindSource file_source_cone(const WindSourceSpec& source);
WindSettings file_source_settings(const WindSourceSpec& source, std::size_t index, WindSettings run);

// One area element that sees the wind: a part of one plane of one component.
struct WindElement {
  int component = 0;
  Vec3 point_body = Vec3::Zero();    // where the force acts: area-weighted centroid, body frame, m
  Vec3 normal_body = Vec3::Zero();   // unit face normal, body frame (sign irrelevant)
  double area = 0;                   // visible area, m^2 (at the refresh's pose)
  Vec3 point_world = Vec3::Zero();   // the same at the refresh's pose, world (for display)
  Vec3 normal_world = Vec3::Zero();
};

// The item buffer of the last refresh: ids[y * width + x] is 0 (no surface, or outside the S0 circle)
// or 1 + a triangle index; component_of_id[id] gives its component (component_of_id[0] == -1).
// Pixel (x, y) covers S0-plane coordinates u in [-r0 + x s, -r0 + (x+1) s], v likewise with y, s = 2 r0 / width,
// along the source's `right` and `up` axes (right = direction x up_hint, see Wind::frame()).
struct ItemBuffer {
  int width = 0;
  std::vector<std::uint32_t> ids;
  std::vector<int> component_of_id;
  int component_at(int x, int y) const { return component_of_id[ids[static_cast<std::size_t>(y) * width + x]]; }
};

// What the wind did in the last apply(), per component (world frame, N and N m about the centre of mass).
struct WindLoads {
  std::vector<Vec3> stoke_force;     // eq. 4 summed over the component's elements
  std::vector<Vec3> random_force;    // eq. 5's random term (|random| < beta |stoke|)
  std::vector<Vec3> torque;          // of both, about the centre of mass
};

class Wind {
 public:
  // Builds the body-frame triangle meshes of every component once. Throws std::invalid_argument on bad
  // source or settings.
  // The Wind keeps a reference to `model`, which must outlive it.
  Wind(const Model& model, const WindSource& source, const WindSettings& settings = {});
  ~Wind();
  Wind(const Wind&) = delete;
  Wind& operator=(const Wind&) = delete;

  // Move or re-aim the source, change the settings (resolution, alpha...). Elements stay until the next
  // refresh; the turbulence process keeps its state (a new seed restarts it).
  void set_source(const WindSource& source);
  void set_settings(const WindSettings& settings);   // round_segments cannot change
  const WindSource& source() const { return source_; }
  const WindSettings& settings() const { return settings_; }
  double alpha() const;  // the effective alpha (settings.alpha, or kAirDensity * l0^4)

  // Render the item buffer from the vertex for `state` and derive the visible elements. Deterministic.
  void refresh_occlusion(const State& state);

  // Add the wind's force and torque for speed v0 (m/s, at S0) to `loads` (which must be sized to the
  // model), advancing the turbulence process by dt (s). The fixed component 0 gets nothing.
  void apply(const State& state, double v0, double dt, ExternalLoads& loads);

  // Results of the last refresh and apply.
  const std::vector<WindElement>& elements() const { return elements_; }
  const ItemBuffer& item_buffer() const { return buffer_; }
  std::vector<double> visible_area() const;   // m^2 per component, at the last refresh
  const WindLoads& last_loads() const { return last_; }
  // The source's orthonormal frame: right, up, direction (columns), world.
  Mat3 frame() const { return frame_; }

 private:
  struct ComponentMesh {
    std::vector<Vec3> vertices;                 // body frame
    std::vector<std::array<int, 3>> triangles;
    std::vector<int> plane_of_triangle;         // coplanar triangles share a plane id (within the component)
  };
  void reset_turbulence();
  void step_turbulence(double dt);

  struct TileAccumulator {
    int plane;              // global plane id
    int component;
    std::uint32_t id;       // one triangle id of the plane
    double area;            // m^2
    Vec3 moment;            // sum of area * point, camera frame, m^3
  };
  const Vec3& triangle_point_body(std::size_t t) const { return triangle_point_body_[t]; }
  // What a triangle's facet stands for. The mesh of a round surface (a wire's side, a sphere) is faceted,
  // and a pixel's force, along its facet's normal at the pixel's point, misses the axis (centre) by up
  // to half a facet's width; the true surface's pressure, along its own normals, meets it. So the points
  // of a round facet's elements are moved along the facet, to where its normal meets the axis (centre):
  // the surface pushes and turns its component as before, but not about its own axis.
  struct RoundSurface {
    enum class Kind : unsigned char { kFlat, kAxis, kCentre };
    Kind kind = Kind::kFlat;
    Vec3 point = Vec3::Zero();      // a point of the axis, or the centre; body frame, m
    Vec3 direction = Vec3::Zero();  // kAxis: the axis, unit, body frame
    // The surface a shape's facets stand for: a wire's side (its flat ends are flat: see
    // through_axis), a sphere; plates, boxes and meshes are flat.
    static RoundSurface of(const Shape& shape);
    // `point_body` moved along a facet of normal `normal` (unit, body frame) to where the normal through
    // it meets the axis or the centre; unchanged for a flat facet and a wire's end.
    Vec3 through_axis(const Vec3& point_body, const Vec3& normal) const;
  };

  const Model& model_;
  WindSource source_;
  WindSettings settings_;
  Mat3 frame_;
  std::vector<ComponentMesh> meshes_;
  // Per global triangle (id - 1): body-frame unit normal and one vertex, component, global plane id.
  std::vector<Vec3> triangle_normal_body_;
  std::vector<Vec3> triangle_point_body_;
  std::vector<int> triangle_component_;
  std::vector<int> triangle_plane_;
  std::vector<RoundSurface> triangle_round_;
  int plane_count_ = 0;
  std::unique_ptr<internal::ItemRasterizer> rasterizer_;
  ItemBuffer buffer_;
  std::vector<WindElement> elements_;
  WindLoads last_;
  // Turbulence: one Ornstein-Uhlenbeck vector per component, unit variance per axis.
  std::vector<Vec3> gust_;
  std::uint64_t rng_state_ = 0;
  // Scratch reused between calls (no allocation in apply()).
  std::vector<Vec3> camera_vertices_;
  std::vector<TileAccumulator> tile_scratch_;
  std::vector<char> plane_seen_;         // per id: camera-frame plane computed this refresh
  std::vector<Vec3> plane_n_;            // per id: unit normal, camera frame
  std::vector<double> plane_d_;          // per id: plane offset n . p, camera frame, m
  std::vector<Mat3> rotation_;           // per component, body -> world, this apply()
  std::vector<Vec3> pressure_center_;    // per component: sum |F| * arm
  std::vector<double> pressure_weight_;  // per component: sum |F|
};

}  // namespace aloft
