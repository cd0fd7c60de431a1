#include "sim/solvers/xpbd/xpbd_rest.hpp"

#include <algorithm>

namespace drape::sim::xpbd {

RestScheduler::~RestScheduler() = default;

void RestScheduler::reset(int pieces, std::vector<int> piece_of) {
  num_pieces_ = pieces;
  piece_of_ = std::move(piece_of);
  rest_.assign(num_pieces_, 0);
  scale_.assign(num_pieces_, 1.0);
  slow_.assign(num_pieces_, 0);
  frozen_.assign(num_pieces_, 0);
  awake_.assign(num_pieces_, 0);
  motion_.assign(num_pieces_, PieceMotion{});
  fixed_prev_.assign(piece_of_.size(), 0);
  full_.assign(num_pieces_, 0);
  coarse_done_.assign(num_pieces_, 0);
  finish_.assign(num_pieces_, 0);
}

void RestScheduler::save(ByteWriter& o) const {
  o.i32(num_pieces_);
  o.i32(frozen_count_);
  o.u8(masses_dirty_ ? 1 : 0);
  o.array(piece_of_.data(), piece_of_.size());
  o.array(rest_.data(), rest_.size());
  o.array(frozen_.data(), frozen_.size());
  o.array(awake_.data(), awake_.size());
  o.array(scale_.data(), scale_.size());
  o.array(slow_.data(), slow_.size());
  o.array(full_.data(), full_.size());
  o.array(fixed_prev_.data(), fixed_prev_.size());
  o.array(reinterpret_cast<const double*>(motion_.data()), motion_.size(), 4);
  o.array(group_.data(), group_.size());
  o.array(coarse_done_.data(), coarse_done_.size());
  std::vector<int> finish = finish_;
  for (int& f : finish)
    if (f == kFinishing) f = 0;  // the job is not saved: it starts again
  o.array(finish.data(), finish.size());
  o.u8(finisher_ ? 1 : 0);
  if (finisher_) {
    const auto& a = finisher_->anchors();
    o.array(reinterpret_cast<const double*>(a.data()), a.size(), 3);
  }
}

bool RestScheduler::restore(ByteReader& in) {
  const int pieces = in.i32();
  frozen_count_ = in.i32();
  masses_dirty_ = in.u8() != 0;
  std::vector<int> piece_of;
  in.array<int>(piece_of);
  if (!in.ok || pieces != num_pieces_ || piece_of != piece_of_) return false;
  in.array<int>(rest_);
  in.array<uint8_t>(frozen_);
  in.array<uint8_t>(awake_);
  in.array<double>(scale_);
  in.array<int>(slow_);
  in.array<int>(full_);
  in.array<uint8_t>(fixed_prev_);
  in.array<double>(motion_, 4);
  in.array<int>(group_);
  in.array<int>(coarse_done_);
  in.array<int>(finish_);
  const size_t np = static_cast<size_t>(num_pieces_);
  for (const size_t s : {rest_.size(), frozen_.size(), awake_.size(), scale_.size(), slow_.size(),
                         full_.size(), motion_.size(), coarse_done_.size(), finish_.size()})
    if (s != np) return false;
  if (fixed_prev_.size() != piece_of_.size() || frozen_count_ < 0) return false;
  for (int g : group_)
    if (g < -1 || g >= num_pieces_) return false;
  for (int f : finish_)
    if (f < -1) return false;
  if (!all_finite(scale_.data(), scale_.size()) ||
      !all_finite(reinterpret_cast<const double*>(motion_.data()), 4 * motion_.size()))
    return false;
  for (double sc : scale_)
    if (sc < 1) return false;  // an inertia scale: 1 (own mass) or more
  finisher_.reset();
  if (in.u8() != 0) {
    std::vector<Vec3> anchors;
    in.array<double>(anchors, 3);
    if (!all_finite(reinterpret_cast<const double*>(anchors.data()), 3 * anchors.size()))
      return false;
    finisher_ = std::make_unique<EquilibriumFinisher>();
    finisher_->set_anchors(std::move(anchors));
  }
  return in.ok;
}

void RestScheduler::forget() {
  finisher_.reset();
  group_.clear();
  frozen_count_ = 0;
  masses_dirty_ = true;
}

double RestScheduler::settle_scale() const {
  double m = 1.0;
  for (double s : scale_) m = std::max(m, s);
  return m;
}

void RestScheduler::unsettle(int piece) {
  masses_dirty_ = true;
  scale_[piece] = 1.0;
  full_[piece] = 0;
  slow_[piece] = 0;
  coarse_done_[piece] = 0;
  finish_[piece] = 0;
}

void RestScheduler::skip_rest_of_self_touching(const Cloth& cloth,
                                               const std::vector<SelfContact>& pairs) {
  const auto& tris = cloth.topo.triangles;
  auto skip = [&](int v) {
    const int p = piece_of_[v];
    coarse_done_[p] = std::max(coarse_done_[p], opt_.coarse_frames);
    finish_[p] = -1;
  };
  for (const SelfContact& c : pairs) {
    skip(c.vertex);
    for (const int v : tris[c.triangle]) skip(v);
  }
}

void RestScheduler::thaw(Cloth& cloth, ThreadPool* pool) {
  auto& S = cloth.state;
  auto clear = [&](int b, int e, int) {
    for (int i = b; i < e; ++i) S.flags[i] &= static_cast<uint8_t>(~kFlagFrozen);
  };
  if (pool)
    pool->parallel_for(cloth.num_vertices(), clear);
  else
    clear(0, cloth.num_vertices(), 0);
  std::fill(frozen_.begin(), frozen_.end(), 0);
  frozen_count_ = 0;
}

bool RestScheduler::any_frozen() const {
  bool any = false;
  for (int p = 0; p < num_pieces_; ++p) any = any || frozen_[p];
  return any;
}

bool RestScheduler::wake(Cloth& cloth, const ClothEnergy& energy) {
  auto& S = cloth.state;
  const int n = cloth.num_vertices();
  std::fill(awake_.begin(), awake_.end(), 0);
  for (int i = 0; i < n; ++i) {
    const int p = piece_of_[i];
    if (!frozen_[p] || awake_[p]) continue;
    bool go;
    if (!cloth.is_free(i))
      go = (S.x[i] - S.x_prev[i]).squaredNorm() > 1e-18;  // a fixed vertex was moved
    else if (!(S.flags[i] & kFlagFrozen))
      go = true;  // released, or freed by a command
    else {
      const int ci = energy.contact_of(i);
      // Deeper than 0.1 mm inside a fresh contact plane: an object entered the shell. (A
      // sleeping vertex rests on the plane it was last projected to; a fresh plane from the
      // same surface can sit a few um off it, which must not wake the piece.) A piece that fell
      // asleep while settled crept along the form with stale planes and can rest ~0.3 mm inside
      // a fresh one: it wakes only on the settling exit's 1 mm push (woken at once, a 64^2
      // drape took its own mass back and sagged 45 mm).
      const double depth = scale_[p] > 1.0 ? 1e-3 : 1e-4;
      go = ci >= 0 && energy.contacts()[ci].n.dot(S.x[i] - energy.contacts()[ci].p) < -depth;
    }
    if (go) awake_[p] = 1;
  }
  bool all_frozen = true;
  for (int p = 0; p < num_pieces_; ++p) {
    if (awake_[p]) {
      frozen_[p] = 0;
      rest_[p] = 0;
      unsettle(p);
    }
    all_frozen = all_frozen && frozen_[p];
  }
  frozen_count_ = 0;
  for (int i = 0; i < n; ++i) {
    if (!frozen_[piece_of_[i]]) {
      S.flags[i] &= static_cast<uint8_t>(~kFlagFrozen);
    } else if (S.flags[i] & kFlagFrozen) {
      ++frozen_count_;
      S.x_prev[i] = S.x[i];
    }
  }
  return all_frozen;
}

void RestScheduler::check_fixed(const Cloth& cloth, ThreadPool* pool) {
  if (!opt_.settle) {
    std::fill(scale_.begin(), scale_.end(), 1.0);
    return;
  }
  const auto& S = cloth.state;
  // Per pool thread and piece: whether a vertex of that piece ends its settling (applied after
  // the loop: unsettle() writes the piece's state).
  const int threads = pool ? pool->size() : 1;
  unsettle_mark_.assign(static_cast<size_t>(threads) * num_pieces_, 0);
  auto check = [&](int b, int e, int wk) {
    char* mark = unsettle_mark_.data() + static_cast<size_t>(wk) * num_pieces_;
    for (int i = b; i < e; ++i) {
      const bool fixed = !cloth.is_free(i);
      if (scale_[piece_of_[i]] > 1.0 &&
          ((fixed && (S.x[i] - S.x_prev[i]).squaredNorm() > 1e-18) || (fixed_prev_[i] && !fixed)))
        mark[piece_of_[i]] = 1;
      fixed_prev_[i] = fixed ? 1 : 0;
    }
  };
  if (pool)
    pool->parallel_for(cloth.num_vertices(), check);
  else
    check(0, cloth.num_vertices(), 0);
  for (int wk = 0; wk < threads; ++wk)
    for (int p = 0; p < num_pieces_; ++p)
      if (unsettle_mark_[static_cast<size_t>(wk) * num_pieces_ + p]) unsettle(p);
}

void RestScheduler::unsettle_pushed(const std::vector<Vec3>& x, const ClothEnergy& energy) {
  if (!opt_.settle || settle_scale() <= 1.0) return;
  // (The contacts are listed in vertex order.)
  for (const Contact& c : energy.contacts()) {
    const int i = c.vertex;
    if (scale_[piece_of_[i]] > 1.0 && c.n.dot(x[i] - c.p) < -kUnsettleDepth) unsettle(piece_of_[i]);
  }
}

// Per piece, once per substep: the largest free-vertex speed (settling may start when all are
// below settle_speed; a piece is awake while one is above freeze_speed) and the mass-weighted RMS
// speed, plain (faster than settle_exit_speed: settling ends) and with each vertex capped at
// settle_speed (a settled piece's rest test). Not the largest speed for the exit: a contact
// re-projection moves a single sliding vertex by ~0.2 mm in one substep, 0.2 m/s, which would
// end the settling of a piece at rest. The exit speed is well above the drape's own motion while
// its bias is released (~0.1-0.2 m/s RMS at 128^2). Summed in registers over each run of
// vertices of one piece (a piece's vertices are mostly contiguous), not through memory vertex
// by vertex.
void RestScheduler::sum_motion(const double* w, const std::vector<Vec3>& v,
                               const std::vector<double>& mass) {
  std::fill(motion_.begin(), motion_.end(), PieceMotion{});
  const double slow2 = opt_.settle_speed * opt_.settle_speed;
  const int n = static_cast<int>(piece_of_.size());
  int cur = -1;
  PieceMotion acc;
  auto flush = [&] {
    if (cur < 0) return;
    PieceMotion& pm = motion_[cur];
    pm.max_v2 = std::max(pm.max_v2, acc.max_v2);
    pm.mv2 += acc.mv2;
    pm.mv2_capped += acc.mv2_capped;
    pm.m += acc.m;
  };
  for (int i = 0; i < n; ++i) {
    if (!(w[i] > 0)) continue;
    if (piece_of_[i] != cur) {
      flush();
      cur = piece_of_[i];
      acc = PieceMotion{};
    }
    const double v2 = v[i].squaredNorm(), m = mass[i];
    acc.max_v2 = std::max(acc.max_v2, v2);
    acc.mv2 += m * v2;
    acc.mv2_capped += m * std::min(v2, slow2);
    acc.m += m;
  }
  flush();
}

void RestScheduler::sum_motion(
    const std::vector<std::vector<std::pair<int, PieceMotion>>>& block_runs) {
  std::fill(motion_.begin(), motion_.end(), PieceMotion{});
  // The sweep's sums per vertex block, added in block order.
  for (const auto& runs : block_runs)
    for (const auto& [piece, acc] : runs) {
      PieceMotion& pm = motion_[piece];
      pm.max_v2 = std::max(pm.max_v2, acc.max_v2);
      pm.mv2 += acc.mv2;
      pm.mv2_capped += acc.mv2_capped;
      pm.m += acc.m;
    }
}

void RestScheduler::settle_pieces(bool hold) {
  if (!opt_.settle) return;
  const double exit2 = opt_.settle_exit_speed * opt_.settle_exit_speed;
  for (int p = 0; p < num_pieces_; ++p) {
    if (frozen_[p]) continue;
    const PieceMotion& pm = motion_[p];
    if (scale_[p] > 1.0 || slow_[p] >= opt_.settle_steps) {
      if (pm.m > 0 && pm.mv2 > exit2 * pm.m) {
        unsettle(p);
      } else if (scale_[p] == 1.0 ||
                 (scale_[p] < opt_.settle_mass_scale && ++slow_[p] >= opt_.settle_grow_steps)) {
        // Start or grow; w changes, the bending inverses are rebuilt once for it.
        masses_dirty_ = true;
        scale_[p] =
            std::min(std::max(opt_.settle_growth, 1.0 + 1e-9) * scale_[p], opt_.settle_mass_scale);
        slow_[p] = 0;
      }
    } else {
      if (pm.max_v2 < opt_.settle_speed * opt_.settle_speed)
        ++slow_[p];
      else if (!hold)
        slow_[p] = 0;
    }
  }
}

void RestScheduler::freeze_pieces(Cloth& cloth, int s, bool hold) {
  if (!opt_.freeze) return;
  auto& S = cloth.state;
  const int n = cloth.num_vertices();
  // A piece rests when all its free vertices are slow; after freeze_steps substeps it sleeps.
  const double v2 = opt_.freeze_speed * opt_.freeze_speed;
  for (int p = 0; p < num_pieces_; ++p) {
    if (frozen_[p]) continue;
    const PieceMotion& pm = motion_[p];
    bool moving = pm.max_v2 >= v2;
    // A fully settled piece rests on its RMS speed, each vertex's speed capped at settle_speed
    // (single sliding vertices re-projected onto the form jump ~0.2 m/s for one substep), and
    // sleeps anyway after settle_sleep_steps substeps at the full scale: a settled 128^2 drape
    // can creep along the frictionless form at ~2 mm/s RMS for good (it settled only after
    // every vertex had been slower than settle_speed, so no flap is still swinging).
    bool settled_long = false;
    if (opt_.settle && scale_[p] >= opt_.settle_mass_scale) {
      settled_long = ++full_[p] >= opt_.settle_sleep_steps;
      if (moving && pm.m > 0 && pm.mv2_capped < v2 * pm.m) moving = false;
    }
    if (!moving)
      ++rest_[p];
    else if (!hold)
      rest_[p] = 0;
    if (rest_[p] >= opt_.freeze_steps || settled_long) {
      frozen_[p] = 1;
      masses_dirty_ = true;
    }
  }
  // (Once per frame, and in a substep in which a piece fell asleep: nothing else changes the
  // flags between substeps.)
  if (s == 0 || masses_dirty_) {
    frozen_count_ = 0;
    for (int i = 0; i < n; ++i)
      if (frozen_[piece_of_[i]] && cloth.is_free(i)) {
        S.flags[i] |= kFlagFrozen;
        S.v[i].setZero();
        ++frozen_count_;
      }
  }
}

void RestScheduler::coarse_step(Cloth& cloth, const SceneObjects& scene, ClothEnergy& energy) {
  if (opt_.coarse_factor <= 0 || !opt_.settle) return;
  // A piece is due when it is awake, at the full scale and not yet corrected this episode.
  auto due = [&](int p) {
    return !frozen_[p] && scale_[p] >= opt_.settle_mass_scale &&
           coarse_done_[p] < opt_.coarse_frames;
  };
  bool any = false;
  for (int p = 0; p < num_pieces_ && !any; ++p) any = due(p);
  if (!any) return;
  auto& S = cloth.state;
  const int n = cloth.num_vertices();
  group_.resize(n);
  for (int i = 0; i < n; ++i) group_[i] = cloth.is_free(i) && due(piece_of_[i]) ? piece_of_[i] : -1;
  if (!coarse_) coarse_ = std::make_unique<CoarseCorrection>();
  coarse_->options() = opt_.coarse;
  coarse_->options().factor = opt_.coarse_factor;
  if (scene.friction > 0) {
    energy.set_friction(scene.friction, 1e-4, S.x);
    energy.lag_friction_load(S.x, S.mass);
  }
  coarse_last_ = coarse_->apply(cloth, energy, group_, S.x);
  energy.clear_friction();
  coarse_ms_ += coarse_last_.total_ms;
  // Counted whether or not a step was taken (a piece the correction cannot improve is not tried
  // again until it settles anew).
  for (int p = 0; p < num_pieces_; ++p)
    if (due(p)) ++coarse_done_[p];
  if (coarse_last_.applied) {
    ++coarse_count_;
    for (int i = 0; i < n; ++i)
      if (group_[i] >= 0) S.v[i].setZero();
  }
}

void RestScheduler::finish_sleeping(Cloth& cloth, const SceneObjects& scene, ThreadPool* pool) {
  if (!opt_.finish || !opt_.freeze) return;
  if (opt_.finish_thread) return finish_on_thread(cloth, scene);
  bool any = false, fresh = false;
  for (int p = 0; p < num_pieces_; ++p)
    if (frozen_[p] && finish_[p] >= 0) {
      any = true;
      fresh = fresh || finish_[p] == 0;
    }
  if (!any) return;
  if (!finisher_) finisher_ = std::make_unique<EquilibriumFinisher>();
  finisher_->options() = opt_.finisher;
  if (fresh) {  // friction anchored where a piece fell asleep
    sleeping_group(cloth, false);
    finisher_->anchor(cloth, group_);
  }
  sleeping_group(cloth, true);
  finish_last_ = finisher_->cycle(cloth, scene, group_, opt_.energy, pool);
  finish_ms_ += finish_last_.total_ms;
  ++finish_cycles_;
  const bool done = finish_last_.last_move < opt_.finisher.move_tolerance;
  for (int p = 0; p < num_pieces_; ++p) {
    if (!frozen_[p] || finish_[p] < 0) continue;
    if (finish_[p] == 0) ++finish_count_;
    if (done || ++finish_[p] >= opt_.finisher.cycles) finish_[p] = -1;
  }
}

void RestScheduler::finish_on_thread(Cloth& cloth, const SceneObjects& scene) {
  if (!finish_thread_) finish_thread_ = std::make_unique<FinishThread>();
  FinishThread& job = *finish_thread_;
  if (job.busy() && !collect_finish(cloth)) return;
  // Pieces asleep and not finished yet: one job for all of them.
  bool any = false;
  for (int p = 0; p < num_pieces_ && !any; ++p) any = frozen_[p] && finish_[p] == 0;
  if (!any) return;
  sleeping_group(cloth, false);
  job.set_nice(opt_.finish_nice);
  job.start(cloth, scene, group_, opt_.energy, opt_.finisher);
  finish_version_ = cloth.topology_version;
  for (int p = 0; p < num_pieces_; ++p)
    if (frozen_[p] && finish_[p] == 0) finish_[p] = kFinishing;
}

bool RestScheduler::collect_finish(Cloth& cloth) {
  auto& S = cloth.state;
  const int n = cloth.num_vertices();
  FinishThread& job = *finish_thread_;
  // A piece's result is kept only while it sleeps on, untouched since the job started: not
  // woken (unsettle() clears its mark), not re-cooked (a cut or sew: another version), and
  // (checked when the job has ended) every vertex where it was, free or fixed as it was: a
  // vertex pinned where it lay or a position set by an operation does not wake a piece.
  const bool same = finish_version_ == cloth.topology_version &&
                    static_cast<int>(job.group().size()) == n &&
                    static_cast<int>(finish_.size()) == num_pieces_;
  piece_ok_.assign(num_pieces_, 0);
  bool any = false;
  for (int p = 0; p < num_pieces_ && same; ++p) {
    piece_ok_[p] = frozen_[p] && finish_[p] == kFinishing;
    any = any || piece_ok_[p];
  }
  if (!any) job.cancel();
  if (!job.ended()) return false;
  finish_last_ = job.collect();
  finish_ms_ += finish_last_.total_ms;
  finish_cycles_ += finish_last_.cycles;
  if (!job.completed()) std::fill(piece_ok_.begin(), piece_ok_.end(), 0);
  const auto& g = job.group();
  if (any && job.completed()) {
    const auto& x0 = job.start_positions();
    for (int i = 0; i < n; ++i)
      if ((g[i] >= 0) != cloth.is_free(i) || S.x[i] != x0[i]) piece_ok_[piece_of_[i]] = 0;
    const auto& xf = job.cloth().state.x;
    for (int i = 0; i < n; ++i)
      if (g[i] >= 0 && piece_ok_[g[i]]) {
        S.x[i] = xf[i];
        S.x_prev[i] = xf[i];
        S.v[i].setZero();
      }
  }
  bool dropped = false;
  for (int p = 0; p < num_pieces_; ++p) {
    if (finish_[p] != kFinishing) continue;
    if (piece_ok_[p]) {
      finish_[p] = -1;
      ++finish_count_;
    } else {
      finish_[p] = 0;  // asleep but not finished: a new job takes it
      dropped = true;
    }
  }
  if (dropped || !any) ++finish_dropped_;
  return true;
}

void RestScheduler::sleeping_group(const Cloth& cloth, bool started) {
  const int n = cloth.num_vertices();
  group_.resize(n);
  for (int i = 0; i < n; ++i) {
    const int p = piece_of_[i];
    const bool in = frozen_[p] && (started ? finish_[p] >= 0 : finish_[p] == 0);
    group_[i] = cloth.is_free(i) && in ? p : -1;
  }
}

}  // namespace drape::sim::xpbd
