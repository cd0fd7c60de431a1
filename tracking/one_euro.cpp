#include "tracking/one_euro.hpp"

#include <algorithm>
#include <cmath>

namespace drape::tracking {

const char* hand_name(Hand h) {
  return h == Hand::Left ? "left" : "right";
}

namespace {
double alpha(double cutoff, double dt) {
  const double tau = 1.0 / (2.0 * M_PI * cutoff);
  return 1.0 / (1.0 + tau / dt);
}
}  // namespace

void OneEuro::reset_to(const Vec3& x, double t) {
  init_ = true;
  t_ = t;
  x_ = x;
  raw_ = x;
  dx_.setZero();
  v_.setZero();
}

Vec3 OneEuro::filter(const Vec3& x, double t) {
  if (!init_ || !x_.allFinite()) {
    reset_to(x, t);
    return x_;
  }
  double dt = t - t_;
  if (!(dt > 1e-6)) dt = 1e-3;  // duplicate/out-of-order timestamp: tiny step
  // Speed estimate as in the paper: from the previous filtered value.
  const Vec3 dx = (x - x_) / dt;
  const double ad = alpha(p_.d_cutoff, dt);
  dx_ += ad * (dx - dx_);
  v_ += ad * ((x - raw_) / dt - v_);
  raw_ = x;
  const double cutoff = p_.min_cutoff + p_.beta * dx_.norm();
  x_ += alpha(cutoff, dt) * (x - x_);
  t_ = t;
  return x_;
}

HandFilter::HandFilter(HandFilterParams p) : p_(p), palm_(p.euro) {
  joints_.fill(OneEuro(p.euro));
}

Vec3 HandFilter::blend(const Vec3& filtered, const Vec3& held, double t) const {
  const double s = p_.reacquire_blend > 0 ? (t - reacq_t_) / p_.reacquire_blend : 1.0;
  if (s >= 1.0) return filtered;
  const double w = std::clamp(s, 0.0, 1.0);
  const double smooth = w * w * (3 - 2 * w);
  return held + smooth * (filtered - held);
}

HandFrame HandFilter::update(const HandFrame& raw) {
  const bool ok =
      raw.tracked && raw.confidence >= p_.min_confidence && raw.palm.position.allFinite();
  out_.hand = raw.hand;
  out_.time = raw.time;
  if (!ok) {
    if (raw.time - last_tracked_ > p_.lost_after) {
      out_.tracked = false;
      out_.confidence = 0;
      was_lost_ = true;
    }
    return out_;
  }
  if (was_lost_) {
    // Re-acquisition: restart filters at the new data but blend the output from where
    // the hand was last shown, so nothing jumps.
    const bool had_output = last_tracked_ > -1e8;
    held_palm_ = had_output ? out_.palm.position : raw.palm.position;
    held_joints_ = had_output ? out_.joints : raw.joints;
    palm_.reset_to(raw.palm.position, raw.time);
    for (int j = 0; j < kJointCount; ++j) joints_[j].reset_to(raw.joints[j], raw.time);
    reacq_t_ = had_output ? raw.time : -1e9;
    was_lost_ = false;
  }
  last_tracked_ = raw.time;
  out_.tracked = true;
  out_.confidence = raw.confidence;
  out_.palm.orientation = raw.palm.orientation;
  out_.palm.position = blend(palm_.filter(raw.palm.position, raw.time), held_palm_, raw.time);
  out_.has_joints = raw.has_joints;
  if (raw.has_joints) {
    for (int j = 0; j < kJointCount; ++j)
      out_.joints[j] = blend(joints_[j].filter(raw.joints[j], raw.time), held_joints_[j], raw.time);
  }
  return out_;
}

HandFrame HandFilter::predict(double t) const {
  HandFrame f = out_;
  if (!f.tracked) return f;
  const double dt = std::clamp(t - out_.time, 0.0, p_.max_prediction);
  f.time = out_.time + dt;
  f.palm.position += palm_.velocity() * dt;
  if (f.has_joints)
    for (int j = 0; j < kJointCount; ++j) f.joints[j] += joints_[j].velocity() * dt;
  return f;
}

}  // namespace drape::tracking
