// The WAV reader: every supported encoding decodes to the same values; malformed files give an InputError
// naming the file and what is wrong, never a crash.

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>

#include "aloft/audio.hpp"
#include "aloft/error.hpp"
#include "audio/wav_bytes.hpp"

namespace aloft::test {
namespace {

// Quantisation of each encoding: 1/32768 for 16-bit; the other encodings are exact for these values.
constexpr float kSixteenBitStep = 1.0f / 32768;

TEST(WavReader, DecodesEveryEncodingToTheSameSamples) {
  // Samples -0.5, 0.25, 0 and a near-full-scale 0.75 in each encoding.
  const std::vector<double> values = {-0.5, 0.25, 0.0, 0.75};
  std::vector<std::uint8_t> pcm16, pcm24, pcm32, f32, f64, u8;
  for (double v : values) {
    const auto i16 = static_cast<std::int16_t>(v * 32768);
    put16(pcm16, static_cast<std::uint16_t>(i16));
    const auto i24 = static_cast<std::int32_t>(v * 8388608);
    for (int k = 0; k < 3; ++k) pcm24.push_back((static_cast<std::uint32_t>(i24) >> (8 * k)) & 0xff);
    put32(pcm32, static_cast<std::uint32_t>(static_cast<std::int32_t>(v * 2147483648.0)));
    float f = static_cast<float>(v);
    std::uint32_t fu;
    std::memcpy(&fu, &f, 4);
    put32(f32, fu);
    std::uint64_t du;
    std::memcpy(&du, &v, 8);
    put32(f64, static_cast<std::uint32_t>(du));
    put32(f64, static_cast<std::uint32_t>(du >> 32));
    u8.push_back(static_cast<std::uint8_t>(128 + v * 128));
  }
  const struct {
    const char* name;
    std::vector<std::uint8_t> bytes;
    float step;
  } cases[] = {
      {"pcm16", wav_bytes(1, 1, 48000, 16, pcm16), kSixteenBitStep},
      {"pcm24", wav_bytes(1, 1, 48000, 24, pcm24), 0},
      {"pcm32", wav_bytes(1, 1, 48000, 32, pcm32), 0},
      {"float32", wav_bytes(3, 1, 48000, 32, f32), 0},
      {"float64", wav_bytes(3, 1, 48000, 64, f64), 0},
      {"pcm8", wav_bytes(1, 1, 8000, 8, u8), 1.0f / 128},
      {"extensible pcm16", wav_bytes(1, 1, 48000, 16, pcm16, true), kSixteenBitStep},
      {"extensible float32 with a LIST chunk", wav_bytes(3, 1, 44100, 32, f32, true, true), 0},
  };
  for (const auto& c : cases) {
    const AudioClip clip = parse_wav(c.bytes, c.name);
    ASSERT_EQ(clip.channels, 1) << c.name;
    ASSERT_EQ(clip.samples.size(), values.size()) << c.name;
    for (std::size_t i = 0; i < values.size(); ++i) EXPECT_NEAR(clip.samples[i], values[i], c.step) << c.name << " " << i;
  }
}

TEST(WavReader, StereoIsAveragedToMono) {
  std::vector<std::uint8_t> data;
  for (int v : {16384, -16384, 8192, 8192}) put16(data, static_cast<std::uint16_t>(static_cast<std::int16_t>(v)));
  const AudioClip clip = parse_wav(wav_bytes(1, 2, 48000, 16, data), "stereo");
  ASSERT_EQ(clip.frames(), 2u);
  const std::vector<float> mono = clip.mono();
  EXPECT_EQ(mono[0], 0.0f);     // (0.5 - 0.5) / 2, exact in float
  EXPECT_EQ(mono[1], 0.25f);    // (0.25 + 0.25) / 2, exact
  EXPECT_EQ(clip.duration(), 2.0 / 48000);
}

std::string message_of(const std::vector<std::uint8_t>& bytes) {
  try {
    parse_wav(bytes, "bad.wav");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(WavReader, MalformedFilesAreNamedAndExplained) {
  std::vector<std::uint8_t> samples(8, 0);
  const std::vector<std::uint8_t> good = wav_bytes(1, 1, 48000, 16, samples);
  EXPECT_NE(message_of({}).find("bad.wav: byte 0: not a WAV file"), std::string::npos) << message_of({});
  std::vector<std::uint8_t> text(good);
  std::memcpy(text.data(), "RIFX", 4);
  EXPECT_NE(message_of(text).find("does not start with \"RIFF\""), std::string::npos);
  // Cut inside the fmt chunk.
  const std::string cut = message_of(std::vector<std::uint8_t>(good.begin(), good.begin() + 30));
  EXPECT_NE(cut.find("truncated"), std::string::npos) << cut;
  // No data chunk at all.
  const std::string no_data = message_of(std::vector<std::uint8_t>(good.begin(), good.begin() + 36));
  EXPECT_NE(no_data.find("no \"data\" chunk"), std::string::npos) << no_data;
  // Unsupported encodings.
  EXPECT_NE(message_of(wav_bytes(2, 1, 48000, 16, samples)).find("unsupported encoding (format code 2)"), std::string::npos);
  EXPECT_NE(message_of(wav_bytes(1, 1, 48000, 12, samples)).find("12-bit integer"), std::string::npos);
  EXPECT_NE(message_of(wav_bytes(1, 9, 48000, 16, samples)).find("9 channels"), std::string::npos);
  EXPECT_NE(message_of(wav_bytes(1, 1, 10, 16, samples)).find("sample rate 10 Hz"), std::string::npos);
  // A recording cut inside its data chunk keeps its whole frames (what a crashed recorder leaves).
  const AudioClip partial = parse_wav(std::vector<std::uint8_t>(good.begin(), good.end() - 3), "cut.wav");
  EXPECT_EQ(partial.frames(), 2u);
  // A missing file.
  try {
    read_wav("/nonexistent/blow.wav");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/blow.wav: cannot open the audio file"), std::string::npos) << e.what();
  }
}

// Float samples as stored, up to 1000 either way (a mix left unclipped goes past full scale, 1); a NaN,
// an infinity or anything beyond 1000 (60 dB above full scale) is not sound, and is named with its
// sample index and byte offset. The data chunk starts at byte 44 in these files.
TEST(WavReader, FloatSamplesThatAreNotSoundAreNamed) {
  const auto float32_file = [](std::vector<float> values) {
    std::vector<std::uint8_t> data;
    for (float f : values) {
      std::uint32_t u;
      std::memcpy(&u, &f, 4);
      put32(data, u);
    }
    return wav_bytes(3, 1, 48000, 32, data);
  };
  const AudioClip loud = parse_wav(float32_file({0.5f, -1000.0f, 2.5f}), "loud.wav");
  ASSERT_EQ(loud.samples.size(), 3u);
  EXPECT_EQ(loud.samples[1], -1000.0f);
  EXPECT_EQ(loud.samples[2], 2.5f);

  const std::string huge = message_of(float32_file({0.5f, 0.25f, 1e30f}));
  EXPECT_NE(huge.find("bad.wav: byte 52: float sample 2 is 1e+30: full scale is 1"), std::string::npos) << huge;
  const std::string over = message_of(float32_file({1000.5f}));
  EXPECT_NE(over.find("byte 44: float sample 0 is 1000.5"), std::string::npos) << over;
  const std::string nan = message_of(float32_file({0.0f, std::nanf("")}));
  EXPECT_NE(nan.find("byte 48: float sample 1 is a NaN or an infinity"), std::string::npos) << nan;
  // A 64-bit 1e300 is finite: named as the number it is (it used to overflow to infinity in float first).
  std::vector<std::uint8_t> f64;
  const double big = 1e300;
  std::uint64_t du;
  std::memcpy(&du, &big, 8);
  put32(f64, static_cast<std::uint32_t>(du));
  put32(f64, static_cast<std::uint32_t>(du >> 32));
  const std::string wide = message_of(wav_bytes(3, 1, 48000, 64, f64));
  EXPECT_NE(wide.find("byte 44: float sample 0 is 1e+300"), std::string::npos) << wide;
}

// A file without a single sample frame gave v0 = 0 throughout: a run without wind and without a word. It is
// named at its "data" chunk, which starts at byte 36 in these files (12 of RIFF header, 24 of "fmt ").
TEST(WavReader, AFileWithoutSamplesIsNamedAtItsDataChunk) {
  const std::vector<std::uint8_t> empty = wav_bytes(1, 1, 48000, 16, {});  // the 44-byte header alone
  ASSERT_EQ(empty.size(), 44u);
  EXPECT_EQ(message_of(empty), "bad.wav: byte 36: the \"data\" chunk is empty (0 bytes): the file holds no samples");
  // Size 0 with the samples after it (a streaming writer that never wrote the size back): not guessed at,
  // since an empty chunk may as well be followed by other chunks.
  std::vector<std::uint8_t> unsized = wav_bytes(1, 1, 48000, 16, std::vector<std::uint8_t>(8, 0x10));
  std::memset(unsized.data() + 40, 0, 4);
  EXPECT_EQ(message_of(unsized), "bad.wav: byte 36: the \"data\" chunk declares 0 bytes, so the file holds no samples "
                                 "(8 bytes follow it: if they are the samples, the recorder never wrote the chunk's "
                                 "size)");
  // An empty "data" chunk, then a real one: the first is the file's data.
  std::vector<std::uint8_t> twice(empty);
  put_tag(twice, "data");
  put32(twice, 4);
  for (int i = 0; i < 4; ++i) twice.push_back(0x10);
  EXPECT_EQ(message_of(twice), "bad.wav: byte 36: the \"data\" chunk declares 0 bytes, so the file holds no samples "
                               "(another \"data\" chunk follows at byte 44: a WAV file holds one)");
  // Less than one frame: 3 bytes of a stereo 16-bit file (4 bytes a frame), or a chunk cut before its first.
  EXPECT_EQ(message_of(wav_bytes(1, 2, 48000, 16, {1, 2, 3})),
            "bad.wav: byte 36: the \"data\" chunk holds 3 bytes, less than one frame (4 bytes): the file holds no "
            "samples");
  std::vector<std::uint8_t> cut = wav_bytes(1, 1, 48000, 16, std::vector<std::uint8_t>(8, 0));
  cut.resize(45);
  EXPECT_EQ(message_of(cut), "bad.wav: byte 36: the \"data\" chunk declares 8 bytes, but the file ends after 1 of "
                             "them, less than one frame (2 bytes): the file holds no samples");
}

// The 16-bit samples 0.25, -0.5 as bytes (exact in 16 bits).
std::vector<std::uint8_t> two_samples() {
  std::vector<std::uint8_t> data;
  put16(data, 8192);
  put16(data, static_cast<std::uint16_t>(-16384));
  return data;
}

// An odd-sized chunk written without its pad byte: the "LIST" chunk of wav_bytes(..., extra_chunk) is 3
// bytes at byte 36, its pad at byte 47, "data" at byte 48.
TEST(WavReader, AnOddChunkWithoutItsPadByteIsReadWhenTheNextTagShowsIt) {
  const std::vector<std::uint8_t> padded = wav_bytes(1, 1, 48000, 16, two_samples(), false, true);
  ASSERT_EQ(padded[47], 0);
  ASSERT_EQ(std::memcmp(padded.data() + 48, "data", 4), 0);
  std::vector<std::uint8_t> unpadded(padded);
  unpadded.erase(unpadded.begin() + 47);
  // Read with the pad, the tag would be "ata\x04" (the size's low byte): not a tag; "data" is one byte sooner.
  const AudioClip clip = parse_wav(unpadded, "nopad.wav");
  ASSERT_EQ(clip.samples.size(), 2u);
  EXPECT_EQ(clip.samples[0], 0.25f);  // exact in 16 bits
  EXPECT_EQ(clip.samples[1], -0.5f);
  // A pad byte that is a printable character is still a pad when a tag follows it.
  std::vector<std::uint8_t> spaced(padded);
  spaced[47] = 'x';  // "xdat" would be a plausible tag too, but "data" after the pad is one
  EXPECT_EQ(parse_wav(spaced, "spaced.wav").samples.size(), 2u);
  // When the size's low byte is a character (72 = 'H'), "ataH" looks like a tag: the reading goes on with
  // the pad, meets a chunk far too long, and the message names the odd-sized chunk before it.
  std::vector<std::uint8_t> long_data;
  for (int i = 0; i < 36; ++i) put16(long_data, 0x1010);  // 72 bytes
  std::vector<std::uint8_t> shifted = wav_bytes(1, 1, 48000, 16, long_data, false, true);
  shifted.erase(shifted.begin() + 47);
  EXPECT_EQ(message_of(shifted),
            "bad.wav: byte 48: truncated file: the \"ataH\" chunk claims 268435456 bytes, 71 are left (it follows "
            "the odd-sized \"LIST\" chunk at byte 36, whose pad byte may be missing)");
}

// A damaged tag's NUL byte cut the message short ("truncated file: the \""): tags are printed with every
// byte that is not printable ASCII, and the quote and backslash, as \xNN.
TEST(WavReader, ChunkTagsInMessagesAreEscaped) {
  std::vector<std::uint8_t> bytes = wav_bytes(1, 1, 48000, 16, two_samples());
  bytes.resize(36);  // up to the end of "fmt "
  const std::uint8_t tag[4] = {'a', 0, '"', 0xFF};
  bytes.insert(bytes.end(), tag, tag + 4);
  put32(bytes, 1000);
  EXPECT_EQ(message_of(bytes), "bad.wav: byte 36: truncated file: the \"a\\x00\\x22\\xFF\" chunk claims 1000 bytes, "
                               "0 are left");
}

// Input files are read whole: /dev/zero or a FIFO was read until memory ran out, without the file named.
TEST(WavReader, OnlyRegularFilesAreRead) {
  const std::string fifo = ::testing::TempDir() + "aloft_wav_fifo";
  std::remove(fifo.c_str());
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  for (const std::string& path : {std::string("/dev/zero"), fifo, ::testing::TempDir()}) {
    try {
      read_wav(path);
      ADD_FAILURE() << path << ": no error";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()), path + ": not a regular file");
    }
  }
  std::remove(fifo.c_str());
}

TEST(WavReader, GarbageNeverCrashes) {
  // Random bytes, and a good file with random bytes overwritten or cut anywhere: either a clip or an
  // InputError (ASan/UBSan builds check that nothing is read out of bounds).
  std::mt19937 rng(5);
  std::vector<std::uint8_t> samples(64);
  for (auto& s : samples) s = static_cast<std::uint8_t>(rng());
  const std::vector<std::uint8_t> good = wav_bytes(1, 2, 48000, 16, samples, true, true);
  int errors = 0, clips = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    std::vector<std::uint8_t> bytes = good;
    if (trial % 3 == 0) bytes.resize(rng() % (good.size() + 1));
    else if (trial % 3 == 1)
      for (int k = 0; k < 4; ++k) bytes[rng() % bytes.size()] = static_cast<std::uint8_t>(rng());
    else
      for (auto& b : bytes) b = static_cast<std::uint8_t>(rng());
    try {
      parse_wav(bytes, "fuzz.wav");
      ++clips;
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).rfind("fuzz.wav: ", 0), 0u) << e.what();
      ++errors;
    }
  }
  EXPECT_GT(errors, 0);
  EXPECT_GT(clips, 0);
}

}  // namespace
}  // namespace aloft::test
