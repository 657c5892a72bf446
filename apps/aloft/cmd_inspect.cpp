// aloft inspect: what compile() made of a mobile file: per component its mass, centre of mass, principal
// moments, rest orientation, parent and joint, and the balance result; as a text table or as JSON.

#include <cstdio>
#include <memory>

#include <nlohmann/json.hpp>

#include "aloft/collision.hpp"
#include "aloft/model.hpp"
#include "common.hpp"

namespace aloft::cli {

namespace {

const char* mode_name(BalanceMode mode) {
  switch (mode) {
    case BalanceMode::Mass: return "mass";
    case BalanceMode::Joints: return "joints";
    case BalanceMode::None: return "none";
  }
  return "?";
}

// Model indices in the order of the file's "components" array.
std::vector<int> file_order(const Model& m) {
  std::vector<int> order(m.count);
  for (int i = 0; i < m.count; ++i) order[m.file_index[i]] = i;
  return order;
}

// Pairs of components as pairs of names.
nlohmann::ordered_json pair_names(const Model& m, const std::vector<std::pair<int, int>>& pairs) {
  nlohmann::ordered_json list = nlohmann::ordered_json::array();
  for (const auto& [a, b] : pairs) list.push_back({m.names[a], m.names[b]});
  return list;
}

std::string inspect_json(const Model& m, const CollisionPairs& pairs) {
  using json = nlohmann::ordered_json;
  auto vec = [](const Vec3& v) { return json::array({v.x(), v.y(), v.z()}); };
  json root;
  root["name"] = m.name;
  root["file"] = m.file;
  root["count"] = m.count;
  json notes = json::array();
  for (const std::string& n : m.balance.notes) notes.push_back(n);
  root["balance"] = {{"mode", mode_name(m.balance.mode)},
                     {"total_mass", m.balance.total_mass},
                     {"max_imbalance", m.balance.max_imbalance},
                     {"notes", notes}};
  root["gravity"] = vec(m.gravity);
  root["timestep"] = m.timestep;
  json components = json::array();
  for (int i : file_order(m)) {
    const bool fixed = i == 0;
    const Quat& q = m.rest_orientation[i];
    json c;
    c["name"] = m.names[i];
    c["parent"] = fixed ? json(nullptr) : json(m.names[m.parent[i]]);
    c["fixed"] = fixed;
    c["mass"] = m.mass[i];
    c["com"] = vec(m.rest_position[i]);
    c["principal_moments"] = vec(m.principal_moments[i]);
    c["rest_orientation"] = json::array({q.w(), q.x(), q.y(), q.z()});
    c["joint"] = fixed ? json(nullptr) : vec(m.joint_world[i]);
    c["volume"] = m.volume[i];
    c["mass_scale"] = m.balance.mass_scale[i];
    components.push_back(std::move(c));
  }
  root["components"] = std::move(components);
  root["collision_pairs"] = {{"total", pairs.total},
                             {"pruned", pairs.total - pairs.candidate_count},
                             {"remaining", pairs.candidate_count},
                             {"joined", pairs.joined},
                             {"never_touch", pairs.never_touch},
                             {"touching_at_rest", pair_names(m, pairs.touching_at_rest)},
                             {"candidates", pairs.listed ? pair_names(m, pairs.candidates)
                                                         : nlohmann::ordered_json(nullptr)}};
  return root.dump(2) + "\n";
}

// The pruning result: counts, the pairs touching at rest and the pairs collision detection tests.
std::string collision_text(const Model& m, const CollisionPairs& pairs) {
  constexpr std::size_t kMaxListed = 100;  // a large mobile has thousands: --json lists them all
  std::string out;
  const long long kept = pairs.candidate_count;
  out += format("\nCollision pairs: %lld of %lld pruned (%lld joined by a joint, %lld can never touch, %zu "
                "touching at rest); %lld remain%s\n",
                pairs.total - kept, pairs.total, pairs.joined, pairs.never_touch, pairs.touching_at_rest.size(),
                kept, kept > 0 ? ":" : ".");
  auto list = [&](const std::vector<std::pair<int, int>>& ps) {
    for (std::size_t k = 0; k < ps.size() && k < kMaxListed; ++k)
      out += "  " + m.names[ps[k].first] + "  --  " + m.names[ps[k].second] + "\n";
    if (ps.size() > kMaxListed) out += format("  ... and %zu more (--json lists all)\n", ps.size() - kMaxListed);
  };
  if (pairs.listed) {
    list(pairs.candidates);
  } else {
    out += format("  (not listed: more than %d components)\n", CollisionPairs::kListedComponents);
  }
  if (!pairs.touching_at_rest.empty()) {
    out += "Touching in the designed pose (left out of collision detection):\n";
    list(pairs.touching_at_rest);
  }
  return out;
}

std::string inspect_text(const Model& m, const CollisionPairs& pairs) {
  std::string out;
  out += "mobile      " + m.name + "\n";
  out += "file        " + m.file + "\n";
  out += format("components  %d (1 fixed, %d moving)\n", m.count, m.count - 1);
  out += format("balance     mode %s, total mass %.6g kg, max imbalance %.3g m\n", mode_name(m.balance.mode),
                m.balance.total_mass, m.balance.max_imbalance);
  for (const std::string& note : m.balance.notes) out += "            " + note + "\n";
  out += format("gravity     [%g, %g, %g] m/s^2, timestep %g s\n", m.gravity.x(), m.gravity.y(), m.gravity.z(),
                m.timestep);

  const std::vector<int> order = file_order(m);
  out += "\nComponents (file order), positions in metres, world frame at the designed rest pose:\n\n";
  Table where({"name", "parent", "mass (kg)", "com x", "com y", "com z", "joint x", "joint y", "joint z"},
              {false, false, true, true, true, true, true, true, true});
  for (int i : order) {
    const Vec3& c = m.rest_position[i];
    if (i == 0) {
      where.add({m.names[i], "(fixed)", format("%.6g", m.mass[i]), fixed(c.x(), 5), fixed(c.y(), 5),
                 fixed(c.z(), 5), "-", "-", "-"});
    } else {
      const Vec3& j = m.joint_world[i];
      where.add({m.names[i], m.names[m.parent[i]], format("%.6g", m.mass[i]), fixed(c.x(), 5),
                 fixed(c.y(), 5), fixed(c.z(), 5), fixed(j.x(), 5), fixed(j.y(), 5),
                 fixed(j.z(), 5)});
    }
  }
  out += where.str("  ");

  out += "\nPrincipal moments of inertia (kg m^2, about the centre of mass) and rest orientation (unit\n"
         "quaternion w x y z turning the principal frame into the world frame):\n\n";
  Table inertia({"name", "I1", "I2", "I3", "qw", "qx", "qy", "qz"},
                {false, true, true, true, true, true, true, true});
  for (int i : order) {
    const Vec3& p = m.principal_moments[i];
    const Quat& q = m.rest_orientation[i];
    inertia.add({m.names[i], format("%.6g", p.x()), format("%.6g", p.y()), format("%.6g", p.z()),
                 fixed(q.w(), 6), fixed(q.x(), 6), fixed(q.y(), 6), fixed(q.z(), 6)});
  }
  out += inertia.str("  ");
  out += collision_text(m, pairs);
  return out;
}

}  // namespace

Runner add_inspect(CLI::App& app) {
  struct Options {
    std::string file;
    std::string balance = "file";
    bool json = false;
  };
  auto o = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand(
      "inspect",
      "Show the masses, inertias, rest pose, joints and balance Aloft derives from a mobile file");
  sub->add_option("file", o->file, "The mobile file (JSON)")->type_name("FILE")->required();
  add_balance_option(sub, o->balance);
  sub->add_flag("--json", o->json,
                "Print JSON instead of a table: {name, file, balance {mode, total_mass, max_imbalance, notes}, "
                "components [{name, parent, fixed, mass, com, principal_moments, rest_orientation [w,x,y,z], "
                "joint, ...}], collision_pairs {total, pruned, remaining, joined, never_touch, touching_at_rest "
                "[[a, b]...], candidates [[a, b]...] (null above 2048 components)}} in SI units, full precision; parent and joint are null for the fixed component");
  sub->footer(
      "Per component: mass, centre of mass, principal moments of inertia, rest orientation (the rotation\n"
      "from the principal frame to the world), parent and joint point; then the balance result (mode,\n"
      "total mass, largest imbalance, notes); then the collision pairs: how many pairs of components\n"
      "are pruned (joined by a joint, too far apart to ever touch, touching in the designed pose) and\n"
      "which remain for collision detection. Components are listed in FILE order (the order of the\n"
      "file's \"components\" array). SI units, world frame, y up.\n"
      "\n"
      "Examples:\n"
      "  aloft inspect mobiles/steel-fish.json\n"
      "  aloft inspect random.json --json > random-inspect.json\n");
  return [o] {
    const Model model = load_mobile_as(o->file, o->balance);
    const CollisionPairs pairs = prune_pairs(model);
    const std::string text = o->json ? inspect_json(model, pairs) : inspect_text(model, pairs);
    std::fwrite(text.data(), 1, text.size(), stdout);
    if (std::fflush(stdout) != 0) throw Failure("cannot write to standard output");
    return kExitOk;
  };
}

static const CommandRegistration registration{"inspect", 20, add_inspect};

}  // namespace aloft::cli
