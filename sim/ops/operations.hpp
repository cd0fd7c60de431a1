// The hand operations as commands applied between simulation steps:
// move, pinch, release, pin, cut, map, smooth. They act with hand proxies (pose, radius, id)
// only, never with devices. Bad input is ignored with a reason in World::messages.
// The OperationController (operation_controller.hpp) maps named triggers to these functions.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "sim/ops/cut.hpp"
#include "sim/runtime/world.hpp"

namespace drape::sim {

struct OperationParams {
  double pinch_reach = 0.05;     // m: a particle farther than max(this, hand radius) is not taken
  double release_reach = 0.30;   // m: the fixed particle to free must be this close
  double pin_reach = 0.15;       // m: the object point to pin at must be this close
  int pin_relax_ticks = 3;       // ticks the pinned particle stays on the object point (relax)
  double smooth_radius = 0.06;   // m around the hand where the cloth is pressed onto the form
  double smooth_pressure = 0.5;  // Pa: weak pressure toward the form (as geometric draping's)
  double ray_length = 0.40;      // m: candidate ray along the hand's pointing direction
  int max_candidates = 6;        // alternatives exposed per hand
  // s: how long an operation waits for its hand after tracking drops out (held meanwhile);
  // then it ends as if the user had ended it. Counted in ticks of the sim's dt.
  double tracking_grace = 0.3;
  CutOptions cut;
};

// A particle an operation could act on, for the renderer to highlight.
struct Candidate {
  int32_t vertex = -1;
  double distance = 0;    // from the hand (m)
  bool from_ray = false;  // found by the ray along the pointing direction (layer `layer`)
  int layer = 0;          // order of the ray hit (0 = first surface under the hand)
};

struct HandCandidates {
  std::vector<Candidate> particles;  // ordered; `particles[chosen]` is what pinch takes
  int chosen = 0;
  int32_t release_vertex = -1;  // fixed particle release would free (never a pinched one)
  bool has_object_point = false;
  Vec3 object_point{0, 0, 0};  // nearest object point (pin target)
  Vec3 object_normal{0, 1, 0};
  bool object_is_form = false;
  int32_t chosen_vertex() const {
    return chosen >= 0 && chosen < static_cast<int>(particles.size()) ? particles[chosen].vertex
                                                                      : -1;
  }
};

// A cut stroke kept beside the mesh cut: smooth, for display and for the pattern outline.
struct CutStroke {
  std::vector<Vec3> smooth;    // 3D at the time of the cut
  std::vector<Vec2> material;  // on the flat cloth (u, v)
};

struct SettlingPin {
  int32_t vertex = -1;
  Vec3 target{0, 0, 0}, normal{0, 1, 0};
  int ticks_left = 0;
};

// Everything the operations remember between ticks. `cut_strokes` is persistent (undone with the
// cloth); the rest describes operations in progress.
struct OperationsState {
  std::array<HandProxy, 2> hands{};
  std::array<bool, 2> hand_valid{false, false};
  std::array<int32_t, 2> pinched{-1, -1};
  std::array<bool, 2> cutting{false, false};
  std::array<std::vector<Vec3>, 2> stroke{};
  std::array<bool, 2> smoothing{false, false};
  bool moving = false;
  std::array<int32_t, 2> move_vertex{-1, -1};  // per hand
  // Corner − hand at grab time (move keeps it: the corner does not jump to the hand); taken
  // at move begin, or at the first tracked frame for a hand untracked then.
  std::array<Vec3, 2> move_offset{Vec3::Zero(), Vec3::Zero()};
  std::array<bool, 2> move_grabbed{false, false};
  std::vector<SettlingPin> settling;
  std::array<int, 2> selected{0, 0};
  std::array<HandCandidates, 2> candidates{};
  std::vector<CutStroke> cut_strokes;
  // Ticks a hand doing an operation has been untracked (0: tracked, or doing nothing); the
  // operation is held until this reaches the grace ticks (OperationParams::tracking_grace).
  std::array<int, 2> lost_ticks{0, 0};
  // The reports of operations ended by a lost hand, for the app to show and log (it takes them;
  // the newest 16 are kept).
  std::vector<std::string> loss_reports;
  // Last results (for tests and the status line).
  double last_pin_landing_error = -1;  // m, |final − (object point + offset·normal)|
  double last_pin_distance = -1;       // m, |final − object point|
  CutResult last_cut;
};

// Pointing direction of a hand: its orientation applied to −z (OpenXR's aim convention).
Vec3 hand_direction(const HandProxy& h);
bool hand_pose_finite(const HandProxy& h);

// Stores the hands (a non-finite pose is reported and the previous pose kept, marked invalid).
void ops_set_hands(World& w, OperationsState& s, const std::array<HandProxy, 2>& hands);
// Recomputes both hands' candidates from the current cloth and scene.
void ops_update_candidates(const World& w, OperationsState& s, const OperationParams& p);
// Nearest object point (form, plates, boxes, spheres) to q; false when the scene has none.
bool nearest_object_point(const SceneObjects& scene, const Vec3& q, Vec3& point, Vec3& normal,
                          bool& is_form);

// Each returns true when it changed something; otherwise a reason is in w.messages.
bool ops_pinch_begin(World& w, OperationsState& s, const OperationParams& p, int hand);
bool ops_pinch_end(World& w, OperationsState& s, int hand);
bool ops_release(World& w, OperationsState& s, const OperationParams& p, int hand);
bool ops_pin(World& w, OperationsState& s, const OperationParams& p, int hand);
bool ops_move_begin(World& w, OperationsState& s);
bool ops_move_end(World& w, OperationsState& s);
bool ops_cut_begin(World& w, OperationsState& s, int hand);
bool ops_cut_end(World& w, OperationsState& s, const OperationParams& p, int hand);
bool ops_cut_stroke(World& w, OperationsState& s, const OperationParams& p,
                    const std::vector<Vec3>& stroke);
bool ops_smooth_begin(World& w, OperationsState& s, int hand);
bool ops_smooth_end(World& w, OperationsState& s, int hand);
bool ops_map(World& w, OperationsState& s, int hand = -1);
// Ends every operation in progress (an unfinished cut stroke is discarded).
void ops_stop(World& w, OperationsState& s);

// Whether the hand is doing an operation: pinching, cutting, smoothing or holding a moved corner.
bool hand_busy(const OperationsState& s, int hand);
// The grace time in ticks of dt (at least 1).
int grace_ticks(const OperationParams& p, double dt);
// Per tick: counts the ticks each busy hand has been untracked; once they reach the grace, ends
// its operations as the user would (pinch let go, cut stroke cancelled, smoothing and move
// ended) with a report naming the hand. Called by ops_before_step.
void ops_track_loss(World& w, OperationsState& s, const OperationParams& p, double dt);
// Per tick, before the solver step: drive pinched and moved particles to the hands, record cut
// samples, press the cloth under smoothing hands.
void ops_before_step(World& w, OperationsState& s, const OperationParams& p, double dt);
// Per tick, after the step: settle pins (offset out of collision), refresh candidates.
void ops_after_step(World& w, OperationsState& s, const OperationParams& p, double dt);
// Adds candidates, cut strokes and pins to a snapshot.
void ops_decorate(const World& w, const OperationsState& s, SceneSnapshot& snap);

// Sets or clears flags and keeps inv_mass consistent with them.
void set_vertex_flags(Cloth& c, int32_t v, uint8_t set, uint8_t clear);

}  // namespace drape::sim
