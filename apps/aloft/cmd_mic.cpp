// aloft mic: a live level meter for the microphone and the wind speed v0 it would give, to set the gain
// and check the noise floor. No microphone is not an error: it says so and exits 0.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <memory>
#include <thread>

#include "aloft/microphone.hpp"
#include "common.hpp"

namespace aloft::cli {

namespace {

volatile std::sig_atomic_t interrupted = 0;
extern "C" void on_interrupt(int) { interrupted = 1; }

// A bar of `width` characters for an RMS level on a dB scale from -60 dBFS (empty) to 0 dBFS (full).
std::string meter(double rms, int width) {
  const double db = rms > 0 ? 20 * std::log10(rms) : -120;
  const int filled = std::clamp(static_cast<int>(std::lround((db + 60) / 60 * width)), 0, width);
  return std::string(static_cast<std::size_t>(filled), '#') + std::string(static_cast<std::size_t>(width - filled), '.');
}

}  // namespace

Runner add_mic(CLI::App& app) {
  struct Options {
    std::string device;
    bool list = false;
    double duration = 0;
    double gain = EnvelopeSettings{}.gain;
    double noise_floor = -1;
    double calibrate = 1.0;
    int rate = 48000;
    std::string csv;
    double interval = 0.001;
  };
  auto o = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand("mic", "Show the microphone's level and the wind speed it would blow");
  sub->add_option("-d,--device", o->device, "Capture device by name (see --list); default: the system's default")
      ->type_name("NAME");
  sub->add_flag("-l,--list", o->list, "List the capture devices and exit");
  sub->add_option("-t,--duration", o->duration,
                  format("Stop after this much audio (s, up to %g); default: until Ctrl-C", kLongestDuration))
      ->type_name("T")
      ->check(duration_in_seconds());
  sub->add_option("--gain", o->gain, "m/s of v0 per unit of RMS above the noise floor (0 to 1e6)")
      ->type_name("G")
      ->capture_default_str()
      ->check(number_in(0.0, 1e6));
  sub->add_option("--noise-floor", o->noise_floor, "Noise floor (RMS, 0 to 1) instead of calibrating it")
      ->type_name("RMS")
      ->check(number_in(0.0, 1.0));
  sub->add_option("--calibrate", o->calibrate, "Seconds of room sound at the start that set the noise floor (0 to 60)")
      ->type_name("S")
      ->capture_default_str()
      ->check(number_in(0.0, 60.0));
  sub->add_option("--rate", o->rate, "Sample rate to capture at (Hz)")
      ->type_name("HZ")
      ->capture_default_str()
      ->check(integer_in(8000, 192000));
  sub->add_option("--csv", o->csv, "Write v0 over audio time as \"t,v0\" rows (s, m/s), usable by --wind-speed")
      ->type_name("FILE");
  sub->add_option("--interval", o->interval,
                  format("Audio time between CSV rows (s, at least one sample, up to %g)", kLongestSpeedInterval))
      ->type_name("S")
      ->capture_default_str()
      ->check(number_in(1.0 / 192000, kLongestSpeedInterval));  // one sample at the highest --rate
  sub->footer(
      "Stay quiet for the first --calibrate seconds (the room's noise floor is measured), then blow.\n"
      "v0 = gain * (envelope - noise floor): the envelope is the RMS over 5 ms, rising in 5 ms and falling\n"
      "in 150 ms. Use the gain you settle on with 'aloft simulate --wind-audio ... --wind-gain G'.\n"
      "\n"
      "Without a microphone (or without a sound server) it says so once and exits 0. Testing without\n"
      "hardware: SDL_AUDIODRIVER=disk SDL_DISKAUDIOFILEIN=blow_f32.raw (mono 32-bit float at --rate).\n"
      "\n"
      "Examples:\n"
      "  aloft mic\n"
      "  aloft mic --list\n"
      "  aloft mic --device \"USB Microphone\" --gain 40 --duration 10 --csv breath.csv\n");
  return [o] {
    if (o->list) {
      const std::vector<std::string> names = capture_devices();
      if (names.empty()) std::printf("no capture devices\n");
      for (const std::string& n : names) std::printf("%s\n", n.c_str());
      return kExitOk;
    }
    MicrophoneOptions mo;
    mo.device = o->device;
    mo.sample_rate = o->rate;
    mo.envelope.gain = o->gain;
    mo.envelope.noise_floor = o->noise_floor;
    mo.envelope.calibration_s = o->calibrate;
    mo.interval = o->interval;
    mo.record = !o->csv.empty();
    Microphone mic(mo);
    if (!mic.available()) {
      std::fprintf(stderr, "aloft: %s\n", mic.status().c_str());
      return kExitOk;
    }
    std::fprintf(stderr, "aloft: %s; %s\n", mic.status().c_str(),
                 o->noise_floor >= 0 ? "noise floor given" : "calibrating the noise floor: stay quiet");
    std::signal(SIGINT, on_interrupt);
    const bool tty = is_terminal(stdout);
    const auto start = WallClock::now();
    double last_line = -1;
    double peak = 0;
    bool announced = o->noise_floor >= 0;
    while (!interrupted) {
      const double v0 = mic.poll();
      peak = std::max(peak, v0);
      const double t = mic.audio_time();
      if (!announced && !mic.calibrating()) {
        std::fprintf(stderr, "%saloft: noise floor %.5f RMS (%.1f dBFS); blow now\n", tty ? "\n" : "", mic.noise_floor(),
                     mic.noise_floor() > 0 ? 20 * std::log10(mic.noise_floor()) : -120.0);
        announced = true;
      }
      if (tty || t - last_line >= 0.5) {
        std::printf("%s%6.2f s  [%s] %6.4f RMS  floor %6.4f  v0 %5.2f m/s%s", tty ? "\r" : "", t,
                    meter(mic.envelope(), 30).c_str(), mic.envelope(), mic.noise_floor(), v0, tty ? "  " : "\n");
        std::fflush(stdout);
        last_line = t;
      }
      if (o->duration > 0 && t >= o->duration) break;
      const double wall = seconds_since(start);
      if (o->duration > 0 && wall > o->duration + 5) {
        std::fprintf(stderr, "%saloft: the device stopped sending sound after %.2f s of audio\n", tty ? "\n" : "", t);
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    std::signal(SIGINT, SIG_DFL);
    if (tty) std::printf("\n");
    std::printf("audio %.3f s, noise floor %.5f RMS, peak v0 %.3f m/s\n", mic.audio_time(), mic.noise_floor(), peak);
    if (!o->csv.empty()) {
      std::string text = "t,v0\n";
      const SpeedSeries& s = mic.series();
      for (std::size_t i = 0; i < s.t.size(); ++i) {
        if (o->duration > 0 && s.t[i] > o->duration + 1e-9) break;
        append_double(text, s.t[i]);
        text += ',';
        append_double(text, s.v0[i]);
        text += '\n';
      }
      write_file(o->csv, text);
    }
    return kExitOk;
  };
}

static const CommandRegistration registration{"mic", 45, add_mic};

}  // namespace aloft::cli
