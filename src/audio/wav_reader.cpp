// RIFF/WAVE reading: PCM integer 8/16/24/32-bit, IEEE float 32/64-bit, WAVE_FORMAT_EXTENSIBLE; 1-8
// channels. Every malformed input becomes an InputError naming the file, the byte offset and the problem.

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>

#include "aloft/audio.hpp"
#include "aloft/error.hpp"
#include "common/little_endian.hpp"
#include "common/printable.hpp"
#include "common/regular_file.hpp"

namespace aloft {

namespace {

constexpr std::uint16_t kFormatPcm = 1;
constexpr std::uint16_t kFormatFloat = 3;
constexpr std::uint16_t kFormatExtensible = 0xFFFE;

// The largest float sample taken as sound: full scale is 1.0, and float files may go past it (a mix
// left unclipped), but 1000 is 60 dB above it. A larger value is not a recording of a breath (a
// damaged file, or raw numbers written as audio): one sample of 1e30 would hold the wind at its
// strongest for many seconds, a silent wrong result.
constexpr double kLargestFloatSample = 1000;

struct Reader {
  const std::vector<std::uint8_t>& bytes;
  const std::string& name;

  [[noreturn]] void fail(std::size_t offset, const std::string& problem) const {
    throw InputError(name, SourcePlace{"byte " + std::to_string(offset), 0, 0}, problem);
  }
  std::uint16_t u16(std::size_t at) const { return little_endian_u16(bytes.data() + at); }
  std::uint32_t u32(std::size_t at) const { return little_endian_u32(bytes.data() + at); }
  bool tag(std::size_t at, const char* four) const { return std::memcmp(bytes.data() + at, four, 4) == 0; }
  // Whether the four bytes at `at` can be a chunk tag: printable ASCII (RIFF tags are letters, digits and
  // spaces).
  bool plausible_tag(std::size_t at) const {
    const auto first = bytes.begin() + static_cast<std::ptrdiff_t>(at);
    return std::all_of(first, first + 4, [](std::uint8_t c) { return c >= 0x20 && c < 0x7f; });
  }
  // The tag at `at` for a message, in quotes (common/printable.hpp: a damaged tag's NUL byte used to cut
  // the message short).
  std::string tag_text(std::size_t at) const {
    std::string out = "\"";
    out += printable(std::string_view(reinterpret_cast<const char*>(bytes.data() + at), 4));
    return out += "\"";
  }
};

// A sample's value for a message: "1e+30", "-1234.5".
std::string format_number(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", value);
  return text;
}

// One float sample at `p` (little-endian, 32 or 64 bits), as stored: any value, NaN included.
double decode_float(const std::uint8_t* p, int bits) {
  return bits == 32 ? std::bit_cast<float>(little_endian_u32(p)) : std::bit_cast<double>(little_endian_u64(p));
}

// One integer sample at `p` (little-endian) as a float in [-1, 1].
float decode_integer(const std::uint8_t* p, int bits) {
  switch (bits) {
    case 8: return (static_cast<int>(p[0]) - 128) / 128.0f;  // unsigned, offset 128
    case 16: return static_cast<std::int16_t>(little_endian_u16(p)) / 32768.0f;
    case 24: {
      std::int32_t v = static_cast<std::int32_t>((static_cast<std::uint32_t>(p[0]) << 8) |
                                                 (static_cast<std::uint32_t>(p[1]) << 16) |
                                                 (static_cast<std::uint32_t>(p[2]) << 24)) >> 8;
      return static_cast<float>(v / 8388608.0);
    }
    default: return static_cast<float>(static_cast<std::int32_t>(little_endian_u32(p)) / 2147483648.0);
  }
}

}  // namespace

std::vector<float> AudioClip::mono() const {
  const std::size_t n = frames();
  std::vector<float> out(n);
  for (std::size_t f = 0; f < n; ++f) {
    double sum = 0;
    for (int c = 0; c < channels; ++c) sum += samples[f * channels + c];
    out[f] = static_cast<float>(sum / channels);
  }
  return out;
}

AudioClip parse_wav(const std::vector<std::uint8_t>& bytes, const std::string& name) {
  const Reader r{bytes, name};
  if (bytes.size() < 12) r.fail(0, "not a WAV file: " + std::to_string(bytes.size()) + " bytes, too short for a RIFF header");
  if (!r.tag(0, "RIFF")) r.fail(0, "not a WAV file: it does not start with \"RIFF\"");
  if (!r.tag(8, "WAVE")) r.fail(8, "not a WAV file: a RIFF file of another type (no \"WAVE\")");

  bool have_format = false;
  std::uint16_t format = 0, channels = 0, bits = 0, block_align = 0;
  std::uint32_t rate = 0;
  std::size_t at = 12;
  std::size_t odd_chunk = 0;  // byte offset of the chunk before `at` when that one is of odd size (0: not)
  // " (it follows the odd-sized chunk at byte N, ...)" when the chunk at `at` follows one of odd size, whose
  // pad byte may be missing and so have shifted the reading by one byte.
  const auto after_odd_chunk = [&] {
    return odd_chunk == 0 ? std::string()
                          : " (it follows the odd-sized " + r.tag_text(odd_chunk) + " chunk at byte " +
                                std::to_string(odd_chunk) + ", whose pad byte may be missing)";
  };
  while (at + 8 <= bytes.size()) {
    const std::uint32_t size = r.u32(at + 4);
    const std::size_t body = at + 8;
    const bool is_data = r.tag(at, "data");
    if (static_cast<std::uint64_t>(body) + size > bytes.size()) {
      // A truncated data chunk (a recording cut short) keeps its whole frames; any other truncation is fatal.
      if (!is_data)
        r.fail(at, "truncated file: the " + r.tag_text(at) + " chunk claims " + std::to_string(size) + " bytes, " +
                       std::to_string(bytes.size() - body) + " are left" + after_odd_chunk());
    }
    if (r.tag(at, "fmt ")) {
      if (size < 16) r.fail(at, "the \"fmt \" chunk is " + std::to_string(size) + " bytes, at least 16 are needed");
      format = r.u16(body);
      channels = r.u16(body + 2);
      rate = r.u32(body + 4);
      block_align = r.u16(body + 12);
      bits = r.u16(body + 14);
      if (format == kFormatExtensible) {
        if (size < 40) r.fail(at, "WAVE_FORMAT_EXTENSIBLE \"fmt \" chunk is " + std::to_string(size) + " bytes, 40 are needed");
        format = r.u16(body + 24);  // the sub-format GUID starts with the format code
      }
      if (format != kFormatPcm && format != kFormatFloat)
        r.fail(body, "unsupported encoding (format code " + std::to_string(format) +
                         "): only PCM integer and IEEE float are read");
      if (channels < 1 || channels > 8) r.fail(body + 2, std::to_string(channels) + " channels: 1 to 8 are read");
      if (rate < 1000 || rate > 768000) r.fail(body + 4, "sample rate " + std::to_string(rate) + " Hz is not plausible");
      const bool int_ok = format == kFormatPcm && (bits == 8 || bits == 16 || bits == 24 || bits == 32);
      const bool float_ok = format == kFormatFloat && (bits == 32 || bits == 64);
      if (!int_ok && !float_ok)
        r.fail(body + 14, std::to_string(bits) + "-bit " + (format == kFormatPcm ? "integer" : "float") +
                              " samples are not supported (integer 8/16/24/32, float 32/64)");
      if (block_align != channels * (bits / 8))
        r.fail(body + 12, "block align " + std::to_string(block_align) + " does not match " + std::to_string(channels) +
                              " channels of " + std::to_string(bits) + " bits");
      have_format = true;
    } else if (is_data) {
      if (!have_format) r.fail(at, "the \"data\" chunk comes before any \"fmt \" chunk");
      const std::size_t available = std::min<std::size_t>(size, bytes.size() - body);
      const std::size_t frames = available / block_align;
      if (frames == 0) {
        // No samples: v0 would be 0 throughout, a run without wind and without a word.
        if (size == 0 && bytes.size() >= body + 8 && r.tag(body, "data"))
          r.fail(at, "the \"data\" chunk declares 0 bytes, so the file holds no samples (another \"data\" chunk "
                     "follows at byte " + std::to_string(body) + ": a WAV file holds one)");
        if (size == 0 && bytes.size() > body)
          r.fail(at, "the \"data\" chunk declares 0 bytes, so the file holds no samples (" +
                         std::to_string(bytes.size() - body) +
                         " bytes follow it: if they are the samples, the recorder never wrote the chunk's size)");
        if (size == 0) r.fail(at, "the \"data\" chunk is empty (0 bytes): the file holds no samples");
        r.fail(at, "the \"data\" chunk " +
                       (available < size ? "declares " + std::to_string(size) + " bytes, but the file ends after " +
                                               std::to_string(available) + " of them"
                                         : "holds " + std::to_string(available) + " bytes") +
                       ", less than one frame (" + std::to_string(block_align) +
                       " bytes): the file holds no samples");
      }
      AudioClip clip;
      clip.file = name;
      clip.sample_rate = static_cast<int>(rate);
      clip.channels = channels;
      clip.samples.resize(frames * channels);
      const std::size_t width = bits / 8;
      for (std::size_t i = 0; i < clip.samples.size(); ++i) {
        const std::size_t offset = body + i * width;
        if (format == kFormatPcm) {
          clip.samples[i] = decode_integer(bytes.data() + offset, bits);
          continue;
        }
        const double value = decode_float(bytes.data() + offset, bits);
        if (!std::isfinite(value)) r.fail(offset, "float sample " + std::to_string(i) + " is a NaN or an infinity");
        if (std::abs(value) > kLargestFloatSample)
          r.fail(offset, "float sample " + std::to_string(i) + " is " + format_number(value) +
                             ": full scale is 1, and a sample beyond +-1000 (60 dB above it) is not sound");
        clip.samples[i] = static_cast<float>(value);
      }
      return clip;
    }
    // Chunks are padded to even sizes. Some writers leave the pad byte out: when the byte after an odd-sized
    // chunk starts a chunk header with a plausible tag and the byte after it does not, the pad is missing
    // and the next chunk starts at once. (Read with the pad, its tag would be three bytes of the real tag and
    // one of its size, often not a character at all, and its size a misreading.)
    std::uint64_t next = static_cast<std::uint64_t>(body) + size;
    odd_chunk = 0;
    if (size & 1) {
      odd_chunk = at;
      const bool unpadded = next + 8 <= bytes.size() && r.plausible_tag(next) &&
                            !(next + 9 <= bytes.size() && r.plausible_tag(next + 1));
      if (!unpadded) ++next;
    }
    if (next >= bytes.size()) break;
    at = static_cast<std::size_t>(next);
  }
  if (!have_format) r.fail(12, "no \"fmt \" chunk: not a usable WAV file");
  r.fail(bytes.size(), "no \"data\" chunk: the file holds no samples");
}

AudioClip read_wav(const std::string& path) {
  require_regular_file(path);  // /dev/zero or a FIFO was read until memory ran out
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, {}, std::string("cannot open the audio file: ") + std::strerror(errno));
  std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw InputError(path, {}, "cannot read the audio file");
  return parse_wav(bytes, path);
}

}  // namespace aloft
