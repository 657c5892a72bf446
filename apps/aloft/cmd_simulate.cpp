// aloft simulate: a headless run from the designed pose at rest, with an optional trajectory CSV, an
// optional CSV of the pairs of components that touched, and a summary (speed, energy drift, joint
// separation, collisions).

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <optional>
#include <variant>
#include <vector>

#include "aloft/contact_tally.hpp"
#include "aloft/model.hpp"
#include "aloft/simulation.hpp"
#include "aloft/spec.hpp"
#include "common.hpp"
#include "contact_report.hpp"
#include "progress.hpp"
#include "wind_options.hpp"

namespace aloft::cli {

namespace {

using Clock = WallClock;

// The trajectory CSV, written frame by frame through a large buffer.
class Trajectory {
 public:
  Trajectory(const std::string& path, const Model& model) : path_(path) {
    file_ = std::fopen(path.c_str(), "wb");
    if (!file_) throw Failure("cannot write " + path + ": " + std::strerror(errno));
    names_.reserve(model.names.size());
    for (const std::string& n : model.names) names_.push_back(csv_field(n));
    buffer_ = "t,component,x,y,z,qw,qx,qy,qz\n";
  }
  ~Trajectory() {
    if (file_) std::fclose(file_);
  }
  Trajectory(const Trajectory&) = delete;
  Trajectory& operator=(const Trajectory&) = delete;

  void frame(const State& s) {
    std::string t;
    append_double(t, s.time);
    for (std::size_t i = 0; i < names_.size(); ++i) {
      buffer_ += t;
      buffer_ += ',';
      buffer_ += names_[i];
      const Vec3& p = s.position[i];
      const Quat& q = s.orientation[i];
      for (double v : {p.x(), p.y(), p.z(), q.w(), q.x(), q.y(), q.z()}) {
        buffer_ += ',';
        append_double(buffer_, v);
      }
      buffer_ += '\n';
    }
    if (buffer_.size() > (1u << 22)) flush();
  }

  void close() {
    flush();
    const int failed = std::fclose(file_);
    file_ = nullptr;
    if (failed != 0) throw Failure("cannot write " + path_ + ": " + std::strerror(errno));
  }

 private:
  void flush() {
    if (!buffer_.empty() && std::fwrite(buffer_.data(), 1, buffer_.size(), file_) != buffer_.size())
      throw Failure("cannot write " + path_ + ": " + std::strerror(errno));
    buffer_.clear();
  }

  std::string path_;
  std::FILE* file_ = nullptr;
  std::vector<std::string> names_;
  std::string buffer_;
};

}  // namespace

Runner add_simulate(CLI::App& app) {
  struct Options {
    std::string file;
    std::string balance = "file";
    double duration = 0;
    double dt = 0;  // 0: the mobile's timestep
    int every = 10;
    std::string out;
    std::string contacts_out;
    bool damping_off = false;
    bool no_collisions = false;
    bool quiet = false;
    WindOptions wind;
  };
  auto o = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand(
      "simulate",
      "Simulate a mobile without a window and write its trajectory");
  sub->add_option("file", o->file, "The mobile file (JSON)")->type_name("FILE")->required();
  add_balance_option(sub, o->balance);
  sub->add_option("-t,--duration", o->duration, format("Simulated time (s, > 0, up to %g)", kLongestDuration))
      ->type_name("T")
      ->required()
      ->check(duration_in_seconds());
  sub->add_option("--dt", o->dt,
                  format("Time step (s, %g to %g); default: the mobile's \"timestep\" (0.001 unless set)",
                         kShortestTimestep, kLongestTimestep))
      ->type_name("H")
      ->check(timestep_range());
  sub->add_option("-k,--every", o->every, "Write a trajectory frame every K steps (>= 1)")
      ->type_name("K")
      ->capture_default_str()
      ->check(integer_in(1, 1000000000));
  sub->add_option("-o,--out", o->out, "Trajectory CSV file (default: none)")->type_name("FILE");
  sub->add_option("--contacts-out", o->contacts_out,
                  "CSV of every pair of components that touched: how many steps, from when to when, how deep")
      ->type_name("FILE");
  sub->add_flag("--damping-off", o->damping_off, "Switch off the mobile's air damping");
  sub->add_flag("--no-collisions", o->no_collisions, "Let components pass through each other (no contact handling)");
  sub->add_flag("-q,--quiet", o->quiet, "Print neither progress nor the summary");
  add_wind_options(sub, o->wind);
  sub->footer(
      "Starts from the designed pose at rest and prints a summary: steps, simulated and wall time, speed,\n"
      "energy drift (energy change, with wind or damping), the largest joint separation seen, and the\n"
      "collisions: their impulses, the deepest overlap, the energy they took out, and the pairs of\n"
      "components that touched (were pushed apart by a contact impulse, or came within 0.1 mm), the most\n"
      "often first. With --contacts-out, also writes every such pair as CSV: header\n"
      "component_a,component_b,steps,first_t,last_t,deepest_overlap_m (the steps in which they touched,\n"
      "the end times of the first and last of them in s, the largest overlap in m). With --out, also\n"
      "writes the trajectory as CSV: header t,component,x,y,z,qw,qx,qy,qz, one row per component (by\n"
      "name) per output frame, a frame every --every steps with t = 0 included; x,y,z is the centre of mass\n"
      "and qw,qx,qy,qz the orientation of the component's principal frame (as 'aloft inspect'\n"
      "rest_orientation), world frame, SI units.\n"
      "\n"
      "Examples:\n"
      "  aloft simulate mobiles/steel-fish.json --duration 10\n"
      "  aloft simulate random.json --duration 2 --dt 0.0005 --every 20 --out trajectory.csv\n"
      "  aloft simulate random.json -t 60 --damping-off        # check energy conservation\n"
      "  aloft simulate mobiles/steel-fish.json -t 30 --balance none   # as built: it swings\n"
      "  aloft simulate mobiles/steel-fish.json -t 10 --wind 2.5        # a steady breath from the front\n"
      "  aloft simulate mobiles/steel-fish.json -t 20 --wind 4 --contacts-out touching.csv   # what knocks?\n"
      "  aloft simulate mobiles/steel-fish.json -t 10 --wind-audio blow.wav --wind-from 0.5,1.8,1.5\n"
      "\n"
      "Wind: the mobile file's \"wind_sources\" (fans, vents) always blow, unless --no-file-wind.\n"
      "One of --wind, --wind-speed or --wind-audio adds a wind from the flags. The source disc S0 sits at\n"
      "--wind-from (default 1.5 m in front, +z, of the mobile's centre) and blows towards --wind-to (default\n"
      "the mobile's centre); the cone's vertex is l0 behind S0. Occlusion is recomputed --wind-refresh times\n"
      "per simulated second; the wind's force and torque are applied at every step. See docs/wind.md.\n"
      "\n"
      "Exit code 3 if the simulation fails (its state stops being finite); the CSVs then hold the\n"
      "frames and contacts computed until then.\n");
  return [o] {
    LoadedMobile loaded = load_mobile_with_spec(o->file, o->balance);
    std::vector<NamedFile> inputs = {{"the mobile file", o->file},
                                     {"--wind-audio's recording", o->wind.audio},
                                     {"--wind-speed's table", o->wind.speed_csv}};
    for (const ComponentSpec& component : loaded.spec.components)
      for (const ShapeSpec& shape : component.shapes)
        if (const Mesh* mesh = std::get_if<Mesh>(&shape.shape))
          inputs.push_back({"the mesh of " + shape.path, mesh->opened});
    check_outputs_apart(inputs, {{"--out", o->out}, {"--contacts-out", o->contacts_out}});
    Model& model = loaded.model;
    if (o->no_collisions) model.contact.enabled = false;
    Simulation sim(model);
    if (o->dt > 0) sim.set_timestep(o->dt);
    if (o->damping_off) sim.set_damping(DampingSpec{});
    const double h = sim.timestep();
    WindSet wind(model, loaded.spec, sim.state(), o->wind, h);
    double largest_move = 0, largest_turn = 0;
    const long long steps = std::max(1LL, static_cast<long long>(std::ceil(o->duration / h - 1e-9)));

    std::unique_ptr<Trajectory> csv;
    if (!o->out.empty()) csv = std::make_unique<Trajectory>(o->out, model);
    if (!o->contacts_out.empty()) write_file(o->contacts_out, "");  // a CSV that cannot be written fails here
    ContactTally tally;

    const State rest = rest_state(model);
    const double e_rest = potential_energy(model, rest);
    const double e0 = kinetic_energy(model, sim.state()) + potential_energy(model, sim.state());
    double worst_separation = max_joint_separation(model, sim.state());
    double peak_kinetic = 0;
    if (csv) csv->frame(sim.state());

    // Shown for runs longer than about 2 s.
    ProgressReport progress(!o->quiet, steps, "simulating", 2.0);
    const auto start = Clock::now();
    bool ok = true;
    long long done = 0;
    while (done < steps) {
      wind.apply(done, sim.state(), h, sim.loads());
      if (!sim.step()) {
        ok = false;
        break;
      }
      ++done;
      if (sim.collisions()) tally.add_step(sim.contacts(), sim.pushed_pairs(), sim.state().time);
      if (done % o->every == 0) {
        const State& s = sim.state();
        if (csv) csv->frame(s);
        worst_separation = std::max(worst_separation, max_joint_separation(model, s));
        peak_kinetic = std::max(peak_kinetic, kinetic_energy(model, s));
        for (int c = 1; c < model.count; ++c) {
          largest_move = std::max(largest_move, (s.position[c] - rest.position[c]).norm());
          largest_turn = std::max(largest_turn, s.orientation[c].angularDistance(rest.orientation[c]));
        }
      }
      if ((done & 63) == 0 && progress.due(done))
        progress.show(done, format("t = %.3f s, %.0f steps/s", sim.state().time, done / progress.elapsed()));
    }
    const double wall = seconds_since(start);
    progress.finish();
    if (csv) csv->close();
    if (!o->contacts_out.empty()) write_contact_pairs_csv(o->contacts_out, model, tally);
    if (!ok) {
      print_error(sim.failure() ? sim.failure()->message : "the simulation failed");
      return kExitSimulation;
    }

    // The energy the run gained (J), against its scale: the swing it started with or, from rest (a swing
    // within round-off of the potential), the largest kinetic energy seen; 0 when that too is round-off.
    const double drift = kinetic_energy(model, sim.state()) + potential_energy(model, sim.state()) - e0;
    const double swing = std::abs(e0 - e_rest);
    const bool from_swing = swing > 1e-12 * std::max(1.0, std::abs(e_rest));
    const double energy_scale = from_swing ? swing : peak_kinetic > 1e-12 ? peak_kinetic : 0.0;

    if (!o->quiet) {
      const State& s = sim.state();
      worst_separation = std::max(worst_separation, max_joint_separation(model, s));
      std::string energy = format("%.3e J", drift);
      if (energy_scale > 0)
        energy += format(from_swing ? " (%.3g %% of the initial swing energy %.3e J)"
                                    : " (%.3g %% of the largest kinetic energy seen, %.3e J)",
                         100 * drift / energy_scale, energy_scale);
      // A drift only when nothing else changes the energy: the wind does work and damping takes energy
      // out, so with either the line says what it is and how to check conservation instead.
      const bool damping_on = !o->damping_off && (model.damping.linear > 0 || model.damping.angular > 0);
      const bool wind_blows = !wind.empty();
      if (wind_blows && damping_on)
        energy += "; the wind does work and damping is on (no wind and --damping-off to check conservation)";
      else if (wind_blows)
        energy += "; the wind does work (no wind to check conservation)";
      else if (damping_on)
        energy += "; damping is on (--damping-off to check conservation)";
      if (sim.collisions() && sim.collision_statistics().energy_removed > 0)
        energy += format("; the contacts took out %.4g J", sim.collision_statistics().energy_removed);
      const char* energy_label = wind_blows || damping_on ? "energy change" : "energy drift ";
      std::printf("mobile            %s\n", model.name.c_str());
      std::printf("components        %d\n", model.count);
      std::printf("steps             %lld (dt = %g s)\n", done, h);
      std::printf("simulated time    %.6g s\n", s.time);
      std::printf("wall time         %.3f s\n", wall);
      std::printf("speed             %.0f steps/s (%.3g x real time)\n", wall > 0 ? done / wall : 0.0,
                  wall > 0 ? s.time / wall : 0.0);
      std::printf("%s     %s\n", energy_label, energy.c_str());
      std::printf("joint separation  %.3e m (largest seen)\n", worst_separation);
      std::printf("motion            %.3g m largest displacement, %.3g deg largest turn (from rest, every %d steps)\n",
                  largest_move, largest_turn * 180 / 3.141592653589793, o->every);
      print_collision_summary(model, sim, tally,
                              o->no_collisions          ? CollisionsOff::kByFlag
                              : !model.contact.enabled  ? CollisionsOff::kByFile
                                                        : CollisionsOff::kNo,
                              o->contacts_out);
      for (const WindDriver& d : wind.drivers()) std::printf("wind              %s\n", d.description.c_str());
      if (!wind.empty()) {
        const long long refreshes = wind.refreshes();
        const double occlusion = wind.occlusion_seconds();
        std::printf("occlusion         %lld refreshes, %.3f ms each (mean), %.0f elements each (mean), %.1f %% of the wall time\n",
                    refreshes, refreshes ? 1e3 * occlusion / refreshes : 0.0,
                    refreshes ? static_cast<double>(wind.elements()) / refreshes : 0.0,
                    wall > 0 ? 100 * occlusion / wall : 0.0);
      }
      if (o->wind.no_file_wind && !loaded.spec.wind_sources.empty())
        std::printf("file wind         %zu source(s) in the file ignored (--no-file-wind)\n",
                    loaded.spec.wind_sources.size());
      if (csv)
        std::printf("trajectory        %s (%lld frames x %d components)\n", o->out.c_str(), done / o->every + 1,
                    model.count);
      std::fflush(stdout);
    }
    // Without wind nothing gives the mobile energy (damping and contacts only take it out): a gain of more
    // than 1 % of its energy scale, a thousand times the integrator's error on the presets and generated
    // mobiles (1e-5), means the motion is wrong. docs/architecture.md, "Known limits".
    if (wind.empty() && energy_scale > 0 && drift > 0.01 * energy_scale)
      print_warning(format("the mobile gained %.3g J, %.3g %% of its energy scale (%.3g J), with no wind to give "
                           "it: the simulation is inaccurate here and its motion not to be trusted (see "
                           "docs/architecture.md, \"Known limits\")",
                           drift, 100 * drift / energy_scale, energy_scale));
    return kExitOk;
  };
}

static const CommandRegistration registration{"simulate", 30, add_simulate};

}  // namespace aloft::cli
