// Static finishing of a settled piece: two-level cycles on the cloth's static energy.
//
// A dynamic solver's settled state is not the static equilibrium: XPBD's sweeps stop at their
// own biased fixed point, and the last millimetres lie along the cloth's softest global modes
// (a skirt swinging as a pendulum, a fold rolling: stiffness ~ M g / L against the membrane's
// ~10^3 N/m), which local sweeps alone do not measurably reduce (180 sweeps at 128^2).
// Each cycle here:
//   1. contacts re-detected (friction anchored where the finish started: the equilibrium
//      nearest to the settled state, as the benchmark's polish),
//   2. `sweeps` Gauss-Seidel sweeps of per-vertex Newton steps on the static energy (vertices of
//      one colour in parallel; the equilibrium is their fixed point, unlike XPBD's),
//   3. one coarse correction (sim/rest/coarse_correction.hpp, with node rotations) for the long
//      wavelengths the sweeps cannot reach,
//   4. an extrapolation along the cycle's displacement (FinisherOptions::extrapolate).
// Positions only: velocities of the finished vertices are zeroed.
#pragma once

#include <atomic>
#include <memory>
#include <utility>
#include <vector>

#include "sim/core/cloth.hpp"
#include "sim/core/scene_objects.hpp"
#include "sim/core/thread_pool.hpp"
#include "sim/energy/energy.hpp"
#include "sim/rest/coarse_correction.hpp"

namespace drape::sim {

struct FinisherOptions {
  int cycles = 20;  // at most
  int sweeps = 3;   // Gauss-Seidel sweeps per cycle
  // Coarse lattice spacing in nominal edges; 0: automatic, about 16 cells across the widest
  // finished piece, between 2 and 4 edges (on the form drape: at 32^2 nodes every 4 edges
  // leave 1.56 mm, every 2 edges 0.71 mm; at 128^2 every 4 edges reach 0.71 mm, every 2 would cost
  // ~4x per cycle).
  int coarse_factor = 0;
  bool rotations = true;  // CoarseOptions::rotations
  // Stop once a cycle moved no vertex farther than this (m).
  double move_tolerance = 1e-5;
  // Each vertex's Newton step is regularised by m / tau^2 (a tiny inertia, s).
  double tau = 0.05;
  // Largest extrapolation along a cycle's displacement (in cycles; 0: none). See cycle().
  double extrapolate = 8;
  // The static problem's contact penalty (N/m) and friction smoothing (m): the static solver's
  // (StaticOptions), so that the finish and the benchmark's polish minimise the same energy.
  double contact_stiffness = 1e4;
  double friction_eps = 1e-4;
};

struct FinisherStats {
  int cycles = 0;
  double energy_before = 0, energy_after = 0;  // J (with the friction potential)
  double max_move = 0;                         // largest displacement of a vertex in all (m)
  double last_move = 0;                        // largest displacement in the last cycle (m)
  double extrapolation = 0;                    // the last cycle's extrapolation (0: none)
  double sweep_ms = 0, coarse_ms = 0, total_ms = 0;
};

class EquilibriumFinisher {
 public:
  explicit EquilibriumFinisher(FinisherOptions opt = {});
  ~EquilibriumFinisher();
  FinisherOptions& options() { return opt_; }

  // Finishes the vertices with group[i] >= 0 (pieces, coarsened apart; -1: stays) toward the
  // static equilibrium of the cloth's energy (`energy_options` as the solver's; the bending
  // matrix is built here) with the scene's objects: anchor(), then cycles until one moves no
  // vertex farther than move_tolerance or `cycles` were run, or `stop` (may be null) was set
  // (checked before each cycle). `pool` may be null (one thread).
  FinisherStats run(Cloth& cloth, const SceneObjects& scene, const std::vector<int>& group,
                    const EnergyOptions& energy_options, ThreadPool* pool,
                    const std::atomic<bool>* stop = nullptr);
  // The same in steps, for a caller that spreads the cycles over frames: anchor() the
  // vertices of group >= 0 where they are now (friction's anchors; others keep theirs), then
  // one cycle() per call. The returned stats describe that cycle.
  void anchor(const Cloth& cloth, const std::vector<int>& group);
  FinisherStats cycle(Cloth& cloth, const SceneObjects& scene, const std::vector<int>& group,
                      const EnergyOptions& energy_options, ThreadPool* pool);
  // Friction's anchors (what carries from one cycle to the next; empty before the first), for
  // saving and restoring a solver's state.
  const std::vector<Vec3>& anchors() const { return anchor_; }
  void set_anchors(std::vector<Vec3> a) { anchor_ = std::move(a); }

 private:
  FinisherOptions opt_;
  ClothEnergy energy_;
  uint64_t version_ = ~0ull;
  std::vector<int> nbr_off_, nbrs_, colour_of_, colour_off_, colour_items_;
  int colours_ = 0;
  CoarseCorrection coarse_;
  std::vector<Vec3> anchor_, before_, dir_, grad_, trial_;
};

}  // namespace drape::sim
