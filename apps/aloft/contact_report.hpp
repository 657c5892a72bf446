#pragma once
// What `aloft simulate` says about collisions: the summary's lines (whether they were on, what the
// contacts did, which pairs of components touched) and the per-pair CSV of --contacts-out.

#include <string>

#include "aloft/contact_tally.hpp"
#include "aloft/model.hpp"
#include "aloft/simulation.hpp"

namespace aloft::cli {

// Why collisions are off, when they are: "--no-collisions", or the mobile file's setting.
enum class CollisionsOff { kNo, kByFlag, kByFile };

// Prints the summary's collision lines on stdout (`csv_path`: the --contacts-out file, or empty).
void print_collision_summary(const Model& model, const Simulation& sim, const ContactTally& tally,
                             CollisionsOff off, const std::string& csv_path);

// Writes every pair that touched as a CSV row: component_a,component_b,steps,first_t,last_t,
// deepest_overlap_m (names quoted as RFC 4180 needs; times in s, the overlap in m). Throws Failure when
// the file cannot be written.
void write_contact_pairs_csv(const std::string& path, const Model& model, const ContactTally& tally);

}  // namespace aloft::cli
