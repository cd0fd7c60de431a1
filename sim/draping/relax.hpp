// Static relaxation of draped cloth on the mapping surface: weak pressure
// toward the form, fixed lines (hip line fixed, centre and side lines held on their planes),
// collision by section lookup, and optional grain control near darts. Two back ends: the
// solvers' Newton static solver (relax_static, sim/solvers/solver_newton.hpp) and a projected
// Gauss-Seidel edge relaxation of our own that also handles the hip shape below the hip.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "sim/draping/mapping.hpp"
#include "sim/draping/panel.hpp"

namespace drape::sim {

// x_a == (1 - t) x_b0 + t x_b1 (a seam joining vertices where counts differ).
struct SeamTie {
  int a = 0, b0 = 0, b1 = 0;
  double t = 0;
};
// Keeps vertex v on the plane n . (x - p) = 0 (a reference line it may slide along).
struct PlaneTie {
  int v = 0;
  Vec3 p, n;
};

// Keeps the point (1 - t) x_a + t x_b of an edge on the plane n . (x - p) = 0: a reference
// line that runs between grid columns, held where it is rather than at the nearest node.
struct EdgePlaneTie {
  int a = 0, b = 0;
  double t = 0;
  Vec3 p, n;
};

struct RelaxProblem {
  std::vector<Vec3> x;
  std::vector<std::array<int, 2>> edges;
  std::vector<double> rest;
  std::vector<uint8_t> fixed;
  std::vector<PlaneTie> planes;
  std::vector<EdgePlaneTie> edge_planes;
  std::vector<SeamTie> seams;
  std::vector<std::array<int, 3>> grain;  // consecutive warp nodes kept straight tangentially
  std::vector<int> on_surface;  // vertices held on the mapping surface (pulled in and pushed out)
};

// Unique triangle edges with rest lengths from material coordinates.
void add_triangle_edges(const std::vector<std::array<int32_t, 3>>& tris,
                        const std::vector<Vec2>& material, int vertex_offset, RelaxProblem& p);

struct RelaxOptions {
  int iterations = 200;
  double pressure_step = 2e-5;  // m per iteration toward the section centre (weak pressure)
  double collision_offset = 0;  // m outside the mapping surface
  bool collide = true;
};

struct RelaxStats {
  std::string backend;  // "newton-static" or "gauss-seidel"
  int iterations = 0;
  double max_strain = 0;  // max |length / rest - 1| over edges at the end
  double rms_strain = 0;
  double ms = 0;
  bool converged = true;
};

// Projected Gauss-Seidel relaxation (our own back end).
RelaxStats relax_gauss_seidel(RelaxProblem& p, const MappingSurface& surf, const RelaxOptions& opt);
// Edge strain statistics of positions x.
void edge_strain(const RelaxProblem& p, double* max_strain, double* rms_strain);

struct PanelRelaxOptions {
  int iterations = 200;
  bool grain_control = true;       // keep warp lines straight near darts
  bool use_static_solver = false;  // call relax_static (hip/centre/side lines pinned)
  double pressure_pa = 1.0;        // weak pressure for the static solver
};

// Relaxes the mapped panel in place with the fixed lines of the piece.
RelaxStats relax_panel(Panel& panel, const MappingSurface& surf, const PieceMapping& pm,
                       const PanelRelaxOptions& opt);

}  // namespace drape::sim
