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

std::vector<std::string> Feedback::lines(int64_t frame) const {
  std::vector<std::string> out;
  for (const auto& [key, msg] : status_) out.push_back(key + ": " + msg);
  static const char* kHand[2] = {"left", "right"};
  for (int h = 0; h < 2; ++h)
    out.push_back(std::string(kHand[h]) + " hand: " + (op_[h].empty() ? "-" : op_[h]));
  if (!heard_.empty()) out.push_back("voice: " + heard_);
  for (const auto& r : refusals_)
    if (frame - r.frame < kRefusalFrames) out.push_back(r.text);
  if (show_help_) {
    out.push_back("");
    for (const auto& l : help_) out.push_back(l);
  }
  return out;
}

}  // namespace drape::app
