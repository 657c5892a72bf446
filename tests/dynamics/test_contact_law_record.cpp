// Recording the contact law's solves (aloft/contact_law_record.hpp): the records hold what the law was
// given and gave, so solving them again gives the same impulses; recording does not change the motion;
// a malformed file is refused with its name, the byte and what is wrong.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include "aloft/contact_law_record.hpp"
#include "aloft/error.hpp"
#include "aloft/generate.hpp"
#include "aloft/model.hpp"
#include "aloft/simulation.hpp"
#include "aloft/spec.hpp"
#include "dynamics/contact_law.hpp"

namespace aloft {
namespace {

// generated-127 (seed 2, as Collisions.EnergyTakenOutIsTheEnergyLost), knocking after 0.3 s of the
// bench's breeze.
Model knocking_mobile() {
  GenerateOptions options;
  options.components = 127;
  options.seed = 2;
  return compile(parse_mobile_text(generate_mobile(options), "generated-127.json"));
}

std::vector<std::uint8_t> bytes_of(const std::string& text) { return {text.begin(), text.end()}; }

std::string written(const std::vector<ContactLawRecord>& records) {
  std::ostringstream out(std::ios::binary);
  write_contact_law_header(out);
  for (const ContactLawRecord& r : records) write_contact_law_record(out, r);
  return out.str();
}

ContactLawRecord two_contacts(bool with_start) {
  ContactLawRecord r;
  const Eigen::MatrixXd G = Eigen::MatrixXd::Random(6, 6);
  r.K = G * G.transpose();
  r.u = Eigen::VectorXd::Random(6);
  r.target_normal = Eigen::Vector2d(0.0, 0.01);
  r.friction = Eigen::Vector2d(0.3, 0.0);
  if (with_start) r.start = Eigen::VectorXd::Random(6);
  r.impulses = Eigen::VectorXd::Random(6);
  return r;
}

// The message of the InputError that parsing `bytes` throws ("" when none is thrown).
std::string refusal(const std::string& bytes) {
  try {
    parse_contact_law_records(bytes_of(bytes), "tangle.law");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(ContactLawRecord, WhatIsWrittenIsReadBackBitForBit) {
  const std::vector<ContactLawRecord> records = {two_contacts(true), two_contacts(false)};
  const std::vector<ContactLawRecord> read = parse_contact_law_records(bytes_of(written(records)), "two.law");
  ASSERT_EQ(read.size(), 2u);
  for (int i = 0; i < 2; ++i) {
    EXPECT_EQ(read[i].K, records[i].K);
    EXPECT_EQ(read[i].u, records[i].u);
    EXPECT_EQ(read[i].target_normal, records[i].target_normal);
    EXPECT_EQ(read[i].friction, records[i].friction);
    EXPECT_EQ(read[i].start.size(), records[i].start.size());
    if (records[i].start.size() > 0) {
      EXPECT_EQ(read[i].start, records[i].start);
    }
    EXPECT_EQ(read[i].impulses, records[i].impulses);
  }
}

// The format's byte order is little-endian whatever the host's, so a recording (tests/data holds one)
// reads the same everywhere: a one-contact record's counts and numbers, byte by byte both ways. 1.0 and
// 0.5 are IEEE 754 binary64 0x3FF0000000000000 and 0x3FE0000000000000, least significant byte first.
TEST(ContactLawRecord, TheFileIsLittleEndianOnEveryHost) {
  ContactLawRecord one;
  one.K = Eigen::Matrix3d::Identity();
  one.u = Eigen::Vector3d(-0.5, 0, 0);
  one.target_normal = Eigen::VectorXd::Zero(1);
  one.friction = Eigen::VectorXd::Constant(1, 0.5);
  one.impulses = Eigen::Vector3d(0.5, 0, 0);
  const std::string bytes = written({one});
  const auto little_endian_double = [](std::uint64_t bits) {
    std::string b;
    for (int k = 0; k < 8; ++k) b += static_cast<char>((bits >> (8 * k)) & 0xff);
    return b;
  };
  const std::string one_le = little_endian_double(0x3FF0000000000000ull);
  const std::string half_le = little_endian_double(0x3FE0000000000000ull);
  const std::string minus_half_le = little_endian_double(0xBFE0000000000000ull);
  const std::string zero_le(8, '\0');
  std::string expected = std::string("ALOFTLAW") + std::string("\x01\0\0\0", 4);  // version 1
  expected += std::string("\x01\0\0\0", 4) + std::string("\0\0\0\0", 4);            // m = 1, no start
  for (int column = 0; column < 3; ++column)
    for (int row = 0; row < 3; ++row) expected += row == column ? one_le : zero_le;    // K, column-major
  expected += minus_half_le + zero_le + zero_le;                                      // u
  expected += zero_le;                                                                // target_normal
  expected += half_le;                                                                // friction
  expected += half_le + zero_le + zero_le;                                            // impulses
  EXPECT_EQ(bytes, expected);

  const std::vector<ContactLawRecord> read = parse_contact_law_records(bytes_of(expected), "one.law");
  ASSERT_EQ(read.size(), 1u);
  EXPECT_EQ(read[0].K, one.K);
  EXPECT_EQ(read[0].u, one.u);
  EXPECT_EQ(read[0].friction, one.friction);
  EXPECT_EQ(read[0].impulses, one.impulses);
}

// The recorder sees every solve of the steps (those that start from the last step's impulses, and the
// contact passes' corrections, which start from zero), and each, solved again, gives the impulses the
// step took from it: the record is the law's whole input. Recording leaves the motion as it was.
TEST(ContactLawRecord, RecordedSolvesGiveTheStepsImpulsesAgainAndLeaveTheMotionAlone) {
  const Model model = knocking_mobile();
  Simulation recorded(model), plain(model);
  for (Simulation* sim : {&recorded, &plain}) {
    ASSERT_TRUE(sim->collisions());
    set_breeze(model, sim->loads());
    ASSERT_TRUE(sim->advance(0.3)) << sim->failure()->message;
    sim->loads().clear();
  }
  std::vector<ContactLawRecord> records;
  recorded.record_contact_laws([&](const ContactLawRecord& r) { records.push_back(r); });
  ASSERT_TRUE(recorded.advance(0.5)) << recorded.failure()->message;
  ASSERT_TRUE(plain.advance(0.5)) << plain.failure()->message;
  recorded.record_contact_laws({});  // no more: the steps below are not recorded
  const std::size_t count = records.size();
  ASSERT_TRUE(recorded.advance(0.01));
  ASSERT_TRUE(plain.advance(0.01));
  EXPECT_EQ(records.size(), count);

  const long long solves = recorded.collision_statistics().law_solves;
  int warm = 0, several = 0;
  for (const ContactLawRecord& r : records) {
    const int m = r.contacts();
    ASSERT_EQ(r.K.rows(), 3 * m);
    ASSERT_EQ(r.K.cols(), 3 * m);
    ASSERT_EQ(r.u.size(), 3 * m);
    ASSERT_EQ(r.impulses.size(), 3 * m);
    warm += r.start.size() > 0;
    several += m > 1;
    Eigen::VectorXd P;
    solve_contact_law(r, P);
    ASSERT_EQ(P, r.impulses) << "solve " << (&r - records.data()) << " of " << m << " contacts";
  }
  std::printf("generated-127, 0.5 s knocking: %zu solves recorded (%d warm, %d of several contacts); the "
              "steps counted %lld of their own\n",
              records.size(), warm, several, solves);
  EXPECT_GT(warm, 0) << "some solves should start from the last step's impulses";
  EXPECT_GT(several, 100) << "the mobile should be knocking";
  // The statistics count the solves of the steps taken (the rejected tries' are recorded too) and not the
  // contact passes' corrections: the records are at least as many.
  EXPECT_GE(static_cast<long long>(records.size()), solves);

  for (int i = 1; i < model.count; ++i) {
    ASSERT_EQ(recorded.state().position[i], plain.state().position[i]) << "component " << i;
    ASSERT_EQ(recorded.state().angular[i], plain.state().angular[i]) << "component " << i;
  }
}

TEST(ContactLawRecord, AMalformedFileIsRefusedWithTheByteAndTheProblem) {
  const std::string good = written({two_contacts(true)});
  EXPECT_EQ(refusal(good), "");

  EXPECT_NE(refusal("ALOFTLAX" + good.substr(8)).find("tangle.law: byte 0"), std::string::npos)
      << refusal("ALOFTLAX" + good.substr(8));
  std::string version = good;
  version[8] = 2;
  EXPECT_NE(refusal(version).find("byte 8"), std::string::npos) << refusal(version);
  EXPECT_NE(refusal(version).find("version 2"), std::string::npos);

  // Cut inside the first record's collision matrix (it begins at byte 12 + 8).
  const std::string cut = refusal(good.substr(0, 100));
  EXPECT_NE(cut.find("byte 20"), std::string::npos) << cut;
  EXPECT_NE(cut.find("ends inside record 1's collision matrix"), std::string::npos) << cut;

  std::string none = good;
  std::memset(none.data() + 12, 0, 4);  // 0 contacts
  EXPECT_NE(refusal(none).find("byte 12: record 1: 0 contacts"), std::string::npos) << refusal(none);
  std::string huge = good;
  std::memset(huge.data() + 12, 0x7f, 4);  // about 2e9 contacts: refused before anything is allocated
  EXPECT_NE(refusal(huge).find("contacts, expected 1 to"), std::string::npos) << refusal(huge);

  std::string flag = good;
  flag[16] = 7;
  EXPECT_NE(refusal(flag).find("start flag 7"), std::string::npos) << refusal(flag);

  std::string not_finite = good;
  const double nan = std::nan("");
  std::memcpy(not_finite.data() + 20 + 8 * 5, &nan, 8);  // K's sixth entry
  EXPECT_NE(refusal(not_finite).find("byte 60: record 1's collision matrix holds a value that is not finite"),
            std::string::npos)
      << refusal(not_finite);

  std::string negative = good;
  const double minus = -0.3;
  std::memcpy(negative.data() + 20 + 8 * (36 + 6 + 2), &minus, 8);  // the first friction coefficient
  EXPECT_NE(refusal(negative).find("negative friction"), std::string::npos) << refusal(negative);

  // A second record cut short names it.
  const std::string two = written({two_contacts(false), two_contacts(true)});
  EXPECT_NE(refusal(two.substr(0, two.size() - 3)).find("ends inside record 2's impulses"), std::string::npos)
      << refusal(two.substr(0, two.size() - 3));

  EXPECT_THROW(read_contact_law_records("/nonexistent/tangle.law"), InputError);
  // A device is refused by name (it used to be read until memory ran out).
  try {
    read_contact_law_records("/dev/zero");
    ADD_FAILURE() << "/dev/zero was read";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "/dev/zero: not a regular file");
  }
}

}  // namespace
}  // namespace aloft
