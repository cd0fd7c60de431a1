// Session record and replay: the initial cloth state plus an event log (hand frames, triggers,
// strokes, candidate choices), each stamped with the simulation step it was applied at, so a
// lock-step replay reproduces the session bit for bit. Saved as JSON with base64 binary arrays
// (format in docs/operations.md); the loader validates every field and names it in errors.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "sim/core/cloth.hpp"
#include "sim/core/scene_objects.hpp"

namespace drape::sim {

enum class TriggerPhase : uint8_t { kBegin = 0, kEnd = 1, kToggle = 2 };

struct SessionEvent {
  enum class Kind : uint8_t { kHands = 0, kTrigger = 1, kStroke = 2, kSelect = 3 };
  Kind kind = Kind::kHands;
  uint64_t step = 0;                 // simulation step (before_step call) it was applied before
  std::array<HandProxy, 2> hands{};  // kHands
  std::string name;                  // kTrigger: "pinch", "cut", ...
  TriggerPhase phase = TriggerPhase::kBegin;
  int hand = 1;              // kTrigger, kSelect, kStroke
  int index = 0;             // kSelect: candidate index
  std::vector<Vec3> points;  // kStroke: predetermined cut stroke
};

struct SessionLog {
  double step_dt = 1.0 / 90;  // solver step length the session was recorded at (s)
  Cloth initial;              // cloth when recording began
  // Scene objects (the dress form is not stored: the session names none; supply it on replay).
  std::vector<Plate> plates;
  std::vector<Box> boxes;
  std::vector<Sphere> spheres;
  bool floor = true;
  double offset = 0.002;
  std::vector<SessionEvent> events;
  uint64_t final_step = 0;  // steps recorded
  uint64_t final_hash = 0;  // state_hash at final_step (0: unknown)
};

// Base64 (RFC 4648, with padding) of raw bytes; decode returns false on malformed input.
std::string base64_encode(const void* data, size_t n);
bool base64_decode(const std::string& text, std::vector<uint8_t>& out);

std::string session_to_json(const SessionLog& log);
Result<SessionLog> parse_session(const std::string& text, const std::string& source);
Result<SessionLog> load_session(const std::string& path);
// Writes the session; returns an empty string or an error message naming the file.
std::string save_session(const std::string& path, const SessionLog& log);

}  // namespace drape::sim
