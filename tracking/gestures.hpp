// Gestures -> triggers. From XR_EXT_hand_tracking joints: the thumb's pinches with each finger
// ("pinch" = index, "pinch_middle", "pinch_ring", "pinch_little"; tip distance with hysteresis,
// the finger clearly the thumb's nearest), the fist ("grab"), pointing with the index finger
// ("point": the other three curled), the flat hand with the fingers
// together and the palm down ("flat"), the open hand with the palm up ("palm_up") and the open
// palm thrust forward ("push"); every held one debounced by a minimum duration, and a resting
// open hand fires nothing. From palm-only sources (Kinect, UDP): "dwell" and "palm_push", and
// from both palms together: "hands_together" (held), "hands_apart" and "both_push".
// Controller buttons: ButtonMapper.
#pragma once
#include <deque>
#include <string>
#include <vector>

#include "tracking/types.hpp"

namespace drape::tracking {

struct GestureParams {
  double pinch_enter = 0.025;   // m: thumb-finger tip distance to start a pinch
  double pinch_leave = 0.040;   // m: distance to end it (hysteresis)
  double pinch_nearest = 0.6;   // a pinch starts only below this fraction of the next finger's
  double min_duration = 0.08;   // s: a state must hold this long before a trigger fires
  double grab_curl = 0.07;      // m: mean fingertip-to-palm distance below = fist
  double extend_curl = 0.10;    // m: mean fingertip-to-palm distance above = fingers extended
  double together = 0.85;       // fingertips' spread across the palm below this fraction of
                                // the knuckles' = fingers together
  double facing_cos = 0.75;     // palm normal within ~40 degrees of up / down / its push
  double dwell_radius = 0.03;   // m: palm-only: hand stays within this radius ...
  double dwell_time = 1.0;      // s: ... this long -> "dwell"
  double push_distance = 0.12;  // m: forward motion (palm-only: along push_axis; joints: along
  double push_time = 0.35;      // s: the palm's normal) within this time -> "push"
  Vec3 push_axis = Vec3(0, 0, -1);
  // Palm-only, both hands (the triggers carry the right hand: its palm is the operation's point):
  double together_enter = 0.10;    // m: palms closer than this ...
  double together_leave = 0.15;    // m: ... (apart again beyond this) ...
  double together_hold = 0.3;      // s: ... this long -> "hands_together" (begin; end when apart)
  double apart_from = 0.25;        // m: palms from closer than this ...
  double apart_to = 0.55;          // m: ... to farther than this ...
  double apart_time = 0.5;         // s: ... within this -> "hands_apart" (not within
  double apart_quiet = 1.0;        // s: this after "hands_together" ended)
  double both_push_window = 0.15;  // s: both palms pushed within this -> "both_push" (and no
                                   // "palm_push": while both hands are seen, a palm push
                                   // waits this long for the other's)
  double pair_stale = 0.2;         // s: the other palm's newest sample older than this: one hand
  Vec3 up = Vec3(0, 1, 0);         // the source's up (OpenXR reference spaces: +y)
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

// The shape of a hand from its joints (exposed for tests and the help text).
struct HandShape {
  double tip_distance[4] = {};  // thumb tip to the index, middle, ring, little tips
  double curl = 0;              // mean fingertip-to-palm distance
  double index_reach = 0;       // the index fingertip's distance from the palm
  double others_curl = 0;       // mean middle, ring and little fingertip-to-palm distance
  double spread = 1;            // the fingertips' extent across the palm / the knuckles'
  Vec3 normal = Vec3::Zero();   // out of the palm (the palm joint's -y)
};
HandShape hand_shape(const HandFrame& f);

class GestureRecognizer {
 public:
  explicit GestureRecognizer(GestureParams p = {}) : p_(p) {}
  // Feed one filtered frame of one hand; appends triggers with begin=true/false.
  void update(const HandFrame& f, std::vector<Trigger>& out);
  bool pinching(Hand h) const { return st_[static_cast<int>(h)].pinch[0].on(); }

 private:
  struct State {
    int pinch_finger = -1;  // the finger the thumb touches (0 index .. 3 little), -1 none
    Debounced pinch[4], grab, point, flat, palm_up;
    std::deque<std::pair<double, Vec3>> history;  // palm positions for dwell/push
    bool dwell_fired = false;
    double push_block_until = -1;
  };
  void update_joints(const HandFrame& f, State& s, std::vector<Trigger>& out);
  void update_pinch_finger(const HandShape& shape, State& s) const;
  bool joint_push(const HandFrame& f, const HandShape& shape, State& s) const;
  void update_palm_only(const HandFrame& f, State& s, std::vector<Trigger>& out);
  void palm_pushed(const HandFrame& f, std::vector<Trigger>& out);
  void update_two_hands(const HandFrame& f, std::vector<Trigger>& out);
  void flush_pushes(double t, std::vector<Trigger>& out);
  bool other_palm_seen(const HandFrame& f) const;
  void lose(const HandFrame& f, State& s, std::vector<Trigger>& out);
  void emit(int edge, const char* name, const HandFrame& f, std::vector<Trigger>& out);
  GestureParams p_;
  State st_[2];
  // Both palms (palm-only): the together state, when it last ended, and each hand's palm push
  // waiting for the other's (time < 0: none).
  Debounced together_;
  double together_ended_ = -1e9;
  bool palms_near_ = false;  // the palms within together_leave (no dwell then)
  double pending_push_[2] = {-1, -1};
};

// Controller buttons -> triggers: edges of named buttons ("trigger", "grip", "a", "b", ...).
class ButtonMapper {
 public:
  void update(Hand h, const std::string& button, bool pressed, double t, std::vector<Trigger>& out);

 private:
  std::vector<std::pair<std::string, bool>> state_[2];
};

}  // namespace drape::tracking
