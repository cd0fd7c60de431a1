// XPBD (Macklin, Mueller, Chentanez 2016) with small steps (Macklin et al. 2019) on the SAME
// energy as the other solvers: each membrane triangle contributes three strain constraints
// (E_uu, E_vv, E_uv with compliances 1/(k A)); the tensor bending (default) three linear vector
// constraints per triangle (its curvature rows, ClothEnergy::bending_row_*), or with the hinge
// models one per hinge (sum K_k x_k, compliance 1/w); each spring a distance constraint;
// contacts are projected.
// The element data are cooked once per topology into flat arrays sorted by colour (elements
// of one colour share no vertex); a substep runs on the thread pool as one element sweep
// (SweepPhase) or, in the configurations the sweep does not serve, one pool call per colour.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "sim/core/thread_pool.hpp"
#include "sim/energy/energy.hpp"
#include "sim/energy/self_collision.hpp"
#include "sim/rest/coarse_correction.hpp"
#include "sim/rest/equilibrium_finisher.hpp"
#include "sim/rest/finish_thread.hpp"
#include "sim/solvers/solver.hpp"
#include "sim/solvers/xpbd/xpbd_kernels.hpp"

namespace drape::sim {

struct XpbdOptions {
  int substeps = 10;
  int iterations = 1;  // per substep (small steps: 1)
  EnergyOptions energy;
  double damping = 1.0;  // velocity damping rate (1/s), air drag as in Verlet and VBD
  int threads = 2;       // colours projected in parallel (results do not depend on it)
  // Cloths with fewer triangles run on the calling thread alone: a colour of a small cloth is
  // too little work to share (measured, form 10x1 on this 2-core VM: 32^2 1.49 ms per frame on
  // one thread, 1.83 on two; 64^2 6.2 vs 4.7 ms wall).
  int min_parallel_triangles = 4000;
  // Tests only: false keeps the pool's worker from taking its part of the element sweep (as if
  // it were never scheduled), so that the caller takes it over (XpbdSolver::SweepPhase).
  bool sweep_worker = true;
  // With reuse_contacts, in the element sweep: each vertex that moved more than half the margin
  // and its clearance (ClothEnergy::clearance2) since its own last contact test is tested again
  // there, instead of all vertices being tested again in the next substep (the frame's first
  // substep still tests all).
  bool retest_contacts = true;
  // Warm start (0..1): each substep starts from the previous substep's multipliers scaled by
  // this factor (and by (h / h_prev)^2), applying their displacement w grad C lambda with the
  // prediction. 0 (default) is classic XPBD: multipliers reset every substep, whose fixed point
  // at rest is not the energy's equilibrium with few iterations (too soft: a sheet sags by mm
  // to cm). With f the bias shrinks about as (1 - f), but the warm displacement is an explicit
  // application of stiff forces: measured on hanging sheets (10^2, 24^2, 10 substeps) 0.5 halves
  // the error (12.1 -> 6.5 mm at 24^2) and 0.7 and above diverge, so it stays off by default.
  double warm_start = 0.0;
  // Freezing of pieces at rest (island sleeping): a connected piece of cloth whose free
  // vertices have all been slower than freeze_speed for freeze_steps substeps is frozen
  // (kFlagFrozen: not simulated; a frame in which every piece sleeps costs one contact check)
  // until one of its fixed vertices moves (pinch, move), a free vertex of it is released, or
  // an object enters its contact shell (a hand, a moved form). Whole pieces, not single
  // vertices: freezing one vertex of a piece moves XPBD's under-converged fixed point of its
  // neighbours, which then wake it again (measured: a sheet never settled). After a cut each
  // piece sleeps on its own.
  // Contacts are detected at each frame's start (objects may have moved) and again in a later
  // substep only once some vertex has moved more than half the contact margin since the last
  // detection: a vertex outside the margin then cannot have reached the surface, and the
  // contact planes of the others are still tangent within a few hundredths of a mm. false:
  // detection every substep (the old behaviour, kept to measure against).
  bool reuse_contacts = true;
  // At each contact detection, a simulated vertex found at most this deep (m) inside its fresh
  // contact plane is moved onto it before the substep starts, as a correction of position and
  // not as motion (its velocity is kept). Between detections a vertex slides on the plane
  // found last; where the form curves inward (under the bust, at the waist) that tangent plane
  // runs up to ~0.2 mm inside the surface, and the next detection's push, taken as motion,
  // gave the vertex ~0.2 m/s for a substep: the settled drape never stopped jittering
  // (docs/solvers.md section 3g). Deeper pushes (an object moving into the cloth) are motion as
  // before. 0: off.
  double contact_snap_depth = 1e-3;
  // Bending blocks projected every n-th substep with compliance alpha / (n h^2) (multi-rate: the
  // same bending impulse per n substeps). Measured (docs/solvers.md): n = 2 costs ~30 % less
  // per frame; at 32^2 the error is the same (form 40 substeps 1.45 vs 1.66 mm, sphere 20
  // substeps 5.8 vs 6.4 mm) but at 16^2 it grows (form 20 substeps 2.1 vs 1.3 mm), so plain
  // XPBD (1) stays the default.
  int bending_every = 1;
  // Triangles and bending blocks projected in single precision, eight per pack (AVX: one
  // register), on the positions' displacements from their place at the frame's start
  // (xpbd_kernels.hpp, P4f); the state stays double and receives the kernels' moves. false: the
  // double kernels, four per pack. Measured in docs/solvers.md section 3o.
  bool single_precision = true;
  // The build of the hot loops by name ("portable", "avx2", "avx512"; xpbd_kernels.hpp), or
  // empty: the fastest this CPU runs. A name the CPU does not run is ignored. For benchmarks
  // that compare builds in one process.
  std::string kernels;
  bool freeze = false;
  double freeze_speed = 1e-3;  // m/s
  int freeze_steps = 30;
  // Settling (quasi-static refinement of a piece at rest; docs/solvers.md "Settling"). With
  // multipliers reset every substep, XPBD's fixed point at rest is not the energy's
  // equilibrium: each substep rebuilds a constraint's whole load lambda ~ h^2 x (its tension)
  // from a violation of about w lambda, so the cloth is too stretchy by ~ w h^2 x load, which
  // grows with the hanging length (7 mm at 32^2, 22 mm at 64^2 on the form, 10 substeps). A
  // piece whose free vertices have all been slower than settle_speed for settle_steps substeps
  // settles: its inertia grows by settle_growth every settle_grow_steps substeps (gently: a
  // sudden step releases the stretch as a jolt) up to settle_mass_scale
  // (w and the prediction's acceleration divided by the scale: the forces, and so the
  // equilibrium, are unchanged, the bias shrinks by the scale) and its air drag is
  // settle_damping. It returns to its own mass at once when its RMS speed exceeds
  // settle_exit_speed, one of its fixed vertices moves or is let go (pinch, drag, release),
  // something pushes 1 mm into its contact shell, it is woken from sleep or the topology
  // changes. A settling piece
  // answers a push like a heavier cloth until the push speeds it past settle_exit_speed.
  bool settle = true;
  double settle_speed = 0.05;      // m/s
  double settle_exit_speed = 0.5;  // m/s, RMS over the piece
  int settle_steps = 30;
  double settle_growth = 1.05;
  int settle_grow_steps = 10;
  double settle_mass_scale = 64;
  // A settling piece's air drag (1/s). About critical for its slowest mode, the free flap's
  // swing under gravity, sqrt(g / L / scale) ~ 0.7 rad/s at the full scale (L ~ 0.3 m): a
  // heavier drag makes that mode creep (overdamped, rate ~ omega^2 / c), a lighter one lets it
  // swing. Measured on the form drape (10x1, error from the nearest equilibrium after 3 / 8 s,
  // docs/solvers.md section 3g): 16^2 3.46 / 2.98 mm at 5/s -> 2.80 / 0.41 mm at 1.5/s, 32^2
  // 1.46 / 0.89 -> 2.06 / 0.86 mm, 64^2 10.4 / 4.43 -> 6.19 / 1.87 mm.
  double settle_damping = 1.5;
  // With freeze: a piece at the full scale for this many substeps sleeps even if it still
  // moves (a safety net: a settled piece normally sleeps on the rest test above). It was 900
  // while re-detected contacts kept a settled drape jittering (contact_snap_depth), which
  // froze the 128^2 drape at 4.2 s, still 8.2 mm RMS from its equilibrium; at 4500 it rests
  // at 8.2 s, 3.2 mm from it (docs/solvers.md section 3g).
  int settle_sleep_steps = 4500;
  // Coarse-grid correction of settled pieces (sim/rest/coarse_correction.hpp): on each of the first
  // coarse_frames frames after a piece has settled to the full inertia scale, at the frame's
  // contact detection, the piece's static residual is reduced on a lattice of nodes every
  // coarse_factor fine edges (a Galerkin Newton step with a line search; positions only, and
  // the corrected vertices' velocities are zeroed: a settled piece is quasi-static). It moves
  // the long-wavelength part of what is left between the settled drape and its equilibrium,
  // which the sweeps would take seconds of settling to move (docs/solvers.md section 3l).
  // Correcting every frame while a piece settles was measured and is worse: the corrections
  // and the sweeps' own fixed point pull against each other and the piece never sleeps.
  // Not done in scenes with self-collision (the coarse model has none). 0: off.
  int coarse_factor = 4;
  int coarse_frames = 1;
  CoarseOptions coarse;  // the correction's own options (coarse.factor is set from coarse_factor)
  // With freeze on: a piece that has fallen asleep is finished statically while it sleeps
  // (sim/rest/equilibrium_finisher.hpp: Gauss-Seidel sweeps on the static energy and a coarse
  // correction with node rotations per cycle, friction anchored where it fell asleep), one
  // cycle per frame until a cycle moves no vertex farther than finisher.move_tolerance or
  // finisher.cycles were run; waking ends it. XPBD's own sweeps would pull an awake piece back
  // toward their biased fixed point, hence only while it sleeps (docs/solvers.md section 3m).
  bool finish = true;
  FinisherOptions finisher;
  // Where the finish runs: on a thread of its own (sim/rest/finish_thread.hpp; all its cycles on a
  // copy taken when the pieces fall asleep, copied back in the frame after it ends, dropped if
  // a piece woke meanwhile), so that the fixed-rate loop keeps its ticks while a drape is
  // finished; or, when false, one cycle per step on the solver's own threads (deterministic
  // frame by frame; the end state is the same). The thread runs at nice + finish_nice (Linux),
  // below the simulation and the renderer (FinishThread::set_nice).
  bool finish_thread = true;
  int finish_nice = 10;
};

class XpbdSolver : public Solver {
 public:
  explicit XpbdSolver(XpbdOptions opt = {});
  ~XpbdSolver() override;
  std::string name() const override { return "xpbd"; }
  StepStats step(Cloth& cloth, const SceneObjects& scene, double dt) override;
  ThreadPool* pool() override { return pool_.get(); }
  XpbdOptions& options() { return opt_; }
  int frozen_count() const { return frozen_count_; }
  int contact_detections() const { return detections_; }
  // Single precision: how many times the anchors were renewed (XpbdOptions::single_precision).
  long anchor_renewals() const { return anchor_renewals_; }
  // Element sweeps run on two threads, and those in which the caller ran both halves itself
  // (the worker had not claimed its half when the caller needed it).
  long sweeps() const { return sweeps_; }
  long sweep_takeovers() const { return sweep_takeovers_; }
  // Vertices tested again for contact in the sweep (XpbdOptions::retest_contacts).
  long contact_retests() const { return contact_retests_; }
  // The energy as the solver cooked it (its contacts: those of the last step).
  const ClothEnergy& energy() const { return energy_; }
  // The bending energy of positions x as the cooked blocks state it (1/2 sum_r |V_r x|^2 k_r;
  // tensor bending, after a step), and their stencil entries (columns whose three coefficients
  // are cancelled zeros are left out, cook()).
  double cooked_bending_energy(const std::vector<Vec3>& x) const;
  int bending_entries() const { return static_cast<int>(row_colv_.size()); }
  // The build of the hot loops in use (xpbd_kernels.hpp: portable, AVX2 or AVX-512).
  const xpbd::Kernels& kernels() const { return *kern_; }
  // Largest inertia scale of any piece (1: nothing settling; XpbdOptions::settle).
  double settle_scale() const;
  // Self-collision pairs found at the last detection (scenes with self_collision on).
  const SelfCollision& self_collision() const { return self_; }
  // The last coarse correction (XpbdOptions::coarse_factor) and how many were applied.
  const CoarseStats& last_coarse() const { return coarse_last_; }
  int coarse_count() const { return coarse_count_; }
  double coarse_ms() const { return coarse_ms_; }
  // The last static finish cycle (XpbdOptions::finish; with finish_thread: the last job, all
  // its cycles), the pieces finished, the cycles and their time (on the finish's thread too).
  const FinisherStats& last_finish() const { return finish_last_; }
  int finish_count() const { return finish_count_; }    // pieces whose finish started
  int finish_cycles() const { return finish_cycles_; }  // cycles run
  double finish_ms() const { return finish_ms_; }
  // With finish_thread: jobs whose result was dropped (a piece woke, the cloth was cut), and
  // whether a job is running now.
  int finish_dropped() const { return finish_dropped_; }
  bool finishing() const { return finish_thread_ && finish_thread_->busy(); }
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
  void cook(const Cloth& cloth);

  XpbdOptions opt_;
  ClothEnergy energy_;
  std::unique_ptr<ThreadPool> pool_;
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
  // Per pool thread: a vertex it updated in the substep moved more than half the contact margin
  // since the last detection (XpbdOptions::reuse_contacts).
  std::vector<char> moved_part_;
  bool w0_changed_ = true;
  // The inverse masses w_ must be recomputed (each frame's start; a piece's settling scale
  // changed or a piece fell asleep within the frame); otherwise they are kept between substeps.
  bool w_dirty_ = true;
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
  // colours, unpack) as phases that two threads run without a barrier between them: in each
  // phase slot 0 runs the first half of the items (vertex blocks or packs, which are in mesh
  // order) and slot 1 the second; a slot runs the items of its half that share no vertex with
  // the other slot's half of the previous phase (safe, counted from the outer end: slot 0 from
  // the front, slot 1 from the back) without waiting, and waits for the other slot to finish
  // the previous phase only before the rest (near the middle). No slot starts a phase before the
  // other has finished the one before the previous. Every item thus sees what it would see after
  // a barrier between the phases: the results are those of the phases run one after the other,
  // bit for bit. Built by build_sweep() in cook(); run by sweep() (step()).
  struct SweepPhase {
    int kind;     // kSweepPack, kSweepTris, kSweepRows, kSweepUnpack
    int b, e;     // items: vertex blocks (kSweepBlock vertices) or packs
    int half;     // slot 0: [b, b + half), slot 1: [b + half, e)
    int safe[2];  // slot 0: [b, b + safe[0]); slot 1: [e - safe[1], e)
  };
  enum { kSweepPack, kSweepTris, kSweepRows, kSweepUnpack };
  static constexpr int kSweepBlock = 256;
  std::vector<SweepPhase> sweep_;
  void build_sweep(int n);
  std::atomic<int> sweep_done_[2] = {};  // phases a slot has finished
  std::atomic<int> sweep_owner_{-1};     // the thread running slot 1 (-1: nobody yet)
  long sweeps_ = 0, sweep_takeovers_ = 0, contact_retests_ = 0;
  // Per sweep slot: vertices tested again for contact and their deepest penetration; pieces a
  // test ends the settling of (slot * pieces + piece).
  struct RetestPart {
    long count = 0;
    double deepest = 0;
  };
  std::vector<RetestPart> retest_part_;
  // Contacts tested again in the sweep and not yet in the energy's contact list (the sweep
  // projects the tested ones, ClothEnergy::project_tested_contacts): listed at the step's end.
  bool contacts_unlisted_ = false;
  std::vector<char> unsettle_mark_;
  bool sweep_parallel_ = false;  // two threads (else one runs the phases one after the other)
  // Shares of a colour's packs, each with its scratch vertex of padding (xpbd::share_begin: n,
  // n + 1, ...); with two, the sweep's halves.
  int scratch_slots_ = 2;
  std::vector<double> anchors_;  // 3 per vertex, and the scratch vertices' (0)
  std::vector<float> tri_anchor8_, row_anchor8_;
  static constexpr double kAnchorReach = 0.05;  // m (a float resolves 3.7e-9 m there)
  long anchor_renewals_ = 0;
  const xpbd::Kernels* kern_ = &xpbd::kernels();
  double h_prev_ = 0;
  std::vector<double> w_;  // inverse mass of each vertex, 0 when not free or frozen
  std::vector<int> piece_of_, piece_rest_;  // connected piece per vertex; rest substeps
  std::vector<uint8_t> piece_frozen_, piece_awake_;
  std::vector<double> piece_scale_;  // settling: inertia scale per piece (1: own mass)
  std::vector<int> piece_slow_;      // settling: slow substeps, then substeps since growing
  // Per piece, each substep (settling and sleeping): the largest squared free-vertex speed,
  // sum of m v^2, the same with v^2 capped at settle_speed^2, and the mass.
  struct PieceMotion {
    double max_v2 = 0, mv2 = 0, mv2_capped = 0, m = 0;
  };
  std::vector<PieceMotion> motion_;
  // The sweep's motion sums per vertex block: (piece, sums) per run of one piece's vertices.
  std::vector<std::vector<std::pair<int, PieceMotion>>> block_motion_;
  // Per sweep vertex block: its vertices all of one piece (the per-vertex kernels then run it).
  std::vector<uint8_t> block_one_piece_;
  std::vector<int> piece_full_;      // settling: substeps at the full scale
  std::vector<uint8_t> fixed_prev_;  // settling: vertex was fixed at the last step
  void unsettle(int piece);
  // Moves simulated vertices lying up to contact_snap_depth inside a fresh contact plane onto
  // it (position only; see XpbdOptions::contact_snap_depth).
  void snap_to_contacts(Cloth& cloth);
  // The same for one contact's vertex.
  void snap_onto(Cloth& cloth, const Contact& c) const;
  int num_pieces_ = 0, frozen_count_ = 0;
  bool contacts_fresh_ = false;  // wake() detected contacts at the frame's start positions
  std::vector<Vec3> x_det_;      // each vertex's position at its last contact test
  SelfCollision self_;
  // Coarse correction of settled pieces (XpbdOptions::coarse_factor).
  std::unique_ptr<CoarseCorrection> coarse_;
  std::vector<int> coarse_group_;
  std::vector<int> piece_coarse_;  // corrections in the piece's current settling episode
  CoarseStats coarse_last_;
  int coarse_count_ = 0;
  double coarse_ms_ = 0;
  std::unique_ptr<EquilibriumFinisher> finisher_;
  FinisherStats finish_last_;
  int finish_count_ = 0, finish_cycles_ = 0;
  // Per piece: cycles run in its sleep (0: none yet); -1: finished; kFinishing: in the job of
  // finish_thread_.
  std::vector<int> piece_finish_;
  static constexpr int kFinishing = -2;
  void finish_sleeping(Cloth& cloth, const SceneObjects& scene);
  void finish_on_thread(Cloth& cloth, const SceneObjects& scene);
  // coarse_group_ = the piece of every free vertex of a sleeping piece whose finish has not
  // started (started false) or is not finished (true), else -1.
  void sleeping_group(const Cloth& cloth, bool started);
  std::vector<uint8_t> piece_ok_;  // finish_on_thread: the job's result stands for the piece
  std::unique_ptr<FinishThread> finish_thread_;
  uint64_t finish_version_ = 0;  // topology_version of the cloth the job copied
  double finish_ms_ = 0;
  int finish_dropped_ = 0;
  void coarse_step(Cloth& cloth, const SceneObjects& scene);
  int detections_ = 0;  // contact detections so far (for tests and the bench)
  double fresh_penetration_ = 0;
  // Wakes frozen pieces that something disturbs; true when every piece is (still) frozen.
  bool wake(Cloth& cloth, const SceneObjects& scene);
};

}  // namespace drape::sim
