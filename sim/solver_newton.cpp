#include "sim/solver_newton.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

namespace drape::sim {

NewtonSolver::NewtonSolver(NewtonOptions opt) : opt_(opt) {}
NewtonSolver::~NewtonSolver() = default;

void NewtonSolver::cook(const Cloth& cloth) {
  energy_.build(cloth, opt_.energy);
  analysed_ = false;
}

double NewtonSolver::objective(const Cloth& cloth, const std::vector<Vec3>& x, double inv_h2,
                               const std::vector<Vec3>* y) const {
  double e = energy_.energy(x, cloth.state.mass);
  if (inv_h2 > 0 && y) {
    for (int i = 0; i < cloth.num_vertices(); ++i)
      if (dof_[i] >= 0) e += 0.5 * inv_h2 * cloth.state.mass[i] * (x[i] - (*y)[i]).squaredNorm();
  }
  return e;
}

int NewtonSolver::minimise(Cloth& cloth, const SceneObjects& scene, double h,
                           const std::vector<Vec3>* y, double tolerance, int max_iterations,
                           double& residual) {
  if (!energy_.up_to_date(cloth)) cook(cloth);
  energy_.set_form(&scene);
  auto& S = cloth.state;
  const int n = cloth.num_vertices();
  // Free DOFs (re-analyse the pattern when the free set changed).
  int nd = 0;
  bool changed = static_cast<int>(dof_.size()) != n;
  dof_.resize(n);
  for (int i = 0; i < n; ++i) {
    const int d = cloth.is_free(i) ? nd++ : -1;
    if (dof_[i] != d) changed = true;
    dof_[i] = d;
  }
  if (changed || nd != ndof_) analysed_ = false;
  ndof_ = nd;
  const double inv_h2 = (h > 0 && std::isfinite(h)) ? 1.0 / (h * h) : 0.0;
  double wscale = 1e-12;
  for (int i = 0; i < n; ++i) wscale = std::max(wscale, S.mass[i] * kGravity);
  if (nd == 0) {
    residual = 0;
    return 0;
  }
  rhs_.resize(3 * nd);
  dx_.resize(3 * nd);
  xtrial_.resize(n);
  double mu = 0;  // Levenberg-Marquardt shift (static mode only)
  double best_res = std::numeric_limits<double>::infinity();
  int best_it = 0;
  int it = 0;
  for (; it < max_iterations; ++it) {
    energy_.gradient(S.x, S.mass, grad_);
    double gmax = 0;
    for (int i = 0; i < n; ++i) {
      if (dof_[i] < 0) continue;
      Vec3 gi = grad_[i];
      if (inv_h2 > 0) gi += inv_h2 * S.mass[i] * (S.x[i] - (*y)[i]);
      if (!gi.allFinite()) {
        residual = std::numeric_limits<double>::infinity();
        return it;
      }
      rhs_.segment<3>(3 * dof_[i]) = -gi;
      gmax = std::max(gmax, gi.cwiseAbs().maxCoeff());
    }
    residual = gmax / wscale;
    if (residual < tolerance) break;
    // Stalled near the round-off floor (residual already below 1e-5 of a vertex weight and no
    // 1 % progress in 10 iterations): stop. Far from it a plateau is normal (large rotations).
    if (residual < 0.99 * best_res) {
      best_res = residual;
      best_it = it;
    } else if (residual < 1e-5 && it - best_it >= 10) {
      break;
    }
    // Assemble H = M/h^2 + sum PSD element Hessians (+ mu M).
    trip_.clear();
    auto add_block = [&](int a, int b, const Mat3& B) {
      const int da = dof_[a], db = dof_[b];
      if (da < 0 || db < 0) return;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) trip_.emplace_back(3 * da + r, 3 * db + c, B(r, c));
    };
    for (int i = 0; i < n; ++i) {
      if (dof_[i] < 0) continue;
      double d = inv_h2 * S.mass[i] + mu * S.mass[i] / 1e-4;
      Mat3 B = d * Mat3::Identity();
      const int ci = energy_.contact_of(i);
      if (ci >= 0) {
        const Contact& c = energy_.contacts()[ci];
        if (c.n.dot(S.x[i] - c.p) < 0) B += energy_.contact_stiffness() * c.n * c.n.transpose();
      }
      add_block(i, i, B);
    }
    Mat9 H9;
    for (int t = 0; t < energy_.num_triangles(); ++t) {
      energy_.tri_hessian(t, S.x, H9, true);
      const auto& v = energy_.tri(t);
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) add_block(v[a], v[b], H9.block<3, 3>(3 * a, 3 * b));
    }
    if (energy_.tensor_bending()) {
      // kTensor bending: the constant P (x) I3 (exact, PSD).
      const auto& off = energy_.bending_offsets();
      const auto& col = energy_.bending_columns();
      const auto& val = energy_.bending_values();
      for (int i = 0; i < n; ++i) {
        const int di = dof_[i];
        if (di < 0) continue;
        for (int k = off[i]; k < off[i + 1]; ++k) {
          const int dj = dof_[col[k]];
          if (dj < 0) continue;
          for (int r = 0; r < 3; ++r) trip_.emplace_back(3 * di + r, 3 * dj + r, val[k]);
        }
      }
    } else {
      Mat12 H12;
      for (int hh = 0; hh < energy_.num_hinges(); ++hh) {
        energy_.hinge_hessian(hh, S.x, H12, true);
        const auto& v = energy_.hinge(hh);
        for (int a = 0; a < 4; ++a)
          for (int b = 0; b < 4; ++b) add_block(v[a], v[b], H12.block<3, 3>(3 * a, 3 * b));
      }
    }
    Eigen::Matrix<double, 6, 6> H6;
    for (int s = 0; s < energy_.num_springs(); ++s) {
      energy_.spring_hessian(s, S.x, H6, true);
      const auto& v = energy_.spring(s);
      for (int a = 0; a < 2; ++a)
        for (int b = 0; b < 2; ++b) add_block(v[a], v[b], H6.block<3, 3>(3 * a, 3 * b));
    }
    H_.resize(3 * nd, 3 * nd);
    H_.setFromTriplets(trip_.begin(), trip_.end());
    if (!ldlt_) ldlt_ = std::make_unique<Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>>();
    if (!analysed_) {
      ldlt_->analyzePattern(H_);
      analysed_ = true;
    }
    ldlt_->factorize(H_);
    if (ldlt_->info() != Eigen::Success) {
      mu = mu > 0 ? mu * 10 : 1e-6;
      continue;
    }
    dx_ = ldlt_->solve(rhs_);
    // Backtracking line search on G.
    const double g0 = objective(cloth, S.x, inv_h2, y);
    const double slope = -rhs_.dot(dx_);
    double alpha = 1.0;
    bool accepted = false;
    for (int ls = 0; ls < (opt_.line_search ? 20 : 1); ++ls) {
      for (int i = 0; i < n; ++i)
        xtrial_[i] = dof_[i] >= 0 ? Vec3(S.x[i] + alpha * dx_.segment<3>(3 * dof_[i])) : S.x[i];
      const double g1 = objective(cloth, xtrial_, inv_h2, y);
      if (!opt_.line_search || (std::isfinite(g1) && g1 <= g0 + 1e-4 * alpha * slope)) {
        accepted = true;
        break;
      }
      alpha *= 0.5;
    }
    if (!accepted && std::abs(slope) < 1e-12 * std::max(std::abs(g0), 1e-30)) {
      // The predicted decrease is below the round-off of G itself: the Armijo test cannot
      // decide. Take the full step when it lowers the gradient residual.
      for (int i = 0; i < n; ++i)
        xtrial_[i] = dof_[i] >= 0 ? Vec3(S.x[i] + dx_.segment<3>(3 * dof_[i])) : S.x[i];
      energy_.gradient(xtrial_, S.mass, grad_);
      double gtrial = 0;
      for (int i = 0; i < n; ++i) {
        if (dof_[i] < 0) continue;
        Vec3 gi = grad_[i];
        if (inv_h2 > 0) gi += inv_h2 * S.mass[i] * (xtrial_[i] - (*y)[i]);
        gtrial = std::max(gtrial, gi.cwiseAbs().maxCoeff());
      }
      accepted = std::isfinite(gtrial) && gtrial < gmax;
    }
    if (!accepted) {
      // No decrease: the step is at round-off level or the model is indefinite; regularise.
      if (inv_h2 == 0 && mu < 1e6) {
        mu = mu > 0 ? mu * 10 : 1e-6;
        continue;
      }
      break;
    }
    std::swap(S.x, xtrial_);
    if (mu > 0) mu = std::max(mu * 0.3, 1e-9);
    if (mu < 1e-8) mu = 0;
  }
  return it;
}

StepStats NewtonSolver::step(Cloth& cloth, const SceneObjects& scene, double dt) {
  StepStats st;
  if (!energy_.up_to_date(cloth)) cook(cloth);
  energy_.set_form(&scene);
  auto& S = cloth.state;
  const int n = cloth.num_vertices();
  const int ns = std::max(1, opt_.substeps);
  const double h = dt / ns;
  y_.resize(n);
  xt_.resize(n);
  for (int s = 0; s < ns; ++s) {
    const auto t0 = std::chrono::steady_clock::now();
    double mmax = 0;
    for (int i = 0; i < n; ++i) mmax = std::max(mmax, S.mass[i]);
    energy_.set_contact_stiffness(opt_.contact_stiffness > 0 ? opt_.contact_stiffness
                                                             : std::max(1e4, 1e3 * mmax / (h * h)));
    st.max_penetration = std::max(st.max_penetration, energy_.detect_contacts(cloth, scene));
    st.collision_ms +=
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    const Vec3 g = opt_.energy.gravity ? opt_.energy.g : Vec3::Zero();
    for (int i = 0; i < n; ++i) {
      xt_[i] = S.x[i];
      if (cloth.is_free(i)) {
        y_[i] = S.x[i] + (h * std::exp(-opt_.air_damping * h)) * S.v[i];
        S.x[i] = y_[i] + h * h * g;
      } else {
        y_[i] = S.x[i];
      }
    }
    double res = 0;
    st.iterations += minimise(cloth, scene, h, &y_, opt_.tolerance, opt_.max_iterations, res);
    st.residual = res;
    for (int i = 0; i < n; ++i) {
      S.x_prev[i] = xt_[i];
      if (cloth.is_free(i)) S.v[i] = (S.x[i] - xt_[i]) / h;
    }
    S.time += h;
    ++st.substeps;
  }
  return st;
}

StaticResult relax_static(Cloth& cloth, const SceneObjects& scene, const StaticOptions& opt) {
  const auto t0 = std::chrono::steady_clock::now();
  StaticResult r;
  NewtonOptions no;
  no.energy = opt.energy;
  no.contact_stiffness = opt.contact_stiffness;
  NewtonSolver solver(no);
  auto& S = cloth.state;
  if (S.mass.size() != static_cast<size_t>(cloth.num_vertices())) lump_masses(cloth);
  double mmax = 0;
  for (double m : S.mass) mmax = std::max(mmax, m);
  solver.energy().build(cloth, opt.energy);
  solver.energy().set_contact_stiffness(opt.contact_stiffness > 0 ? opt.contact_stiffness : 1e4);
  // Contacts are linearised: redetect a few times as the cloth moves.
  int total = 0;
  double res = 0, prev_res = std::numeric_limits<double>::infinity();
  for (int round = 0; round < 8; ++round) {
    if (opt.contacts) solver.energy().detect_contacts(cloth, scene);
    const int it =
        solver.minimise(cloth, scene, 0.0, nullptr, opt.tolerance, opt.max_iterations - total, res);
    total += it;
    if (!opt.contacts || total >= opt.max_iterations) break;
    // A round that stalled (round-off floor of the line search) without any contact to
    // re-linearise: another round cannot do better.
    if (res >= opt.tolerance && solver.energy().contacts().empty() && res > 0.99 * prev_res) break;
    prev_res = res;
    // Done when no vertex violates a freshly detected contact by more than 0.1 mm.
    std::vector<Vec3> before = S.x;
    solver.energy().detect_contacts(cloth, scene);
    bool violated = false;
    for (const auto& c : solver.energy().contacts())
      if (c.n.dot(S.x[c.vertex] - c.p) < -1e-4) violated = true;
    if (!violated && res < opt.tolerance) break;
  }
  for (int i = 0; i < cloth.num_vertices(); ++i) {
    S.v[i].setZero();
    S.x_prev[i] = S.x[i];
  }
  r.iterations = total;
  r.residual = res;
  r.converged = res < opt.tolerance;
  r.energy = solver.energy().energy(S.x, S.mass);
  r.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

}  // namespace drape::sim
