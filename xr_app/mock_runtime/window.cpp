// Window mode of the mock runtime: the window thread (GLFW on X11, an OpenGL 2.1 context that
// draws the read-back eye images as a texture) and the mapping of mouse and keyboard to the
// head, the hands and the controllers. See window.hpp and docs/mock-window.md.
#include "xr_app/mock_runtime/window.hpp"

#include <GLFW/glfw3.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <future>
#include <limits>
#include <mutex>
#include <thread>
#include <vector>

namespace drape::mock {

namespace {

constexpr int kDefaultWidth = 960, kDefaultHeight = 720;
constexpr float kDefaultDistance = 0.45f;  // view depth of a hand when the app submits no depth
constexpr float kMinDistance = 0.05f;
constexpr float kMoveSpeed = 1.0f;       // m/s
constexpr float kLookPerPixel = 0.004f;  // rad per pixel of right-drag
constexpr float kWheelStep = 0.02f;      // m per wheel notch
constexpr float kSelfHit = 0.01f;        // depth hits within a joint's radius plus this: the hand

constexpr float kPushDistance = 0.2f;  // m: T thrusts the open palm this far forward ...
constexpr float kPushSpeed = 1.5f;     // m/s: ... at this speed

// The keys held down (besides the one-shot ones: Tab, R, V, Escape). Z X C G U T P: gestures;
// the arrows and Enter: the thumbstick (trackpad) and its click.
enum Key {
  kW,
  kA,
  kS,
  kD,
  kQ,
  kE,
  kF,
  k1,
  k2,
  k3,
  k4,
  kM,
  kLeftShift,
  kRightShift,
  kZ,
  kX,
  kC,
  kG,
  kU,
  kT,
  kP,
  kUp,
  kDown,
  kLeft,
  kRight,
  kEnter,
  kF5,
  kKeys
};
constexpr int kGlfwKeys[kKeys] = {
    GLFW_KEY_W,     GLFW_KEY_A,  GLFW_KEY_S,          GLFW_KEY_D,           GLFW_KEY_Q,
    GLFW_KEY_E,     GLFW_KEY_F,  GLFW_KEY_1,          GLFW_KEY_2,           GLFW_KEY_3,
    GLFW_KEY_4,     GLFW_KEY_M,  GLFW_KEY_LEFT_SHIFT, GLFW_KEY_RIGHT_SHIFT, GLFW_KEY_Z,
    GLFW_KEY_X,     GLFW_KEY_C,  GLFW_KEY_G,          GLFW_KEY_U,           GLFW_KEY_T,
    GLFW_KEY_P,     GLFW_KEY_UP, GLFW_KEY_DOWN,       GLFW_KEY_LEFT,        GLFW_KEY_RIGHT,
    GLFW_KEY_ENTER, GLFW_KEY_F5};

double seconds_now() {
  return static_cast<double>(now_ns()) * 1e-9;
}

// A key from its press and release events: whether it is down, pressed at all, and for how long
// since it was last taken (so a frame sees a quick tap, and the head moves for exactly as long
// as a key was held however seldom the app's frames come).
struct KeyState {
  bool down = false;
  int presses = 0;
  double since = 0, held = 0;
};

// What the window thread gathers; the runtime takes it once per frame.
struct RawInput {
  int win_w = 0, win_h = 0;
  double cx = -1, cy = -1;
  bool lmb = false;
  KeyState key[kKeys];
  double look_dx = 0, look_dy = 0;                    // accumulated until taken
  double wheel = 0;                                   // accumulated until taken
  int tab = 0, reset = 0, view = 0, lmb_presses = 0;  // presses until taken
  bool quit = false;
};

struct Rect {
  float x, y, w, h;
};

// The content (cw x ch) scaled to fit the window and centred.
Rect fit(float ww, float wh, float cw, float ch) {
  float s = std::min(ww / cw, wh / ch);
  return {(ww - cw * s) / 2, (wh - ch * s) / 2, cw * s, ch * s};
}

XrQuaternionf axis_angle(XrVector3f axis, float angle) {
  float s = std::sin(angle / 2);
  return {axis.x * s, axis.y * s, axis.z * s, std::cos(angle / 2)};
}
// The shortest rotation taking unit vector a to unit vector b.
XrQuaternionf rotation_between(XrVector3f a, XrVector3f b) {
  XrVector3f c{a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
  float d = a.x * b.x + a.y * b.y + a.z * b.z;
  if (d < -0.9999f) return {0, 1, 0, 0};
  return quat_normalize({c.x, c.y, c.z, 1 + d});
}

std::string last_glfw_error;
void on_glfw_error(int code, const char* text) {
  last_glfw_error = std::to_string(code) + ": " + (text ? text : "");
}

}  // namespace

struct Window {
  // ---- shared with the window thread (under mu)
  std::mutex mu;
  RawInput raw;
  std::vector<unsigned char> pixels;  // the image to show (RGBA, rows top down)
  int pw = 0, ph = 0;
  bool fresh = false;  // pixels not yet taken by the window thread
  std::string title;
  bool title_dirty = false;
  bool stop = false;
  bool dragging = false;  // right button held
  bool motion_seen = false;
  double motion_x = 0, motion_y = 0;  // the cursor as of the last motion event
  std::thread thread;
  int req_w = kDefaultWidth, req_h = kDefaultHeight;

  // ---- runtime side (under g_lock)
  XrPosef home{};  // head pose of frame 0 of the scenario (or the default)
  XrVector3f head_pos{};
  float yaw = 0, pitch = 0;
  struct Hand {
    XrVector3f pos{};  // the pinch point (between thumb and index tips)
    XrVector3f ray{0, 0, -1};
    float z = kDefaultDistance;  // view depth of the surface it sits on
    float wheel = 0;             // nearer (<0) / farther (>0) than that surface
    float pinch = 0, fist = 0;
    HandShape shape =
        kShapeOpen;        // Z X C: the thumb's pinch with middle, ring, little; G: flat; P: point
    bool palm_up = false;  // U
    float push = -1;       // T: how far the palm has thrust forward (-1: not pushing)
    XrVector2f stick{0, 0};    // the arrows
    bool stick_click = false;  // Enter
    HandSample published;      // the joints as last published (stage)
  } hands[2];
  bool both = false;  // both eyes side by side
  int eye_w = 0, eye_h = 0;
  bool depth_seen = false;  // the app has submitted depth
  bool hit_valid = false;
  bool hit_hand = false;  // the hit was on the app's drawing of a hand (ignored)
  float hit_z = 0;
  int hit_eye = 0;
  std::vector<XrPath> cycle;  // XR_NULL_PATH: hand tracking only
  size_t cycle_at = 0;
  bool cycle_ready = false;
  bool quit_sent = false;
  int64_t menu_until = -1;  // F5: the menu button is held until this frame
  FILE* log_file = nullptr;
  std::string shown_title;

  // A depth hit on the app's drawing of a hand: within a joint's radius (plus kSelfHit) of one
  // of the joints published last or of a bone between two of them.
  bool on_a_hand(const XrVector3f& p) const {
    auto near_segment = [&](const XrVector3f& a, const XrVector3f& b, float r) {
      XrVector3f ab = sub(b, a);
      float l2 = ab.x * ab.x + ab.y * ab.y + ab.z * ab.z;
      XrVector3f ap = sub(p, a);
      float t = l2 > 0 ? std::clamp((ap.x * ab.x + ap.y * ab.y + ap.z * ab.z) / l2, 0.f, 1.f) : 0;
      return len(sub(p, add(a, mul(ab, t)))) < r + kSelfHit;
    };
    for (const Hand& h : hands) {
      const HandSample& s = h.published;
      if (!s.tracked) continue;
      for (int j = 0; j < kHandJointCount; ++j) {
        // Each joint's bone toward the wrist: the metacarpals from the wrist, the others from
        // the joint before them on the finger; the palm and the wrist as spheres.
        int from = j;
        if (j == XR_HAND_JOINT_THUMB_METACARPAL_EXT || j == XR_HAND_JOINT_INDEX_METACARPAL_EXT ||
            j == XR_HAND_JOINT_MIDDLE_METACARPAL_EXT || j == XR_HAND_JOINT_RING_METACARPAL_EXT ||
            j == XR_HAND_JOINT_LITTLE_METACARPAL_EXT)
          from = XR_HAND_JOINT_WRIST_EXT;
        else if (j > XR_HAND_JOINT_WRIST_EXT)
          from = j - 1;
        if (near_segment(s.joints[from].position, s.joints[j].position,
                         std::max(s.radii[from], s.radii[j])))
          return true;
      }
    }
    return false;
  }

  ~Window() {
    {
      std::lock_guard<std::mutex> g(mu);
      stop = true;
    }
    if (thread.joinable()) thread.join();
    if (log_file) std::fclose(log_file);
  }

  void run(std::promise<std::string> ready);

  // The cursor over the shown image: which eye and where in it ([0, 1), v down).
  bool cursor_in_view(const RawInput& r, int* eye, float* u, float* v) const {
    if (r.win_w <= 0 || r.win_h <= 0) return false;
    float ew = eye_w > 0 ? static_cast<float>(eye_w) : 1.f;
    float eh = eye_h > 0 ? static_cast<float>(eye_h) : 1.f;
    Rect rc = fit(static_cast<float>(r.win_w), static_cast<float>(r.win_h), both ? 2 * ew : ew, eh);
    float x = (static_cast<float>(r.cx) - rc.x) / rc.w,
          y = (static_cast<float>(r.cy) - rc.y) / rc.h;
    if (!(x >= 0 && x < 1 && y >= 0 && y < 1)) return false;
    *eye = 0;
    if (both) {
      *eye = x < 0.5f ? 0 : 1;
      x = x * 2 - static_cast<float>(*eye);
    }
    *u = x;
    *v = y;
    return true;
  }
};

namespace {

Window* self_of(GLFWwindow* w) {
  return static_cast<Window*>(glfwGetWindowUserPointer(w));
}

void on_key(GLFWwindow* gw, int key, int, int action, int) {
  if (action == GLFW_REPEAT) return;
  Window* w = self_of(gw);
  std::lock_guard<std::mutex> g(w->mu);
  for (int k = 0; k < kKeys; ++k) {
    if (kGlfwKeys[k] != key) continue;
    KeyState& ks = w->raw.key[k];
    const double t = seconds_now();
    if (action == GLFW_PRESS && !ks.down) {
      ks.down = true;
      ++ks.presses;
      ks.since = t;
    } else if (action == GLFW_RELEASE && ks.down) {
      ks.down = false;
      ks.held += t - ks.since;
    }
  }
  if (action != GLFW_PRESS) return;
  switch (key) {
    case GLFW_KEY_TAB:
      ++w->raw.tab;
      break;
    case GLFW_KEY_R:
      ++w->raw.reset;
      break;
    case GLFW_KEY_V:
      ++w->raw.view;
      break;
    case GLFW_KEY_ESCAPE:
      w->raw.quit = true;
      break;
    default:
      break;
  }
}

// Mouse buttons. The right one starts and ends a look drag (on_cursor adds up the motion events
// in between, in the order of the events, not from where the pointer is when they are handled); the
// left one is held, and counted when pressed (a quick click pinches for at least one frame).
void on_button(GLFWwindow* gw, int button, int action, int) {
  Window* w = self_of(gw);
  std::lock_guard<std::mutex> g(w->mu);
  if (button == GLFW_MOUSE_BUTTON_LEFT) {
    w->raw.lmb = action == GLFW_PRESS;
    if (w->raw.lmb) ++w->raw.lmb_presses;
  }
  if (button != GLFW_MOUSE_BUTTON_RIGHT) return;
  w->dragging = action == GLFW_PRESS;
}

void on_cursor(GLFWwindow* gw, double x, double y) {
  Window* w = self_of(gw);
  std::lock_guard<std::mutex> g(w->mu);
  if (w->dragging && w->motion_seen) {
    w->raw.look_dx += x - w->motion_x;
    w->raw.look_dy += y - w->motion_y;
  }
  w->motion_seen = true;
  w->motion_x = x;
  w->motion_y = y;
}

void on_scroll(GLFWwindow* gw, double, double dy) {
  Window* w = self_of(gw);
  std::lock_guard<std::mutex> g(w->mu);
  w->raw.wheel += dy;
}

}  // namespace

void Window::run(std::promise<std::string> ready) {
  glfwSetErrorCallback(on_glfw_error);
#if GLFW_VERSION_MAJOR * 100 + GLFW_VERSION_MINOR >= 304
  glfwInitHint(GLFW_PLATFORM, GLFW_PLATFORM_X11);
#endif
  if (!glfwInit()) {
    ready.set_value("glfwInit failed (is DISPLAY set?) " + last_glfw_error);
    return;
  }
  glfwWindowHint(GLFW_CLIENT_API, GLFW_OPENGL_API);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 2);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 1);
  GLFWwindow* win = glfwCreateWindow(req_w, req_h, "drape mock runtime", nullptr, nullptr);
  if (!win) {
    std::string e = last_glfw_error;
    glfwTerminate();
    ready.set_value("glfwCreateWindow failed " + e);
    return;
  }
  glfwSetWindowUserPointer(win, this);
  glfwSetKeyCallback(win, on_key);
  glfwSetScrollCallback(win, on_scroll);
  glfwSetMouseButtonCallback(win, on_button);
  glfwSetCursorPosCallback(win, on_cursor);
  glfwMakeContextCurrent(win);
  glfwSwapInterval(0);
  GLuint tex = 0;
  glGenTextures(1, &tex);
  glBindTexture(GL_TEXTURE_2D, tex);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  ready.set_value("");

  int tex_w = 0, tex_h = 0, drawn_w = 0, drawn_h = 0;
  std::vector<unsigned char> px;
  for (;;) {
    glfwWaitEventsTimeout(1.0 / 240);
    int ww = 0, wh = 0, fw = 0, fh = 0;
    glfwGetWindowSize(win, &ww, &wh);
    glfwGetFramebufferSize(win, &fw, &fh);
    double cx = 0, cy = 0;
    glfwGetCursorPos(win, &cx, &cy);
    bool upload = false;
    std::string new_title;
    {
      std::lock_guard<std::mutex> g(mu);
      if (stop) break;
      RawInput& r = raw;
      r.win_w = ww;
      r.win_h = wh;
      r.cx = cx;
      r.cy = cy;
      if (glfwWindowShouldClose(win)) r.quit = true;
      if (fresh) {
        px.swap(pixels);
        tex_w = pw;
        tex_h = ph;
        fresh = false;
        upload = true;
      }
      if (title_dirty) {
        new_title = title;
        title_dirty = false;
      }
    }
    if (!new_title.empty()) glfwSetWindowTitle(win, new_title.c_str());
    if (upload && tex_w > 0 && tex_h > 0 &&
        px.size() >= static_cast<size_t>(tex_w) * static_cast<size_t>(tex_h) * 4)
      glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, tex_w, tex_h, 0, GL_RGBA, GL_UNSIGNED_BYTE,
                   px.data());
    if (!upload && drawn_w == fw && drawn_h == fh) continue;
    drawn_w = fw;
    drawn_h = fh;
    glViewport(0, 0, fw, fh);
    glClearColor(0.08f, 0.08f, 0.08f, 1.f);
    glClear(GL_COLOR_BUFFER_BIT);
    if (tex_w > 0 && tex_h > 0 && ww > 0 && wh > 0) {
      glMatrixMode(GL_PROJECTION);
      glLoadIdentity();
      glOrtho(0, ww, wh, 0, -1, 1);  // window coordinates, y down
      glMatrixMode(GL_MODELVIEW);
      glLoadIdentity();
      Rect rc = fit(static_cast<float>(ww), static_cast<float>(wh), static_cast<float>(tex_w),
                    static_cast<float>(tex_h));
      glEnable(GL_TEXTURE_2D);
      glColor3f(1, 1, 1);
      glBegin(GL_QUADS);  // texture row 0 is the image's top
      glTexCoord2f(0, 0);
      glVertex2f(rc.x, rc.y);
      glTexCoord2f(1, 0);
      glVertex2f(rc.x + rc.w, rc.y);
      glTexCoord2f(1, 1);
      glVertex2f(rc.x + rc.w, rc.y + rc.h);
      glTexCoord2f(0, 1);
      glVertex2f(rc.x, rc.y + rc.h);
      glEnd();
      glDisable(GL_TEXTURE_2D);
    }
    glfwSwapBuffers(win);
  }
  glDeleteTextures(1, &tex);
  glfwDestroyWindow(win);
  glfwTerminate();
}

bool window_requested() {
  const char* v = std::getenv("DRAPE_MOCK_WINDOW");
  if (!v || !*v || std::strcmp(v, "0") == 0) return false;
  if (std::strcmp(v, "1") == 0) return true;
  log("ignoring DRAPE_MOCK_WINDOW=%s (1 opens the window, 0 or unset does not)", v);
  return false;
}

std::shared_ptr<Window> open_window(Session* s, std::string* why) {
  auto w = std::make_shared<Window>();
  if (const char* sz = std::getenv("DRAPE_MOCK_WINDOW_SIZE"); sz && *sz) {
    int a = 0, b = 0;
    char extra = 0;
    if (std::sscanf(sz, "%dx%d%c", &a, &b, &extra) == 2 && a >= 64 && b >= 64 && a <= 8192 &&
        b <= 8192) {
      w->req_w = a;
      w->req_h = b;
    } else {
      log("ignoring DRAPE_MOCK_WINDOW_SIZE=%s (WIDTHxHEIGHT, 64 to 8192)", sz);
    }
  }
  Instance* inst = instance_of(s);
  w->home = inst->scenario.head_pose(0);
  w->head_pos = w->home.position;
  for (int h = 0; h < 2; ++h) {
    XrVector3f local{h == 0 ? -0.15f : 0.15f, -0.3f, -kDefaultDistance};
    w->hands[h].pos = add(w->home.position, quat_rotate(w->home.orientation, local));
  }
  if (const char* lp = std::getenv("DRAPE_MOCK_WINDOW_LOG"); lp && *lp) {
    w->log_file = std::fopen(lp, "w");
    if (!w->log_file) {
      *why = std::string("cannot write DRAPE_MOCK_WINDOW_LOG=") + lp;
      return nullptr;
    }
  }
  std::promise<std::string> ready;
  std::future<std::string> result = ready.get_future();
  Window* wp = w.get();
  w->thread = std::thread([wp, p = std::move(ready)]() mutable { wp->run(std::move(p)); });
  if (std::string e = result.get(); !e.empty()) {
    *why = e;
    return nullptr;
  }
  log("window mode: %dx%d window, keys in docs/mock-window.md", w->req_w, w->req_h);
  return w;
}

// The surface depth's step (m).
constexpr float kDepthStep = 1e-4f;

float depth_to_distance(float d, float min_depth, float max_depth, float near_z, float far_z) {
  const float inf = std::numeric_limits<float>::infinity();
  float t = (d - min_depth) / (max_depth - min_depth);
  float inv = 1.f / near_z + t * (1.f / far_z - 1.f / near_z);  // 1/inf = 0
  if (!(inv > 0)) return inf;
  float z = 1.f / inv;
  if (z >= 0.999f * std::max(near_z, far_z)) return inf;  // the far plane: nothing drawn
  return z;
}

namespace {
// Z X C G U T P and the arrows / Enter for the hand under the mouse; the other hand's gestures and
// stick are let go. T thrusts the palm forward at kPushSpeed (held_t: T's time held since the
// last frame) up to kPushDistance.
template <class On>
void take_gesture_keys(Window::Hand& hd, Window::Hand& other, On on, float held_t) {
  hd.shape = on(kZ)   ? kShapePinchMiddle
             : on(kX) ? kShapePinchRing
             : on(kC) ? kShapePinchLittle
             : on(kG) ? kShapeTogether
             : on(kP) ? kShapePoint
                      : kShapeOpen;
  hd.palm_up = on(kU);
  hd.push = on(kT) ? std::min(kPushDistance, std::max(0.f, hd.push) + kPushSpeed * held_t) : -1;
  auto axis = [&](Key plus, Key minus) { return (on(plus) ? 1.f : 0.f) - (on(minus) ? 1.f : 0.f); };
  hd.stick = {axis(kRight, kLeft), axis(kUp, kDown)};
  hd.stick_click = on(kEnter);
  other.shape = kShapeOpen;
  other.palm_up = false;
  other.push = -1;
  other.stick = {0, 0};
  other.stick_click = false;
}

const char* gesture_name(const Window::Hand& k) {
  if (k.push >= 0) return "push";
  if (k.palm_up) return "palm_up";
  const char* names[] = {"open", "pinch_middle", "pinch_ring", "pinch_little", "flat", "point"};
  return names[k.shape];
}

// The palm's orientation: down with the fingers forward (body), turned up (U), or facing
// forward with the fingers up (T); and where the pinch point sits (T: thrust forward).
XrPosef palm_pose(const Window::Hand& k, const XrQuaternionf& body, const XrVector3f& mid) {
  XrQuaternionf q = body;
  if (k.palm_up) q = quat_mul(body, axis_angle({0, 0, 1}, 3.14159265f));
  if (k.push >= 0) q = quat_mul(body, axis_angle({1, 0, 0}, 3.14159265f / 2));
  const XrVector3f at = k.push > 0 ? add(k.pos, quat_rotate(body, {0, 0, -k.push})) : k.pos;
  return XrPosef{q, sub(at, quat_rotate(q, mid))};
}

// The controller of hand h: its grip (rolled palm up on U: the grip's +x is the left palm's
// normal, -x the right one's), the arrows and Enter as the thumbstick (the trackpad on a
// profile without a stick) and its click.
void stick_inputs(const Window::Hand& k, int h, bool pad_only, ControllerKey& ck) {
  if (k.palm_up)
    ck.grip.orientation =
        quat_mul(ck.grip.orientation, axis_angle({0, 0, 1}, (h == 0 ? 1 : -1) * 3.14159265f / 2));
  const char* stick = pad_only ? "trackpad" : "thumbstick";
  ck.inputs[stick] = {k.stick.x, k.stick.y};
  ck.inputs[std::string(stick) + "/click"] = {k.stick_click ? 1.f : 0.f, 0};
}
}  // namespace

namespace {
// Interaction profile: the one chosen at attach, then Tab cycles through the suggested ones
// and, with XR_EXT_hand_tracking enabled, hand tracking alone (no controller).
void init_profile_cycle(Window* w, Session* s, Instance* inst) {
  if (!w->cycle_ready && !s->attached_sets.empty()) {
    w->cycle = suggested_profiles(s);
    if (inst->extensions.count(XR_EXT_HAND_TRACKING_EXTENSION_NAME))
      w->cycle.push_back(XR_NULL_PATH);
    auto it = std::find(w->cycle.begin(), w->cycle.end(), s->profile[0]);
    w->cycle_at = it == w->cycle.end() ? 0 : static_cast<size_t>(it - w->cycle.begin());
    w->cycle_ready = true;
    // With hand tracking enabled and no scenario naming a profile, the keys make gestures: the
    // window starts with the hands alone.
    if (!w->cycle.empty() && w->cycle.back() == XR_NULL_PATH &&
        inst->scenario.interaction_profile.empty() && s->profile[0] != XR_NULL_PATH) {
      w->cycle_at = w->cycle.size() - 1;
      s->profile[0] = s->profile[1] = XR_NULL_PATH;
      XrEventDataInteractionProfileChanged ev{XR_TYPE_EVENT_DATA_INTERACTION_PROFILE_CHANGED};
      ev.session = to_handle<XrSession>(s->handle);
      push_event(inst, &ev, sizeof(ev));
      log("window: interaction profile none (hand tracking)");
    }
  }
}
}  // namespace

// F5 (a tap) holds the menu button for kMenuHoldFrames of the runtime's frames: 1.1 s of its
// frame time, past the 1 s for which the drape app saves the session (button.menu_hold).
constexpr int64_t kMenuHoldFrames = 100;
bool menu_held(Window* w, const RawInput& r, int64_t frame) {
  if (r.key[kF5].presses > 0 || r.key[kF5].down) w->menu_until = frame + kMenuHoldFrames;
  return frame < w->menu_until;
}

void window_wait_frame(Session* s, int64_t frame) {
  Window* w = s->window.get();
  Instance* inst = instance_of(s);
  RawInput r;
  {
    std::lock_guard<std::mutex> g(w->mu);
    const double t = seconds_now();
    for (KeyState& k : w->raw.key) {
      if (k.down) {
        k.held += t - k.since;
        k.since = t;
      }
    }
    r = w->raw;
    w->raw.look_dx = w->raw.look_dy = w->raw.wheel = 0;
    w->raw.tab = w->raw.reset = w->raw.view = w->raw.lmb_presses = 0;
    for (KeyState& k : w->raw.key) k.presses = 0, k.held = 0;
  }
  // A key is on for this frame when it is down or was pressed since the last one.
  auto on = [&](Key k) { return r.key[k].down || r.key[k].presses > 0; };
  auto held = [&](Key k) { return static_cast<float>(std::min(r.key[k].held, 0.25)); };
  const bool menu = on(kM) || menu_held(w, r, frame);

  init_profile_cycle(w, s, inst);
  if (w->cycle_ready && w->cycle.size() > 1 && r.tab > 0) {
    w->cycle_at = (w->cycle_at + static_cast<size_t>(r.tab)) % w->cycle.size();
    s->profile[0] = s->profile[1] = w->cycle[w->cycle_at];
    XrEventDataInteractionProfileChanged ev{XR_TYPE_EVENT_DATA_INTERACTION_PROFILE_CHANGED};
    ev.session = to_handle<XrSession>(s->handle);
    push_event(inst, &ev, sizeof(ev));
    std::string name = path_string(inst, s->profile[0]);
    log("window: interaction profile %s", name.empty() ? "none (hand tracking)" : name.c_str());
  }
  const bool controllers = s->profile[0] != XR_NULL_PATH;

  if (r.quit && !w->quit_sent) {
    w->quit_sent = true;
    log("window: closed or Escape: ending the session");
    begin_stopping(s);
  }
  if (r.view % 2) w->both = !w->both;

  // Head: yaw and pitch from right-drag, WASD in the yawed plane, Q/E down/up, R resets.
  if (r.reset > 0) {
    w->head_pos = w->home.position;
    w->yaw = w->pitch = 0;
    for (auto& h : w->hands) h.wheel = 0;
  }
  w->yaw -= static_cast<float>(r.look_dx) * kLookPerPixel;
  w->pitch = std::clamp(w->pitch - static_cast<float>(r.look_dy) * kLookPerPixel, -1.5f, 1.5f);
  const XrQuaternionf body = quat_mul(w->home.orientation, axis_angle({0, 1, 0}, w->yaw));
  const XrVector3f fwd = quat_rotate(body, {0, 0, -1}), right = quat_rotate(body, {1, 0, 0});
  XrVector3f move = add(mul(fwd, held(kW) - held(kS)), mul(right, held(kD) - held(kA)));
  move.y += held(kE) - held(kQ);
  w->head_pos = add(w->head_pos, mul(move, kMoveSpeed));
  const XrPosef head{quat_normalize(quat_mul(body, axis_angle({1, 0, 0}, w->pitch))), w->head_pos};

  // The hand under the mouse (left with Shift): pinch on the left button, fist on F, on the ray
  // under the cursor at the depth the app submitted there (else kDefaultDistance), the wheel
  // nearer/farther. The other hand keeps its place, pinch and fist.
  const int act = on(kLeftShift) || on(kRightShift) ? 0 : 1;
  Window::Hand& hd = w->hands[act];
  const bool was_pinching = hd.pinch > 0.5f;
  hd.pinch = r.lmb || r.lmb_presses > 0 ? 1.f : 0.f;
  hd.fist = on(kF) ? 1.f : 0.f;
  take_gesture_keys(hd, w->hands[1 - act], on, held(kT));
  hd.wheel += static_cast<float>(r.wheel) * kWheelStep;
  int eye = 0;
  float u = 0, v = 0;
  const bool over = w->cursor_in_view(r, &eye, &u, &v);
  w->hit_hand = false;
  if (over) {
    const XrPosef eye_pose =
        pose_mul(head, XrPosef{{0, 0, 0, 1}, {eye == 0 ? -kIpd / 2 : kIpd / 2, 0, 0}});
    const float t = std::tan(kHalfFov);
    const XrVector3f dir{-t + 2 * t * u, t - 2 * t * v, -1};
    const bool pinching = hd.pinch > 0.5f;
    if (!pinching && !was_pinching) {  // a held pinch keeps its depth
      if (w->hit_valid && w->hit_eye == eye) {
        XrVector3f hit = pose_mul(eye_pose, XrPosef{{0, 0, 0, 1}, mul(dir, w->hit_z)}).position;
        w->hit_hand = w->on_a_hand(hit);
        if (!w->hit_hand) hd.z = w->hit_z;
      } else if (!w->depth_seen) {
        hd.z = kDefaultDistance;
      }
    }
    const float z = std::max(kMinDistance, hd.z + hd.wheel);
    hd.pos = pose_mul(eye_pose, XrPosef{{0, 0, 0, 1}, mul(dir, z)}).position;
    hd.ray = quat_rotate(eye_pose.orientation, mul(dir, 1.f / len(dir)));
  }

  // Into the scenario tracks: one key each (the head with frame 0 at home: LOCAL's origin).
  Scenario& sc = inst->scenario;
  const bool pad_only = path_string(inst, s->profile[0]).find("htc/vive") != std::string::npos;
  sc.head = {PoseKey{0, w->home}, PoseKey{1e-3, head}};
  if (frame == 0) sc.head.resize(1);
  for (int h = 0; h < 2; ++h) {
    Window::Hand& k = w->hands[h];
    HandKey hk;
    hk.tracked = true;
    hk.pinch = k.pinch;
    hk.fist = k.fist;
    // The palm faces down, fingers forward (the body's yaw); the pinch point sits on k.pos.
    std::array<XrPosef, kHandJointCount> j;
    std::array<float, kHandJointCount> rad;
    hk.shape = k.shape;
    generate_hand(h, pose_identity(), k.pinch, &j, &rad, k.fist);
    XrVector3f mid =
        mul(add(j[XR_HAND_JOINT_THUMB_TIP_EXT].position, j[XR_HAND_JOINT_INDEX_TIP_EXT].position),
            0.5f);
    hk.palm = palm_pose(k, body, mid);
    sc.hands[h] = {hk};
    k.published = sc.hand(h, 0);
    ControllerKey ck;
    ck.tracked = controllers;
    XrQuaternionf aim = rotation_between({0, 0, -1}, k.ray);
    ck.aim = XrPosef{aim, k.pos};
    ck.grip = XrPosef{aim, k.pos};
    ck.inputs["trigger/value"] = {k.pinch, 0};
    ck.inputs["trigger/touch"] = {k.pinch, 0};
    ck.inputs["select/click"] = {k.pinch, 0};
    ck.inputs["squeeze/value"] = {k.fist, 0};
    ck.inputs["menu/click"] = {menu ? 1.f : 0.f, 0};
    if (h == 1) {
      ck.inputs["a/click"] = {on(k1) ? 1.f : 0.f, 0};
      ck.inputs["b/click"] = {on(k2) ? 1.f : 0.f, 0};
    } else {
      ck.inputs["x/click"] = {on(k3) ? 1.f : 0.f, 0};
      ck.inputs["y/click"] = {on(k4) ? 1.f : 0.f, 0};
    }
    stick_inputs(k, h, pad_only, ck);
    sc.controllers[h] = {ck};
  }

  std::string profile = path_string(inst, s->profile[0]);
  if (profile.empty()) profile = "hand_tracking";
  std::string title =
      "drape mock runtime | " + profile.substr(profile.rfind('/') + 1) + " | " +
      (act ? "right" : "left") + " hand" + (hd.pinch > 0.5f ? " pinch" : "") +
      (hd.fist > 0.5f ? " fist" : "") +
      (hd.shape != kShapeOpen || hd.palm_up || hd.push >= 0 ? std::string(" ") + gesture_name(hd)
                                                            : std::string()) +
      " | WASD/QE move, right-drag look, R reset, LMB pinch, F fist, Z/X/C/G/U/T "
      "gestures, arrows/Enter stick, wheel depth, Shift left hand, Tab profile, "
      "F5 menu held 1.1 s (save), V eyes, Esc quit";
  if (title != w->shown_title) {
    w->shown_title = title;
    std::lock_guard<std::mutex> g(w->mu);
    w->title = title;
    w->title_dirty = true;
  }
  if (w->log_file) {
    const XrVector3f& L = w->hands[0].pos;
    const XrVector3f& R = w->hands[1].pos;
    char depth[48] = "-";
    if (w->hit_valid)
      std::snprintf(depth, sizeof(depth), "%.4f%s", w->hit_z, w->hit_hand ? "(hand)" : "");
    std::fprintf(w->log_file,
                 "frame=%lld head=%.4f,%.4f,%.4f yaw=%.4f pitch=%.4f active=%s "
                 "left=%.4f,%.4f,%.4f right=%.4f,%.4f,%.4f pinch=%d,%d fist=%d,%d "
                 "wheel=%.3f,%.3f z=%.4f buttons=%d%d%d%d%d cursor=%s eye=%d depth=%s view=%s "
                 "profile=%s gesture=%s,%s stick=%.0f,%.0f,%d\n",
                 static_cast<long long>(frame), head.position.x, head.position.y, head.position.z,
                 w->yaw, w->pitch, act ? "right" : "left", L.x, L.y, L.z, R.x, R.y, R.z,
                 w->hands[0].pinch > 0.5f, w->hands[1].pinch > 0.5f, w->hands[0].fist > 0.5f,
                 w->hands[1].fist > 0.5f, w->hands[0].wheel, w->hands[1].wheel, hd.z, on(k1),
                 on(k2), on(k3), on(k4), menu, over ? "in" : "out", eye, depth,
                 w->both ? "both" : "left", profile.c_str(), gesture_name(w->hands[0]),
                 gesture_name(w->hands[1]), hd.stick.x, hd.stick.y, hd.stick_click ? 1 : 0);
    std::fflush(w->log_file);
  }
}

void window_end_frame(Session* s, const XrCompositionLayerProjection* layer) {
  Window* w = s->window.get();
  Instance* inst = instance_of(s);
  RawInput r;
  bool want_pixels = false;
  {
    std::lock_guard<std::mutex> g(w->mu);
    r = w->raw;
    want_pixels = !w->fresh;
  }
  if (want_pixels) {  // the window thread has taken the last image
    std::vector<unsigned char> left, right;
    const XrRect2Di& lr = layer->views[0].subImage.imageRect;
    const XrRect2Di& rr = layer->views[1].subImage.imageRect;
    if (read_color(s, layer->views[0].subImage, &left)) {
      int wl = lr.extent.width, h = lr.extent.height;
      w->eye_w = wl;
      w->eye_h = h;
      std::vector<unsigned char> out;
      int ow = wl;
      if (w->both && rr.extent.height == h && read_color(s, layer->views[1].subImage, &right)) {
        int wr = rr.extent.width;
        ow = wl + wr;
        out.resize(static_cast<size_t>(ow) * h * 4);
        for (int y = 0; y < h; ++y) {
          std::memcpy(&out[static_cast<size_t>(y) * ow * 4], &left[static_cast<size_t>(y) * wl * 4],
                      static_cast<size_t>(wl) * 4);
          std::memcpy(&out[(static_cast<size_t>(y) * ow + wl) * 4],
                      &right[static_cast<size_t>(y) * wr * 4], static_cast<size_t>(wr) * 4);
        }
      } else {
        out.swap(left);
      }
      std::lock_guard<std::mutex> g(w->mu);
      w->pixels.swap(out);
      w->pw = ow;
      w->ph = h;
      w->fresh = true;
    }
  }
  // The depth under the cursor (XR_KHR_composition_layer_depth).
  w->hit_valid = false;
  int eye = 0;
  float u = 0, v = 0;
  if (!w->cursor_in_view(r, &eye, &u, &v)) return;
  const XrCompositionLayerDepthInfoKHR* d = depth_info(inst, layer->views[eye]);
  if (!d) return;
  w->depth_seen = true;
  int x = static_cast<int>(u * static_cast<float>(d->subImage.imageRect.extent.width));
  int y = static_cast<int>(v * static_cast<float>(d->subImage.imageRect.extent.height));
  float dv = 0;
  if (!read_depth_texel(s, d->subImage, x, y, &dv)) return;
  float z = depth_to_distance(dv, d->minDepth, d->maxDepth, d->nearZ, d->farZ);
  if (!std::isfinite(z)) return;
  w->hit_valid = true;
  // In steps of kDepthStep: renderers differ in the depth's last bits (a CPU rasterizer's code is
  // made for the CPU it runs on), which must not move the hand, and with it a session played
  // from input events, from one machine to another.
  w->hit_z = std::round(z / kDepthStep) * kDepthStep;
  w->hit_eye = eye;
}

}  // namespace drape::mock
