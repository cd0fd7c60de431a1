// Undo/redo of every operation, topology edits included: each entry is a full copy of the cloth
// (topology + state), the cut strokes and which particles hands and move held, taken just
// before the operation, so undo restores the exact previous state (same state_hash). Undo and
// redo move the current cloth to the other stack (no copy); the kept incidence travels with it.
#pragma once

#include <array>
#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include "sim/core/cloth.hpp"
#include "sim/ops/operations.hpp"

namespace drape::sim {

struct HistoryEntry {
  // Unique in the process, given when the entry is made: an entry does not change while it is
  // stacked, so a checkpoint copies each serial once (checkpoint.hpp).
  uint64_t serial = 0;
  std::string label;  // the operation that followed this state ("pinch", "cut", ...)
  Cloth cloth;
  std::vector<CutStroke> cut_strokes;
  std::array<int32_t, 2> pinched{-1, -1};
  bool moving = false;
  std::array<int32_t, 2> move_vertex{-1, -1};
  std::array<Vec3, 2> move_offset{Vec3::Zero(), Vec3::Zero()};
  std::array<bool, 2> move_grabbed{false, false};
  std::vector<SettlingPin> settling;
};

class History {
 public:
  explicit History(size_t max_entries = 64) : max_(max_entries) {}
  // Records the state before an operation; clears the redo stack. The rvalue form takes a copy
  // the caller already made (see copy_state), so the cloth is copied once per operation.
  void push(std::string label, const Cloth& cloth, const OperationsState& ops);
  void push(std::string label, Cloth&& cloth, const OperationsState& ops);
  // A copy of the cloth for the history: topology and state, without the kept incidence
  // (rebuilt when next needed), so storing an operation copies less.
  static Cloth copy_state(const Cloth& cloth);
  // The same copy into a buffer allocated (and its pages touched) beforehand by
  // prepare_spare(), so the copy an operation takes for undo does not allocate: the
  // allocation happens in a tick (after_step), not in the command. Falls back to copy_state.
  Cloth take_copy(const Cloth& cloth);
  void prepare_spare(const Cloth& like);
  bool can_undo() const { return !undo_.empty(); }
  bool can_redo() const { return !redo_.empty(); }
  // Restores the state before the last operation into (cloth, ops); the current state goes to
  // the redo stack. Strokes being drawn are discarded. Returns the label undone, or an empty
  // string when there is none.
  std::string undo(Cloth& cloth, OperationsState& ops);
  std::string redo(Cloth& cloth, OperationsState& ops);
  void clear() { undo_.clear(), redo_.clear(); }
  // A change that needs no undo point of its own (the end of a pinch or move: the entry taken
  // at its begin covers it) still makes the redo stack stale.
  void drop_redo() { redo_.clear(); }
  size_t undo_size() const { return undo_.size(); }
  size_t redo_size() const { return redo_.size(); }
  const std::deque<HistoryEntry>& undo_entries() const { return undo_; }
  const std::deque<HistoryEntry>& redo_entries() const { return redo_; }
  // Replaces both stacks (a checkpoint's; each entry gets a fresh serial).
  void restore_entries(std::deque<HistoryEntry> undo, std::deque<HistoryEntry> redo);
  const HistoryEntry* last() const { return undo_.empty() ? nullptr : &undo_.back(); }

 private:
  static HistoryEntry make(std::string label, Cloth&& cloth, const OperationsState& ops);
  static void restore(HistoryEntry& e, Cloth& cloth, OperationsState& ops);
  size_t max_;
  std::deque<HistoryEntry> undo_, redo_;
  Cloth spare_;  // pre-allocated copy target (see take_copy)
};

}  // namespace drape::sim
