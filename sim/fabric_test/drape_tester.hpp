// The virtual drape tester (a Cusick drape test; docs/fabrics.md): a circular specimen laid
// centred on a support disc with a rounded rim (top at y = 0, the stage's up axis), clamped
// over the disc's flat top as a Cusick tester's upper disc holds it, draped under gravity by
// the real-time solver (XPBD) from a flat start with a small seeded perturbation, then brought
// to the static equilibrium by the static finish (sim/rest/equilibrium_finisher.hpp). The
// shadow of the equilibrium is measured (drape_measure.hpp).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "sim/core/cloth.hpp"
#include "sim/core/scene_objects.hpp"
#include "sim/fabric_test/drape_measure.hpp"

namespace drape::sim {

struct DrapeTestOptions {
  double specimen_diameter = 0.30;  // m
  double disc_diameter = 0.18;      // m
  // Rings of vertices from the centre to the rim (edge length ~ specimen radius / rings). 30
  // (5 mm) resolves the folds: the node count grows with the rings (7 at 20 rings where 8 to 9
  // were measured) and a drape stays near two seconds on one core; docs/fabrics.md has the
  // convergence.
  int resolution = 30;
  // Radial spacing of the rings at the disc's rim, as a fraction of the nominal edge (1:
  // uniform). The overhang bends hardest just past the rim, over about a bending length
  // (B / w)^(1/3) ~ 2 cm: with uniform rings DC climbs by 0.10 between 20 and 40 rings, with
  // 0.4 by 0.03-0.05 (docs/fabrics.md, "DC against resolution").
  double rim_spacing = 0.4;
  uint64_t seed = 1;
  // Amplitude (m) of the start's perturbation: a random sum of angular waves (3 to 16 around
  // the rim) lifting or lowering the overhang, growing as the square of the distance past the
  // clamp, plus per-vertex noise of a tenth of it.
  double perturbation = 0.002;
  bool clamp = true;              // pin the specimen over the disc's flat top (Cusick's upper disc)
  double friction = 0.5;          // Coulomb, cloth on the disc
  double disc_thickness = 0.004;  // m
  double edge_radius = 0.002;     // m, the rim's rounding
  double offset = 0.001;          // m, the cloth's half thickness: collision distance
  double max_time = 6.0;          // s of simulated time at most
  double min_time = 1.0;          // s at least
  double rest_speed = 0.003;      // m/s: the dynamic phase ends once no vertex is faster
  int finish_cycles = 40;         // static finish cycles at most
};

struct DrapeTestResult {
  DrapeMeasures measures;
  Cloth cloth;          // the draped specimen
  ShadowRaster shadow;  // its top-view shadow, holes filled
  double sim_time = 0;  // s simulated
  int finish_cycles = 0;
  double finish_last_move = 0;  // m, the last finish cycle's largest move
  double seconds = 0;           // wall time
};

// The specimen: concentric rings joined by triangles, so its rim is the circle itself;
// material coordinates centred on its centre. The rings are radius / rings apart (ring k at
// k radius / rings with round(2 pi k) vertices), closer by the factor rim_spacing around
// rim_radius (the disc's rim), each with round(2 pi r / h) vertices.
Cloth make_circular_specimen(double radius, int rings, const FabricParams& fabric,
                             double rim_radius = 0, double rim_spacing = 1);

// One drape of `fabric`. Errors: bad options (named), or a drape that did not stay finite.
Result<DrapeTestResult> run_drape_test(const FabricParams& fabric, const DrapeTestOptions& opt);

struct DrapeSeries {
  std::vector<DrapeTestResult> runs;  // one per seed: seed, seed + 1, ...
  double dc_mean = 0, dc_sd = 0, nodes_mean = 0, nodes_sd = 0;
  // The node count's median and range: a drape test reports the median of its integer counts.
  double nodes_median = 0;
  int nodes_min = 0, nodes_max = 0;
  double rmin_mean = 0, rmax_mean = 0;  // m
  double seconds = 0;                   // wall time of the whole series
};

// `seeds` drapes (opt.seed, opt.seed + 1, ...) on up to `threads` threads; sample standard
// deviations (0 for one seed).
Result<DrapeSeries> run_drape_series(const FabricParams& fabric, const DrapeTestOptions& opt,
                                     int seeds, int threads = 2);

// The drape and the disc (named "specimen" and "disc") as glTF (.gltf/.glb) or OBJ.
std::string write_drape_mesh(const DrapeTestResult& result, const DrapeTestOptions& opt,
                             const std::string& path);

}  // namespace drape::sim
