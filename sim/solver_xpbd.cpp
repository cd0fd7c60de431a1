#include "sim/solver_xpbd.hpp"

#include <chrono>
#include <cmath>

namespace drape::sim {

StepStats XpbdSolver::step(Cloth& cloth, const SceneObjects& scene, double dt) {
  StepStats st;
  if (!energy_.up_to_date(cloth)) energy_.build(cloth, opt_.energy);
  energy_.set_form(&scene);
  auto& S = cloth.state;
  const int n = cloth.num_vertices();
  const int ns = std::max(1, opt_.substeps);
  const double h = dt / ns;
  const FabricParams& fab = cloth.fabric;
  const double ku = fab.stretch_weft, kv = fab.stretch_warp, kg = fab.shear;
  lambda_tri_.resize(3 * energy_.num_triangles());
  lambda_hinge_.resize(energy_.num_hinges());
  lambda_spring_.resize(energy_.num_springs());
  xt_.resize(n);
  for (int s = 0; s < ns; ++s) {
    const auto t0 = std::chrono::steady_clock::now();
    st.max_penetration = std::max(st.max_penetration, energy_.detect_contacts(cloth, scene));
    st.collision_ms +=
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    for (int i = 0; i < n; ++i) {
      xt_[i] = S.x[i];
      if (S.inv_mass[i] > 0 && cloth.is_free(i))
        S.x[i] += h * S.v[i] + h * h * energy_.external_force(i, S.x[i], S.mass[i]) / S.mass[i];
    }
    std::fill(lambda_tri_.begin(), lambda_tri_.end(), 0.0);
    std::fill(lambda_hinge_.begin(), lambda_hinge_.end(), Vec3::Zero());
    std::fill(lambda_spring_.begin(), lambda_spring_.end(), 0.0);
    const double ih2 = 1.0 / (h * h);
    auto w = [&](int i) { return cloth.is_free(i) ? S.inv_mass[i] : 0.0; };
    for (int it = 0; it < opt_.iterations; ++it) {
      // Membrane: three strain constraints per triangle.
      for (int t = 0; t < energy_.num_triangles(); ++t) {
        const auto& v = energy_.tri(t);
        const auto& D = energy_.tri_D(t);
        for (int c = 0; c < 3; ++c) {
          const Vec3 fu = S.x[v[0]] * D(0, 0) + S.x[v[1]] * D(1, 0) + S.x[v[2]] * D(2, 0);
          const Vec3 fv = S.x[v[0]] * D(0, 1) + S.x[v[1]] * D(1, 1) + S.x[v[2]] * D(2, 1);
          Vec3 grads[3];
          double C;
          if (c == 0) {
            C = 0.5 * (fu.squaredNorm() - 1);
            for (int k = 0; k < 3; ++k) grads[k] = D(k, 0) * fu;
          } else if (c == 1) {
            C = 0.5 * (fv.squaredNorm() - 1);
            for (int k = 0; k < 3; ++k) grads[k] = D(k, 1) * fv;
          } else {
            C = 0.5 * fu.dot(fv);
            for (int k = 0; k < 3; ++k) grads[k] = 0.5 * (D(k, 0) * fv + D(k, 1) * fu);
          }
          const double A = energy_.rest_area(t);
          const double k = c == 0 ? ku : (c == 1 ? kv : 4.0 * kg);
          const double alpha = ih2 / (k * A);
          double denom = alpha;
          for (int q = 0; q < 3; ++q) denom += w(v[q]) * grads[q].squaredNorm();
          if (denom < 1e-20) continue;
          double& lam = lambda_tri_[3 * t + c];
          const double dl = (-C - alpha * lam) / denom;
          lam += dl;
          for (int q = 0; q < 3; ++q) S.x[v[q]] += w(v[q]) * dl * grads[q];
        }
      }
      for (int hh = 0; hh < energy_.num_hinges(); ++hh) {
        const auto& v = energy_.hinge(hh);
        const auto& K = energy_.hinge_K(hh);
        const Vec3 C = K[0] * S.x[v[0]] + K[1] * S.x[v[1]] + K[2] * S.x[v[2]] + K[3] * S.x[v[3]];
        const double alpha = ih2 / energy_.hinge_w(hh);
        double denom = alpha;
        for (int q = 0; q < 4; ++q) denom += w(v[q]) * K[q] * K[q];
        const Vec3 dl = (-C - alpha * lambda_hinge_[hh]) / denom;
        lambda_hinge_[hh] += dl;
        for (int q = 0; q < 4; ++q) S.x[v[q]] += w(v[q]) * K[q] * dl;
      }
      for (int sp = 0; sp < energy_.num_springs(); ++sp) {
        const auto& v = energy_.spring(sp);
        const Vec3 d = S.x[v[0]] - S.x[v[1]];
        const double l = d.norm();
        if (l < 1e-15) continue;
        const Vec3 nn = d / l;
        const double C = l - energy_.spring_rest(sp);
        const double alpha = ih2 / energy_.spring_k(sp);
        const double denom = w(v[0]) + w(v[1]) + alpha;
        if (denom < 1e-20) continue;
        const double dl = (-C - alpha * lambda_spring_[sp]) / denom;
        lambda_spring_[sp] += dl;
        S.x[v[0]] += w(v[0]) * dl * nn;
        S.x[v[1]] -= w(v[1]) * dl * nn;
      }
      energy_.project_contacts(S.x);
      ++st.iterations;
    }
    const double damp = std::exp(-opt_.damping * h);
    for (int i = 0; i < n; ++i) {
      S.x_prev[i] = xt_[i];
      if (cloth.is_free(i)) S.v[i] = damp * (S.x[i] - xt_[i]) / h;
    }
    S.time += h;
    ++st.substeps;
  }
  return st;
}

}  // namespace drape::sim
