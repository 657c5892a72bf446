#pragma once
// A Dear ImGui slider whose value stays in [lo, hi] however it is edited. Ctrl+click turns a slider into a
// text box, and Dear ImGui keeps whatever number is typed there (1e300, -5) unless told to clamp
// (imgui.h, ImGuiSliderFlags_AlwaysClamp), so a restitution of 5 or a total mass of 1e300 kg could reach
// the simulation. Its clamp lets NaN through (every comparison with NaN is false); this does not.

#include <imgui.h>

#include <algorithm>
#include <cmath>

namespace aloft::view {

// As ImGui::SliderFloat; returns whether `value` changed. A typed NaN leaves `value` as it was.
inline bool bounded_slider(const char* label, float& value, float lo, float hi, const char* format,
                           ImGuiSliderFlags flags = 0) {
  float edited = value;
  if (!ImGui::SliderFloat(label, &edited, lo, hi, format, flags | ImGuiSliderFlags_AlwaysClamp)) return false;
  if (!std::isfinite(edited)) return false;
  value = std::clamp(edited, lo, hi);
  return true;
}

}  // namespace aloft::view
