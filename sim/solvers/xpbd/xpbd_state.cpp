// XpbdSolver's saved state (Solver::save_state, restore_state): what one step hands to the next
// beyond the cloth, so that a solver restored from it steps on bit for bit as the saved one.
#include <cmath>

#include "sim/solvers/xpbd/solver_xpbd.hpp"

namespace drape::sim {

namespace {
constexpr uint32_t kStateMagic = 0x44505258;  // "XRPD" little-endian
constexpr uint32_t kStateVersion = 1;
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
  if (const uint32_t v = in.u32(); v != kStateVersion)
    return "version " + std::to_string(v) + " (this program reads " +
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
  if (anchored) anchor_terms();
  if (!rest_.restore(in)) return "the pieces' rest state does not fit the cloth";
  return "";
}

}  // namespace drape::sim
