// Calibration in the app (`drape run --calibrate` with an external hand source): four marked
// points in the stage (two on the form's front, two on the floor) are touched in turn; a point is
// taken when a palm dwells on it (tracking::GestureRecognizer's dwell: within 3 cm for 1 s), as
// the mean of the palm's unfiltered positions over the last 0.5 s in the tracker's own frame.
// After the fourth, tracking::calibrate gives the tracker-to-stage transform and its residual;
// a degenerate set (collinear, coincident) is refused with its reason and the points are taken
// again from the first. No file access here: the session saves the result.
#pragma once

#include <Eigen/Core>
#include <deque>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "tracking/calibration.hpp"
#include "tracking/gestures.hpp"

namespace drape::app {

struct CalibrationMarker {
  tracking::Vec3 stage;  // where it is drawn (m, stage space)
  const char* name;      // what the panel calls it
};

// The four marked points: the form's front at chest and hip height, the floor left and right in
// front of the form (not coplanar, so a rotation about any axis is determined).
const std::vector<CalibrationMarker>& calibration_markers();

class CalibrationMode {
 public:
  CalibrationMode();

  // What one frame's palms did: a point taken, the calibration computed or refused.
  struct Event {
    enum Kind { Taken, Computed, Refused } kind;
    int marker = 0;          // Taken: the marker's index
    tracking::Vec3 tracker;  // Taken: the palm in the tracker's frame
    std::string message;     // Refused: the reason (tracking::calibrate's error)
  };
  // `raw`: a palm frame as the source gave it; `filtered`: the same after the hand's filter
  // (both in the tracker's frame).
  std::vector<Event> update(const tracking::HandFrame& raw, const tracking::HandFrame& filtered);

  int current() const { return static_cast<int>(taken_.size()); }  // the marker to touch next
  bool done() const { return result_.has_value(); }
  const std::optional<tracking::Calibration>& result() const { return result_; }
  // The panel's guidance line ("touch marker 2 of 4 (the form's hip) and hold still 1 s").
  std::string guidance() const;

 private:
  tracking::GestureRecognizer dwell_;
  std::deque<std::pair<double, tracking::Vec3>> raw_[2];  // the last 0.5 s of each palm
  std::vector<tracking::Vec3> taken_;
  std::optional<tracking::Calibration> result_;
};

}  // namespace drape::app
