// Calibration in the app (see calibration_mode.hpp).
#include "xr_app/app/calibration_mode.hpp"

#include <cstdio>
#include <filesystem>

#include "xr_app/app/draping_session.hpp"

namespace drape::app {

namespace {
constexpr double kAverageOver = 0.5;  // s of unfiltered palm positions averaged into a point
}  // namespace

const std::vector<CalibrationMarker>& calibration_markers() {
  static const std::vector<CalibrationMarker> markers = {
      {tracking::Vec3(0.0, 1.30, 0.16), "the form's chest"},
      {tracking::Vec3(0.12, 0.95, 0.16), "the form's right hip"},
      {tracking::Vec3(-0.30, 0.0, 0.40), "the floor, front left"},
      {tracking::Vec3(0.30, 0.0, 0.40), "the floor, front right"},
  };
  return markers;
}

CalibrationMode::CalibrationMode() = default;

std::vector<CalibrationMode::Event> CalibrationMode::update(const tracking::HandFrame& raw,
                                                            const tracking::HandFrame& filtered) {
  std::vector<Event> events;
  if (done()) return events;
  auto& hist = raw_[static_cast<int>(raw.hand)];
  if (!raw.tracked) {
    hist.clear();
  } else {
    hist.emplace_back(raw.time, raw.palm.position);
    while (!hist.empty() && raw.time - hist.front().first > kAverageOver) hist.pop_front();
  }
  std::vector<tracking::Trigger> trig;
  dwell_.update(filtered, trig);
  for (const auto& t : trig) {
    if (t.command != "dwell" || hist.empty()) continue;
    tracking::Vec3 mean = tracking::Vec3::Zero();
    for (const auto& [time, p] : hist) mean += p;
    mean /= static_cast<double>(hist.size());
    events.push_back({Event::Taken, current(), mean, {}});
    taken_.push_back(mean);
    if (taken_.size() < calibration_markers().size()) continue;
    std::vector<tracking::Vec3> stage;
    for (const auto& m : calibration_markers()) stage.push_back(m.stage);
    std::string error;
    result_ = tracking::calibrate(taken_, stage, &error);
    if (result_) {
      events.push_back({Event::Computed, 0, {}, {}});
      break;
    }
    events.push_back({Event::Refused, 0, {}, error});
    taken_.clear();  // again from the first marker
  }
  return events;
}

std::string CalibrationMode::guidance() const {
  if (done()) return "done";
  const auto& markers = calibration_markers();
  const int i = current();
  return "touch marker " + std::to_string(i + 1) + " of " + std::to_string(markers.size()) + " (" +
         markers[i].name + ") with one palm and hold it still for 1 s";
}

namespace {
std::string mm(double metres) {
  char b[32];
  std::snprintf(b, sizeof b, "%.1f mm", metres * 1e3);
  return b;
}

std::string point(const tracking::Vec3& p) {
  char b[96];
  std::snprintf(b, sizeof b, "(%.4f, %.4f, %.4f)", p.x(), p.y(), p.z());
  return b;
}
}  // namespace

// --calibrate: the markers drawn, the first one asked for.
void DrapingSession::open_calibration_mode() {
  ext_->calibrating = std::make_unique<CalibrationMode>();
  rep_.note("calibration: touch the " + std::to_string(calibration_markers().size()) +
            " marked points in turn; the result goes to " + opt_.calibration_save);
  feedback_.set_status("calibration", ext_->calibrating->guidance());
  markers_.clear();
  for (size_t i = 0; i < calibration_markers().size(); ++i)
    markers_.push_back({calibration_markers()[i].stage.cast<float>(),
                        i == 0 ? std::array<float, 3>{1.0f, 0.2f, 0.8f}
                               : std::array<float, 3>{0.45f, 0.45f, 0.5f}});
}

// One palm frame while calibrating: the points taken, then the result computed, shown, logged
// and saved (or refused: the reason, nothing saved, the markers again from the first).
void DrapingSession::calibration_frame(const tracking::HandFrame& raw,
                                       const tracking::HandFrame& filtered) {
  CalibrationMode& cm = *ext_->calibrating;
  const auto events = cm.update(raw, filtered);
  for (const auto& e : events) {
    if (e.kind == CalibrationMode::Event::Taken) {
      rep_.note("calibration: marker " + std::to_string(e.marker + 1) + " (" +
                calibration_markers()[e.marker].name + ") taken at " + point(e.tracker) +
                " in the tracker's frame");
    } else if (e.kind == CalibrationMode::Event::Refused) {
      rep_.note("calibration: refused: " + e.message +
                "; nothing saved; touch the markers again from the first");
      feedback_.set_status("calibration", "refused (" + e.message + "), again from marker 1");
    } else {
      const tracking::Calibration& c = *cm.result();
      ext_->calibration = c;
      const std::string residual =
          "residual rms " + mm(c.rms_residual) + ", max " + mm(c.max_residual);
      std::string error;
      std::error_code ec;
      std::filesystem::create_directories(
          std::filesystem::path(opt_.calibration_save).parent_path(), ec);
      const bool saved = tracking::save_calibration(c, opt_.calibration_save, &error);
      rep_.note("calibration: " + residual + " over " + std::to_string(c.pairs) + " points; " +
                (saved ? "saved to " + opt_.calibration_save : "not saved: " + error));
      feedback_.set_status("calibration", residual + (saved ? ", saved" : ", NOT saved: " + error));
    }
  }
  if (events.empty()) return;
  if (cm.done()) {
    markers_.clear();
    return;
  }
  if (events.back().kind != CalibrationMode::Event::Refused)
    feedback_.set_status("calibration", cm.guidance());
  for (size_t i = 0; i < markers_.size(); ++i)
    markers_[i].colour = static_cast<int>(i) < cm.current() ? std::array<float, 3>{0.2f, 0.9f, 0.3f}
                         : static_cast<int>(i) == cm.current()
                             ? std::array<float, 3>{1.0f, 0.2f, 0.8f}
                             : std::array<float, 3>{0.45f, 0.45f, 0.5f};
}

}  // namespace drape::app
