// CookAheadSolver (see header): the edit's cook on a worker, the base stepped meanwhile, the
// swap at a fixed step.
#include "sim/solvers/cook_ahead.hpp"

#if defined(__linux__)
#include <pthread.h>
#include <sched.h>
#endif

#include <algorithm>
#include <chrono>
#include <cstring>
#include <functional>
#include <unordered_map>

#include "sim/core/cloth_io.hpp"
#include "sim/core/memory.hpp"
#include "sim/core/stopwatch.hpp"
#include "sim/core/thread_pool.hpp"

namespace drape::sim {

namespace {

constexpr uint32_t kMagic = 0x48414b43;  // "CKAH" little-endian
constexpr uint32_t kVersion = 1;
constexpr int kTrianglesPerTicks = 32768;
constexpr uint8_t kDriven = kFlagPinned | kFlagPinched | kFlagKinematic;

// The topology, fabric and state of a cloth without its incidence (a solver does not read it).
void copy_without_incidence(const Cloth& from, Cloth& to) {
  to.topo = from.topo;
  to.state = from.state;
  to.fabric = from.fabric;
  to.topology_version = from.topology_version;
  to.incidence = ClothIncidence{};
}

// Single precision: the anchors of `base`'s vertices (3 each, then its scratch vertices' zeros)
// for the n vertices of a cloth that map onto them (src), with as many scratch vertices; none
// when the base has none.
std::vector<double> mapped_anchors(const XpbdSolver& base, int nb, const std::vector<int32_t>& src,
                                   int n) {
  const std::vector<double>& a = base.anchors();
  if (a.size() < 3 * static_cast<size_t>(nb) || static_cast<int>(src.size()) < n) return {};
  std::vector<double> m(a.size() - 3 * static_cast<size_t>(nb) + 3 * static_cast<size_t>(n), 0.0);
  for (int j = 0; j < n; ++j)
    for (int k = 0; k < 3; ++k) m[3 * j + k] = a[3 * static_cast<size_t>(src[j]) + k];
  return m;
}

// The cores this process may run on.
int usable_cores() {
#if defined(__linux__)
  cpu_set_t set;
  if (sched_getaffinity(0, sizeof set, &set) == 0) return CPU_COUNT(&set);
#endif
  return std::max(1u, std::thread::hardware_concurrency());
}

// A thread that only runs on a core nothing else wants (Linux SCHED_IDLE; any user may choose
// it) and yields it at once: work off the ticks that must not stretch them.
void idle_priority() {
#if defined(__linux__)
  sched_param none{};
  pthread_setschedparam(pthread_self(), SCHED_IDLE, &none);
#endif
}

}  // namespace

CookAheadSolver::CookAheadSolver(XpbdOptions xpbd, CookAheadOptions opt)
    : opt_(opt), active_(std::make_unique<XpbdSolver>(xpbd)) {
  using K = CookAheadOptions::KeepOff;
  keep_off_ = opt_.keep_off_steps == K::kAlways ||
              (opt_.keep_off_steps == K::kAuto &&
               usable_cores() < std::max(1, xpbd.threads) + std::max(1, opt_.worker_threads));
}

CookAheadSolver::~CookAheadSolver() {
  join();
  if (reaper_.joinable()) reaper_.join();
}

void CookAheadSolver::join() {
  release();     // a worker not yet released would wait forever
  gate_.open();  // and one held at the gate
  if (worker_.joinable()) worker_.join();
  copying_ = nullptr;
}

int CookAheadSolver::ticks_for(const Cloth& cloth, bool self_collision) const {
  const int per = (cloth.topo.num_triangles() + kTrianglesPerTicks - 1) / kTrianglesPerTicks;
  const int ticks = opt_.ticks * std::max(1, per);
  return std::max(1, self_collision ? (ticks * opt_.self_collision_percent + 99) / 100 : ticks);
}

bool CookAheadSolver::map_onto_base(const Cloth& cloth) {
  const int nb = base_.num_vertices(), nc = cloth.num_vertices();
  if (!have_base_ || nc < nb || !same_values(cloth.fabric, base_.fabric)) return false;
  if (cloth.topology_version == base_.topology_version && nc == nb) return false;
  const auto& bt = base_.topo;
  const auto& ct = cloth.topo;
  for (int i = 0; i < nb; ++i)
    if (ct.material[i] != bt.material[i] || ct.vertex_origin[i] != bt.vertex_origin[i])
      return false;
  // The base vertices of each origin a new vertex has.
  std::unordered_map<int32_t, std::vector<int32_t>> of_origin;
  for (int j = nb; j < nc; ++j) of_origin[ct.vertex_origin[j]];
  for (int i = 0; i < nb; ++i)
    if (auto it = of_origin.find(ct.vertex_origin[i]); it != of_origin.end())
      it->second.push_back(i);
  src_.resize(nc);
  for (int i = 0; i < nb; ++i) src_[i] = i;
  const auto& x = cloth.state.x;
  for (int j = nb; j < nc; ++j) {
    const auto& cand = of_origin[ct.vertex_origin[j]];
    auto same = std::find_if(cand.begin(), cand.end(), [&](int32_t i) {
      return std::memcmp(x[i].data(), x[j].data(), sizeof(double) * 3) == 0;
    });
    if (same == cand.end()) return false;
    src_[j] = *same;
  }
  return true;
}

bool CookAheadSolver::mapped(const Cloth& cloth) {
  if (cloth.topology_version != mapped_version_ || cloth.num_vertices() != mapped_n_) {
    map_ok_ = map_onto_base(cloth);
    mapped_version_ = cloth.topology_version;
    mapped_n_ = cloth.num_vertices();
  }
  return map_ok_;
}

void CookAheadSolver::launch(std::function<void(ThreadPool&)> job) {
  // The worker before this one (a spare energy's build) ends first, on the new thread: the step
  // never waits for it.
  released_.store(false, std::memory_order_relaxed);
  worker_ = std::thread([this, prev = std::move(worker_), job = std::move(job)]() mutable {
    if (prev.joinable()) prev.join();
    // Not during the step that launched it: the cook's memory traffic would slow that step,
    // which already carries the edit (measured: 7-11 ms instead of 5 at 128^2 on two cores).
    released_.wait(false, std::memory_order_acquire);
    if (opt_.idle_priority) idle_priority();  // (the pool made below inherits it)
    set_thread_gate(&gate_);
    if (opt_.worker_delay_ms > 0)
      std::this_thread::sleep_for(std::chrono::milliseconds(opt_.worker_delay_ms));
    ThreadPool pool(std::max(1, opt_.worker_threads), &gate_);
    job(pool);
  });
}

void CookAheadSolver::release() {
  if (!released_.load(std::memory_order_relaxed))
    released_at_.store(std::chrono::steady_clock::now().time_since_epoch().count(),
                       std::memory_order_relaxed);
  released_.store(true, std::memory_order_release);
  released_.notify_all();
}

void CookAheadSolver::start(const Cloth& cloth, int steps, double dt) {
  copy_without_incidence(cloth, next_cloth_);
  next_ = std::make_unique<XpbdSolver>(active_->options());
  // The swap's step starts from the base's anchors then (adopt()): the worker makes the element
  // terms at its anchors now, which serve when the base keeps them until the swap.
  next_src_ = src_;
  next_src_.resize(cloth.num_vertices());
  std::vector<double> anchors =
      mapped_anchors(*active_, base_.num_vertices(), next_src_, cloth.num_vertices());
  // The base steps as it was cooked: a vertex let go in the window (pinned when the base was
  // kept) has its own inverse mass; the step reads it only for free vertices.
  ClothState& B = base_.state;
  for (int i = 0; i < base_.num_vertices(); ++i)
    B.inv_mass[i] = B.mass[i] > 0 ? 1.0 / B.mass[i] : 0.0;
  done_.store(false, std::memory_order_relaxed);
  copying_ = next_.get();
  launch([this, s = next_.get(), spare = opt_.spare_energy, dt, self = self_collision_,
          anchors = std::move(anchors)](ThreadPool& pool) {
    using Clock = std::chrono::steady_clock;
    const Clock::time_point t0{Clock::duration{released_at_.load(std::memory_order_relaxed)}};
    start_ms_.store(ms_since(t0), std::memory_order_relaxed);
    ready_ms_.store(-1, std::memory_order_relaxed);
    spare_ms_.store(-1, std::memory_order_relaxed);
    if (spare_) s->seed_energy(std::move(*spare_));
    spare_.reset();
    const long faults0 = process_page_faults();
    s->prepare(next_cloth_, &pool);
    // The first step's masses, blocks and anchor terms, off the swap's step.
    if (opt_.warm) s->warm(next_cloth_, dt, anchors, self, &pool);
    ready_faults_.store(process_page_faults() - faults0, std::memory_order_relaxed);
    ready_ms_.store(ms_since(t0), std::memory_order_relaxed);
    done_.store(true, std::memory_order_release);
    done_.notify_all();
    // The next edit's cook starts from this topology's energy: a copy of what it reads, made
    // after the swap may take the solver (it reads nothing the steps write; a step that cooks
    // again joins this worker first), instead of a second build after the swap.
    if (spare) spare_ = std::make_unique<ClothEnergy>(s->energy().spare_copy());
    spare_ms_.store(ms_since(t0), std::memory_order_relaxed);
  });
  pending_ = true;
  steps_left_ = steps;
}

void CookAheadSolver::start_spare(const Cloth& cloth) {
  auto copy = std::make_shared<Cloth>();
  copy_without_incidence(cloth, *copy);
  // The energy alone, as the solver's cook builds it (not the solver's packs and plan: a cut
  // soon after would wait for them).
  launch([this, copy, eo = XpbdSolver::cook_energy_options(active_->options())](ThreadPool& pool) {
    ClothEnergy e;
    e.build(*copy, eo, &pool);
    spare_ = std::make_unique<ClothEnergy>(e.spare_copy());
  });
}

void CookAheadSolver::adopt() {
  // The worker may still be copying the spare energy after it has cooked: it is joined later
  // (the next launch, a cook in a step, a restore, the destructor).
  if (!done_.load(std::memory_order_acquire)) {
    ++waits_;
    release();
    with_gate_open([this] { done_.wait(false, std::memory_order_acquire); });
  }
  next_->options() = active_->options();
  next_->set_ties(active_->ties(), active_->tie_passes());
  next_->trade_pool(*active_);
  // The new vertices start from their base vertices' anchors, as they start from their positions.
  next_->take_anchors(
      mapped_anchors(*active_, base_.num_vertices(), next_src_, next_cloth_.num_vertices()));
  std::unique_ptr<XpbdSolver> old = std::move(active_);
  auto old_base = std::make_unique<Cloth>(std::move(base_));
  active_ = std::move(next_);
  base_ = std::move(next_cloth_);
  next_cloth_ = Cloth{};
  mapped_version_ = 0;
  pending_ = false;
  steps_left_ = 0;
  // The retired solver and base cloth are freed on a thread of their own once this step has
  // ended (the gate): their memory's release (unmaps, the pool's joins) stays off the steps.
  if (reaper_.joinable()) with_gate_open([this] { reaper_.join(); });
  reaper_ = std::thread([p = std::move(old), b = std::move(old_base), idle = opt_.idle_priority,
                         gate = &gate_]() mutable {
    if (idle) idle_priority();
    gate->pass();
    p.reset();
    b.reset();
  });
}

void CookAheadSolver::with_gate_open(const std::function<void()>& wait) {
  // The worker's threads and the reaper wait at the gate: they pass it while the step waits for
  // them, and it closes again after.
  const bool closed = gate_.closed();
  gate_.open();
  wait();
  if (closed) gate_.close();
}

void CookAheadSolver::keep_base(const Cloth& cloth) {
  copy_without_incidence(cloth, base_);
  have_base_ = true;
  mapped_version_ = 0;
}

StepStats CookAheadSolver::step(Cloth& cloth, const SceneObjects& scene, double dt) {
  // The worker's threads wait while the step runs (TickGate), unless the steps leave no time
  // between them (they overran their period): the worker then cooks beside them, at SCHED_IDLE.
  using Clock = std::chrono::steady_clock;
  const bool close = opt_.keep_off_steps == CookAheadOptions::KeepOff::kAlways ||
                     (keep_off_ && Clock::now() - last_step_end_ >= std::chrono::milliseconds(1));
  struct Closed {
    TickGate* g;
    Clock::time_point& end;
    ~Closed() {
      if (g) g->open();
      end = Clock::now();
    }
  } closed{close ? &gate_ : nullptr, last_step_end_};
  if (close) gate_.close();
  self_collision_ = scene.self_collision;
  if (pending_) {
    const bool edited_again = cloth.topology_version != next_cloth_.topology_version ||
                              cloth.num_vertices() != next_cloth_.num_vertices();
    // Another edit in the window must map onto the base too, or the pending one lands now.
    if (steps_left_ > 0 && (!edited_again || mapped(cloth))) {
      --steps_left_;
      return step_base(cloth, scene, dt);
    }
    adopt();
  }
  if (!active_->cooked_for(cloth) && mapped(cloth)) {
    ++edits_ahead_;
    start(cloth, ticks_for(cloth, scene.self_collision) - 1, dt);
    const StepStats st = step_base(cloth, scene, dt);
    release();  // the worker starts once the edit's own step is done (see launch())
    return st;
  }
  if (!active_->cooked_for(cloth)) {
    if (have_base_) ++edits_in_step_;
    // A worker copying the active solver's energy (start()) ends before the cook changes it.
    if (copying_ == active_.get()) with_gate_open([this] { join(); });
  }
  StepStats st = active_->step(cloth, scene, dt);
  // A new base cooked in the step: the next edit's cook starts from its energy, built on a
  // worker. An adopted base is no new base here: the worker that cooked it kept a copy of its
  // energy (start()).
  const bool new_base = !have_base_ || base_.topology_version != cloth.topology_version ||
                        base_.num_vertices() != cloth.num_vertices();
  if (new_base) keep_base(cloth);
  if (new_base && opt_.spare_energy) {
    start_spare(base_);
    release();
  }
  return st;
}

StepStats CookAheadSolver::step_base(Cloth& cloth, const SceneObjects& scene, double dt) {
  ClothState& B = base_.state;
  ClothState& C = cloth.state;
  const int nb = base_.num_vertices(), nc = cloth.num_vertices();
  for (int i = 0; i < nb; ++i) {
    B.x[i] = C.x[i];
    B.x_prev[i] = C.x_prev[i];
    B.v[i] = C.v[i];
    B.flags[i] = C.flags[i];
  }
  // A hand, pin or move on a new vertex acts on its base vertex.
  for (int j = nb; j < nc; ++j) {
    const uint8_t f = C.flags[j] & kDriven;
    if (!f) continue;
    const int s = src_[j];
    B.flags[s] |= f;
    B.x[s] = C.x[j];
    B.x_prev[s] = C.x_prev[j];
    B.v[s] = C.v[j];
  }
  B.time = C.time;
  const StepStats st = active_->step(base_, scene, dt);
  for (int i = 0; i < nb; ++i) {
    C.x[i] = B.x[i];
    C.x_prev[i] = B.x_prev[i];
    C.v[i] = B.v[i];
    C.flags[i] = static_cast<uint8_t>((C.flags[i] & ~kFlagFrozen) | (B.flags[i] & kFlagFrozen));
  }
  for (int j = nb; j < nc; ++j) {
    if (C.flags[j] & kDriven) continue;
    const int s = src_[j];
    C.x[j] = B.x[s];
    C.x_prev[j] = B.x_prev[s];
    C.v[j] = B.v[s];
    C.flags[j] = static_cast<uint8_t>((C.flags[j] & ~kFlagFrozen) | (B.flags[s] & kFlagFrozen));
  }
  C.time = B.time;
  return st;
}

std::vector<unsigned char> CookAheadSolver::save_state(const Cloth& cloth) const {
  if (!pending_) return active_->save_state(cloth);
  ByteWriter o;
  o.u32(kMagic);
  o.u32(kVersion);
  o.i32(steps_left_);
  put_cloth(o, base_);
  put_ints(o, src_);
  const std::vector<unsigned char> a = active_->save_state(base_);
  o.u32(static_cast<uint32_t>(a.size()));
  o.b.insert(o.b.end(), a.begin(), a.end());
  return o.b;
}

std::string CookAheadSolver::restore_state(const std::vector<unsigned char>& bytes,
                                           const Cloth& cloth) {
  join();
  next_.reset();
  spare_.reset();  // built for the cloth before the restore
  pending_ = false;
  steps_left_ = 0;
  have_base_ = false;
  mapped_version_ = 0;
  const bool framed = bytes.size() >= 4 && bytes[0] == (kMagic & 0xff) &&
                      bytes[1] == ((kMagic >> 8) & 0xff) && bytes[2] == ((kMagic >> 16) & 0xff) &&
                      bytes[3] == (kMagic >> 24);
  if (!framed) return active_->restore_state(bytes, cloth);
  auto fail = [&](const std::string& why) {
    active_ = std::make_unique<XpbdSolver>(active_->options());
    return "cook-ahead state: " + why;
  };
  ByteReader in{bytes.data(), bytes.size()};
  in.u32();
  if (const uint32_t v = in.u32(); v != kVersion)
    return fail("version " + std::to_string(v) + " (this program reads " +
                std::to_string(kVersion) + ")");
  const int steps = in.i32();
  Cloth base;
  get_cloth(in, base);
  std::vector<int32_t> src;
  get_ints(in, src);
  const uint32_t len = in.count(1);
  if (!in.ok) return fail("its bytes are malformed");
  std::vector<unsigned char> a(bytes.begin() + static_cast<long>(in.i),
                               bytes.begin() + static_cast<long>(in.i + len));
  in.i += len;
  if (in.i != in.n) return fail("its bytes are malformed");
  if (steps < 0 || steps > std::max(ticks_for(cloth, false), ticks_for(cloth, true)))
    return fail("steps left out of range");
  if (const std::string e = base.validate(); !e.empty()) return fail("base cloth: " + e);
  const int nb = base.num_vertices();
  if (static_cast<int>(src.size()) != cloth.num_vertices() || nb > cloth.num_vertices())
    return fail("the base does not fit the cloth's " + std::to_string(cloth.num_vertices()) +
                " vertices");
  for (size_t j = 0; j < src.size(); ++j)
    if (src[j] < 0 || src[j] >= nb || (static_cast<int>(j) < nb && src[j] != static_cast<int>(j)))
      return fail("vertex " + std::to_string(j) + " maps onto no base vertex");
  base_ = std::move(base);
  src_ = std::move(src);
  have_base_ = true;
  map_ok_ = true;
  mapped_version_ = cloth.topology_version;
  mapped_n_ = cloth.num_vertices();
  if (std::string e = active_->restore_state(a, base_); !e.empty()) {
    have_base_ = false;
    return fail(e);
  }
  active_->prepare(base_);
  start(cloth, steps, 0.0);  // (the frame's length is not saved: the swap's step makes the blocks)
  release();
  return "";
}

}  // namespace drape::sim
