// The viewer's Dear ImGui panel (playback, mobile settings, wind, view, capture), its key help, the
// error banner, and the lines drawn over the scene (wind cone, occlusion elements, mouse spring).

#include <imgui.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "bounded_slider.hpp"
#include "viewer_state.hpp"

namespace aloft::view {

namespace {

const char* balance_name(BalanceMode m) {
  switch (m) {
    case BalanceMode::Mass: return "mass (hangs still)";
    case BalanceMode::Joints: return "joints (move hooks)";
    case BalanceMode::None: return "none (as built)";
  }
  return "";
}

void help_window(bool& open) {
  if (!open) return;
  const ImVec2 centre = ImGui::GetMainViewport()->GetCenter();
  ImGui::SetNextWindowPos(centre, ImGuiCond_Always, ImVec2(0.5f, 0.5f));
  ImGui::Begin("Keys and mouse", &open, ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoCollapse);
  static const char* const kRows[][2] = {
      {"left drag", "orbit the camera"},
      {"left drag on a piece", "grab it and pull (a spring to the cursor)"},
      {"right / middle / shift+left drag", "pan"},
      {"wheel", "zoom"},
      {"ctrl + left drag", "aim the wind"},
      {"drop a .json file", "load it"},
      {"space", "play / pause"},
      {"N or right arrow", "single step (pauses)"},
      {"R", "reset to rest"},
      {"+ / -", "time scale x2 / /2 (slow motion)"},
      {"G", "a gust of wind"},
      {"W", "all wind on / off (yours and the file's sources)"},
      {"K / O", "show the wind cone / what the wind reaches"},
      {"S", "shadows on / off"},
      {"C", "reset the camera"},
      {"P or F12", "screenshot (PNG)"},
      {"V", "start / stop recording (MP4)"},
      {"H or tab", "hide / show the panel"},
      {"?", "this help"},
      {"Q or Esc", "quit"},
  };
  if (ImGui::BeginTable("keys", 2, ImGuiTableFlags_RowBg | ImGuiTableFlags_SizingFixedFit)) {
    for (const auto& row : kRows) {
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      ImGui::TextColored(ImVec4(1.0f, 0.8f, 0.45f, 1), "%s", row[0]);
      ImGui::TableNextColumn();
      ImGui::TextUnformatted(row[1]);
    }
    ImGui::EndTable();
  }
  ImGui::TextDisabled("The mobile file is reloaded when it changes on disk.");
  ImGui::End();
}

void error_banner(MobileSession& session) {
  if (session.error().empty()) return;
  const ImGuiViewport* vp = ImGui::GetMainViewport();
  ImGui::SetNextWindowPos(ImVec2(vp->WorkPos.x + vp->WorkSize.x * 0.5f, vp->WorkPos.y + 10), ImGuiCond_Always,
                          ImVec2(0.5f, 0));
  ImGui::SetNextWindowSizeConstraints(ImVec2(200, 0), ImVec2(vp->WorkSize.x * 0.6f, vp->WorkSize.y * 0.5f));
  ImGui::PushStyleColor(ImGuiCol_WindowBg, ImVec4(0.55f, 0.08f, 0.06f, 0.94f));
  ImGui::Begin("##error", nullptr,
               ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoSavedSettings |
                   ImGuiWindowFlags_NoFocusOnAppearing);
  ImGui::PushTextWrapPos(vp->WorkSize.x * 0.58f);
  ImGui::TextUnformatted(session.error().c_str());
  ImGui::PopTextWrapPos();
  ImGui::TextColored(ImVec4(1, 0.85f, 0.8f, 1), "The last good mobile keeps running. Fix the file and save it.");
  if (ImGui::SmallButton("dismiss")) session.clear_error();
  ImGui::End();
  ImGui::PopStyleColor();
}

#if ALOFT_HAVE_WIND
// The cone of `wind`: the S0 circle, a circle at `reach` m from the vertex, and 8 lines along its side.
render::LineSet cone_lines(const Wind& wind, double reach, const std::array<float, 4>& color) {
  const WindSource& src = wind.source();
  const Mat3 frame = wind.frame();
  const Vec3 right = frame.col(0), up = frame.col(1);
  render::LineSet cone;
  cone.color = color;
  constexpr int kSides = 48;
  for (double l : {src.l0, reach}) {
    const double r = src.r0 * l / src.l0;
    const Vec3 c = src.vertex + l * src.direction;
    for (int k = 0; k < kSides; ++k) {
      const double a0 = 2 * std::numbers::pi * k / kSides, a1 = 2 * std::numbers::pi * (k + 1) / kSides;
      cone.points.push_back(c + r * (std::cos(a0) * right + std::sin(a0) * up));
      cone.points.push_back(c + r * (std::cos(a1) * right + std::sin(a1) * up));
    }
  }
  for (int k = 0; k < 8; ++k) {
    const double a = 2 * std::numbers::pi * k / 8;
    const Vec3 rim = std::cos(a) * right + std::sin(a) * up;
    cone.points.push_back(src.vertex);
    cone.points.push_back(src.vertex + reach * src.direction + src.r0 * reach / src.l0 * rim);
  }
  return cone;
}

// Every area element `wind` reaches: a short hair along its normal, facing the wind, and a cross.
render::LineSet element_lines(const Wind& wind, const State& state, const std::array<float, 4>& color) {
  render::LineSet hairs;
  hairs.color = color;
  const Vec3 d = wind.source().direction;
  for (const WindElement& e : wind.elements()) {
    const int c = e.component;
    if (c < 0 || c >= static_cast<int>(state.position.size())) continue;
    const Vec3 p = state.position[c] + state.orientation[c] * e.point_body;
    Vec3 n = state.orientation[c] * e.normal_body;
    if (n.dot(d) > 0) n = -n;
    const double size = std::clamp(std::sqrt(e.area), 0.006, 0.05);  // m: about the element's width
    hairs.points.insert(hairs.points.end(), {p, p + n * size * 1.5});
    const Vec3 a = n.unitOrthogonal() * size * 0.5, b = n.cross(a);
    hairs.points.insert(hairs.points.end(), {p - a, p + a, p - b, p + b});
  }
  return hairs;
}
#endif

}  // namespace

void style_panel() {
  ImGui::StyleColorsDark();
  ImGuiStyle& s = ImGui::GetStyle();
  s.WindowRounding = 6;
  s.FrameRounding = 4;
  s.GrabRounding = 4;
  s.WindowBorderSize = 0;
  s.Colors[ImGuiCol_WindowBg] = ImVec4(0.10f, 0.10f, 0.11f, 0.86f);
  s.Colors[ImGuiCol_Header] = ImVec4(0.30f, 0.22f, 0.16f, 0.8f);
  s.Colors[ImGuiCol_HeaderHovered] = ImVec4(0.45f, 0.30f, 0.18f, 0.8f);
  s.Colors[ImGuiCol_Button] = ImVec4(0.28f, 0.24f, 0.21f, 1);
  s.Colors[ImGuiCol_ButtonHovered] = ImVec4(0.55f, 0.32f, 0.16f, 1);
  s.Colors[ImGuiCol_FrameBg] = ImVec4(0.22f, 0.21f, 0.20f, 1);
  s.Colors[ImGuiCol_SliderGrab] = ImVec4(0.85f, 0.45f, 0.20f, 1);
  s.Colors[ImGuiCol_CheckMark] = ImVec4(0.95f, 0.55f, 0.25f, 1);
  s.Colors[ImGuiCol_PlotHistogram] = ImVec4(0.85f, 0.45f, 0.20f, 1);
}

std::vector<render::LineSet> ViewerState::overlay_lines() const {
  std::vector<render::LineSet> lines;
  const State& state = session->simulation().state();
  if (const auto& g = session->grabbed()) {
    render::LineSet spring;
    spring.color = {1.0f, 0.55f, 0.15f, 1.0f};
    spring.points = {g->point_world(state), g->target};
    lines.push_back(std::move(spring));
  }
#if ALOFT_HAVE_WIND
  const Wind* wind = session->wind();
  const bool blowing = session->wind_control.enabled;
  if (wind && blowing && show_cone) {
    lines.push_back(cone_lines(*wind, wind->source().l0 + 2 * session->wind_control.distance,
                               {0.45f, 0.75f, 1.0f, 0.75f}));
  }
  // The file's sources that blow: warm cones, long enough to pass the whole mobile.
  for (const FileWind& f : session->file_winds()) {
    if (!f.wind || !f.enabled || !blowing || !show_cone) continue;
    const WindSource& src = f.wind->source();
    double reach = src.l0 + 0.5;  // m from the vertex
    for (const Vec3& p : state.position) reach = std::max(reach, (p - src.vertex).dot(src.direction) + 0.3);
    lines.push_back(cone_lines(*f.wind, reach, {1.0f, 0.78f, 0.35f, 0.75f}));
  }
  if (wind && blowing && show_occlusion) lines.push_back(element_lines(*wind, state, {0.2f, 1.0f, 0.85f, 1.0f}));
  for (const FileWind& f : session->file_winds())
    if (f.wind && f.enabled && blowing && show_occlusion)
      lines.push_back(element_lines(*f.wind, state, {1.0f, 0.9f, 0.3f, 1.0f}));
#endif
  return lines;
}

void ViewerState::draw_panel() {
  error_banner(*session);
  help_window(show_help);
  const double now = seconds_since(start);
  if (!message.empty() && now < message_until) {
    const ImGuiViewport* vp = ImGui::GetMainViewport();
    ImGui::SetNextWindowPos(ImVec2(vp->WorkPos.x + vp->WorkSize.x * 0.5f, vp->WorkPos.y + vp->WorkSize.y - 12),
                            ImGuiCond_Always, ImVec2(0.5f, 1));
    ImGui::Begin("##message", nullptr, ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize |
                                           ImGuiWindowFlags_NoFocusOnAppearing | ImGuiWindowFlags_NoInputs);
    ImGui::TextUnformatted(message.c_str());
    ImGui::End();
  }
  if (!show_panel) return;

  ImGui::SetNextWindowPos(ImVec2(10, 10), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(kPanelWidth, 0), ImGuiCond_Always);
  ImGui::Begin("Aloft", &show_panel, ImGuiWindowFlags_NoResize);
  ImGui::PushItemWidth(150);
  const Model& model = session->model();
  Simulation& sim = session->simulation();

  ImGui::TextColored(ImVec4(1.0f, 0.8f, 0.5f, 1), "%s", model.name.c_str());
  ImGui::TextDisabled("%s  (%d pieces, %.3g kg)", session->path().c_str(), model.count - 1, model.balance.total_mass);
  ImGui::Separator();

  // Playback and speed.
  const double fps = 1 / std::max(stats.frame_seconds, 1e-6);
  ImGui::Text("%.0f fps   real time x%.2f   t = %.2f s", fps, stats.realtime, sim.state().time);
  ImGui::TextDisabled("physics %.2f ms  wind %.2f ms  render %.1f ms", stats.physics * 1e3,
                      stats.wind * 1e3, stats.render * 1e3);
  if (ImGui::Button(session->paused ? "Play" : "Pause", ImVec2(70, 0))) session->paused = !session->paused;
  ImGui::SameLine();
  if (ImGui::Button("Step")) {
    session->paused = true;
    session->single_step();
  }
  ImGui::SameLine();
  if (ImGui::Button("Reset")) session->reset();
  ImGui::SameLine();
  ImGui::TextDisabled("(?) keys");
  if (ImGui::IsItemClicked()) show_help = true;
  float scale = static_cast<float>(session->time_scale);
  if (bounded_slider("time scale", scale, 1.0f / 64, 4.0f, "x%.3g", ImGuiSliderFlags_Logarithmic))
    session->time_scale = scale;

  if (ImGui::CollapsingHeader("Mobile")) {
    BuildSettings build = session->build_settings();
    const BalanceMode mode = build.balance.value_or(session->spec().balance.mode);
    if (ImGui::BeginCombo("balance", balance_name(mode))) {
      for (BalanceMode m : {BalanceMode::Mass, BalanceMode::Joints, BalanceMode::None})
        if (ImGui::Selectable(balance_name(m), m == mode)) {
          build.balance = m;
          session->rebuild(build);
        }
      ImGui::EndCombo();
    }
    float mass = static_cast<float>(model.balance.total_mass);
    ImGui::BeginDisabled(mode != BalanceMode::Mass);
    bounded_slider("total mass (kg)", mass, 0.05f, 50.0f, "%.3g", ImGuiSliderFlags_Logarithmic);
    if (ImGui::IsItemDeactivatedAfterEdit()) {
      build.total_mass = mass;
      session->rebuild(build);
    }
    ImGui::EndDisabled();
    float restitution = static_cast<float>(build.restitution.value_or(session->spec().contact.restitution));
    bounded_slider("restitution", restitution, 0.0f, 1.0f, "%.2f");
    if (ImGui::IsItemDeactivatedAfterEdit()) {
      build.restitution = restitution;
      session->rebuild(build);
    }
    float friction = static_cast<float>(build.friction.value_or(session->spec().contact.friction));
    bounded_slider("friction", friction, 0.0f, 2.0f, "%.2f");
    if (ImGui::IsItemDeactivatedAfterEdit()) {
      build.friction = friction;
      session->rebuild(build);
    }
    bool contact = build.contact_enabled.value_or(session->spec().contact.enabled);
    if (ImGui::Checkbox("collisions", &contact)) {
      build.contact_enabled = contact;
      session->rebuild(build);
    }
    DampingSpec damping = session->damping();
    float linear = static_cast<float>(damping.linear), angular = static_cast<float>(damping.angular);
    bool changed = bounded_slider("air damping (1/s)", linear, 0.0f, 2.0f, "%.3f", ImGuiSliderFlags_Logarithmic);
    changed |= bounded_slider("spin damping (1/s)", angular, 0.0f, 2.0f, "%.3f", ImGuiSliderFlags_Logarithmic);
    if (changed) session->set_damping(DampingSpec{linear, angular});
  }

#if ALOFT_HAVE_WIND
  if (ImGui::CollapsingHeader("Wind", ImGuiTreeNodeFlags_DefaultOpen)) {
    WindControl& w = session->wind_control;
    ImGui::Checkbox("wind", &w.enabled);
    ImGui::SameLine();
    if (ImGui::Button("Gust (G)")) session->gust();
    ImGui::SameLine();
    ImGui::BeginDisabled(w.follow_camera);
    if (ImGui::Button("From me")) w.follow_camera = true;
    ImGui::EndDisabled();
    float breeze = static_cast<float>(w.breeze);
    if (bounded_slider("breeze v0 (m/s)", breeze, 0.0f, static_cast<float>(kStrongestBreeze), "%.2f"))
      w.breeze = breeze;
    const double v0 = session->v0();
    ImGui::ProgressBar(static_cast<float>(std::min(v0 / kStrongestBreeze, 1.0)), ImVec2(-1, 0),
                       (std::to_string(static_cast<int>(std::lround(v0 * 100)) / 100.0).substr(0, 4) + " m/s at S0").c_str());
    float r0 = static_cast<float>(w.r0), l0 = static_cast<float>(w.l0);
    if (bounded_slider("r0 (m)", r0, 0.05f, 3.0f, "%.2f", ImGuiSliderFlags_Logarithmic)) w.r0 = r0;
    if (bounded_slider("l0 (m)", l0, 0.1f, 5.0f, "%.2f", ImGuiSliderFlags_Logarithmic)) w.l0 = l0;
    // alpha = rho l0^4 (docs/wind.md): from a hundredth of air's to water's (the files' rule, kDensestWind)
    // at this l0, so that the slider means the same at every l0 (MobileSession::update_wind keeps a set
    // alpha within water's when l0 shrinks).
    const double l0_4 = std::pow(w.l0, 4);
    const float alpha_lo = static_cast<float>(kAirDensity * l0_4 / 100);
    const float alpha_hi = static_cast<float>(largest_wind_alpha(w.l0));
    float alpha = static_cast<float>(session->wind() ? session->wind()->alpha() : kAirDensity * l0_4);
    if (bounded_slider("alpha (kg m)", alpha, alpha_lo, alpha_hi, "%.3g", ImGuiSliderFlags_Logarithmic))
      w.settings.alpha = alpha;
    ImGui::SameLine();
    if (ImGui::SmallButton("air")) w.settings.alpha = -1;
    float beta = static_cast<float>(w.settings.beta);
    if (bounded_slider("beta (turbulence)", beta, 0.0f, 2.0f, "%.2f")) w.settings.beta = beta;
    ImGui::Checkbox("cone (K)", &show_cone);
    ImGui::SameLine();
    ImGui::Checkbox("what it reaches (O)", &show_occlusion);
    ImGui::TextDisabled("ctrl + drag to aim it");
    draw_microphone_controls();
    const auto& file_winds = session->file_winds();
    if (!file_winds.empty()) {
      ImGui::Separator();
      ImGui::TextUnformatted("In the file (warm cones):");
      for (std::size_t i = 0; i < file_winds.size(); ++i) {
        ImGui::PushID(static_cast<int>(i));
        bool on = file_winds[i].enabled;
        if (ImGui::Checkbox(file_winds[i].source.name.c_str(), &on)) session->set_file_wind_enabled(i, on);
        ImGui::SameLine();
        ImGui::TextDisabled("%.2f m/s", session->file_wind_v0(i));
        ImGui::PopID();
      }
    }
  }
#endif

  if (sim.collisions() && ImGui::CollapsingHeader("Contacts", ImGuiTreeNodeFlags_DefaultOpen)) {
    // Which pieces knock together (contact_tally.hpp): the pairs touching at the last step, then those
    // that touched most often since the mobile was loaded or reset.
    constexpr std::size_t kShown = 6;
    const std::vector<ContactTally::Pair> pairs = session->contact_tally().pairs();
    std::size_t now = 0;
    for (const ContactTally::Pair& p : pairs) now += p.last == session->last_step_time();
    ImGui::Text("pairs touching now: %zu, so far: %zu", now, pairs.size());
    for (std::size_t k = 0; k < pairs.size() && k < kShown; ++k) {
      const ContactTally::Pair& p = pairs[k];
      const bool touching = p.last == session->last_step_time();
      ImGui::TextColored(touching ? ImVec4(1.0f, 0.55f, 0.4f, 1) : ImVec4(0.75f, 0.75f, 0.75f, 1), "%s - %s",
                         model.names[p.a].c_str(), model.names[p.b].c_str());
      ImGui::SameLine();
      ImGui::TextDisabled("%lld steps, from %.1f s", p.steps, p.first);
    }
    if (pairs.size() > kShown) ImGui::TextDisabled("... and %zu more", pairs.size() - kShown);
    if (ImGui::Button("Clear")) session->clear_contacts();
    ImGui::SameLine();
    ImGui::Checkbox("glow where they touch", &glow_touching);
  }

  if (ImGui::CollapsingHeader("View")) {
    ImGui::Checkbox("shadows (S)", &shadows);
    static const int kSamples[] = {0, 2, 4, 8};
    static const char* const kSampleNames[] = {"off", "2x", "4x", "8x"};
    int index = 0;
    for (int i = 0; i < 4; ++i)
      if (kSamples[i] == samples) index = i;
    if (ImGui::Combo("anti-aliasing", &index, kSampleNames, 4)) samples = kSamples[index];
    if (ImGui::Button("Reset camera (C)")) camera = framed_camera();
    ImGui::SameLine();
    if (ImGui::Button("Screenshot (P)")) screenshot_requested = true;
    ImGui::SameLine();
    if (ImGui::Button(recorder ? "Stop (V)" : "Record (V)")) toggle_recording();
    if (recorder) ImGui::TextColored(ImVec4(1, 0.3f, 0.3f, 1), "recording %s", recorder->path().c_str());
  }
  ImGui::PopItemWidth();
  ImGui::End();
}

}  // namespace aloft::view
