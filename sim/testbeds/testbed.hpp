// The reference scenes (testbeds), written once and shared by tests and benchmarks:
// a sheet hanging from two corners, a 20-particle chain, a Peirce cantilever strip, a cloth
// draped on the dress form, a cloth on a sphere. Plus the exact elastica of the cantilever.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "sim/core/cloth.hpp"
#include "sim/core/scene_objects.hpp"
#include "sim/energy/energy.hpp"
#include "sim/runtime/world.hpp"
#include "sim/solvers/solver.hpp"

namespace drape::sim {

struct Testbed {
  std::string name;
  Cloth cloth;
  SceneObjects objects;
  bool springs_model = false;  // the chain uses springs (no triangles)
  double duration = 2.0;       // simulated seconds before the error is measured
  // Air drag (1/s) every solver uses on this scene in the benchmarks; < 0: the solvers' default
  // (1/s). The form scene settles (its error is that of the settled drape, not of a swing).
  double air_drag = -1;
};

// Muslin (or `fabric`) sheet of side 0.5 m with res x res vertices, hanging in the x-y plane
// from its two top corners (pinned) at height 1.2 m; starts flat and sags.
Testbed make_hanging_sheet(int res, const FabricParams& fabric = {});
// 20 particles of 1 kg, 0.1 m apart, hanging straight down from the top one (pinned), joined
// by springs of stiffness k (N/m). The support force must equal the total weight (196.1 N).
Testbed make_chain(int particles = 20, double mass = 1.0, double k = 1e5);
// Peirce cantilever strip (ASTM D1388) along the warp: width x overhang, clamped over
// `clamp` (pinned rows), horizontal at 1 m; `spacing` = grid step.
Testbed make_cantilever(double overhang, double spacing, double width = 0.01,
                        const FabricParams& fabric = {});
// A res x res muslin panel 0.5 x 0.5 m whose top edge is pinned across the upper chest of
// the parametric 9AR form (form collision). fall = false (the app's default scenario): it
// hangs straight down from the chest line, 1.5 s. fall = true (the benchmarks' "form" scene): it
// starts horizontal, sticking forward, falls over the bust and drapes against it, 3 s, with
// an air drag of 4/s so that it has settled when the error is measured.
Testbed make_form_drape(int res, const FabricParams& fabric = {}, bool fall = false);
// A res x res panel 0.6 x 0.6 m dropped flat onto a sphere (r = 0.15 m) with its centre
// vertex pinned on the sphere's top.
Testbed make_sphere_drape(int res, const FabricParams& fabric = {});
// Drags the hanging sheet's top-right corner (its last vertex, pinned) along +x at 0.2 m/s for
// `frames` frames of 1/90 s with `solver`; returns how far the bottom-left vertex moved (m).
// Tests use it to check that a solver's resting (frozen) cloth wakes and follows.
double drag_sheet_corner(Testbed& sheet, Solver& solver, int frames);
// By name: "sheet", "chain", "cantilever", "form", "sphere".
Testbed make_scene(const std::string& name, int res);

// Exact elastica of a cantilever of length l, rigidity B (N m, whole width) and weight per
// length q (N/m), clamped horizontally: integrates theta' = M/B, M' = -q (l - s) cos theta by
// shooting on M(0). Returns the tip (x forward, y down positive) relative to the clamp.
Vec2 elastica_tip(double l, double B, double q, int steps = 2000);
// The rigidity B for which the elastica's tip drops by `tip_drop` (bisection on log B).
double elastica_rigidity_for_drop(double l, double q, double tip_drop);

// Stress cases, shared by tests/sim/solvers/stress_test.cpp and bench/stress_bench:
// "large_dt" (dt = 1/30 s), "stiffness_ratio" (warp/shear = 1e4), "jerk" (a pinned vertex
// jerked at 10 m/s), "cuts" (random cuts on a dense cloth), "crush" (cloth between the form and
// a rising plate). `scale` 1 = test size, larger = benchmark size (more steps, cuts, vertices).
// A step fails when, after the solver (with its watchdog), a position is non-finite, a vertex
// is beyond 10 m, or the kinetic energy exceeds 1e3 J/kg; the other figures of the outcome are
// what the tests bound.
struct StressResult {
  int steps = 0;
  int failures = 0;
  int rollbacks = 0;  // watchdog retries (a step restored and re-run)
  int vertices = 0;
  double max_kinetic = 0;      // J/kg: the largest kinetic energy per unit mass
  double energy_growth = 0;    // J/kg: the largest rise of kinetic + gravitational energy per
                               // unit mass over the lowest since the last driven step
  double max_penetration = 0;  // m: the deepest a vertex went below the floor, into the form or
                               // into a plate (below its surface)
  std::string note;
};
StressResult run_stress_case(const std::string& name, const std::string& solver, int scale);
const std::vector<std::string>& stress_case_names();

// RMS and max vertex distance (m) between two position arrays of equal size.
void position_error(const std::vector<Vec3>& a, const std::vector<Vec3>& b, double& rms,
                    double& max);

// A World of the testbed's cloth and objects, stepped by `solver`.
World testbed_world(Testbed t, std::unique_ptr<Solver> solver);

}  // namespace drape::sim
