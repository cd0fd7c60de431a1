// Scenario loading and sampling, the generated hand skeleton, pose math and a tiny PNG writer.
#include "xr_app/mock_runtime/scenario.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>

namespace drape::mock {

// ---------------------------------------------------------------- pose math
XrQuaternionf quat_mul(const XrQuaternionf& a, const XrQuaternionf& b) {
  return {
      a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y, a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
      a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w, a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z};
}
XrQuaternionf quat_conj(const XrQuaternionf& q) {
  return {-q.x, -q.y, -q.z, q.w};
}
XrQuaternionf quat_normalize(const XrQuaternionf& q) {
  float n = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
  if (n < 1e-12f) return {0, 0, 0, 1};
  return {q.x / n, q.y / n, q.z / n, q.w / n};
}
XrQuaternionf quat_slerp(const XrQuaternionf& a, XrQuaternionf const& b0, float t) {
  XrQuaternionf b = b0;
  float d = a.x * b.x + a.y * b.y + a.z * b.z + a.w * b.w;
  if (d < 0) {
    b = {-b.x, -b.y, -b.z, -b.w};
    d = -d;
  }
  if (d > 0.9995f) {
    return quat_normalize({a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t, a.z + (b.z - a.z) * t,
                           a.w + (b.w - a.w) * t});
  }
  float th = std::acos(d), s = std::sin(th);
  float wa = std::sin((1 - t) * th) / s, wb = std::sin(t * th) / s;
  return {wa * a.x + wb * b.x, wa * a.y + wb * b.y, wa * a.z + wb * b.z, wa * a.w + wb * b.w};
}
XrVector3f quat_rotate(const XrQuaternionf& q, const XrVector3f& v) {
  XrQuaternionf p{v.x, v.y, v.z, 0};
  XrQuaternionf r = quat_mul(quat_mul(q, p), quat_conj(q));
  return {r.x, r.y, r.z};
}
XrPosef pose_mul(const XrPosef& a, const XrPosef& b) {
  XrPosef r;
  r.orientation = quat_normalize(quat_mul(a.orientation, b.orientation));
  XrVector3f t = quat_rotate(a.orientation, b.position);
  r.position = {a.position.x + t.x, a.position.y + t.y, a.position.z + t.z};
  return r;
}
XrPosef pose_inverse(const XrPosef& p) {
  XrPosef r;
  r.orientation = quat_conj(p.orientation);
  XrVector3f t = quat_rotate(r.orientation, p.position);
  r.position = {-t.x, -t.y, -t.z};
  return r;
}
XrPosef pose_identity() {
  return XrPosef{{0, 0, 0, 1}, {0, 0, 0}};
}
XrPosef pose_lerp(const XrPosef& a, const XrPosef& b, float t) {
  XrPosef r;
  r.orientation = quat_slerp(a.orientation, b.orientation, t);
  r.position = {a.position.x + (b.position.x - a.position.x) * t,
                a.position.y + (b.position.y - a.position.y) * t,
                a.position.z + (b.position.z - a.position.z) * t};
  return r;
}

// ---------------------------------------------------------------- hand skeleton
namespace {
// Right hand, palm frame: +x towards the little finger, +y out of the back of the hand,
// fingers along -z (the XR_EXT_hand_tracking joint convention).
constexpr float kRightHand[kHandJointCount][3] = {
    {0, 0, 0},       // palm
    {0, 0, 0.045f},  // wrist
    {-0.025f, -0.01f, 0.03f},
    {-0.045f, -0.015f, 0.005f},
    {-0.055f, -0.02f, -0.025f},
    {-0.06f, -0.022f, -0.045f},  // thumb
    {-0.02f, 0, 0.035f},
    {-0.022f, 0, -0.03f},
    {-0.023f, 0, -0.07f},
    {-0.024f, 0, -0.095f},
    {-0.024f, 0, -0.115f},  // index
    {0, 0, 0.035f},
    {0, 0, -0.035f},
    {0, 0, -0.08f},
    {0, 0, -0.108f},
    {0, 0, -0.13f},  // middle
    {0.018f, 0, 0.035f},
    {0.02f, 0, -0.03f},
    {0.021f, 0, -0.07f},
    {0.022f, 0, -0.095f},
    {0.022f, 0, -0.115f},  // ring
    {0.03f, 0, 0.035f},
    {0.038f, 0, -0.02f},
    {0.04f, 0, -0.05f},
    {0.041f, 0, -0.068f},
    {0.042f, 0, -0.085f},  // little
};
XrVector3f v3(const float* p) {
  return {p[0], p[1], p[2]};
}
}  // namespace

XrVector3f add(XrVector3f a, XrVector3f b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
XrVector3f sub(XrVector3f a, XrVector3f b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
XrVector3f mul(XrVector3f a, float s) {
  return {a.x * s, a.y * s, a.z * s};
}
float len(XrVector3f a) {
  return std::sqrt(a.x * a.x + a.y * a.y + a.z * a.z);
}

bool hand_shape_from_name(const std::string& name, HandShape* shape) {
  const char* names[] = {"open", "pinch_middle", "pinch_ring", "pinch_little", "together", "point"};
  for (int i = 0; i < 6; ++i)
    if (name == names[i]) return *shape = static_cast<HandShape>(i), true;
  return false;
}

namespace {
// The thumb's tip 5 mm under another fingertip (palm side), its distal and proximal joints
// dragged along; or the fingers' distal joints drawn together toward the middle finger.
void shape_hand(HandShape shape, XrVector3f* p) {
  if (shape >= kShapePinchMiddle && shape <= kShapePinchLittle) {
    const int tips[] = {XR_HAND_JOINT_MIDDLE_TIP_EXT, XR_HAND_JOINT_RING_TIP_EXT,
                        XR_HAND_JOINT_LITTLE_TIP_EXT};
    const int T = XR_HAND_JOINT_THUMB_TIP_EXT;
    const XrVector3f target = add(p[tips[shape - kShapePinchMiddle]], {0, -0.005f, 0});
    const XrVector3f d = sub(target, p[T]);
    p[T] = target;
    p[XR_HAND_JOINT_THUMB_DISTAL_EXT] = add(p[XR_HAND_JOINT_THUMB_DISTAL_EXT], mul(d, 0.6f));
    p[XR_HAND_JOINT_THUMB_PROXIMAL_EXT] = add(p[XR_HAND_JOINT_THUMB_PROXIMAL_EXT], mul(d, 0.25f));
  }
  if (shape == kShapePoint)  // as a fist's curl, index finger left out
    for (int f0 : {XR_HAND_JOINT_MIDDLE_INTERMEDIATE_EXT, XR_HAND_JOINT_RING_INTERMEDIATE_EXT,
                   XR_HAND_JOINT_LITTLE_INTERMEDIATE_EXT}) {
      const XrVector3f curl{p[f0].x, -0.03f, -0.01f};
      const float amount[] = {0.4f, 0.75f, 0.9f};
      for (int k = 0; k < 3; ++k) p[f0 + k] = add(p[f0 + k], mul(sub(curl, p[f0 + k]), amount[k]));
    }
  if (shape == kShapeTogether) {
    for (int f0 : {XR_HAND_JOINT_INDEX_INTERMEDIATE_EXT, XR_HAND_JOINT_RING_INTERMEDIATE_EXT,
                   XR_HAND_JOINT_LITTLE_INTERMEDIATE_EXT})
      for (int k = 0; k < 3; ++k) p[f0 + k].x *= 0.55f;
  }
}
}  // namespace

void generate_hand(int hand, const XrPosef& palm, float pinch,
                   std::array<XrPosef, kHandJointCount>* joints,
                   std::array<float, kHandJointCount>* radii, float fist, HandShape shape) {
  pinch = std::clamp(pinch, 0.f, 1.f);
  XrVector3f p[kHandJointCount];
  for (int j = 0; j < kHandJointCount; ++j) p[j] = v3(kRightHand[j]);
  // Open tips placed exactly kOpenPinchGap apart around their midpoint; pinching shrinks the
  // gap linearly to kClosedPinchGap and drags the distal joints along.
  const int T = XR_HAND_JOINT_THUMB_TIP_EXT, I = XR_HAND_JOINT_INDEX_TIP_EXT;
  XrVector3f m = mul(add(p[T], p[I]), 0.5f);
  XrVector3f u = sub(p[I], p[T]);
  u = mul(u, 1.f / len(u));
  float gap = kOpenPinchGap + (kClosedPinchGap - kOpenPinchGap) * pinch;
  XrVector3f t_new = sub(m, mul(u, gap * 0.5f)), i_new = add(m, mul(u, gap * 0.5f));
  XrVector3f t_open = sub(m, mul(u, kOpenPinchGap * 0.5f)),
             i_open = add(m, mul(u, kOpenPinchGap * 0.5f));
  XrVector3f dt = sub(t_new, p[T]), di = sub(i_new, p[I]);
  XrVector3f dt_rest = sub(t_new, t_open), di_rest = sub(i_new, i_open);
  p[T] = t_new;
  p[I] = i_new;
  (void)dt;
  (void)di;
  p[XR_HAND_JOINT_THUMB_DISTAL_EXT] = add(p[XR_HAND_JOINT_THUMB_DISTAL_EXT], mul(dt_rest, 0.6f));
  p[XR_HAND_JOINT_THUMB_PROXIMAL_EXT] =
      add(p[XR_HAND_JOINT_THUMB_PROXIMAL_EXT], mul(dt_rest, 0.25f));
  p[XR_HAND_JOINT_INDEX_DISTAL_EXT] = add(p[XR_HAND_JOINT_INDEX_DISTAL_EXT], mul(di_rest, 0.6f));
  p[XR_HAND_JOINT_INDEX_INTERMEDIATE_EXT] =
      add(p[XR_HAND_JOINT_INDEX_INTERMEDIATE_EXT], mul(di_rest, 0.3f));
  fist = std::clamp(fist, 0.f, 1.f);
  if (fist > 0.f) {
    // Each finger's intermediate, distal and tip joints move toward a point under the palm.
    const int first[] = {pinch > 0.5f ? -1 : XR_HAND_JOINT_INDEX_INTERMEDIATE_EXT,
                         XR_HAND_JOINT_MIDDLE_INTERMEDIATE_EXT, XR_HAND_JOINT_RING_INTERMEDIATE_EXT,
                         XR_HAND_JOINT_LITTLE_INTERMEDIATE_EXT};
    const float amount[] = {0.4f, 0.75f, 0.9f};
    for (int f0 : first) {
      if (f0 < 0) continue;
      XrVector3f curl{p[f0].x, -0.03f, -0.01f};
      for (int k = 0; k < 3; ++k)
        p[f0 + k] = add(p[f0 + k], mul(sub(curl, p[f0 + k]), amount[k] * fist));
    }
  }
  shape_hand(shape, p);
  for (int j = 0; j < kHandJointCount; ++j) {
    XrVector3f q = p[j];
    if (hand == 0) q.x = -q.x;  // left hand: mirror image
    XrPosef local{{0, 0, 0, 1}, q};
    (*joints)[j] = pose_mul(palm, local);
    float r = 0.01f;
    if (j == XR_HAND_JOINT_PALM_EXT || j == XR_HAND_JOINT_WRIST_EXT) r = 0.02f;
    if (j == XR_HAND_JOINT_THUMB_TIP_EXT || j == XR_HAND_JOINT_INDEX_TIP_EXT ||
        j == XR_HAND_JOINT_MIDDLE_TIP_EXT || j == XR_HAND_JOINT_RING_TIP_EXT ||
        j == XR_HAND_JOINT_LITTLE_TIP_EXT)
      r = 0.008f;
    (*radii)[j] = r;
  }
}

// ---------------------------------------------------------------- sampling
namespace {
template <class K>
void bracket(const std::vector<K>& keys, double frame, size_t* a, size_t* b, float* t) {
  // keys sorted by frame, non-empty
  if (frame <= keys.front().frame) {
    *a = *b = 0;
    *t = 0;
    return;
  }
  if (frame >= keys.back().frame) {
    *a = *b = keys.size() - 1;
    *t = 0;
    return;
  }
  size_t hi = 1;
  while (keys[hi].frame < frame) ++hi;
  if (keys[hi].frame == frame) {
    // On a key: that key alone, so its clicks (not interpolated) arrive in the same frame as its
    // values (which a bracket ending at it would interpolate to it at t = 1).
    *a = *b = hi;
    *t = 0;
    return;
  }
  *a = hi - 1;
  *b = hi;
  double span = keys[hi].frame - keys[hi - 1].frame;
  *t = span > 0 ? static_cast<float>((frame - keys[hi - 1].frame) / span) : 0.f;
}
bool interpolated_input(const std::string& name) {
  auto ends = [&](const char* s) {
    std::string x(s);
    return name.size() >= x.size() && name.compare(name.size() - x.size(), x.size(), x) == 0;
  };
  return ends("/value") || ends("/force") || ends("thumbstick") || ends("trackpad") || ends("/x") ||
         ends("/y");
}
}  // namespace

XrPosef Scenario::head_pose(double frame) const {
  if (head.empty()) return XrPosef{{0, 0, 0, 1}, {0, 1.6f, 1.0f}};
  size_t a, b;
  float t;
  bracket(head, frame, &a, &b, &t);
  return pose_lerp(head[a].pose, head[b].pose, t);
}

HandSample Scenario::hand(int h, double frame) const {
  HandSample s;
  const auto& keys = hands[h];
  if (keys.empty()) return s;
  size_t a, b;
  float t;
  bracket(keys, frame, &a, &b, &t);
  const HandKey& ka = keys[a];
  const HandKey& kb = keys[b];
  if (!ka.tracked || (t > 0 && !kb.tracked)) return s;
  s.tracked = true;
  std::array<XrPosef, kHandJointCount> ja, jb;
  std::array<float, kHandJointCount> ra, rb;
  auto joints_of = [&](const HandKey& k, std::array<XrPosef, kHandJointCount>* j,
                       std::array<float, kHandJointCount>* r) {
    if (k.explicit_joints) {
      *j = k.joints;
      XrPosef dummy = pose_identity();
      std::array<XrPosef, kHandJointCount> tmp;
      generate_hand(h, dummy, 0, &tmp, r);
    } else {
      generate_hand(h, k.palm, k.pinch, j, r, k.fist, k.shape);
    }
  };
  if (!ka.explicit_joints && !kb.explicit_joints) {
    // Interpolate palm and pinch, then generate: keeps the pinch gap exactly linear.
    XrPosef palm = pose_lerp(ka.palm, kb.palm, t);
    generate_hand(h, palm, ka.pinch + (kb.pinch - ka.pinch) * t, &s.joints, &s.radii,
                  ka.fist + (kb.fist - ka.fist) * t, ka.shape);
    return s;
  }
  joints_of(ka, &ja, &ra);
  joints_of(kb, &jb, &rb);
  for (int j = 0; j < kHandJointCount; ++j) {
    s.joints[j] = pose_lerp(ja[j], jb[j], t);
    s.radii[j] = ra[j];
  }
  return s;
}

bool Scenario::controller(int h, double frame, XrPosef* grip, XrPosef* aim,
                          std::map<std::string, std::array<float, 2>>* inputs) const {
  const auto& keys = controllers[h];
  inputs->clear();
  if (keys.empty()) {
    float x = h == 0 ? -0.2f : 0.2f;
    *grip = XrPosef{{0, 0, 0, 1}, {x, 1.3f, 0.6f}};
    *aim = *grip;
    // A hand the scenario tracks as a hand and not as a controller is bare: its controller is
    // set down (untracked), as a runtime reports it while it tracks the hand itself.
    return hands[h].empty();
  }
  size_t a, b;
  float t;
  bracket(keys, frame, &a, &b, &t);
  const ControllerKey& ka = keys[a];
  const ControllerKey& kb = keys[b];
  *grip = pose_lerp(ka.grip, kb.grip, t);
  *aim = pose_lerp(ka.aim, kb.aim, t);
  for (const auto& [name, v] : ka.inputs) {
    auto it = kb.inputs.find(name);
    if (interpolated_input(name) && it != kb.inputs.end()) {
      (*inputs)[name] = {v[0] + (it->second[0] - v[0]) * t, v[1] + (it->second[1] - v[1]) * t};
    } else {
      (*inputs)[name] = v;
    }
  }
  return ka.tracked;
}

// ---------------------------------------------------------------- loading
namespace {
using nlohmann::json;

struct FieldError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

float num(const json& j, const std::string& field) {
  if (!j.is_number()) throw FieldError(field + ": expected a number");
  double v = j.get<double>();
  if (!std::isfinite(v)) throw FieldError(field + ": not finite");
  return static_cast<float>(v);
}

XrVector3f vec3(const json& j, const std::string& field) {
  if (!j.is_array() || j.size() != 3) throw FieldError(field + ": expected [x, y, z]");
  return {num(j[0], field + "[0]"), num(j[1], field + "[1]"), num(j[2], field + "[2]")};
}

XrPosef pose(const json& j, const std::string& field) {
  if (!j.is_object())
    throw FieldError(field + ": expected {\"position\": [..], \"orientation\": [..]}");
  XrPosef p = pose_identity();
  if (!j.contains("position")) throw FieldError(field + ".position: missing");
  p.position = vec3(j["position"], field + ".position");
  if (j.contains("orientation")) {
    const json& o = j["orientation"];
    if (!o.is_array() || o.size() != 4)
      throw FieldError(field + ".orientation: expected a quaternion [x, y, z, w]");
    XrQuaternionf q{num(o[0], field + ".orientation[0]"), num(o[1], field + ".orientation[1]"),
                    num(o[2], field + ".orientation[2]"), num(o[3], field + ".orientation[3]")};
    float n = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
    if (n < 1e-6f) throw FieldError(field + ".orientation: zero quaternion");
    p.orientation = quat_normalize(q);
  }
  return p;
}

// A generated hand's "pinch" and "fist" (0..1) and "shape" (see HandShape).
void parse_hand_shape(const json& kj, const std::string& f, HandKey* k) {
  if (kj.contains("pinch")) {
    k->pinch = num(kj["pinch"], f + ".pinch");
    if (k->pinch < 0 || k->pinch > 1) throw FieldError(f + ".pinch: must be in [0, 1]");
  }
  if (kj.contains("fist")) {
    k->fist = num(kj["fist"], f + ".fist");
    if (k->fist < 0 || k->fist > 1) throw FieldError(f + ".fist: must be in [0, 1]");
  }
  if (kj.contains("shape") &&
      (!kj["shape"].is_string() || !hand_shape_from_name(kj["shape"], &k->shape)))
    throw FieldError(f +
                     ".shape: expected one of open, pinch_middle, pinch_ring, pinch_little, "
                     "together, point");
}

double frame_of(const json& j, const std::string& field, double prev) {
  if (!j.contains("frame")) throw FieldError(field + ".frame: missing");
  double f = num(j["frame"], field + ".frame");
  if (f < 0) throw FieldError(field + ".frame: negative");
  if (f < prev) throw FieldError(field + ".frame: keyframes must be in increasing frame order");
  return f;
}

const json& array_field(const json& j, const char* name, const std::string& field) {
  const json& a = j[name];
  if (!a.is_array()) throw FieldError(field + ": expected an array of keyframes");
  return a;
}

int hand_index(const std::string& key, const std::string& field) {
  if (key == "left") return 0;
  if (key == "right") return 1;
  throw FieldError(field + "." + key + ": expected \"left\" or \"right\"");
}

void parse(const json& root, const std::filesystem::path& dir, Scenario* s) {
  if (!root.is_object()) throw FieldError("top level: expected an object");
  static const char* known[] = {"end_after_frames",
                                "fast",
                                "interaction_profile",
                                "head",
                                "hands",
                                "controllers",
                                "audio",
                                "events",
                                "write_frames",
                                "description",
                                "name"};
  for (auto it = root.begin(); it != root.end(); ++it) {
    bool ok = false;
    for (const char* k : known) ok = ok || it.key() == k;
    if (!ok) throw FieldError(it.key() + ": unknown field");
  }
  if (root.contains("end_after_frames")) {
    const json& e = root["end_after_frames"];
    if (!e.is_number_integer() || e.get<int64_t>() < 1)
      throw FieldError("end_after_frames: expected a positive integer");
    s->end_after_frames = e.get<int64_t>();
  }
  if (root.contains("fast")) {
    if (!root["fast"].is_boolean()) throw FieldError("fast: expected true or false");
    s->fast = root["fast"].get<bool>();
  }
  if (root.contains("interaction_profile")) {
    if (!root["interaction_profile"].is_string())
      throw FieldError("interaction_profile: expected a path string");
    s->interaction_profile = root["interaction_profile"].get<std::string>();
  }
  if (root.contains("head")) {
    double prev = 0;
    const json& a = array_field(root, "head", "head");
    for (size_t i = 0; i < a.size(); ++i) {
      std::string f = "head[" + std::to_string(i) + "]";
      PoseKey k;
      k.frame = prev = frame_of(a[i], f, prev);
      k.pose = pose(a[i], f);
      s->head.push_back(k);
    }
  }
  if (root.contains("hands")) {
    const json& h = root["hands"];
    if (!h.is_object()) throw FieldError("hands: expected {\"left\": [..], \"right\": [..]}");
    for (auto it = h.begin(); it != h.end(); ++it) {
      int hi = hand_index(it.key(), "hands");
      std::string base = "hands." + it.key();
      if (!it.value().is_array()) throw FieldError(base + ": expected an array of keyframes");
      double prev = 0;
      for (size_t i = 0; i < it.value().size(); ++i) {
        const json& kj = it.value()[i];
        std::string f = base + "[" + std::to_string(i) + "]";
        HandKey k;
        k.frame = prev = frame_of(kj, f, prev);
        if (kj.contains("tracked")) {
          if (!kj["tracked"].is_boolean()) throw FieldError(f + ".tracked: expected a boolean");
          k.tracked = kj["tracked"].get<bool>();
        }
        if (kj.contains("joints")) {
          const json& js = kj["joints"];
          if (!js.is_array() || js.size() != kHandJointCount)
            throw FieldError(f + ".joints: expected 26 joints");
          k.explicit_joints = true;
          for (int j = 0; j < kHandJointCount; ++j) {
            std::string jf = f + ".joints[" + std::to_string(j) + "]";
            if (js[j].is_array()) {
              k.joints[j] = XrPosef{{0, 0, 0, 1}, vec3(js[j], jf)};
            } else {
              k.joints[j] = pose(js[j], jf);
            }
          }
        } else if (k.tracked) {
          if (!kj.contains("palm"))
            throw FieldError(f + ": needs \"palm\" (+ \"pinch\") or \"joints\"");
          k.palm = pose(kj["palm"], f + ".palm");
          parse_hand_shape(kj, f, &k);
        }
        s->hands[hi].push_back(k);
      }
    }
  }
  if (root.contains("controllers")) {
    const json& c = root["controllers"];
    if (!c.is_object()) throw FieldError("controllers: expected {\"left\": [..], \"right\": [..]}");
    for (auto it = c.begin(); it != c.end(); ++it) {
      int hi = hand_index(it.key(), "controllers");
      std::string base = "controllers." + it.key();
      if (!it.value().is_array()) throw FieldError(base + ": expected an array of keyframes");
      double prev = 0;
      for (size_t i = 0; i < it.value().size(); ++i) {
        const json& kj = it.value()[i];
        std::string f = base + "[" + std::to_string(i) + "]";
        ControllerKey k;
        k.frame = prev = frame_of(kj, f, prev);
        if (kj.contains("tracked")) {
          if (!kj["tracked"].is_boolean()) throw FieldError(f + ".tracked: expected a boolean");
          k.tracked = kj["tracked"].get<bool>();
        }
        float x = hi == 0 ? -0.2f : 0.2f;
        k.grip = kj.contains("grip") ? pose(kj["grip"], f + ".grip")
                                     : XrPosef{{0, 0, 0, 1}, {x, 1.3f, 0.6f}};
        k.aim = kj.contains("aim") ? pose(kj["aim"], f + ".aim") : k.grip;
        if (kj.contains("inputs")) {
          const json& in = kj["inputs"];
          if (!in.is_object()) throw FieldError(f + ".inputs: expected an object");
          for (auto ii = in.begin(); ii != in.end(); ++ii) {
            std::string nf = f + ".inputs." + ii.key();
            const json& v = ii.value();
            if (v.is_boolean()) {
              k.inputs[ii.key()] = {v.get<bool>() ? 1.f : 0.f, 0.f};
            } else if (v.is_number()) {
              k.inputs[ii.key()] = {num(v, nf), 0.f};
            } else if (v.is_array() && v.size() == 2) {
              k.inputs[ii.key()] = {num(v[0], nf + "[0]"), num(v[1], nf + "[1]")};
            } else {
              throw FieldError(nf + ": expected a boolean, a number or [x, y]");
            }
          }
        }
        s->controllers[hi].push_back(k);
      }
    }
  }
  if (root.contains("audio")) {
    const json& a = array_field(root, "audio", "audio");
    for (size_t i = 0; i < a.size(); ++i) {
      std::string f = "audio[" + std::to_string(i) + "]";
      AudioCue cue;
      if (!a[i].is_object() || !a[i].contains("wav") || !a[i]["wav"].is_string())
        throw FieldError(f + ".wav: missing (a WAV file path)");
      std::filesystem::path p = a[i]["wav"].get<std::string>();
      if (p.is_relative()) p = dir / p;
      cue.wav = p.lexically_normal().string();
      if (!a[i].contains("frame") || !a[i]["frame"].is_number_integer() ||
          a[i]["frame"].get<int64_t>() < 0)
        throw FieldError(f + ".frame: expected a non-negative integer");
      cue.frame = a[i]["frame"].get<int64_t>();
      if (a[i].contains("text") && a[i]["text"].is_string()) cue.text = a[i]["text"];
      s->audio.push_back(cue);
    }
  }
  if (root.contains("events")) {
    const json& a = array_field(root, "events", "events");
    for (size_t i = 0; i < a.size(); ++i) {
      std::string f = "events[" + std::to_string(i) + "]";
      ScriptedEvent e;
      if (!a[i].is_object() || !a[i].contains("type") || !a[i]["type"].is_string())
        throw FieldError(f + ".type: missing");
      e.type = a[i]["type"].get<std::string>();
      if (e.type != "session_loss" && e.type != "request_exit")
        throw FieldError(f + ".type: expected \"session_loss\" or \"request_exit\"");
      if (!a[i].contains("frame") || !a[i]["frame"].is_number_integer() ||
          a[i]["frame"].get<int64_t>() < 0)
        throw FieldError(f + ".frame: expected a non-negative integer");
      e.frame = a[i]["frame"].get<int64_t>();
      s->events.push_back(e);
    }
  }
  if (root.contains("write_frames")) {
    const json& w = root["write_frames"];
    if (!w.is_object() || !w.contains("dir") || !w["dir"].is_string())
      throw FieldError("write_frames.dir: missing");
    std::filesystem::path p = w["dir"].get<std::string>();
    if (p.is_relative()) p = std::filesystem::current_path() / p;
    s->write_frames_dir = p.string();
    if (w.contains("every")) {
      if (!w["every"].is_number_integer() || w["every"].get<int>() < 1)
        throw FieldError("write_frames.every: expected a positive integer");
      s->write_every = w["every"].get<int>();
    }
  }
}
}  // namespace

bool load_scenario(const std::string& path, Scenario* out, std::string* error) {
  std::ifstream in(path);
  if (!in) {
    *error = path + ": cannot open scenario file";
    return false;
  }
  Scenario s;
  s.path = path;
  try {
    json root = json::parse(in);
    parse(root, std::filesystem::absolute(path).parent_path(), &s);
  } catch (const json::parse_error& e) {
    *error = path + ": invalid JSON: " + e.what();
    return false;
  } catch (const FieldError& e) {
    *error = path + ": " + e.what();
    return false;
  } catch (const std::exception& e) {
    *error = path + ": " + e.what();
    return false;
  }
  *out = std::move(s);
  return true;
}

// ---------------------------------------------------------------- PNG
namespace {
uint32_t crc32(const unsigned char* d, size_t n, uint32_t crc = 0) {
  static uint32_t table[256];
  static bool init = false;
  if (!init) {
    for (uint32_t i = 0; i < 256; ++i) {
      uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      table[i] = c;
    }
    init = true;
  }
  crc = ~crc;
  for (size_t i = 0; i < n; ++i) crc = table[(crc ^ d[i]) & 0xFF] ^ (crc >> 8);
  return ~crc;
}
void put32(std::vector<unsigned char>* v, uint32_t x) {
  v->push_back(static_cast<unsigned char>(x >> 24));
  v->push_back(static_cast<unsigned char>(x >> 16));
  v->push_back(static_cast<unsigned char>(x >> 8));
  v->push_back(static_cast<unsigned char>(x));
}
void chunk(std::vector<unsigned char>* out, const char* type, const std::vector<unsigned char>& d) {
  put32(out, static_cast<uint32_t>(d.size()));
  std::vector<unsigned char> td(type, type + 4);
  td.insert(td.end(), d.begin(), d.end());
  out->insert(out->end(), td.begin(), td.end());
  put32(out, crc32(td.data(), td.size()));
}
}  // namespace

bool write_png_rgba(const std::string& path, int width, int height, const unsigned char* rgba) {
  std::vector<unsigned char> raw;
  raw.reserve(static_cast<size_t>(height) * (width * 4 + 1));
  for (int y = 0; y < height; ++y) {
    raw.push_back(0);
    raw.insert(raw.end(), rgba + static_cast<size_t>(y) * width * 4,
               rgba + static_cast<size_t>(y + 1) * width * 4);
  }
  std::vector<unsigned char> z = {0x78, 0x01};
  size_t pos = 0;
  do {
    size_t n = std::min<size_t>(65535, raw.size() - pos);
    bool last = pos + n == raw.size();
    z.push_back(last ? 1 : 0);
    z.push_back(static_cast<unsigned char>(n & 0xFF));
    z.push_back(static_cast<unsigned char>(n >> 8));
    z.push_back(static_cast<unsigned char>(~n & 0xFF));
    z.push_back(static_cast<unsigned char>((~n >> 8) & 0xFF));
    z.insert(z.end(), raw.begin() + pos, raw.begin() + pos + n);
    pos += n;
  } while (pos < raw.size());
  uint32_t a = 1, b = 0;
  for (unsigned char c : raw) {
    a = (a + c) % 65521;
    b = (b + a) % 65521;
  }
  put32(&z, (b << 16) | a);
  std::vector<unsigned char> out = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  std::vector<unsigned char> ihdr;
  put32(&ihdr, static_cast<uint32_t>(width));
  put32(&ihdr, static_cast<uint32_t>(height));
  ihdr.insert(ihdr.end(), {8, 6, 0, 0, 0});
  chunk(&out, "IHDR", ihdr);
  chunk(&out, "IDAT", z);
  chunk(&out, "IEND", {});
  FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return false;
  bool ok = std::fwrite(out.data(), 1, out.size(), f) == out.size();
  ok = std::fclose(f) == 0 && ok;
  return ok;
}

}  // namespace drape::mock
