// Recorded traces: record HandFrames to CSV and replay them as a HandSource.
// Format (docs/tracking.md): first line "# drape-trace v1", then one line per frame:
//   time,hand,tracked,confidence,px,py,pz,qx,qy,qz,qw,has_joints[,j0x,j0y,j0z ... j25z]
#pragma once
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include "tracking/hand_source.hpp"

namespace drape::tracking {

class TraceRecorder {
 public:
  explicit TraceRecorder(const std::string& path);
  bool ok() const { return static_cast<bool>(out_); }
  void write(const HandFrame& f);

 private:
  std::ofstream out_;
};

// Whole-file reader; error names the file and line.
std::optional<std::vector<HandFrame>> read_trace(const std::string& path, std::string* error);

class TraceSource : public HandSource {
 public:
  explicit TraceSource(const std::string& path);
  std::string name() const override { return "trace"; }
  // Frames with time <= the playback clock (trace time 0 = first frame) since the last poll.
  std::vector<HandFrame> poll() override;
  void set_time(double t) { clock_ = t; }  // playback position, seconds from first frame
  bool finished() const { return next_ >= frames_.size(); }
  SourceStatus status() const override;

 private:
  std::vector<HandFrame> frames_;
  std::string error_;
  size_t next_ = 0;
  double clock_ = 0;
};

}  // namespace drape::tracking
