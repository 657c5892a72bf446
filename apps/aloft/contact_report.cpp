// aloft simulate's collision summary and --contacts-out CSV (contact_report.hpp).

#include "contact_report.hpp"

#include <algorithm>
#include <cstdio>

#include "common.hpp"

namespace aloft::cli {

namespace {

constexpr std::size_t kPairsShown = 5;  // the summary's list; the CSV has them all

// The mobile's restitution and friction, as one value each when every component has the same.
std::string contact_settings(const Model& model) {
  const auto range = [&](const std::vector<double>& values, const char* what) {
    double low = values.empty() ? 0 : values[0], high = low;
    for (double v : values) low = std::min(low, v), high = std::max(high, v);
    return low == high ? format("%s %g", what, low) : format("%s %g to %g", what, low, high);
  };
  return range(model.restitution, "restitution") + ", " + range(model.friction, "friction");
}

}  // namespace

void print_collision_summary(const Model& model, const Simulation& sim, const ContactTally& tally,
                             CollisionsOff off, const std::string& csv_path) {
  if (off == CollisionsOff::kByFlag) {
    std::printf("collisions        off (--no-collisions)\n");
    return;
  }
  if (off == CollisionsOff::kByFile || !sim.collision_detector()) {
    std::printf("collisions        off (the mobile file's \"contact\": {\"enabled\": false})\n");
    return;
  }
  const CollisionPairs& pairs = sim.collision_detector()->pairs();
  std::printf("collisions        on: %lld of %lld pairs can touch (the rest pruned: 'aloft inspect' says why); %s\n",
              pairs.candidate_count, pairs.total, contact_settings(model).c_str());
  // Pairs touching in the designed pose are left out of detection for the whole run (docs/collisions.md):
  // their other pieces pass through each other too, which the summary must not keep quiet about.
  if (!pairs.touching_at_rest.empty()) {
    std::printf("not collided      %zu pair%s touching in the designed pose (hung from one point?) pass%s through each "
                "other:",
                pairs.touching_at_rest.size(), pairs.touching_at_rest.size() == 1 ? "" : "s",
                pairs.touching_at_rest.size() == 1 ? "es" : "");
    for (std::size_t k = 0; k < pairs.touching_at_rest.size() && k < kPairsShown; ++k)
      std::printf("%s '%s' and '%s'", k ? "," : "", model.names[pairs.touching_at_rest[k].first].c_str(),
                  model.names[pairs.touching_at_rest[k].second].c_str());
    if (pairs.touching_at_rest.size() > kPairsShown)
      std::printf(" and %zu more ('aloft inspect' lists them)", pairs.touching_at_rest.size() - kPairsShown);
    std::printf("\n");
  }
  const CollisionStatistics& stats = sim.collision_statistics();
  std::printf("contacts          %lld impulses (%lld sliding); deepest overlap %.3f mm; %.4g J taken out\n",
              stats.impulses, stats.sliding, stats.deepest * 1e3, stats.energy_removed);
  const std::vector<ContactTally::Pair> touched = tally.pairs();
  if (touched.empty()) {
    std::printf("touching pairs    none (no contact impulse, no two components within %.2g mm of each other)\n",
                ContactTally::kTouchingGap * 1e3);
    return;
  }
  std::printf("touching pairs    %zu (pushed apart, or within %.2g mm), in %lld steps; the most often:\n",
              touched.size(), ContactTally::kTouchingGap * 1e3, tally.steps_touching());
  for (std::size_t k = 0; k < touched.size() && k < kPairsShown; ++k) {
    const ContactTally::Pair& p = touched[k];
    std::printf("                  '%s' and '%s': %lld steps, %.3f to %.3f s, overlap up to %.3f mm\n",
                model.names[p.a].c_str(), model.names[p.b].c_str(), p.steps, p.first, p.last, p.deepest * 1e3);
  }
  if (touched.size() > kPairsShown)
    std::printf("                  ... and %zu more%s\n", touched.size() - kPairsShown,
                csv_path.empty() ? " (--contacts-out FILE lists them all)" : "");
  if (!csv_path.empty()) std::printf("contact pairs     %s (%zu pairs)\n", csv_path.c_str(), touched.size());
}

void write_contact_pairs_csv(const std::string& path, const Model& model, const ContactTally& tally) {
  std::string text = "component_a,component_b,steps,first_t,last_t,deepest_overlap_m\n";
  for (const ContactTally::Pair& p : tally.pairs()) {
    text += csv_field(model.names[p.a]) + ',' + csv_field(model.names[p.b]) + ',' + std::to_string(p.steps);
    for (double v : {p.first, p.last, p.deepest}) {
      text += ',';
      append_double(text, v);
    }
    text += '\n';
  }
  write_file(path, text);
}

}  // namespace aloft::cli
