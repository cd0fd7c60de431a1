// Calibration in the app (see calibration_mode.hpp).
#include "xr_app/app/calibration_mode.hpp"

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

}  // namespace drape::app
