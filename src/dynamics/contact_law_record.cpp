// Writing and reading the contact law's recorded solves (aloft/contact_law_record.hpp: the format).

#include "aloft/contact_law_record.hpp"

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <ostream>
#include <string>

#include "aloft/error.hpp"
#include "common/little_endian.hpp"
#include "common/regular_file.hpp"

namespace aloft {

namespace {

constexpr char kMagic[8] = {'A', 'L', 'O', 'F', 'T', 'L', 'A', 'W'};
constexpr std::uint32_t kVersion = 1;

// The file is little-endian on every host (the format's byte order, aloft/contact_law_record.hpp):
// little-endian hosts copy the bytes as they are, others reverse each value's.
constexpr bool kHostIsLittleEndian = std::endian::native == std::endian::little;
static_assert(kHostIsLittleEndian || std::endian::native == std::endian::big, "mixed-endian hosts are not supported");

// Reverses the bytes of each of `count` values of `size` bytes at `data` (in place). Called on big-endian
// hosts only (behind `if constexpr`), hence maybe_unused: clang warns of it on little-endian ones.
[[maybe_unused]] void reverse_each(unsigned char* data, std::size_t count, std::size_t size) {
  for (std::size_t k = 0; k < count; ++k) std::reverse(data + k * size, data + (k + 1) * size);
}

void put_u32(std::ostream& out, std::uint32_t value) {
  unsigned char bytes[4];
  for (int k = 0; k < 4; ++k) bytes[k] = static_cast<unsigned char>(value >> (8 * k));
  out.write(reinterpret_cast<const char*>(bytes), 4);
}

void put_doubles(std::ostream& out, const double* values, Eigen::Index count) {
  const auto size = static_cast<std::streamsize>(count * 8);
  if constexpr (kHostIsLittleEndian) {
    out.write(reinterpret_cast<const char*>(values), size);
  } else {
    std::vector<unsigned char> bytes(static_cast<std::size_t>(size));
    std::memcpy(bytes.data(), values, bytes.size());
    reverse_each(bytes.data(), static_cast<std::size_t>(count), 8);
    out.write(reinterpret_cast<const char*>(bytes.data()), size);
  }
}

class RecordParser {
 public:
  RecordParser(const std::vector<std::uint8_t>& bytes, const std::string& name) : bytes_(bytes), name_(name) {}

  std::vector<ContactLawRecord> parse() {
    if (bytes_.size() < 12 || std::memcmp(bytes_.data(), kMagic, 8) != 0)
      fail(0, "not a recorded contact-law file (it does not start with \"ALOFTLAW\")");
    at_ = 8;
    const std::uint32_t version = u32("the version");
    if (version != kVersion)
      fail(8, "version " + std::to_string(version) + ", this build reads version " + std::to_string(kVersion));
    std::vector<ContactLawRecord> records;
    while (at_ < bytes_.size()) records.push_back(record(records.size()));
    return records;
  }

 private:
  [[noreturn]] void fail(std::size_t offset, const std::string& problem) const {
    throw InputError(name_, SourcePlace{"byte " + std::to_string(offset), 0, 0}, problem);
  }

  std::uint32_t u32(const char* what) {
    if (bytes_.size() - at_ < 4) fail(at_, std::string("the file ends inside ") + what);
    const std::uint32_t value = little_endian_u32(bytes_.data() + at_);
    at_ += 4;
    return value;
  }

  // rows x cols finite doubles (column-major) into `out`, resized to that.
  template <class Dense>
  void doubles(Dense& out, Eigen::Index rows, Eigen::Index cols, const std::string& what) {
    const std::size_t size = static_cast<std::size_t>(rows * cols) * 8;
    if (bytes_.size() - at_ < size) fail(at_, "the file ends inside " + what);
    out.resize(rows, cols);
    std::memcpy(out.data(), bytes_.data() + at_, size);
    if constexpr (!kHostIsLittleEndian)
      reverse_each(reinterpret_cast<unsigned char*>(out.data()), static_cast<std::size_t>(rows * cols), 8);
    for (Eigen::Index k = 0; k < rows * cols; ++k)
      if (!std::isfinite(out.data()[k])) fail(at_ + static_cast<std::size_t>(k) * 8, what + " holds a value that is not finite");
    at_ += size;
  }

  ContactLawRecord record(std::size_t index) {
    const std::size_t begins = at_;
    const std::string which = "record " + std::to_string(index + 1);
    const std::uint32_t m = u32(("the contact count of " + which).c_str());
    if (m < 1 || m > static_cast<std::uint32_t>(kMaxRecordedContacts))
      fail(begins, which + ": " + std::to_string(m) + " contacts, expected 1 to " +
                       std::to_string(kMaxRecordedContacts));
    const std::uint32_t has_start = u32(("the start flag of " + which).c_str());
    if (has_start > 1) fail(begins + 4, which + ": start flag " + std::to_string(has_start) + ", expected 0 or 1");
    const Eigen::Index rows = 3 * static_cast<Eigen::Index>(m);
    ContactLawRecord r;
    doubles(r.K, rows, rows, which + "'s collision matrix");
    doubles(r.u, rows, 1, which + "'s contact velocities");
    doubles(r.target_normal, m, 1, which + "'s normal targets");
    const std::size_t friction_at = at_;
    doubles(r.friction, m, 1, which + "'s friction coefficients");
    if (r.friction.minCoeff() < 0) fail(friction_at, which + " has a negative friction coefficient");
    if (has_start) doubles(r.start, rows, 1, which + "'s starting impulses");
    doubles(r.impulses, rows, 1, which + "'s impulses");
    return r;
  }

  const std::vector<std::uint8_t>& bytes_;
  const std::string& name_;
  std::size_t at_ = 0;
};

}  // namespace

void write_contact_law_header(std::ostream& out) {
  out.write(kMagic, 8);
  put_u32(out, kVersion);
}

void write_contact_law_record(std::ostream& out, const ContactLawRecord& record) {
  const Eigen::Index m = record.contacts();
  put_u32(out, static_cast<std::uint32_t>(m));
  put_u32(out, record.start.size() > 0 ? 1 : 0);
  put_doubles(out, record.K.data(), 9 * m * m);
  put_doubles(out, record.u.data(), 3 * m);
  put_doubles(out, record.target_normal.data(), m);
  put_doubles(out, record.friction.data(), m);
  if (record.start.size() > 0) put_doubles(out, record.start.data(), 3 * m);
  put_doubles(out, record.impulses.data(), 3 * m);
}

std::vector<ContactLawRecord> parse_contact_law_records(const std::vector<std::uint8_t>& bytes,
                                                        const std::string& name) {
  return RecordParser(bytes, name).parse();
}

std::vector<ContactLawRecord> read_contact_law_records(const std::string& path) {
  require_regular_file(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, SourcePlace{}, std::string("cannot open: ") + std::strerror(errno));
  const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw InputError(path, SourcePlace{}, "read error");
  return parse_contact_law_records(bytes, path);
}

}  // namespace aloft
