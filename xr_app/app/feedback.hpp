// What the user sees in view about the session (the text panel): per hand the operation in
// progress, the last voice command heard, each refusal with its reason, lasting states (a
// missing microphone, a lost hand) and, on request, the help (every binding). Written by the
// frame loop (interaction, voice, the sim's reports as they are drained); read by the drawing of
// the same frame. Not thread-safe: the frame loop owns it.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "tracking/command_map.hpp"

namespace drape::app {

class Feedback {
 public:
  // The operation the hand (0 left, 1 right) is doing now; "" when none.
  void set_operation(int hand, const std::string& op);
  const std::string& operation(int hand) const { return op_[hand == 0 ? 0 : 1]; }
  // A voice command recognised: the phrase heard and the command it gave ("" when rejected).
  void heard(int64_t frame, const std::string& phrase, const std::string& command);
  // An operation refused, with its reason ("pinch: nothing within 3 cm to pinch"); shown for a
  // few seconds.
  void refused(int64_t frame, const std::string& reason);
  // A state that lasts until cleared (key: "voice", "hands", ...; "" message clears it).
  void set_status(const std::string& key, const std::string& message);
  // The help: a line per operation with its bindings (set once from the command map).
  void set_help(std::vector<std::string> lines) { help_ = std::move(lines); }
  void toggle_help();
  void show_help(bool on);
  bool help_shown() const { return show_help_; }
  // The help also shows before `frame` (the first seconds of a live session).
  void show_help_until(int64_t frame);

  // The panel's lines at `frame` (90 frames a second): statuses, the hands, the voice, the
  // refusals of the last kRefusalFrames frames, then the help when shown.
  std::vector<std::string> lines(int64_t frame) const;
  // Bumped on every change, so a renderer rebuilds its text only when it changed.
  uint64_t version() const { return version_; }
  // Changes whenever lines(frame) may differ from the last frame's: version() and what the
  // frame itself changes (refusals expired, the first seconds' help over).
  uint64_t shown_version(int64_t frame) const;

  static constexpr int64_t kRefusalFrames = 4 * 90;
  static constexpr size_t kMaxRefusals = 3;

 private:
  struct Refusal {
    int64_t frame;
    std::string text;
  };
  std::string op_[2];
  std::string heard_;
  int64_t heard_frame_ = -1;
  std::vector<Refusal> refusals_;
  std::map<std::string, std::string> status_;
  std::vector<std::string> help_;
  bool show_help_ = false;
  int64_t help_until_ = -1;
  uint64_t version_ = 0;
};

// How the help names a binding's input: its label (else source and command), with its hand.
std::string help_label(const tracking::Binding& b);
// The help: a title and one line per operation with its gestures, buttons and phrase.
std::vector<std::string> help_lines(const tracking::CommandMap& map);

}  // namespace drape::app
