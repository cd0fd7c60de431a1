// One-Euro filter (Casiez, Roussel, Vogel, CHI 2012) per coordinate, a per-hand filter
// over all joints with prediction to display time, tracking-loss and re-acquisition.
#pragma once
#include "tracking/types.hpp"

namespace drape::tracking {

struct OneEuroParams {
  double min_cutoff = 1.0;  // Hz: cutoff at rest; lower = less jitter, more lag
  double beta = 2.0;        // s/m: cutoff grows by beta * |speed|; higher = less lag when moving
  double d_cutoff = 1.0;    // Hz: cutoff of the speed estimate
};

class OneEuro {
 public:
  explicit OneEuro(OneEuroParams p = {}) : p_(p) {}
  Vec3 filter(const Vec3& x, double t);
  void reset() { init_ = false; }
  const Vec3& value() const { return x_; }
  // Velocity for prediction: low-passed (d_cutoff) derivative of the raw input.
  const Vec3& velocity() const { return v_; }
  bool initialised() const { return init_; }
  // Restart from x keeping zero speed (used at re-acquisition).
  void reset_to(const Vec3& x, double t);

 private:
  OneEuroParams p_;
  bool init_ = false;
  double t_ = 0;
  Vec3 x_ = Vec3::Zero(), dx_ = Vec3::Zero(), raw_ = Vec3::Zero(), v_ = Vec3::Zero();
};

struct HandFilterParams {
  OneEuroParams euro;
  double lost_after = 0.25;       // s without a tracked frame -> hand marked lost
  double min_confidence = 0.3;    // frames below are treated as not tracked
  double reacquire_blend = 0.15;  // s: after loss, blend from last output to new data
  double max_prediction = 0.05;   // s: cap on extrapolation to display time
};

// Filters one hand: palm + joints; predict(t) extrapolates to display time.
class HandFilter {
 public:
  explicit HandFilter(HandFilterParams p = {});
  // Feed a raw frame; returns the filtered frame (tracked may be false).
  HandFrame update(const HandFrame& raw);
  // The latest filtered state extrapolated to display time t (<= max_prediction ahead).
  HandFrame predict(double t) const;
  bool lost() const { return !out_.tracked; }

 private:
  Vec3 blend(const Vec3& filtered, const Vec3& held, double t) const;
  HandFilterParams p_;
  OneEuro palm_;
  std::array<OneEuro, kJointCount> joints_;
  HandFrame out_;
  double last_tracked_ = -1e9;
  bool was_lost_ = true;
  double reacq_t_ = -1e9;
  Vec3 held_palm_ = Vec3::Zero();
  std::array<Vec3, kJointCount> held_joints_{};
};

}  // namespace drape::tracking
