// Undo/redo of every operation, topology edits included: each entry is a full copy of the cloth
// (topology + state), the cut strokes and which particles hands and move held, taken just
// before the operation, so undo restores the exact previous state (same state_hash).
#pragma once

#include <array>
#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include "sim/cloth.hpp"
#include "sim/operations.hpp"

namespace drape::sim {

struct HistoryEntry {
  std::string label;  // the operation that followed this state ("pinch", "cut", ...)
  Cloth cloth;
  std::vector<CutStroke> cut_strokes;
  std::array<int32_t, 2> pinched{-1, -1};
  bool moving = false;
  std::array<int32_t, 2> move_vertex{-1, -1};
  std::vector<SettlingPin> settling;
  uint64_t hash = 0;  // state_hash(cloth) when taken
};

class History {
 public:
  explicit History(size_t max_entries = 64) : max_(max_entries) {}
  // Records the state before an operation; clears the redo stack.
  void push(std::string label, const Cloth& cloth, const OperationsState& ops);
  bool can_undo() const { return !undo_.empty(); }
  bool can_redo() const { return !redo_.empty(); }
  // Restores the state before the last operation into (cloth, ops); the current state goes to
  // the redo stack. Strokes being drawn are discarded. Returns the label undone, or an empty
  // string when there is none.
  std::string undo(Cloth& cloth, OperationsState& ops);
  std::string redo(Cloth& cloth, OperationsState& ops);
  void clear() { undo_.clear(), redo_.clear(); }
  size_t undo_size() const { return undo_.size(); }
  size_t redo_size() const { return redo_.size(); }
  const HistoryEntry* last() const { return undo_.empty() ? nullptr : &undo_.back(); }

 private:
  static HistoryEntry make(std::string label, const Cloth& cloth, const OperationsState& ops);
  static void restore(HistoryEntry& e, Cloth& cloth, OperationsState& ops);
  size_t max_;
  std::deque<HistoryEntry> undo_, redo_;
};

}  // namespace drape::sim
