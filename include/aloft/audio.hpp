#pragma once
// Sound in, wind speed out (method-notes section 7): the wind speed v0 at S0 follows the loudness of the
// breath on a microphone, or of a recording.
//
//   samples (mono, [-1, 1]) -> RMS over window_ms -> attack/release smoothing = envelope
//   v0 = gain * max(0, envelope - noise_floor)                                 (m/s)
//
// The noise floor is calibrated from the first calibration_s seconds (room sound) unless given. All of this
// is pure code; live capture is in the separate aloft_capture library (capture/), which feeds the same
// EnvelopeFollower so that a recording and a live device give the same v0 for the same samples.

#include <cstdint>
#include <string>
#include <vector>

namespace aloft {

// A decoded audio file: interleaved samples as floats, full scale 1 (integer encodings in [-1, 1); float
// ones as stored, which read_wav keeps within +-1000).
struct AudioClip {
  std::string file;
  int sample_rate = 0;               // Hz
  int channels = 0;
  std::vector<float> samples;        // frames * channels, interleaved
  std::size_t frames() const { return channels > 0 ? samples.size() / static_cast<std::size_t>(channels) : 0; }
  double duration() const { return sample_rate > 0 ? static_cast<double>(frames()) / sample_rate : 0; }
  std::vector<float> mono() const;   // channels averaged
};

// Read a RIFF/WAVE file: PCM 8/16/24/32-bit integer or IEEE float 32/64-bit (also WAVE_FORMAT_EXTENSIBLE),
// 1 to 8 channels. Throws InputError naming the file, the byte offset and what is wrong (not a RIFF file,
// truncated chunk, unsupported encoding, no data chunk, a data chunk without a whole frame, a float sample
// that is a NaN, infinite or beyond +-1000, 60 dB above full scale: not sound, ...), or "not a regular
// file" (a device or FIFO, which has no end). An odd-sized chunk without its pad byte is read when the next
// tag shows it (see parse_wav).
AudioClip read_wav(const std::string& path);
// The same from bytes in memory (`name` is used in messages).
AudioClip parse_wav(const std::vector<std::uint8_t>& bytes, const std::string& name);

struct EnvelopeSettings {
  double window_ms = 5;        // RMS window
  double attack_ms = 5;        // time constant when the level rises
  double release_ms = 150;     // time constant when it falls
  double gain = 25;            // m/s of v0 per unit of RMS above the noise floor
  double calibration_s = 1.0;  // seconds of room sound for the noise floor (0: no calibration)
  double noise_floor = -1;     // RMS; >= 0: use this one and do not calibrate
  double max_v0 = 20;          // m/s, v0 is clamped to this
  void validate() const;       // throws std::invalid_argument naming the bad setting
  // The samples the calibration takes at `sample_rate` (Hz), during which v0 is 0; 0 without calibration.
  std::uint64_t calibration_frames(int sample_rate) const;
};

// Sample-by-sample envelope follower with noise-floor calibration. During calibration v0 is 0; the floor is
// then the 95th percentile of the window RMS over the calibration period (a click does not raise it).
class EnvelopeFollower {
 public:
  EnvelopeFollower(int sample_rate, const EnvelopeSettings& settings = {});
  void push(const float* mono, std::size_t count);
  void push(float sample);

  double envelope() const { return envelope_; }   // RMS, smoothed
  double level() const { return rms_; }            // RMS over the last window, unsmoothed
  double noise_floor() const { return floor_; }    // RMS (0 until calibrated)
  bool calibrating() const { return calibrating_; }
  double v0() const;                                // m/s
  double time() const { return static_cast<double>(count_) / rate_; }  // s of audio pushed
  void set_gain(double gain) { settings_.gain = gain; }
  void recalibrate();                               // start a new calibration period now
  const EnvelopeSettings& settings() const { return settings_; }

 private:
  int rate_;
  EnvelopeSettings settings_;
  std::vector<double> window_;   // squares of the last window's samples, ring buffer
  std::size_t head_ = 0;
  double sum_ = 0;               // sum of window_, recomputed now and then against drift
  double rms_ = 0;
  double envelope_ = 0;
  double attack_ = 0, release_ = 0;  // per-sample smoothing factors
  double floor_ = 0;
  bool calibrating_ = false;
  std::uint64_t calibration_end_ = 0;
  std::vector<float> calibration_levels_;
  std::uint64_t count_ = 0;
};

// v0 as a function of time: samples (t, v0) with linear interpolation; before the first and after the last
// sample it holds the end values. Empty: v0 = 0.
struct SpeedSeries {
  std::vector<double> t;     // s, strictly increasing
  std::vector<double> v0;    // m/s, >= 0
  double at(double time) const;
  double duration() const { return t.empty() ? 0 : t.back(); }
};

// "t,v0" rows (an optional header line, '#' comments and blank lines allowed; a UTF-8 byte order mark at the
// start is skipped). Numbers are decimal, as in OBJ files (no hexadecimal, inf or nan; 1e-400 reads as 0).
// Throws InputError naming the file and line for a bad number, a negative speed or times not increasing,
// or "not a regular file".
SpeedSeries read_speed_csv(const std::string& path);

// Feeds an EnvelopeFollower and records v0 every `interval` seconds of *audio* time (the follower's value
// after the sample that ends each interval, sample index round(k interval rate)): the same series whether
// the samples come from a file in one piece or from a device in chunks of any size. The interval is from
// one sample (1 / rate) to kLongestSpeedInterval; the constructor throws std::invalid_argument otherwise.
inline constexpr double kLongestSpeedInterval = 3600;  // s
class SpeedSampler {
 public:
  SpeedSampler(int sample_rate, const EnvelopeSettings& settings, double interval = 0.001);
  void push(const float* mono, std::size_t count);
  const SpeedSeries& series() const { return series_; }
  void forget_series();   // drop all recorded samples but the last (a long live session)
  const EnvelopeFollower& follower() const { return follower_; }
  EnvelopeFollower& follower() { return follower_; }

 private:
  EnvelopeFollower follower_;
  int rate_;
  double interval_;
  long long next_k_ = 1;
  std::uint64_t pushed_ = 0;
  std::uint64_t next_end_ = 0;
  SpeedSeries series_;
};

// The v0 of a recording, sampled every `interval` seconds (the follower's value at the end of each
// interval), channels averaged.
SpeedSeries speed_from_audio(const AudioClip& clip, const EnvelopeSettings& settings, double interval = 0.001);

}  // namespace aloft
