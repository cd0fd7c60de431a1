// The drape OpenXR application (see xr_app.hpp).
#include "xr_app/app/xr_app.hpp"

#include <malloc.h>
#include <time.h>
#include <unistd.h>
#include <vulkan/vulkan.h>
// (Vulkan first: openxr_platform.h uses its types)
#define XR_USE_GRAPHICS_API_VULKAN
#include <openxr/openxr.h>
#include <openxr/openxr_platform.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <mutex>
#include <set>
#include <sstream>
#include <thread>

#ifdef DRAPE_XR_WITH_RENDER
#include "render/camera.hpp"
#include "render/renderer.hpp"
#include "sim/io/mesh_io.hpp"
#include "sim/ops/operation_controller.hpp"
#include "sim/runtime/sim_thread.hpp"
#include "sim/solvers/solver_factory.hpp"
#include "sim/testbeds/testbed.hpp"
#include "tracking/command_map.hpp"
#include "tracking/gestures.hpp"
#include "tracking/hand_source.hpp"
#include "tracking/voice.hpp"
#endif
#include <nlohmann/json.hpp>

namespace drape::app {

const char* to_string(XrAppState s) {
  switch (s) {
    case XrAppState::kNoRuntime:
      return "no_runtime";
    case XrAppState::kInstance:
      return "instance";
    case XrAppState::kSessionIdle:
      return "session_idle";
    case XrAppState::kSessionRunning:
      return "session_running";
    case XrAppState::kSessionStopping:
      return "session_stopping";
    case XrAppState::kSessionLost:
      return "session_lost";
    case XrAppState::kExiting:
      return "exiting";
    case XrAppState::kFailed:
      return "failed";
  }
  return "?";
}

std::string select_runtime() {
  if (const char* j = std::getenv("XR_RUNTIME_JSON"); j && *j) return j;
  namespace fs = std::filesystem;
  std::vector<fs::path> dirs;
  if (const char* x = std::getenv("XDG_CONFIG_HOME"); x && *x) dirs.emplace_back(x);
  if (const char* h = std::getenv("HOME"); h && *h) dirs.push_back(fs::path(h) / ".config");
  if (const char* x = std::getenv("XDG_CONFIG_DIRS"); x && *x) {
    std::string s = x;
    size_t p = 0;
    while (p <= s.size()) {
      size_t q = s.find(':', p);
      if (q == std::string::npos) q = s.size();
      if (q > p) dirs.emplace_back(s.substr(p, q - p));
      p = q + 1;
    }
  }
  dirs.emplace_back("/etc/xdg");
  std::error_code ec;
  for (const auto& d : dirs)
    if (fs::exists(d / "openxr/1/active_runtime.json", ec)) return "";
  // No runtime configured: the mock runtime built next to this executable.
  fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  fs::path mock = exe.parent_path() / "drape_mock_runtime.json";
  if (!ec && fs::exists(mock, ec)) {
    setenv("XR_RUNTIME_JSON", mock.c_str(), 1);
    return mock.string();
  }
  return "";
}

namespace {

double cpu_ms(clockid_t clock) {
  timespec ts{};
  clock_gettime(clock, &ts);
  return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
}
double thread_cpu_ms() {
  return cpu_ms(CLOCK_THREAD_CPUTIME_ID);
}
double process_cpu_ms() {  // all threads: the app, lavapipe's, the sim's
  return cpu_ms(CLOCK_PROCESS_CPUTIME_ID);
}

using Clock = std::chrono::steady_clock;
double ms_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

// CPU seconds (user + system) of each live thread of this process: tid -> (name, seconds).
[[maybe_unused]] std::map<int, std::pair<std::string, double>> thread_cpu_seconds() {
  std::map<int, std::pair<std::string, double>> out;
  const double tick = static_cast<double>(sysconf(_SC_CLK_TCK));
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator("/proc/self/task", ec)) {
    std::ifstream f(e.path() / "stat");
    std::string line;
    if (!std::getline(f, line)) continue;
    const size_t open = line.find('('), close = line.rfind(')');
    if (open == std::string::npos || close == std::string::npos) continue;
    std::istringstream rest(line.substr(close + 2));
    std::string tok;
    double ut = 0, st = 0;
    for (int field = 3; rest >> tok && field <= 15; ++field) {  // utime 14, stime 15
      if (field == 14) ut = std::atof(tok.c_str());
      if (field == 15) st = std::atof(tok.c_str());
    }
    out[std::atoi(e.path().filename().c_str())] = {line.substr(open + 1, close - open - 1),
                                                   (ut + st) / tick};
  }
  return out;
}

const char* const kProfiles[] = {
    "/interaction_profiles/khr/simple_controller", "/interaction_profiles/oculus/touch_controller",
    "/interaction_profiles/valve/index_controller", "/interaction_profiles/htc/vive_controller",
    "/interaction_profiles/microsoft/motion_controller"};

XRAPI_ATTR XrBool32 XRAPI_CALL debug_callback(XrDebugUtilsMessageSeverityFlagsEXT,
                                              XrDebugUtilsMessageTypeFlagsEXT,
                                              const XrDebugUtilsMessengerCallbackDataEXT* data,
                                              void* user) {
  auto* r = static_cast<XrAppResult*>(user);
  ++r->validation_messages;
  if (r->log.size() < 200)
    r->log.push_back(std::string("validation: ") + (data && data->message ? data->message : ""));
  return XR_FALSE;
}

class App {
 public:
  App(const XrAppOptions& opt, XrAppResult* res) : opt_(opt), r_(*res) {}
  ~App() { teardown_all(); }

  void run();
  XrAppState state() const { return state_; }

 private:
  bool ok(XrResult x, const char* what) {
    if (XR_SUCCEEDED(x)) return true;
    char buf[XR_MAX_RESULT_STRING_SIZE] = "";
    if (instance_ != XR_NULL_HANDLE) xrResultToString(instance_, x, buf);
    r_.error = std::string(what) + " failed: " + (buf[0] ? buf : std::to_string(x));
    note(r_.error);
    return false;
  }
  void note(const std::string& s) {
    r_.log.push_back(s);
    if (opt_.verbose) std::fprintf(stderr, "[drape xr] %s\n", s.c_str());
  }
  void set_state(XrAppState s) {
    if (state_ == s) return;
    note(std::string("state ") + to_string(state_) + " -> " + to_string(s));
    state_ = s;
  }
  template <class F>
  F fn(const char* name) {
    PFN_xrVoidFunction f = nullptr;
    if (XR_FAILED(xrGetInstanceProcAddr(instance_, name, &f))) return nullptr;
    return reinterpret_cast<F>(f);
  }
  XrPath path(const char* s) {
    XrPath p = XR_NULL_PATH;
    xrStringToPath(instance_, s, &p);
    return p;
  }

  bool create_instance();
  bool create_vulkan();
  bool create_session();
  void create_actions();
  void destroy_session();
  void teardown_all();
  bool handle_events();
  bool frame();
#ifdef DRAPE_XR_WITH_RENDER
  void start_sim();
  void load_cues();
  void interact(const XrFrameState& fs, XrHandJointLocationEXT (*joints)[XR_HAND_JOINT_COUNT_EXT],
                const bool* joints_active);
  void finish_sim();
#endif

  XrAppOptions opt_;
  XrAppResult& r_;
  XrAppState state_ = XrAppState::kNoRuntime;
  XrInstance instance_ = XR_NULL_HANDLE;
  XrSystemId system_ = XR_NULL_SYSTEM_ID;
  XrDebugUtilsMessengerEXT messenger_ = XR_NULL_HANDLE;
  bool has_hands_ext_ = false, has_debug_ext_ = false;
  // Vulkan (created through the runtime)
  VkInstance vk_instance_ = VK_NULL_HANDLE;
  VkPhysicalDevice vk_physical_ = VK_NULL_HANDLE;
  VkDevice vk_device_ = VK_NULL_HANDLE;
  uint32_t queue_family_ = 0;
  // session
  XrSession session_ = XR_NULL_HANDLE;
  XrSessionState xr_state_ = XR_SESSION_STATE_UNKNOWN;
  bool running_ = false;
  bool exit_requested_ = false;
  XrSpace space_ = XR_NULL_HANDLE;
  XrActionSet action_set_ = XR_NULL_HANDLE;
  XrAction pinch_ = XR_NULL_HANDLE, grab_ = XR_NULL_HANDLE, pose_ = XR_NULL_HANDLE,
           primary_ = XR_NULL_HANDLE, secondary_ = XR_NULL_HANDLE, haptic_ = XR_NULL_HANDLE;
  XrPath hand_paths_[2] = {XR_NULL_PATH, XR_NULL_PATH};
  XrSpace hand_spaces_[2] = {XR_NULL_HANDLE, XR_NULL_HANDLE};
  XrHandTrackerEXT trackers_[2] = {XR_NULL_HANDLE, XR_NULL_HANDLE};
  PFN_xrLocateHandJointsEXT locate_joints_ = nullptr;
  struct Eye {
    XrSwapchain chain = XR_NULL_HANDLE;
    uint32_t width = 0, height = 0;
    std::vector<XrSwapchainImageVulkan2KHR> images;
  } eyes_[2];
  int64_t format_ = VK_FORMAT_R8G8B8A8_SRGB;
#ifdef DRAPE_XR_WITH_RENDER
  std::unique_ptr<render::Renderer> renderer_;
  std::unique_ptr<sim::SimThread> sim_;
  sim::SnapshotReader reader_;
  std::shared_ptr<sim::OperationController> ops_;
  tracking::GestureRecognizer gestures_;
  struct Cue {
    int64_t frame = 0;
    std::string wav, text;
    bool done = false;
  };
  std::vector<Cue> cues_;
  std::unique_ptr<tracking::VoiceRecognizer> voice_;
  tracking::XrHandSource xr_source_;           // the tracking XR adapter: joints + controllers
  tracking::CommandMap commands_;              // triggers -> operations (assets/commands.json)
  std::vector<render::HandOverlay> overlays_;  // this frame's hands, drawn from its own pose
  bool ops_busy_[2] = {false, false}, cutting_[2] = {false, false};
  int pinned_at_start_ = 0;
  struct Posted {
    int64_t frame;
    sim::Vec3 position;
    Clock::time_point when;
  };
  std::vector<Posted> posted_;  // right-hand pose posted per frame
  std::mutex tick_mu_;
  std::vector<std::chrono::steady_clock::time_point> tick_starts_;
  // Sim tick cost (profile): written on the thread that runs the ticks, read at the end.
  Clock::time_point step_t0_{}, step_end_{};
  double step_cpu0_ = 0;
  bool step_done_ = false;
  std::atomic<int> sim_tid_{0};  // the thread running the ticks
  std::set<int> pre_sim_tids_;   // threads alive before the sim and its solver were made
  std::map<int, std::pair<std::string, double>> cpu_at_first_frame_;      // start-up excluded
  std::vector<double> sim_step_wall_, sim_step_cpu_, sim_snapshot_wall_;  // guarded by tick_mu_
#endif
  void prof(const char* stage, double ms) {
    r_.profile_ms[stage].push_back(ms);
  }
  int64_t session_frame_ = 0;  // xrWaitFrame calls in this session (the scenario's frame index)
};

int count_pinned(const sim::Cloth& c) {
  int n = 0;
  for (uint8_t f : c.state.flags) n += (f & sim::kFlagPinned) != 0;
  return n;
}

#ifdef DRAPE_XR_WITH_RENDER
void App::start_sim() {
  sim::World& w = sim_->world();  // the thread is not started yet
  pinned_at_start_ = count_pinned(w.cloth);
  if (opt_.operations) {
    ops_ = std::make_shared<sim::OperationController>();
    ops_->install(w);
    ops_->start_recording(w);
    load_cues();
    // The command map: triggers -> operations.
    std::string path = opt_.commands_path;
    if (path.empty()) {
      path = "assets/commands.json";
      if (!std::filesystem::exists(path)) path = std::string(DRAPE_SOURCE_DIR) + "/" + path;
    }
    std::string err;
    if (auto m = tracking::CommandMap::load(path, &err)) {
      commands_ = *m;
      r_.commands_file = path;
    } else if (!opt_.commands_path.empty()) {
      r_.error = "command map: " + err;  // an explicit file that does not load is an error
      note(r_.error);
    } else {
      commands_ = tracking::CommandMap::defaults();
      r_.commands_file = "(built-in defaults)";
    }
    note("command map: " + r_.commands_file + " (" + std::to_string(commands_.bindings().size()) +
         " bindings)");
  }
  {
    // Tick start times (free-running sim: the jitter of its clock under rendering load) and the
    // tick's cost: the solver step (wall and CPU of the thread running it) and fill_snapshot.
    auto inner = w.before_step;
    const bool free = !opt_.sim_lock_step;
    w.before_step = [this, inner, free](sim::World& world, double dt) {
      if (free) {
        std::lock_guard<std::mutex> lk(tick_mu_);
        if (tick_starts_.size() < 100000) tick_starts_.push_back(Clock::now());
      }
      if (inner) inner(world, dt);
      sim_tid_.store(static_cast<int>(gettid()), std::memory_order_relaxed);
      step_cpu0_ = thread_cpu_ms();
      step_t0_ = Clock::now();
    };
    auto inner_after = w.after_step;
    w.after_step = [this, inner_after](sim::World& world, double dt) {
      const auto t1 = Clock::now();
      const double cpu = thread_cpu_ms() - step_cpu0_;
      {
        std::lock_guard<std::mutex> lk(tick_mu_);
        if (sim_step_wall_.size() < 100000) {
          sim_step_wall_.push_back(ms_between(step_t0_, t1));
          sim_step_cpu_.push_back(cpu);
        }
      }
      if (inner_after) inner_after(world, dt);
      step_end_ = Clock::now();
      step_done_ = true;
    };
    auto inner_decorate = w.decorate_snapshot;
    w.decorate_snapshot = [this, inner_decorate](const sim::World& world, sim::SceneSnapshot& s) {
      if (inner_decorate) inner_decorate(world, s);
      if (!step_done_) return;  // make_reader() before the first tick
      step_done_ = false;
      std::lock_guard<std::mutex> lk(tick_mu_);
      if (sim_snapshot_wall_.size() < 100000)
        sim_snapshot_wall_.push_back(ms_between(step_end_, Clock::now()));
    };
  }
  // Lock step: the ticks run on this thread inside advance() (no hand-off per frame).
  if (!opt_.sim_lock_step) sim_->start();
}

// The scenario's audio cues (the mock runtime's documented voice side channel, docs/xr.md).
void App::load_cues() {
  const char* path = std::getenv("DRAPE_MOCK_SCENARIO");
  if (!opt_.voice || !path || !*path) return;
  std::ifstream in(path);
  if (!in) return;  // the runtime reports an unreadable scenario itself
  nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
  if (j.is_discarded() || !j.contains("audio") || !j["audio"].is_array()) return;
  const std::filesystem::path dir = std::filesystem::path(path).parent_path();
  for (const auto& a : j["audio"]) {
    if (!a.is_object() || !a.contains("frame") || !a.contains("wav")) continue;
    Cue c;
    c.frame = a["frame"].get<int64_t>();
    std::filesystem::path wav = a["wav"].get<std::string>();
    c.wav = (wav.is_absolute() ? wav : dir / wav).string();
    if (a.contains("text") && a["text"].is_string()) c.text = a["text"].get<std::string>();
    cues_.push_back(c);
  }
  if (!cues_.empty()) note("voice: " + std::to_string(cues_.size()) + " audio cue(s)");
}

void App::interact(const XrFrameState& fs,
                   XrHandJointLocationEXT (*joints)[XR_HAND_JOINT_COUNT_EXT],
                   const bool* joints_active) {
  if (!sim_) return;
  const int64_t frame_idx = session_frame_ - 1;  // this frame's index (the scenario's)
  const double t = static_cast<double>(frame_idx) / 90.0;
  std::array<sim::HandProxy, 2> hands{};
  std::vector<tracking::Trigger> trig;
  overlays_.clear();
  // Every hand input goes through the tracking XR adapter (tracking::XrHandSource): the joints
  // of XR_EXT_hand_tracking and the controller (grip pose, trigger, squeeze, a/b buttons).
  for (int h = 0; h < 2; ++h) {
    const auto hand = static_cast<tracking::Hand>(h);
    hands[h].id = h;
    tracking::HandFrame joint_frame;
    bool have_joint_frame = false;
    if (trackers_[h] != XR_NULL_HANDLE) {
      tracking::XrJointInput in;
      in.active = joints_active[h];
      in.time = t;
      for (int k = 0; k < tracking::kJointCount; ++k) {
        const auto& jl = joints[h][k];
        const auto& p = jl.pose.position;
        const auto& q = jl.pose.orientation;
        in.joints[k].position = tracking::Vec3(p.x, p.y, p.z);
        in.joints[k].orientation = tracking::Quat(q.w, q.x, q.y, q.z);
        if (in.joints[k].orientation.norm() > 0.5) in.joints[k].orientation.normalize();
        in.valid[k] = joints_active[h] && (jl.locationFlags & XR_SPACE_LOCATION_POSITION_VALID_BIT);
      }
      xr_source_.feed_joints(hand, in);
      for (const auto& f : xr_source_.poll()) {
        gestures_.update(f, trig);  // joint frames only: pinch / grab / open palm
        if (f.tracked && f.has_joints) {
          joint_frame = f;
          have_joint_frame = true;
        }
      }
    }
    tracking::XrControllerInput ci;
    ci.time = t;
    XrSpaceLocation loc{XR_TYPE_SPACE_LOCATION};
    if (hand_spaces_[h] != XR_NULL_HANDLE &&
        XR_SUCCEEDED(xrLocateSpace(hand_spaces_[h], space_, fs.predictedDisplayTime, &loc)) &&
        (loc.locationFlags & XR_SPACE_LOCATION_POSITION_VALID_BIT)) {
      ci.active = true;
      ci.grip.position =
          tracking::Vec3(loc.pose.position.x, loc.pose.position.y, loc.pose.position.z);
      ci.grip.orientation = tracking::Quat(loc.pose.orientation.w, loc.pose.orientation.x,
                                           loc.pose.orientation.y, loc.pose.orientation.z);
    }
    XrActionStateGetInfo gi{XR_TYPE_ACTION_STATE_GET_INFO};
    gi.subactionPath = hand_paths_[h];
    gi.action = pinch_;
    XrActionStateFloat fv{XR_TYPE_ACTION_STATE_FLOAT};
    if (XR_SUCCEEDED(xrGetActionStateFloat(session_, &gi, &fv)) && fv.isActive)
      ci.trigger = fv.currentState;
    auto boolean = [&](XrAction a) {
      gi.action = a;
      XrActionStateBoolean bv{XR_TYPE_ACTION_STATE_BOOLEAN};
      return a != XR_NULL_HANDLE && XR_SUCCEEDED(xrGetActionStateBoolean(session_, &gi, &bv)) &&
             bv.isActive && bv.currentState == XR_TRUE;
    };
    ci.squeeze = boolean(grab_);
    ci.a = boolean(primary_);
    ci.b = boolean(secondary_);
    xr_source_.feed_controller(hand, ci);
    tracking::HandFrame ctrl_frame;
    bool have_ctrl = false;
    for (const auto& f : xr_source_.poll())
      if (f.tracked) {
        ctrl_frame = f;
        have_ctrl = true;
      }
    for (auto& tr : xr_source_.take_triggers()) trig.push_back(tr);
    render::HandOverlay ov;
    ov.id = h;
    if (have_joint_frame) {
      // The hand proxy: the pinch point between the thumb and index tips (palm orientation).
      const auto& J = joint_frame.joints;
      hands[h].tracked = true;
      hands[h].position = 0.5 * (J[static_cast<int>(tracking::Joint::ThumbTip)] +
                                 J[static_cast<int>(tracking::Joint::IndexTip)]);
      hands[h].orientation = joint_frame.palm.orientation;
      hands[h].tip = hands[h].position;
      hands[h].radius = 0.02;
      ov.has_joints = true;
      for (int k = 0; k < tracking::kJointCount; ++k) ov.joints[k] = J[k].cast<float>();
    } else if (have_ctrl) {
      // No hand tracking for this hand: the controller's grip pose is the hand.
      hands[h].tracked = true;
      hands[h].position = ctrl_frame.palm.position;
      hands[h].orientation = ctrl_frame.palm.orientation;
      hands[h].tip = hands[h].position;
      hands[h].radius = 0.03;
    }
    if (hands[h].tracked) {
      ov.pointer = hands[h].position.cast<float>();
      ov.active = gestures_.pinching(hand) || ops_busy_[h];
      overlays_.push_back(ov);
    }
  }
  // Voice: the scenario's audio cues, decoded when their frame is reached.
  for (auto& c : cues_) {
    if (c.done || frame_idx < c.frame) continue;
    c.done = true;
    if (!voice_) {
      voice_ = std::make_unique<tracking::VoiceRecognizer>(tracking::VoiceConfig{});
      if (!voice_->ok()) note("voice: recogniser unavailable: " + voice_->error());
    }
    std::vector<int16_t> pcm;
    std::string err;
    if (!voice_->ok()) continue;
    if (!tracking::read_wav(c.wav, pcm, &err)) {
      note("voice: " + err);
      continue;
    }
    // The recogniser's own energy VAD cuts the utterance out of the recording.
    tracking::EnergyVad vad(voice_->config());
    std::vector<tracking::EnergyVad::Segment> segs;
    vad.feed(pcm.data(), static_cast<long>(pcm.size()), segs);
    vad.flush(segs);
    if (segs.empty()) {
      note("voice: no speech in " + c.wav);
      continue;
    }
    const auto& sg = segs.front();
    auto vr = voice_->decode(sg.audio.data(), static_cast<long>(sg.audio.size()),
                             static_cast<double>(sg.speech_end - sg.start) / tracking::kVoiceRate);
    note("voice: frame " + std::to_string(frame_idx) + " '" + c.wav + "' heard '" + vr.hypothesis +
         "' -> " + (vr.command.empty() ? "(rejected: " + vr.reason + ")" : vr.command));
    if (!vr.command.empty()) {
      r_.voice_commands.push_back(vr.command);
      trig.push_back({vr.command, "voice", t, tracking::Hand::Right, true});
    }
  }
  // Triggers -> the command map (assets/commands.json) -> operations of the sim.
  struct Op {
    std::string name;
    sim::TriggerPhase phase;
    int hand;
  };
  std::vector<Op> use;
  for (const auto& tr : trig) {
    const auto act = commands_.lookup(tr);
    std::string line = "frame " + std::to_string(frame_idx) + ": " + tr.source + " " + tr.command +
                       (tr.begin ? " begin" : " end") + " hand " + tracking::hand_name(tr.hand);
    if (!act) {
      if (opt_.verbose) note("unmapped trigger " + line);
      continue;
    }
    Op op{act->operation, sim::TriggerPhase::kBegin, static_cast<int>(tr.hand)};
    switch (act->phase) {
      case tracking::Phase::Begin:
      case tracking::Phase::Once:
        op.phase = sim::TriggerPhase::kBegin;
        break;
      case tracking::Phase::End:
        op.phase = sim::TriggerPhase::kEnd;
        break;
      case tracking::Phase::Toggle:
        op.phase = sim::TriggerPhase::kToggle;
        break;
    }
    if (op.name == "*") {  // "stop": ends whatever is in progress
      op.name = "stop";
      op.phase = sim::TriggerPhase::kBegin;
    }
    line += " -> " + op.name + " " + tracking::phase_name(act->phase);
    r_.triggers.push_back(line);
    if (opt_.verbose) note("trigger " + line);
    use.push_back(op);
  }
  if (hands[1].tracked) {
    posted_.push_back({frame_idx, hands[1].position, Clock::now()});
    if (posted_.size() > 256) posted_.erase(posted_.begin());
  }
  bool cut_trigger = false;
  for (const auto& op : use) cut_trigger = cut_trigger || op.name == "cut" || op.name == "stop";
  if (ops_) {
    auto ops = ops_;
    sim_->post([ops, hands, use](sim::World& w) {
      ops->set_hands(w, hands);
      w.scene.hands.assign(hands.begin(), hands.end());  // into the snapshot (latency probe)
      for (const auto& op : use) ops->trigger(w, op.name, op.phase, op.hand);
    });
  }
  if (opt_.sim_lock_step) {
    sim_->advance(1);  // orders the sim's writes before these reads (sim_thread.hpp)
    if (ops_) {
      const auto& st = ops_->state();
      if (st.pinched[0] >= 0 || st.pinched[1] >= 0) ++r_.frames_pinched;
      bool cut_end = false;
      for (int h = 0; h < 2; ++h) {
        cut_end = cut_end || (cut_trigger && cutting_[h] && !st.cutting[h]);
        cutting_[h] = st.cutting[h];
        ops_busy_[h] = st.pinched[h] >= 0 || st.cutting[h];
      }
      if (cut_end) {
        if (st.last_cut.ok) {
          ++r_.cuts_ok;
          r_.cut_new_vertices += static_cast<int>(st.last_cut.new_vertices.size());
          r_.components_before = st.last_cut.components_before;
          r_.components_after = st.last_cut.components_after;
        }
        note("cut: " + std::string(st.last_cut.ok ? "ok" : "failed: " + st.last_cut.reason) +
             ", components " + std::to_string(st.last_cut.components_before) + " -> " +
             std::to_string(st.last_cut.components_after));
      }
    }
  }
}

void App::finish_sim() {
  if (!sim_) return;
  // Who used the CPU (before the sim's threads end): the frame loop, the sim thread, the
  // solver's workers (threads created with the sim), lavapipe's rasterisers (llvmpipe-N), the
  // rest (lavapipe's queue thread, the loader, ...).
  for (const auto& [tid, t] : thread_cpu_seconds()) {
    const auto base = cpu_at_first_frame_.find(tid);
    const double sec = t.second - (base != cpu_at_first_frame_.end() ? base->second.second : 0.0);
    std::string group = "other (lavapipe queue, loader)";
    if (tid == getpid())
      group = "app frame loop (main)";
    else if (tid == sim_tid_.load())
      group = "sim thread";
    else if (t.first.rfind("llvmpipe", 0) == 0)
      group = "lavapipe rasterisers (" + t.first.substr(0, 8) + "-*)";
    else if (!pre_sim_tids_.count(tid))
      group = "solver workers";
    r_.thread_cpu_s[group] += sec;
  }
  sim_->stop();
  sim::World& w = sim_->world();
  r_.pinned_added = count_pinned(w.cloth) - pinned_at_start_;
  for (const auto& m : w.messages) r_.sim_messages.push_back(m);
  {
    std::lock_guard<std::mutex> lk(tick_mu_);
    if (tick_starts_.size() > 10) {
      std::vector<double> d;
      for (size_t i = 1; i < tick_starts_.size(); ++i)
        d.push_back(std::chrono::duration<double, std::milli>(tick_starts_[i] - tick_starts_[i - 1])
                        .count());
      double mean = 0, var = 0;
      for (double x : d) mean += x;
      mean /= static_cast<double>(d.size());
      for (double x : d) var += (x - mean) * (x - mean);
      r_.sim_tick_jitter_ms = std::sqrt(var / static_cast<double>(d.size()));
      r_.profile_ms["sim.tick_interval"] = d;
    }
    r_.profile_ms["sim.step_wall"] = sim_step_wall_;
    r_.profile_ms["sim.step_cpu"] = sim_step_cpu_;
    r_.profile_ms["sim.snapshot_wall"] = sim_snapshot_wall_;
  }
  if (ops_ && !opt_.out_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(opt_.out_dir, ec);
    sim::SessionLog log = ops_->stop_recording(w);
    const std::string lp = opt_.out_dir + "/session_log.json";
    if (std::string e = sim::save_session(lp, log); e.empty())
      r_.written.push_back(lp);
    else
      note("session log: " + e);
    const std::string cp = opt_.out_dir + "/drape_cloth.gltf";
    if (std::string e = sim::write_meshes(cp, {sim::cloth_to_mesh(w.cloth, "cloth")}); e.empty())
      r_.written.push_back(cp);
    else
      note("glTF: " + e);
    const std::string tp = opt_.out_dir + "/xr_session.txt";
    std::ofstream o(tp);
    for (const auto& l : r_.log) o << l << "\n";
    for (const auto& l : r_.triggers) o << "trigger " << l << "\n";
    for (const auto& l : r_.sim_messages) o << "sim: " << l << "\n";
    o << "frames " << r_.frames << " pinched_frames " << r_.frames_pinched << " pinned_added "
      << r_.pinned_added << " cuts " << r_.cuts_ok << " components " << r_.components_before
      << " -> " << r_.components_after << "\n";
    if (o) r_.written.push_back(tp);
  }
}
#endif

bool App::create_instance() {
  uint32_t n = 0;
  XrResult x = xrEnumerateInstanceExtensionProperties(nullptr, 0, &n, nullptr);
  if (XR_FAILED(x)) {
    r_.error = "no OpenXR runtime (xrEnumerateInstanceExtensionProperties: " + std::to_string(x) +
               "); set XR_RUNTIME_JSON or install a runtime (docs/xr.md)";
    note(r_.error);
    set_state(XrAppState::kNoRuntime);
    return false;
  }
  std::vector<XrExtensionProperties> props(n, {XR_TYPE_EXTENSION_PROPERTIES});
  xrEnumerateInstanceExtensionProperties(nullptr, n, &n, props.data());
  bool has_vk2 = false;
  for (const auto& p : props) {
    has_vk2 = has_vk2 || !std::strcmp(p.extensionName, XR_KHR_VULKAN_ENABLE2_EXTENSION_NAME);
    has_hands_ext_ =
        has_hands_ext_ || !std::strcmp(p.extensionName, XR_EXT_HAND_TRACKING_EXTENSION_NAME);
    has_debug_ext_ =
        has_debug_ext_ || !std::strcmp(p.extensionName, XR_EXT_DEBUG_UTILS_EXTENSION_NAME);
  }
  // Extensions of explicitly enabled API layers (the core validation layer's debug utils).
  if (const char* layers = std::getenv("XR_ENABLE_API_LAYERS"); layers && !has_debug_ext_) {
    std::string all = layers;
    size_t p = 0;
    while (p <= all.size()) {
      size_t q = all.find_first_of(":;", p);
      if (q == std::string::npos) q = all.size();
      std::string layer = all.substr(p, q - p);
      p = q + 1;
      if (layer.empty()) continue;
      uint32_t ln = 0;
      if (XR_FAILED(xrEnumerateInstanceExtensionProperties(layer.c_str(), 0, &ln, nullptr)))
        continue;
      std::vector<XrExtensionProperties> lp(ln, {XR_TYPE_EXTENSION_PROPERTIES});
      xrEnumerateInstanceExtensionProperties(layer.c_str(), ln, &ln, lp.data());
      for (const auto& e : lp)
        has_debug_ext_ =
            has_debug_ext_ || !std::strcmp(e.extensionName, XR_EXT_DEBUG_UTILS_EXTENSION_NAME);
    }
  }
  if (!has_vk2) {
    r_.error = "the OpenXR runtime does not offer XR_KHR_vulkan_enable2";
    set_state(XrAppState::kFailed);
    return false;
  }
  std::vector<const char*> exts = {XR_KHR_VULKAN_ENABLE2_EXTENSION_NAME};
  if (has_hands_ext_) exts.push_back(XR_EXT_HAND_TRACKING_EXTENSION_NAME);
  if (has_debug_ext_) exts.push_back(XR_EXT_DEBUG_UTILS_EXTENSION_NAME);
  XrInstanceCreateInfo ci{XR_TYPE_INSTANCE_CREATE_INFO};
  std::snprintf(ci.applicationInfo.applicationName, XR_MAX_APPLICATION_NAME_SIZE, "drape");
  ci.applicationInfo.applicationVersion = 1;
  std::snprintf(ci.applicationInfo.engineName, XR_MAX_ENGINE_NAME_SIZE, "drape");
  ci.applicationInfo.apiVersion = XR_MAKE_VERSION(1, 0, 0);
  ci.enabledExtensionCount = static_cast<uint32_t>(exts.size());
  ci.enabledExtensionNames = exts.data();
  x = xrCreateInstance(&ci, &instance_);
  if (XR_FAILED(x)) {
    r_.error = "xrCreateInstance failed (" + std::to_string(x) + ")";
    note(r_.error);
    set_state(x == XR_ERROR_RUNTIME_UNAVAILABLE ? XrAppState::kNoRuntime : XrAppState::kFailed);
    return false;
  }
  if (has_debug_ext_) {
    auto create = fn<PFN_xrCreateDebugUtilsMessengerEXT>("xrCreateDebugUtilsMessengerEXT");
    XrDebugUtilsMessengerCreateInfoEXT mi{XR_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    mi.messageSeverities = XR_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                           XR_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    mi.messageTypes = XR_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                      XR_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                      XR_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT |
                      XR_DEBUG_UTILS_MESSAGE_TYPE_CONFORMANCE_BIT_EXT;
    mi.userCallback = &debug_callback;
    mi.userData = &r_;
    if (create) create(instance_, &mi, &messenger_);
  }
  XrInstanceProperties ip{XR_TYPE_INSTANCE_PROPERTIES};
  if (XR_SUCCEEDED(xrGetInstanceProperties(instance_, &ip))) r_.runtime_name = ip.runtimeName;
  note("runtime: " + r_.runtime_name);
  XrSystemGetInfo gi{XR_TYPE_SYSTEM_GET_INFO};
  gi.formFactor = XR_FORM_FACTOR_HEAD_MOUNTED_DISPLAY;
  for (int attempt = 0;; ++attempt) {
    x = xrGetSystem(instance_, &gi, &system_);
    if (x != XR_ERROR_FORM_FACTOR_UNAVAILABLE || attempt >= 20) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(250));  // headset not yet plugged in
  }
  if (!ok(x, "xrGetSystem")) return false;
  if (has_hands_ext_) {
    XrSystemHandTrackingPropertiesEXT ht{XR_TYPE_SYSTEM_HAND_TRACKING_PROPERTIES_EXT};
    XrSystemProperties sp{XR_TYPE_SYSTEM_PROPERTIES, &ht};
    if (XR_SUCCEEDED(xrGetSystemProperties(instance_, system_, &sp)))
      r_.hand_tracking = ht.supportsHandTracking == XR_TRUE;
  }
  set_state(XrAppState::kInstance);
  return true;
}

bool App::create_vulkan() {
  auto reqs = fn<PFN_xrGetVulkanGraphicsRequirements2KHR>("xrGetVulkanGraphicsRequirements2KHR");
  auto mk_inst = fn<PFN_xrCreateVulkanInstanceKHR>("xrCreateVulkanInstanceKHR");
  auto get_dev = fn<PFN_xrGetVulkanGraphicsDevice2KHR>("xrGetVulkanGraphicsDevice2KHR");
  auto mk_dev = fn<PFN_xrCreateVulkanDeviceKHR>("xrCreateVulkanDeviceKHR");
  if (!reqs || !mk_inst || !get_dev || !mk_dev) {
    r_.error = "XR_KHR_vulkan_enable2 functions missing";
    return false;
  }
  XrGraphicsRequirementsVulkan2KHR rq{XR_TYPE_GRAPHICS_REQUIREMENTS_VULKAN2_KHR};
  if (!ok(reqs(instance_, system_, &rq), "xrGetVulkanGraphicsRequirements2KHR")) return false;
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "drape";
  app.apiVersion = VK_API_VERSION_1_1;
  VkInstanceCreateInfo vci{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  vci.pApplicationInfo = &app;
  XrVulkanInstanceCreateInfoKHR xi{XR_TYPE_VULKAN_INSTANCE_CREATE_INFO_KHR};
  xi.systemId = system_;
  xi.pfnGetInstanceProcAddr = &vkGetInstanceProcAddr;
  xi.vulkanCreateInfo = &vci;
  VkResult vr = VK_SUCCESS;
  if (!ok(mk_inst(instance_, &xi, &vk_instance_, &vr), "xrCreateVulkanInstanceKHR")) return false;
  if (vr != VK_SUCCESS) {
    r_.error = "vkCreateInstance failed: " + std::to_string(vr);
    return false;
  }
  XrVulkanGraphicsDeviceGetInfoKHR gi{XR_TYPE_VULKAN_GRAPHICS_DEVICE_GET_INFO_KHR};
  gi.systemId = system_;
  gi.vulkanInstance = vk_instance_;
  if (!ok(get_dev(instance_, &gi, &vk_physical_), "xrGetVulkanGraphicsDevice2KHR")) return false;
  uint32_t nq = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(vk_physical_, &nq, nullptr);
  std::vector<VkQueueFamilyProperties> qf(nq);
  vkGetPhysicalDeviceQueueFamilyProperties(vk_physical_, &nq, qf.data());
  queue_family_ = 0;
  while (queue_family_ < nq && !(qf[queue_family_].queueFlags & VK_QUEUE_GRAPHICS_BIT))
    ++queue_family_;
  if (queue_family_ == nq) {
    r_.error = "no graphics queue";
    return false;
  }
  float prio = 1;
  VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  qci.queueFamilyIndex = queue_family_;
  qci.queueCount = 1;
  qci.pQueuePriorities = &prio;
  VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &qci;
  XrVulkanDeviceCreateInfoKHR xd{XR_TYPE_VULKAN_DEVICE_CREATE_INFO_KHR};
  xd.systemId = system_;
  xd.pfnGetInstanceProcAddr = &vkGetInstanceProcAddr;
  xd.vulkanPhysicalDevice = vk_physical_;
  xd.vulkanCreateInfo = &dci;
  if (!ok(mk_dev(instance_, &xd, &vk_device_, &vr), "xrCreateVulkanDeviceKHR")) return false;
  if (vr != VK_SUCCESS) {
    r_.error = "vkCreateDevice failed: " + std::to_string(vr);
    return false;
  }
#ifdef DRAPE_XR_WITH_RENDER
  if (opt_.render) {
    render::ExternalDevice ed;
    ed.instance = vk_instance_;
    ed.physical_device = vk_physical_;
    ed.device = vk_device_;
    ed.queue_family = queue_family_;
    auto rr = render::Renderer::create_on(ed);
    if (!rr) {
      r_.error = "renderer: " + rr.error();
      return false;
    }
    renderer_ = std::move(rr.value());
    for (const auto& [tid, t] : thread_cpu_seconds()) pre_sim_tids_.insert(tid);
    auto scene = sim::make_form_drape(opt_.cloth_res);
    sim::SolverConfig solver_cfg;
    solver_cfg.freeze = true;  // pieces at rest sleep until a hand, pin or cut disturbs them
    // A lock-step run replays bit for bit: the static finish of a sleeping piece then runs one
    // cycle per tick instead of landing whenever its thread ends.
    solver_cfg.finish_thread = !opt_.sim_lock_step;
    auto solver = sim::make_solver("default", solver_cfg);
    if (!solver) {
      r_.error = "solver: " + solver.error();
      return false;
    }
    sim::World w;
    w.cloth = std::move(scene.cloth);
    w.scene = std::move(scene.objects);
    w.solver = std::move(solver.value());
    sim::SimThreadOptions so;
    so.lock_step = opt_.sim_lock_step;
    sim_ = std::make_unique<sim::SimThread>(std::move(w), so);
    reader_ = sim_->make_reader();
    start_sim();
    if (!r_.error.empty()) return false;  // e.g. a command map file that does not load
  }
#endif
  return true;
}

void App::create_actions() {
  XrActionSetCreateInfo si{XR_TYPE_ACTION_SET_CREATE_INFO};
  std::snprintf(si.actionSetName, XR_MAX_ACTION_SET_NAME_SIZE, "drape");
  std::snprintf(si.localizedActionSetName, XR_MAX_LOCALIZED_ACTION_SET_NAME_SIZE, "Drape");
  if (!ok(xrCreateActionSet(instance_, &si, &action_set_), "xrCreateActionSet")) return;
  hand_paths_[0] = path("/user/hand/left");
  hand_paths_[1] = path("/user/hand/right");
  auto make = [&](const char* name, const char* loc, XrActionType t) {
    XrActionCreateInfo ai{XR_TYPE_ACTION_CREATE_INFO};
    std::snprintf(ai.actionName, XR_MAX_ACTION_NAME_SIZE, "%s", name);
    std::snprintf(ai.localizedActionName, XR_MAX_LOCALIZED_ACTION_NAME_SIZE, "%s", loc);
    ai.actionType = t;
    ai.countSubactionPaths = 2;
    ai.subactionPaths = hand_paths_;
    XrAction a = XR_NULL_HANDLE;
    ok(xrCreateAction(action_set_, &ai, &a), name);
    return a;
  };
  pinch_ = make("pinch", "Pinch", XR_ACTION_TYPE_FLOAT_INPUT);
  grab_ = make("grab", "Grab", XR_ACTION_TYPE_BOOLEAN_INPUT);
  pose_ = make("hand_pose", "Hand pose", XR_ACTION_TYPE_POSE_INPUT);
  primary_ = make("primary", "Primary button", XR_ACTION_TYPE_BOOLEAN_INPUT);
  secondary_ = make("secondary", "Secondary button", XR_ACTION_TYPE_BOOLEAN_INPUT);
  haptic_ = make("haptic", "Haptic", XR_ACTION_TYPE_VIBRATION_OUTPUT);
  for (const char* prof : kProfiles) {
    std::string p = prof;
    std::vector<XrActionSuggestedBinding> b;
    const bool simple = p.find("simple") != std::string::npos;
    const bool oculus = p.find("oculus") != std::string::npos;
    const bool index = p.find("index") != std::string::npos;
    for (const char* side : {"left", "right"}) {
      const std::string h = std::string("/user/hand/") + side;
      const bool left = std::string(side) == "left";
      auto bind = [&](XrAction a, const std::string& comp) {
        b.push_back({a, path((h + comp).c_str())});
      };
      bind(pinch_, simple ? "/input/select/click" : "/input/trigger/value");
      if (!simple) bind(grab_, oculus || index ? "/input/squeeze/value" : "/input/squeeze/click");
      bind(pose_, "/input/grip/pose");
      // Primary / secondary buttons ("button.a" / "button.b" of the command map): A/B (X/Y on
      // the left Touch controller); trackpad click / menu on Vive and WMR; menu on simple.
      if (oculus) {
        bind(primary_, left ? "/input/x/click" : "/input/a/click");
        bind(secondary_, left ? "/input/y/click" : "/input/b/click");
      } else if (index) {
        bind(primary_, "/input/a/click");
        bind(secondary_, "/input/b/click");
      } else if (simple) {
        bind(secondary_, "/input/menu/click");
      } else {
        bind(primary_, "/input/trackpad/click");
        bind(secondary_, "/input/menu/click");
      }
      bind(haptic_, "/output/haptic");
    }
    XrInteractionProfileSuggestedBinding sb{XR_TYPE_INTERACTION_PROFILE_SUGGESTED_BINDING};
    sb.interactionProfile = path(prof);
    sb.countSuggestedBindings = static_cast<uint32_t>(b.size());
    sb.suggestedBindings = b.data();
    ok(xrSuggestInteractionProfileBindings(instance_, &sb), prof);
  }
}

bool App::create_session() {
  XrGraphicsBindingVulkan2KHR gb{XR_TYPE_GRAPHICS_BINDING_VULKAN2_KHR};
  gb.instance = vk_instance_;
  gb.physicalDevice = vk_physical_;
  gb.device = vk_device_;
  gb.queueFamilyIndex = queue_family_;
  XrSessionCreateInfo ci{XR_TYPE_SESSION_CREATE_INFO, &gb};
  ci.systemId = system_;
  if (!ok(xrCreateSession(instance_, &ci, &session_), "xrCreateSession")) return false;
  ++r_.sessions;
  session_frame_ = 0;
  xr_state_ = XR_SESSION_STATE_UNKNOWN;
  set_state(XrAppState::kSessionIdle);
  // STAGE (floor at y = 0) when offered, LOCAL otherwise.
  uint32_t n = 0;
  xrEnumerateReferenceSpaces(session_, 0, &n, nullptr);
  std::vector<XrReferenceSpaceType> types(n);
  xrEnumerateReferenceSpaces(session_, n, &n, types.data());
  bool stage = false;
  for (auto t : types) stage = stage || t == XR_REFERENCE_SPACE_TYPE_STAGE;
  XrReferenceSpaceCreateInfo rs{XR_TYPE_REFERENCE_SPACE_CREATE_INFO};
  rs.referenceSpaceType = stage ? XR_REFERENCE_SPACE_TYPE_STAGE : XR_REFERENCE_SPACE_TYPE_LOCAL;
  rs.poseInReferenceSpace.orientation.w = 1;
  if (!stage) rs.poseInReferenceSpace.position.y = -1.6f;  // LOCAL: put the floor below the head
  if (!ok(xrCreateReferenceSpace(session_, &rs, &space_), "xrCreateReferenceSpace")) return false;
  note(stage ? "space: STAGE" : "space: LOCAL (no STAGE)");
  if (action_set_ == XR_NULL_HANDLE) create_actions();
  XrSessionActionSetsAttachInfo at{XR_TYPE_SESSION_ACTION_SETS_ATTACH_INFO};
  at.countActionSets = 1;
  at.actionSets = &action_set_;
  ok(xrAttachSessionActionSets(session_, &at), "xrAttachSessionActionSets");
  for (int h = 0; h < 2; ++h) {
    XrActionSpaceCreateInfo as{XR_TYPE_ACTION_SPACE_CREATE_INFO};
    as.action = pose_;
    as.subactionPath = hand_paths_[h];
    as.poseInActionSpace.orientation.w = 1;
    ok(xrCreateActionSpace(session_, &as, &hand_spaces_[h]), "xrCreateActionSpace");
  }
  if (r_.hand_tracking) {
    auto create = fn<PFN_xrCreateHandTrackerEXT>("xrCreateHandTrackerEXT");
    locate_joints_ = fn<PFN_xrLocateHandJointsEXT>("xrLocateHandJointsEXT");
    for (int h = 0; h < 2 && create; ++h) {
      XrHandTrackerCreateInfoEXT hc{XR_TYPE_HAND_TRACKER_CREATE_INFO_EXT};
      hc.hand = h == 0 ? XR_HAND_LEFT_EXT : XR_HAND_RIGHT_EXT;
      hc.handJointSet = XR_HAND_JOINT_SET_DEFAULT_EXT;
      ok(create(session_, &hc, &trackers_[h]), "xrCreateHandTrackerEXT");
    }
  }
  // Swapchains: one per eye, sRGB colour.
  uint32_t nf = 0;
  xrEnumerateSwapchainFormats(session_, 0, &nf, nullptr);
  std::vector<int64_t> formats(nf);
  xrEnumerateSwapchainFormats(session_, nf, &nf, formats.data());
  format_ = formats.empty() ? int64_t{VK_FORMAT_R8G8B8A8_SRGB} : formats[0];
  for (int64_t want : {int64_t{VK_FORMAT_R8G8B8A8_SRGB}, int64_t{VK_FORMAT_B8G8R8A8_SRGB}}) {
    bool found = false;
    for (int64_t f : formats) found = found || f == want;
    if (found) {
      format_ = want;
      break;
    }
  }
  uint32_t nv = 0;
  xrEnumerateViewConfigurationViews(instance_, system_, XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO,
                                    0, &nv, nullptr);
  std::vector<XrViewConfigurationView> vcv(nv, {XR_TYPE_VIEW_CONFIGURATION_VIEW});
  xrEnumerateViewConfigurationViews(instance_, system_, XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO,
                                    nv, &nv, vcv.data());
  if (nv < 2) {
    r_.error = "the system has no stereo view configuration";
    return false;
  }
  for (int e = 0; e < 2; ++e) {
    XrSwapchainCreateInfo sc{XR_TYPE_SWAPCHAIN_CREATE_INFO};
    sc.usageFlags = XR_SWAPCHAIN_USAGE_COLOR_ATTACHMENT_BIT | XR_SWAPCHAIN_USAGE_SAMPLED_BIT;
    sc.format = format_;
    sc.sampleCount = 1;
    sc.width =
        opt_.eye_size > 0 ? static_cast<uint32_t>(opt_.eye_size) : vcv[e].recommendedImageRectWidth;
    sc.height = opt_.eye_size > 0 ? static_cast<uint32_t>(opt_.eye_size)
                                  : vcv[e].recommendedImageRectHeight;
    sc.faceCount = sc.arraySize = sc.mipCount = 1;
    if (!ok(xrCreateSwapchain(session_, &sc, &eyes_[e].chain), "xrCreateSwapchain")) return false;
    eyes_[e].width = sc.width;
    eyes_[e].height = sc.height;
    uint32_t ni = 0;
    xrEnumerateSwapchainImages(eyes_[e].chain, 0, &ni, nullptr);
    eyes_[e].images.assign(ni, {XR_TYPE_SWAPCHAIN_IMAGE_VULKAN2_KHR});
    if (!ok(xrEnumerateSwapchainImages(
                eyes_[e].chain, ni, &ni,
                reinterpret_cast<XrSwapchainImageBaseHeader*>(eyes_[e].images.data())),
            "xrEnumerateSwapchainImages"))
      return false;
  }
  return true;
}

void App::destroy_session() {
#ifdef DRAPE_XR_WITH_RENDER
  if (renderer_) renderer_->forget_targets();
#endif
  if (vk_device_ != VK_NULL_HANDLE) vkDeviceWaitIdle(vk_device_);
  for (auto& e : eyes_) {
    if (e.chain != XR_NULL_HANDLE) xrDestroySwapchain(e.chain);
    e = Eye{};
  }
  auto destroy_tracker = trackers_[0] || trackers_[1]
                             ? fn<PFN_xrDestroyHandTrackerEXT>("xrDestroyHandTrackerEXT")
                             : nullptr;
  for (int h = 0; h < 2; ++h) {
    if (trackers_[h] && destroy_tracker) destroy_tracker(trackers_[h]);
    trackers_[h] = XR_NULL_HANDLE;
    if (hand_spaces_[h]) xrDestroySpace(hand_spaces_[h]);
    hand_spaces_[h] = XR_NULL_HANDLE;
  }
  if (space_) xrDestroySpace(space_);
  space_ = XR_NULL_HANDLE;
  if (session_) xrDestroySession(session_);
  session_ = XR_NULL_HANDLE;
  running_ = false;
}

void App::teardown_all() {
  destroy_session();
#ifdef DRAPE_XR_WITH_RENDER
  finish_sim();
  reader_ = sim::SnapshotReader();
  sim_.reset();
  renderer_.reset();
#endif
  if (vk_device_) vkDestroyDevice(vk_device_, nullptr);
  vk_device_ = VK_NULL_HANDLE;
  if (vk_instance_) vkDestroyInstance(vk_instance_, nullptr);
  vk_instance_ = VK_NULL_HANDLE;
  if (action_set_) xrDestroyActionSet(action_set_);
  action_set_ = XR_NULL_HANDLE;
  if (messenger_) {
    auto destroy = fn<PFN_xrDestroyDebugUtilsMessengerEXT>("xrDestroyDebugUtilsMessengerEXT");
    if (destroy) destroy(messenger_);
    messenger_ = XR_NULL_HANDLE;
  }
  if (instance_) xrDestroyInstance(instance_);
  instance_ = XR_NULL_HANDLE;
}

// Returns false when the app should leave the loop.
bool App::handle_events() {
  XrEventDataBuffer ev{XR_TYPE_EVENT_DATA_BUFFER};
  while (xrPollEvent(instance_, &ev) == XR_SUCCESS) {
    if (ev.type == XR_TYPE_EVENT_DATA_SESSION_STATE_CHANGED) {
      auto* sc = reinterpret_cast<XrEventDataSessionStateChanged*>(&ev);
      xr_state_ = sc->state;
      switch (sc->state) {
        case XR_SESSION_STATE_READY: {
          XrSessionBeginInfo bi{XR_TYPE_SESSION_BEGIN_INFO};
          bi.primaryViewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
          if (ok(xrBeginSession(session_, &bi), "xrBeginSession")) {
            running_ = true;
            set_state(XrAppState::kSessionRunning);
          }
          break;
        }
        case XR_SESSION_STATE_STOPPING:
          set_state(XrAppState::kSessionStopping);
          ok(xrEndSession(session_), "xrEndSession");
          running_ = false;
          break;
        case XR_SESSION_STATE_EXITING:
          set_state(XrAppState::kExiting);
          return false;
        case XR_SESSION_STATE_LOSS_PENDING:
          ++r_.sessions_lost;
          set_state(XrAppState::kSessionLost);
          destroy_session();
          if (r_.sessions_lost > opt_.max_session_restarts) {
            r_.error = "session lost too often";
            return false;
          }
          if (!create_session()) return false;
          break;
        default:
          break;
      }
    } else if (ev.type == XR_TYPE_EVENT_DATA_INSTANCE_LOSS_PENDING) {
      r_.error = "instance loss pending";
      set_state(XrAppState::kFailed);
      return false;
    }
    ev = {XR_TYPE_EVENT_DATA_BUFFER};
  }
  return true;
}

bool App::frame() {
  XrFrameState fs{XR_TYPE_FRAME_STATE};
  const auto tw = Clock::now();
  XrResult x = xrWaitFrame(session_, nullptr, &fs);
  if (x == XR_ERROR_SESSION_LOST) return true;  // LOSS_PENDING arrives through the event queue
  if (!ok(x, "xrWaitFrame")) return false;
  const auto t0 = Clock::now();
  const double cpu0 = thread_cpu_ms(), pcpu0 = process_cpu_ms();
  // Stage laps of this frame (the profile): wall ms since the previous lap.
  std::vector<std::pair<const char*, double>> laps;
  laps.emplace_back("xr.wait_frame", ms_between(tw, t0));
  auto lap_t = t0;
  auto lap = [&](const char* stage) {
    const auto now = Clock::now();
    laps.emplace_back(stage, ms_between(lap_t, now));
    lap_t = now;
  };
  const int64_t this_frame = session_frame_++;
#ifdef DRAPE_XR_WITH_RENDER
  if (r_.frames == 0 && cpu_at_first_frame_.empty()) cpu_at_first_frame_ = thread_cpu_seconds();
#endif
  x = xrBeginFrame(session_, nullptr);
  if (x == XR_ERROR_SESSION_LOST) return true;
  if (!ok(x, "xrBeginFrame")) return false;
  lap("xr.begin_frame");

  // Input: actions and hands.
  XrActiveActionSet active{action_set_, XR_NULL_PATH};
  XrActionsSyncInfo sync{XR_TYPE_ACTIONS_SYNC_INFO};
  sync.countActiveActionSets = 1;
  sync.activeActionSets = &active;
  if (XR_SUCCEEDED(xrSyncActions(session_, &sync))) {
    for (int h = 0; h < 2; ++h) {
      XrActionStateGetInfo gi{XR_TYPE_ACTION_STATE_GET_INFO};
      gi.action = pinch_;
      gi.subactionPath = hand_paths_[h];
      XrActionStateFloat f{XR_TYPE_ACTION_STATE_FLOAT};
      if (XR_SUCCEEDED(xrGetActionStateFloat(session_, &gi, &f)) && f.isActive)
        r_.max_trigger = std::max(r_.max_trigger, f.currentState);
    }
  }
  XrHandJointLocationEXT joints[2][XR_HAND_JOINT_COUNT_EXT];
  bool joints_active[2] = {false, false};
  for (int h = 0; h < 2 && locate_joints_; ++h) {
    if (!trackers_[h]) continue;
    XrHandJointLocationsEXT loc{XR_TYPE_HAND_JOINT_LOCATIONS_EXT};
    loc.jointCount = XR_HAND_JOINT_COUNT_EXT;
    loc.jointLocations = joints[h];
    XrHandJointsLocateInfoEXT li{XR_TYPE_HAND_JOINTS_LOCATE_INFO_EXT};
    li.baseSpace = space_;
    li.time = fs.predictedDisplayTime;
    joints_active[h] = XR_SUCCEEDED(locate_joints_(trackers_[h], &li, &loc)) && loc.isActive;
  }
  lap("input");
#ifdef DRAPE_XR_WITH_RENDER
  if (running_) interact(fs, joints, joints_active);
#endif
  lap("interact");
  {
    const XrHandJointLocationEXT* j = joints[1];
    if (joints_active[1]) {
      ++r_.hand_frames_tracked;
      auto& a = j[XR_HAND_JOINT_THUMB_TIP_EXT].pose.position;
      auto& b = j[XR_HAND_JOINT_INDEX_TIP_EXT].pose.position;
      float d = std::sqrt((a.x - b.x) * (a.x - b.x) + (a.y - b.y) * (a.y - b.y) +
                          (a.z - b.z) * (a.z - b.z));
      r_.min_pinch_gap_m = std::min(r_.min_pinch_gap_m, d);
    }
  }

  XrCompositionLayerProjectionView pv[2] = {{XR_TYPE_COMPOSITION_LAYER_PROJECTION_VIEW},
                                            {XR_TYPE_COMPOSITION_LAYER_PROJECTION_VIEW}};
  XrCompositionLayerProjection layer{XR_TYPE_COMPOSITION_LAYER_PROJECTION};
  const XrCompositionLayerBaseHeader* layers[1] = {
      reinterpret_cast<XrCompositionLayerBaseHeader*>(&layer)};
  uint32_t layer_count = 0;
  bool cloth_matched = false;           // the drawn snapshot holds a posted right-hand pose ...
  Clock::time_point cloth_posted_at{};  // ... posted then
  if (fs.shouldRender) {
    XrView views[2] = {{XR_TYPE_VIEW}, {XR_TYPE_VIEW}};
    XrViewState vs{XR_TYPE_VIEW_STATE};
    XrViewLocateInfo vl{XR_TYPE_VIEW_LOCATE_INFO};
    vl.viewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
    vl.displayTime = fs.predictedDisplayTime;
    vl.space = space_;
    uint32_t nv = 0;
    x = xrLocateViews(session_, &vl, &vs, 2, &nv, views);
    lap("xr.locate_views");
    bool located = XR_SUCCEEDED(x) && (vs.viewStateFlags & XR_VIEW_STATE_ORIENTATION_VALID_BIT) &&
                   (vs.viewStateFlags & XR_VIEW_STATE_POSITION_VALID_BIT);
    if (located) {
#ifdef DRAPE_XR_WITH_RENDER
      const sim::SceneSnapshot* snap = renderer_ ? &reader_.latest() : nullptr;
      // Free-running sim: wait a bounded time for the tick that consumed this frame's hand pose
      // (posted in interact()), so the cloth drawn now reacts to the hand drawn now.
      // Only when the sim's ticks are short enough for that tick to finish within the wait
      // (a 128^2 VBD tick takes ~240 ms of CPU: waiting would only add to every frame).
      if (snap && ops_ && !opt_.sim_lock_step && opt_.pose_wait_ms > 0 && !posted_.empty() &&
          posted_.back().frame == this_frame && sim_->timing().step_ms_p50 < opt_.pose_wait_ms) {
        const auto deadline =
            std::chrono::steady_clock::now() +
            std::chrono::microseconds(static_cast<int64_t>(opt_.pose_wait_ms * 1e3));
        auto holds_pose = [&](const sim::SceneSnapshot& s) {
          for (const auto& hp : s.hands)
            if (hp.id == 1 && hp.tracked && hp.position == posted_.back().position) return true;
          return false;
        };
        while (!holds_pose(*snap) && std::chrono::steady_clock::now() < deadline) {
          std::this_thread::sleep_for(std::chrono::microseconds(250));
          snap = &reader_.latest();
        }
      }
      lap("pose_wait");
      // Pose-to-photon probes. Cloth (sim) latency: which frame's right-hand pose is in the
      // snapshot drawn now. Hand latency: which frame's pose the drawn hand has.
      if (snap && ops_) {
        for (const auto& hp : snap->hands)
          if (hp.id == 1 && hp.tracked)
            for (auto it = posted_.rbegin(); it != posted_.rend(); ++it)
              if (it->position == hp.position) {
                r_.cloth_latency_frames.push_back(static_cast<int>(this_frame - it->frame));
                cloth_posted_at = it->when;
                cloth_matched = true;
                break;
              }
        for (const auto& ov : overlays_)
          if (ov.id == 1)
            for (auto it = posted_.rbegin(); it != posted_.rend(); ++it)
              if (it->position.cast<float>() == ov.pointer) {
                r_.latency_frames.push_back(static_cast<int>(this_frame - it->frame));
                break;
              }
      }
#endif
      lap("probes");
      // Both eyes: acquire and wait both swapchain images, draw them with one geometry build and
      // one submission (render::Renderer::render_views), release both.
      uint32_t idx[2] = {0, 0};
      for (int e = 0; e < 2; ++e) {
        if (!ok(xrAcquireSwapchainImage(eyes_[e].chain, nullptr, &idx[e]),
                "xrAcquireSwapchainImage"))
          return false;
        XrSwapchainImageWaitInfo wi{XR_TYPE_SWAPCHAIN_IMAGE_WAIT_INFO};
        wi.timeout = XR_INFINITE_DURATION;
        if (!ok(xrWaitSwapchainImage(eyes_[e].chain, &wi), "xrWaitSwapchainImage")) return false;
      }
      lap("xr.acquire");
#ifdef DRAPE_XR_WITH_RENDER
      if (renderer_ && snap) {
        render::ViewTarget vt[2];
        for (int e = 0; e < 2; ++e) {
          render::Pose pose;
          const XrPosef& p = views[e].pose;
          pose.orientation = Eigen::Quaternionf(p.orientation.w, p.orientation.x, p.orientation.y,
                                                p.orientation.z);
          pose.position = {p.position.x, p.position.y, p.position.z};
          render::Fov fov{views[e].fov.angleLeft, views[e].fov.angleRight, views[e].fov.angleUp,
                          views[e].fov.angleDown};
          vt[e].view = render::make_view(pose, fov);
          vt[e].target.image = eyes_[e].images[idx[e]].image;
          vt[e].target.format = static_cast<VkFormat>(format_);
          vt[e].target.width = eyes_[e].width;
          vt[e].target.height = eyes_[e].height;
        }
        render::DrawOptions dopt;
        dopt.hands = overlays_;
        // The form's level of detail from the eyes' pixel size (lavapipe is vertex-bound).
        const float rad_per_px =
            (views[0].fov.angleRight - views[0].fov.angleLeft) / static_cast<float>(eyes_[0].width);
        const render::FormLod lod = render::form_lod_for_pixels(rad_per_px);
        if (opt_.form_lod) {
          dopt.form_section_spacing = lod.section_spacing;
          dopt.form_angle_step = lod.angle_step;
        }
        if (opt_.pointer_probe && ops_) {
          // Left eye: where the right-hand pointer of this and the 3 previous frames projects.
          XrAppResult::PointerProbe pr;
          pr.frame = this_frame;
          int n = 0;
          for (auto it = posted_.rbegin(); it != posted_.rend() && n < 4; ++it, ++n) {
            auto px = render::project_to_pixel(vt[0].view, it->position.cast<float>(),
                                               static_cast<int>(vt[0].target.width),
                                               static_cast<int>(vt[0].target.height));
            pr.frames_back[n] = static_cast<int>(this_frame - it->frame);
            pr.px[n] =
                px ? std::array<float, 2>{px->x(), px->y()} : std::array<float, 2>{-1e9f, -1e9f};
          }
          pr.count = n;
          r_.pointer_probe.push_back(pr);
        }
        auto st = renderer_->render_views(*snap, vt, 2, dopt);
        if (!st) note("render: " + st.error);
        lap("render");
        const render::FrameStats& rs = renderer_->last_frame();
        laps.emplace_back("render.build", rs.build_ms);
        laps.emplace_back("render.upload", rs.upload_ms);
        laps.emplace_back("render.record_submit", rs.submit_ms - rs.upload_ms);
        laps.emplace_back("render.gpu_wait", rs.wait_ms);
        laps.emplace_back("render.cloth_rebuilt", rs.cloth_rebuilt ? 1.0 : 0.0);
      }
#endif
      for (int e = 0; e < 2; ++e) {
        if (!ok(xrReleaseSwapchainImage(eyes_[e].chain, nullptr), "xrReleaseSwapchainImage"))
          return false;
        pv[e].pose = views[e].pose;
        pv[e].fov = views[e].fov;
        pv[e].subImage.swapchain = eyes_[e].chain;
        pv[e].subImage.imageRect = {
            {0, 0}, {static_cast<int32_t>(eyes_[e].width), static_cast<int32_t>(eyes_[e].height)}};
      }
      lap("xr.release");
      layer.space = space_;
      layer.viewCount = 2;
      layer.views = pv;
      layer_count = 1;
    }
  }
  XrFrameEndInfo ei{XR_TYPE_FRAME_END_INFO};
  ei.displayTime = fs.predictedDisplayTime;
  ei.environmentBlendMode = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
  ei.layerCount = layer_count;
  ei.layers = layers;
  x = xrEndFrame(session_, &ei);
  if (x == XR_ERROR_SESSION_LOST) return true;
  if (!ok(x, "xrEndFrame")) return false;
  lap("xr.end_frame");
  const auto t_end = Clock::now();
  r_.frame_ms.push_back(ms_between(t0, t_end));
  if (cloth_matched) r_.cloth_latency_ms.push_back(ms_between(cloth_posted_at, t_end));
  for (const auto& [stage, ms] : laps) prof(stage, ms);
  prof("frame.cpu", thread_cpu_ms() - cpu0);
  prof("frame.process_cpu", process_cpu_ms() - pcpu0);
  ++r_.frames;
  if (layer_count) ++r_.frames_rendered;
  if (opt_.max_frames > 0 && r_.frames >= opt_.max_frames && !exit_requested_) {
    exit_requested_ = true;
    ok(xrRequestExitSession(session_), "xrRequestExitSession");
  }
  return true;
}

void App::run() {
  if (!create_instance()) return;
  if (!create_vulkan()) {
    set_state(XrAppState::kFailed);
    return;
  }
  if (!create_session()) {
    set_state(XrAppState::kFailed);
    return;
  }
  for (;;) {
    if (!handle_events()) break;
    if (state_ == XrAppState::kFailed) break;
    if (running_) {
      if (!frame()) {
        set_state(XrAppState::kFailed);
        break;
      }
    } else {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));  // wait for READY / EXITING
    }
  }
}

}  // namespace

XrAppResult run_xr_app(const XrAppOptions& opt) {
  XrAppResult res;
#ifdef M_TRIM_THRESHOLD
  if (opt.tune_malloc) {
    // lavapipe (llvmpipe's draw module) mallocs and frees tens of MB of vertex data per draw on
    // its queue thread; glibc returns the freed top of that thread's arena to the kernel
    // (madvise) every time and the next frame faults every page back in: 660k page faults and
    // ~30 ms of system time per frame at 2 x 512^2 (docs/xr.md, "Profile"). Keep freed memory in
    // the process instead (as GLIBC_TUNABLES=glibc.malloc.trim_threshold=... would).
    mallopt(M_TRIM_THRESHOLD, 512 << 20);
    mallopt(M_MMAP_THRESHOLD, 32 << 20);
  }
#endif
  {
    App app(opt, &res);
    app.run();
    res.final_state = app.state();
  }
  if (res.final_state == XrAppState::kExiting && res.error.empty())
    res.exit_code = 0;
  else if (res.final_state == XrAppState::kNoRuntime)
    res.exit_code = 3;
  else
    res.exit_code = 1;
  return res;
}

}  // namespace drape::app
