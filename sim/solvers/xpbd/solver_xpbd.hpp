// XPBD (Macklin, Mueller, Chentanez 2016) with small steps (Macklin et al. 2019) on the SAME
// energy as the other solvers: each membrane triangle contributes three strain constraints
// (E_uu, E_vv, E_uv with compliances 1/(k A)); the tensor bending (default) three linear vector
// constraints per triangle (its curvature rows, ClothEnergy::bending_row_*), or with the hinge
// models one per hinge (sum K_k x_k, compliance 1/w); each spring a distance constraint;
// contacts are projected.
// The element data are cooked once per topology into flat arrays sorted by colour (elements
// of one colour share no vertex); a substep runs on the thread pool as one element sweep
// (xpbd::SweepPlan, xpbd_sweep.hpp) or, in the configurations the sweep does not serve, one pool
// call per colour. A step runs as named phases on one context (Step): begin_frame (wake, static
// finish, settling checks) and renew_anchors once per frame; per substep detect_contacts,
// set_masses, plan_substep, predict, warm_start, then either the sweep or project_triangles and
// project_bending_springs with velocities, and last update_pieces and schedule_rest. The pieces'
// sleep, settling, coarse correction and finish are xpbd::RestScheduler's (xpbd_rest.hpp).
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "sim/core/thread_pool.hpp"
#include "sim/energy/energy.hpp"
#include "sim/energy/self_collision.hpp"
#include "sim/solvers/solver.hpp"
#include "sim/solvers/xpbd/xpbd_kernels.hpp"
#include "sim/solvers/xpbd/xpbd_options.hpp"
#include "sim/solvers/xpbd/xpbd_rest.hpp"
#include "sim/solvers/xpbd/xpbd_sweep.hpp"
#include "sim/solvers/xpbd/xpbd_ties.hpp"

namespace drape::sim {

class XpbdSolver : public Solver {
 public:
  explicit XpbdSolver(XpbdOptions opt = {});
  ~XpbdSolver() override;
  std::string name() const override { return "xpbd"; }
  StepStats step(Cloth& cloth, const SceneObjects& scene, double dt) override;
  ThreadPool* pool() override { return pool_.get(); }
  // Trades thread pools with `other` when both have as many threads: a solver taking over from
  // another (CookAheadSolver's swap) steps on the threads that stepped that one, awake and on their
  // cores, rather than on its own, asleep since it was made (measured: a pool woken for the swap's
  // step could miss the whole step, its share run by the stepping thread). Results do not depend
  // on which threads run a step.
  void trade_pool(XpbdSolver& other) {
    if (pool_->size() == other.pool_->size()) std::swap(pool_, other.pool_);
  }
  // Cooks the element data of the cloth's topology unless they are cooked already (the first
  // step does it otherwise): CookAheadSolver cooks a cut's topology this way on a worker thread
  // while another solver steps on. Reads only the cloth's topology, fabric and masses. The
  // energy's build runs on `cook_pool` (null: the calling thread alone), not on the solver's.
  void prepare(const Cloth& cloth) { prepare(cloth, pool_.get()); }
  void prepare(const Cloth& cloth, ThreadPool* cook_pool);
  bool cooked_for(const Cloth& cloth) const;
  // The work of a cooked solver's first step done ahead, on `pool` (CookAheadSolver's worker,
  // after prepare): the inverse masses and the bending blocks' inverses for the cloth's pins
  // and frozen vertices and frames of length dt (0: not made), and single precision's element
  // terms at `anchors` (3 per vertex, then the scratch vertices'; none: not made), and with
  // `self_collision` the cloth's split into self-collision regions (SelfCollision::prepare).
  // The step keeps what still holds when it comes (the same masses and substep; take_anchors with
  // the same anchors; the regions of the same topology) and makes the rest again: no result
  // depends on whether or when warm ran.
  void warm(const Cloth& cloth, double dt, std::vector<double> anchors, bool self_collision,
            ThreadPool* pool);
  // The anchors the next step starts from instead of new ones at its positions (a solver taking
  // over from another: CookAheadSolver's swap); their element terms are made here unless warm
  // made them for the same anchors. Ignored unless single precision and the cooked cloth's size.
  void take_anchors(std::vector<double> anchors);
  // Single precision: the anchors (empty before the first step).
  const std::vector<double>& anchors() const { return anchors_; }
  // The energy a solver not yet stepped starts from: its first cook updates it for the cloth
  // (XpbdOptions::incremental_cook: only the triangles the change reached) instead of building
  // it whole. CookAheadSolver seeds the solver it cooks with the energy of the last one.
  void seed_energy(ClothEnergy energy) { energy_ = std::move(energy); }
  // The options the solver builds its energy with (its cook's; a seed is built with them).
  static EnergyOptions cook_energy_options(const XpbdOptions& opt) {
    EnergyOptions eo = opt.energy;
    eo.bending_matrix = false;  // XPBD projects the bending rows and never evaluates P
    return eo;
  }
  // What carries from one step to the next (xpbd_state.cpp): the warm-start multipliers (with
  // warm_start > 0; else they start at zero in every substep), the last substep's length, the
  // single-precision anchors and the rest scheduler's state. The element data are cooked again
  // from the cloth on restore (the same cloth: the same data); contacts, self-collision pairs
  // and the inverse masses are found again at every frame's start.
  std::vector<unsigned char> save_state(const Cloth& cloth) const override;
  std::string restore_state(const std::vector<unsigned char>& bytes, const Cloth& cloth) override;
  XpbdOptions& options() { return opt_; }
  int frozen_count() const { return rest_.frozen_count(); }
  // Ties (xpbd_ties.hpp: a sewn garment's seams), projected tie_passes times after the elements
  // in every substep; the velocities of the vertices they move follow their corrected positions.
  // Indices refer to the cloth the solver steps; kept until set again. With freeze, tied
  // vertices belong to one piece (they sleep, settle and wake together): new ties make the
  // pieces again at the next step.
  void set_ties(std::vector<xpbd::Tie> ties, int passes = 2) {
    // (No ties before or after, as at each cook-ahead swap of the panel: the pieces stand.)
    if (!ties_.empty() || !ties.empty()) pieces_stale_ = true;
    ties_ = std::move(ties);
    tie_passes_ = passes;
  }
  const std::vector<xpbd::Tie>& ties() const { return ties_; }
  int tie_passes() const { return tie_passes_; }
  int contact_detections() const { return detections_; }
  // Self-collision detections so far (found at a frame's start and once the cloth deforms).
  int self_detections() const { return self_detections_; }
  // Single precision: how many times the anchors were renewed (XpbdOptions::single_precision).
  long anchor_renewals() const { return anchor_renewals_; }
  // Element sweeps run on several threads, and those in which a thread took over the share of
  // another (a worker had not claimed its share when it was needed).
  long sweeps() const { return sweeps_; }
  long sweep_takeovers() const { return sweep_takeovers_; }
  // Wall ms spent in the element sweeps so far (the rest of a step is the per-substep and
  // per-frame work around them).
  double sweep_ms() const { return sweep_ms_; }
  // Wall ms spent so far in each part of the steps (the sweeps among them): which parts are
  // serial, and which scale with the pool (the many-core cost outside the sweeps).
  enum StepPart {
    kPartFrame,     // the frame's start: wake, thaw, the static finish, the fixed vertices
    kPartAnchors,   // the single-precision anchors' reach test and renewal
    kPartContacts,  // contact and self-collision detection, the coarse correction
    kPartPlan,      // the inverse masses (with the bending blocks' inverses) and the plan
    kPartSweep,     // the element sweeps (fused substeps) or the coloured passes
    kPartRetests,   // the contact retests after the sweep, counted
    kPartAfter,     // the self-collision pairs and the ties after the sweep
    kPartPieces,    // the pieces' motion sums, settling and sleep
    kPartList,      // the contacts listed at the step's end
    kStepParts
  };
  static const char* part_name(int part);
  double part_ms(int part) const { return part_ms_[part]; }
  // XpbdOptions::sweep_profile: the sweeps' runs timed on one thread and replayed on the plan's
  // slots (xpbd::SweepPlan::schedule), summed over the sweeps so far, with a hand-over of 0 and
  // of kProfileHandoverNs per wait, and with a phase gate (SweepPlan::schedule, hand-over 0).
  static constexpr double kProfileHandoverNs = 300;
  struct SweepProfile {
    long sweeps = 0;
    int slots = 0;
    xpbd::SweepPlan::Schedule ideal, handover, gated;
  };
  const SweepProfile& sweep_profile() const { return profile_; }
  // MB of the arrays one single-precision sweep streams through at least once: the triangle
  // and bending packs with their anchor terms, and per vertex the packed positions, positions,
  // previous positions, velocities, inverse masses and anchors (0 when it has not cooked one).
  double sweep_megabytes(int n) const;
  // Vertices tested again for contact in the sweep (XpbdOptions::retest_contacts).
  long contact_retests() const { return contact_retests_; }
  // The last cook of a topology (the first step, and the step after a cut, slit or sew): wall ms
  // of its parts (the energy's build, the triangles' packs, the bending blocks and their packs,
  // the sweep's plan, the rest) and the cooks so far.
  // With XpbdOptions::incremental_cook: whether the energy's bending rows and the blocks were
  // made again only for the triangles the change reached (ClothEnergy::update), and how many.
  struct CookStats {
    double energy_ms = 0, triangles_ms = 0, bending_ms = 0, sweep_ms = 0, other_ms = 0,
           total_ms = 0;
    int cooks = 0;
    bool incremental = false;
    int rebuilt_triangles = 0;
  };
  const CookStats& last_cook() const { return last_cook_; }
  // The energy as the solver cooked it (its contacts: those of the last step).
  const ClothEnergy& energy() const { return energy_; }
  // The bending energy of positions x as the cooked blocks state it (1/2 sum_r |V_r x|^2 k_r;
  // tensor bending, after a step), and their stencil entries (columns whose three coefficients
  // are cancelled zeros are left out, cook()).
  double cooked_bending_energy(const std::vector<Vec3>& x) const;
  int bending_entries() const { return static_cast<int>(row_colv_.size()); }
  // The build of the hot loops in use (xpbd_kernels.hpp: portable, AVX2 or AVX-512).
  const xpbd::Kernels& kernels() const { return *kern_; }
  // The pieces' sleep, settling, coarse correction and static finish.
  const xpbd::RestScheduler& rest() const { return rest_; }
  // Largest inertia scale of any piece (1: nothing settling; XpbdOptions::settle).
  double settle_scale() const { return rest_.settle_scale(); }
  // Self-collision pairs found at the last detection (scenes with self_collision on).
  const SelfCollision& self_collision() const { return self_; }
  // The last coarse correction (XpbdOptions::coarse_factor) and how many were applied.
  const CoarseStats& last_coarse() const { return rest_.last_coarse(); }
  int coarse_count() const { return rest_.coarse_count(); }
  double coarse_ms() const { return rest_.coarse_ms(); }
  // The last static finish cycle (XpbdOptions::finish; with finish_thread: the last job, all
  // its cycles), the pieces finished, the cycles and their time (on the finish's thread too).
  const FinisherStats& last_finish() const { return rest_.last_finish(); }
  int finish_count() const { return rest_.finish_count(); }    // pieces whose finish started
  int finish_cycles() const { return rest_.finish_cycles(); }  // cycles run
  double finish_ms() const { return rest_.finish_ms(); }
  // With finish_thread: jobs whose result was dropped (a piece woke, the cloth was cut), and
  // whether a job is running now.
  int finish_dropped() const { return rest_.finish_dropped(); }
  bool finishing() const { return rest_.finishing(); }
  int num_colours() const {
    return static_cast<int>(tri_col_.size() + hinge_col_.size() + spring_col_.size() +
                            row_cols_.size()) -
           4;
  }

 private:
  using Tri = xpbd::Tri;
  struct Hinge {
    int32_t v[4];
    double K[4];
    double iw;  // 1 / w
  };
  struct Spring {
    int32_t v[2];
    double rest, ik;  // rest length, 1 / k
  };
  // The names one step shares between its phases (solver_xpbd.cpp): the cloth, the substep's
  // length and what it runs.
  struct Step;

  // Cooking: the element data of a new topology (cook() and its parts).
  void cook(const Cloth& cloth);
  void cook_triangles(const Cloth& cloth);
  void cook_bending(int n, bool incremental);
  void assemble_blocks(bool incremental);
  void assemble_block(int r0);
  void cook_hinges_springs(int n);
  void cook_pieces(int n);
  void build_sweep(int n);

  // The step's phases, in the order step() and substep() run them.
  bool begin_frame(Step& c);    // wake, finish, settling checks; false: everything sleeps
  void renew_anchors(Step& c);  // single precision: new anchors once a vertex left its own
  void anchor_terms(const std::vector<double>& anchors, ThreadPool* pool);
  std::string read_state(ByteReader& in, const Cloth& cloth);
  std::string read_self_state(ByteReader& in, const Cloth& cloth);
  void substep(Step& c);
  void detect_contacts(Step& c);
  void detect_self(const Cloth& cloth, const SceneObjects& scene, const std::vector<Vec3>& x);
  void start_self(const Cloth& cloth, const SceneObjects& scene);
  bool self_due(const Step& c);
  void self_motion(const Step& c, int b, int e, int slot);
  void self_motion_of(const Step& c, const std::vector<int>& moved);
  void set_masses(Step& c);  // w and the bending blocks' inverses
  void take_masses(const Cloth& cloth, const double* scale, const int* piece_of, ThreadPool* pool);
  void row_inverses(double ihb, const double* scale, const int* piece_of, ThreadPool* pool);
  void plan_substep(Step& c);
  void predict(const Step& c, int b, int e);
  void warm_start(Step& c);
  void sweep(const Step& c);  // the whole substep as one element sweep (xpbd_sweep.hpp)
  template <class Items>
  void profile_sweep(Items& items);  // XpbdOptions::sweep_profile
  void collect_retests(Step& c);
  void project_triangles(const Step& c);  // and the bending blocks (packed alike)
  void project_bending_springs(Step& c);  // hinges, springs, contacts, self-collision
  void project_self_after_sweep(Step& c);
  void project_ties_after_sweep(Step& c);
  void refresh_velocities(Step& c, const std::vector<int>& moved);
  void velocities(const Step& c, int b, int e, int wk);
  void update_pieces(Step& c);  // the pieces' motion sums
  void schedule_rest(Step& c);  // settling and sleep

  // The phases' loops over items [b, e): vertices, vertex blocks k, elements or packs.
  void build_row_inverses(double ihb, const double* scale, const int* piece_of, int b, int e);
  void block_predict(const Step& c, int k, int b, int e);
  void warm_tris(const Step& c, int b, int e);
  void warm_hinges(const Step& c, int b, int e);
  void warm_rows(const Step& c, int b, int e);
  void warm_springs(const Step& c, int b, int e);
  void sweep_items(const Step& c, const xpbd::SweepPlan::Phase& P, int b, int e, int slot);
  void project_tris8(const Step& c, int b, int e);
  void project_rows8(const Step& c, int b, int e);
  void project_hinges(const Step& c, int b, int e);
  void project_springs(const Step& c, int b, int e);
  void block_velocities(const Step& c, int k, int b, int e, int wk);
  void block_motion(const Step& c, int k, int b, int e);
  bool moved_beyond(const Step& c, int i) const;
  void list_moved(const Step& c, int b, int e, int slot);
  void retest_listed(const Step& c);
  void test_moved_part(const Step& c, int b, int e, int wk);
  // Runs fn(b, e, worker) over each colour's items (offsets off), colour after colour; the packs'
  // version gives each share of a colour's packs to its own thread (xpbd::share_begin).
  template <class Fn>
  void by_colour(const std::vector<int>& off, Fn&& fn);
  template <class Fn>
  void by_colour_packs(const std::vector<int>& off, Fn&& fn);

  // Wakes frozen pieces that something disturbs; true when every piece is (still) frozen.
  bool wake(Cloth& cloth, const SceneObjects& scene);
  // Moves simulated vertices lying up to contact_snap_depth inside a fresh contact plane onto
  // it (position only; see XpbdOptions::contact_snap_depth).
  void snap_to_contacts(Cloth& cloth);
  // The same for one contact's vertex.
  void snap_onto(Cloth& cloth, const Contact& c) const;

  XpbdOptions opt_;
  ClothEnergy energy_;
  std::unique_ptr<ThreadPool> pool_;
  xpbd::RestScheduler rest_{opt_};
  std::vector<Tri> tris_;
  std::vector<Hinge> hinges_;
  std::vector<Spring> springs_;
  std::vector<int> tri_col_, hinge_col_, spring_col_;  // colour offsets into the arrays
  // The triangles in packs of four doubles of one colour (xpbd_kernels.hpp), colour offsets in
  // packs (the eight-float packs of single precision: below).
  std::vector<xpbd::TriPack> tri_packs_;
  std::vector<int> tpack_col_;
  // The energy's tensor bending as linear vector constraints (ClothEnergy bending rows), CSR in
  // colour order: row r is sum_k row_val_[k] x[row_col_[k]], inverse stiffness row_ik_[r].
  std::vector<int> row_off_, row_colv_, row_cols_;
  std::vector<double> row_val_, row_ik_;
  // The same blocks in triangle order, before the colouring (block t: columns blk_col_[blk_off_[t]
  // .. blk_off_[t + 1]), three values each, three inverse stiffnesses): an incremental cook
  // makes again only the blocks of the triangles whose rows the energy made again.
  std::vector<int> blk_off_, blk_col_;
  std::vector<double> blk_val_, blk_ik_;
  // The same blocks in packs of four doubles of one colour (xpbd_kernels.hpp), colour offsets in
  // packs (or eight floats: row_packs8_).
  // Per block the packs hold the inverse of its 3x3 system matrix A = sum_j w_j v_j v_j^T +
  // alpha/h^2 (upper triangle, 6 entries; all zero when A is singular). A depends only on the
  // inverse masses and the substep, so it is rebuilt only when one of them changes (a piece
  // freezes or wakes, a vertex is pinned or released, the frame is split differently).
  xpbd::RowPackData row_packs_;
  std::vector<int> rpack_col_;
  double row_ai_h_ = -1;  // the 1/(be h^2) the cached inverses were built for
  bool w_changed_ = true;
  // The inverse masses without the settling scale (w0_) and whether they changed since the
  // bending blocks' sums row_b_ (6 per block: sum_j w0_j v_j v_j^T) were taken.
  std::vector<double> w0_, row_b_;
  // Per pool thread: take_masses()' changed flags (w, w0), renew_anchors()' "beyond the reach".
  std::vector<char> changed_part_;
  // Per pool thread: a vertex it updated in the substep moved more than half the contact margin
  // since the last detection (XpbdOptions::reuse_contacts).
  std::vector<char> moved_part_;
  bool w0_changed_ = true;
  std::vector<Vec3> lambda_row_;
  std::vector<double> lambda_tri_, lambda_spring_;
  std::vector<Vec3> lambda_hinge_;
  // Positions padded to four doubles (the fourth: inverse mass) for the triangle and bending
  // kernels (xpbd_kernels.hpp), packed before and unpacked after them in every iteration; then
  // the scratch vertices (w = 0) of the packs' padding (scratch_slots_). (xp8_: the same in
  // floats.)
  std::vector<xpbd::P4> xp_;
  // The single-precision forms (XpbdOptions::single_precision; only those of the precision the
  // solver was cooked for are filled), the anchors (positions at the frame's start) and the
  // elements' terms at the anchors (xpbd_kernels.hpp, Kernels::tris8).
  // Triangles in packs of eight floats, or of sixteen when the kernels' build prefers it
  // (AVX-512: Kernels::tri_lanes, cooked into tlanes_; the colour offsets count the packs in
  // use); bending blocks in packs of eight (sixteen measured slower, xpbd_kernels.hpp).
  bool cooked_f32_ = false;
  std::string cooked_kernels_;  // XpbdOptions::kernels when cooked
  int tlanes_ = 8;
  std::vector<xpbd::TriPack8> tri_packs8_;
  std::vector<xpbd::TriPack16> tri_packs16_;
  std::vector<int> tpack8_col_;
  xpbd::RowPackData8 row_packs8_;
  std::vector<int> rpack8_col_;
  std::vector<xpbd::P4f> xp8_;
  int float_tri_packs() const {
    return static_cast<int>(tlanes_ == 16 ? tri_packs16_.size() : tri_packs8_.size());
  }
  // The single-precision element sweep of a substep (pack, the triangle colours, the bending
  // colours, unpack) as phases that the pool's threads run without a barrier between them, each
  // phase split in one share per thread, items in mesh order (xpbd_sweep.hpp: a share waits
  // only for the shares of the previous phase it touches). The results are those of the phases
  // run one after the other, bit for bit. Built by build_sweep() in cook(); run by sweep().
  enum { kSweepPack, kSweepTris, kSweepRows, kSweepUnpack };
  static constexpr int kSweepBlock = 256;
  xpbd::SweepPlan sweep_;
  long sweeps_ = 0, sweep_takeovers_ = 0, contact_retests_ = 0;
  double sweep_ms_ = 0;
  std::array<double, kStepParts> part_ms_{};
  // Adds the wall ms since t to the part's sum and restarts t.
  void add_part(int part, std::chrono::steady_clock::time_point& t);
  SweepProfile profile_;
  std::vector<double> profile_ns_;  // per run of the plan: its duration in the last sweep
  // Per pool thread of the retests (retest_listed): vertices tested again for contact and their
  // deepest penetration; pieces a test ends the settling of (thread * pieces + piece).
  struct RetestPart {
    long count = 0;
    double deepest = 0;
  };
  std::vector<RetestPart> retest_part_;
  // Per sweep slot: the vertices its share found moved beyond their last test in this substep;
  // retest_off_: where each slot's list starts when they are laid one after the other.
  std::vector<std::vector<int>> retest_list_;
  std::vector<int> retest_off_;
  // Contacts tested again after a sweep and not yet in the energy's contact list (the sweep
  // projects the tested ones, ClothEnergy::project_tested_contacts): listed at the step's end.
  bool contacts_unlisted_ = false;
  std::vector<char> unsettle_mark_;
  bool sweep_parallel_ = false;  // the pool's threads (else one runs the phases in turn)
  // Shares of a colour's packs, each with its scratch vertex of padding (xpbd::share_begin: n,
  // n + 1, ...): the sweep's shares, one per thread of the pool (at least two).
  int scratch_slots_ = 2;
  std::vector<double> anchors_;       // 3 per vertex, and the scratch vertices' (0)
  std::vector<double> warm_anchors_;  // the anchors warm() made the terms at
  std::vector<float> tri_anchor8_, row_anchor8_;
  static constexpr double kAnchorReach = 0.05;  // m (a float resolves 3.7e-9 m there)
  long anchor_renewals_ = 0;
  const xpbd::Kernels* kern_ = &xpbd::kernels();
  double h_prev_ = 0;
  std::vector<double> w_;  // inverse mass of each vertex, 0 when not free or frozen
  // The sweep's motion sums per vertex block: (piece, sums) per run of one piece's vertices.
  std::vector<std::vector<std::pair<int, xpbd::PieceMotion>>> block_motion_;
  // Per sweep vertex block: its vertices all of one piece (the per-vertex kernels then run it).
  std::vector<uint8_t> block_one_piece_;
  bool contacts_fresh_ = false;  // wake() detected contacts at the frame's start positions
  std::vector<Vec3> x_det_;      // each vertex's position at its last contact test
  SelfCollision self_;
  std::vector<Vec3> x_self_;  // the positions the self-collision pairs were found at
  // The flags that decide which pairs are tested (SelfCollision::detect), per vertex then.
  static constexpr uint8_t kSelfFlags =
      kFlagPinned | kFlagPinched | kFlagKinematic | kFlagNoCollide;
  std::vector<uint8_t> self_flags_;
  std::vector<char> self_flags_changed_;  // per pool part (start_self)
  // The box of displacements since x_self_ and the largest squared displacement, per sweep slot
  // or pool thread (self_due).
  struct SelfBox {
    Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    double most2 = 0;
    void add(const Vec3& d) {
      lo = lo.cwiseMin(d);
      hi = hi.cwiseMax(d);
      most2 = std::max(most2, d.squaredNorm());
    }
    void add(const SelfBox& o) {
      lo = lo.cwiseMin(o.lo);
      hi = hi.cwiseMax(o.hi);
      most2 = std::max(most2, o.most2);
    }
    // The bound on how much closer a vertex and a triangle came (self_due) exceeds the margin.
    bool beyond(double margin) const {
      return std::min((hi - lo).squaredNorm(), 4 * most2) > margin * margin;
    }
  };
  std::vector<SelfBox> self_box_;
  int self_detections_ = 0;
  std::vector<int> self_moved_;  // vertices the last self-collision projection moved
  std::vector<xpbd::Tie> ties_;
  int tie_passes_ = 2;
  bool pieces_stale_ = false;   // the ties changed since the pieces were made
  std::vector<int> tie_moved_;  // vertices the last tie projection moved
  CookStats last_cook_;
  ThreadPool* cook_pool_ = nullptr;  // cook() spreads its parallel parts over it (null: pool_)
  ThreadPool* cook_pool() const { return cook_pool_ ? cook_pool_ : pool_.get(); }
  int detections_ = 0;  // contact detections so far (for tests and the bench)
  double fresh_penetration_ = 0;
};

}  // namespace drape::sim
