// libFuzzer target: arbitrary bytes as a WAV file, decoded and turned into the wind speed v0 it would
// blow (the envelope follower at its defaults, v0 every millisecond). The only acceptable failure is an
// InputError; a crash, a sanitizer report, another exception or a hang is a bug, and so is a v0 that is
// not a finite speed within [0, max_v0]: the wind would silently be wrong.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "aloft/audio.hpp"
#include "aloft/error.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::vector<std::uint8_t> bytes(data, data + size);
  aloft::AudioClip clip;
  try {
    clip = aloft::parse_wav(bytes, "fuzz.wav");
  } catch (const aloft::InputError&) {
    return 0;
  }
  const aloft::EnvelopeSettings settings;
  const aloft::SpeedSeries series = aloft::speed_from_audio(clip, settings);
  for (std::size_t i = 0; i < series.v0.size(); ++i) {
    const double v0 = series.v0[i];
    if (!(v0 >= 0 && v0 <= settings.max_v0)) {
      std::fprintf(stderr, "v0 %g at t = %g s is not a speed in [0, %g]\n", v0, series.t[i], settings.max_v0);
      std::abort();
    }
  }
  return 0;
}
