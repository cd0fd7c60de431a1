// Flat panel with dart slits: grid, node duplication along slits, zones.
#include "sim/draping/panel.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "sim/form/dress_form.hpp"

namespace drape::sim {
namespace {

bool finite_pos(double x) {
  return std::isfinite(x) && x > 0;
}

int grid_count(double len, double spacing) {
  return std::max(2, static_cast<int>(std::lround(len / spacing)) + 1);
}

// Of the candidate triangles offered, the one whose barycentric coordinates of m have the
// largest minimum (>= 0: m inside it); the first such candidate wins ties.
struct BestTriangle {
  const Panel& panel;
  Vec2 m;
  int tri = -1;
  double min_coeff = -1e300;
  Vec3 bary{1.0 / 3, 1.0 / 3, 1.0 / 3};

  void offer(int ti) {
    const Vec3 bc = panel.barycentric(ti, m);
    if (bc.minCoeff() > min_coeff) {
      min_coeff = bc.minCoeff();
      tri = ti;
      bary = bc;
    }
  }
  int result(Vec3* out) const {
    if (out) *out = bary;
    return tri;
  }
};

// The grid cell index (clamped to the grid's count - 1 cells) of a material coordinate.
int cell_index(double coord, double spacing, int count) {
  return std::clamp(static_cast<int>(std::floor(coord / spacing)), 0, count - 2);
}

}  // namespace

std::string validate_panel(const PanelDesign& d, const std::string& where, const DressForm* form,
                           double ease, double top_y) {
  std::ostringstream e;
  if (!finite_pos(d.width)) return where + ".width: must be a positive number of metres";
  if (!finite_pos(d.height)) return where + ".height: must be a positive number of metres";
  if (!finite_pos(d.spacing) || d.spacing > d.width / 2 || d.spacing > d.height / 2)
    return where + ".spacing: must be positive and at most half the width and height";
  if (!std::isfinite(d.top_above_waist) || std::abs(d.top_above_waist) > 0.5)
    return where + ".top_above_waist: must be a finite offset within 0.5 m";
  if (form) {
    const double half = 0.5 * (form->girth_at(form->landmarks().hip_y) + ease);
    if (d.width > half) {
      e << where << ".width: panel larger than the form: " << d.width * 1000
        << " mm is wider than half the hip girth (" << half * 1000 << " mm)";
      return e.str();
    }
    if (top_y - d.height < 0) {
      e << where << ".height: panel larger than the form: " << d.height * 1000
        << " mm reaches below the floor from the top edge at " << top_y * 1000 << " mm";
      return e.str();
    }
  }
  const int nx = grid_count(d.width, d.spacing), ny = grid_count(d.height, d.spacing);
  const double dx = d.width / (nx - 1), dy = d.height / (ny - 1);
  std::vector<int> cols;
  for (size_t s = 0; s < d.slits.size(); ++s) {
    const DartSlit& sl = d.slits[s];
    const std::string f = where + ".slits[" + std::to_string(s) + "]";
    const int li =
        std::isfinite(sl.position) ? static_cast<int>(std::lround(sl.position / dx)) : -1;
    if (!std::isfinite(sl.position) || sl.position <= 0 || sl.position >= d.width || li < 1 ||
        li > nx - 2) {
      e << f << ".position: slit off the panel (" << sl.position * 1000 << " mm; the panel is "
        << d.width * 1000 << " mm wide and a slit needs one grid column on each side)";
      return e.str();
    }
    const int tip =
        std::isfinite(sl.depth) ? static_cast<int>(std::lround((d.height - sl.depth) / dy)) : -1;
    if (!std::isfinite(sl.depth) || sl.depth <= 0 || sl.depth >= d.height || tip < 1 ||
        tip > ny - 2) {
      e << f << ".depth: slit off the panel (" << sl.depth * 1000 << " mm; the panel is "
        << d.height * 1000 << " mm high)";
      return e.str();
    }
    if (!std::isfinite(sl.intake) || sl.intake < 0 || sl.intake >= sl.position) {
      e << f << ".intake: must be >= 0 and smaller than the slit's position";
      return e.str();
    }
    for (size_t o = 0; o < cols.size(); ++o) {
      if (std::abs(cols[o] - li) < 2) {
        e << f << ".position: overlapping slits: within one grid column of slits[" << o << "] ("
          << sl.position * 1000 << " mm vs " << d.slits[o].position * 1000 << " mm)";
        return e.str();
      }
    }
    cols.push_back(li);
  }
  return "";
}

Result<Panel> build_panel(const PanelDesign& d, const FabricParams& fabric,
                          const std::string& where) {
  if (std::string err = validate_panel(d, where); !err.empty()) return Error{err};
  Panel p;
  p.design = d;
  p.nx = grid_count(d.width, d.spacing);
  p.ny = grid_count(d.height, d.spacing);
  p.dx = d.width / (p.nx - 1);
  p.dy = d.height / (p.ny - 1);
  const int nx = p.nx, ny = p.ny;
  ClothTopology& t = p.cloth.topo;
  t.spacing = std::min(p.dx, p.dy);
  t.grid_nx = nx;
  t.grid_ny = ny;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) t.material.emplace_back(i * p.dx, j * p.dy);
  // Criss-cross: the cell diagonal alternates so no shear direction is preferred.
  for (int j = 0; j + 1 < ny; ++j)
    for (int i = 0; i + 1 < nx; ++i) {
      const int a = j * nx + i, b = a + 1, c = a + nx + 1, dd = a + nx;
      if ((i + j) % 2 == 0) {
        t.triangles.push_back({a, b, c});
        t.triangles.push_back({a, c, dd});
      } else {
        t.triangles.push_back({a, b, dd});
        t.triangles.push_back({b, c, dd});
      }
    }
  // Slits, ordered from the centre edge.
  std::vector<DartSlit> sl = d.slits;
  std::sort(sl.begin(), sl.end(),
            [](const DartSlit& a, const DartSlit& b) { return a.position < b.position; });
  std::vector<int> li_of;  // column index counted from the centre edge
  for (const DartSlit& s : sl) {
    PanelSlit ps;
    const int li = static_cast<int>(std::lround(s.position / p.dx));
    li_of.push_back(li);
    ps.column = d.centre_edge_left ? li : nx - 1 - li;
    ps.tip_row = static_cast<int>(std::lround((d.height - s.depth) / p.dy));
    ps.l = li * p.dx;
    ps.v_tip = ps.tip_row * p.dy;
    ps.intake = s.intake;
    ps.tip_node = ps.tip_row * nx + ps.column;
    p.slits.push_back(ps);
  }
  const auto li_vertex = [&](int i) { return d.centre_edge_left ? i : nx - 1 - i; };
  t.vertex_zone.assign(t.material.size(), 0);
  t.vertex_origin.resize(t.material.size());
  for (int v = 0; v < static_cast<int>(t.material.size()); ++v) {
    t.vertex_origin[v] = v;
    int z = 0;
    for (int li : li_of) z += li < li_vertex(v % nx) ? 1 : 0;
    t.vertex_zone[v] = z;
  }
  t.triangle_zone.assign(t.triangles.size(), 0);
  for (int j = 0; j + 1 < ny; ++j)
    for (int i = 0; i + 1 < nx; ++i) {
      const int cell_li = std::min(li_vertex(i), li_vertex(i + 1));
      int z = 0;
      for (int li : li_of) z += li <= cell_li ? 1 : 0;
      t.triangle_zone[p.cell_triangle(i, j, 0)] = z;
      t.triangle_zone[p.cell_triangle(i, j, 1)] = z;
    }
  // Node duplication: every slit node but the end gets a twin; the triangles
  // on the far side of the slit are re-pointed to the twins.
  for (size_t s = 0; s < p.slits.size(); ++s) {
    PanelSlit& ps = p.slits[s];
    const int far_cell = d.centre_edge_left ? ps.column : ps.column - 1;
    for (int j = ps.tip_row + 1; j < ny; ++j) {
      const int old = j * nx + ps.column;
      const int nw = static_cast<int>(t.material.size());
      t.material.push_back(t.material[old]);
      t.vertex_zone.push_back(static_cast<int>(s) + 1);
      t.vertex_origin.push_back(old);
      ps.near_nodes.push_back(old);
      ps.far_nodes.push_back(nw);
      for (int cj = j - 1; cj <= j; ++cj) {
        if (cj < ps.tip_row || cj > ny - 2) continue;
        for (int k = 0; k < 2; ++k)
          for (int32_t& vi : t.triangles[p.cell_triangle(far_cell, cj, k)])
            if (vi == old) vi = nw;
      }
    }
  }
  // State: flat in the plane z = 0, lumped masses from material areas.
  const int nv = t.num_vertices();
  ClothState& st = p.cloth.state;
  st.x.resize(nv);
  for (int v = 0; v < nv; ++v) st.x[v] = Vec3(t.material[v].x(), t.material[v].y(), 0);
  st.x_prev = st.x;
  st.v.assign(nv, Vec3::Zero());
  st.mass.assign(nv, 0.0);
  for (const auto& tri : t.triangles) {
    const Vec2 e1 = t.material[tri[1]] - t.material[tri[0]],
               e2 = t.material[tri[2]] - t.material[tri[0]];
    const double m = 0.5 * std::abs(e1.x() * e2.y() - e1.y() * e2.x()) * fabric.areal_density / 3;
    for (int vi : tri) st.mass[vi] += m;
  }
  st.inv_mass.resize(nv);
  for (int v = 0; v < nv; ++v) st.inv_mass[v] = st.mass[v] > 0 ? 1.0 / st.mass[v] : 0.0;
  st.flags.assign(nv, 0);
  p.cloth.fabric = fabric;
  return p;
}

Vec3 Panel::barycentric(int ti, const Vec2& m) const {
  const auto& t = cloth.topo;
  const auto& tri = t.triangles[ti];
  const Vec2 a = t.material[tri[0]], b = t.material[tri[1]], c = t.material[tri[2]];
  const double det = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
  const Vec2 q = m - a;
  const double l1 = (q.x() * (c - a).y() - q.y() * (c - a).x()) / det;
  const double l2 = ((b - a).x() * q.y() - (b - a).y() * q.x()) / det;
  return Vec3(1 - l1 - l2, l1, l2);
}

int Panel::locate(const Vec2& m, Vec3* bary) const {
  const int ci = cell_index(m.x(), dx, nx), cj = cell_index(m.y(), dy, ny);
  BestTriangle best{*this, m};
  for (int k = 0; k < 2; ++k) best.offer(cell_triangle(ci, cj, k));
  return best.result(bary);
}

int Panel::locate_in_zone(const Vec2& m, int zone, Vec3* bary) const {
  const int ci0 = cell_index(m.x(), dx, nx), cj0 = cell_index(m.y(), dy, ny);
  BestTriangle best{*this, m};
  for (int ci = std::max(0, ci0 - 1); ci <= std::min(nx - 2, ci0 + 1); ++ci)
    for (int cj = std::max(0, cj0 - 1); cj <= std::min(ny - 2, cj0 + 1); ++cj)
      for (int k = 0; k < 2; ++k) {
        const int ti = cell_triangle(ci, cj, k);
        if (cloth.topo.triangle_zone[ti] == zone) best.offer(ti);
      }
  if (best.tri < 0 || best.min_coeff < -0.5) return locate(m, bary);
  return best.result(bary);
}

}  // namespace drape::sim
