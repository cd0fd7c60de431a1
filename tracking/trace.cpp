#include "tracking/trace.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

namespace drape::tracking {

TraceRecorder::TraceRecorder(const std::string& path) : out_(path) {
  if (out_) out_ << "# drape-trace v1\n";
}

void TraceRecorder::write(const HandFrame& f) {
  char buf[96];
  auto num = [&](double v) {
    std::snprintf(buf, sizeof buf, ",%.9g", v);
    out_ << buf;
  };
  std::snprintf(buf, sizeof buf, "%.9f", f.time);
  out_ << buf << ',' << static_cast<int>(f.hand) << ',' << (f.tracked ? 1 : 0);
  num(f.confidence);
  for (int k = 0; k < 3; ++k) num(f.palm.position(k));
  const Quat& q = f.palm.orientation;
  for (double v : {q.x(), q.y(), q.z(), q.w()}) num(v);
  out_ << ',' << (f.has_joints ? 1 : 0);
  if (f.has_joints)
    for (const auto& j : f.joints)
      for (int k = 0; k < 3; ++k) num(j(k));
  out_ << '\n';
}

std::optional<std::vector<HandFrame>> read_trace(const std::string& path, std::string* error) {
  auto fail = [&](const std::string& m) -> std::optional<std::vector<HandFrame>> {
    if (error) *error = m;
    return std::nullopt;
  };
  std::ifstream in(path);
  if (!in) return fail(path + ": cannot open");
  std::string line;
  if (!std::getline(in, line) || line.rfind("# drape-trace v1", 0) != 0)
    return fail(path + ":1: missing header '# drape-trace v1'");
  std::vector<HandFrame> frames;
  int ln = 1;
  while (std::getline(in, line)) {
    ++ln;
    if (line.empty() || line[0] == '#') continue;
    std::vector<double> v;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) {
      try {
        size_t used = 0;
        v.push_back(std::stod(cell, &used));
        if (used != cell.size()) throw std::invalid_argument("junk");
      } catch (const std::exception&) {
        return fail(path + ":" + std::to_string(ln) + ": not a number: '" + cell + "'");
      }
    }
    const std::string where = path + ":" + std::to_string(ln) + ": ";
    if (v.size() != 12 && v.size() != 12 + 3 * kJointCount)
      return fail(where + "expected 12 or 90 fields, got " + std::to_string(v.size()));
    HandFrame f;
    f.time = v[0];
    if (v[1] != 0 && v[1] != 1) return fail(where + "field 'hand' must be 0 or 1");
    f.hand = static_cast<Hand>(static_cast<int>(v[1]));
    f.tracked = v[2] != 0;
    f.confidence = v[3];
    f.palm.position = Vec3(v[4], v[5], v[6]);
    f.palm.orientation = Quat(v[10], v[7], v[8], v[9]);
    f.has_joints = v[11] != 0;
    if (f.has_joints != (v.size() > 12)) return fail(where + "has_joints disagrees with fields");
    for (int j = 0; f.has_joints && j < kJointCount; ++j)
      f.joints[j] = Vec3(v[12 + 3 * j], v[13 + 3 * j], v[14 + 3 * j]);
    if (!std::isfinite(f.time) || !f.palm.position.allFinite())
      return fail(where + "non-finite time or position");
    if (!frames.empty() && f.time < frames.back().time) return fail(where + "time goes backwards");
    frames.push_back(f);
  }
  return frames;
}

TraceSource::TraceSource(const std::string& path) {
  auto r = read_trace(path, &error_);
  if (r) frames_ = std::move(*r);
}

std::vector<HandFrame> TraceSource::poll() {
  std::vector<HandFrame> out;
  if (frames_.empty()) return out;
  const double t0 = frames_.front().time;
  while (next_ < frames_.size() && frames_[next_].time - t0 <= clock_ + 1e-9)
    out.push_back(frames_[next_++]);
  return out;
}

SourceStatus TraceSource::status() const {
  if (!error_.empty()) return {SourceState::Error, error_};
  if (frames_.empty()) return {SourceState::NoData, "trace: empty"};
  return {SourceState::Ok, "trace: " + std::to_string(next_) + "/" +
                               std::to_string(frames_.size()) + " frames played"};
}

}  // namespace drape::tracking
