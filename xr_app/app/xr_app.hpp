// The drape OpenXR application: instance, system and session lifecycle as a state machine
// (a missing runtime and a lost session are ordinary states), STAGE space (LOCAL fallback),
// controller actions, XR_EXT_hand_tracking when offered, and the frame loop that renders the
// simulation's latest snapshot into the runtime's swapchains. See docs/xr.md.
// Its parts, as in Khronos' hello_xr: the program (xr_program.*: instance, session, events,
// frame loop), the graphics (xr_graphics.*: Vulkan handover, swapchains), the input
// (xr_input.*: actions, hand tracking), the draping session (draping_session.*, interaction.cpp,
// voice_cues.cpp: sim thread, interaction, voice cues) and the profiling (profiling.*).
// The library reads no environment variable: files and layers come in through XrAppOptions.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace drape::app {

enum class XrAppState {
  kNoRuntime,       // no OpenXR runtime could be loaded
  kInstance,        // instance + system, no session
  kSessionIdle,     // session created, waiting for READY
  kSessionRunning,  // between xrBeginSession and STOPPING
  kSessionStopping,
  kSessionLost,  // LOSS_PENDING: the session is destroyed and re-created
  kExiting,      // EXITING (or the frame budget is spent)
  kFailed,
};
const char* to_string(XrAppState s);

struct XrAppOptions {
  int64_t max_frames = -1;  // stop (xrRequestExitSession) after this many frames; -1: never
  int eye_size = 0;         // swapchain edge (px); 0 = the runtime's recommendation
  bool render = true;       // draw the scene (drape_render) or submit the images undrawn
  int cloth_res = 24;       // cloth resolution of the default scene
  // The scene (desk_scene.hpp): "" = the default scenario's (sim::make_form_drape: muslin
  // hanging from the 9AR form's chest line); else a start state ("spread", "rolled",
  // "pinned-top") of the fabric `fabric` (from `fabrics_path`; "" = the built-in muslin) on the
  // form `form_mesh` when set, else `form_measurements` when set, else the size `form_size`
  // (measurements read from `forms_dir`, else built in).
  std::string start;
  std::string fabric = "muslin", fabrics_path;
  // The cloth collides with itself (folds keep their layers apart; XPBD's self-collision,
  // sim/energy/self_collision.hpp).
  bool self_collision = true;
  std::string form_size = "9AR", form_measurements, form_mesh, forms_dir;
  // The sewn garment of a skirt, bodice or dress design file instead of the panel
  // (garment_scene.hpp: the design's pattern sewn on the form, simulated with its seams as ties);
  // "" = none. Its fabric is garment_fabric ("" = the design's), from fabrics_path.
  std::string garment, garment_fabric;
  // The sim's messages get the cloth's state hash before and after each operation's outcome
  // (tests: an undo restores the hash from before the operation).
  bool log_state_hashes = false;
  int max_session_restarts = 3;
  bool verbose = false;
  // Interaction (needs the renderer/sim build): hands (XR joints, else controller grips) and
  // triggers (thumb-index pinch gesture, controller trigger = cut stroke, controller menu = pin,
  // the scenario's audio cues decoded by the voice recogniser) drive the sim operations.
  bool operations = true;
  bool voice = true;          // decode the scenario's audio cues (scenario_path)
  bool sim_lock_step = true;  // one sim tick per rendered frame; false: sim on its own 90 Hz clock
  std::string out_dir;        // when set: session_log.json and drape_cloth.gltf written there
  // At the session's end, the pattern of the cloth as draped into out_dir/pattern/session-1/.
  bool export_pattern = true;
  // The live pattern board beside the form (app/pattern_board.hpp): the draped cloth's pattern
  // rebuilt off the sim thread from its snapshots; false: no board (the renderer's panel empty).
  bool pattern_board = true;
  // The scenario file the simulated runtime plays ("" = none): its audio cues are the voice
  // input (docs/xr.md).
  std::string scenario_path;
  // Live voice commands: "" none, "mic" the default ALSA capture device, else a WAV file (16 kHz
  // mono 16-bit) streamed at real time as if it were the microphone (app/voice_input.hpp).
  std::string voice_input;
  // The hands: "xr" the runtime's; "udp" a skeleton stream (tracking::UdpSkeletonSource bound to
  // hands_address:hands_port); "trace" a recorded trace (hands_trace, played from the session's
  // first frame); "kinect" a Kinect v1 (tracking::KinectSource; `kinect_record` names the fakenect
  // recording the process replays instead of the device, "" = the device). udp, trace and kinect
  // replace the runtime's hands (palm-only gestures, filtered, brought into the stage by the
  // calibration file `calibration_path`, "" = identity).
  std::string hands = "xr";
  std::string hands_address = "127.0.0.1";
  int hands_port = 9740;
  std::string hands_trace, calibration_path, kinect_record;
  // `calibration_path` is the source's saved calibration (calibration_save's file), found when no
  // file was given: the session's status says so.
  bool calibration_saved = false;
  // Calibration mode (udp, trace, kinect): the hands touch the marked points (app/
  // calibration_mode.hpp) instead of draping; the result is written to `calibration_save` (the
  // source's file in the user's config directory, chosen by the executable).
  bool calibrate = false;
  std::string calibration_save;
  // The UDP stream's pairing key (32 bytes; empty: unsigned packets, loopback only): with it only
  // signed packets are accepted (tracking/udp_auth.hpp).
  std::vector<uint8_t> hands_key;
  // The API layers the loader enables (its XR_ENABLE_API_LAYERS): their instance extensions are
  // offered too (the core validation layer's XR_EXT_debug_utils).
  std::vector<std::string> api_layers;
  // Triggers -> operations: this command map file; a file that does not load is an error
  // ("" = tracking::CommandMap::defaults()).
  std::string commands_path;
  // Free-running sim: how long a frame may wait for the tick that consumed its hand pose
  // before drawing (0 = never wait: draw the newest snapshot at once).
  double pose_wait_ms = 6.0;
  bool pointer_probe = false;  // record XrAppResult::pointer_probe (tests)
  // Keep freed heap memory in the process (glibc mallopt) instead of trimming it back to the
  // kernel after every frame: lavapipe's per-draw allocations otherwise page-fault every frame.
  bool tune_malloc = true;
  // Draw the dress form at a level of detail chosen from the eyes' pixel size
  // (render::form_lod_for_pixels); false: the renderer's full-detail default.
  bool form_lod = true;
  // Draw the feedback panel (the hands' operations, voice, refusals, help) over the scene;
  // false: the scene alone (screenshots compared with golden images of the scene).
  bool feedback_panel = true;
  // When set: the session is recorded there (docs/sessions.md): journal.bin (the sim's inputs,
  // written from the sim thread), meta.json and, at the end, session.txt.
  std::string record_dir;
  // With record_dir: a World checkpoint every this many seconds of session time (0: none),
  // solver state included (sim/ops/checkpoint.hpp): the session goes on exactly as without it,
  // and a resume replays at most this much of the journal (docs/sessions.md: the cost).
  double checkpoint_every_s = 10;
  // When set: the session resumes the one recorded there (its scene options are the journal's):
  // its journal replayed to its last whole record, then the session goes on, appending to it.
  std::string resume_dir;
  // When set: the session starts from this saved session (a checkpoint file, `drape open`): its
  // scene options are the file's; "save session" writes out_dir/saved_session.drape.
  std::string open_file;
};

struct XrAppResult {
  int exit_code = 0;  // 0 ok, 3 no runtime, 1 failure
  XrAppState final_state = XrAppState::kFailed;
  std::string runtime_name;
  std::string error;
  int64_t frames = 0;           // xrEndFrame calls that succeeded
  int64_t frames_rendered = 0;  // frames with a projection layer
  int sessions = 0;             // sessions created
  int sessions_lost = 0;
  bool hand_tracking = false;
  int64_t hand_frames_tracked = 0;   // frames with an active right-hand joint set
  float min_pinch_gap_m = 1e9f;      // smallest right thumb-index tip distance seen
  float max_trigger = 0.f;           // largest "pinch" action value seen
  uint32_t validation_messages = 0;  // XR_EXT_debug_utils errors/warnings (validation layer)
  std::vector<std::string> log;      // state transitions and notable events
  // Interaction outcomes (lock-step runs; see XrAppOptions::operations).
  std::vector<std::string> triggers;                // "frame F: source command begin|end hand"
  int64_t frames_pinched = 0;                       // frames in which a hand held a cloth particle
  int pinned_added = 0;                             // pinned vertices at the end minus at the start
  int cuts_ok = 0;                                  // cut strokes applied to the cloth mesh
  int cut_new_vertices = 0;                         // particles duplicated along the cuts
  int components_before = 0, components_after = 0;  // of the last successful cut
  std::vector<std::string> voice_commands;          // commands the recogniser accepted
  std::vector<std::string> sim_messages;            // World::messages at the end
  std::vector<std::string> written;                 // files written to out_dir
  std::vector<double> frame_ms;                     // wall time per frame (wait → end)
  // Per-stage profile, one sample per frame (or per sim tick for "sim.*"): wall ms of each stage
  // of the frame loop ("xr.wait_frame", "input", "interact", "pose_wait", "render.build",
  // "render.upload", "render.record_submit", "render.gpu_wait", "xr.end_frame", ...), the frame
  // loop thread's CPU ms ("frame.cpu"), the whole process's CPU ms from xrWaitFrame's return to
  // xrEndFrame's return ("frame.process_cpu": lavapipe's threads, the sim thread, the loop),
  // and the sim's tick cost: "sim.step_wall",
  // "sim.step_cpu" (solver step on the sim thread), "sim.snapshot_wall" (fill_snapshot).
  std::map<std::string, std::vector<double>> profile_ms;
  // CPU seconds (user + system) per group of threads from the first frame to the end of the run
  // (start-up excluded): the frame loop, the sim
  // thread, the solver's workers, lavapipe's rasterisers, the rest.
  std::map<std::string, double> thread_cpu_s;
  double sim_tick_jitter_ms = -1;  // free-running sim: stddev of tick period
  // Pose-to-photon, per rendered frame (only where a unique pose was matched): frames between
  // the frame whose right-hand pose the drawn hand has and the frame drawing it (the hand is
  // drawn from the frame's own located pose) ...
  std::vector<int> latency_frames;
  // ... and frames between the frame whose right-hand pose the drawn snapshot (the cloth's
  // response) holds and the frame drawing it.
  std::vector<int> cloth_latency_frames;
  // ... and the same in time: from posting that pose to the sim to the end of the frame drawing
  // the snapshot that holds it (ms).
  std::vector<double> cloth_latency_ms;
  // Per rendered frame (XrAppOptions::pointer_probe): left-eye pixel positions of the right-hand
  // pointer as located in this frame (frames_back 0) and the previous ones, for a pixel check of
  // the pose-to-photon latency against the runtime's screenshots.
  struct PointerProbe {
    int64_t frame = 0;
    int count = 0;
    std::array<int, 4> frames_back{};
    std::array<std::array<float, 2>, 4> px{};
  };
  std::vector<PointerProbe> pointer_probe;
  std::string commands_file;  // the command map used
  // Each refusal as the feedback panel showed it: "frame F: reason".
  std::vector<std::string> refusals;
  // Live voice (XrAppOptions::voice_input): per decoded utterance, the frames from the frame
  // during which its last voiced sample was read to the frame that received it.
  std::vector<int> voice_latency_frames;
  // The sim's ticks and the cloth's state hash at the end (sessions with a sim), as a replay of
  // the session's journal reproduces them.
  uint64_t final_ticks = 0, final_state_hash = 0;
  // The mid-session patterns written ("make pattern") and the pieces on the last board drawn
  // (profile_ms "board.latency": ms from the snapshot's tick to the board drawn; "board.build":
  // its extraction on the worker; "board.interval": ms between new boards drawn).
  int patterns_written = 0;
  int board_pieces = 0;
  bool has_final_state = false;
};

XrAppResult run_xr_app(const XrAppOptions& opt);

}  // namespace drape::app
