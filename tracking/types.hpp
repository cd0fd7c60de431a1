// Hand frames and trigger events: the data every tracking source produces.
#pragma once
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <string>

namespace drape::tracking {

using Vec3 = Eigen::Vector3d;
using Quat = Eigen::Quaterniond;

// Joint order of XR_EXT_hand_tracking (XrHandJointEXT).
enum class Joint : int {
  Palm = 0,
  Wrist,
  ThumbMetacarpal,
  ThumbProximal,
  ThumbDistal,
  ThumbTip,
  IndexMetacarpal,
  IndexProximal,
  IndexIntermediate,
  IndexDistal,
  IndexTip,
  MiddleMetacarpal,
  MiddleProximal,
  MiddleIntermediate,
  MiddleDistal,
  MiddleTip,
  RingMetacarpal,
  RingProximal,
  RingIntermediate,
  RingDistal,
  RingTip,
  LittleMetacarpal,
  LittleProximal,
  LittleIntermediate,
  LittleDistal,
  LittleTip
};
inline constexpr int kJointCount = 26;

enum class Hand : int { Left = 0, Right = 1 };

struct Pose {
  Vec3 position = Vec3::Zero();
  Quat orientation = Quat::Identity();
};

// One hand at one instant. Positions in metres, in the source's frame (stage after
// calibration). `joints` is valid only if has_joints.
struct HandFrame {
  Hand hand = Hand::Right;
  double time = 0.0;  // seconds, monotonic clock of the producer
  bool tracked = false;
  double confidence = 0.0;  // 0..1
  Pose palm;
  bool has_joints = false;
  std::array<Vec3, kJointCount> joints{};
};

// A command event: "begin pinch" etc. The command map decides what it does.
struct Trigger {
  std::string command;  // e.g. "pinch", "release", "cut", "button.a"
  std::string source;   // "gesture", "voice", "controller", "key"
  double time = 0.0;
  Hand hand = Hand::Right;
  bool begin = true;  // true: gesture/button entered; false: left (released)
};

const char* hand_name(Hand h);

}  // namespace drape::tracking
