// Scenes shared by the operations tests: the two initial states (spread, rolled) of a
// small panel with some particles fixed, a world stepped like the SimThread's tick, and hands.
#pragma once

#include <cmath>
#include <memory>
#include <string>

#include "sim/core/cloth.hpp"
#include "sim/ops/operation_controller.hpp"
#include "sim/runtime/world.hpp"
#include "sim/solvers/solver_vbd.hpp"
#include "sim/solvers/xpbd/solver_xpbd.hpp"

namespace drape::sim::testing {

enum class Initial { kSpread, kRolled };
inline const char* initial_name(Initial s) {
  return s == Initial::kSpread ? "spread" : "rolled";
}

inline constexpr double kDt = 1.0 / 90;

// A 0.4 m square panel, n x n particles, top edge at y = 1.4 m (spread: hanging in the x-y plane
// at z = 0; rolled: rolled up from its bottom edge, its top edge at y = 1.0 m). `fixed` top
// particles are pinned: 1 = the top-left corner, 2 = both top corners, 3+ = evenly spread.
inline World make_world(Initial s, int fixed, int n = 9) {
  World w;
  PanelSpec spec;
  spec.width = spec.height = 0.4;
  spec.nx = spec.ny = n;
  spec.spacing = 0.4 / (n - 1);
  w.cloth = make_panel(spec, FabricParams{});
  if (s == Initial::kSpread)
    place_spread(w.cloth, Vec3(-0.2, 1.0, 0), Vec3::UnitX(), Vec3::UnitY());
  else
    place_rolled(w.cloth, Vec3(-0.2, 1.0, 0), Vec3::UnitX(), Vec3::UnitY(), 0.02);
  const int top = (n - 1) * n;  // vertex (i, n-1) = top + i
  auto pin = [&](int v) { w.cloth.state.flags[v] |= kFlagPinned; };
  if (fixed >= 1) pin(top);
  if (fixed >= 2) pin(top + n - 1);
  for (int k = 2; k < fixed; ++k) pin(top + (n - 1) * (k - 1) / (fixed - 1));
  w.cloth.relump_masses();
  // The operations do not depend on the solver; these tests run XPBD (20 substeps), the solver
  // that is best on the benchmarks' chart. VBD with its adaptive initial guess under-converges
  // a free fall (a released cloth fell 4.7 cm in 0.22 s instead of ~24 cm), which
  // ReleaseWithOneFixedLetsTheClothFall detects.
  XpbdOptions o;
  o.substeps = 20;
  w.solver = std::make_unique<XpbdSolver>(o);
  return w;
}

// One tick as SimThread::tick() runs it (commands already applied by the caller).
inline void tick(World& w, int n = 1) {
  for (int i = 0; i < n; ++i) {
    if (w.before_step) w.before_step(w, kDt);
    if (!w.paused && w.solver) w.last_step = w.solver->step(w.cloth, w.scene, kDt);
    if (w.after_step) w.after_step(w, kDt);
  }
}

inline HandProxy hand_at(int id, const Vec3& p, double radius = 0.03) {
  HandProxy h;
  h.id = id;
  h.tracked = true;
  h.position = p;
  h.tip = p;
  h.radius = radius;
  return h;
}

inline bool stable(const Cloth& c, double bound = 5.0) {
  for (const Vec3& x : c.state.x)
    if (!x.allFinite() || x.cwiseAbs().maxCoeff() > bound) return false;
  return true;
}

inline bool has_message(const World& w, const std::string& part) {
  for (const auto& m : w.messages)
    if (m.find(part) != std::string::npos) return true;
  return false;
}

inline int top_vertex(const World& w, int i, int n = 9) {
  (void)w;
  return (n - 1) * n + i;
}

}  // namespace drape::sim::testing
