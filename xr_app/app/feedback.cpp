// The in-view feedback's content (see feedback.hpp).
#include "xr_app/app/feedback.hpp"

namespace drape::app {

void Feedback::set_operation(int hand, const std::string& op) {
  if (hand < 0 || hand > 1 || op_[hand] == op) return;
  op_[hand] = op;
  ++version_;
}

void Feedback::heard(int64_t frame, const std::string& phrase, const std::string& command) {
  heard_ = command.empty() ? "heard \"" + phrase + "\": not a command"
                           : "heard \"" + phrase + "\" -> " + command;
  heard_frame_ = frame;
  ++version_;
}

void Feedback::refused(int64_t frame, const std::string& reason) {
  refusals_.push_back({frame, reason});
  if (refusals_.size() > kMaxRefusals) refusals_.erase(refusals_.begin());
  ++version_;
}

void Feedback::set_status(const std::string& key, const std::string& message) {
  auto it = status_.find(key);
  if (message.empty()) {
    if (it == status_.end()) return;
    status_.erase(it);
  } else {
    if (it != status_.end() && it->second == message) return;
    status_[key] = message;
  }
  ++version_;
}

void Feedback::toggle_help() {
  show_help_ = !show_help_;
  ++version_;
}

void Feedback::show_help(bool on) {
  if (show_help_ == on) return;
  show_help_ = on;
  ++version_;
}

void Feedback::show_help_until(int64_t frame) {
  help_until_ = frame;
  ++version_;
}

uint64_t Feedback::shown_version(int64_t frame) const {
  uint64_t expired = 0;
  for (const auto& r : refusals_) expired += frame - r.frame >= kRefusalFrames;
  const uint64_t intro = frame < help_until_ ? 1 : 0;
  static_assert(kMaxRefusals <= 3, "the expired count takes two bits");
  return (version_ << 3) | (expired << 1) | intro;
}

std::vector<std::string> Feedback::lines(int64_t frame) const {
  std::vector<std::string> out;
  for (const auto& [key, msg] : status_) out.push_back(key + ": " + msg);
  static const char* kHand[2] = {"left", "right"};
  for (int h = 0; h < 2; ++h)
    out.push_back(std::string(kHand[h]) + " hand: " + (op_[h].empty() ? "-" : op_[h]));
  if (!heard_.empty()) out.push_back("voice: " + heard_);
  for (const auto& r : refusals_)
    if (frame - r.frame < kRefusalFrames) out.push_back(r.text);
  if (show_help_ || frame < help_until_) {
    out.push_back("");
    for (const auto& l : help_) out.push_back(l);
  }
  return out;
}

std::string help_label(const tracking::Binding& b) {
  std::string label = b.label.empty() ? b.source + " " + b.command : b.label;
  if (!b.hand.empty()) label = b.hand + ": " + label;
  return label;
}

// One line per operation: its gestures (the hand where it matters), the controller inputs every
// profile shares, its phrase ("pin: right: thumb-middle pinch | thumbstick up | "pin here"").
// The end of a held input is its begin's ("(held)" in the label); per-profile variants and the
// palm-only trackers' gestures are in commands.json and `drape run --help`.
std::vector<std::string> help_lines(const tracking::CommandMap& map) {
  static const char* kOps[] = {"pinch", "move",    "pin",     "release", "cut",
                               "map",   "smooth",  "next",    "undo",    "redo",
                               "stop",  "pattern", "colours", "save",    "help"};
  std::vector<std::string> out{"help: each operation's gesture | buttons | phrase"};
  for (const char* op : kOps) {
    std::string by[3];  // gesture, controller, voice
    for (const auto& b : map.bindings()) {
      const std::string name = b.action.operation == "*" ? "stop" : b.action.operation;
      if (name != op || b.edge == "end" || !b.profile.empty()) continue;
      if (b.command == "palm_push" || b.command == "dwell") continue;  // palm-only trackers
      const int k = b.source == "gesture" ? 0 : b.source == "controller" ? 1 : 2;
      by[k] += (by[k].empty() ? "" : ", ") + help_label(b);
    }
    std::string line = std::string(op) + ":";
    for (int k = 0; k < 3; ++k) line += (k ? " | " : " ") + (by[k].empty() ? "-" : by[k]);
    out.push_back(line);
  }
  return out;
}

}  // namespace drape::app
