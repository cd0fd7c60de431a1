#include "sim/solvers/solver_newton.hpp"

#include <Eigen/CholmodSupport>
#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <stdexcept>

#include "sim/core/stopwatch.hpp"

namespace drape::sim {

namespace {
using SpMat = Eigen::SparseMatrix<double>;
constexpr double kStickyReach = 1e-3;  // m, see minimise()
}  // namespace

// The Newton matrix (lower triangle only: both factorisations read nothing else) with a pattern
// fixed while the free set and the topology stay the same: the first assembly records the
// (row, col) of every contribution, later ones add each value straight into its slot of the
// compressed storage (no triplet sort per iteration). The symbolic analysis (ordering,
// elimination tree, supernodes) is done once per pattern as well.
struct NewtonSolver::Linear {
  SpMat H;
  std::vector<std::pair<int, int>> entries;  // record pass: (row, col), row >= col
  std::vector<int> slot;                     // value index of every contribution, in order
  size_t next = 0;
  LinearSolver kind = LinearSolver::kCholmod;
  std::unique_ptr<Eigen::CholmodSupernodalLLT<SpMat, Eigen::Lower>> chol;
  std::unique_ptr<Eigen::SimplicialLDLT<SpMat, Eigen::Lower>> ldlt;

  void add(int r, int c, double v, bool record) {
    if (r < c) return;
    if (record) {
      entries.emplace_back(r, c);
    } else {
      H.valuePtr()[slot[next++]] += v;
    }
  }
  // Builds the pattern from the recorded entries and the slot of each.
  void build_pattern(int n) {
    std::vector<Eigen::Triplet<double>> t;
    t.reserve(entries.size());
    for (const auto& [r, c] : entries) t.emplace_back(r, c, 0.0);
    H.resize(n, n);
    H.setFromTriplets(t.begin(), t.end());
    H.makeCompressed();
    slot.resize(entries.size());
    const int* outer = H.outerIndexPtr();
    const int* inner = H.innerIndexPtr();
    for (size_t k = 0; k < entries.size(); ++k) {
      const auto [r, c] = entries[k];
      slot[k] =
          static_cast<int>(std::lower_bound(inner + outer[c], inner + outer[c + 1], r) - inner);
    }
    entries.clear();
    entries.shrink_to_fit();
  }
  void analyse(bool trace) {
    factor_ok = false;
    if (kind == LinearSolver::kCholmod) {
      chol = std::make_unique<Eigen::CholmodSupernodalLLT<SpMat, Eigen::Lower>>();
      chol->cholmod().print = 0;  // "not positive definite" is expected (exact H): no message
      chol->analyzePattern(H);
      if (trace)
        std::fprintf(stderr, "cholmod: n %ld nnz(H) %ld nnz(L) %.0f flops %.3g ordering %d\n",
                     static_cast<long>(H.rows()), static_cast<long>(H.nonZeros()),
                     chol->cholmod().lnz, chol->cholmod().fl,
                     chol->cholmod().method[chol->cholmod().selected].ordering);
    } else {
      ldlt = std::make_unique<Eigen::SimplicialLDLT<SpMat, Eigen::Lower>>();
      ldlt->analyzePattern(H);
    }
  }
  // Numeric factorisation. Returns false when it failed; `positive` tells whether the matrix
  // was positive definite (LL^T succeeded; LDL^T: every pivot > 0).
  bool factorize(bool& positive) {
    if (kind == LinearSolver::kCholmod) {
      chol->factorize(H);
      positive = chol->info() == Eigen::Success;
      return positive;
    }
    ldlt->factorize(H);
    if (ldlt->info() != Eigen::Success) {
      positive = false;
      return false;
    }
    positive = ldlt->vectorD().minCoeff() > 0;
    return true;
  }
  void solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) const {
    if (kind == LinearSolver::kCholmod)
      x = chol->solve(b);
    else
      x = ldlt->solve(b);
  }
  // H x = b by conjugate gradients preconditioned with the current factorisation (of an
  // earlier H). False when the relative residual is not below `tol` within `max_it`
  // iterations, or on a direction of non-positive curvature (H not positive definite there).
  // On success x (started from 0) has b.x > 0: a descent direction of the model.
  bool pcg(const Eigen::VectorXd& b, Eigen::VectorXd& x, double tol, int max_it, int& its) {
    const auto Hs = H.selfadjointView<Eigen::Lower>();
    x.setZero(b.size());
    r = b;
    solve(r, z);
    p = z;
    double rz = r.dot(z);
    const double bn = b.norm();
    its = 0;
    if (!(bn > 0)) return true;
    while (its < max_it) {
      ++its;
      q.noalias() = Hs * p;
      const double pq = p.dot(q);
      if (!(pq > 0)) return false;
      const double a = rz / pq;
      x += a * p;
      r -= a * q;
      if (r.norm() <= tol * bn) return true;
      solve(r, z);
      const double rz1 = r.dot(z);
      p = z + (rz1 / rz) * p;
      rz = rz1;
    }
    return false;
  }
  bool factor_ok = false;  // the factorisation is of a positive definite matrix
  Eigen::VectorXd r, z, p, q;
};

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

// H = M/h^2 + sum element Hessians (PSD-projected unless `exact`) + mu M / (1e-2 s)^2 + contact
// blocks. `record`: only the pattern (every block is emitted whatever its value, so that the
// scatter order of later calls is the same).
void NewtonSolver::assemble(const Cloth& cloth, double inv_h2, double mu, bool exact, bool record) {
  const auto& S = cloth.state;
  const int n = cloth.num_vertices();
  Linear& L = *lin_;
  if (!record) {
    std::fill(L.H.valuePtr(), L.H.valuePtr() + L.H.nonZeros(), 0.0);
    L.next = 0;
  }
  auto add_block = [&](int a, int b, const auto& B) {
    const int da = dof_[a], db = dof_[b];
    if (da < 0 || db < 0) return;
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < 3; ++r) L.add(3 * da + r, 3 * db + c, B(r, c), record);
  };
  for (int i = 0; i < n; ++i) {
    if (dof_[i] < 0) continue;
    const double d = inv_h2 * S.mass[i] + mu * S.mass[i] / 1e-4;
    Mat3 B = d * Mat3::Identity();
    const int ci = energy_.contact_of(i);
    if (ci >= 0 && contact_active_[ci]) {
      const Contact& c = energy_.contacts()[ci];
      B += energy_.contact_stiffness() * c.n * c.n.transpose();
    }
    if (energy_.friction_on()) {
      Vec3 gf;
      Mat3 Hf;
      energy_.friction_gradient_hessian(i, S.x[i], gf, &Hf);
      B += Hf;
    }
    add_block(i, i, B);
  }
  // An element's (3k x 3k) Hessian H over its k vertices v, block by block.
  auto add_element = [&](const auto& v, int k, const auto& H) {
    for (int a = 0; a < k; ++a)
      for (int b = 0; b < k; ++b) add_block(v[a], v[b], H.template block<3, 3>(3 * a, 3 * b));
  };
  Mat9 H9;
  for (int t = 0; t < energy_.num_triangles(); ++t) {
    energy_.tri_hessian(t, S.x, H9, !exact);
    add_element(energy_.tri(t), 3, H9);
  }
  if (energy_.tensor_bending()) {
    // kTensor bending: the constant P (x) I3 (exact, PSD).
    if (!energy_.has_bending_matrix())
      throw std::logic_error("NewtonSolver: the energy was built with bending_matrix = false");
    const auto& off = energy_.bending_offsets();
    const auto& col = energy_.bending_columns();
    const auto& val = energy_.bending_values();
    for (int i = 0; i < n; ++i) {
      const int di = dof_[i];
      if (di < 0) continue;
      for (int k = off[i]; k < off[i + 1]; ++k) {
        const int dj = dof_[col[k]];
        if (dj < 0) continue;
        for (int r = 0; r < 3; ++r) L.add(3 * di + r, 3 * dj + r, val[k], record);
      }
    }
  } else {
    Mat12 H12;
    for (int hh = 0; hh < energy_.num_hinges(); ++hh) {
      energy_.hinge_hessian(hh, S.x, H12, !exact);
      add_element(energy_.hinge(hh), 4, H12);
    }
  }
  Eigen::Matrix<double, 6, 6> H6;
  for (int s = 0; s < energy_.num_springs(); ++s) {
    energy_.spring_hessian(s, S.x, H6, !exact);
    add_element(energy_.spring(s), 2, H6);
  }
}

int NewtonSolver::minimise(Cloth& cloth, const SceneObjects& scene, double h,
                           const std::vector<Vec3>* y, double tolerance, int max_iterations,
                           double& residual) {
  if (!energy_.up_to_date(cloth)) cook(cloth);
  energy_.set_form(&scene);
  counters_ = Counters{};
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
  // The energy may also have been rebuilt from outside (energy().build()): compare its element
  // counts with the ones the assembly pattern was recorded for.
  const std::array<size_t, 5> sig = {
      static_cast<size_t>(energy_.num_triangles()), static_cast<size_t>(energy_.num_hinges()),
      static_cast<size_t>(energy_.num_springs()), energy_.bending_columns().size(),
      energy_.tensor_bending() ? 1u : 0u};
  if (sig != pattern_sig_) changed = true;
  pattern_sig_ = sig;
  if (changed || nd != ndof_) analysed_ = false;
  if (!lin_ || lin_->kind != opt_.linear_solver) {
    lin_ = std::make_unique<Linear>();
    lin_->kind = opt_.linear_solver;
    analysed_ = false;
  }
  ndof_ = nd;
  const double inv_h2 = (h > 0 && std::isfinite(h)) ? 1.0 / (h * h) : 0.0;
  double wscale = 1e-12;
  for (int i = 0; i < n; ++i) wscale = std::max(wscale, S.mass[i] * kGravity);
  if (nd == 0) {
    residual = 0;
    return 0;
  }
  sticky_.assign(n, 0);
  rhs_.resize(3 * nd);
  dx_.resize(3 * nd);
  xtrial_.resize(n);
  // Exact Hessian (static mode): tried at every iteration unless it was not positive definite
  // recently (then `exact_hold` iterations with the projected one, doubling on each failure).
  const bool allow_exact = opt_.exact_hessian && inv_h2 == 0;
  int exact_hold = 0, exact_wait = 1;
  double mu = 0;  // Levenberg-Marquardt shift (static mode only)
  double best_res = std::numeric_limits<double>::infinity();
  int best_it = 0;
  double prev_step = 0;
  int it = 0;
  for (; it < max_iterations; ++it) {
    // Static mode: contact planes re-linearised at every iterate (Newton on the penalty of the
    // distance itself; the planes of a fixed point are those of its own positions).
    // Once the steps are below 0.1 um the planes stay (their change is second order in the
    // tangential slide, < 1e-10 m) and the last iterations converge quadratically.
    if (redetect_ && inv_h2 == 0 && it > 0 && prev_step > 1e-7)
      energy_.detect_contacts(cloth, scene);
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
    // The contact penalty's active set of the Newton model: the penetrating vertices. With
    // prediction (below) it starts from the previous iteration's final set instead (a vertex
    // the last model held on its plane stays held while within kStickyReach of it): the set
    // then changes little from one iteration to the next and few re-solves are needed.
    const auto& contacts = energy_.contacts();
    contact_active_.resize(contacts.size());
    const bool predict = opt_.contact_prediction && inv_h2 == 0;
    for (size_t k = 0; k < contacts.size(); ++k) {
      const double d = contacts[k].n.dot(S.x[contacts[k].vertex] - contacts[k].p);
      contact_active_[k] = d < 0 || (predict && sticky_[contacts[k].vertex] && d < kStickyReach);
    }
    // rhs of the model with the current active set: -(E's gradient) with the plane term
    // k d n of every held vertex above its plane added (and removed for a released one below).
    auto model_rhs = [&]() {
      model_rhs_ = rhs_;
      for (size_t k = 0; k < contacts.size(); ++k) {
        const Contact& c = contacts[k];
        const int dv = dof_[c.vertex];
        if (dv < 0) continue;
        const double d0 = c.n.dot(S.x[c.vertex] - c.p);
        if (contact_active_[k] && d0 >= 0)
          model_rhs_.segment<3>(3 * dv) -= energy_.contact_stiffness() * d0 * c.n;
        if (!contact_active_[k] && d0 < 0)
          model_rhs_.segment<3>(3 * dv) += energy_.contact_stiffness() * d0 * c.n;
      }
    };
    const auto ta = std::chrono::steady_clock::now();
    if (!analysed_) {
      lin_->entries.clear();
      assemble(cloth, inv_h2, mu, false, true);
      lin_->build_pattern(3 * nd);
      lin_->analyse(opt_.trace);
      analysed_ = true;
    }
    bool exact = allow_exact && exact_hold == 0;
    assemble(cloth, inv_h2, mu, exact, false);
    counters_.assemble_ms += ms_since(ta);
    // The system by CG on the last factorisation when there is one (static mode).
    const bool reuse = opt_.reuse_factorisation && inv_h2 == 0;
    auto try_cg = [&](const Eigen::VectorXd& b) {
      if (!reuse || !lin_->factor_ok) return false;
      const auto tc = std::chrono::steady_clock::now();
      int its = 0;
      const bool ok = lin_->pcg(b, cg_x_, opt_.reuse_cg_tolerance, opt_.reuse_max_cg, its);
      counters_.cg_iterations += its;
      counters_.cg_ms += ms_since(tc);
      if (ok) {
        ++counters_.cg_solves;
        std::swap(dx_, cg_x_);  // else dx_ keeps the last solved system's step
      }
      return ok;
    };
    if (predict) model_rhs();
    bool solved = try_cg(predict ? model_rhs_ : rhs_);
    auto tf = std::chrono::steady_clock::now();
    bool positive = solved;
    bool factored = solved;
    if (!solved) {
      factored = lin_->factorize(positive);
      lin_->factor_ok = factored && positive;
      ++counters_.factorisations;
    }
    if (!solved && exact && !positive) {
      // Not positive definite (wrinkles still moving, or a saddle): projected Hessian for a
      // while; retry the exact one later.
      ++counters_.not_positive;
      exact = false;
      exact_hold = exact_wait;
      exact_wait = std::min(2 * exact_wait, 16);
      counters_.factor_ms += ms_since(tf);
      const auto ta2 = std::chrono::steady_clock::now();
      assemble(cloth, inv_h2, mu, false, false);
      counters_.assemble_ms += ms_since(ta2);
      tf = std::chrono::steady_clock::now();
      factored = lin_->factorize(positive);
      lin_->factor_ok = factored && positive;
      ++counters_.factorisations;
    } else if (exact_hold > 0) {
      --exact_hold;
    }
    counters_.factor_ms += ms_since(tf);
    if (!factored) {
      mu = mu > 0 ? mu * 10 : 1e-6;
      continue;
    }
    if (!predict) {
      if (!solved) lin_->solve(rhs_, dx_);
    } else {
      if (!solved) lin_->solve(model_rhs_, dx_);
      // The model's contact term is the penalty itself, 1/2 k min(0, d + n.dx)^2 (same value
      // and gradient as E at dx = 0, convex): minimise it by updating the active set to the
      // contacts the step ends up penetrating (a step through a contact the model thought
      // inactive is what stalls the line search after each re-detection). Its minimiser is a
      // descent direction of E. A few passes; the last system that factorised is kept.
      for (int pass = 0; pass < 3; ++pass) {
        bool change = false;
        for (size_t k = 0; k < contacts.size(); ++k) {
          const Contact& c = contacts[k];
          const int dv = dof_[c.vertex];
          if (dv < 0) continue;
          const double d0 = c.n.dot(S.x[c.vertex] - c.p);
          const bool want = d0 + c.n.dot(dx_.segment<3>(3 * dv)) < 0;
          if (want != static_cast<bool>(contact_active_[k])) change = true;
          contact_active_[k] = want;
        }
        if (!change) break;
        model_rhs();
        const auto ta2 = std::chrono::steady_clock::now();
        assemble(cloth, inv_h2, mu, exact, false);
        counters_.assemble_ms += ms_since(ta2);
        ++counters_.contact_passes;
        // A few changed contact blocks: CG on the factorisation usually converges in a few
        // iterations (the change is of low rank).
        if (try_cg(model_rhs_)) continue;
        const auto tf2 = std::chrono::steady_clock::now();
        bool pos2 = false;
        const bool ok2 = lin_->factorize(pos2);
        lin_->factor_ok = ok2 && pos2;
        ++counters_.factorisations;
        counters_.factor_ms += ms_since(tf2);
        if (!ok2 || (exact && !pos2)) break;
        lin_->solve(model_rhs_, dx_);
      }
      std::fill(sticky_.begin(), sticky_.end(), 0);
      for (size_t k = 0; k < contacts.size(); ++k) sticky_[contacts[k].vertex] = contact_active_[k];
    }
    // Backtracking line search on G.
    const double g0 = objective(cloth, S.x, inv_h2, y);
    const double slope = -rhs_.dot(dx_);
    double alpha = 1.0;
    bool accepted = false;
    // Static mode, predicted decrease below 1e-13 of G: the Armijo test is decided by
    // round-off in G (it then accepts or rejects tiny steps at random and the quadratic
    // convergence is lost). Decide on the gradient instead: the full step (or half of it)
    // when it lowers |grad|_inf; a step of < 1e-10 m that does not is the round-off floor;
    // otherwise fall back to the Armijo test.
    const bool roundoff =
        opt_.line_search && inv_h2 == 0 && std::abs(slope) < 1e-13 * std::max(std::abs(g0), 1e-30);
    if (roundoff) {
      for (int ls = 0; ls < 2 && !accepted; ++ls, alpha *= 0.5) {
        for (int i = 0; i < n; ++i)
          xtrial_[i] = dof_[i] >= 0 ? Vec3(S.x[i] + alpha * dx_.segment<3>(3 * dof_[i])) : S.x[i];
        energy_.gradient(xtrial_, S.mass, grad_);
        double gtrial = 0;
        for (int i = 0; i < n; ++i)
          if (dof_[i] >= 0) gtrial = std::max(gtrial, grad_[i].cwiseAbs().maxCoeff());
        if (std::isfinite(gtrial) && gtrial < gmax) {
          accepted = true;
          break;
        }
      }
      if (!accepted && dx_.cwiseAbs().maxCoeff() < 1e-10) break;
      alpha = 1.0;
    }
    for (int ls = 0; !accepted && ls < (opt_.line_search ? 20 : 1); ++ls) {
      for (int i = 0; i < n; ++i)
        xtrial_[i] = dof_[i] >= 0 ? Vec3(S.x[i] + alpha * dx_.segment<3>(3 * dof_[i])) : S.x[i];
      const double g1 = objective(cloth, xtrial_, inv_h2, y);
      if (!opt_.line_search || (std::isfinite(g1) && g1 <= g0 + 1e-4 * alpha * slope)) {
        accepted = true;
        break;
      }
      alpha *= 0.5;
    }
    if (!accepted && !roundoff && std::abs(slope) < 1e-12 * std::max(std::abs(g0), 1e-30)) {
      // The predicted decrease is below the round-off of G itself: the Armijo test cannot
      // decide. Take the full step when it lowers the gradient residual.
      alpha = 1.0;
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
    if (exact)
      ++counters_.exact_steps;
    else
      ++counters_.projected_steps;
    const double step = alpha * dx_.cwiseAbs().maxCoeff();
    counters_.last_step = step;
    if (opt_.trace)
      std::fprintf(stderr, "newton it %d res %.3e alpha %.3g step %.3e exact %d mu %.1e\n", it,
                   residual, alpha, step, exact ? 1 : 0, mu);
    if (mu > 0) mu = std::max(mu * 0.3, 1e-9);
    if (mu < 1e-8) mu = 0;
    // Position rule: a full step below the tolerance whose length contracts (ratio r < 0.5
    // on the previous step: the travel left, <= step r / (1 - r), is below it as well).
    if (step_tolerance_ > 0 && alpha == 1.0 && step < step_tolerance_ && prev_step > 0 &&
        step < 0.5 * prev_step) {
      ++it;
      break;
    }
    prev_step = step;
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
    if (scene.friction > 0) {
      // Friction anchored where the step starts, sticking below a slip speed of
      // kFrictionSlipSpeed; the normal loads lagged from the forces there (the penalty's own
      // force at the start of an implicit step is often zero: the step before ended on the
      // plane, measured on a sliding cloth).
      energy_.set_friction(scene.friction, kFrictionSlipSpeed * h, S.x);
      energy_.lag_friction_load(S.x, S.mass);
    } else {
      energy_.clear_friction();
    }
    const Vec3 g = opt_.energy.gravity ? opt_.energy.g : Vec3::Zero();
    for (int i = 0; i < n; ++i) {
      xt_[i] = S.x[i];
      if (cloth.is_free(i)) {
        y_[i] = S.x[i] + (h * std::exp(-opt_.air_drag * h)) * S.v[i];
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
  no.linear_solver = opt.linear_solver;
  no.exact_hessian = opt.exact_hessian;
  no.contact_prediction = opt.contact_prediction;
  no.reuse_factorisation = opt.reuse_factorisation;
  no.reuse_max_cg = opt.reuse_max_cg;
  no.reuse_cg_tolerance = opt.reuse_cg_tolerance;
  NewtonSolver solver(no);
  solver.set_step_tolerance(opt.step_tolerance);
  solver.set_contact_redetection(opt.contacts && opt.redetect_every_iteration);
  auto& S = cloth.state;
  if (S.mass.size() != static_cast<size_t>(cloth.num_vertices())) lump_masses(cloth);
  double mmax = 0;
  for (double m : S.mass) mmax = std::max(mmax, m);
  solver.energy().build(cloth, opt.energy);
  solver.energy().set_contact_stiffness(opt.contact_stiffness > 0 ? opt.contact_stiffness : 1e4);
  // Contacts are linearised: redetect a few times as the cloth moves.
  int total = 0;
  double res = 0, prev_res = std::numeric_limits<double>::infinity();
  bool step_converged = false;
  // Friction: anchored where the solve starts (the state it polishes), the normal loads lagged
  // once per round (held fixed while minimising: a fixed objective for the line search; the
  // rounds end when a re-lagged round has nothing left to do); within friction_eps of its
  // anchor a contact vertex sticks.
  const bool friction = opt.contacts && opt.friction && scene.friction > 0;
  const std::vector<Vec3> anchor = friction ? S.x : std::vector<Vec3>{};
  for (int round = 0; round < 8; ++round) {
    if (opt.contacts) solver.energy().detect_contacts(cloth, scene);
    if (friction) {
      solver.energy().set_friction(scene.friction, opt.friction_eps, anchor);
      solver.energy().lag_friction_load(S.x, S.mass);
    }
    const int it =
        solver.minimise(cloth, scene, 0.0, nullptr, opt.tolerance, opt.max_iterations - total, res);
    total += it;
    ++r.rounds;
    const auto& c = solver.counters();
    r.exact_steps += c.exact_steps;
    r.factor_ms += c.factor_ms;
    r.factorisations += c.factorisations;
    r.cg_solves += c.cg_solves;
    r.cg_iterations += c.cg_iterations;
    r.cg_ms += c.cg_ms;
    r.last_step = c.last_step;
    step_converged = opt.step_tolerance > 0 && c.last_step > 0 && c.last_step < opt.step_tolerance;
    if (!opt.contacts || total >= opt.max_iterations || (round > 0 && it == 0)) break;
    // A round that stalled (round-off floor of the line search) without any contact to
    // re-linearise, or that ended on the round-off floor of the Newton step itself (steps of
    // 1e-12 m: the residual cannot go lower in double precision, the tolerance was below
    // it): another round cannot do better.
    if (res >= opt.tolerance && solver.energy().contacts().empty() && res > 0.99 * prev_res) break;
    if (res >= opt.tolerance && c.last_step < 1e-12 && res < 1e-6) break;
    prev_res = res;
    // Done when no vertex violates a freshly detected contact by more than 0.1 mm.
    solver.energy().detect_contacts(cloth, scene);
    bool violated = false;
    for (const auto& c2 : solver.energy().contacts())
      if (c2.n.dot(S.x[c2.vertex] - c2.p) < -1e-4) violated = true;
    if (!violated && (res < opt.tolerance || step_converged)) break;
  }
  for (int i = 0; i < cloth.num_vertices(); ++i) {
    S.v[i].setZero();
    S.x_prev[i] = S.x[i];
  }
  r.iterations = total;
  r.residual = res;
  r.converged = res < opt.tolerance || step_converged;
  r.energy = solver.energy().energy(S.x, S.mass);
  r.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

}  // namespace drape::sim
