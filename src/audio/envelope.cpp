// The envelope follower: windowed RMS, attack/release smoothing, noise-floor calibration, gain -> v0.

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "aloft/audio.hpp"
#include "aloft/spec.hpp"

namespace aloft {

namespace {

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument(what);
}

// Per-sample factor of a one-pole smoother with time constant `ms` at `rate` Hz (1: no smoothing).
double smoothing_factor(double ms, int rate) {
  const double samples = ms * 1e-3 * rate;
  return samples > 0 ? 1 - std::exp(-1 / samples) : 1.0;
}

}  // namespace

std::uint64_t EnvelopeSettings::calibration_frames(int sample_rate) const {
  return calibration_s > 0 ? static_cast<std::uint64_t>(std::llround(calibration_s * sample_rate)) : 0;
}

void EnvelopeSettings::validate() const {
  require(std::isfinite(window_ms) && window_ms > 0 && window_ms <= 1000, "the RMS window must be in (0, 1000] ms");
  require(std::isfinite(attack_ms) && attack_ms >= 0 && attack_ms <= 10000, "the attack time must be in [0, 10000] ms");
  require(std::isfinite(release_ms) && release_ms >= 0 && release_ms <= 10000, "the release time must be in [0, 10000] ms");
  require(std::isfinite(gain) && gain >= 0, "the microphone gain must be >= 0 (m/s per unit RMS)");
  require(std::isfinite(calibration_s) && calibration_s >= 0 && calibration_s <= 60,
          "the noise calibration must last 0 to 60 s");
  require(std::isfinite(noise_floor) && noise_floor <= 1, "the noise floor must be an RMS <= 1 (or < 0: calibrate)");
  require(max_v0 > 0 && acceptable_wind_speed(max_v0), "the largest v0 must be > 0 m/s and at most 100 m/s (kFastestWind)");
}

EnvelopeFollower::EnvelopeFollower(int sample_rate, const EnvelopeSettings& settings)
    : rate_(sample_rate), settings_(settings) {
  require(sample_rate >= 1000 && sample_rate <= 768000, "the sample rate must be in [1000, 768000] Hz");
  settings.validate();
  const std::size_t n = std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(settings.window_ms * 1e-3 * rate_)));
  window_.assign(n, 0.0);
  attack_ = smoothing_factor(settings.attack_ms, rate_);
  release_ = smoothing_factor(settings.release_ms, rate_);
  if (settings.noise_floor >= 0)
    floor_ = settings.noise_floor;
  else
    recalibrate();
}

void EnvelopeFollower::recalibrate() {
  if (settings_.calibration_s <= 0) {
    calibrating_ = false;
    return;
  }
  calibrating_ = true;
  calibration_end_ = count_ + settings_.calibration_frames(rate_);
  calibration_levels_.clear();
}

void EnvelopeFollower::push(const float* mono, std::size_t count) {
  for (std::size_t i = 0; i < count; ++i) push(mono[i]);
}

void EnvelopeFollower::push(float sample) {
  const std::size_t n = window_.size();
  // Squared in double: the square of any finite float is finite there (at most 1.2e77). A float square
  // of a sample past 1.8e19 is infinite: the window's RMS then was too, the smoothed envelope with it,
  // and once the RMS came back the envelope's step inf - inf left it NaN for good (v0 read 0).
  const double square = static_cast<double>(sample) * sample;
  sum_ += square - window_[head_];
  window_[head_] = square;
  if (++head_ == n) {
    head_ = 0;
    // Once per window, add the window up afresh so that rounding in the running sum cannot build up.
    double exact = 0;
    for (double s : window_) exact += s;
    sum_ = exact;
    if (calibrating_) calibration_levels_.push_back(static_cast<float>(std::sqrt(exact / n)));
  }
  rms_ = std::sqrt(std::max(0.0, sum_) / static_cast<double>(n));
  envelope_ += (rms_ - envelope_) * (rms_ > envelope_ ? attack_ : release_);
  ++count_;
  if (calibrating_ && count_ >= calibration_end_) {
    // The 95th percentile of the window levels: the room's sound, not its loudest click.
    if (calibration_levels_.empty()) {
      floor_ = rms_;
    } else {
      const std::size_t k = (calibration_levels_.size() - 1) * 95 / 100;
      std::nth_element(calibration_levels_.begin(), calibration_levels_.begin() + static_cast<std::ptrdiff_t>(k),
                       calibration_levels_.end());
      floor_ = calibration_levels_[k];
    }
    calibrating_ = false;
  }
}

double EnvelopeFollower::v0() const {
  if (calibrating_) return 0;
  return std::min(settings_.max_v0, settings_.gain * std::max(0.0, envelope_ - floor_));
}

SpeedSampler::SpeedSampler(int sample_rate, const EnvelopeSettings& settings, double interval)
    : follower_(sample_rate, settings), rate_(sample_rate), interval_(interval) {
  // At least one sample, so that every interval ends at a later sample than the one before. With 1e-300 s
  // each interval's end rounds to the sample push() is at, and its loop records it again without end.
  require(std::isfinite(interval) && interval * sample_rate >= 1 && interval <= kLongestSpeedInterval,
          "the speed series interval must be from one sample (1/" + std::to_string(sample_rate) + " s) to " +
              std::to_string(static_cast<int>(kLongestSpeedInterval)) + " s");
  series_.t.push_back(0);
  series_.v0.push_back(0);
  next_end_ = static_cast<std::uint64_t>(std::llround(interval_ * rate_));
}

void SpeedSampler::push(const float* mono, std::size_t count) {
  std::size_t i = 0;
  while (i < count) {
    // Samples up to the end of the current interval, then one record.
    const std::uint64_t room = next_end_ - pushed_;
    const std::size_t take = static_cast<std::size_t>(std::min<std::uint64_t>(room, count - i));
    follower_.push(mono + i, take);
    i += take;
    pushed_ += take;
    if (pushed_ == next_end_) {
      series_.t.push_back(static_cast<double>(pushed_) / rate_);
      series_.v0.push_back(follower_.v0());
      ++next_k_;
      next_end_ = static_cast<std::uint64_t>(std::llround(next_k_ * interval_ * rate_));
    }
  }
}

void SpeedSampler::forget_series() {
  if (series_.t.size() <= 1) return;
  series_.t.erase(series_.t.begin(), series_.t.end() - 1);
  series_.v0.erase(series_.v0.begin(), series_.v0.end() - 1);
}

SpeedSeries speed_from_audio(const AudioClip& clip, const EnvelopeSettings& settings, double interval) {
  const std::vector<float> mono = clip.mono();
  SpeedSampler sampler(clip.sample_rate, settings, interval);
  sampler.push(mono.data(), mono.size());
  return sampler.series();
}

}  // namespace aloft
