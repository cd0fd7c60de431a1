// The scenario that scripts the mock runtime: head track, hand tracks, controller inputs,
// audio cues, scripted events and when to end. Format: docs/xr.md.
#pragma once

#include <openxr/openxr.h>

#include <array>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace drape::mock {

// --- small pose math (OpenXR conventions: quaternion x,y,z,w; right-handed, y up) ---
XrQuaternionf quat_mul(const XrQuaternionf& a, const XrQuaternionf& b);
XrQuaternionf quat_conj(const XrQuaternionf& q);
XrQuaternionf quat_normalize(const XrQuaternionf& q);
XrQuaternionf quat_slerp(const XrQuaternionf& a, const XrQuaternionf& b, float t);
XrVector3f quat_rotate(const XrQuaternionf& q, const XrVector3f& v);
XrPosef pose_mul(const XrPosef& a, const XrPosef& b);  // a * b (b expressed in a)
XrPosef pose_inverse(const XrPosef& p);
XrPosef pose_identity();
XrPosef pose_lerp(const XrPosef& a, const XrPosef& b, float t);
XrVector3f add(XrVector3f a, XrVector3f b);
XrVector3f sub(XrVector3f a, XrVector3f b);
XrVector3f mul(XrVector3f a, float s);
float len(XrVector3f a);

constexpr int kHandJointCount = XR_HAND_JOINT_COUNT_EXT;  // 26

struct HandSample {
  bool tracked = false;
  std::array<XrPosef, kHandJointCount> joints{};
  std::array<float, kHandJointCount> radii{};
};

// A generated hand's shape: the thumb tip 5 mm under the middle, ring or little fingertip (the
// thumb's pinch with that finger), the fingers together (a flat hand), or pointing (the index
// finger out, the middle, ring and little fingers curled into the palm); open: as generated.
enum HandShape {
  kShapeOpen,
  kShapePinchMiddle,
  kShapePinchRing,
  kShapePinchLittle,
  kShapeTogether,
  kShapePoint
};

struct HandKey {
  double frame = 0;
  bool tracked = true;
  bool explicit_joints = false;
  XrPosef palm{};  // palm pose (generated mode)
  float pinch = 0.f;
  float fist = 0.f;                               // fingers curled into the palm (generated mode)
  HandShape shape = kShapeOpen;                   // (generated mode, not interpolated)
  std::array<XrPosef, kHandJointCount> joints{};  // explicit mode
};

struct ControllerKey {
  double frame = 0;
  bool tracked = true;
  XrPosef grip{};
  XrPosef aim{};
  std::map<std::string, std::array<float, 2>> inputs;  // "trigger/value" -> {v, 0}
};

struct PoseKey {
  double frame = 0;
  XrPosef pose{};
};

struct AudioCue {
  std::string wav;  // absolute path (resolved against the scenario file's directory)
  int64_t frame = 0;
  std::string text;  // optional: what is said (for logs/tests)
};

struct ScriptedEvent {
  int64_t frame = 0;
  std::string type;  // "session_loss" | "request_exit"
};

struct Scenario {
  std::string path;               // the file it came from ("" = built-in default)
  int64_t end_after_frames = -1;  // -1: never
  bool fast = false;
  std::string interaction_profile;  // "" = first suggested in preference order
  std::vector<PoseKey> head;
  std::vector<HandKey> hands[2];
  std::vector<ControllerKey> controllers[2];
  std::vector<AudioCue> audio;
  std::vector<ScriptedEvent> events;
  std::string write_frames_dir;
  int write_every = 1;

  // Sampling at a (fractional) frame index.
  XrPosef head_pose(double frame) const;
  HandSample hand(int hand, double frame) const;
  // Controller state: tracked, grip/aim poses and the input values (step for buttons,
  // linear for values and poses).
  bool controller(int hand, double frame, XrPosef* grip, XrPosef* aim,
                  std::map<std::string, std::array<float, 2>>* inputs) const;
};

// Loads and validates a scenario file. On error returns false and sets *error to a message
// naming the file and the field.
bool load_scenario(const std::string& path, Scenario* out, std::string* error);

// The 26 joints of a hand (0 = left, 1 = right) from a palm pose and a pinch amount in [0, 1]:
// the thumb-tip to index-tip distance is lerp(kOpenPinchGap, kClosedPinchGap, pinch). `fist` in
// [0, 1] curls the middle, ring and little fingers (and the index, unless pinching) into the
// palm; 0 leaves the hand as without it.
constexpr float kOpenPinchGap = 0.085f;
constexpr float kClosedPinchGap = 0.005f;
// shape: see HandShape.
void generate_hand(int hand, const XrPosef& palm, float pinch,
                   std::array<XrPosef, kHandJointCount>* joints,
                   std::array<float, kHandJointCount>* radii, float fist = 0.f,
                   HandShape shape = kShapeOpen);
// "open", "pinch_middle", "pinch_ring", "pinch_little", "together"; false if unknown.
bool hand_shape_from_name(const std::string& name, HandShape* shape);

// Minimal PNG writer (8-bit RGBA, zlib "stored" blocks). Returns false on I/O error.
bool write_png_rgba(const std::string& path, int width, int height, const unsigned char* rgba);

}  // namespace drape::mock
