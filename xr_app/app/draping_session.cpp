// The draping session: set-up, drawing and the end of the run (see draping_session.hpp).
#include "xr_app/app/draping_session.hpp"

#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <thread>

#include "render/camera.hpp"
#include "sim/io/mesh_io.hpp"
#include "sim/solvers/solver_factory.hpp"
#include "sim/testbeds/testbed.hpp"
#include "xr_app/app/desk_scene.hpp"
#include "xr_app/app/garment_scene.hpp"
#include "xr_app/app/session_pattern_export.hpp"
#include "xr_app/app/session_record.hpp"
#include "xr_app/output_files.hpp"

namespace drape::app {

namespace {
int count_pinned(const sim::Cloth& c) {
  int n = 0;
  for (uint8_t f : c.state.flags) n += (f & sim::kFlagPinned) != 0;
  return n;
}

// Whether a report of an operation says it did nothing (sim/ops/operations.cpp words every
// such report with one of these), as opposed to a result ("cut: 12 edges, ...").
bool is_refusal(const std::string& m) {
  for (const char* w : {"ignored", "nothing", " no ", "not ", "already", "failed", "discarded"})
    if (m.find(w) != std::string::npos) return true;
  return false;
}

// What the hand is doing, for the panel ("" when nothing).
std::string operation_text(const sim::OperationsState& st, int h) {
  // Tracking lost: the sim holds the operation for its grace time (sim::ops_track_loss).
  if (st.lost_ticks[h] > 0 && sim::hand_busy(st, h)) {
    const char* op = st.pinched[h] >= 0 ? "the pinch"
                     : st.cutting[h]    ? "the cut"
                     : st.smoothing[h]  ? "the smoothing"
                                        : "the move";
    return std::string("lost: holding ") + op;
  }
  if (st.pinched[h] >= 0) return "pinching particle " + std::to_string(st.pinched[h]);
  if (st.cutting[h]) return "cutting";
  if (st.smoothing[h]) return "smoothing";
  if (st.moving) return "moving the cloth";
  return "";
}

// How long a live session shows the help at its start (frames at 90 Hz).
constexpr int64_t kIntroHelpFrames = 8 * 90;
// After each step the cloth's state hash and the newest message; when a command of the next tick
// (a trigger) reports an outcome, the message "state hash <before> -> <after>: <outcome>" (an
// undo restores the hash from before the operation it undoes). Hashing costs a pass over the
// cloth per tick: only when XrAppOptions::log_state_hashes asks.
void hash_outcomes(sim::World& w) {
  struct Last {
    uint64_t hash = 0;
    size_t count = 0;
    std::string back;
  };
  auto last = std::make_shared<Last>();
  last->hash = sim::state_hash(w.cloth);
  last->count = w.messages.size();
  last->back = w.messages.empty() ? "" : w.messages.back();
  auto inner_before = w.before_step;
  w.before_step = [last, inner_before](sim::World& world, double dt) {
    const std::string back = world.messages.empty() ? "" : world.messages.back();
    if (world.messages.size() != last->count || back != last->back) {
      char line[64];
      std::snprintf(line, sizeof line,
                    "state hash %016llx -> %016llx: ", static_cast<unsigned long long>(last->hash),
                    static_cast<unsigned long long>(sim::state_hash(world.cloth)));
      world.report(line + back);
    }
    if (inner_before) inner_before(world, dt);
  };
  auto inner_after = w.after_step;
  w.after_step = [last, inner_after](sim::World& world, double dt) {
    if (inner_after) inner_after(world, dt);
    last->hash = sim::state_hash(world.cloth);
    last->count = world.messages.size();
    last->back = world.messages.empty() ? "" : world.messages.back();
  };
}

}  // namespace

std::unique_ptr<SessionContent> make_draping_session(const VulkanDevice& device,
                                                     const XrAppOptions& opt, Report& rep) {
  if (!opt.render) return nullptr;
  auto s = std::make_unique<DrapingSession>(opt, rep);
  s->create(device);
  return s;
}

DrapingSession::~DrapingSession() {
  patterns_.reset();  // its snapshot reader goes before the sim thread
  reader_ = sim::SnapshotReader();
  sim_.reset();
  renderer_.reset();
}

bool DrapingSession::create(const VulkanDevice& device) {
  render::ExternalDevice ed;
  ed.instance = device.instance;
  ed.physical_device = device.physical;
  ed.device = device.device;
  ed.queue_family = device.queue_family;
  auto rr = render::Renderer::create_on(ed);
  if (!rr) {
    rep_.r.error = "renderer: " + rr.error();
    return false;
  }
  renderer_ = std::move(rr.value());
  threads_.mark_before_sim();
  sim::SimThreadOptions so;
  so.lock_step = opt_.sim_lock_step;
  // A resumed session (--resume) starts from its journal's replay (session_record.cpp).
  auto w = !opt_.resume_dir.empty()  ? resume_world(so.first_tick)
           : !opt_.open_file.empty() ? open_world(so.first_tick)
                                     : make_session_world(opt_, opt_.sim_lock_step);
  if (!w) {
    rep_.r.error = w.error();
    return false;
  }
  if (!opt_.garment.empty()) rep_.note(garment_status(w.value(), 0) + " (" + opt_.garment + ")");
  sim_ = std::make_unique<sim::SimThread>(std::move(w.value()), so);
  reader_ = sim_->make_reader();
  start_sim();
  if (ops_) {
    PatternWorkerOptions po;
    po.board = opt_.pattern_board;
    po.out_dir = opt_.out_dir;
    patterns_ = std::make_unique<PatternWorker>(sim_->make_reader(), po);
  }
  return rep_.r.error.empty();
}

void DrapingSession::start_sim() {
  sim::World& w = sim_->world();  // the thread is not started yet
  pinned_at_start_ = count_pinned(w.cloth);
  if (opt_.operations) {
    if (!ops_) {  // a resumed session has the replay's, installed
      ops_ = std::make_shared<sim::OperationController>();
      ops_->install(w);
    }
    grace_frames_ = static_cast<int>(std::ceil(ops_->params().tracking_grace * 90.0));
    ops_->start_recording(w);
    load_cues();
    load_commands();
    feedback_.set_help(help_lines(commands_));
    // Live (the user at the headset or the desk window, no scenario): the help first.
    if (opt_.scenario_path.empty()) feedback_.show_help_until(kIntroHelpFrames);
    if (opt_.log_state_hashes) hash_outcomes(w);
  }
  profile_ticks(w);
  if (!opt_.record_dir.empty()) open_record();
  install_checkpoints(w);
  // Lock step: the ticks run on the frame loop's thread inside advance() (no hand-off per frame).
  if (!opt_.sim_lock_step) sim_->start();
}

// The command map: triggers -> operations.
void DrapingSession::load_commands() {
  if (opt_.commands_path.empty()) {
    commands_ = tracking::CommandMap::defaults();
    rep_.r.commands_file = "(built-in defaults)";
  } else {
    std::string err;
    if (auto m = tracking::CommandMap::load(opt_.commands_path, &err)) {
      commands_ = *m;
      rep_.r.commands_file = opt_.commands_path;
    } else {
      rep_.r.error = "command map: " + err;
      rep_.note(rep_.r.error);
    }
  }
  rep_.note("command map: " + rep_.r.commands_file + " (" +
            std::to_string(commands_.bindings().size()) + " bindings)");
}

// Tick start times (free-running sim: the jitter of its clock under rendering load) and the
// tick's cost: the solver step (wall and CPU of the thread running it) and fill_snapshot.
void DrapingSession::profile_ticks(sim::World& w) {
  auto inner = w.before_step;
  const bool free = !opt_.sim_lock_step;
  w.before_step = [this, inner, free](sim::World& world, double dt) {
    if (free) ticks_.tick_started();
    if (inner) inner(world, dt);
    threads_.set_sim_thread(static_cast<int>(gettid()));
    ticks_.step_started();
  };
  auto inner_after = w.after_step;
  w.after_step = [this, inner_after](sim::World& world, double dt) {
    ticks_.step_finished();
    if (inner_after) inner_after(world, dt);
    ticks_.after_step_finished();
  };
  auto inner_decorate = w.decorate_snapshot;
  w.decorate_snapshot = [this, inner_decorate](const sim::World& world, sim::SceneSnapshot& s) {
    if (inner_decorate) inner_decorate(world, s);
    ticks_.snapshot_filled();
  };
}

void DrapingSession::frame_started() {
  threads_.mark_first_frame();
  snap_ = nullptr;
  cloth_matched_ = false;
}

// Free-running sim: waits a bounded time for the tick that consumed this frame's hand pose
// (posted in interact()), so the cloth drawn now reacts to the hand drawn now. Only when the
// sim's ticks are short enough to finish within the wait (a 128^2 VBD tick takes ~240 ms of
// CPU: waiting would only add to every frame).
void DrapingSession::wait_for_pose(int64_t frame) {
  snap_ = renderer_ ? &reader_.latest() : nullptr;
  if (!snap_ || !ops_ || opt_.sim_lock_step || opt_.pose_wait_ms <= 0 || posted_.empty() ||
      posted_.back().frame != frame || sim_->timing().step_ms_p50 >= opt_.pose_wait_ms)
    return;
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::microseconds(static_cast<int64_t>(opt_.pose_wait_ms * 1e3));
  auto holds_pose = [&](const sim::SceneSnapshot& s) {
    for (const auto& hp : s.hands)
      if (hp.id == 1 && hp.tracked && hp.position == posted_.back().position) return true;
    return false;
  };
  while (!holds_pose(*snap_) && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::microseconds(250));
    snap_ = &reader_.latest();
  }
}

// Pose-to-photon probes. Cloth (sim) latency: which frame's right-hand pose is in the snapshot
// drawn now. Hand latency: which frame's pose the drawn hand has.
void DrapingSession::record_probes(int64_t frame) {
  if (!snap_ || !ops_) return;
  for (const auto& hp : snap_->hands)
    if (hp.id == 1 && hp.tracked)
      for (auto it = posted_.rbegin(); it != posted_.rend(); ++it)
        if (it->position == hp.position) {
          rep_.r.cloth_latency_frames.push_back(static_cast<int>(frame - it->frame));
          cloth_posted_at_ = it->when;
          cloth_matched_ = true;
          break;
        }
  for (const auto& ov : overlays_)
    if (ov.id == 1)
      for (auto it = posted_.rbegin(); it != posted_.rend(); ++it)
        if (it->position.cast<float>() == ov.pointer) {
          rep_.r.latency_frames.push_back(static_cast<int>(frame - it->frame));
          break;
        }
}

// Left eye: where the right-hand pointer of this and the 3 previous frames projects.
void DrapingSession::record_pointer_probe(int64_t frame, const render::ViewTarget& left_eye) {
  XrAppResult::PointerProbe pr;
  pr.frame = frame;
  int n = 0;
  for (auto it = posted_.rbegin(); it != posted_.rend() && n < 4; ++it, ++n) {
    auto px = render::project_to_pixel(left_eye.view, it->position.cast<float>(),
                                       static_cast<int>(left_eye.target.width),
                                       static_cast<int>(left_eye.target.height));
    pr.frames_back[n] = static_cast<int>(frame - it->frame);
    pr.px[n] = px ? std::array<float, 2>{px->x(), px->y()} : std::array<float, 2>{-1e9f, -1e9f};
  }
  pr.count = n;
  rep_.r.pointer_probe.push_back(pr);
}

// Both eyes with one geometry build and one submission (render::Renderer::render_views).
void DrapingSession::draw(int64_t frame, const EyeTarget (&eyes)[2], FrameLaps& laps) {
  if (!renderer_ || !snap_) return;
  render::ViewTarget vt[2];
  for (int e = 0; e < 2; ++e) {
    render::Pose pose;
    const XrPosef& p = eyes[e].view.pose;
    pose.orientation =
        Eigen::Quaternionf(p.orientation.w, p.orientation.x, p.orientation.y, p.orientation.z);
    pose.position = {p.position.x, p.position.y, p.position.z};
    const XrFovf& f = eyes[e].view.fov;
    vt[e].view = render::make_view(
        pose, render::Fov{f.angleLeft, f.angleRight, f.angleUp, f.angleDown}, kNearZ, kFarZ);
    vt[e].target.image = eyes[e].image;
    vt[e].target.format = eyes[e].format;
    vt[e].target.width = eyes[e].width;
    vt[e].target.height = eyes[e].height;
    vt[e].target.depth_image = eyes[e].depth_image;  // stored for the runtime when handed one
    vt[e].target.depth_format = eyes[e].depth_format;
  }
  render::DrawOptions dopt;
  dopt.hands = overlays_;
  dopt.markers = markers_;
  dopt.colour_map = colour_map_;
  const BoardBuild board = patterns_ ? patterns_->latest_board() : BoardBuild{};
  dopt.board = board.board;
  // The board stands beside the form, to its left seen from the front (the user's right),
  // turned towards where the user stands, within the default view.
  dopt.panel_centre = {0.5f, 1.2f, 0.2f};
  dopt.panel_yaw = -0.4f;
  dopt.panel_size = 0.38f;
  // The form's level of detail from the eyes' pixel size (lavapipe is vertex-bound).
  const XrFovf& f0 = eyes[0].view.fov;
  const float rad_per_px = (f0.angleRight - f0.angleLeft) / static_cast<float>(eyes[0].width);
  const render::FormLod lod = render::form_lod_for_pixels(rad_per_px);
  if (opt_.form_lod) {
    dopt.form_section_spacing = lod.section_spacing;
    dopt.form_angle_step = lod.angle_step;
  }
  if (opt_.pointer_probe && ops_) record_pointer_probe(frame, vt[0]);
  if (opt_.feedback_panel) prepare_panel(frame, eyes);
  // A lost device is said once: the renderer refuses every later frame, while the sim, the
  // hands and the outputs go on.
  const bool was_lost = renderer_->device_lost();
  auto st = renderer_->render_views(*snap_, vt, 2, dopt);
  if (!st && !was_lost)
    rep_.note("render: " + st.error +
              (renderer_->device_lost()
                   ? "; the cloth is no longer drawn, the session goes on and saves its work"
                   : ""));
  laps.lap("render");
  if (st && board.board) note_board_drawn(board);
  const render::FrameStats& rs = renderer_->last_frame();
  laps.add("render.build", rs.build_ms);
  laps.add("render.upload", rs.upload_ms);
  laps.add("render.record_submit", rs.submit_ms - rs.upload_ms);
  laps.add("render.gpu_wait", rs.wait_ms);
  laps.add("render.cloth_rebuilt", rs.cloth_rebuilt ? 1.0 : 0.0);
}

// The feedback panel: its lines re-read only when they changed; it hangs in front of the head
// (between the eyes, looking where the left eye looks), sized for the eyes' pixels.
void DrapingSession::prepare_panel(int64_t frame, const EyeTarget (&eyes)[2]) {
  const uint64_t v = feedback_.shown_version(frame);
  if (!panel_set_ || v != panel_.version) {
    panel_.lines = feedback_.lines(frame);
    panel_.version = v;
    panel_set_ = true;
  }
  // Legible in the eyes' pixels: larger than arm's-length size when they are coarse (a desk
  // window of a few hundred pixels).
  const XrFovf& f = eyes[0].view.fov;
  const float rad_per_px = (f.angleRight - f.angleLeft) / static_cast<float>(eyes[0].width);
  panel_.style =
      render::scaled(render::PanelStyle{}, render::legible_scale(render::PanelStyle{}, rad_per_px));
  const XrPosef& l = eyes[0].view.pose;
  const XrPosef& r = eyes[1].view.pose;
  panel_.head.orientation =
      Eigen::Quaternionf(l.orientation.w, l.orientation.x, l.orientation.y, l.orientation.z);
  panel_.head.position = 0.5f * (Eigen::Vector3f(l.position.x, l.position.y, l.position.z) +
                                 Eigen::Vector3f(r.position.x, r.position.y, r.position.z));
  renderer_->set_text_panel(panel_);
  if (!text_error_noted_ && !renderer_->text_error().empty()) {
    rep_.note("feedback panel: " + renderer_->text_error() + " (drawn without it)");
    text_error_noted_ = true;
  }
}

// On the sim thread. World::messages is swapped out around the triggers so that exactly their
// reports are seen, then restored with them appended (it keeps its last 32).
void DrapingSession::apply_triggers(sim::World& w, const std::vector<Op>& use,
                                    sim::OperationController& ops, Said& out) {
  std::deque<std::string> kept;
  kept.swap(w.messages);
  for (const auto& op : use) ops.trigger(w, op.name, op.phase, op.hand);
  std::vector<std::string> said(w.messages.begin(), w.messages.end());
  for (const auto& m : said) kept.push_back(m);
  while (kept.size() > 32) kept.pop_front();
  w.messages.swap(kept);
  std::lock_guard lock(out.m);
  for (auto& m : said) out.messages.push_back(std::move(m));
  for (auto& m : ops.state().loss_reports) out.lost.push_back(std::move(m));
  ops.state().loss_reports.clear();
  for (int h = 0; h < 2; ++h) out.operation[h] = operation_text(ops.state(), h);
}

// On the frame loop: the refusals and the hands' operations into the panel.
void DrapingSession::drain_said(int64_t frame) {
  std::vector<std::string> messages, lost;
  std::lock_guard lock(said_->m);
  messages.swap(said_->messages);
  lost.swap(said_->lost);
  for (int h = 0; h < 2; ++h) {
    // The grace after a tracking loss, once into the log ("right hand lost: holding the pinch").
    const std::string& op = said_->operation[h];
    if (op.rfind("lost:", 0) == 0 && op != feedback_.operation(h))
      rep_.note(std::string(h == 0 ? "left" : "right") + " hand " + op);
    feedback_.set_operation(h, op);
  }
  for (const auto& m : lost) {  // shown like a refusal: the user did not end it
    feedback_.refused(frame, m);
    rep_.note(m);
  }
  for (const auto& m : messages) {
    if (!is_refusal(m)) continue;
    feedback_.refused(frame, m);
    rep_.r.refusals.push_back("frame " + std::to_string(frame) + ": " + m);
  }
}

void DrapingSession::frame_ended(Clock::time_point end) {
  if (cloth_matched_) rep_.r.cloth_latency_ms.push_back(ms_between(cloth_posted_at_, end));
}

void DrapingSession::forget_targets() {
  if (renderer_) renderer_->forget_targets();
}

// What the hands were doing ends where the cloth is now, as a "stop" does: the next session
// reports the hands elsewhere, and a pinch held across the loss would pull the cloth there.
void DrapingSession::session_lost() {
  if (!sim_ || !ops_) return;
  rep_.note("session lost: the operations in progress end here (stop); the cloth is kept");
  feedback_.refused(0, "XR session lost: operations in progress ended, the cloth is kept");
  auto ops = ops_;
  std::shared_ptr<Said> said = said_;
  const std::vector<Op> stop = {{"stop", sim::TriggerPhase::kBegin, 1}};
  sim_->post([ops, stop, said](sim::World& w) { apply_triggers(w, stop, *ops, *said); });
}

void DrapingSession::finish() {
  if (!sim_) return;
  rep_.r.thread_cpu_s = threads_.seconds();  // before the sim's threads end
  if (patterns_) {                           // the exports asked for are written before the end
    patterns_->stop();
    drain_exports();
  }
  sim_->stop();
  poll_saves(-1, true);
  if (ops_ && !opt_.sim_lock_step) drain_free_outcomes();
  sim::World& w = sim_->world();
  rep_.r.pinned_added = count_pinned(w.cloth) - pinned_at_start_;
  for (const auto& m : w.messages) rep_.r.sim_messages.push_back(m);
  ticks_.write(rep_.r);
  rep_.r.final_ticks = sim_->ticks();
  rep_.r.final_state_hash = sim::state_hash(w.cloth);
  rep_.r.has_final_state = true;
  if (!opt_.garment.empty()) rep_.note(garment_status(w, rep_.r.final_ticks));
  if (journal_) close_record();
  if (ops_ && !opt_.out_dir.empty()) write_outputs(w);
}

namespace {
// The message of a failed output, also on stderr (the session's own log may be the file that
// could not be written).
void not_saved(Report& rep, const std::string& what, const std::string& error) {
  const std::string m = what + " not saved: " + error + " (the previous file, if any, is kept)";
  std::fprintf(stderr, "drape: %s\n", m.c_str());
  rep.note(m);
}
}  // namespace

// out_dir: session_log.json (the operations as the sim received them), drape_cloth.gltf and
// xr_session.txt (the log, the triggers, the sim's messages and the outcome), each written whole
// or not at all (write_whole).
void DrapingSession::write_outputs(sim::World& w) {
  XrAppResult& r = rep_.r;
  std::error_code ec;
  std::filesystem::create_directories(opt_.out_dir, ec);
  sim::SessionLog log = ops_->stop_recording(w);
  const std::string lp = opt_.out_dir + "/session_log.json";
  if (std::string e = write_whole(
          opt_.out_dir,
          [&](const std::string& d) { return sim::save_session(d + "/session_log.json", log); });
      e.empty())
    r.written.push_back(lp);
  else
    not_saved(rep_, "session log", e);
  const std::string cp = opt_.out_dir + "/drape_cloth.gltf";
  if (std::string e = write_whole(opt_.out_dir,
                                  [&](const std::string& d) {
                                    return sim::write_meshes(
                                        d + "/drape_cloth.gltf",
                                        {sim::cloth_to_mesh(w.cloth, "cloth")});
                                  });
      e.empty())
    r.written.push_back(cp);
  else
    not_saved(rep_, "glTF", e);
  if (opt_.export_pattern) {
    const int n = patterns_ ? patterns_->next_number() : 1;
    const SessionPatternExport pe = export_session_pattern(w, ops_->state(), opt_.out_dir, n);
    r.log.push_back(pe.summary);
    for (const auto& f : pe.files) r.written.push_back(f);
  }
  write_session_text(opt_.out_dir + "/xr_session.txt");
}

// The session's text log: the log, the triggers, the sim's messages and the outcome. Written
// whole (a failed write keeps the previous file), or appended after a resumed session's own.
void DrapingSession::write_session_text(const std::string& tp, bool append) {
  XrAppResult& r = rep_.r;
  auto write = [&r](const std::string& p, std::ios::openmode mode) -> std::string {
    std::ofstream o(p, mode);
    for (const auto& l : r.log) o << l << "\n";
    for (const auto& l : r.triggers) o << "trigger " << l << "\n";
    for (const auto& l : r.sim_messages) o << "sim: " << l << "\n";
    o << "frames " << r.frames << " pinched_frames " << r.frames_pinched << " pinned_added "
      << r.pinned_added << " cuts " << r.cuts_ok << " components " << r.components_before << " -> "
      << r.components_after << "\n";
    o.close();
    return o ? std::string() : p + ": write failed: " + std::strerror(errno);
  };
  const std::filesystem::path path(tp);
  const std::string e = append
                            ? write(tp, std::ios::app)
                            : write_whole(path.parent_path().string(), [&](const std::string& d) {
                                return write(d + "/" + path.filename().string(), std::ios::trunc);
                              });
  if (e.empty())
    r.written.push_back(tp);
  else
    not_saved(rep_, "session text", e);
}

}  // namespace drape::app
