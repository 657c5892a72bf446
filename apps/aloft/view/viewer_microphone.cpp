// The viewer's microphone: blowing on it drives the wind (v0 follows the breath's loudness). Opened
// once at start; with no device the panel says why and the wind keeps its other inputs.

#include <imgui.h>

#include <algorithm>
#include <cmath>

#include "bounded_slider.hpp"
#include "viewer_state.hpp"

#if ALOFT_HAVE_MICROPHONE
#include "aloft/microphone.hpp"
#endif

namespace aloft::view {

struct MicrophoneInput {
#if ALOFT_HAVE_MICROPHONE
  Microphone device;
#endif
};

void ViewerState::open_microphone() {
#if ALOFT_HAVE_MICROPHONE
  microphone = std::make_unique<MicrophoneInput>();
#endif
}

ViewerState::ViewerState() = default;
ViewerState::~ViewerState() = default;

void ViewerState::poll_microphone() {
#if ALOFT_HAVE_MICROPHONE && ALOFT_HAVE_WIND
  session->wind_control.mic_v0 = microphone && microphone->device.available() ? microphone->device.poll() : 0.0;
#endif
}

void ViewerState::draw_microphone_controls() {
#if ALOFT_HAVE_MICROPHONE
  if (!microphone) {
    ImGui::TextDisabled("microphone off (started with --no-mic)");
    return;
  }
  Microphone& mic = microphone->device;
  if (!mic.available()) {
    ImGui::PushTextWrapPos(ImGui::GetCursorPosX() + 300);
    ImGui::TextDisabled("%s", mic.status().c_str());
    ImGui::PopTextWrapPos();
    return;
  }
  // Level meter on a log scale: -60 dBFS (silence) to 0 dBFS; the noise floor marked in the label.
  const auto db = [](double rms) { return 20 * std::log10(std::max(rms, 1e-6)); };
  const double level = db(mic.envelope());
  char label[96];
  std::snprintf(label, sizeof label, "mic %.0f dB (floor %.0f dB)%s", level, db(mic.noise_floor()),
                mic.calibrating() ? " calibrating..." : "");
  ImGui::ProgressBar(static_cast<float>(std::clamp((level + 60) / 60, 0.0, 1.0)), ImVec2(-1, 0), label);
  if (ImGui::Button("Calibrate")) mic.recalibrate();
  ImGui::SameLine();
  ImGui::SetNextItemWidth(150);
  if (bounded_slider("gain", mic_gain, 1.0f, 200.0f, "%.0f m/s", ImGuiSliderFlags_Logarithmic))
    mic.set_gain(mic_gain);
#else
  ImGui::TextDisabled("no microphone support in this build");
#endif
}

}  // namespace aloft::view
