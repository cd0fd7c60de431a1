// Gestures -> triggers: pinch (thumb tip - index tip distance with hysteresis and a minimum
// duration), grab (fist), open palm; dwell and push for palm-only sources; controller buttons.
#pragma once
#include <deque>
#include <string>
#include <vector>

#include "tracking/types.hpp"

namespace drape::tracking {

struct GestureParams {
  double pinch_enter = 0.025;   // m: thumb-index tip distance to start a pinch
  double pinch_leave = 0.040;   // m: distance to end it (hysteresis)
  double min_duration = 0.08;   // s: a state must hold this long before a trigger fires
  double grab_curl = 0.07;      // m: mean fingertip-to-palm distance below = fist
  double open_extend = 0.14;    // m: mean fingertip-to-palm distance above = open palm
  double dwell_radius = 0.03;   // m: palm-only: hand stays within this radius ...
  double dwell_time = 1.0;      // s: ... this long -> "dwell"
  double push_distance = 0.12;  // m: palm-only: forward (toward -z of the source) motion ...
  double push_time = 0.35;      // s: ... within this time -> "push"
  Vec3 push_axis = Vec3(0, 0, -1);
};

// A boolean state with hysteresis already applied, debounced by a minimum duration.
class Debounced {
 public:
  // Returns +1 when the debounced state turns on, -1 when it turns off, 0 otherwise.
  int update(bool raw, double t, double min_duration);
  bool on() const { return on_; }

 private:
  bool on_ = false, cand_ = false;
  double since_ = 0;
};

class GestureRecognizer {
 public:
  explicit GestureRecognizer(GestureParams p = {}) : p_(p) {}
  // Feed one filtered frame of one hand; appends triggers ("pinch", "grab", "open_palm",
  // "dwell", "push") with begin=true/false.
  void update(const HandFrame& f, std::vector<Trigger>& out);
  bool pinching(Hand h) const { return st_[static_cast<int>(h)].pinch.on(); }

 private:
  struct State {
    bool pinch_raw = false;
    Debounced pinch, grab, open;
    std::deque<std::pair<double, Vec3>> history;  // palm positions for dwell/push
    bool dwell_fired = false;
    double push_block_until = -1;
  };
  void emit(int edge, const char* name, const HandFrame& f, std::vector<Trigger>& out);
  GestureParams p_;
  State st_[2];
};

// Controller buttons -> triggers: edges of named buttons ("trigger", "grip", "a", "b", ...).
class ButtonMapper {
 public:
  void update(Hand h, const std::string& button, bool pressed, double t, std::vector<Trigger>& out);

 private:
  std::vector<std::pair<std::string, bool>> state_[2];
};

}  // namespace drape::tracking
