// The membrane strain of one triangle against its material (rest) shape, for strain maps (the
// renderer's colour map, the simulated garment's fit report).
#pragma once

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace drape::sim {

template <class S>
struct TriangleStrain {
  S strain = 0;  // the principal stretch farthest from 1, minus 1 (+ stretched, - compressed)
  S area = 0;    // the material area (0: degenerate, strain left 0)
};

// The triangle (x0, x1, x2) against its material triangle (m0, m1, m2): the principal stretches
// are the singular values of the deformation gradient F = [x1 - x0, x2 - x0] [m1 - m0, m2 - m0]^-1,
// the square roots of the eigenvalues of F^T F (closed form for a symmetric 2x2). A material
// area of min_area or less is degenerate.
template <class S>
TriangleStrain<S> triangle_strain_of(const Eigen::Matrix<S, 3, 1>& x0,
                                     const Eigen::Matrix<S, 3, 1>& x1,
                                     const Eigen::Matrix<S, 3, 1>& x2,
                                     const Eigen::Matrix<S, 2, 1>& m0,
                                     const Eigen::Matrix<S, 2, 1>& m1,
                                     const Eigen::Matrix<S, 2, 1>& m2, S min_area) {
  TriangleStrain<S> r;
  Eigen::Matrix<S, 2, 2> dm;
  dm.col(0) = m1 - m0;
  dm.col(1) = m2 - m0;
  const S area = S(0.5) * std::abs(dm.determinant());
  if (!(area > min_area)) return r;
  r.area = area;
  Eigen::Matrix<S, 3, 2> ds;
  ds.col(0) = x1 - x0;
  ds.col(1) = x2 - x0;
  const Eigen::Matrix<S, 3, 2> f = ds * dm.inverse();
  const Eigen::Matrix<S, 2, 2> cg = f.transpose() * f;  // right Cauchy-Green tensor
  const S tr = cg.trace(), det = cg.determinant();
  const S disc = std::sqrt(std::max(S(0.25) * tr * tr - det, S(0)));
  const S s1 = std::sqrt(std::max(S(0.5) * tr + disc, S(0))) - S(1);
  const S s2 = std::sqrt(std::max(S(0.5) * tr - disc, S(0))) - S(1);
  r.strain = std::abs(s1) >= std::abs(s2) ? s1 : s2;
  return r;
}

}  // namespace drape::sim
