#pragma once
// The contact law's solves, written out as the simulation made them, so that a change to the law can be
// measured on the same inputs (docs/performance.md, "The contact law on recorded solves"). With
// collisions on, the motion is chaotic: any change to the law changes the trajectory, and with it which
// solves a span makes, so two versions of the law timed on a span compare two different tangles.
// Solving the recorded solves again compares them on the same ones, and tells whether the impulses
// changed at all.
//
// File format (version 1), little-endian on every host (every double is IEEE 754 binary64; files written
// before 2026-12-07 were in the writer's byte order, the same on x86-64 and little-endian ARM):
//   header: the 8 bytes "ALOFTLAW", then uint32 version = 1
//   records until the end of the file, each:
//     uint32 m (contacts, 1 ... kMaxRecordedContacts), uint32 has_start (0 or 1),
//     K (3m x 3m, column-major), u (3m), target_normal (m), friction (m), start (3m, only if has_start),
//     impulses (3m)
// Reading a malformed file throws InputError naming the file, the byte offset and what is wrong.

#include <Eigen/Dense>

#include <cstdint>
#include <functional>
#include <iosfwd>
#include <string>
#include <vector>

namespace aloft {

// One solve of the contact law (dynamics/contact_law.hpp) for m contacts, each in its own basis (normal
// row first): its inputs and the impulses it gave.
struct ContactLawRecord {
  Eigen::MatrixXd K;              // 3m x 3m: the collision matrix (m/s per N s)
  Eigen::VectorXd u;              // 3m: the contact velocities before the impulses (m/s)
  Eigen::VectorXd target_normal;  // m: the least normal velocity allowed after them (m/s)
  Eigen::VectorXd friction;       // m: Coulomb's mu
  Eigen::VectorXd start;          // 3m, where Gauss-Seidel started (N s); empty: from zero
  Eigen::VectorXd impulses;       // 3m: the solve's result P (N s)

  int contacts() const { return static_cast<int>(target_normal.size()); }
};

// Called by the simulation with each solve it makes (Simulation::record_contact_laws); the record is
// valid during the call only.
using ContactLawRecorder = std::function<void(const ContactLawRecord&)>;

// The most contacts a record may hold: more than a step ever solves (ContactResponse::kMaxContacts),
// small enough that a corrupt count cannot ask for gigabytes.
inline constexpr int kMaxRecordedContacts = 4096;

void write_contact_law_header(std::ostream& out);
void write_contact_law_record(std::ostream& out, const ContactLawRecord& record);

// Every record of the file at `path` (throws InputError for a file that cannot be read or is malformed:
// a wrong header or version, a count out of range, a record cut short, a value that is not finite).
std::vector<ContactLawRecord> read_contact_law_records(const std::string& path);

// The same from bytes already read; `name` is the file's name for the messages.
std::vector<ContactLawRecord> parse_contact_law_records(const std::vector<std::uint8_t>& bytes,
                                                        const std::string& name);

}  // namespace aloft
