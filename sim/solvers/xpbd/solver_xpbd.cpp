#include "sim/solvers/xpbd/solver_xpbd.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <thread>

#include "sim/core/memory.hpp"
#include "sim/core/stopwatch.hpp"

namespace drape::sim {

XpbdSolver::XpbdSolver(XpbdOptions opt)
    : opt_(opt), pool_(std::make_unique<ThreadPool>(std::max(1, opt.threads))) {
  pool_->set_min_parallel(64);
  // A cook's arrays reuse the memory the cook before it freed instead of fresh pages (a page
  // fault each 4 KiB: a third of a cut's re-cook at 128^2 on a virtual machine).
  retain_freed_memory();
}
XpbdSolver::~XpbdSolver() = default;

namespace {

// A bending coefficient this small against its block's largest is a cancelled zero (cook()).
constexpr double kZeroCoefficient = 1e-9;
// Sorts elements by colour: returns the colour offsets and fills `order`.
std::vector<int> colour_sorted(int n, int count, int k, const int32_t* verts, size_t stride,
                               std::vector<int>& order) {
  std::vector<int> off(count + 1), vs;
  vs.reserve(static_cast<size_t>(count) * k);
  for (int e = 0; e < count; ++e) {
    const int32_t* v = reinterpret_cast<const int32_t*>(reinterpret_cast<const char*>(verts) +
                                                        stride * static_cast<size_t>(e));
    for (int a = 0; a < k; ++a) vs.push_back(v[a]);
    off[e + 1] = static_cast<int>(vs.size());
  }
  std::vector<int> col;
  colour_elements(n, off, vs, order, col);
  return col;
}

template <class T>
void apply_order(std::vector<T>& items, const std::vector<int>& order) {
  std::vector<T> sorted;
  sorted.reserve(items.size());
  for (int e : order) sorted.push_back(items[e]);
  items.swap(sorted);
}

}  // namespace

void XpbdSolver::cook(const Cloth& cloth) {
  // Each part's wall time (last_cook(): what a re-cook after a cut costs, and where).
  using Clock = std::chrono::steady_clock;
  // Between its parts a cook waits while its thread's gate is closed (a cook ahead: the ticks
  // run meanwhile), counted in the part before.
  auto since = [](Clock::time_point& t) {
    pause_point();
    const auto now = Clock::now();
    const double ms = std::chrono::duration<double, std::milli>(now - t).count();
    t = now;
    return ms;
  };
  auto t = Clock::now();
  CookStats st;
  x_self_.clear();  // the self-collision pairs name triangles of the last topology
  self_.clear();
  const EnergyOptions eo = cook_energy_options(opt_);
  // An incremental cook keeps the bending rows and blocks of the triangles the change did not
  // reach (ClothEnergy::update); everything else is cooked again as in a full cook.
  ThreadPool* pool = cook_pool();
  if (opt_.incremental_cook)
    st.incremental = energy_.update(cloth, eo, pool);
  else
    energy_.build(cloth, eo, pool);
  for (char r : energy_.rebuilt_triangles()) st.rebuilt_triangles += r;
  st.energy_ms = since(t);
  const int n = cloth.num_vertices();
  cook_triangles(cloth);
  st.triangles_ms = since(t);
  cook_bending(n, st.incremental);
  st.bending_ms = since(t);
  cook_hinges_springs(n);
  const int S = scratch_slots_;
  lambda_tri_.assign(3 * tris_.size(), 0.0);
  lambda_hinge_.assign(hinges_.size(), Vec3::Zero());
  lambda_spring_.assign(springs_.size(), 0.0);
  // + the scratch vertices of padding, one per share of a colour's packs (xpbd::share_begin)
  xp_.assign(cooked_f32_ ? 0 : n + S, xpbd::P4{{0, 0, 0, 0}});
  xp8_.assign(cooked_f32_ ? n + S : 0, xpbd::P4f{{0, 0, 0, 0}});
  anchors_.clear();  // renewed at the next step
  tri_anchor8_.assign(static_cast<size_t>(6 * tlanes_) * float_tri_packs(), 0.0f);
  row_anchor8_.assign(72 * static_cast<size_t>(row_packs8_.packs()), 0.0f);
  st.other_ms = since(t);
  build_sweep(n);
  st.sweep_ms = since(t);
  w_.assign(n, -1.0);  // no valid inverse mass: the first set_w() marks w changed
  w0_.assign(n, -1.0);
  cook_pieces(n);
  st.other_ms += since(t);
  st.total_ms = st.energy_ms + st.triangles_ms + st.bending_ms + st.sweep_ms + st.other_ms;
  st.cooks = last_cook_.cooks + 1;
  last_cook_ = st;
}

// The triangles' constraint data, sorted by colour and packed for the kernels.
void XpbdSolver::cook_triangles(const Cloth& cloth) {
  const FabricParams& fab = cloth.fabric;
  const double kc[3] = {fab.stretch_weft, fab.stretch_warp, 4.0 * fab.shear};
  const int n = cloth.num_vertices();
  std::vector<int> order;
  tris_.clear();
  for (int t = 0; t < energy_.num_triangles(); ++t) {
    if ((t & 1023) == 0) pause_point();
    Tri T{};
    const auto& D = energy_.tri_D(t);
    for (int a = 0; a < 3; ++a) {
      T.v[a] = energy_.tri(t)[a];
      T.D[2 * a] = D(a, 0);
      T.D[2 * a + 1] = D(a, 1);
      const double kA = kc[a] * energy_.rest_area(t);
      T.ia[a] = kA > 0 ? 1.0 / kA : 0.0;
    }
    tris_.push_back(T);
  }
  tri_col_ = colour_sorted(n, static_cast<int>(tris_.size()), 3,
                           tris_.empty() ? nullptr : tris_[0].v, sizeof(Tri), order);
  apply_order(tris_, order);
  // Packs of four (double) or eight or sixteen (single precision) triangles of one colour
  // (sim/solvers/xpbd/xpbd_kernels.hpp); padding lanes use the scratch vertices n, n + 1, ...: one
  // per share of a colour's packs, the shares the threads run (by_colour_packs, the sweep's
  // halves).
  scratch_slots_ = std::clamp(opt_.sweep_slots > 0 ? opt_.sweep_slots : pool_->size(), 2,
                              xpbd::SweepPlan::kMaxSlots);
  const int S = scratch_slots_;
  cooked_f32_ = opt_.single_precision;
  cooked_kernels_ = opt_.kernels;
  kern_ = &xpbd::kernels();
  for (const xpbd::Kernels* k : xpbd::all_kernels())
    if (opt_.kernels == k->name) kern_ = k;
  tlanes_ = kern_->tri_lanes;
  tri_packs_.clear();
  tri_packs8_.clear();
  tri_packs16_.clear();
  tpack_col_.assign(1, 0);
  tpack8_col_.assign(1, 0);
  for (size_t c = 0; c + 1 < tri_col_.size(); ++c) {
    if (cooked_f32_ && tlanes_ == 16) {
      xpbd::pack_triangles<float, 16>(tris_.data(), tri_col_[c], tri_col_[c + 1], n, tri_packs16_,
                                      S);
      tpack8_col_.push_back(static_cast<int>(tri_packs16_.size()));
    } else if (cooked_f32_) {
      xpbd::pack_triangles<float, 8>(tris_.data(), tri_col_[c], tri_col_[c + 1], n, tri_packs8_, S);
      tpack8_col_.push_back(static_cast<int>(tri_packs8_.size()));
    } else {
      xpbd::pack_triangles(tris_.data(), tri_col_[c], tri_col_[c + 1], n, tri_packs_, S);
      tpack_col_.push_back(static_cast<int>(tri_packs_.size()));
    }
  }
  // (Items of the parallel loops: vertices, packs of elements, hinges, springs.)
  sweep_parallel_ =
      pool_->size() >= 2 && static_cast<int>(tris_.size()) >= opt_.min_parallel_triangles;
  pool_->set_min_parallel(static_cast<int>(tris_.size()) < opt_.min_parallel_triangles
                              ? std::numeric_limits<int>::max()
                              : 64);
}

// The bending blocks in triangle order (blk_*), one per three energy rows. Incremental (the
// energy's update() kept the rows of some triangles): the blocks of those triangles are kept
// from the last cook, the others assembled again; the same blocks as assembling all.
void XpbdSolver::assemble_blocks(bool incremental) {
  const int nrows = energy_.num_bending_rows();
  const int nb = (nrows + 2) / 3;
  const auto& rebuilt = energy_.rebuilt_triangles();
  const bool reuse = incremental && static_cast<int>(blk_off_.size()) == nb + 1 &&
                     static_cast<int>(rebuilt.size()) == nb;
  std::vector<int> old_off, old_col;
  std::vector<double> old_val, old_ik;
  if (reuse) {
    old_off.swap(blk_off_);
    old_col.swap(blk_col_);
    old_val.swap(blk_val_);
    old_ik.swap(blk_ik_);
  }
  // Upper bounds (a block's three rows share most columns): ~1M entries at 128^2, which
  // growing by push_back copied many times over (a re-cook after every cut).
  const size_t entries = energy_.bending_row_columns().size();
  blk_off_.assign(1, 0);
  blk_col_.clear();
  blk_val_.clear();
  blk_ik_.clear();
  blk_col_.reserve(reuse ? old_col.size() + 4096 : entries);
  blk_val_.reserve(reuse ? old_val.size() + 3 * 4096 : 3 * entries);
  blk_off_.reserve(nb + 1);
  blk_ik_.reserve(3 * nb);
  for (int bk = 0; bk < nb; ++bk) {
    if ((bk & 1023) == 0) pause_point();
    if (reuse && !rebuilt[bk]) {
      blk_col_.insert(blk_col_.end(), old_col.begin() + old_off[bk],
                      old_col.begin() + old_off[bk + 1]);
      blk_val_.insert(blk_val_.end(), old_val.begin() + 3 * old_off[bk],
                      old_val.begin() + 3 * old_off[bk + 1]);
      blk_off_.push_back(static_cast<int>(blk_col_.size()));
      blk_ik_.insert(blk_ik_.end(), old_ik.begin() + 3 * bk, old_ik.begin() + 3 * bk + 3);
      continue;
    }
    assemble_block(3 * bk);
  }
}

// Appends the block of rows r0 .. r0 + 2 to blk_*.
void XpbdSolver::assemble_block(int r0) {
  const int nrows = energy_.num_bending_rows();
  const auto& ro = energy_.bending_row_offsets();
  const auto& rc = energy_.bending_row_columns();
  const auto& rv = energy_.bending_row_values();
  std::vector<int>& boff = blk_off_;
  std::vector<int>& bcol = blk_col_;
  std::vector<double>& bval = blk_val_;
  std::vector<double>& bik = blk_ik_;
  thread_local std::vector<std::array<double, 4>> ent;  // column, value uu, vv, uv
  // The energy's three rows of a triangle share one pattern, sorted, exact zeros kept: then
  // the block is read off directly (the merge below costs ~15 ms at 128^2), with the same
  // values (the merge adds each to zeros).
  const int len = ro[r0 + 1] - ro[r0];
  const auto c0 = rc.begin() + ro[r0];
  if (r0 + 2 < nrows && ro[r0 + 2] - ro[r0 + 1] == len && ro[r0 + 3] - ro[r0 + 2] == len &&
      std::equal(c0, c0 + len, rc.begin() + ro[r0 + 1]) &&
      std::equal(c0, c0 + len, rc.begin() + ro[r0 + 2]) &&
      std::adjacent_find(c0, c0 + len, std::greater_equal<int>()) == c0 + len) {
    for (int e = 0; e < len; ++e) {
      bcol.push_back(c0[e]);
      for (int a = 0; a < 3; ++a) bval.push_back(rv[ro[r0 + a] + e]);
    }
  }
  ent.clear();
  for (int a = 0; a < 3 && r0 + a < nrows && static_cast<int>(bcol.size()) == boff.back(); ++a)
    for (int e = ro[r0 + a]; e < ro[r0 + a + 1]; ++e) {
      std::array<double, 4> q{double(rc[e]), 0, 0, 0};
      q[1 + a] = rv[e];
      ent.push_back(q);
    }
  std::sort(ent.begin(), ent.end(), [](const auto& p, const auto& q) { return p[0] < q[0]; });
  for (size_t i = 0; i < ent.size(); ++i) {
    if (!bcol.empty() && static_cast<int>(boff.size()) - 1 >= 0 &&
        static_cast<int>(bcol.size()) > boff.back() && bcol.back() == int(ent[i][0])) {
      for (int a = 0; a < 3; ++a) bval[bval.size() - 3 + a] += ent[i][1 + a];
      continue;
    }
    bcol.push_back(static_cast<int>(ent[i][0]));
    for (int a = 0; a < 3; ++a) bval.push_back(ent[i][1 + a]);
  }
  // Columns whose three coefficients are round-off of an exact zero (a cancellation: on a
  // regular grid one in five, ~1e-11 of the block's largest coefficient) are left out; the
  // block's rows keep their other coefficients bit for bit.
  {
    const int b0 = boff.back(), b1 = static_cast<int>(bcol.size());
    double big = 0;
    for (int e = 3 * b0; e < 3 * b1; ++e) big = std::max(big, std::abs(bval[e]));
    int out = b0;
    for (int e = b0; e < b1; ++e) {
      if (std::abs(bval[3 * e]) <= kZeroCoefficient * big &&
          std::abs(bval[3 * e + 1]) <= kZeroCoefficient * big &&
          std::abs(bval[3 * e + 2]) <= kZeroCoefficient * big)
        continue;
      bcol[out] = bcol[e];
      for (int a = 0; a < 3; ++a) bval[3 * out + a] = bval[3 * e + a];
      ++out;
    }
    bcol.resize(out);
    bval.resize(3 * out);
  }
  boff.push_back(static_cast<int>(bcol.size()));
  for (int a = 0; a < 3; ++a) {
    const double k = r0 + a < nrows ? energy_.bending_row_stiffness(r0 + a) : 0.0;
    bik.push_back(k > 0 ? 1.0 / k : 0.0);
  }
}

// Bending: the energy's own rows when it has them (tensor bending). The three rows of a triangle
// (uu, vv, uv) share their stencil: they are one block, solved together (3x3 system) with one
// pass over the stencil. The blocks in triangle order (assemble_blocks), then coloured and
// packed.
void XpbdSolver::cook_bending(int n, bool incremental) {
  const int S = scratch_slots_;
  assemble_blocks(incremental);
  const std::vector<int>& boff = blk_off_;
  const std::vector<int>& bcol = blk_col_;
  const std::vector<double>& bval = blk_val_;
  const std::vector<double>& bik = blk_ik_;
  std::vector<int> order_b, col;
  pause_point();
  colour_elements(n, boff, bcol, order_b, col);
  pause_point();
  row_cols_ = col.empty() ? std::vector<int>(1, 0) : col;
  // The blocks in colour order (row_*): the offsets first, then each block's entries copied to
  // its place on the cook's pool.
  const int nb = static_cast<int>(order_b.size());
  row_off_.resize(nb + 1);
  row_off_[0] = 0;
  for (int k = 0; k < nb; ++k)
    row_off_[k + 1] = row_off_[k] + boff[order_b[k] + 1] - boff[order_b[k]];
  row_colv_.resize(row_off_[nb]);
  row_val_.resize(3 * static_cast<size_t>(row_off_[nb]));
  row_ik_.resize(3 * static_cast<size_t>(nb));
  ThreadPool* pool = cook_pool();
  pool->parallel_for(nb, [&](int b, int e, int) {
    for (int k = b; k < e; ++k) {
      const int bk = order_b[k], len = boff[bk + 1] - boff[bk];
      std::copy_n(bcol.begin() + boff[bk], len, row_colv_.begin() + row_off_[k]);
      std::copy_n(bval.begin() + 3 * boff[bk], 3 * len, row_val_.begin() + 3 * row_off_[k]);
      std::copy_n(bik.begin() + 3 * bk, 3, row_ik_.begin() + 3 * k);
    }
  });
  pause_point();
  lambda_row_.assign(row_ik_.size(), Vec3::Zero());
  row_packs_.clear();
  row_packs8_.clear();
  rpack_col_.assign(1, 0);
  rpack8_col_.assign(1, 0);
  if (cooked_f32_)
    row_packs8_.assign(row_off_.data(), row_colv_.data(), row_val_.data(), row_ik_.data(),
                       row_cols_, n, S, pool, rpack8_col_);
  else
    row_packs_.assign(row_off_.data(), row_colv_.data(), row_val_.data(), row_ik_.data(), row_cols_,
                      n, S, pool, rpack_col_);
  row_ai_h_ = -1;
}

// The hinges (bending without rows) and the springs, sorted by colour.
void XpbdSolver::cook_hinges_springs(int n) {
  const int nrows = energy_.num_bending_rows();
  std::vector<int> order;
  hinges_.clear();
  for (int h = 0; h < (nrows > 0 ? 0 : energy_.num_hinges()); ++h) {
    Hinge H{};
    for (int a = 0; a < 4; ++a) {
      H.v[a] = energy_.hinge(h)[a];
      H.K[a] = energy_.hinge_K(h)[a];
    }
    H.iw = energy_.hinge_w(h) > 0 ? 1.0 / energy_.hinge_w(h) : 0.0;
    if (energy_.hinge_w(h) > 0) hinges_.push_back(H);
  }
  hinge_col_ = colour_sorted(n, static_cast<int>(hinges_.size()), 4,
                             hinges_.empty() ? nullptr : hinges_[0].v, sizeof(Hinge), order);
  apply_order(hinges_, order);
  springs_.clear();
  for (int s = 0; s < energy_.num_springs(); ++s) {
    Spring S{};
    S.v[0] = energy_.spring(s)[0];
    S.v[1] = energy_.spring(s)[1];
    S.rest = energy_.spring_rest(s);
    S.ik = energy_.spring_k(s) > 0 ? 1.0 / energy_.spring_k(s) : 0.0;
    springs_.push_back(S);
  }
  spring_col_ = colour_sorted(n, static_cast<int>(springs_.size()), 2,
                              springs_.empty() ? nullptr : springs_[0].v, sizeof(Spring), order);
  apply_order(springs_, order);
}

// The connected pieces (union-find over the elements' vertices, and the ties with sleep on) and
// the sweep blocks of one piece. A bending block's stencil (the vertices of its triangle's hinges
// and its edge neighbours' hinges) lies in triangles joined edge to edge with its own, so the
// triangles join every vertex a block joins: the blocks are not walked (a million entries at
// 128^2).
void XpbdSolver::cook_pieces(int n) {
  std::vector<int> parent(n);
  for (int i = 0; i < n; ++i) parent[i] = i;
  auto find = [&](int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  auto join = [&](int a, int b) { parent[find(a)] = find(b); };
  for (const Tri& T : tris_) join(T.v[0], T.v[1]), join(T.v[1], T.v[2]);
  for (const Hinge& H : hinges_) join(H.v[0], H.v[2]), join(H.v[0], H.v[3]);
  for (const Spring& Sp : springs_) join(Sp.v[0], Sp.v[1]);
  // With sleep, a seam's two sides are one piece: a piece asleep on one side would hold the
  // other's ties still. Without it each side settles on its own (the garment's measured fit).
  if (opt_.freeze)
    for (const xpbd::Tie& t : ties_)
      if (std::max({t.a, t.b0, t.b1}) < n && std::min({t.a, t.b0, t.b1}) >= 0)
        join(t.a, t.b0), join(t.a, t.b1);
  pieces_stale_ = false;
  std::vector<int> piece_of(n, -1);
  std::vector<int> id(n, -1);
  int pieces = 0;
  for (int i = 0; i < n; ++i) {
    const int r = find(i);
    if (id[r] < 0) id[r] = pieces++;
    piece_of[i] = id[r];
  }
  block_one_piece_.assign((n + kSweepBlock - 1) / kSweepBlock, 1);
  for (int i = 0; i < n; ++i)
    if (piece_of[i] != piece_of[i / kSweepBlock * kSweepBlock])
      block_one_piece_[i / kSweepBlock] = 0;
  rest_.reset(pieces, std::move(piece_of));
}

double XpbdSolver::cooked_bending_energy(const std::vector<Vec3>& x) const {
  double e = 0;
  for (size_t r = 0; r + 1 < row_off_.size(); ++r) {
    Vec3 V[3] = {Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
    for (int k = row_off_[r]; k < row_off_[r + 1]; ++k)
      for (int a = 0; a < 3; ++a) V[a] += row_val_[3 * k + a] * x[row_colv_[k]];
    for (int a = 0; a < 3; ++a)
      if (row_ik_[3 * r + a] > 0) e += 0.5 * V[a].squaredNorm() / row_ik_[3 * r + a];
  }
  return e;
}

// The sweep's phases (xpbd_sweep.hpp): the prediction with the packing over vertex blocks, each
// triangle colour's packs, each bending colour's packs, the unpacking over vertex blocks; split
// in one share per pool thread (the packs' padding shares, scratch_slots_).
void XpbdSolver::build_sweep(int n) {
  sweep_.clear();
  const bool padded = !tris_.empty() || row_off_.size() > 1;
  if (!cooked_f32_ || !padded) return;
  const int blocks = (n + kSweepBlock - 1) / kSweepBlock;
  sweep_.add_phase(kSweepPack, 0, blocks);
  for (size_t c = 0; c + 1 < tpack8_col_.size(); ++c)
    sweep_.add_phase(kSweepTris, tpack8_col_[c], tpack8_col_[c + 1]);
  for (size_t c = 0; c + 1 < rpack8_col_.size(); ++c)
    sweep_.add_phase(kSweepRows, rpack8_col_[c], rpack8_col_[c + 1]);
  sweep_.add_phase(kSweepUnpack, 0, blocks);
  // The vertices of item i of a phase (the scratch vertices n, n + 1, ... of padding lanes left
  // out: each share of a phase's packs has its own).
  const auto& phases = sweep_.phases();
  sweep_.plan(scratch_slots_, n, [&](int p, int i, auto&& fn) {
    switch (phases[p].kind) {
      case kSweepPack:
      case kSweepUnpack:
        for (int v = i * kSweepBlock; v < std::min(n, (i + 1) * kSweepBlock); ++v) fn(v);
        break;
      case kSweepTris:
        for (int q = 0; q < 3; ++q)
          for (int l = 0; l < tlanes_; ++l) {
            const int v = tlanes_ == 16 ? tri_packs16_[i].v[q][l] : tri_packs8_[i].v[q][l];
            if (v < n) fn(v);
          }
        break;
      default:
        for (int k = row_packs8_.off[i]; k < row_packs8_.off[i + 1]; ++k)
          for (int l = 0; l < 8; ++l) {
            const int v = row_packs8_.colv[8 * k + l];
            if (v < n) fn(v);
          }
    }
  });
}

bool XpbdSolver::wake(Cloth& cloth, const SceneObjects& scene) {
  if (!rest_.any_frozen()) {  // also clears flags left by a cut (re-cook) or by another solver
    rest_.thaw(cloth, pool_.get());
    return false;
  }
  fresh_penetration_ = energy_.detect_contacts(cloth, scene, pool_.get());
  ++detections_;           // (x_det_ is taken at the end, after the snap)
  contacts_fresh_ = true;  // the first substep reuses them (same positions)
  const bool all_frozen = rest_.wake(cloth, energy_);
  snap_to_contacts(cloth);
  // (A cloth that sleeps on needs no pairs: the frame computes nothing.)
  if (scene.self_collision && !all_frozen) start_self(cloth, scene);
  x_det_ = cloth.state.x;
  return all_frozen;
}

void XpbdSolver::snap_to_contacts(Cloth& cloth) {
  if (opt_.contact_snap_depth <= 0) return;
  const auto& cs = energy_.contacts();
  pool_->parallel_for(static_cast<int>(cs.size()), [&](int b, int e, int) {
    for (int k = b; k < e; ++k) snap_onto(cloth, cs[k]);
  });
}

void XpbdSolver::snap_onto(Cloth& cloth, const Contact& c) const {
  const int i = c.vertex;
  const double lim = opt_.contact_snap_depth;
  auto& S = cloth.state;
  if (lim <= 0 || !cloth.is_free(i) || (S.flags[i] & kFlagFrozen)) return;
  const double d = c.n.dot(S.x[i] - c.p);
  if (d < 0 && d > -lim) S.x[i] -= d * c.n;
}

// The names one step shares between its phases. Those of the frame are set once; those of the
// substep (from s on) by detect_contacts() and plan_substep().
struct XpbdSolver::Step {
  Step(XpbdSolver& sol, Cloth& cl, const SceneObjects& sc, double frame)
      : cloth(cl),
        scene(sc),
        S(cl.state),
        x(cl.state.x),
        n(cl.num_vertices()),
        ns(std::max(1, sol.opt_.substeps)),
        dt(frame),
        h(frame / ns),
        ih2(1.0 / (h * h)),
        be(std::max(1, sol.opt_.bending_every)),
        ihb(ih2 / be),
        w(sol.w_.data()),
        warm(sol.opt_.warm_start > 0),
        keep_lambda(sol.opt_.iterations > 1 || warm),
        padded(!sol.tris_.empty() || sol.row_off_.size() > 1),
        wide_t(sol.tlanes_ == 16),
        K(*sol.kern_),
        xp(sol.xp_.data()),
        xp8(sol.xp8_.data()),
        lam_tri(keep_lambda ? sol.lambda_tri_.data() : nullptr),
        lam_row(keep_lambda && !sol.lambda_row_.empty() ? sol.lambda_row_[0].data() : nullptr),
        rp(sol.row_packs_.view()),
        rp8(sol.row_packs8_.view()),
        damp(std::exp(-sol.opt_.air_drag * h)),
        damp_settle(std::exp(-sol.opt_.settle_air_drag * h)),
        margin(sol.energy_.options().contact_margin),
        moved_lim(0.25 * margin * margin),
        slow2(sol.opt_.settle_speed * sol.opt_.settle_speed),
        piece_of(sol.rest_.piece_of().data()),
        scale(sol.rest_.scales().data()) {}

  Cloth& cloth;
  const SceneObjects& scene;
  ClothState& S;
  std::vector<Vec3>& x;
  const int n, ns;  // vertices, substeps
  const double dt, h, ih2;
  // Bending blocks projected every be-th substep with compliance alpha / (be h^2): the same
  // impulse per be substeps (multi-rate splitting; be = 1 is plain XPBD).
  const int be;
  const double ihb;
  const double* w;  // inverse masses (w_)
  const bool warm, keep_lambda;
  const bool padded;  // triangles or bending blocks, in packs (the springs model has neither)
  const bool wide_t;  // single-precision triangles sixteen per pack
  const xpbd::Kernels& K;
  xpbd::P4* xp;
  xpbd::P4f* xp8;
  double* lam_tri;
  double* lam_row;
  const xpbd::RowPacks rp;
  const xpbd::RowPacksT<float> rp8;
  const double damp, damp_settle;  // velocity damping per substep, own mass and settling
  const double margin, moved_lim;  // contact margin, (half the margin)^2
  const double slow2;              // settle_speed^2
  const int* piece_of;             // per vertex (RestScheduler)
  const double* scale;             // inertia scale per piece (RestScheduler)
  StepStats st;

  int s = 0;              // the substep
  bool copy_det = false;  // contacts detected: the prediction copies x to x_det_
  bool fresh = false;     // the substep projects freshly detected contacts
  bool gravity_only = true;
  Vec3 gk = Vec3::Zero();  // gravity (zero when off)
  bool fused = false;      // the substep runs as one sweep (sweep())
  bool retest = false;     // the sweep tests moved vertices for contact again
  bool test_moved = false;
  bool self_watch = false;    // the velocity loops take the box of motion for self_due()
  bool settle_check = false;  // some piece settles
  bool bending() const { return s % be == be - 1 || s == ns - 1; }
};

bool XpbdSolver::cooked_for(const Cloth& cloth) const {
  return last_cook_.cooks > 0 && energy_.up_to_date(cloth) &&
         opt_.single_precision == cooked_f32_ && opt_.kernels == cooked_kernels_;
}

void XpbdSolver::prepare(const Cloth& cloth, ThreadPool* cook_pool) {
  if (cooked_for(cloth)) {
    if (pieces_stale_) cook_pieces(cloth.num_vertices());
    return;
  }
  cook_pool_ = cook_pool;
  cook(cloth);
  cook_pool_ = nullptr;
}

void XpbdSolver::warm(const Cloth& cloth, double dt, std::vector<double> anchors,
                      bool self_collision, ThreadPool* pool) {
  if (!cooked_for(cloth)) return;
  const double* scale = rest_.scales().data();
  const int* piece_of = rest_.piece_of().data();
  take_masses(cloth, scale, piece_of, pool);
  if (dt > 0) {
    // 1/(be h^2) with Step's arithmetic.
    const double h = dt / std::max(1, opt_.substeps);
    const double ih2 = 1.0 / (h * h);
    row_inverses(ih2 / std::max(1, opt_.bending_every), scale, piece_of, pool);
  }
  warm_anchors_.clear();
  if (cooked_f32_ &&
      anchors.size() == 3 * static_cast<size_t>(cloth.num_vertices() + scratch_slots_)) {
    anchor_terms(anchors, pool);
    warm_anchors_ = std::move(anchors);
  }
  // The positions of the contacts' last tests, written (their pages faulted) here rather than in
  // the first step's prediction, which copies every position into them after its detection.
  x_det_.assign(cloth.num_vertices(), Vec3::Zero());
  if (self_collision) {
    pause_point();
    self_.prepare(cloth);
  }
}

void XpbdSolver::take_anchors(std::vector<double> anchors) {
  if (!cooked_f32_ || anchors.size() != 3 * (w_.size() + scratch_slots_)) return;
  const bool made =
      warm_anchors_.size() == anchors.size() &&
      std::memcmp(warm_anchors_.data(), anchors.data(), sizeof(double) * anchors.size()) == 0;
  anchors_ = std::move(anchors);
  warm_anchors_.clear();
  if (!made) anchor_terms(anchors_, pool_.get());
}

StepStats XpbdSolver::step(Cloth& cloth, const SceneObjects& scene, double dt) {
  prepare(cloth);
  rest_.mark_masses_dirty();  // pins, releases, wakes and finishes happen between frames
  energy_.set_form(&scene);
  Step c(*this, cloth, scene, dt);
  auto t = std::chrono::steady_clock::now();
  const bool moving = begin_frame(c);
  add_part(kPartFrame, t);
  if (!moving) return c.st;
  renew_anchors(c);
  add_part(kPartAnchors, t);
  for (c.s = 0; c.s < c.ns; ++c.s) substep(c);
  t = std::chrono::steady_clock::now();
  if (contacts_unlisted_) {
    energy_.list_contacts(c.n, pool_.get());
    contacts_unlisted_ = false;
  }
  add_part(kPartList, t);
  return c.st;
}

void XpbdSolver::add_part(int part, std::chrono::steady_clock::time_point& t) {
  const auto now = std::chrono::steady_clock::now();
  part_ms_[part] += std::chrono::duration<double, std::milli>(now - t).count();
  t = now;
}

const char* XpbdSolver::part_name(int part) {
  static const char* const names[kStepParts] = {"frame start", "anchors", "contacts",
                                                "masses+plan", "sweep",   "retests",
                                                "after sweep", "pieces",  "list"};
  return part >= 0 && part < kStepParts ? names[part] : "?";
}

bool XpbdSolver::begin_frame(Step& c) {
  contacts_fresh_ = false;
  if (!opt_.freeze) {
    rest_.thaw(c.cloth, pool_.get());
  } else if (wake(c.cloth, c.scene)) {
    // Every piece sleeps and nothing disturbed it: nothing to compute this frame but the static
    // finish of pieces that have just fallen asleep.
    rest_.finish_sleeping(c.cloth, c.scene, pool_.get());
    for (int i = 0; i < c.n; ++i)
      if (!c.cloth.is_free(i)) c.S.x_prev[i] = c.x[i];
    c.S.time += c.dt;
    return false;
  } else {
    rest_.finish_sleeping(c.cloth, c.scene, pool_.get());  // pieces asleep while others move
  }
  rest_.check_fixed(c.cloth, pool_.get());
  return true;
}

// Single precision: the anchors are the positions at the start of a frame, renewed once a vertex
// is more than kAnchorReach from its anchor (or after a cook); the elements' terms at the anchors
// are summed in double then (xpbd_kernels.hpp, Kernels::tris8). A float resolves a displacement
// of 5 cm to 3.7e-9 m; a cloth at rest keeps its anchors. (At 2 cm the falling 128^2 drape
// renews them 75 times in 270 frames, 3 % of its time; at 5 cm 30, with the same error at rest
// to 5 um.)
void XpbdSolver::renew_anchors(Step& c) {
  if (!cooked_f32_ || !c.padded) return;
  const int n = c.n;
  const auto& x = c.x;
  const double* xd = reinterpret_cast<const double*>(x.data());
  bool renew = anchors_.size() != static_cast<size_t>(3 * (n + scratch_slots_));
  if (!renew) {
    // Some vertex beyond the reach (on the pool: a flag per thread).
    const double reach2 = kAnchorReach * kAnchorReach;
    changed_part_.assign(pool_->size(), 0);
    pool_->parallel_for(n, [&](int b, int e, int wk) {
      bool far = false;
      for (int i = b; i < e && !far; ++i)
        far =
            (x[i] - Vec3(anchors_[3 * i], anchors_[3 * i + 1], anchors_[3 * i + 2])).squaredNorm() >
            reach2;
      if (far) changed_part_[wk] = 1;
    });
    for (char f : changed_part_) renew = renew || f;
  }
  if (!renew) return;
  anchors_.assign(xd, xd + 3 * n);
  anchors_.resize(3 * (n + scratch_slots_), 0.0);  // the scratch vertices (their P4f: 0)
  anchor_terms(anchors_, pool_.get());
  ++anchor_renewals_;
}

// The elements' terms at `anchors` (tri_anchor8_, row_anchor8_), on `pool`.
void XpbdSolver::anchor_terms(const std::vector<double>& anchors, ThreadPool* pool) {
  const xpbd::Kernels& K = *kern_;
  const bool wide = tlanes_ == 16;
  pool->parallel_for(float_tri_packs(), [&](int b, int e, int) {
    if (wide)
      K.anchor_triangles16(tri_packs16_.data(), b, e, anchors.data(), tri_anchor8_.data());
    else
      K.anchor_triangles(tri_packs8_.data(), b, e, anchors.data(), tri_anchor8_.data());
  });
  const xpbd::RowPacksT<float> rp8 = row_packs8_.view();
  pool->parallel_for(row_packs8_.packs(), [&](int b, int e, int) {
    K.anchor_rows(rp8, b, e, anchors.data(), row_anchor8_.data());
  });
}

void XpbdSolver::substep(Step& c) {
  auto t = std::chrono::steady_clock::now();
  detect_contacts(c);
  if (c.s == 0) rest_.coarse_step(c.cloth, c.scene, energy_);
  contacts_fresh_ = false;
  add_part(kPartContacts, t);
  set_masses(c);
  plan_substep(c);
  add_part(kPartPlan, t);
  if (!c.fused) pool_->parallel_for(c.n, [&](int b, int e, int) { predict(c, b, e); });
  warm_start(c);
  for (int it = 0; it < opt_.iterations && c.fused; ++it) {
    sweep(c);
    ++c.st.iterations;
  }
  add_part(kPartSweep, t);
  retest_listed(c);
  add_part(kPartRetests, t);
  if (c.fused && c.scene.self_collision) project_self_after_sweep(c);
  if (c.fused) project_ties_after_sweep(c);
  add_part(kPartAfter, t);
  collect_retests(c);
  add_part(kPartRetests, t);
  for (int it = 0; it < opt_.iterations && !c.fused; ++it) {
    project_triangles(c);
    project_bending_springs(c);
    for (int p = 0; p < tie_passes_; ++p) xpbd::project_ties(ties_, c.x, c.w, nullptr);
    ++c.st.iterations;
  }
  if (!c.fused)
    pool_->parallel_for(c.n, [&](int b, int e, int wk) {
      velocities(c, b, e, wk);
      if (c.self_watch) self_motion(c, b, e, wk);
    });
  add_part(kPartSweep, t);
  update_pieces(c);
  schedule_rest(c);
  add_part(kPartPieces, t);
  c.S.time += c.h;
  ++c.st.substeps;
}

void XpbdSolver::detect_contacts(Step& c) {
  c.copy_det = false;
  if (c.s == 0 && contacts_fresh_) c.st.max_penetration = fresh_penetration_;
  c.fresh = c.s == 0 && contacts_fresh_;
  bool detect = c.s == 0 ? !contacts_fresh_ : true;
  if (c.s > 0 && opt_.reuse_contacts) {
    // Some vertex more than half the margin from where contacts were last detected (tested per
    // vertex in the previous substep's velocity loop, on the pool).
    detect = false;
    for (char m : moved_part_) detect = detect || m;
  }
  // Self-collision pairs are found again only once the cloth has deformed by half the margin
  // (start_self at a frame's start, self_due in it); the contacts with the form are tested again
  // vertex by vertex.
  const bool frame_self = c.s == 0 && !contacts_fresh_ && c.scene.self_collision;
  const bool self = c.scene.self_collision && c.s > 0 && (!opt_.reuse_contacts || self_due(c));
  if (!detect && !self && !frame_self) return;
  const auto t0 = std::chrono::steady_clock::now();
  if (detect) {
    c.fresh = true;
    c.st.max_penetration =
        std::max(c.st.max_penetration, energy_.detect_contacts(c.cloth, c.scene, pool_.get()));
    rest_.unsettle_pushed(c.x, energy_);
    snap_to_contacts(c.cloth);
    x_det_.resize(c.n);
    c.copy_det = true;  // x_det_ = x, in the prediction
    ++detections_;
  }
  if (frame_self)
    start_self(c.cloth, c.scene);
  else if (self)
    detect_self(c.cloth, c.scene, c.x);
  c.st.collision_ms +=
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// Self-collision pairs at positions x, which are kept (x_self_, with the vertices' flags that
// decide which are tested: self_flags_) for self_due() and start_self().
void XpbdSolver::detect_self(const Cloth& cloth, const SceneObjects& scene,
                             const std::vector<Vec3>& x) {
  self_.detect(cloth, x, scene.offset, energy_.options().contact_margin, pool_.get());
  rest_.skip_rest_of_self_touching(cloth, self_.contacts());
  x_self_ = x;
  self_flags_.resize(x.size());
  for (size_t i = 0; i < x.size(); ++i) self_flags_[i] = cloth.state.flags[i] & kSelfFlags;
  ++self_detections_;
}

// A frame's start: the pairs are found again when the cloth deformed since they were found
// (self_due's bound over every vertex, with what moved between frames: hands, moves), when a
// vertex was pinned, let go or made kinematic or not colliding (which pairs exist), or after a
// cook; otherwise the last frame's pairs go on (their pieces still skip the coarse correction and
// the finish). The pairs carried from frame to frame are part of the solver's saved state.
void XpbdSolver::start_self(const Cloth& cloth, const SceneObjects& scene) {
  const int n = cloth.num_vertices();
  const auto& x = cloth.state.x;
  bool due = x_self_.size() != static_cast<size_t>(n) || self_flags_.size() != x_self_.size();
  if (!due) {
    const int parts = pool_->size();
    self_box_.assign(parts, SelfBox{});
    self_flags_changed_.assign(parts, 0);
    pool_->parallel_parts(n, [&](int b, int e, int part) {
      SelfBox& B = self_box_[part];
      for (int i = b; i < e; ++i) {
        B.add(x[i] - x_self_[i]);
        if ((cloth.state.flags[i] & kSelfFlags) != self_flags_[i]) self_flags_changed_[part] = 1;
      }
    });
    SelfBox all;
    for (int p = 0; p < parts; ++p) {
      all.add(self_box_[p]);
      due = due || self_flags_changed_[p];
    }
    const double margin = energy_.options().contact_margin;
    due = due || (all.beyond(margin) &&
                  !self_.keeps_pairs(cloth, x, x_self_, scene.offset, margin, pool_.get()));
  }
  if (due)
    detect_self(cloth, scene, x);
  else
    rest_.skip_rest_of_self_touching(cloth, self_.contacts());
}

// The cloth deformed enough since its self-collision pairs were found that a pair not found
// could come within the thickness. Only relative motion brings a vertex and a triangle closer:
// with d_i each vertex's displacement since then, a triangle's points move by convex
// combinations of its corners' d, so a vertex's distance to a triangle changes by at most the
// diagonal of the box around all d_i, and by at most twice the largest |d_i|. The pairs were
// found within thickness + margin: they stay complete while the smaller bound is at most the
// margin (a cloth that falls or is carried whole keeps them). The box is taken by the previous
// substep's velocity loops (self_motion) and after its projections. Beyond it, the same bound
// region by region (SelfCollision::keeps_pairs) can still keep them: parts of the cloth that
// move against each other but lie apart (a hand lifting one edge, a flap swinging) need no
// detection.
bool XpbdSolver::self_due(const Step& c) {
  if (x_self_.size() != static_cast<size_t>(c.n) || self_box_.empty()) return true;
  SelfBox all;
  for (const SelfBox& B : self_box_) all.add(B);
  return all.beyond(c.margin) &&
         !self_.keeps_pairs(c.cloth, c.x, x_self_, c.scene.offset, c.margin, pool_.get());
}

// Vertices [b, e) into slot's box of displacements since the self-collision pairs were found.
void XpbdSolver::self_motion(const Step& c, int b, int e, int slot) {
  SelfBox B;  // (a local box: the loop keeps it in registers)
  for (int i = b; i < e; ++i) B.add(c.x[i] - x_self_[i]);
  self_box_[slot].add(B);
}

// The same for vertices a projection after the sweep moved (repeats are harmless).
void XpbdSolver::self_motion_of(const Step& c, const std::vector<int>& moved) {
  if (!c.self_watch) return;
  for (const int i : moved) self_box_[0].add(c.x[i] - x_self_[i]);
}

// w = the unscaled inverse mass (w0: 0 when not free or frozen) / the piece's settling scale.
// A change of w0 (a pin, a release, a piece falling asleep or waking) needs the bending blocks'
// sums over their stencils again; a change of scale alone does not (build_row_inverses()).
void XpbdSolver::set_masses(Step& c) {
  if (rest_.masses_dirty()) {
    take_masses(c.cloth, c.scale, c.piece_of, pool_.get());
    rest_.masses_set();
  }
  row_inverses(c.ihb, c.scale, c.piece_of, pool_.get());
}

// w_ and w0_ from the cloth's state, pieces' scales `scale` (vertex i's piece: piece_of[i]);
// notes which changed. The vertices on `pool`.
void XpbdSolver::take_masses(const Cloth& cloth, const double* scale, const int* piece_of,
                             ThreadPool* pool) {
  const ClothState& S = cloth.state;
  changed_part_.assign(2 * static_cast<size_t>(pool->size()), 0);
  pool->parallel_for(cloth.num_vertices(), [&](int b, int e, int wk) {
    bool w_changed = false, w0_changed = false;
    for (int i = b; i < e; ++i) {
      const double w0 = cloth.is_free(i) && !(S.flags[i] & kFlagFrozen) ? S.inv_mass[i] : 0.0;
      const double wi = w0 > 0 ? w0 / scale[piece_of[i]] : 0.0;
      w_changed = w_changed || wi != w_[i];
      w0_changed = w0_changed || w0 != w0_[i];
      w_[i] = wi;
      w0_[i] = w0;
    }
    if (w_changed) changed_part_[2 * wk] = 1;
    if (w0_changed) changed_part_[2 * wk + 1] = 1;
  });
  for (size_t k = 0; k < changed_part_.size(); k += 2) {
    w_changed_ = w_changed_ || changed_part_[k];
    w0_changed_ = w0_changed_ || changed_part_[k + 1];
  }
}

// The bending blocks' inverses for substeps with 1/(be h^2) = ihb, made again when w or ihb
// changed since they were made.
void XpbdSolver::row_inverses(double ihb, const double* scale, const int* piece_of,
                              ThreadPool* pool) {
  if (row_ik_.empty() || (!w_changed_ && ihb == row_ai_h_)) return;
  row_b_.resize(row_ik_.size() * 2);  // 6 per block (3 rows)
  pool->parallel_for(static_cast<int>(row_ik_.size() / 3),
                     [&](int b, int e, int) { build_row_inverses(ihb, scale, piece_of, b, e); });
  row_ai_h_ = ihb;
  w_changed_ = false;
  w0_changed_ = false;
}

// The bending blocks' inverse system matrices (in row_packs_), for the current w and h:
// A = sum_j w_j v_j v_j^T + alpha / (be h^2). A block's stencil lies in one piece, so
// w_j = w0_j / scale and A = B / scale + alpha with B = sum_j w0_j v_j v_j^T, kept per block
// (row_b_) and summed again only when w0 changed.
void XpbdSolver::build_row_inverses(double ihb, const double* scale, const int* piece_of, int b,
                                    int e) {
  for (int r = b; r < e; ++r) {
    double* B = &row_b_[6 * r];  // 00 01 02 11 12 22
    if (w0_changed_) {
      for (int m = 0; m < 6; ++m) B[m] = 0;
      for (int k = row_off_[r]; k < row_off_[r + 1]; ++k) {
        const double wj = w0_[row_colv_[k]];
        if (wj == 0) continue;
        const double* v = &row_val_[3 * k];
        B[0] += wj * v[0] * v[0];
        B[1] += wj * v[0] * v[1];
        B[2] += wj * v[0] * v[2];
        B[3] += wj * v[1] * v[1];
        B[4] += wj * v[1] * v[2];
        B[5] += wj * v[2] * v[2];
      }
    }
    const double is =
        row_off_[r + 1] > row_off_[r] ? 1.0 / scale[piece_of[row_colv_[row_off_[r]]]] : 1.0;
    double A[6];
    for (int m = 0; m < 6; ++m) A[m] = B[m] * is;
    double ai[6] = {0, 0, 0, 0, 0, 0};
    auto store = [&] {
      for (int m = 0; m < 6; ++m) {
        if (cooked_f32_)
          row_packs8_.ai_of(r, m) = static_cast<float>(ai[m]);
        else
          row_packs_.ai_of(r, m) = ai[m];
      }
    };
    if (A[0] + A[3] + A[5] == 0) {  // every vertex of the block fixed
      store();
      continue;
    }
    A[0] += ihb * row_ik_[3 * r];
    A[3] += ihb * row_ik_[3 * r + 1];
    A[5] += ihb * row_ik_[3 * r + 2];
    // Closed-form inverse of the symmetric positive definite 3x3 A.
    const double c00 = A[3] * A[5] - A[4] * A[4];
    const double c01 = A[2] * A[4] - A[1] * A[5];
    const double c02 = A[1] * A[4] - A[2] * A[3];
    const double det = A[0] * c00 + A[1] * c01 + A[2] * c02;
    if (!(det > 0)) {
      store();
      continue;
    }
    const double id = 1.0 / det;
    ai[0] = c00 * id;
    ai[1] = c01 * id;
    ai[2] = c02 * id;
    ai[3] = (A[0] * A[5] - A[2] * A[2]) * id;
    ai[4] = (A[2] * A[1] - A[0] * A[4]) * id;
    ai[5] = (A[0] * A[3] - A[1] * A[1]) * id;
    store();
  }
}

void XpbdSolver::plan_substep(Step& c) {
  // Gravity alone is written out in the prediction (the same arithmetic as
  // ClothEnergy::external_force); the pressure toward the form goes through it.
  const EnergyOptions& eo = energy_.options();
  c.gravity_only = !(eo.pressure > 0 && c.scene.form);
  c.gk = eo.gravity ? eo.g : Vec3::Zero();
  // The whole substep in one sweep (xpbd_sweep.hpp: the prediction with the packing, the elements,
  // the unpacking with the contacts, velocities and motion sums) where it applies: single
  // precision, one iteration, no warm start, bending in this substep. Self-collision pairs are
  // projected after it (project_self_after_sweep).
  c.fused = c.padded && cooked_f32_ && !sweep_.empty() &&
            pool_->size() <= xpbd::SweepPlan::kMaxSlots && opt_.iterations == 1 && !c.warm &&
            hinges_.empty() && springs_.empty() && c.bending();
  // With contacts reused, the sweep tests again each vertex that moved more than half the margin
  // since its own last test (a detection of all vertices happens only at a frame's start);
  // otherwise such a vertex makes the next substep detect all of them again. (Only when every
  // substep runs the sweep, bending_every = 1: a substep outside it projects the energy's
  // contact list, which lists the tested contacts only at the step's end.)
  c.retest = c.fused && c.be == 1 && opt_.reuse_contacts && opt_.retest_contacts && c.s + 1 < c.ns;
  c.test_moved = opt_.reuse_contacts && c.s + 1 < c.ns && !c.retest;
  c.self_watch = c.scene.self_collision && opt_.reuse_contacts && c.s + 1 < c.ns &&
                 x_self_.size() == static_cast<size_t>(c.n);
  const int slots = std::max(pool_->size(), scratch_slots_);  // pool threads or sweep slots
  moved_part_.assign(slots, 0);
  self_box_.assign(c.self_watch ? slots : 0, SelfBox{});
  if (c.retest) {
    retest_part_.assign(slots, RetestPart{});
    retest_list_.resize(slots);
    for (std::vector<int>& listed : retest_list_) {
      listed.clear();
      listed.reserve(c.n);
    }
    unsettle_mark_.assign(static_cast<size_t>(slots) * rest_.num_pieces(), 0);
  }
  c.settle_check = opt_.settle && rest_.settle_scale() > 1.0;
  if (c.fused && (opt_.settle || opt_.freeze))
    block_motion_.resize((c.n + kSweepBlock - 1) / kSweepBlock);
}

// The substep's start positions go straight to x_prev (the velocity update reads them there, and
// they are what x_prev holds after the step).
void XpbdSolver::predict(const Step& c, int b, int e) {
  const EnergyOptions& eo = energy_.options();
  auto& S = c.S;
  auto& x = c.x;
  const double h = c.h;
  const double* w = c.w;
  if (c.copy_det) std::copy(x.begin() + b, x.begin() + e, x_det_.begin() + b);
  for (int i = b; i < e; ++i) {
    S.x_prev[i] = x[i];
    if (!(w[i] > 0)) continue;
    const double m = S.mass[i];
    const Vec3 f = !c.gravity_only ? energy_.external_force(i, x[i], m)
                   : eo.gravity    ? Vec3(m * eo.g)
                                   : Vec3::Zero();
    x[i] += h * S.v[i] + (h * h / (c.scale[c.piece_of[i]] * m)) * f;
  }
}

// The same for sweep vertex block k = [b, e): the kernels' loop when it is of one piece and
// gravity the only force.
void XpbdSolver::block_predict(const Step& c, int k, int b, int e) {
  if (!c.gravity_only || !block_one_piece_[k]) {
    predict(c, b, e);
    return;
  }
  auto& x = c.x;
  if (c.copy_det) std::copy(x.begin() + b, x.begin() + e, x_det_.begin() + b);
  c.K.predict(reinterpret_cast<double*>(x.data()), reinterpret_cast<double*>(c.S.x_prev.data()),
              reinterpret_cast<const double*>(c.S.v.data()), c.w, c.S.mass.data(),
              c.scale[c.piece_of[b]], c.h, c.gk.data(), b, e);
}

template <class Fn>
void XpbdSolver::by_colour(const std::vector<int>& off, Fn&& fn) {
  for (size_t c = 0; c + 1 < off.size(); ++c) {
    const int b = off[c], cnt = off[c + 1] - off[c];
    pool_->parallel_for(cnt, [&](int lo, int hi, int wk) { fn(b + lo, b + hi, wk); });
  }
}

// Packs (triangles, bending blocks): each thread runs its own share of a colour's packs, whose
// padding uses that share's scratch vertex.
template <class Fn>
void XpbdSolver::by_colour_packs(const std::vector<int>& off, Fn&& fn) {
  const int S = scratch_slots_;
  for (size_t c = 0; c + 1 < off.size(); ++c) {
    const int b = off[c], cnt = off[c + 1] - off[c];
    auto share = [&](int t, int wk) {
      const int lo = b + xpbd::share_begin(cnt, t, S), hi = b + xpbd::share_begin(cnt, t + 1, S);
      if (lo < hi) fn(lo, hi, wk);
    };
    if (sweep_parallel_ && pool_->size() == S)
      pool_->parallel_slots(share);
    else
      for (int t = 0; t < S; ++t) share(t, 0);
  }
}

// Warm start: the multipliers of the previous substep, scaled, applied as displacements; without
// it the multipliers start from zero.
void XpbdSolver::warm_start(Step& c) {
  if (c.warm) {
    const double h = c.h;
    const double f = opt_.warm_start * (h_prev_ > 0 ? (h / h_prev_) * (h / h_prev_) : 0.0);
    for (double& l : lambda_tri_) l *= f;
    for (Vec3& l : lambda_hinge_) l *= f;
    for (Vec3& l : lambda_row_) l *= f;
    for (double& l : lambda_spring_) l *= f;
    h_prev_ = h;
    by_colour(tri_col_, [&](int b, int e, int) { warm_tris(c, b, e); });
    by_colour(hinge_col_, [&](int b, int e, int) { warm_hinges(c, b, e); });
    by_colour(row_cols_, [&](int b, int e, int) { warm_rows(c, b, e); });
    by_colour(spring_col_, [&](int b, int e, int) { warm_springs(c, b, e); });
  } else if (c.keep_lambda) {
    std::fill(lambda_tri_.begin(), lambda_tri_.end(), 0.0);
    std::fill(lambda_hinge_.begin(), lambda_hinge_.end(), Vec3::Zero());
    std::fill(lambda_row_.begin(), lambda_row_.end(), Vec3::Zero());
    std::fill(lambda_spring_.begin(), lambda_spring_.end(), 0.0);
  }
}

void XpbdSolver::warm_tris(const Step& c, int b, int e) {
  auto& x = c.x;
  const double* w = c.w;
  for (int k = b; k < e; ++k) {
    const Tri& T = tris_[k];
    const double wq[3] = {w[T.v[0]], w[T.v[1]], w[T.v[2]]};
    const double* L = &lambda_tri_[3 * k];
    if (wq[0] + wq[1] + wq[2] == 0 || (L[0] == 0 && L[1] == 0 && L[2] == 0)) continue;
    const double* D = T.D;
    const Vec3 fu = x[T.v[0]] * D[0] + x[T.v[1]] * D[2] + x[T.v[2]] * D[4];
    const Vec3 fv = x[T.v[0]] * D[1] + x[T.v[1]] * D[3] + x[T.v[2]] * D[5];
    for (int q = 0; q < 3; ++q) {
      const Vec3 g = L[0] * D[2 * q] * fu + L[1] * D[2 * q + 1] * fv +
                     L[2] * 0.5 * (D[2 * q] * fv + D[2 * q + 1] * fu);
      x[T.v[q]] += wq[q] * g;
    }
  }
}

void XpbdSolver::warm_hinges(const Step& c, int b, int e) {
  for (int k = b; k < e; ++k) {
    const Hinge& H = hinges_[k];
    for (int q = 0; q < 4; ++q) c.x[H.v[q]] += (c.w[H.v[q]] * H.K[q]) * lambda_hinge_[k];
  }
}

void XpbdSolver::warm_rows(const Step& c, int b, int e) {
  for (int r = b; r < e; ++r) {
    const Vec3* lam = &lambda_row_[3 * r];
    for (int k = row_off_[r]; k < row_off_[r + 1]; ++k) {
      const int j = row_colv_[k];
      const double* v = &row_val_[3 * k];
      c.x[j] += c.w[j] * (v[0] * lam[0] + v[1] * lam[1] + v[2] * lam[2]);
    }
  }
}

namespace {

// Spring Sp's unit direction (v0 - v1) and length; false when degenerate.
template <class Spring>
inline bool spring_dir(const std::vector<Vec3>& x, const Spring& Sp, Vec3& nn, double& l) {
  const Vec3 d = x[Sp.v[0]] - x[Sp.v[1]];
  l = d.norm();
  if (l < 1e-15) return false;
  nn = d / l;
  return true;
}

// Moves spring Sp's ends by w dl along nn (the constraint's gradient).
template <class Spring>
inline void spring_move(std::vector<Vec3>& x, const double* w, const Spring& Sp, const Vec3& nn,
                        double dl) {
  x[Sp.v[0]] += (w[Sp.v[0]] * dl) * nn;
  x[Sp.v[1]] -= (w[Sp.v[1]] * dl) * nn;
}

}  // namespace

void XpbdSolver::warm_springs(const Step& c, int b, int e) {
  for (int k = b; k < e; ++k) {
    Vec3 nn;
    double l;
    if (spring_dir(c.x, springs_[k], nn, l))
      spring_move(c.x, c.w, springs_[k], nn, lambda_spring_[k]);
  }
}

// Triangles and bending blocks in single precision: the kernels of xpbd_kernels.hpp on the
// padded copy xp8_.
void XpbdSolver::project_tris8(const Step& c, int b, int e) {
  if (c.wide_t)
    c.K.tris16(tri_packs16_.data(), tri_anchor8_.data(), b, e, c.xp8, c.ih2, c.lam_tri);
  else
    c.K.tris8(tri_packs8_.data(), tri_anchor8_.data(), b, e, c.xp8, c.ih2, c.lam_tri);
}

void XpbdSolver::project_rows8(const Step& c, int b, int e) {
  c.K.rows8(c.rp8, row_anchor8_.data(), b, e, c.xp8, c.ihb, c.lam_row);
}

// One iteration's triangles and (in a bending substep) bending blocks: the positions packed, the
// packs projected colour by colour, the positions unpacked.
void XpbdSolver::project_triangles(const Step& c) {
  const int n = c.n;
  const xpbd::Kernels& K = c.K;
  double* x = reinterpret_cast<double*>(c.x.data());
  if (c.padded && cooked_f32_) {
    pool_->parallel_for(n,
                        [&](int b, int e, int) { K.pack8(x, c.w, anchors_.data(), c.xp8, b, e); });
    by_colour_packs(tpack8_col_, [&](int b, int e, int) { project_tris8(c, b, e); });
    if (c.bending())
      by_colour_packs(rpack8_col_, [&](int b, int e, int) { project_rows8(c, b, e); });
    pool_->parallel_for(n, [&](int b, int e, int) { K.unpack8(c.xp8, anchors_.data(), x, b, e); });
  } else if (c.padded) {
    pool_->parallel_for(n, [&](int b, int e, int) { K.pack(x, c.w, c.xp, b, e); });
    by_colour_packs(tpack_col_, [&](int b, int e, int) {
      K.tris(tri_packs_.data(), b, e, c.xp, c.ih2, c.lam_tri);
    });
    if (c.bending())
      by_colour_packs(rpack_col_,
                      [&](int b, int e, int) { K.rows(c.rp, b, e, c.xp, c.ihb, c.lam_row); });
    pool_->parallel_for(n, [&](int b, int e, int) { K.unpack(c.xp, x, b, e); });
  }
}

// The rest of an iteration: hinges, springs, contacts and self-collision. (Hinges exist only
// without bending blocks: the order of the two does not matter.)
void XpbdSolver::project_bending_springs(Step& c) {
  by_colour(hinge_col_, [&](int b, int e, int) { project_hinges(c, b, e); });
  by_colour(spring_col_, [&](int b, int e, int) { project_springs(c, b, e); });
  energy_.project_contacts(c.x, &c.S.x_prev, c.scene.friction);
  if (c.scene.self_collision) self_.project(c.cloth, c.x, c.w, c.scene.offset);
}

// Self-collision in a substep run as one element sweep: the pairs projected once after it (the
// sweep's unpacking has projected the object contacts), then the velocities of the vertices they
// moved computed again from their corrected positions, as velocities() does.
void XpbdSolver::project_self_after_sweep(Step& c) {
  if (self_.contacts().empty()) return;
  self_moved_.clear();
  self_.project(c.cloth, c.x, c.w, c.scene.offset, &self_moved_);
  refresh_velocities(c, self_moved_);
  self_motion_of(c, self_moved_);
}

// The velocities of free vertices moved after the element sweep, computed again from their
// corrected positions as velocities() does (the sweep has already set them from the old ones).
void XpbdSolver::refresh_velocities(Step& c, const std::vector<int>& moved) {
  for (const int i : moved)
    if (c.w[i] > 0)
      c.S.v[i] = ((c.scale[c.piece_of[i]] > 1.0 ? c.damp_settle : c.damp) / c.h) *
                 (c.x[i] - c.S.x_prev[i]);
}

// Ties in a substep run as one element sweep: projected after it, then the velocities of the
// vertices they moved computed again.
void XpbdSolver::project_ties_after_sweep(Step& c) {
  if (ties_.empty()) return;
  tie_moved_.clear();
  for (int p = 0; p < tie_passes_; ++p) xpbd::project_ties(ties_, c.x, c.w, &tie_moved_);
  refresh_velocities(c, tie_moved_);
  self_motion_of(c, tie_moved_);
}

void XpbdSolver::project_hinges(const Step& c, int b, int e) {
  auto& x = c.x;
  const double* w = c.w;
  for (int k = b; k < e; ++k) {
    const Hinge& H = hinges_[k];
    const double wq[4] = {w[H.v[0]], w[H.v[1]], w[H.v[2]], w[H.v[3]]};
    double denom = c.ih2 * H.iw;
    const double alpha = denom;
    for (int q = 0; q < 4; ++q) denom += wq[q] * H.K[q] * H.K[q];
    if (denom == alpha) continue;
    const Vec3 C =
        H.K[0] * x[H.v[0]] + H.K[1] * x[H.v[1]] + H.K[2] * x[H.v[2]] + H.K[3] * x[H.v[3]];
    const Vec3 lam = c.keep_lambda ? lambda_hinge_[k] : Vec3::Zero();
    const Vec3 dl = (-C - alpha * lam) / denom;
    if (c.keep_lambda) lambda_hinge_[k] = lam + dl;
    for (int q = 0; q < 4; ++q) x[H.v[q]] += (wq[q] * H.K[q]) * dl;
  }
}

void XpbdSolver::project_springs(const Step& c, int b, int e) {
  const double* w = c.w;
  for (int k = b; k < e; ++k) {
    const Spring& Sp = springs_[k];
    Vec3 nn;
    double l;
    if (!spring_dir(c.x, Sp, nn, l)) continue;
    const double C = l - Sp.rest;
    const double alpha = c.ih2 * Sp.ik;
    const double denom = w[Sp.v[0]] + w[Sp.v[1]] + alpha;
    if (denom < 1e-20 || denom == alpha) continue;
    const double lam = c.keep_lambda ? lambda_spring_[k] : 0.0;
    const double dl = (-C - alpha * lam) / denom;
    if (c.keep_lambda) lambda_spring_[k] = lam + dl;
    spring_move(c.x, w, Sp, nn, dl);
  }
}

// Vertex i moved more than half the margin since its last contact test, and more than its
// clearance then (ClothEnergy::clearance2: short of it a test finds nothing).
bool XpbdSolver::moved_beyond(const Step& c, int i) const {
  const double m2 = (c.x[i] - x_det_[i]).squaredNorm();
  return m2 > c.moved_lim && m2 > energy_.clearance2(i);
}

// Vertices [b, e) that moved beyond their last test are listed (retest_list_[slot]) for
// retest_listed, which tests them after the sweep; the self-collision watch takes the motion of
// the others now and theirs once tested (a test may move a vertex onto its plane).
void XpbdSolver::list_moved(const Step& c, int b, int e, int slot) {
  std::vector<int>& listed = retest_list_[slot];
  int from = b;  // the watch's next stretch of unlisted vertices
  for (int i = b; i < e; ++i) {
    if (!moved_beyond(c, i)) continue;
    listed.push_back(i);  // (no allocation: reserved for every vertex)
    if (c.self_watch) self_motion(c, from, i, slot);
    from = i + 1;
  }
  if (c.self_watch) self_motion(c, from, e, slot);
}

// The vertices list_moved listed are tested again as contact detection tests them; then as after
// a detection, a settling piece pushed more than kUnsettleDepth into a fresh plane ends its
// settling (unsettle_mark_), a vertex up to contact_snap_depth inside it is put on it, and the
// test's position is kept (x_det_). A vertex's test reads and writes that vertex alone, so the
// tests run in any order after the sweep, on the whole pool: the vertices that move (a flap
// falling after a cut) often lie in one slot's strip, and tested in the sweep they kept that
// slot's thread busy while the others waited at its border.
void XpbdSolver::retest_listed(const Step& c) {
  if (!c.retest) return;
  const int slots = static_cast<int>(retest_list_.size());
  retest_off_.assign(slots + 1, 0);
  for (int t = 0; t < slots; ++t)
    retest_off_[t + 1] = retest_off_[t] + static_cast<int>(retest_list_[t].size());
  const int listed = retest_off_[slots];
  if (listed == 0) return;
  const int pieces = rest_.num_pieces();
  // Entries [b, e) of the slots' lists one after the other.
  auto test = [&](int b, int e, int wk) {
    RetestPart& rp = retest_part_[wk];
    double deepest = 0;
    int t = static_cast<int>(std::upper_bound(retest_off_.begin(), retest_off_.end(), b) -
                             retest_off_.begin()) -
            1;
    for (int k = b; k < e; ++k) {
      while (k >= retest_off_[t + 1]) ++t;
      const int i = retest_list_[t][k - retest_off_[t]];
      deepest = std::max(deepest, energy_.retest_contact(c.cloth, c.scene, i));
      const Contact& ct = energy_.tested_contact(i);
      if (ct.vertex >= 0) {
        if (c.settle_check && ct.n.dot(c.x[i] - ct.p) < -xpbd::kUnsettleDepth &&
            c.scale[c.piece_of[i]] > 1.0)
          unsettle_mark_[static_cast<size_t>(wk) * pieces + c.piece_of[i]] = 1;
        snap_onto(c.cloth, ct);
      }
      x_det_[i] = c.x[i];
      if (c.self_watch) self_box_[wk].add(c.x[i] - x_self_[i]);
    }
    rp.count += e - b;
    rp.deepest = std::max(rp.deepest, deepest);
  };
  // A few tests do not pay for waking the pool.
  constexpr int kRetestsOnPool = 64;
  if (listed < kRetestsOnPool)
    test(0, listed, 0);
  else
    pool_->parallel_for(listed, test);
}

// The contact-reuse test: some vertex of [b, e) moved beyond its last test (moved_part_, per
// thread).
void XpbdSolver::test_moved_part(const Step& c, int b, int e, int wk) {
  if (c.test_moved && !moved_part_[wk])
    for (int i = b; i < e; ++i)
      if (moved_beyond(c, i)) {
        moved_part_[wk] = 1;
        break;
      }
}

// Velocities from the substep's motion, and the contact-reuse test.
void XpbdSolver::velocities(const Step& c, int b, int e, int wk) {
  auto& S = c.S;
  auto& x = c.x;
  const double* w = c.w;
  for (int i = b; i < e; ++i) {
    if (w[i] > 0)
      S.v[i] =
          ((c.scale[c.piece_of[i]] > 1.0 ? c.damp_settle : c.damp) / c.h) * (x[i] - S.x_prev[i]);
    else if (S.flags[i] & kFlagFrozen)
      S.v[i].setZero();
  }
  test_moved_part(c, b, e, wk);
}

// The same for sweep vertex block k = [b, e): the kernels' loop when it is of one piece.
void XpbdSolver::block_velocities(const Step& c, int k, int b, int e, int wk) {
  if (!block_one_piece_[k]) {
    velocities(c, b, e, wk);
    return;
  }
  auto& S = c.S;
  c.K.velocities(reinterpret_cast<const double*>(c.x.data()),
                 reinterpret_cast<const double*>(S.x_prev.data()),
                 reinterpret_cast<double*>(S.v.data()), c.w, S.flags.data(), kFlagFrozen,
                 c.scale[c.piece_of[b]] > 1.0 ? c.damp_settle : c.damp, c.h, b, e);
  test_moved_part(c, b, e, wk);
}

// Sweep vertex block k: the pieces' motion sums over its free vertices (xpbd::PieceMotion), one
// run per stretch of vertices of one piece.
void XpbdSolver::block_motion(const Step& c, int k, int b, int e) {
  auto& runs = block_motion_[k];
  const auto& S = c.S;
  const double* w = c.w;
  runs.clear();
  if (block_one_piece_[k]) {
    double sums[4];
    if (c.K.motion(reinterpret_cast<const double*>(S.v.data()), w, S.mass.data(), c.slow2, b, e,
                   sums) > 0)
      runs.push_back({c.piece_of[b], xpbd::PieceMotion{sums[0], sums[1], sums[2], sums[3]}});
    return;
  }
  for (int i = b; i < e; ++i) {
    if (!(w[i] > 0)) continue;
    if (runs.empty() || runs.back().first != c.piece_of[i]) runs.push_back({c.piece_of[i], {}});
    xpbd::PieceMotion& acc = runs.back().second;
    const double v2 = S.v[i].squaredNorm(), m = S.mass[i];
    acc.max_v2 = std::max(acc.max_v2, v2);
    acc.mv2 += m * v2;
    acc.mv2_capped += m * std::min(v2, c.slow2);
    acc.m += m;
  }
}

// The element sweep (xpbd_sweep.hpp): items [b, e) of phase P, run by sweep slot `slot`.
void XpbdSolver::sweep_items(const Step& c, const xpbd::SweepPlan::Phase& P, int b, int e,
                             int slot) {
  if (b >= e) return;
  const int n = c.n;
  const xpbd::Kernels& K = c.K;
  double* x = reinterpret_cast<double*>(c.x.data());
  switch (P.kind) {
    case kSweepPack:
      for (int k = b; k < e; ++k) {
        const int vb = k * kSweepBlock, ve = std::min(n, vb + kSweepBlock);
        block_predict(c, k, vb, ve);
        K.pack8(x, c.w, anchors_.data(), c.xp8, vb, ve);
      }
      break;
    case kSweepTris:
      project_tris8(c, b, e);
      break;
    case kSweepRows:
      project_rows8(c, b, e);
      break;
    default:
      for (int k = b; k < e; ++k) {
        const int vb = k * kSweepBlock, ve = std::min(n, vb + kSweepBlock);
        K.unpack8(c.xp8, anchors_.data(), x, vb, ve);
        energy_.project_tested_contacts(c.x, &c.S.x_prev, c.scene.friction, vb, ve);
        block_velocities(c, k, vb, ve, slot);
        if (opt_.settle || opt_.freeze) block_motion(c, k, vb, ve);
        if (c.retest)
          list_moved(c, vb, ve, slot);  // (and the self-collision watch)
        else if (c.self_watch)
          self_motion(c, vb, ve, slot);
      }
  }
}

void XpbdSolver::sweep(const Step& c) {
  const auto t0 = std::chrono::steady_clock::now();
  auto items = [&](const xpbd::SweepPlan::Phase& P, int b, int e, int slot) {
    sweep_items(c, P, b, e, slot);
  };
  if (opt_.sweep_profile && pool_->size() == 1) {
    profile_sweep(items);
  } else if (!sweep_parallel_) {
    for (const auto& P : sweep_.phases()) items(P, P.b, P.e, 0);
  } else {
    ++sweeps_;
    // A pool thread other than the caller claims its share unless a test plays it absent.
    auto claims = [&](int wk) {
      return wk == 0 || (opt_.sweep_worker && wk != opt_.sweep_absent_worker);
    };
    if (sweep_.run(*pool_, items, claims)) ++sweep_takeovers_;
  }
  sweep_ms_ += ms_since(t0);
}

double XpbdSolver::sweep_megabytes(int n) const {
  if (!cooked_f32_ || sweep_.empty()) return 0.0;
  auto bytes = [](const auto& v) { return static_cast<double>(v.size() * sizeof(v[0])); };
  const auto& rp = row_packs8_;
  const double packs = bytes(tri_packs8_) + bytes(tri_packs16_) + bytes(tri_anchor8_) +
                       bytes(rp.off) + bytes(rp.colv) + bytes(rp.val) + bytes(rp.ik) +
                       bytes(rp.ai) + bytes(row_anchor8_);
  const double per_vertex = sizeof(xpbd::P4f) + 4 * sizeof(Vec3) + sizeof(double);
  return (packs + per_vertex * n) / (1 << 20);
}

template <class Items>
void XpbdSolver::profile_sweep(Items& items) {
  profile_ns_.assign(sweep_.num_runs(), 0.0);
  sweep_.run_timed(items, profile_ns_);
  auto add = [](xpbd::SweepPlan::Schedule& sum, const xpbd::SweepPlan::Schedule& s) {
    sum.work_ns += s.work_ns;
    sum.span_ns += s.span_ns;
    sum.border_ns += s.border_ns;
    sum.tail_ns += s.tail_ns;
  };
  add(profile_.ideal, sweep_.schedule(profile_ns_, 0));
  add(profile_.handover, sweep_.schedule(profile_ns_, kProfileHandoverNs));
  add(profile_.gated, sweep_.schedule(profile_ns_, 0, true));
  profile_.slots = sweep_.slots();
  ++profile_.sweeps;
}

// The sweep's contact retests: counted, their deepest penetration, the settling they end.
void XpbdSolver::collect_retests(Step& c) {
  if (!c.retest) return;
  long count = 0;
  for (const RetestPart& rp : retest_part_) {
    count += rp.count;
    c.st.max_penetration = std::max(c.st.max_penetration, rp.deepest);
  }
  if (count == 0) return;
  contacts_unlisted_ = true;  // (listed after the last substep)
  contact_retests_ += count;
  const size_t pieces = rest_.num_pieces();
  for (size_t p = 0; p < pieces; ++p)
    for (size_t k = p; k < unsettle_mark_.size(); k += pieces)
      if (unsettle_mark_[k]) {
        rest_.unsettle(static_cast<int>(p));
        break;
      }
}

void XpbdSolver::update_pieces(Step& c) {
  if (!(opt_.settle || opt_.freeze)) return;
  // The sweep's sums are of the velocities before the ties moved the seams' vertices after it:
  // with ties, the sums of the final velocities.
  if (c.fused && ties_.empty())
    rest_.sum_motion(block_motion_);
  else
    rest_.sum_motion(c.w, c.S.v, c.S.mass);
}

void XpbdSolver::schedule_rest(Step& c) {
  const bool hold = c.fresh && opt_.rest_holds_at_detection;
  rest_.settle_pieces(hold);
  rest_.freeze_pieces(c.cloth, c.s, hold);
}

}  // namespace drape::sim
