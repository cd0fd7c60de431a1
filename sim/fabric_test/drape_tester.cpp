// The virtual drape tester (sim/fabric_test/drape_tester.hpp).
#include "sim/fabric_test/drape_tester.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>
#include <thread>

#include "sim/io/mesh_io.hpp"
#include "sim/rest/equilibrium_finisher.hpp"
#include "sim/solvers/solver_factory.hpp"

namespace drape::sim {

namespace {
constexpr double kPi = 3.14159265358979323846;

// Vertices of a ring of radius r on a mesh of nominal edge h (6 on the first ring).
int ring_count(double r, double h) {
  return std::max(6, static_cast<int>(std::lround(2 * kPi * r / h)));
}

// Joins ring `in` (first vertex `a`, na vertices) to ring `out` (first `b`, nb), walking both
// by angle: each step advances the ring whose next vertex comes first. Counter-clockwise in
// the material plane.
void join_rings(int a, int na, double off_a, int b, int nb, double off_b,
                std::vector<std::array<int32_t, 3>>& tris) {
  int i = 0, j = 0;
  while (i < na || j < nb) {
    const double next_a = off_a + 2 * kPi * (i + 1) / na;
    const double next_b = off_b + 2 * kPi * (j + 1) / nb;
    if (j >= nb || (i < na && next_a < next_b)) {
      tris.push_back({a + i % na, b + j % nb, a + (i + 1) % na});
      ++i;
    } else {
      tris.push_back({a + i % na, b + j % nb, b + (j + 1) % nb});
      ++j;
    }
  }
}

// Ring radii from the centre to `radius`: steps of h = radius / rings, shrunk to
// h * rim_spacing at rim_radius and back to h over 3 h on either side.
std::vector<double> ring_radii(double radius, int rings, double rim_radius, double rim_spacing) {
  const double h = radius / rings;
  std::vector<double> r{0.0};
  for (;;) {
    const double g =
        rim_spacing + (1 - rim_spacing) * std::min(1.0, std::abs(r.back() - rim_radius) / (3 * h));
    const double next = r.back() + h * g;
    if (next > radius - 0.5 * h * g) break;
    r.push_back(next);
  }
  r.push_back(radius);
  return r;
}
}  // namespace

Cloth make_circular_specimen(double radius, int rings, const FabricParams& fabric,
                             double rim_radius, double rim_spacing) {
  Cloth c;
  c.fabric = fabric;
  const double h = radius / rings;
  c.topo.spacing = h;
  const std::vector<double> radii = ring_radii(radius, rings, rim_radius, rim_spacing);
  std::vector<int> first, count;
  std::vector<double> offset;
  for (size_t k = 0; k < radii.size(); ++k) {
    first.push_back(c.topo.num_vertices());
    const int n = k == 0 ? 1 : ring_count(radii[k], h);
    count.push_back(n);
    // Every other ring turned by half a step: no seam of aligned edges runs from the centre.
    offset.push_back(k % 2 ? kPi / n : 0.0);
    for (int q = 0; q < n; ++q) {
      const double a = offset[k] + 2 * kPi * q / n;
      c.topo.material.emplace_back(radii[k] * std::cos(a), radii[k] * std::sin(a));
    }
  }
  for (int q = 0; q < count[1]; ++q)
    c.topo.triangles.push_back({0, first[1] + q, first[1] + (q + 1) % count[1]});
  for (size_t k = 1; k + 1 < radii.size(); ++k)
    join_rings(first[k], count[k], offset[k], first[k + 1], count[k + 1], offset[k + 1],
               c.topo.triangles);
  const int n = c.topo.num_vertices();
  c.topo.vertex_zone.assign(n, 0);
  c.topo.triangle_zone.assign(c.topo.triangles.size(), 0);
  c.topo.vertex_origin.resize(n);
  for (int i = 0; i < n; ++i) c.topo.vertex_origin[i] = i;
  c.state.flags.assign(n, 0);
  // Material (u, v) -> stage (u, y, -v): the top view (x, -z) is the material plane, and the
  // counter-clockwise triangles face up.
  place_spread(c, Vec3::Zero(), Vec3::UnitX(), -Vec3::UnitZ());
  c.relump_masses();
  return c;
}

namespace {
std::string check_options(const DrapeTestOptions& o) {
  if (!(o.specimen_diameter > 0)) return "specimen diameter must be positive";
  if (!(o.disc_diameter > 0) || !(o.disc_diameter < o.specimen_diameter))
    return "disc diameter must be positive and smaller than the specimen's";
  if (o.resolution < 4 || o.resolution > 200) return "resolution must be 4 to 200 rings";
  if (!(o.rim_spacing >= 0.1 && o.rim_spacing <= 1)) return "rim spacing must be in [0.1, 1]";
  if (!(o.perturbation >= 0) || !(o.friction >= 0) || !(o.offset > 0))
    return "perturbation and friction must be >= 0, offset > 0";
  if (!(o.edge_radius > 0) || !(o.disc_thickness >= 2 * o.edge_radius))
    return "the disc's edge radius must be positive and at most half its thickness";
  return {};
}

// Lays the specimen flat on the disc, pins what the clamp holds and lifts or lowers the
// overhang by the seeded perturbation.
void lay_specimen(Cloth& c, const DrapeTestOptions& o, double clamp_r) {
  const double R = 0.5 * o.specimen_diameter;
  std::mt19937_64 rng(o.seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::uniform_real_distribution<double> phase(0.0, 2 * kPi);
  constexpr int kLo = 3, kHi = 16;
  std::array<double, kHi + 1> amp{}, ph{};
  for (int k = kLo; k <= kHi; ++k) {
    amp[k] = gauss(rng) / std::sqrt(kHi - kLo + 1.0);
    ph[k] = phase(rng);
  }
  for (int i = 0; i < c.num_vertices(); ++i) {
    const Vec2& m = c.topo.material[i];
    const double r = m.norm(), th = std::atan2(m.y(), m.x());
    const double s = std::max(0.0, (r - clamp_r) / (R - clamp_r));
    double wave = 0;
    for (int k = kLo; k <= kHi; ++k) wave += amp[k] * std::cos(k * th + ph[k]);
    const double dy = o.perturbation * s * s * (wave + 0.1 * gauss(rng));
    c.state.x[i] = Vec3(m.x(), o.offset + dy, -m.y());
    if (o.clamp && r <= clamp_r + 1e-9) c.state.flags[i] |= kFlagPinned;
  }
  c.state.x_prev = c.state.x;
  c.relump_masses();
}

double max_free_speed(const Cloth& c) {
  double v2 = 0;
  for (int i = 0; i < c.num_vertices(); ++i)
    if (c.is_free(i)) v2 = std::max(v2, c.state.v[i].squaredNorm());
  return std::sqrt(v2);
}

bool all_finite(const Cloth& c) {
  return std::all_of(c.state.x.begin(), c.state.x.end(),
                     [](const Vec3& p) { return p.allFinite(); });
}

// The dynamic phase: XPBD frames of 1/60 s until the drape is at rest (or max_time).
std::string drape_dynamically(Cloth& c, const SceneObjects& scene, const DrapeTestOptions& o,
                              double& sim_time) {
  SolverConfig cfg;
  cfg.threads = 1;
  cfg.freeze = false;
  auto solver = make_solver("xpbd", cfg);
  if (!solver) return solver.error();
  constexpr double kDt = 1.0 / 60;
  for (sim_time = 0; sim_time < o.max_time;) {
    (*solver)->step(c, scene, kDt);
    sim_time += kDt;
    if (sim_time >= o.min_time && max_free_speed(c) < o.rest_speed) break;
  }
  return all_finite(c) ? std::string() : "the drape did not stay finite";
}
}  // namespace

Result<DrapeTestResult> run_drape_test(const FabricParams& fabric, const DrapeTestOptions& o) {
  if (std::string e = check_options(o); !e.empty()) return make_error("drape test", e);
  const auto t0 = std::chrono::steady_clock::now();
  DrapeTestResult res;
  const double R = 0.5 * o.specimen_diameter, rd = 0.5 * o.disc_diameter;
  res.cloth = make_circular_specimen(R, o.resolution, fabric, rd, o.rim_spacing);
  lay_specimen(res.cloth, o, rd - o.edge_radius);
  SceneObjects scene;
  scene.floor = false;
  scene.offset = o.offset;
  scene.friction = o.friction;
  scene.discs.push_back({Vec3::Zero(), rd, o.disc_thickness, o.edge_radius});
  if (std::string e = drape_dynamically(res.cloth, scene, o, res.sim_time); !e.empty())
    return make_error("drape test", fabric.name + ": " + e);
  FinisherOptions fo;
  fo.cycles = o.finish_cycles;
  EquilibriumFinisher finisher(fo);
  std::vector<int> group(res.cloth.num_vertices());
  for (int i = 0; i < res.cloth.num_vertices(); ++i) group[i] = res.cloth.is_free(i) ? 0 : -1;
  const FinisherStats fs = finisher.run(res.cloth, scene, group, EnergyOptions{}, nullptr);
  res.finish_cycles = fs.cycles;
  res.finish_last_move = fs.last_move;
  if (!all_finite(res.cloth))
    return make_error("drape test", fabric.name + ": the static finish did not stay finite");
  DrapeMeasureOptions mo;
  mo.specimen_diameter = o.specimen_diameter;
  mo.disc_diameter = o.disc_diameter;
  res.shadow.reset(R + 0.01, 0.0005);
  rasterize_mesh(cloth_to_mesh(res.cloth), res.shadow);
  fill_holes(res.shadow);
  res.measures = measure_shadow(res.shadow, mo);
  res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return res;
}

namespace {
void mean_sd(const std::vector<double>& v, double& mean, double& sd) {
  mean = sd = 0;
  if (v.empty()) return;
  for (double x : v) mean += x;
  mean /= static_cast<double>(v.size());
  if (v.size() < 2) return;
  for (double x : v) sd += (x - mean) * (x - mean);
  sd = std::sqrt(sd / static_cast<double>(v.size() - 1));
}
}  // namespace

Result<DrapeSeries> run_drape_series(const FabricParams& fabric, const DrapeTestOptions& opt,
                                     int seeds, int threads) {
  if (seeds < 1) return make_error("drape test", "seeds must be at least 1");
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<Result<DrapeTestResult>> out(seeds, Error{"not run"});
  const int nt = std::clamp(threads, 1, seeds);
  std::vector<std::thread> workers;
  for (int w = 0; w < nt; ++w) {
    workers.emplace_back([&, w] {
      for (int s = w; s < seeds; s += nt) {
        DrapeTestOptions o = opt;
        o.seed = opt.seed + static_cast<uint64_t>(s);
        out[s] = run_drape_test(fabric, o);
      }
    });
  }
  for (auto& t : workers) t.join();
  DrapeSeries series;
  std::vector<double> dc, nodes, rmin, rmax;
  for (auto& r : out) {
    if (!r) return Error{r.error()};
    dc.push_back(r->measures.dc);
    nodes.push_back(r->measures.nodes);
    rmin.push_back(r->measures.r_min);
    rmax.push_back(r->measures.r_max);
    series.runs.push_back(std::move(*r));
  }
  double sd_unused = 0;
  mean_sd(dc, series.dc_mean, series.dc_sd);
  mean_sd(nodes, series.nodes_mean, series.nodes_sd);
  if (!nodes.empty()) {
    std::sort(nodes.begin(), nodes.end());
    const size_t h = nodes.size() / 2;
    series.nodes_median = nodes.size() % 2 ? nodes[h] : 0.5 * (nodes[h - 1] + nodes[h]);
    series.nodes_min = static_cast<int>(nodes.front());
    series.nodes_max = static_cast<int>(nodes.back());
  }
  mean_sd(rmin, series.rmin_mean, sd_unused);
  mean_sd(rmax, series.rmax_mean, sd_unused);
  series.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return series;
}

std::string write_drape_mesh(const DrapeTestResult& result, const DrapeTestOptions& opt,
                             const std::string& path) {
  TriMesh disc;
  disc.name = "disc";
  constexpr int kSeg = 96;
  disc.vertices.emplace_back(0, 0, 0);
  for (int q = 0; q < kSeg; ++q) {
    const double a = 2 * kPi * q / kSeg;
    disc.vertices.emplace_back(0.5 * opt.disc_diameter * std::cos(a), 0,
                               -0.5 * opt.disc_diameter * std::sin(a));
  }
  for (int q = 0; q < kSeg; ++q) disc.triangles.push_back({0, 1 + q, 1 + (q + 1) % kSeg});
  return write_meshes(path, {cloth_to_mesh(result.cloth, "specimen"), disc});
}

}  // namespace drape::sim
