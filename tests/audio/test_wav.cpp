// The WAV reader: every supported encoding decodes to the same values; malformed files give an InputError
// naming the file and what is wrong, never a crash.

#include <gtest/gtest.h>

#include <cmath>
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
