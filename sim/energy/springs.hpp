// The study's mass-spring network (method 3.2, eq. 3-1) derived from any triangle mesh:
// every triangle edge, plus the pair of vertices opposite each diagonal edge (the cell's other
// diagonal). On the criss-cross grid this is exactly the 8-neighbour stencil: 4 structural and
// 4 diagonal springs per interior particle. Rebuild after every topology edit.
#pragma once

#include <cstdint>
#include <vector>

#include "sim/core/cloth.hpp"

namespace drape::sim {

enum class SpringKind : uint8_t { kStructural = 0, kDiagonal = 1 };

// Structure of arrays, one entry per spring.
struct Springs {
  std::vector<int32_t> a, b;  // vertex indices
  std::vector<double> rest;   // rest length (m) from material coordinates
  std::vector<double> k;      // stiffness (N/m)
  std::vector<SpringKind> kind;
  uint64_t topology_version = 0;  // of the cloth they were built from

  int size() const { return static_cast<int>(a.size()); }
  int count(SpringKind kd) const;
};

// Builds the springs of the cloth's current topology. A pair is structural when its
// material-space direction is within 22.5 degrees of the u or v axis, else diagonal.
//
// Stiffness from the fabric (documented in docs/sim-core.md):
//  * structural: k = S(dir) * w / L, with S = stretch_weft cos^2 + stretch_warp sin^2 of the
//    spring's material angle, L its rest length and w the width of cloth it represents
//    (sum over its triangles of area / L: the full cell width inside, half on a border).
//    On a square grid of muslin this is 8000 N/m along the warp at any spacing.
//  * diagonal: the two crossed diagonals of a cell carry its shear energy G gamma^2 A / 2
//    (G = fabric.shear); a diagonal at angle t stretches by gamma sin t cos t under shear gamma,
//    so k = G A / (2 L^2 sin^2 t cos^2 t) with A the cell area (both triangles); = G on squares.
// stiffness_scale multiplies every k (1 = the fabric; < 1 a softened cloth, e.g. for a demo).
Springs build_springs(const Cloth& cloth, double stiffness_scale = 1.0);

// Upper bound of the largest eigenvalue of M^-1 K (K the springs' stiffness matrix at rest) by
// Gershgorin: max over free vertices of 2 sum_j k_ij / m_i. The explicit Verlet step is stable
// for dt < 2 / sqrt(lambda_max), so 2 / sqrt(bound) is a safe step.
double max_eigenvalue_bound(const Cloth& cloth, const Springs& springs);

}  // namespace drape::sim
