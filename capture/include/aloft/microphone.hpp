#pragma once
// A live microphone (SDL2 audio capture) turned into a wind speed v0 by aloft_core's envelope follower.
//
// No device is not an error: the Microphone is then simply not available(), v0() stays 0, and status()
// says why (once, for the caller to print). Tested without hardware through SDL's "disk" driver:
//     SDL_AUDIODRIVER=disk SDL_DISKAUDIOFILEIN=blow_f32.raw   (raw 32-bit float, mono, at sample_rate)
// Not thread-safe; call poll() from one thread (e.g. once per frame), it never blocks.

#include <memory>
#include <string>
#include <vector>

#include "aloft/audio.hpp"

namespace aloft {

struct MicrophoneOptions {
  std::string device;            // capture device name as listed by capture_devices(); empty: the default
  int sample_rate = 48000;       // Hz, requested (mono, 32-bit float)
  EnvelopeSettings envelope;     // gain, noise floor calibration, attack/release
  double interval = 0.001;       // s of audio between recorded v0 samples (series())
  bool record = false;           // keep the v0 series (series()); otherwise only the latest values
};

// Names of the capture devices SDL sees (empty when there are none or audio cannot start).
std::vector<std::string> capture_devices();

class Microphone {
 public:
  explicit Microphone(const MicrophoneOptions& options = {});
  ~Microphone();
  Microphone(const Microphone&) = delete;
  Microphone& operator=(const Microphone&) = delete;

  bool available() const { return device_ != 0; }
  // "capturing from <name> at 48000 Hz" or why there is no microphone.
  const std::string& status() const { return status_; }
  const std::string& device_name() const { return name_; }
  int sample_rate() const { return rate_; }

  // Take what the device captured since the last call and update the envelope. Returns v0 (m/s).
  double poll();
  double v0() const;                 // m/s, 0 without a device or while calibrating
  double level() const;              // RMS of the last window
  double envelope() const;           // smoothed RMS
  double noise_floor() const;        // RMS
  bool calibrating() const;
  double audio_time() const;         // s of audio received
  void set_gain(double gain);        // m/s per unit RMS
  void recalibrate();                // measure the room again, starting now
  const SpeedSeries& series() const; // v0 every `interval` s of audio time (options.record)

 private:
  unsigned device_ = 0;              // SDL_AudioDeviceID, 0: none
  bool audio_started_ = false;
  std::string status_;
  std::string name_;
  int rate_ = 0;
  std::unique_ptr<SpeedSampler> sampler_;
  std::vector<float> buffer_;
  bool record_ = false;
};

}  // namespace aloft
