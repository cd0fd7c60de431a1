// Static relaxation of mapped cloth: fixed lines, weak pressure, collision.
#include "sim/draping/relax.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <utility>

#include "sim/core/scene_objects.hpp"
#include "sim/form/dress_form.hpp"
#include "sim/solvers/solver_newton.hpp"

namespace drape::sim {

void add_triangle_edges(const std::vector<std::array<int32_t, 3>>& tris,
                        const std::vector<Vec2>& material, int off, RelaxProblem& p) {
  std::map<std::pair<int, int>, int> seen;
  for (const auto& t : tris)
    for (int k = 0; k < 3; ++k) {
      int a = t[k], b = t[(k + 1) % 3];
      if (a > b) std::swap(a, b);
      if (!seen.emplace(std::make_pair(a, b), 1).second) continue;
      p.edges.push_back({a + off, b + off});
      p.rest.push_back((material[a] - material[b]).norm());
    }
}

void edge_strain(const RelaxProblem& p, double* max_strain, double* rms_strain) {
  double mx = 0, s2 = 0;
  for (size_t e = 0; e < p.edges.size(); ++e) {
    const double len = (p.x[p.edges[e][0]] - p.x[p.edges[e][1]]).norm();
    const double s = len / p.rest[e] - 1.0;
    mx = std::max(mx, std::abs(s));
    s2 += s * s;
  }
  if (max_strain) *max_strain = mx;
  if (rms_strain) *rms_strain = p.edges.empty() ? 0 : std::sqrt(s2 / p.edges.size());
}

RelaxStats relax_gauss_seidel(RelaxProblem& p, const MappingSurface& surf,
                              const RelaxOptions& opt) {
  const auto t0 = std::chrono::steady_clock::now();
  const int nv = static_cast<int>(p.x.size());
  if (p.fixed.size() != p.x.size()) p.fixed.resize(p.x.size(), 0);
  std::vector<double> w(nv);
  for (int i = 0; i < nv; ++i) w[i] = p.fixed[i] ? 0.0 : 1.0;
  auto& x = p.x;
  for (int it = 0; it < opt.iterations; ++it) {
    // Weak pressure: a small step toward the section centre (the smoothing hand).
    for (int i = 0; i < nv; ++i) {
      if (!w[i]) continue;
      const Vec2 c = surf.centre(x[i].y());
      Vec3 r(x[i].x() - c.x(), 0, x[i].z() - c.y());
      const double rn = r.norm();
      if (rn > 1e-9) x[i] -= opt.pressure_step * r / rn;
    }
    // Inextensible-ish membrane: project every edge to its rest length (Gauss-Seidel).
    for (size_t e = 0; e < p.edges.size(); ++e) {
      const int a = p.edges[e][0], b = p.edges[e][1];
      const double ws = w[a] + w[b];
      if (ws == 0) continue;
      Vec3 d = x[b] - x[a];
      const double len = d.norm();
      if (len < 1e-12) continue;
      const Vec3 corr = (len - p.rest[e]) / (len * ws) * d;
      x[a] += w[a] * corr;
      x[b] -= w[b] * corr;
    }
    // Seams: stiff ties of a vertex onto a point of the other seam's polyline.
    for (const SeamTie& s : p.seams) {
      const Vec3 target = (1 - s.t) * x[s.b0] + s.t * x[s.b1];
      const Vec3 c = x[s.a] - target;
      const double ws = w[s.a] + (1 - s.t) * (1 - s.t) * w[s.b0] + s.t * s.t * w[s.b1];
      if (ws == 0) continue;
      x[s.a] -= w[s.a] / ws * c;
      x[s.b0] += w[s.b0] * (1 - s.t) / ws * c;
      x[s.b1] += w[s.b1] * s.t / ws * c;
    }
    // Grain control: consecutive warp nodes stay straight in the horizontal tangent direction.
    for (const auto& g : p.grain) {
      if (!w[g[1]]) continue;
      const Vec2 c = surf.centre(x[g[1]].y());
      const double th = std::atan2(x[g[1]].x() - c.x(), x[g[1]].z() - c.y());
      const Vec3 t(std::cos(th), 0, -std::sin(th));
      x[g[1]] += 0.5 * ((0.5 * (x[g[0]] + x[g[2]]) - x[g[1]]).dot(t)) * t;
    }
    for (const PlaneTie& pl : p.planes) x[pl.v] -= pl.n.dot(x[pl.v] - pl.p) * pl.n;
    for (const EdgePlaneTie& pl : p.edge_planes) {
      const double wa = w[pl.a] * (1 - pl.t), wb = w[pl.b] * pl.t;
      const double ws = wa * (1 - pl.t) + wb * pl.t;
      if (ws < 1e-12) continue;
      const double c = pl.n.dot((1 - pl.t) * x[pl.a] + pl.t * x[pl.b] - pl.p);
      x[pl.a] -= wa / ws * c * pl.n;
      x[pl.b] -= wb / ws * c * pl.n;
    }
    for (int i : p.on_surface) {
      const Vec2 c = surf.centre(x[i].y());
      const double dx = x[i].x() - c.x(), dz = x[i].z() - c.y();
      const double rn = std::hypot(dx, dz);
      const double rs = surf.radius(x[i].y(), std::atan2(dx, dz)) + opt.collision_offset;
      if (rn > 1e-9) {
        x[i].x() = c.x() + dx * rs / rn;
        x[i].z() = c.y() + dz * rs / rn;
      }
    }
    // Collision by section lookup, on the mapping surface (ease, hip shape).
    if (opt.collide)
      for (int i = 0; i < nv; ++i) {
        if (!w[i]) continue;
        const Vec2 c = surf.centre(x[i].y());
        const double dx = x[i].x() - c.x(), dz = x[i].z() - c.y();
        const double rn = std::hypot(dx, dz);
        const double rs = surf.radius(x[i].y(), std::atan2(dx, dz)) + opt.collision_offset;
        if (rn < rs && rn > 1e-9) {
          x[i].x() = c.x() + dx * rs / rn;
          x[i].z() = c.y() + dz * rs / rn;
        }
      }
  }
  RelaxStats st;
  st.backend = "gauss-seidel";
  st.iterations = opt.iterations;
  edge_strain(p, &st.max_strain, &st.rms_strain);
  st.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return st;
}

namespace {

// Grid rows holding a horizontal reference line at height y: the row on it, or both rows
// around it when it falls between rows.
std::pair<int, int> rows_of_line(const Panel& panel, const PieceMapping& pm, double y) {
  const double f = pm.v_of_y(y) / panel.dy;
  const int lo = static_cast<int>(std::floor(f + 1e-6)), hi = static_cast<int>(std::ceil(f - 1e-6));
  return {std::clamp(lo, 0, panel.ny - 1), std::clamp(hi, 0, panel.ny - 1)};
}

// Fixed lines of a mapped panel: the hip rows (pinned), the waist rows (held on the surface and
// on their meridian planes but free to slide up or down: pinned at their mapped heights the
// warp threads between waist and hip stay stretched by the form's slope, eq. 2-1 maps by height
// not by surface distance; left free the cloth bridges the waist hollow and the waist widths grow
// by ~18 mm), the centre column, the node nearest the side line in every row (pinned by the
// static solver; the Gauss-Seidel relaxation holds the side line between nodes instead,
// side_line_ties). Returns per-vertex role: 1 pinned, 2 centre, 3 side, 4 waist.
std::vector<uint8_t> fixed_line_roles(const Panel& panel, const MappingSurface& surf,
                                      const PieceMapping& pm) {
  const auto& topo = panel.cloth.topo;
  std::vector<uint8_t> role(topo.num_vertices(), 0);
  const auto [h0, h1] = rows_of_line(panel, pm, surf.form().landmarks().hip_y);
  const auto [w0, w1] = rows_of_line(panel, pm, surf.form().landmarks().waist_y);
  const int centre_i = panel.design.centre_edge_left ? 0 : panel.nx - 1;
  const int last_zone = panel.num_zones() - 1;
  for (int v = 0; v < topo.num_vertices(); ++v) {
    const int j = static_cast<int>(std::lround(topo.material[v].y() / panel.dy));
    if (j == h0 || j == h1) role[v] = 1;
    if ((j == w0 || j == w1) && !role[v]) role[v] = 4;
  }
  for (int j = 0; j < panel.ny; ++j) {
    const double y = pm.y_of_v(j * panel.dy);
    if (!role[j * panel.nx + centre_i]) role[j * panel.nx + centre_i] = 2;
    const ArcTable T = ArcTable::build(surf, y, pm.theta_centre, pm.dir);
    const double l_side = pm.l_at(last_zone, y, pm.theta_side, T);
    const int li = static_cast<int>(std::lround(l_side / panel.dx));
    if (li <= 0 || li >= panel.nx) continue;
    const int i = panel.design.centre_edge_left ? li : panel.nx - 1 - li;
    int v = j * panel.nx + i;
    // On a slit column above its tip the far-side twin belongs to the last zone.
    for (const PanelSlit& s : panel.slits)
      if (s.column == i && j > s.tip_row) v = s.far_nodes[j - s.tip_row - 1];
    if (!role[v]) role[v] = 3;
  }
  return role;
}

// The side line held where the mapping puts it: in every row between the hip and the top, the
// point of the row at the side line's weft distance (between two grid nodes, interpolated) on
// the vertical plane through the section centre at the side line's angle. Holding the nearest
// node instead (up to half a spacing off the line, on its own meridian) jumps by a column
// wherever the line crosses one, and the cloth between those rows shows it as a bump on the
// side seam.
std::vector<EdgePlaneTie> side_line_ties(const Panel& panel, const MappingSurface& surf,
                                         const PieceMapping& pm) {
  std::vector<EdgePlaneTie> ties;
  const int last_zone = panel.num_zones() - 1;
  const auto node = [&](int i, int j) {
    // On a slit column above its tip the far-side twin belongs to the last zone.
    for (const PanelSlit& s : panel.slits)
      if (s.column == i && j > s.tip_row) return s.far_nodes[j - s.tip_row - 1];
    return j * panel.nx + i;
  };
  for (int j = 0; j < panel.ny; ++j) {
    const double y = pm.y_of_v(j * panel.dy);
    const ArcTable T = ArcTable::build(surf, y, pm.theta_centre, pm.dir);
    const double f = pm.l_at(last_zone, y, pm.theta_side, T) / panel.dx;
    const int l0 = static_cast<int>(std::floor(f));
    if (l0 < 0 || l0 + 1 >= panel.nx) continue;
    const bool left = panel.design.centre_edge_left;
    const int i0 = left ? l0 : panel.nx - 1 - l0, i1 = left ? l0 + 1 : panel.nx - 2 - l0;
    const Vec2 c = surf.centre(y);
    ties.push_back({node(i0, j), node(i1, j), f - l0, Vec3(c.x(), 0, c.y()),
                    Vec3(std::cos(pm.theta_side), 0, -std::sin(pm.theta_side))});
  }
  return ties;
}

}  // namespace

RelaxStats relax_panel(Panel& panel, const MappingSurface& surf, const PieceMapping& pm,
                       const PanelRelaxOptions& opt) {
  Cloth& cloth = panel.cloth;
  const std::vector<uint8_t> role = fixed_line_roles(panel, surf, pm);
  const int nv = cloth.num_vertices();
  if (opt.use_static_solver) {
    const auto t0 = std::chrono::steady_clock::now();
    for (int i = 0; i < nv; ++i) {
      cloth.state.flags[i] = role[i] ? kFlagPinned : 0;
      cloth.state.inv_mass[i] = role[i] ? 0.0 : 1.0 / cloth.state.mass[i];
    }
    SceneObjects scene;
    scene.form = std::shared_ptr<const DressForm>(&surf.form(), [](const DressForm*) {});
    scene.floor = false;
    scene.offset = surf.offset() + 1e-4;
    StaticOptions so;
    so.energy.gravity = false;
    so.energy.pressure = opt.pressure_pa;
    so.max_iterations = std::max(10, opt.iterations / 4);
    const StaticResult r = relax_static(cloth, scene, so);
    for (int i = 0; i < nv; ++i) cloth.state.flags[i] = 0;
    RelaxProblem p;
    p.x = cloth.state.x;
    add_triangle_edges(cloth.topo.triangles, cloth.topo.material, 0, p);
    RelaxStats st;
    st.backend = "newton-static";
    st.iterations = r.iterations;
    st.converged = r.converged;
    edge_strain(p, &st.max_strain, &st.rms_strain);
    st.ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    return st;
  }
  RelaxProblem p;
  p.x = cloth.state.x;
  add_triangle_edges(cloth.topo.triangles, cloth.topo.material, 0, p);
  p.fixed.assign(nv, 0);
  // Centre and side line nodes slide on the vertical plane through their own section centre
  // and their mapped angle (a plane through one common axis point conflicts with the pinned
  // hip row where the section centres move with height; the side node nearest the side line
  // is up to half a spacing off it, so it keeps its own meridian rather than the side line's).
  for (int i = 0; i < nv; ++i) {
    if (role[i] == 1) p.fixed[i] = 1;
    if (role[i] == 4) p.on_surface.push_back(i);
    if (role[i] == 2 || role[i] == 4) {
      const Vec3& xi = p.x[i];
      const Vec2 c = surf.centre(xi.y());
      const double th = std::atan2(xi.x() - c.x(), xi.z() - c.y());
      p.planes.push_back({i, Vec3(c.x(), 0, c.y()), Vec3(std::cos(th), 0, -std::sin(th))});
    }
  }
  p.edge_planes = side_line_ties(panel, surf, pm);
  if (opt.grain_control) {
    const int nx = panel.nx;
    for (const PanelSlit& s : panel.slits)
      for (int i = std::max(0, s.column - 3); i <= std::min(nx - 1, s.column + 3); ++i) {
        for (int side = 0; side < (i == s.column ? 2 : 1); ++side) {
          const auto node = [&](int j) {
            if (i == s.column && side == 1 && j > s.tip_row) return s.far_nodes[j - s.tip_row - 1];
            return j * nx + i;
          };
          for (int j = std::max(1, s.tip_row - 3); j + 1 < panel.ny; ++j)
            p.grain.push_back({node(j - 1), node(j), node(j + 1)});
        }
      }
  }
  RelaxOptions ro;
  ro.iterations = opt.iterations;
  RelaxStats st = relax_gauss_seidel(p, surf, ro);
  cloth.state.x = p.x;
  cloth.state.x_prev = p.x;
  return st;
}

}  // namespace drape::sim
