// Snapshot-based undo/redo (see history.hpp).
#include "sim/ops/history.hpp"

#include <atomic>
#include <utility>

namespace drape::sim {

Cloth History::copy_state(const Cloth& cloth) {
  Cloth c;
  c.topo = cloth.topo;
  c.state = cloth.state;
  c.fabric = cloth.fabric;
  c.topology_version = cloth.topology_version;
  return c;
}

namespace {
// Gives v at least n elements' worth of touched storage (resize writes them).
template <class V>
void touch(V& v, size_t n) {
  if (v.capacity() < n) {
    V fresh;
    fresh.resize(n);
    v.swap(fresh);
  }
}
}  // namespace

void History::prepare_spare(const Cloth& c) {
  touch(spare_.topo.triangles, c.topo.triangles.size());
  touch(spare_.topo.material, c.topo.material.size());
  touch(spare_.topo.vertex_zone, c.topo.vertex_zone.size());
  touch(spare_.topo.triangle_zone, c.topo.triangle_zone.size());
  touch(spare_.topo.vertex_origin, c.topo.vertex_origin.size());
  touch(spare_.state.x, c.state.x.size());
  touch(spare_.state.x_prev, c.state.x_prev.size());
  touch(spare_.state.v, c.state.v.size());
  touch(spare_.state.mass, c.state.mass.size());
  touch(spare_.state.inv_mass, c.state.inv_mass.size());
  touch(spare_.state.flags, c.state.flags.size());
}

Cloth History::take_copy(const Cloth& cloth) {
  // Copy assignment reuses the spare's storage when it is large enough (no allocation).
  spare_.topo = cloth.topo;
  spare_.state = cloth.state;
  spare_.fabric = cloth.fabric;
  spare_.topology_version = cloth.topology_version;
  spare_.incidence = ClothIncidence{};
  Cloth out = std::move(spare_);
  spare_ = Cloth{};
  return out;
}

namespace {
uint64_t next_serial() {
  static std::atomic<uint64_t> serial{0};
  return ++serial;
}
}  // namespace

void History::restore_entries(std::deque<HistoryEntry> undo, std::deque<HistoryEntry> redo) {
  for (auto* stack : {&undo, &redo})
    for (HistoryEntry& e : *stack) e.serial = next_serial();
  undo_ = std::move(undo);
  redo_ = std::move(redo);
}

HistoryEntry History::make(std::string label, Cloth&& cloth, const OperationsState& ops) {
  HistoryEntry e;
  e.serial = next_serial();
  e.label = std::move(label);
  e.cloth = std::move(cloth);
  e.cut_strokes = ops.cut_strokes;
  e.pinched = ops.pinched;
  e.moving = ops.moving;
  e.move_vertex = ops.move_vertex;
  e.move_offset = ops.move_offset;
  e.move_grabbed = ops.move_grabbed;
  e.settling = ops.settling;
  return e;
}

void History::push(std::string label, const Cloth& cloth, const OperationsState& ops) {
  push(std::move(label), copy_state(cloth), ops);
}

void History::push(std::string label, Cloth&& cloth, const OperationsState& ops) {
  undo_.push_back(make(std::move(label), std::move(cloth), ops));
  while (undo_.size() > max_) undo_.pop_front();
  redo_.clear();
}

void History::restore(HistoryEntry& e, Cloth& cloth, OperationsState& ops) {
  // The restored cloth gets a fresh topology version so every solver re-cooks (the restored
  // topology may differ from what the solver last saw at an equal version number). Its kept
  // incidence, when it has one for its topology, stays valid under the new number.
  const uint64_t version = cloth.topology_version + 1;
  cloth = std::move(e.cloth);
  if (cloth.incidence.built && cloth.incidence.version == cloth.topology_version)
    cloth.incidence.version = version;
  cloth.topology_version = version;
  ops.cut_strokes = std::move(e.cut_strokes);
  ops.pinched = e.pinched;
  ops.moving = e.moving;
  ops.move_vertex = e.move_vertex;
  ops.move_offset = e.move_offset;
  ops.move_grabbed = e.move_grabbed;
  ops.settling = std::move(e.settling);
  for (int h = 0; h < 2; ++h) {
    ops.cutting[h] = false;
    ops.stroke[h].clear();
  }
}

std::string History::undo(Cloth& cloth, OperationsState& ops) {
  if (undo_.empty()) return {};
  HistoryEntry e = std::move(undo_.back());
  undo_.pop_back();
  std::string label = e.label;
  redo_.push_back(make(e.label, std::move(cloth), ops));  // the current state, moved
  restore(e, cloth, ops);
  return label;
}

std::string History::redo(Cloth& cloth, OperationsState& ops) {
  if (redo_.empty()) return {};
  HistoryEntry e = std::move(redo_.back());
  redo_.pop_back();
  std::string label = e.label;
  undo_.push_back(make(e.label, std::move(cloth), ops));
  restore(e, cloth, ops);
  return label;
}

}  // namespace drape::sim
