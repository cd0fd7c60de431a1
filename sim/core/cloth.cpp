// The cloth: panel generator (criss-cross triangulation), the two initial states (spread, rolled),
// mass lumping, vertex duplication for topology edits, validation and the state hash.
#include "sim/core/cloth.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>

namespace drape::sim {

int Cloth::duplicate_vertex(int src) {
  const int n = num_vertices();
  topo.material.push_back(topo.material[src]);
  topo.vertex_zone.push_back(topo.vertex_zone[src]);
  topo.vertex_origin.push_back(topo.vertex_origin[src]);
  state.x.push_back(state.x[src]);
  state.x_prev.push_back(state.x_prev[src]);
  state.v.push_back(state.v[src]);
  state.mass.push_back(state.mass[src]);
  state.inv_mass.push_back(state.inv_mass[src]);
  state.flags.push_back(state.flags[src]);
  return n;
}

void Cloth::relump_masses() {
  const int n = num_vertices();
  state.mass.assign(n, 0.0);
  state.inv_mass.assign(n, 0.0);
  // Each triangle's material-space area times the areal density, a third to each corner.
  for (const auto& t : topo.triangles) {
    const Vec2 e1 = topo.material[t[1]] - topo.material[t[0]];
    const Vec2 e2 = topo.material[t[2]] - topo.material[t[0]];
    const double area = 0.5 * std::abs(e1.x() * e2.y() - e1.y() * e2.x());
    const double m3 = area * fabric.areal_density / 3.0;
    for (int k = 0; k < 3; ++k) state.mass[t[k]] += m3;
  }
  for (int i = 0; i < n; ++i) {
    state.inv_mass[i] = (is_free(i) && state.mass[i] > 0) ? 1.0 / state.mass[i] : 0.0;
  }
}

std::string Cloth::validate() const {
  const size_t n = topo.material.size();
  std::ostringstream err;
  auto check_size = [&](size_t got, const char* what) {
    if (got != n) err << what << " has " << got << " entries, expected " << n << "; ";
  };
  check_size(topo.vertex_zone.size(), "vertex_zone");
  check_size(topo.vertex_origin.size(), "vertex_origin");
  check_size(state.x.size(), "x");
  check_size(state.x_prev.size(), "x_prev");
  check_size(state.v.size(), "v");
  check_size(state.mass.size(), "mass");
  check_size(state.inv_mass.size(), "inv_mass");
  check_size(state.flags.size(), "flags");
  if (topo.triangle_zone.size() != topo.triangles.size()) {
    err << "triangle_zone has " << topo.triangle_zone.size() << " entries, expected "
        << topo.triangles.size() << "; ";
  }
  if (!err.str().empty()) return err.str();
  for (size_t t = 0; t < topo.triangles.size(); ++t) {
    const auto& tri = topo.triangles[t];
    for (int k = 0; k < 3; ++k) {
      if (tri[k] < 0 || static_cast<size_t>(tri[k]) >= n) {
        err << "triangle " << t << " has vertex index " << tri[k] << " out of range [0, " << n
            << ")";
        return err.str();
      }
    }
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2]) {
      err << "triangle " << t << " is degenerate (repeated vertex)";
      return err.str();
    }
  }
  for (size_t i = 0; i < n; ++i) {
    if (!state.x[i].allFinite() || !state.x_prev[i].allFinite() || !state.v[i].allFinite() ||
        !topo.material[i].allFinite()) {
      err << "vertex " << i << " has a non-finite position, velocity or material coordinate";
      return err.str();
    }
    if (!std::isfinite(state.mass[i]) || state.mass[i] < 0 || !std::isfinite(state.inv_mass[i]) ||
        state.inv_mass[i] < 0) {
      err << "vertex " << i << " has an invalid mass " << state.mass[i];
      return err.str();
    }
    if (topo.vertex_origin[i] < 0 || static_cast<size_t>(topo.vertex_origin[i]) >= n) {
      err << "vertex " << i << " has origin " << topo.vertex_origin[i] << " out of range";
      return err.str();
    }
  }
  return {};
}

Cloth make_panel(const PanelSpec& spec, const FabricParams& fabric) {
  const int nx = spec.nx > 0
                     ? spec.nx
                     : std::max(2, static_cast<int>(std::lround(spec.width / spec.spacing)) + 1);
  const int ny = spec.ny > 0
                     ? spec.ny
                     : std::max(2, static_cast<int>(std::lround(spec.height / spec.spacing)) + 1);
  const double du = spec.width / (nx - 1);
  const double dv = spec.height / (ny - 1);
  Cloth c;
  c.fabric = fabric;
  c.topo.grid_nx = nx;
  c.topo.grid_ny = ny;
  c.topo.spacing = std::sqrt(du * dv);
  const int n = nx * ny;
  c.topo.material.resize(n);
  c.topo.vertex_zone.assign(n, 0);
  c.topo.vertex_origin.resize(n);
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const int k = j * nx + i;
      c.topo.material[k] = Vec2(i * du, j * dv);
      c.topo.vertex_origin[k] = k;
    }
  }
  // Criss-cross: the cell diagonal alternates like a checkerboard, so the mesh has no
  // preferred shear direction. Both triangles counter-clockwise in (u, v).
  c.topo.triangles.reserve(static_cast<size_t>(2) * (nx - 1) * (ny - 1));
  for (int j = 0; j + 1 < ny; ++j) {
    for (int i = 0; i + 1 < nx; ++i) {
      const int a = j * nx + i, b = a + 1, d = a + nx, e = d + 1;  // a b bottom, d e top
      if ((i + j) % 2 == 0) {
        c.topo.triangles.push_back({a, b, e});
        c.topo.triangles.push_back({a, e, d});
      } else {
        c.topo.triangles.push_back({a, b, d});
        c.topo.triangles.push_back({b, e, d});
      }
    }
  }
  c.topo.triangle_zone.assign(c.topo.triangles.size(), 0);
  c.state.x.resize(n);
  c.state.flags.assign(n, 0);
  place_spread(c, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY());
  c.relump_masses();
  return c;
}

void place_spread(Cloth& cloth, const Vec3& origin, const Vec3& axis_u, const Vec3& axis_v) {
  const Vec3 au = axis_u.normalized(), av = axis_v.normalized();
  const int n = cloth.num_vertices();
  cloth.state.x.resize(n);
  for (int i = 0; i < n; ++i) {
    const Vec2& m = cloth.topo.material[i];
    cloth.state.x[i] = origin + m.x() * au + m.y() * av;
  }
  cloth.state.x_prev = cloth.state.x;
  cloth.state.v.assign(n, Vec3::Zero());
}

void place_rolled(Cloth& cloth, const Vec3& origin, const Vec3& axis_u, const Vec3& up,
                  double inner_radius) {
  const int n = cloth.num_vertices();
  const Vec3 au = axis_u.normalized();
  const Vec3 w = (up - up.dot(au) * au).normalized();  // up, made perpendicular to the roll axis
  const Vec3 t = au.cross(w);                          // horizontal, across the roll
  double vmax = 0;
  for (int i = 0; i < n; ++i) vmax = std::max(vmax, cloth.topo.material[i].y());
  // Archimedean spiral r(phi) = r0 + b phi, layers one pitch apart (2 cloth thicknesses plus a
  // grid spacing, so layers do not touch). Arc length s(phi) = r0 phi + b phi^2 / 2, solved for
  // phi at each v.
  const double pitch = 2.0 * cloth.fabric.thickness + cloth.topo.spacing;
  const double b = pitch / (2.0 * M_PI);
  const double r0 = std::max(inner_radius, 1e-4);
  auto phi_of = [&](double s) { return (-r0 + std::sqrt(r0 * r0 + 2.0 * b * s)) / b; };
  const double phi_max = phi_of(vmax);
  const double r_outer = r0 + b * phi_max;
  // The outermost point (v = vmax) lies at `origin`, at the bottom of the roll; the roll's axis
  // is r_outer above it.
  const Vec3 centre = origin + r_outer * w;
  for (int i = 0; i < n; ++i) {
    const Vec2& m = cloth.topo.material[i];
    const double phi = phi_of(m.y());
    const double r = r0 + b * phi;
    const double psi = phi_max - phi;  // 0 at the outer end, growing inwards
    cloth.state.x[i] = centre + m.x() * au + r * (-std::cos(psi) * w + std::sin(psi) * t);
  }
  cloth.state.x_prev = cloth.state.x;
  cloth.state.v.assign(n, Vec3::Zero());
}

namespace {
struct Fnv1a {
  uint64_t h = 1469598103934665603ull;
  void bytes(const void* p, size_t len) {
    const auto* c = static_cast<const unsigned char*>(p);
    for (size_t i = 0; i < len; ++i) {
      h ^= c[i];
      h *= 1099511628211ull;
    }
  }
};
}  // namespace

uint64_t state_hash(const Cloth& cloth) {
  Fnv1a f;
  for (const Vec3& p : cloth.state.x) {
    const double d[3] = {p.x(), p.y(), p.z()};
    f.bytes(d, sizeof d);
  }
  f.bytes(cloth.state.flags.data(), cloth.state.flags.size());
  for (const auto& t : cloth.topo.triangles) f.bytes(t.data(), sizeof(int32_t) * 3);
  return f.h;
}

}  // namespace drape::sim
