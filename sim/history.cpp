// Snapshot-based undo/redo (see history.hpp).
#include "sim/history.hpp"

#include <utility>

namespace drape::sim {

HistoryEntry History::make(std::string label, const Cloth& cloth, const OperationsState& ops) {
  HistoryEntry e;
  e.label = std::move(label);
  e.cloth = cloth;
  e.cut_strokes = ops.cut_strokes;
  e.pinched = ops.pinched;
  e.moving = ops.moving;
  e.move_vertex = ops.move_vertex;
  e.settling = ops.settling;
  e.hash = state_hash(cloth);
  return e;
}

void History::push(std::string label, const Cloth& cloth, const OperationsState& ops) {
  undo_.push_back(make(std::move(label), cloth, ops));
  while (undo_.size() > max_) undo_.pop_front();
  redo_.clear();
}

void History::restore(HistoryEntry& e, Cloth& cloth, OperationsState& ops) {
  // The restored cloth gets a fresh topology version so every solver re-cooks (the restored
  // topology may differ from what the solver last saw at an equal version number).
  const uint64_t version = cloth.topology_version + 1;
  cloth = std::move(e.cloth);
  cloth.topology_version = version;
  ops.cut_strokes = std::move(e.cut_strokes);
  ops.pinched = e.pinched;
  ops.moving = e.moving;
  ops.move_vertex = e.move_vertex;
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
  redo_.push_back(make(e.label, cloth, ops));
  std::string label = e.label;
  restore(e, cloth, ops);
  return label;
}

std::string History::redo(Cloth& cloth, OperationsState& ops) {
  if (redo_.empty()) return {};
  HistoryEntry e = std::move(redo_.back());
  redo_.pop_back();
  undo_.push_back(make(e.label, cloth, ops));
  std::string label = e.label;
  restore(e, cloth, ops);
  return label;
}

}  // namespace drape::sim
