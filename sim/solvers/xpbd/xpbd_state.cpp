// XpbdSolver's saved state (Solver::save_state, restore_state): what one step hands to the next
// beyond the cloth, so that a solver restored from it steps on bit for bit as the saved one.
#include <cmath>

#include "sim/solvers/xpbd/solver_xpbd.hpp"

namespace drape::sim {

namespace {
constexpr uint32_t kStateMagic = 0x44505258;  // "XRPD" little-endian
// 2: the self-collision pairs carried from frame to frame (version 1 states still load).
constexpr uint32_t kStateVersion = 2;
}  // namespace

std::vector<unsigned char> XpbdSolver::save_state(const Cloth& cloth) const {
  // Not cooked for this cloth (never stepped, or cut since): the next step cooks afresh and
  // resets everything, as a fresh solver's first step does.
  if (last_cook_.cooks == 0 || !energy_.up_to_date(cloth) || opt_.single_precision != cooked_f32_ ||
      opt_.kernels != cooked_kernels_)
    return {};
  ByteWriter o;
  o.u32(kStateMagic);
  o.u32(kStateVersion);
  o.u8(cooked_f32_ ? 1 : 0);
  o.i32(cloth.num_vertices());
  o.i32(scratch_slots_);
  o.f64(h_prev_);
  // Without warm starts the multipliers start at zero in every substep: nothing to carry.
  const bool warm = opt_.warm_start > 0;
  auto lambdas = [&](const auto& v, size_t per) {
    const double* d = reinterpret_cast<const double*>(v.data());
    o.array(d, warm ? v.size() : 0, per);
  };
  lambdas(lambda_tri_, 1);
  lambdas(lambda_hinge_, 3);
  lambdas(lambda_row_, 3);
  lambdas(lambda_spring_, 1);
  o.array(anchors_.data(), anchors_.size());
  rest_.save(o);
  // The self-collision pairs, where they were found and the flags then (start_self).
  const bool self = x_self_.size() == static_cast<size_t>(cloth.num_vertices());
  o.array(reinterpret_cast<const double*>(x_self_.data()), self ? x_self_.size() : 0, 3);
  o.array(self_flags_.data(), self ? self_flags_.size() : 0);
  const auto& pairs = self_.contacts();
  o.u32(static_cast<uint32_t>(self ? pairs.size() : 0));
  for (size_t k = 0; self && k < pairs.size(); ++k) {
    o.i32(pairs[k].vertex);
    o.i32(pairs[k].triangle);
    o.u8(pairs[k].side > 0 ? 1 : 0);
  }
  return std::move(o.b);
}

std::string XpbdSolver::restore_state(const std::vector<unsigned char>& bytes, const Cloth& cloth) {
  if (bytes.empty()) return "";
  ByteReader in{bytes.data(), bytes.size()};
  std::string e = read_state(in, cloth);
  if (e.empty() && (!in.ok || in.i != in.n)) e = "its bytes are malformed";
  if (!e.empty()) {
    cook(cloth);  // as a fresh solver
    rest_.forget();
    h_prev_ = 0;
    return "XPBD state: " + e;
  }
  return "";
}

std::string XpbdSolver::read_state(ByteReader& in, const Cloth& cloth) {
  if (in.u32() != kStateMagic) return "not an XPBD solver's state";
  const uint32_t version = in.u32();
  if (version != 1 && version != kStateVersion)
    return "version " + std::to_string(version) + " (this program reads 1 and " +
           std::to_string(kStateVersion) + ")";
  const bool f32 = in.u8() != 0;
  const int n = in.i32(), slots = in.i32();
  if (f32 != opt_.single_precision)
    return std::string("saved by a solver in ") + (f32 ? "single" : "double") +
           " precision, restored into one in the other";
  cook(cloth);
  if (n != cloth.num_vertices() || slots != scratch_slots_)
    return "saved for " + std::to_string(n) + " vertices and " + std::to_string(slots) +
           " threads' scratch slots; the cloth has " + std::to_string(cloth.num_vertices()) +
           " vertices and the solver " + std::to_string(scratch_slots_);
  h_prev_ = in.f64();
  if (!std::isfinite(h_prev_) || h_prev_ < 0) return "the last substep's length is not a length";
  auto lambdas = [&](auto& v, size_t per) {
    using Item = typename std::decay_t<decltype(v)>::value_type;
    std::vector<Item> got;
    in.array<double>(got, per);
    if (!got.empty() && got.size() != v.size()) return false;
    if (!all_finite(reinterpret_cast<const double*>(got.data()), got.size() * per)) return false;
    if (!got.empty()) v.swap(got);
    return in.ok;
  };
  if (!lambdas(lambda_tri_, 1) || !lambdas(lambda_hinge_, 3) || !lambdas(lambda_row_, 3) ||
      !lambdas(lambda_spring_, 1))
    return "the warm-start multipliers do not fit the cloth's elements";
  in.array<double>(anchors_);
  const bool anchored = anchors_.size() == static_cast<size_t>(3 * (n + scratch_slots_));
  if (!in.ok || (!anchors_.empty() && (!anchored || !cooked_f32_)) ||
      !all_finite(anchors_.data(), anchors_.size()))
    return "the anchors do not fit the cloth";
  if (anchored) anchor_terms(anchors_, pool_.get());
  if (!rest_.restore(in)) return "the pieces' rest state does not fit the cloth";
  if (version >= 2) return read_self_state(in, cloth);
  return "";
}

// The self-collision pairs of a version 2 state (save_state), checked against the cloth.
std::string XpbdSolver::read_self_state(ByteReader& in, const Cloth& cloth) {
  const int n = cloth.num_vertices();
  const int nt = static_cast<int>(cloth.topo.triangles.size());
  in.array<double>(x_self_, 3);
  in.array<uint8_t>(self_flags_);
  const uint32_t count = in.count(9);  // a pair: vertex, triangle, side
  if (!in.ok ||
      (!x_self_.empty() &&
       (x_self_.size() != static_cast<size_t>(n) || self_flags_.size() != x_self_.size())) ||
      !all_finite(reinterpret_cast<const double*>(x_self_.data()), 3 * x_self_.size()) ||
      (x_self_.empty() && (count > 0 || !self_flags_.empty()))) {
    x_self_.clear();
    return "the self-collision pairs' positions do not fit the cloth";
  }
  std::vector<SelfContact> pairs(count);
  for (SelfContact& c : pairs) {
    c.vertex = in.i32();
    c.triangle = in.i32();
    const uint8_t side = in.u8();
    if (!in.ok || c.vertex < 0 || c.vertex >= n || c.triangle < 0 || c.triangle >= nt || side > 1) {
      x_self_.clear();
      return "a self-collision pair names no vertex or triangle of the cloth";
    }
    c.side = side ? 1.0 : -1.0;
  }
  self_.set_contacts(std::move(pairs));
  return "";
}

}  // namespace drape::sim
