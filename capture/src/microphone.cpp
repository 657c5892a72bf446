// SDL2 audio capture: open a device (by name or the default), dequeue its samples without a callback,
// feed them to the SpeedSampler. No device: a status message, v0 = 0.

#include "aloft/microphone.hpp"

#include <SDL.h>

#include <algorithm>

namespace aloft {

namespace {

// SDL's audio subsystem, started on demand. False (with SDL's reason in `why`) when it cannot start;
// `started` tells whether this call started it (and so must stop it), not someone before.
bool start_audio(bool& started, std::string& why) {
  started = false;
  if (SDL_WasInit(SDL_INIT_AUDIO) != 0) return true;
  if (SDL_InitSubSystem(SDL_INIT_AUDIO) != 0) {
    why = SDL_GetError();
    return false;
  }
  started = true;
  return true;
}

}  // namespace

std::vector<std::string> capture_devices() {
  std::vector<std::string> names;
  std::string why;
  bool started = false;
  if (!start_audio(started, why)) return names;
  const int count = SDL_GetNumAudioDevices(1);
  for (int i = 0; i < count; ++i)
    if (const char* name = SDL_GetAudioDeviceName(i, 1)) names.emplace_back(name);
  if (started) SDL_QuitSubSystem(SDL_INIT_AUDIO);
  return names;
}

Microphone::Microphone(const MicrophoneOptions& options) : record_(options.record) {
  options.envelope.validate();
  rate_ = options.sample_rate;
  // The follower exists even without a device, so the level and v0 read as 0.
  sampler_ = std::make_unique<SpeedSampler>(rate_, options.envelope, options.interval);
  std::string why;
  if (!start_audio(audio_started_, why)) {
    status_ = "no microphone: audio does not start (" + why + "); the wind stays still";
    return;
  }
  SDL_AudioSpec want{};
  want.freq = options.sample_rate;
  want.format = AUDIO_F32SYS;
  want.channels = 1;
  want.samples = 512;
  want.callback = nullptr;  // queued: SDL_DequeueAudio in poll()
  SDL_AudioSpec have{};
  const char* requested = options.device.empty() ? nullptr : options.device.c_str();
  // No allowed changes: SDL converts whatever the device gives to mono float at our rate.
  device_ = SDL_OpenAudioDevice(requested, 1, &want, &have, 0);
  if (device_ == 0) {
    status_ = std::string("no microphone") + (requested ? " named \"" + options.device + "\"" : std::string()) + ": " +
              SDL_GetError() + "; the wind stays still";
    if (audio_started_) SDL_QuitSubSystem(SDL_INIT_AUDIO);
    audio_started_ = false;
    return;
  }
  name_ = requested ? options.device : std::string("the default capture device");
  status_ = "capturing from " + name_ + " (" + SDL_GetCurrentAudioDriver() + ") at " + std::to_string(have.freq) + " Hz";
  SDL_PauseAudioDevice(device_, 0);
}

Microphone::~Microphone() {
  if (device_ != 0) SDL_CloseAudioDevice(device_);
  if (audio_started_) SDL_QuitSubSystem(SDL_INIT_AUDIO);
}

double Microphone::poll() {
  if (device_ == 0) return 0;
  for (;;) {
    const Uint32 queued = SDL_GetQueuedAudioSize(device_);
    if (queued < sizeof(float)) break;
    buffer_.resize(std::min<std::size_t>(queued / sizeof(float), 1 << 16));
    const Uint32 got = SDL_DequeueAudio(device_, buffer_.data(), static_cast<Uint32>(buffer_.size() * sizeof(float)));
    if (got == 0) break;
    sampler_->push(buffer_.data(), got / sizeof(float));
    if (!record_ && sampler_->series().t.size() > 4096) sampler_->forget_series();  // keeps the last value
  }
  return v0();
}

double Microphone::v0() const { return device_ != 0 ? sampler_->follower().v0() : 0.0; }
double Microphone::level() const { return sampler_->follower().level(); }
double Microphone::envelope() const { return sampler_->follower().envelope(); }
double Microphone::noise_floor() const { return sampler_->follower().noise_floor(); }
bool Microphone::calibrating() const { return sampler_->follower().calibrating(); }
double Microphone::audio_time() const { return sampler_->follower().time(); }
void Microphone::set_gain(double gain) { sampler_->follower().set_gain(gain); }
void Microphone::recalibrate() { sampler_->follower().recalibrate(); }
const SpeedSeries& Microphone::series() const { return sampler_->series(); }

}  // namespace aloft
