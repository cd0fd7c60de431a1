// The draping session: the simulation on its thread (lock step: one tick per frame; else its
// own 90 Hz clock), the interaction (hands, controller buttons, gestures and the scenario's
// voice cues or the live voice input, through the command map, drive the sim's operations), the
// renderer drawing the latest snapshot, and the pose-to-photon probes. Files: draping_session.cpp
// (set-up, drawing, the end), interaction.cpp (hands and triggers), voice_cues.cpp (the
// scenario's audio cues and the live voice input).
#pragma once

#include <array>
#include <atomic>
#include <chrono>
#include <future>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "render/renderer.hpp"
#include "sim/ops/checkpoint.hpp"
#include "sim/ops/operation_controller.hpp"
#include "sim/runtime/journal.hpp"
#include "sim/runtime/sim_thread.hpp"
#include "tracking/calibration.hpp"
#include "tracking/command_map.hpp"
#include "tracking/gestures.hpp"
#include "tracking/hand_source.hpp"
#include "tracking/one_euro.hpp"
#include "tracking/trace.hpp"
#include "tracking/udp_source.hpp"
#include "tracking/voice.hpp"
#include "xr_app/app/calibration_mode.hpp"
#include "xr_app/app/feedback.hpp"
#include "xr_app/app/pattern_board.hpp"
#include "xr_app/app/session_content.hpp"
#include "xr_app/app/voice_input.hpp"

namespace drape::app {

class DrapingSession : public SessionContent {
 public:
  DrapingSession(const XrAppOptions& opt, Report& rep) : opt_(opt), rep_(rep) {}
  ~DrapingSession() override;
  // The renderer on the device, the default scene and its solver on the sim thread.
  bool create(const VulkanDevice& device);

  void frame_started() override;
  void interact(int64_t frame, const HandInput& in) override;
  void wait_for_pose(int64_t frame) override;
  void record_probes(int64_t frame) override;
  void draw(int64_t frame, const EyeTarget (&eyes)[2], FrameLaps& laps) override;
  void frame_ended(Clock::time_point end) override;
  void forget_targets() override;
  void session_lost() override;
  void finish() override;

 private:
  struct Cue {  // a scenario's audio cue
    int64_t frame = 0;
    std::string wav, text;
    bool done = false;
  };
  struct Op {  // a trigger mapped to a sim operation
    std::string name;
    sim::TriggerPhase phase;
    int hand;
  };
  struct Posted {  // the right hand's pose as posted to the sim
    int64_t frame;
    sim::Vec3 position;
    Clock::time_point when;
  };

  void start_sim();
  void load_commands();
  void profile_ticks(sim::World& w);
  void load_cues();
  // One hand's joints and controller -> its proxy, overlay and triggers.
  void read_hand(int h, double t, const HandInput& in, sim::HandProxy& hand,
                 std::vector<tracking::Trigger>& trig);
  // External hands (opt_.hands udp or trace, external_hands.cpp): the source opened on the
  // first frame, then polled every frame; each hand's palm filtered, calibrated into the stage
  // and made the hand proxy; its palm-only gestures into `trig`.
  void open_external_hands();
  void read_external_hands(double t, std::array<sim::HandProxy, 2>& hands,
                           std::vector<tracking::Trigger>& trig);
  void note_external_status();
  void hear_cues(int64_t frame, double t, std::vector<tracking::Trigger>& trig);
  void hear_live_voice(int64_t frame, double t, std::vector<tracking::Trigger>& trig);
  std::vector<Op> map_triggers(int64_t frame, const std::vector<tracking::Trigger>& trig);
  void note_lock_step_outcomes(bool cut_trigger);
  // What the sim thread saw of the pinches, read by the frame loop (free-running sim; the lines
  // in both modes).
  struct FreeOutcomes {
    std::atomic<int64_t> frames_pinched{0};      // posted frames after which a hand held a particle
    std::atomic<bool> busy[2] = {false, false};  // pinching (the hand's overlay is drawn active)
    int pinched[2] = {-1, -1};                   // sim thread only
    sim::Vec3 taken_at[2];                       // sim thread only
    std::mutex m;
    std::vector<std::string> lines;  // "pinch: ..." for the log, under m
  };
  static void note_free_outcomes(const sim::World& w, const sim::OperationsState& st,
                                 FreeOutcomes& out);
  void drain_free_outcomes();
  void drain_pinch_lines();
  // What the sim said while applying a frame's triggers, and the hands' operations after them
  // (filled on the sim thread, drained by the frame loop into the feedback panel).
  struct Said {
    std::mutex m;
    std::vector<std::string> messages;
    std::string operation[2];
    std::vector<std::string> lost;  // operations the sim ended for a lost hand
  };
  // On the sim thread: applies the triggers, keeping what they report (World::messages keeps it
  // too) and each hand's operation afterwards.
  static void apply_triggers(sim::World& w, const std::vector<Op>& use,
                             sim::OperationController& ops, Said& out);
  void drain_said(int64_t frame);
  // The app's own operations (not sent to the sim): "help", "pattern" (an export of the newest
  // snapshot by the pattern worker) and "colours" (the cloth's colour map: none, strain, ease).
  // Returns false for a sim operation.
  bool app_operation(const tracking::Action& act, const Op& op);
  void ask_pattern();
  void next_colour_map();
  // The pattern worker's finished exports into the log, the written files and the panel.
  void drain_exports();
  // The board drawn with this frame: its latency (snapshot filled -> drawn) when it is new.
  void note_board_drawn(const BoardBuild& b);
  void prepare_panel(int64_t frame, const EyeTarget (&eyes)[2]);
  void record_pointer_probe(int64_t frame, const render::ViewTarget& left_eye);
  void write_outputs(sim::World& w);
  void write_session_text(const std::string& path, bool append = false);
  // --record (session_record.cpp): the journal opened and meta.json written before the sim
  // starts; at the end the end record, meta.json again and session.txt.
  void open_record();
  // --record with external hands: their frames as received into hands.csv (a trace).
  void record_hand_frames(const std::vector<tracking::HandFrame>& frames);
  // --resume: the World and the operations from the replay of opt_.resume_dir's journal to its
  // last whole record; `first_tick` the ticks it ran.
  sim::Result<sim::World> resume_world(uint64_t& first_tick);
  // With the journal open: a checkpoint every opt_.checkpoint_every_s of session time, taken by
  // the sim thread at a tick's start (journal record, copy with the solver's state), written by
  // checkpoints_'s thread into the record directory.
  void install_checkpoints(sim::World& w);
  // "save session": the sim copies the session at its next tick; a thread writes it whole into
  // out_dir/saved_session.drape (session_save.cpp). poll_saves reports the ended saves (all of
  // them, waiting, when `wait`).
  void save_session(int64_t frame);
  void poll_saves(int64_t frame, bool wait);
  // drape open FILE: the World and the operations from the saved session opt_.open_file.
  sim::Result<sim::World> open_world(uint64_t& first_tick);
  void close_record();

  const XrAppOptions opt_;
  Report& rep_;
  std::unique_ptr<render::Renderer> renderer_;
  std::unique_ptr<sim::SimThread> sim_;
  sim::SnapshotReader reader_;
  std::shared_ptr<sim::OperationController> ops_;
  tracking::GestureRecognizer gestures_;
  std::vector<Cue> cues_;
  std::unique_ptr<tracking::VoiceRecognizer> voice_;
  std::unique_ptr<VoiceInput> live_voice_;     // the microphone or a recording (opt_.voice_input)
  tracking::XrHandSource xr_source_;           // the tracking XR adapter: joints + controllers
  tracking::CommandMap commands_;              // triggers -> operations (assets/commands.json)
  std::vector<render::HandOverlay> overlays_;  // this frame's hands, drawn from its own pose
  bool ops_busy_[2] = {false, false}, cutting_[2] = {false, false};
  // Frames each hand's joints have been lost (held controller aside), and the sim's grace time
  // in frames: the gestures are kept as they were while the sim holds the hand's operation.
  int lost_frames_[2] = {0, 0};
  int grace_frames_ = 0;
  std::shared_ptr<FreeOutcomes> free_ = std::make_shared<FreeOutcomes>();
  int pinned_at_start_ = 0;
  std::vector<Posted> posted_;                // right-hand pose posted per frame
  const sim::SceneSnapshot* snap_ = nullptr;  // the snapshot this frame draws
  bool cloth_matched_ = false;           // the drawn snapshot holds a posted right-hand pose ...
  Clock::time_point cloth_posted_at_{};  // ... posted then
  Feedback feedback_;                    // the text panel's content (feedback.hpp)
  std::shared_ptr<Said> said_ = std::make_shared<Said>();
  render::TextPanel panel_;  // what the renderer draws of feedback_ (rebuilt when it changes)
  bool panel_set_ = false, text_error_noted_ = false;
  TickProfile ticks_;
  ThreadGroups threads_;
  // The live pattern board and the mid-session exports (pattern_board.hpp), off the sim thread.
  std::unique_ptr<PatternWorker> patterns_;
  uint64_t board_drawn_serial_ = 0;
  std::chrono::steady_clock::time_point board_drawn_at_{};  // when the last new board was drawn
  render::ColourMap colour_map_ = render::ColourMap::kNone;

  // The external hand source (opt_.hands != "xr") and what the session keeps of it.
  struct ExternalHands {
    std::unique_ptr<tracking::HandSource> source;
    tracking::TraceSource* trace = nullptr;      // source, when it is a trace
    tracking::UdpSkeletonSource* udp = nullptr;  // source, when it is a UDP stream
    double start = -1;                           // the frame time the trace started at
    std::array<tracking::HandFilter, 2> filter;
    std::array<tracking::HandFrame, 2> last;  // filtered, in the stage
    std::array<double, 2> last_seen{-1e9, -1e9};
    tracking::Calibration calibration;
    std::string status;                            // the status shown ("" = all well)
    std::unique_ptr<CalibrationMode> calibrating;  // --calibrate: the marked points' touches
  };
  std::unique_ptr<ExternalHands> ext_;
  void open_calibration_mode();
  void calibration_frame(const tracking::HandFrame& raw, const tracking::HandFrame& filtered);
  std::vector<render::DrawOptions::Marker> markers_;  // drawn in the scene (calibration)

  // The session's journal (opt_.record_dir): written by the sim thread inside the posted
  // commands while it runs, by finish() after it stopped.
  std::shared_ptr<sim::JournalWriter> journal_;
  uint64_t resume_inputs_end_ = 0;                      // a resumed journal: append from this byte
  std::unique_ptr<sim::CheckpointWriter> checkpoints_;  // the checkpoint files' writer thread
  // The longest a checkpoint took on the sim thread (ms: journal record, copy, solver state).
  std::shared_ptr<std::atomic<double>> checkpoint_cost_ = std::make_shared<std::atomic<double>>(0);
  std::vector<std::future<std::string>> saves_;         // "save session": each save's message
  uint64_t opened_tick_ = 0;                            // drape open: the saved session's tick
  std::unique_ptr<tracking::TraceRecorder> hands_csv_;  // --record, external hands

  // Each hand's interaction profile family: controller triggers are looked up under it.
  std::string profiles_[2];
};

}  // namespace drape::app
