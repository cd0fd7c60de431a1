// Bringing XPBD's pieces of cloth to rest (XpbdOptions: freeze, settle, coarse_factor, finish):
// the per-piece state of sleep, settling, the coarse correction and the static finish, and the
// decisions on it that the solver's step calls once per frame or substep. The solver owns the
// simulation and the contacts; this class owns which pieces sleep, how heavy each one is and
// what happens to them at rest.
#pragma once

#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "sim/core/byte_io.hpp"
#include "sim/core/thread_pool.hpp"
#include "sim/energy/energy.hpp"
#include "sim/energy/self_collision.hpp"
#include "sim/rest/coarse_correction.hpp"
#include "sim/rest/equilibrium_finisher.hpp"
#include "sim/rest/finish_thread.hpp"
#include "sim/solvers/xpbd/xpbd_options.hpp"

namespace drape::sim::xpbd {

// A settling piece with a vertex deeper than this inside a fresh contact plane was pushed (a
// hand, a moved form): its settling ends. Not 0.1 mm as for waking a sleeping piece: a settling
// piece still slides, and a plane re-found on a curved form after half a margin of sliding can
// sit ~0.1 mm off (at 128^2 that ended settling over and over).
inline constexpr double kUnsettleDepth = 1e-3;

// A piece's motion in one substep (settling and sleeping): the largest squared free-vertex
// speed, sum of m v^2, the same with v^2 capped at settle_speed^2, and the mass.
struct PieceMotion {
  double max_v2 = 0, mv2 = 0, mv2_capped = 0, m = 0;
};

class RestScheduler {
 public:
  explicit RestScheduler(const XpbdOptions& opt) : opt_(opt) {}
  ~RestScheduler();

  // A new topology: the pieces of its n vertices (piece_of), each awake at its own mass.
  void reset(int pieces, std::vector<int> piece_of);

  int num_pieces() const { return num_pieces_; }
  const std::vector<int>& piece_of() const { return piece_of_; }
  // Inertia scale per piece (1: its own mass).
  const std::vector<double>& scales() const { return scale_; }
  bool frozen(int piece) const { return frozen_[piece] != 0; }
  int frozen_count() const { return frozen_count_; }
  // Largest inertia scale of any piece (1: nothing settling).
  double settle_scale() const;

  // The inverse masses must be set again (a piece's scale changed, a piece fell asleep or
  // woke, a new frame); cleared by the solver once it has.
  bool masses_dirty() const { return masses_dirty_; }
  void mark_masses_dirty() { masses_dirty_ = true; }
  void masses_set() { masses_dirty_ = false; }

  // A piece returns to its own mass and its settling episode (coarse correction, finish) ends.
  void unsettle(int piece);
  // Self-collision pairs found (vertex, triangle's corners): their pieces get neither the coarse
  // correction nor the static finish in their current settling episode (both solve without the
  // self pairs and could push one layer through another); the other pieces still do.
  void skip_rest_of_self_touching(const Cloth& cloth, const std::vector<SelfContact>& pairs);

  // Frame start without freeze: every piece awake, no vertex frozen (the vertices on `pool`).
  void thaw(Cloth& cloth, ThreadPool* pool = nullptr);
  bool any_frozen() const;
  // Frame start with freeze, after a fresh contact detection: wakes the sleeping pieces that
  // something disturbs (a fixed vertex moved, a vertex released, an object in the contact
  // shell) and resets the frozen flags; true when every piece still sleeps.
  bool wake(Cloth& cloth, const ClothEnergy& energy);
  // Frame start: a fixed vertex that moved since the last frame or was let go ends its piece's
  // settling (without settle: every piece at its own mass). The vertices on `pool`.
  void check_fixed(const Cloth& cloth, ThreadPool* pool = nullptr);
  // After a contact detection: something pushed into a settling piece (kUnsettleDepth).
  void unsettle_pushed(const std::vector<Vec3>& x, const ClothEnergy& energy);

  // The substep's motion sums per piece: over the free vertices (w > 0) of v in vertex order,
  // or from the sweep's sums per vertex block (runs of one piece each).
  void sum_motion(const double* w, const std::vector<Vec3>& v, const std::vector<double>& mass);
  void sum_motion(const std::vector<std::vector<std::pair<int, PieceMotion>>>& block_runs);
  // After the substep's motion sums: settling starts, grows or ends (settle), pieces fall
  // asleep (freeze) and their vertices get the frozen flag (substep s of the frame).
  // hold: the substep projected freshly detected contacts and a fast piece keeps its count of
  // slow substeps (XpbdOptions::rest_holds_at_detection).
  void settle_pieces(bool hold = false);
  void freeze_pieces(Cloth& cloth, int s, bool hold = false);

  // The coarse correction of the pieces due for it (XpbdOptions::coarse_factor).
  void coarse_step(Cloth& cloth, const SceneObjects& scene, ClothEnergy& energy);
  // The static finish of sleeping pieces (XpbdOptions::finish), on the solver's pool or its own
  // thread.
  void finish_sleeping(Cloth& cloth, const SceneObjects& scene, ThreadPool* pool);

  // The state carried from one step to the next (per piece: sleep, settling, corrections and
  // finish cycles done; per vertex: fixed at the last step; the finish's friction anchors), for
  // the solver's saved state (Solver::save_state). A finish job running on its own thread is not
  // saved: its pieces are saved as not yet finished, and a restored scheduler starts the job
  // again. restore() follows reset() for the same topology; false when the bytes do not fit it.
  void save(ByteWriter& o) const;
  bool restore(ByteReader& in);
  // After a failed restore() and reset(): what reset() keeps goes too (as a fresh scheduler).
  void forget();

  const CoarseStats& last_coarse() const { return coarse_last_; }
  int coarse_count() const { return coarse_count_; }
  double coarse_ms() const { return coarse_ms_; }
  const FinisherStats& last_finish() const { return finish_last_; }
  int finish_count() const { return finish_count_; }
  int finish_cycles() const { return finish_cycles_; }
  double finish_ms() const { return finish_ms_; }
  int finish_dropped() const { return finish_dropped_; }
  bool finishing() const { return finish_thread_ && finish_thread_->busy(); }

 private:
  void finish_on_thread(Cloth& cloth, const SceneObjects& scene);
  // Collects the finish job if it has ended (else false): copies its result to the pieces it
  // stands for.
  bool collect_finish(Cloth& cloth);
  // group_ = the piece of every free vertex of a sleeping piece whose finish has not started
  // (started false) or is not finished (true), else -1.
  void sleeping_group(const Cloth& cloth, bool started);

  const XpbdOptions& opt_;
  int num_pieces_ = 0, frozen_count_ = 0;
  bool masses_dirty_ = true;
  std::vector<int> piece_of_;            // connected piece per vertex
  std::vector<int> rest_;                // per piece: substeps at rest
  std::vector<uint8_t> frozen_, awake_;  // asleep; woken this frame
  std::vector<double> scale_;            // settling: inertia scale (1: own mass)
  std::vector<int> slow_;                // settling: slow substeps, then substeps since growing
  std::vector<int> full_;                // settling: substeps at the full scale
  std::vector<uint8_t> fixed_prev_;      // per vertex: fixed at the last step
  std::vector<char> unsettle_mark_;      // check_fixed: per pool thread and piece
  std::vector<PieceMotion> motion_;      // this substep's motion per piece
  std::vector<int> group_;               // per vertex: its piece if corrected or finished, else -1
  // Coarse correction.
  std::unique_ptr<CoarseCorrection> coarse_;
  std::vector<int> coarse_done_;  // per piece: corrections in its current settling episode
  CoarseStats coarse_last_;
  int coarse_count_ = 0;
  double coarse_ms_ = 0;
  // Static finish. Per piece: cycles run in its sleep (0: none yet); -1: finished; kFinishing:
  // in the job of finish_thread_.
  static constexpr int kFinishing = -2;
  std::vector<int> finish_;
  std::unique_ptr<EquilibriumFinisher> finisher_;
  FinisherStats finish_last_;
  int finish_count_ = 0, finish_cycles_ = 0;
  std::vector<uint8_t> piece_ok_;  // finish_on_thread: the job's result stands for the piece
  std::unique_ptr<FinishThread> finish_thread_;
  uint64_t finish_version_ = 0;  // topology_version of the cloth the job copied
  double finish_ms_ = 0;
  int finish_dropped_ = 0;
};

}  // namespace drape::sim::xpbd
