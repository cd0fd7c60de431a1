// The XPBD solver's options (XpbdSolver, solver_xpbd.hpp). They stay one flat struct: benches,
// tests, the app and the solver factory set them by name, and grouping them would change those
// call sites without changing what they mean. By topic: the step (substeps .. kernels),
// contacts (reuse_contacts, retest_contacts, contact_snap_depth), sleep (freeze ..), settling
// (settle ..), the coarse correction (coarse_factor ..) and the static finish (finish ..).
#pragma once

#include <string>

#include "sim/energy/energy.hpp"
#include "sim/rest/coarse_correction.hpp"
#include "sim/rest/equilibrium_finisher.hpp"

namespace drape::sim {

struct XpbdOptions {
  int substeps = 10;
  int iterations = 1;  // per substep (small steps: 1)
  EnergyOptions energy;
  double air_drag = 1.0;  // 1/s: velocities decay as exp(-air_drag t), as in Verlet, VBD and Newton
  int threads = 2;        // the pool's threads, the caller included (results do not depend on it)
  // Cloths with fewer triangles run on the calling thread alone: a colour of a small cloth is
  // too little work to share (on two cores, 32^2 takes 1.49 ms per frame on one thread and 1.83
  // on two).
  int min_parallel_triangles = 4000;
  // After a topology change (cut, slit, sew) the energy's tensor bending rows and the bending
  // blocks made of them are made again only for the triangles the change reached
  // (ClothEnergy::update; bit for bit those of a full cook); false: every cook is a full one.
  bool incremental_cook = true;
  // Tests only: false keeps the pool's workers from taking their shares of the element sweep
  // (as if they were never scheduled), so that the caller takes them over; sweep_absent_worker
  // >= 1 does so for that one worker only, whose share the others take over (xpbd_sweep.hpp).
  bool sweep_worker = true;
  int sweep_absent_worker = -1;
  // Benchmarks: the element sweep's shares (and the packs' padding shares) planned for this many
  // threads whatever the pool's size (0: the pool's; results do not depend on it), and with
  // sweep_profile on a pool of one thread each sweep's runs timed and replayed as that many
  // threads would run them (XpbdSolver::sweep_profile(), xpbd::SweepPlan::schedule).
  int sweep_slots = 0;
  bool sweep_profile = false;
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
  // application of stiff forces: 0.5 halves the error of a hanging sheet and 0.7 and above
  // diverge, so it stays off by default.
  double warm_start = 0.0;
  // Contacts are detected at each frame's start (objects may have moved) and again in a later
  // substep only once some vertex has moved more than half the contact margin since the last
  // detection: a vertex outside the margin then cannot have reached the surface, and the
  // contact planes of the others are still tangent within a few hundredths of a mm. false:
  // detection every substep (kept to measure against).
  bool reuse_contacts = true;
  // At each contact detection, a simulated vertex found at most this deep (m) inside its fresh
  // contact plane is moved onto it before the substep starts, as a correction of position and
  // not as motion (its velocity is kept). Between detections a vertex slides on the plane
  // found last; where the form curves inward (under the bust, at the waist) that tangent plane
  // runs up to ~0.2 mm inside the surface, and the next detection's push, taken as motion,
  // would give the vertex ~0.2 m/s for a substep, so that a settled drape never stops
  // jittering. Deeper pushes (an object moving into the cloth) are motion. 0: off.
  double contact_snap_depth = 1e-3;
  // Bending blocks projected every n-th substep with compliance alpha / (n h^2) (multi-rate: the
  // same bending impulse per n substeps). n = 2 costs ~30 % less per frame, but the error grows
  // on coarse cloths (16^2), so plain XPBD (1) stays the default.
  int bending_every = 1;
  // Triangles and bending blocks projected in single precision, eight per pack (AVX: one
  // register), on the positions' displacements from their place at the frame's start
  // (xpbd_kernels.hpp, P4f); the state stays double and receives the kernels' moves. false: the
  // double kernels, four per pack.
  bool single_precision = true;
  // The build of the hot loops by name ("portable", "avx2", "avx512"; xpbd_kernels.hpp), or
  // empty: the fastest this CPU runs. A name the CPU does not run is ignored. For benchmarks
  // that compare builds in one process.
  std::string kernels;
  // Freezing of pieces at rest (island sleeping): a connected piece of cloth whose free
  // vertices have all been slower than freeze_speed for freeze_steps substeps is frozen
  // (kFlagFrozen: not simulated; a frame in which every piece sleeps costs one contact check)
  // until one of its fixed vertices moves (pinch, move), a free vertex of it is released, or
  // an object enters its contact shell (a hand, a moved form). Whole pieces, not single
  // vertices: freezing one vertex of a piece moves XPBD's under-converged fixed point of its
  // neighbours, which then wake it again. After a cut each piece sleeps on its own.
  bool freeze = false;
  double freeze_speed = 1e-3;  // m/s
  int freeze_steps = 30;
  // Settling (quasi-static refinement of a piece at rest; docs/solvers.md "Settling"). With
  // multipliers reset every substep, XPBD's fixed point at rest is not the energy's
  // equilibrium: each substep rebuilds a constraint's whole load lambda ~ h^2 x (its tension)
  // from a violation of about w lambda, so the cloth is too stretchy by ~ w h^2 x load, which
  // grows with the hanging length (22 mm at 64^2 on the form, 10 substeps). A piece whose free
  // vertices have all been slower than settle_speed for settle_steps substeps settles: its
  // inertia grows by settle_growth every settle_grow_steps substeps (gently: a sudden step
  // releases the stretch as a jolt) up to settle_mass_scale (w and the prediction's
  // acceleration divided by the scale: the forces, and so the equilibrium, are unchanged, the
  // bias shrinks by the scale) and its air drag is settle_air_drag. It returns to its own mass
  // at once when its RMS speed exceeds settle_exit_speed, one of its fixed vertices moves or is
  // let go (pinch, drag, release), something pushes 1 mm into its contact shell, it is woken
  // from sleep or the topology changes. A settling piece answers a push like a heavier cloth
  // until the push speeds it past settle_exit_speed.
  bool settle = true;
  double settle_speed = 0.05;  // m/s
  // A fast substep that projects freshly detected contacts does not end a piece's run of slow
  // substeps (settle and freeze tests). Where a seam's ties hold a vertex
  // against the form (the sewn garment), each fresh contact plane moves it ~30 um and back, a
  // speed of 5.5 cm/s at 20 substeps: with the tests' 30 substeps longer than a frame, the
  // garment would never settle nor sleep. Off: the panel's measured rest behaviour.
  bool rest_holds_at_detection = false;
  double settle_exit_speed = 0.5;  // m/s, RMS over the piece
  int settle_steps = 30;
  double settle_growth = 1.05;
  int settle_grow_steps = 10;
  double settle_mass_scale = 64;
  // A settling piece's air drag (1/s). About critical for its slowest mode, the free flap's
  // swing under gravity, sqrt(g / L / scale) ~ 0.7 rad/s at the full scale (L ~ 0.3 m): a
  // heavier drag makes that mode creep (overdamped, rate ~ omega^2 / c), a lighter one lets it
  // swing (at 64^2 the error from the nearest equilibrium after 8 s falls from 4.4 mm at 5/s
  // to 1.9 mm at 1.5/s).
  double settle_air_drag = 1.5;
  // With freeze: a piece at the full scale for this many substeps sleeps even if it still
  // moves (a safety net: a settled piece normally sleeps on the rest test above). Long enough
  // for the 128^2 drape to come within 3.2 mm of its equilibrium before it sleeps.
  int settle_sleep_steps = 4500;
  // Coarse-grid correction of settled pieces (sim/rest/coarse_correction.hpp): on each of the
  // first coarse_frames frames after a piece has settled to the full inertia scale, at the
  // frame's contact detection, the piece's static residual is reduced on a lattice of nodes
  // every coarse_factor fine edges (a Galerkin Newton step with a line search; positions only,
  // and the corrected vertices' velocities are zeroed: a settled piece is quasi-static). It
  // moves the long-wavelength part of what is left between the settled drape and its
  // equilibrium, which the sweeps would take seconds of settling to move. Not every frame while
  // a piece settles: the corrections and the sweeps' own fixed point then pull against each
  // other and the piece never sleeps. Not done in scenes with self-collision (the coarse model
  // has none). 0: off.
  int coarse_factor = 4;
  int coarse_frames = 1;
  CoarseOptions coarse;  // the correction's own options (coarse.factor is set from coarse_factor)
  // With freeze on: a piece that has fallen asleep is finished statically while it sleeps
  // (sim/rest/equilibrium_finisher.hpp: Gauss-Seidel sweeps on the static energy and a coarse
  // correction with node rotations per cycle, friction anchored where it fell asleep), one
  // cycle per frame until a cycle moves no vertex farther than finisher.move_tolerance or
  // finisher.cycles were run; waking ends it. XPBD's own sweeps would pull an awake piece back
  // toward their biased fixed point, hence only while it sleeps.
  bool finish = true;
  FinisherOptions finisher;
  // Where the finish runs: on a thread of its own (sim/rest/finish_thread.hpp; all its cycles on
  // a copy taken when the pieces fall asleep, copied back in the frame after it ends, dropped
  // if a piece woke meanwhile), so that the fixed-rate loop keeps its ticks while a drape is
  // finished; or, when false, one cycle per step on the solver's own threads (deterministic
  // frame by frame; the end state is the same). The thread runs at nice + finish_nice (Linux),
  // below the simulation and the renderer (FinishThread::set_nice).
  bool finish_thread = true;
  int finish_nice = 10;
};

}  // namespace drape::sim
