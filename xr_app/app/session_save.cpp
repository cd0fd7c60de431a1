// Saving a draping session ("save session") and opening a saved one (drape open FILE): the saved
// file is a World checkpoint (sim/ops/checkpoint.hpp) with the scene options in its header.
#include <chrono>
#include <cstdio>
#include <filesystem>

#include "sim/ops/checkpoint.hpp"
#include "xr_app/app/draping_session.hpp"
#include "xr_app/app/session_record.hpp"
#include "xr_app/output_files.hpp"

namespace drape::app {

namespace {
constexpr const char* kSavedName = "saved_session.drape";
}  // namespace

void DrapingSession::save_session(int64_t frame) {
  if (!sim_ || !ops_) return;
  if (!opt_.garment.empty()) {  // a saved session's header names the panel's scene only
    rep_.note("save: frame " + std::to_string(frame) + ": a garment session is not saved");
    feedback_.refused(frame, "save: a garment session is not saved");
    return;
  }
  auto taken = std::make_shared<std::promise<std::shared_ptr<sim::WorldCheckpoint>>>();
  std::future<std::shared_ptr<sim::WorldCheckpoint>> copy = taken->get_future();
  sim_->post([taken, ops = ops_, header = journal_header(opt_).fields](sim::World& w) {
    sim::CheckpointTaker taker;
    taken->set_value(taker.take(w, *ops, header));
  });
  const std::string dir = opt_.out_dir.empty() ? std::string(".") : opt_.out_dir;
  rep_.note("save: frame " + std::to_string(frame) + ": saving the session");
  saves_.push_back(std::async(std::launch::async, [copy = std::move(copy), dir]() mutable {
    const std::string path = dir + "/" + kSavedName;
    if (copy.wait_for(std::chrono::seconds(10)) != std::future_status::ready)
      return "session not saved: " + path + ": the sim did not take the copy";
    auto c = copy.get();
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    const std::string e = write_whole(dir, [&](const std::string& into) {
      return sim::write_checkpoint_file(into + "/" + kSavedName, *c);
    });
    if (!e.empty()) return "session not saved: " + e + " (the previous file, if any, is kept)";
    return "save: the session at tick " + std::to_string(c->tick) + " saved to " + path +
           " (drape open " + path + ")";
  }));
}

void DrapingSession::poll_saves(int64_t frame, bool wait) {
  for (auto it = saves_.begin(); it != saves_.end();) {
    if (!wait && it->wait_for(std::chrono::seconds(0)) != std::future_status::ready) {
      ++it;
      continue;
    }
    const std::string m = it->get();
    rep_.note(m);
    if (m.rfind("session not saved", 0) == 0) {
      std::fprintf(stderr, "drape: %s\n", m.c_str());
      if (frame >= 0) feedback_.refused(frame, m);
    } else if (frame >= 0) {
      feedback_.set_status("save", m);
    }
    it = saves_.erase(it);
  }
}

sim::Result<sim::World> DrapingSession::open_world(uint64_t& first_tick) {
  sim::WorldCheckpoint c;
  if (std::string e = sim::load_checkpoint(opt_.open_file, c); !e.empty())
    return sim::Error{"open: " + e};
  auto w = make_session_world(opt_, opt_.sim_lock_step);
  if (!w) return sim::Error{"open: " + opt_.open_file + ": " + w.error()};
  ops_ = std::make_shared<sim::OperationController>();
  ops_->install(w.value());
  if (std::string e = sim::restore_checkpoint(c, w.value(), *ops_); !e.empty())
    return sim::Error{"open: " + opt_.open_file + ": field 'solver': " + e};
  first_tick = opened_tick_ = c.tick;
  rep_.note("open: " + opt_.open_file + ": the session at tick " + std::to_string(c.tick) + " (" +
            std::to_string(c.undo.size()) + " undo steps, " + std::to_string(c.redo.size()) +
            " redo steps)");
  return std::move(w.value());
}

}  // namespace drape::app
