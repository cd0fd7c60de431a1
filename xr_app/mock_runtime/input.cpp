// The mock runtime's input: action sets, actions, suggested bindings for the common
// interaction profiles, xrSyncActions and action states, action spaces, haptics, and
// XR_EXT_hand_tracking (26 joints from the scenario).
#include <algorithm>
#include <cmath>
#include <cstring>

#include "xr_app/mock_runtime/runtime.hpp"

namespace drape::mock {
namespace {

#define DRAPE_LOCK std::lock_guard<std::recursive_mutex> guard_(g_lock)

const char* const kHandPaths[2] = {"/user/hand/left", "/user/hand/right"};

struct Profile {
  const char* path;
  std::vector<std::string> both;
  std::vector<std::string> left_only;
  std::vector<std::string> right_only;
};

const std::vector<Profile>& profiles() {
  static const std::vector<Profile> p = {
      {"/interaction_profiles/khr/simple_controller",
       {"input/select/click", "input/menu/click", "input/grip/pose", "input/aim/pose",
        "output/haptic"},
       {},
       {}},
      {"/interaction_profiles/oculus/touch_controller",
       {"input/squeeze/value", "input/trigger/value", "input/trigger/touch", "input/thumbstick/x",
        "input/thumbstick/y", "input/thumbstick/click", "input/thumbstick/touch",
        "input/thumbrest/touch", "input/grip/pose", "input/aim/pose", "output/haptic"},
       {"input/x/click", "input/x/touch", "input/y/click", "input/y/touch", "input/menu/click"},
       {"input/a/click", "input/a/touch", "input/b/click", "input/b/touch", "input/system/click"}},
      {"/interaction_profiles/valve/index_controller",
       {"input/system/click",   "input/system/touch",     "input/a/click",
        "input/a/touch",        "input/b/click",          "input/b/touch",
        "input/squeeze/value",  "input/squeeze/force",    "input/trigger/click",
        "input/trigger/value",  "input/trigger/touch",    "input/thumbstick/x",
        "input/thumbstick/y",   "input/thumbstick/click", "input/thumbstick/touch",
        "input/trackpad/x",     "input/trackpad/y",       "input/trackpad/force",
        "input/trackpad/touch", "input/grip/pose",        "input/aim/pose",
        "output/haptic"},
       {},
       {}},
      {"/interaction_profiles/htc/vive_controller",
       {"input/system/click", "input/squeeze/click", "input/menu/click", "input/trigger/click",
        "input/trigger/value", "input/trackpad/x", "input/trackpad/y", "input/trackpad/click",
        "input/trackpad/touch", "input/grip/pose", "input/aim/pose", "output/haptic"},
       {},
       {}},
      {"/interaction_profiles/microsoft/motion_controller",
       {"input/menu/click", "input/squeeze/click", "input/trigger/value", "input/thumbstick/x",
        "input/thumbstick/y", "input/thumbstick/click", "input/trackpad/x", "input/trackpad/y",
        "input/trackpad/click", "input/trackpad/touch", "input/grip/pose", "input/aim/pose",
        "output/haptic"},
       {},
       {}},
  };
  return p;
}

const Profile* find_profile(const std::string& path) {
  for (const auto& p : profiles())
    if (path == p.path) return &p;
  return nullptr;
}

// "input/trigger" and "input/thumbstick" (parent identifiers) are accepted as well.
bool profile_has(const Profile& p, int hand, const std::string& component) {
  auto match = [&](const std::vector<std::string>& list) {
    for (const auto& c : list) {
      if (c == component) return true;
      if (c.size() > component.size() && c.compare(0, component.size(), component) == 0 &&
          c[component.size()] == '/')
        return true;
    }
    return false;
  };
  return match(p.both) || match(hand == 0 ? p.left_only : p.right_only);
}

// Splits "/user/hand/left/input/trigger/value" -> hand 0, "input/trigger/value".
bool split_binding(const std::string& path, int* hand, std::string* component) {
  for (int h = 0; h < 2; ++h) {
    std::string prefix = std::string(kHandPaths[h]) + "/";
    if (path.compare(0, prefix.size(), prefix) == 0) {
      *hand = h;
      *component = path.substr(prefix.size());
      return true;
    }
  }
  return false;
}

bool valid_name(const char* n, size_t max) {
  size_t len = strnlen(n, max);
  if (len == 0 || len >= max) return false;
  for (size_t i = 0; i < len; ++i) {
    char c = n[i];
    if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-' || c == '_' || c == '.'))
      return false;
  }
  return true;
}

int hand_of_path(Instance* inst, XrPath p) {
  std::string s = path_string(inst, p);
  for (int h = 0; h < 2; ++h)
    if (s == kHandPaths[h]) return h;
  return -1;
}

bool is_top_level_user_path(const std::string& s) {
  return s == "/user/hand/left" || s == "/user/hand/right" || s == "/user/head" ||
         s == "/user/gamepad" || s == "/user/treadmill";
}

// ------------------------------------------------------------------ action sets / actions
XrResult XRAPI_CALL CreateActionSet(XrInstance h, const XrActionSetCreateInfo* info,
                                    XrActionSet* out) {
  DRAPE_LOCK;
  Instance* inst = lookup<Instance>(h);
  if (!inst) return XR_ERROR_HANDLE_INVALID;
  if (!info || !out || info->type != XR_TYPE_ACTION_SET_CREATE_INFO)
    return XR_ERROR_VALIDATION_FAILURE;
  if (!valid_name(info->actionSetName, XR_MAX_ACTION_SET_NAME_SIZE))
    return XR_ERROR_PATH_FORMAT_INVALID;
  if (strnlen(info->localizedActionSetName, XR_MAX_LOCALIZED_ACTION_SET_NAME_SIZE) == 0)
    return XR_ERROR_LOCALIZED_NAME_INVALID;
  // Duplicate checks over the instance's sets.
  bool dup = false, dup_loc = false;
  for_each_child(inst->handle, Kind::ActionSet, [&](Object* o) {
    auto* s = static_cast<ActionSet*>(o);
    dup = dup || s->name == info->actionSetName;
    dup_loc = dup_loc || s->localized == info->localizedActionSetName;
  });
  if (dup) return XR_ERROR_NAME_DUPLICATED;
  if (dup_loc) return XR_ERROR_LOCALIZED_NAME_DUPLICATED;
  auto s = std::make_unique<ActionSet>();
  s->name = info->actionSetName;
  s->localized = info->localizedActionSetName;
  s->priority = info->priority;
  *out = to_handle<XrActionSet>(register_object(std::move(s), inst->handle));
  return XR_SUCCESS;
}

XrResult XRAPI_CALL DestroyActionSet(XrActionSet h) {
  DRAPE_LOCK;
  if (!lookup<ActionSet>(h)) return XR_ERROR_HANDLE_INVALID;
  destroy_object(from_handle(h));
  return XR_SUCCESS;
}

XrResult XRAPI_CALL CreateAction(XrActionSet h, const XrActionCreateInfo* info, XrAction* out) {
  DRAPE_LOCK;
  ActionSet* set = lookup<ActionSet>(h);
  if (!set) return XR_ERROR_HANDLE_INVALID;
  if (!info || !out || info->type != XR_TYPE_ACTION_CREATE_INFO) return XR_ERROR_VALIDATION_FAILURE;
  if (set->attached) return XR_ERROR_ACTIONSETS_ALREADY_ATTACHED;
  if (!valid_name(info->actionName, XR_MAX_ACTION_NAME_SIZE)) return XR_ERROR_PATH_FORMAT_INVALID;
  if (strnlen(info->localizedActionName, XR_MAX_LOCALIZED_ACTION_NAME_SIZE) == 0)
    return XR_ERROR_LOCALIZED_NAME_INVALID;
  switch (info->actionType) {
    case XR_ACTION_TYPE_BOOLEAN_INPUT:
    case XR_ACTION_TYPE_FLOAT_INPUT:
    case XR_ACTION_TYPE_VECTOR2F_INPUT:
    case XR_ACTION_TYPE_POSE_INPUT:
    case XR_ACTION_TYPE_VIBRATION_OUTPUT:
      break;
    default:
      return XR_ERROR_VALIDATION_FAILURE;
  }
  if (info->countSubactionPaths > 0 && !info->subactionPaths) return XR_ERROR_VALIDATION_FAILURE;
  Instance* inst = instance_of(set);
  std::vector<XrPath> subs;
  for (uint32_t i = 0; i < info->countSubactionPaths; ++i) {
    XrPath p = info->subactionPaths[i];
    if (p == XR_NULL_PATH || p >= inst->paths.size()) return XR_ERROR_PATH_INVALID;
    if (!is_top_level_user_path(inst->paths[p])) return XR_ERROR_PATH_UNSUPPORTED;
    if (std::find(subs.begin(), subs.end(), p) != subs.end()) return XR_ERROR_PATH_UNSUPPORTED;
    subs.push_back(p);
  }
  bool dup = false, dup_loc = false;
  for_each_child(set->handle, Kind::Action, [&](Object* o) {
    auto* a = static_cast<Action*>(o);
    dup = dup || a->name == info->actionName;
    dup_loc = dup_loc || a->localized == info->localizedActionName;
  });
  if (dup) return XR_ERROR_NAME_DUPLICATED;
  if (dup_loc) return XR_ERROR_LOCALIZED_NAME_DUPLICATED;
  auto a = std::make_unique<Action>();
  a->name = info->actionName;
  a->localized = info->localizedActionName;
  a->type = info->actionType;
  a->subaction_paths = subs;
  a->action_set = set->handle;
  *out = to_handle<XrAction>(register_object(std::move(a), set->handle));
  return XR_SUCCESS;
}

XrResult XRAPI_CALL DestroyAction(XrAction h) {
  DRAPE_LOCK;
  if (!lookup<Action>(h)) return XR_ERROR_HANDLE_INVALID;
  destroy_object(from_handle(h));
  return XR_SUCCESS;
}

XrResult XRAPI_CALL
SuggestInteractionProfileBindings(XrInstance h, const XrInteractionProfileSuggestedBinding* sb) {
  DRAPE_LOCK;
  Instance* inst = lookup<Instance>(h);
  if (!inst) return XR_ERROR_HANDLE_INVALID;
  if (!sb || sb->type != XR_TYPE_INTERACTION_PROFILE_SUGGESTED_BINDING)
    return XR_ERROR_VALIDATION_FAILURE;
  if (sb->countSuggestedBindings == 0 || !sb->suggestedBindings) return XR_ERROR_VALIDATION_FAILURE;
  if (sb->interactionProfile == XR_NULL_PATH || sb->interactionProfile >= inst->paths.size())
    return XR_ERROR_PATH_INVALID;
  const Profile* prof = find_profile(inst->paths[sb->interactionProfile]);
  if (!prof) return XR_ERROR_PATH_UNSUPPORTED;
  std::vector<std::pair<Action*, XrPath>> binds;
  for (uint32_t i = 0; i < sb->countSuggestedBindings; ++i) {
    const XrActionSuggestedBinding& b = sb->suggestedBindings[i];
    Action* a = lookup<Action>(b.action);
    if (!a || instance_of(a) != inst) return XR_ERROR_HANDLE_INVALID;
    ActionSet* set = lookup<ActionSet>(a->action_set);
    if (set && set->attached) return XR_ERROR_ACTIONSETS_ALREADY_ATTACHED;
    if (b.binding == XR_NULL_PATH || b.binding >= inst->paths.size()) return XR_ERROR_PATH_INVALID;
    int hand;
    std::string comp;
    if (!split_binding(inst->paths[b.binding], &hand, &comp) || !profile_has(*prof, hand, comp))
      return XR_ERROR_PATH_UNSUPPORTED;
    binds.emplace_back(a, b.binding);
  }
  // A new suggestion for a profile replaces the previous one.
  for (Action* a : [&] {
         std::vector<Action*> all;
         for_each_of_kind(Kind::Action, [&](Object* o) {
           if (instance_of(o) == inst) all.push_back(static_cast<Action*>(o));
         });
         return all;
       }())
    a->suggested.erase(sb->interactionProfile);
  for (auto& [a, p] : binds) a->suggested[sb->interactionProfile].push_back(p);
  inst->suggested_any = true;
  return XR_SUCCESS;
}

XrResult XRAPI_CALL AttachSessionActionSets(XrSession h,
                                            const XrSessionActionSetsAttachInfo* info) {
  DRAPE_LOCK;
  Session* s = lookup<Session>(h);
  if (!s) return XR_ERROR_HANDLE_INVALID;
  if (s->lost) return XR_ERROR_SESSION_LOST;
  if (!info || info->type != XR_TYPE_SESSION_ACTION_SETS_ATTACH_INFO ||
      info->countActionSets == 0 || !info->actionSets)
    return XR_ERROR_VALIDATION_FAILURE;
  if (!s->attached_sets.empty()) return XR_ERROR_ACTIONSETS_ALREADY_ATTACHED;
  Instance* inst = instance_of(s);
  std::vector<ActionSet*> sets;
  for (uint32_t i = 0; i < info->countActionSets; ++i) {
    ActionSet* set = lookup<ActionSet>(info->actionSets[i]);
    if (!set || instance_of(set) != inst) return XR_ERROR_HANDLE_INVALID;
    sets.push_back(set);
  }
  for (ActionSet* set : sets) {
    set->attached = true;
    s->attached_sets.push_back(set->handle);
  }
  // Pick the interaction profile: the scenario's, else the first suggested one in the
  // order of the profile table.
  std::set<XrPath> suggested;
  for_each_of_kind(Kind::Action, [&](Object* o) {
    auto* a = static_cast<Action*>(o);
    if (std::find(s->attached_sets.begin(), s->attached_sets.end(), a->action_set) ==
        s->attached_sets.end())
      return;
    for (auto& [p, b] : a->suggested) suggested.insert(p);
  });
  XrPath chosen = XR_NULL_PATH;
  if (!inst->scenario.interaction_profile.empty()) {
    XrPath want = intern_path(inst, inst->scenario.interaction_profile);
    if (suggested.count(want)) chosen = want;
  }
  if (chosen == XR_NULL_PATH) {
    for (const auto& p : profiles()) {
      XrPath pp = intern_path(inst, p.path);
      if (suggested.count(pp)) {
        chosen = pp;
        break;
      }
    }
  }
  s->profile[0] = s->profile[1] = chosen;
  return XR_SUCCESS;
}

XrResult XRAPI_CALL GetCurrentInteractionProfile(XrSession h, XrPath top,
                                                 XrInteractionProfileState* state) {
  DRAPE_LOCK;
  Session* s = lookup<Session>(h);
  if (!s) return XR_ERROR_HANDLE_INVALID;
  if (s->lost) return XR_ERROR_SESSION_LOST;
  if (!state || state->type != XR_TYPE_INTERACTION_PROFILE_STATE)
    return XR_ERROR_VALIDATION_FAILURE;
  Instance* inst = instance_of(s);
  if (top == XR_NULL_PATH || top >= inst->paths.size()) return XR_ERROR_PATH_INVALID;
  if (!is_top_level_user_path(inst->paths[top])) return XR_ERROR_PATH_UNSUPPORTED;
  if (s->attached_sets.empty()) return XR_ERROR_ACTIONSET_NOT_ATTACHED;
  int hand = hand_of_path(inst, top);
  state->interactionProfile = hand >= 0 ? s->profile[hand] : XR_NULL_PATH;
  return XR_SUCCESS;
}

// ------------------------------------------------------------------ state evaluation
bool attached_to(Session* s, Action* a) {
  return std::find(s->attached_sets.begin(), s->attached_sets.end(), a->action_set) !=
         s->attached_sets.end();
}

// Components of `a` bound for hand `h` under the session's profile.
std::vector<std::string> bound_components(Session* s, Action* a, int h) {
  std::vector<std::string> out;
  Instance* inst = instance_of(s);
  auto it = a->suggested.find(s->profile[h]);
  if (it == a->suggested.end()) return out;
  for (XrPath p : it->second) {
    int hand;
    std::string comp;
    if (split_binding(inst->paths[p], &hand, &comp) && hand == h) out.push_back(comp);
  }
  return out;
}

// Reads one component from the scenario's input map ("input/" stripped), with click/value
// fallbacks. Returns {x, y}.
std::array<float, 2> read_component(const std::map<std::string, std::array<float, 2>>& in,
                                    std::string comp, XrActionType type) {
  if (comp.compare(0, 6, "input/") == 0) comp = comp.substr(6);
  auto get = [&](const std::string& k, std::array<float, 2>* v) {
    auto it = in.find(k);
    if (it == in.end()) return false;
    *v = it->second;
    return true;
  };
  std::array<float, 2> v{0, 0};
  if (get(comp, &v)) return v;
  auto slash = comp.rfind('/');
  std::string base = slash == std::string::npos ? comp : comp.substr(0, slash);
  std::string leaf = slash == std::string::npos ? "" : comp.substr(slash + 1);
  if (leaf == "x" || leaf == "y") {
    if (get(base, &v)) return {leaf == "x" ? v[0] : v[1], 0};
    return {0, 0};
  }
  if (leaf == "click") {
    if (get(base + "/value", &v)) return {v[0] >= 0.5f ? 1.f : 0.f, 0};
    return {0, 0};
  }
  if (leaf == "value") {
    if (get(base + "/click", &v)) return v;
    return {0, 0};
  }
  if (leaf.empty()) {  // parent identifier: pick by action type
    if (type == XR_ACTION_TYPE_VECTOR2F_INPUT) {
      std::array<float, 2> x{0, 0}, y{0, 0};
      get(base + "/x", &x);
      get(base + "/y", &y);
      return {x[0], y[0]};
    }
    if (get(base + "/value", &v)) return v;
    if (get(base + "/click", &v)) return v;
  }
  return {0, 0};
}

int64_t sample_frame(Session* s) {
  return std::max<int64_t>(0, s->frames_waited - 1);
}

void evaluate(Session* s, Action* a, bool focused) {
  Instance* inst = instance_of(s);
  XrTime t = s->epoch + sample_frame(s) * kFramePeriodNs;
  ActionStateSlot combined;
  bool any_bound = false;
  float best = -1;
  for (int h = 0; h < 2; ++h) {
    XrPath hp = intern_path(inst, kHandPaths[h]);
    ActionStateSlot& slot = a->state[hp];
    float old0 = slot.value[0], old1 = slot.value[1];
    bool was_active = slot.active;
    auto comps = bound_components(s, a, h);
    XrPosef grip, aim;
    std::map<std::string, std::array<float, 2>> in;
    bool tracked =
        inst->scenario.controller(h, static_cast<double>(sample_frame(s)), &grip, &aim, &in);
    slot.active = focused && !comps.empty() && tracked;
    float v0 = 0, v1 = 0;
    for (const auto& c : comps) {
      auto v = read_component(in, c, a->type);
      if (a->type == XR_ACTION_TYPE_BOOLEAN_INPUT) {
        v0 = std::max(v0, v[0] >= 0.5f ? 1.f : 0.f);
      } else if (a->type == XR_ACTION_TYPE_VECTOR2F_INPUT) {
        if (v[0] * v[0] + v[1] * v[1] > v0 * v0 + v1 * v1) v0 = v[0], v1 = v[1];
      } else {
        if (std::abs(v[0]) > std::abs(v0)) v0 = v[0];
      }
    }
    if (!slot.active) v0 = v1 = 0;
    slot.value[0] = v0;
    slot.value[1] = v1;
    slot.changed = slot.active && was_active && (old0 != v0 || old1 != v1);
    if (slot.changed || (slot.active && !was_active)) slot.last_change = t;
    if (slot.active) {
      any_bound = true;
      float mag = a->type == XR_ACTION_TYPE_VECTOR2F_INPUT ? v0 * v0 + v1 * v1 : std::abs(v0);
      if (mag > best) {
        best = mag;
        combined.value[0] = v0;
        combined.value[1] = v1;
      }
      combined.changed = combined.changed || slot.changed;
      combined.last_change = std::max(combined.last_change, slot.last_change);
    }
  }
  combined.active = any_bound;
  a->state[XR_NULL_PATH] = combined;
}

XrResult XRAPI_CALL SyncActions(XrSession h, const XrActionsSyncInfo* info) {
  DRAPE_LOCK;
  Session* s = lookup<Session>(h);
  if (!s) return XR_ERROR_HANDLE_INVALID;
  if (s->lost) return XR_ERROR_SESSION_LOST;
  if (!info || info->type != XR_TYPE_ACTIONS_SYNC_INFO) return XR_ERROR_VALIDATION_FAILURE;
  if (info->countActiveActionSets > 0 && !info->activeActionSets)
    return XR_ERROR_VALIDATION_FAILURE;
  Instance* inst = instance_of(s);
  std::set<uint64_t> active;
  for (uint32_t i = 0; i < info->countActiveActionSets; ++i) {
    const XrActiveActionSet& as = info->activeActionSets[i];
    ActionSet* set = lookup<ActionSet>(as.actionSet);
    if (!set) return XR_ERROR_HANDLE_INVALID;
    if (std::find(s->attached_sets.begin(), s->attached_sets.end(), set->handle) ==
        s->attached_sets.end())
      return XR_ERROR_ACTIONSET_NOT_ATTACHED;
    if (as.subactionPath != XR_NULL_PATH) {
      if (as.subactionPath >= inst->paths.size()) return XR_ERROR_PATH_INVALID;
      if (!is_top_level_user_path(inst->paths[as.subactionPath])) return XR_ERROR_PATH_UNSUPPORTED;
    }
    active.insert(set->handle);
  }
  bool focused = s->state == XR_SESSION_STATE_FOCUSED;
  if (!s->profile_event_sent && !s->attached_sets.empty()) {
    s->profile_event_sent = true;
    XrEventDataInteractionProfileChanged ev{XR_TYPE_EVENT_DATA_INTERACTION_PROFILE_CHANGED};
    ev.session = h;
    push_event(inst, &ev, sizeof(ev));
  }
  for_each_of_kind(Kind::Action, [&](Object* o) {
    auto* a = static_cast<Action*>(o);
    if (!attached_to(s, a)) return;
    evaluate(s, a, focused && active.count(a->action_set) > 0);
  });
  return focused ? XR_SUCCESS : XR_SESSION_NOT_FOCUSED;
}

XrResult get_action_for_state(XrSession h, const XrActionStateGetInfo* info, XrActionType type,
                              Session** out_s, Action** out_a) {
  Session* s = lookup<Session>(h);
  if (!s) return XR_ERROR_HANDLE_INVALID;
  if (s->lost) return XR_ERROR_SESSION_LOST;
  if (!info || info->type != XR_TYPE_ACTION_STATE_GET_INFO) return XR_ERROR_VALIDATION_FAILURE;
  Action* a = lookup<Action>(info->action);
  if (!a) return XR_ERROR_HANDLE_INVALID;
  if (!attached_to(s, a)) return XR_ERROR_ACTIONSET_NOT_ATTACHED;
  if (a->type != type) return XR_ERROR_ACTION_TYPE_MISMATCH;
  if (info->subactionPath != XR_NULL_PATH) {
    Instance* inst = instance_of(s);
    if (info->subactionPath >= inst->paths.size()) return XR_ERROR_PATH_INVALID;
    if (std::find(a->subaction_paths.begin(), a->subaction_paths.end(), info->subactionPath) ==
        a->subaction_paths.end())
      return XR_ERROR_PATH_UNSUPPORTED;
  }
  *out_s = s;
  *out_a = a;
  return XR_SUCCESS;
}

ActionStateSlot slot_of(Action* a, XrPath sub) {
  auto it = a->state.find(sub);
  return it == a->state.end() ? ActionStateSlot{} : it->second;
}

XrResult XRAPI_CALL GetActionStateBoolean(XrSession h, const XrActionStateGetInfo* info,
                                          XrActionStateBoolean* st) {
  DRAPE_LOCK;
  Session* s;
  Action* a;
  if (!st || st->type != XR_TYPE_ACTION_STATE_BOOLEAN) return XR_ERROR_VALIDATION_FAILURE;
  if (XrResult r = get_action_for_state(h, info, XR_ACTION_TYPE_BOOLEAN_INPUT, &s, &a);
      r != XR_SUCCESS)
    return r;
  ActionStateSlot sl = slot_of(a, info->subactionPath);
  st->currentState = sl.value[0] >= 0.5f ? XR_TRUE : XR_FALSE;
  st->changedSinceLastSync = sl.changed ? XR_TRUE : XR_FALSE;
  st->lastChangeTime = sl.last_change;
  st->isActive = sl.active ? XR_TRUE : XR_FALSE;
  return XR_SUCCESS;
}

XrResult XRAPI_CALL GetActionStateFloat(XrSession h, const XrActionStateGetInfo* info,
                                        XrActionStateFloat* st) {
  DRAPE_LOCK;
  Session* s;
  Action* a;
  if (!st || st->type != XR_TYPE_ACTION_STATE_FLOAT) return XR_ERROR_VALIDATION_FAILURE;
  if (XrResult r = get_action_for_state(h, info, XR_ACTION_TYPE_FLOAT_INPUT, &s, &a);
      r != XR_SUCCESS)
    return r;
  ActionStateSlot sl = slot_of(a, info->subactionPath);
  st->currentState = sl.value[0];
  st->changedSinceLastSync = sl.changed ? XR_TRUE : XR_FALSE;
  st->lastChangeTime = sl.last_change;
  st->isActive = sl.active ? XR_TRUE : XR_FALSE;
  return XR_SUCCESS;
}

XrResult XRAPI_CALL GetActionStateVector2f(XrSession h, const XrActionStateGetInfo* info,
                                           XrActionStateVector2f* st) {
  DRAPE_LOCK;
  Session* s;
  Action* a;
  if (!st || st->type != XR_TYPE_ACTION_STATE_VECTOR2F) return XR_ERROR_VALIDATION_FAILURE;
  if (XrResult r = get_action_for_state(h, info, XR_ACTION_TYPE_VECTOR2F_INPUT, &s, &a);
      r != XR_SUCCESS)
    return r;
  ActionStateSlot sl = slot_of(a, info->subactionPath);
  st->currentState = {sl.value[0], sl.value[1]};
  st->changedSinceLastSync = sl.changed ? XR_TRUE : XR_FALSE;
  st->lastChangeTime = sl.last_change;
  st->isActive = sl.active ? XR_TRUE : XR_FALSE;
  return XR_SUCCESS;
}

XrResult XRAPI_CALL GetActionStatePose(XrSession h, const XrActionStateGetInfo* info,
                                       XrActionStatePose* st) {
  DRAPE_LOCK;
  Session* s;
  Action* a;
  if (!st || st->type != XR_TYPE_ACTION_STATE_POSE) return XR_ERROR_VALIDATION_FAILURE;
  if (XrResult r = get_action_for_state(h, info, XR_ACTION_TYPE_POSE_INPUT, &s, &a);
      r != XR_SUCCESS)
    return r;
  st->isActive = slot_of(a, info->subactionPath).active ? XR_TRUE : XR_FALSE;
  return XR_SUCCESS;
}

XrResult XRAPI_CALL EnumerateBoundSourcesForAction(XrSession h,
                                                   const XrBoundSourcesForActionEnumerateInfo* info,
                                                   uint32_t cap, uint32_t* count, XrPath* out) {
  DRAPE_LOCK;
  Session* s = lookup<Session>(h);
  if (!s) return XR_ERROR_HANDLE_INVALID;
  if (!info || info->type != XR_TYPE_BOUND_SOURCES_FOR_ACTION_ENUMERATE_INFO)
    return XR_ERROR_VALIDATION_FAILURE;
  Action* a = lookup<Action>(info->action);
  if (!a) return XR_ERROR_HANDLE_INVALID;
  if (!attached_to(s, a)) return XR_ERROR_ACTIONSET_NOT_ATTACHED;
  Instance* inst = instance_of(s);
  std::vector<XrPath> src;
  for (int hnd = 0; hnd < 2; ++hnd)
    for (const auto& c : bound_components(s, a, hnd))
      src.push_back(intern_path(inst, std::string(kHandPaths[hnd]) + "/" + c));
  return two_call<XrPath>(cap, count, out, src);
}

XrResult XRAPI_CALL GetInputSourceLocalizedName(XrSession h,
                                                const XrInputSourceLocalizedNameGetInfo* info,
                                                uint32_t cap, uint32_t* count, char* buf) {
  DRAPE_LOCK;
  Session* s = lookup<Session>(h);
  if (!s) return XR_ERROR_HANDLE_INVALID;
  if (!info || info->type != XR_TYPE_INPUT_SOURCE_LOCALIZED_NAME_GET_INFO ||
      info->whichComponents == 0)
    return XR_ERROR_VALIDATION_FAILURE;
  Instance* inst = instance_of(s);
  if (info->sourcePath == XR_NULL_PATH || info->sourcePath >= inst->paths.size())
    return XR_ERROR_PATH_INVALID;
  if (s->attached_sets.empty()) return XR_ERROR_ACTIONSET_NOT_ATTACHED;
  int hand;
  std::string comp;
  if (!split_binding(inst->paths[info->sourcePath], &hand, &comp)) return XR_ERROR_PATH_UNSUPPORTED;
  std::string name;
  if (info->whichComponents & XR_INPUT_SOURCE_LOCALIZED_NAME_USER_PATH_BIT)
    name += hand == 0 ? "Left Hand" : "Right Hand";
  if (info->whichComponents & XR_INPUT_SOURCE_LOCALIZED_NAME_INTERACTION_PROFILE_BIT) {
    if (!name.empty()) name += " ";
    name += "Mock Controller";
  }
  if (info->whichComponents & XR_INPUT_SOURCE_LOCALIZED_NAME_COMPONENT_BIT) {
    if (!name.empty()) name += " ";
    name += comp;
  }
  return two_call_string(cap, count, buf, name);
}

XrResult haptic_common(XrSession h, const XrHapticActionInfo* info) {
  Session* s = lookup<Session>(h);
  if (!s) return XR_ERROR_HANDLE_INVALID;
  if (s->lost) return XR_ERROR_SESSION_LOST;
  if (!info || info->type != XR_TYPE_HAPTIC_ACTION_INFO) return XR_ERROR_VALIDATION_FAILURE;
  Action* a = lookup<Action>(info->action);
  if (!a) return XR_ERROR_HANDLE_INVALID;
  if (!attached_to(s, a)) return XR_ERROR_ACTIONSET_NOT_ATTACHED;
  if (a->type != XR_ACTION_TYPE_VIBRATION_OUTPUT) return XR_ERROR_ACTION_TYPE_MISMATCH;
  if (info->subactionPath != XR_NULL_PATH &&
      std::find(a->subaction_paths.begin(), a->subaction_paths.end(), info->subactionPath) ==
          a->subaction_paths.end())
    return XR_ERROR_PATH_UNSUPPORTED;
  return s->state == XR_SESSION_STATE_FOCUSED ? XR_SUCCESS : XR_SESSION_NOT_FOCUSED;
}

XrResult XRAPI_CALL ApplyHapticFeedback(XrSession h, const XrHapticActionInfo* info,
                                        const XrHapticBaseHeader* fb) {
  DRAPE_LOCK;
  if (!fb || fb->type != XR_TYPE_HAPTIC_VIBRATION) return XR_ERROR_VALIDATION_FAILURE;
  return haptic_common(h, info);
}

XrResult XRAPI_CALL StopHapticFeedback(XrSession h, const XrHapticActionInfo* info) {
  DRAPE_LOCK;
  return haptic_common(h, info);
}

XrResult XRAPI_CALL CreateActionSpace(XrSession h, const XrActionSpaceCreateInfo* info,
                                      XrSpace* out) {
  DRAPE_LOCK;
  Session* s = lookup<Session>(h);
  if (!s) return XR_ERROR_HANDLE_INVALID;
  if (s->lost) return XR_ERROR_SESSION_LOST;
  if (!info || !out || info->type != XR_TYPE_ACTION_SPACE_CREATE_INFO)
    return XR_ERROR_VALIDATION_FAILURE;
  Action* a = lookup<Action>(info->action);
  if (!a || instance_of(a) != instance_of(s)) return XR_ERROR_HANDLE_INVALID;
  if (a->type != XR_ACTION_TYPE_POSE_INPUT) return XR_ERROR_ACTION_TYPE_MISMATCH;
  if (info->subactionPath != XR_NULL_PATH &&
      std::find(a->subaction_paths.begin(), a->subaction_paths.end(), info->subactionPath) ==
          a->subaction_paths.end())
    return XR_ERROR_PATH_UNSUPPORTED;
  const XrQuaternionf& q = info->poseInActionSpace.orientation;
  if (std::abs(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w - 1.f) > 1e-3f)
    return XR_ERROR_POSE_INVALID;
  auto sp = std::make_unique<Space>();
  sp->space_kind = SpaceKind::Action;
  sp->action = a->handle;
  sp->subaction = info->subactionPath;
  sp->offset = info->poseInActionSpace;
  *out = to_handle<XrSpace>(register_object(std::move(sp), s->handle));
  return XR_SUCCESS;
}

// ------------------------------------------------------------------ hand tracking
XrResult XRAPI_CALL CreateHandTrackerEXT(XrSession h, const XrHandTrackerCreateInfoEXT* info,
                                         XrHandTrackerEXT* out) {
  DRAPE_LOCK;
  Session* s = lookup<Session>(h);
  if (!s) return XR_ERROR_HANDLE_INVALID;
  if (s->lost) return XR_ERROR_SESSION_LOST;
  if (!info || !out || info->type != XR_TYPE_HAND_TRACKER_CREATE_INFO_EXT)
    return XR_ERROR_VALIDATION_FAILURE;
  if (info->hand != XR_HAND_LEFT_EXT && info->hand != XR_HAND_RIGHT_EXT)
    return XR_ERROR_VALIDATION_FAILURE;
  if (info->handJointSet != XR_HAND_JOINT_SET_DEFAULT_EXT) return XR_ERROR_VALIDATION_FAILURE;
  auto t = std::make_unique<HandTracker>();
  t->hand = info->hand;
  *out = to_handle<XrHandTrackerEXT>(register_object(std::move(t), s->handle));
  return XR_SUCCESS;
}

XrResult XRAPI_CALL DestroyHandTrackerEXT(XrHandTrackerEXT h) {
  DRAPE_LOCK;
  if (!lookup<HandTracker>(h)) return XR_ERROR_HANDLE_INVALID;
  destroy_object(from_handle(h));
  return XR_SUCCESS;
}

XrResult XRAPI_CALL LocateHandJointsEXT(XrHandTrackerEXT h, const XrHandJointsLocateInfoEXT* info,
                                        XrHandJointLocationsEXT* loc) {
  DRAPE_LOCK;
  HandTracker* t = lookup<HandTracker>(h);
  if (!t) return XR_ERROR_HANDLE_INVALID;
  Session* s = lookup<Session>(t->parent);
  if (!s) return XR_ERROR_HANDLE_INVALID;
  if (s->lost) return XR_ERROR_SESSION_LOST;
  if (!info || info->type != XR_TYPE_HAND_JOINTS_LOCATE_INFO_EXT || !loc ||
      loc->type != XR_TYPE_HAND_JOINT_LOCATIONS_EXT)
    return XR_ERROR_VALIDATION_FAILURE;
  if (loc->jointCount != XR_HAND_JOINT_COUNT_EXT || !loc->jointLocations)
    return XR_ERROR_VALIDATION_FAILURE;
  if (info->time <= 0) return XR_ERROR_TIME_INVALID;
  Space* base = lookup<Space>(info->baseSpace);
  if (!base || base->parent != s->handle) return XR_ERROR_HANDLE_INVALID;
  XrHandJointVelocitiesEXT* vel = nullptr;
  for (auto* n = static_cast<XrBaseOutStructure*>(loc->next); n; n = n->next) {
    if (n->type == XR_TYPE_HAND_JOINT_VELOCITIES_EXT) {
      vel = reinterpret_cast<XrHandJointVelocitiesEXT*>(n);
      if (vel->jointCount != XR_HAND_JOINT_COUNT_EXT || !vel->jointVelocities)
        return XR_ERROR_VALIDATION_FAILURE;
    }
  }
  Instance* inst = instance_of(s);
  int hand = t->hand == XR_HAND_LEFT_EXT ? 0 : 1;
  HandSample hs = inst->scenario.hand(hand, frame_of_time(s, info->time));
  XrPosef pb;
  bool tb;
  bool base_ok = space_pose_in_stage(s, base, info->time, &pb, &tb);
  loc->isActive =
      (hs.tracked && base_ok && s->state == XR_SESSION_STATE_FOCUSED) ? XR_TRUE : XR_FALSE;
  XrPosef inv = base_ok ? pose_inverse(pb) : pose_identity();
  for (int j = 0; j < XR_HAND_JOINT_COUNT_EXT; ++j) {
    XrHandJointLocationEXT& jl = loc->jointLocations[j];
    if (loc->isActive) {
      jl.pose = pose_mul(inv, hs.joints[j]);
      jl.radius = hs.radii[j];
      jl.locationFlags =
          XR_SPACE_LOCATION_ORIENTATION_VALID_BIT | XR_SPACE_LOCATION_POSITION_VALID_BIT |
          XR_SPACE_LOCATION_ORIENTATION_TRACKED_BIT | XR_SPACE_LOCATION_POSITION_TRACKED_BIT;
    } else {
      jl.pose = pose_identity();
      jl.radius = 0;
      jl.locationFlags = 0;
    }
    if (vel) {
      vel->jointVelocities[j].velocityFlags =
          loc->isActive ? XR_SPACE_VELOCITY_LINEAR_VALID_BIT | XR_SPACE_VELOCITY_ANGULAR_VALID_BIT
                        : 0;
      vel->jointVelocities[j].linearVelocity = {0, 0, 0};
      vel->jointVelocities[j].angularVelocity = {0, 0, 0};
    }
  }
  return XR_SUCCESS;
}

}  // namespace

std::vector<XrPath> suggested_profiles(Session* s) {
  Instance* inst = instance_of(s);
  std::set<XrPath> suggested;
  for_each_of_kind(Kind::Action, [&](Object* o) {
    auto* a = static_cast<Action*>(o);
    if (!attached_to(s, a)) return;
    for (auto& [p, b] : a->suggested) suggested.insert(p);
  });
  std::vector<XrPath> out;
  for (const auto& p : profiles())
    if (XrPath pp = intern_path(inst, p.path); suggested.count(pp)) out.push_back(pp);
  return out;
}

bool action_pose(Session* s, Action* a, XrPath subaction, XrTime t, XrPosef* out, bool* tracked) {
  if (!attached_to(s, a)) return false;
  Instance* inst = instance_of(s);
  for (int h = 0; h < 2; ++h) {
    if (subaction != XR_NULL_PATH && hand_of_path(inst, subaction) != h) continue;
    for (const auto& c : bound_components(s, a, h)) {
      bool grip = c.compare(0, 10, "input/grip") == 0;
      bool aim = c.compare(0, 9, "input/aim") == 0;
      if (!grip && !aim) continue;
      XrPosef g, am;
      std::map<std::string, std::array<float, 2>> in;
      bool tr = inst->scenario.controller(h, frame_of_time(s, t), &g, &am, &in);
      if (!tr) return false;
      *out = grip ? g : am;
      *tracked = true;
      return true;
    }
  }
  return false;
}

#define DRAPE_ENTRY(fn) \
  if (name == "xr" #fn) return reinterpret_cast<void*>(&fn)
void* input_proc(const std::string& name) {
  DRAPE_ENTRY(CreateActionSet);
  DRAPE_ENTRY(DestroyActionSet);
  DRAPE_ENTRY(CreateAction);
  DRAPE_ENTRY(DestroyAction);
  DRAPE_ENTRY(SuggestInteractionProfileBindings);
  DRAPE_ENTRY(AttachSessionActionSets);
  DRAPE_ENTRY(GetCurrentInteractionProfile);
  DRAPE_ENTRY(SyncActions);
  DRAPE_ENTRY(GetActionStateBoolean);
  DRAPE_ENTRY(GetActionStateFloat);
  DRAPE_ENTRY(GetActionStateVector2f);
  DRAPE_ENTRY(GetActionStatePose);
  DRAPE_ENTRY(EnumerateBoundSourcesForAction);
  DRAPE_ENTRY(GetInputSourceLocalizedName);
  DRAPE_ENTRY(ApplyHapticFeedback);
  DRAPE_ENTRY(StopHapticFeedback);
  DRAPE_ENTRY(CreateActionSpace);
  DRAPE_ENTRY(CreateHandTrackerEXT);
  DRAPE_ENTRY(DestroyHandTrackerEXT);
  DRAPE_ENTRY(LocateHandJointsEXT);
  return nullptr;
}
#undef DRAPE_ENTRY

}  // namespace drape::mock
