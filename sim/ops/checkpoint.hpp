// World checkpoints: a whole picture of a draping session's sim state (the cloth with its rest
// state and topology after cuts, the scene's objects and hands, the operations in progress, the
// candidates, the pins settling, the undo and redo history) taken on the sim thread at the start
// of a tick, written on another thread, read back to resume a session without replaying its
// journal from the start (docs/sessions.md).
//
// File layout: the 8-byte magic "DRAPECKP", a u32 format version, then records as in the
// journal (a u32 payload length, a u32 CRC32 of the payload, the payload, whose first byte is its
// kind): the header (the journal header's fields that rebuild the static scene — the form, the
// solver — the tick and the operation controller's step), the world (cloth and scene objects),
// the operations' state, the solver's state (format 2), one record per history entry (undo
// stack, then redo stack, oldest first) and the end (the entry counts). A checkpoint without its
// end record is incomplete and is not used; loading it says where it stops.
//
// The solver's state (Solver::save_state: XPBD's warm starts, which pieces sleep and how far
// they settled, the finish's anchors, the single-precision anchors) is in the checkpoint from
// format 2 on: a World restored from it steps on bit for bit as the World it was taken from, so
// taking a checkpoint changes nothing in the session. A checkpoint of format 1 (written by
// sessions that restarted their solver at each checkpoint) is read as well and restores a fresh
// solver, as those sessions did.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "sim/ops/operation_controller.hpp"

namespace drape::sim {

inline constexpr uint32_t kCheckpointFormat = 2;
inline constexpr uint32_t kCheckpointFormatNoSolver = 1;  // still read

struct WorldCheckpoint {
  std::map<std::string, std::string> header;  // the journal's header fields
  uint64_t tick = 0;                          // taken at the start of this tick
  uint64_t step = 0;                          // OperationController::step()
  Cloth cloth;
  SceneObjects scene;  // without the form (static: rebuilt from the header)
  bool paused = false;
  OperationsState ops;  // without last_cut (a result kept for tests)
  std::vector<std::shared_ptr<const HistoryEntry>> undo, redo;
  // The solver's name and Solver::save_state (empty: nothing to carry, or a format-1 file).
  std::string solver;
  std::vector<unsigned char> solver_state;
};

// Takes checkpoints on the sim thread: copies the world's cloth, scene and operations, and each
// history entry once (entries do not change while stacked; copies are kept by serial and shared
// by later checkpoints), so a checkpoint costs a copy of the current cloth and of the entries
// pushed since the last one.
class CheckpointTaker {
 public:
  std::shared_ptr<WorldCheckpoint> take(const World& w, const OperationController& ops,
                                        const std::map<std::string, std::string>& header);

 private:
  std::shared_ptr<const HistoryEntry> entry(
      const HistoryEntry& e, std::map<uint64_t, std::shared_ptr<const HistoryEntry>>& kept);
  std::map<uint64_t, std::shared_ptr<const HistoryEntry>> kept_;
};

std::vector<unsigned char> encode_checkpoint(const WorldCheckpoint& c);
// Decodes a checkpoint file's bytes; `source` names it in messages. Returns "" when whole and
// valid, else the error naming the source, the byte offset and the field. A file cut off or
// corrupted after its header reports where its whole records end.
std::string decode_checkpoint(const unsigned char* p, size_t n, const std::string& source,
                              WorldCheckpoint& out);
std::string load_checkpoint(const std::string& path, WorldCheckpoint& out);
// Writes the checkpoint whole or not at all: into path + ".tmp", flushed to the disk, then
// renamed over path. Returns "" or the error (the temporary file is removed).
std::string write_checkpoint_file(const std::string& path, const WorldCheckpoint& c);

// Puts a checkpoint's state into a World built from its header (form, fresh solver) and into the
// controller installed on it (operations, history, step), the solver's state into its solver.
// Returns "" or why the solver's state does not fit the World's solver (another solver, another
// configuration); the World then has the checkpoint's state with a fresh solver.
std::string restore_checkpoint(const WorldCheckpoint& c, World& w, OperationController& ops);

// The checkpoint files' writer thread: submit() never blocks the sim thread; a checkpoint not yet
// started when a newer one comes is dropped for it. Keeps the newest `keep` files it wrote in its
// directory and removes the older ones. Anything handed over as `retire` (an old solver) is
// destroyed on this thread.
class CheckpointWriter {
 public:
  explicit CheckpointWriter(std::string dir, int keep = 2);
  ~CheckpointWriter();  // writes what is pending, then joins
  CheckpointWriter(const CheckpointWriter&) = delete;
  CheckpointWriter& operator=(const CheckpointWriter&) = delete;
  void submit(std::shared_ptr<const WorldCheckpoint> c, std::string file,
              std::shared_ptr<void> retire = nullptr);
  // Messages of failed writes since the last call (any thread).
  std::vector<std::string> take_errors();
  int written() const;

 private:
  void run();
  void write_one(const WorldCheckpoint& c, const std::string& file);
  std::string dir_;
  int keep_;
  mutable std::mutex mu_;
  std::condition_variable cv_;
  std::shared_ptr<const WorldCheckpoint> pending_;
  std::string pending_file_;
  std::vector<std::shared_ptr<void>> retired_;
  bool stop_ = false;
  int written_ = 0;
  std::vector<std::string> files_, errors_;
  std::thread thread_;
};

// "checkpoint-<tick>.bin": the file name of the checkpoint taken at `tick`.
std::string checkpoint_file_name(uint64_t tick);

}  // namespace drape::sim
