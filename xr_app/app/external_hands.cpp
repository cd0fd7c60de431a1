// External hands (XrAppOptions::hands udp, trace or kinect): a tracking::HandSource polled every
// frame instead of the runtime's hands. Each hand's palm goes through tracking::HandFilter
// (One-Euro; frames below its confidence threshold count as untracked), then the calibration into
// the stage, then the palm-only gestures (palm_push, dwell); the runtime still gives the head and
// the frame loop. The source's troubles (no packets yet, dropped packets, an unreadable trace, a
// Kinect that is missing or goes away) are log lines and the feedback panel's "hands" status, never
// a failed session: a hand that stops coming is untracked after kExternalStale, and the sim holds
// its operation for its tracking grace, then ends it. With a pairing key the UDP source accepts
// signed packets only; forged and replayed ones are counted in that status.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <optional>

#include "tracking/kinect.hpp"
#include "tracking/udp_auth.hpp"
#include "xr_app/app/draping_session.hpp"

namespace drape::app {

namespace {
// A hand with no frame for this long (s, the source's clock) is untracked.
constexpr double kExternalStale = 0.3;

double steady_now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
}  // namespace

void DrapingSession::open_external_hands() {
  ext_ = std::make_unique<ExternalHands>();
  std::string where;
  if (opt_.hands == "trace") {
    auto trace = std::make_unique<tracking::TraceSource>(opt_.hands_trace);
    ext_->trace = trace.get();
    ext_->source = std::move(trace);
    where = opt_.hands_trace;
  } else if (opt_.hands == "kinect") {
    // Under fakenect (--kinect-record) the recording's directory is checked before libfreenect
    // opens it; the device otherwise.
    ext_->source = std::make_unique<tracking::KinectSource>(tracking::SegmenterParams{}, 0,
                                                            opt_.kinect_record);
    where = opt_.kinect_record.empty() ? "device 0" : "recording " + opt_.kinect_record;
  } else {
    std::optional<tracking::UdpKey> key;
    if (opt_.hands_key.size() == tracking::UdpKey().size()) {
      key.emplace();
      std::copy(opt_.hands_key.begin(), opt_.hands_key.end(), key->begin());
    }
    auto udp = std::make_unique<tracking::UdpSkeletonSource>(static_cast<uint16_t>(opt_.hands_port),
                                                             opt_.hands_address, key);
    ext_->udp = udp.get();
    ext_->source = std::move(udp);
    where = opt_.hands_address + ":" + std::to_string(opt_.hands_port) +
            (opt_.hands_key.empty() ? "" : " (signed packets only)");
  }
  rep_.note("hands: " + opt_.hands + " source " + where);
  if (!opt_.calibration_path.empty()) {
    std::string error;
    if (auto c = tracking::load_calibration(opt_.calibration_path, &error)) {
      ext_->calibration = *c;
      rep_.note("hands: calibration " + opt_.calibration_path +
                (opt_.calibration_saved ? " (the saved calibration of this source)" : ""));
      if (opt_.calibration_saved)
        feedback_.set_status("calibration", "saved one, " + opt_.calibration_path);
    } else {
      rep_.note("hands: calibration " + opt_.calibration_path + " not used (identity): " + error);
      feedback_.set_status("calibration", "calibration not loaded: " + error);
    }
  }
  if (opt_.calibrate) open_calibration_mode();
}

// The source's status into the log and the panel when it changes: a trace that does not load, a
// UDP port with no packets yet, UDP packets dropped (malformed or out of order, with the reason).
void DrapingSession::note_external_status() {
  const tracking::SourceStatus st = ext_->source->status();
  std::string shown = st.state == tracking::SourceState::Ok ? "" : st.message;
  if (ext_->udp && st.state != tracking::SourceState::Unavailable) {
    const tracking::UdpStats& s = ext_->udp->stats();
    if (s.dropped() > 0)
      shown = "udp: " + std::to_string(s.dropped()) + " packets dropped (" +
              std::to_string(s.malformed) + " malformed, " + std::to_string(s.stale) +
              " out of order" +
              (ext_->udp->authenticated() ? ", " + std::to_string(s.forged) + " forged, " +
                                                std::to_string(s.replayed) + " replayed"
                                          : "") +
              "), last: " + s.last_error;
    else if (st.state == tracking::SourceState::NoData)
      shown =
          "udp: no packets yet on " + opt_.hands_address + ":" + std::to_string(ext_->udp->port());
  }
  if (shown == ext_->status) return;
  rep_.note("hands: " + (shown.empty() ? st.message : shown));
  ext_->status = shown;
  feedback_.set_status("hands", shown);
}

void DrapingSession::read_external_hands(double t, std::array<sim::HandProxy, 2>& hands,
                                         std::vector<tracking::Trigger>& trig) {
  if (!ext_) open_external_hands();
  double now = steady_now();
  if (ext_->trace) {
    if (ext_->start < 0) ext_->start = t;
    ext_->trace->set_time(t - ext_->start);
    now = t - ext_->start;
  }
  std::vector<tracking::HandFrame> frames = ext_->source->poll();
  record_hand_frames(frames);  // --record: hands.csv (session_record.cpp)
  note_external_status();
  const bool calibrating = ext_->calibrating && !ext_->calibrating->done();
  for (auto& raw : frames) {
    const int h = static_cast<int>(raw.hand);
    const tracking::HandFrame filtered = ext_->filter[h].update(raw);
    if (calibrating) calibration_frame(raw, filtered);  // the markers' touches, no operations
    tracking::HandFrame f = ext_->calibration.apply(filtered);
    if (!calibrating) gestures_.update(f, trig);
    ext_->last[h] = f;
    ext_->last_seen[h] = now;
  }
  overlays_.clear();
  for (int h = 0; h < 2; ++h) {
    sim::HandProxy& hand = hands[h];
    hand.id = h;
    tracking::HandFrame& f = ext_->last[h];
    if (f.tracked && now - ext_->last_seen[h] >= kExternalStale) {
      f.tracked = false;  // the source stopped sending this hand: whatever it held ends
      gestures_.update(f, trig);
    }
    // While calibrating, the hands are drawn but do not touch the cloth.
    hand.tracked = f.tracked && !calibrating;
    if (!f.tracked) continue;
    hand.position = f.palm.position;
    hand.orientation = f.palm.orientation;
    hand.tip = hand.position;
    hand.radius = 0.03;
    render::HandOverlay ov;
    ov.id = h;
    ov.pointer = hand.position.cast<float>();
    ov.active = ops_busy_[h];
    overlays_.push_back(ov);
  }
}

namespace {
std::string mm(double metres) {
  char b[32];
  std::snprintf(b, sizeof b, "%.1f mm", metres * 1e3);
  return b;
}

// A marker's colour: taken (green), the one to touch (magenta), later (grey).
std::array<float, 3> marker_colour(int marker, int current) {
  if (marker < current) return {0.2f, 0.9f, 0.3f};
  if (marker == current) return {1.0f, 0.2f, 0.8f};
  return {0.45f, 0.45f, 0.5f};
}

std::string point(const tracking::Vec3& p) {
  char b[96];
  std::snprintf(b, sizeof b, "(%.4f, %.4f, %.4f)", p.x(), p.y(), p.z());
  return b;
}
}  // namespace

// --calibrate: the markers drawn, the first one asked for.
void DrapingSession::open_calibration_mode() {
  ext_->calibrating = std::make_unique<CalibrationMode>();
  rep_.note("calibration: touch the " + std::to_string(calibration_markers().size()) +
            " marked points in turn; the result goes to " + opt_.calibration_save);
  feedback_.set_status("calibration", ext_->calibrating->guidance());
  markers_.clear();
  for (size_t i = 0; i < calibration_markers().size(); ++i)
    markers_.push_back(
        {calibration_markers()[i].stage.cast<float>(), marker_colour(static_cast<int>(i), 0)});
}

// One palm frame while calibrating: the points taken, then the result computed, shown, logged
// and saved (or refused: the reason, nothing saved, the markers again from the first).
void DrapingSession::calibration_frame(const tracking::HandFrame& raw,
                                       const tracking::HandFrame& filtered) {
  CalibrationMode& cm = *ext_->calibrating;
  const auto events = cm.update(raw, filtered);
  for (const auto& e : events) {
    if (e.kind == CalibrationMode::Event::Taken) {
      rep_.note("calibration: marker " + std::to_string(e.marker + 1) + " (" +
                calibration_markers()[e.marker].name + ") taken at " + point(e.tracker) +
                " in the tracker's frame");
    } else if (e.kind == CalibrationMode::Event::Refused) {
      rep_.note("calibration: refused: " + e.message +
                "; nothing saved; touch the markers again from the first");
      feedback_.set_status("calibration", "refused (" + e.message + "), again from marker 1");
    } else {
      const tracking::Calibration& c = *cm.result();
      ext_->calibration = c;
      const std::string residual =
          "residual rms " + mm(c.rms_residual) + ", max " + mm(c.max_residual);
      std::string error;
      std::error_code ec;
      std::filesystem::create_directories(
          std::filesystem::path(opt_.calibration_save).parent_path(), ec);
      const bool saved = tracking::save_calibration(c, opt_.calibration_save, &error);
      rep_.note("calibration: " + residual + " over " + std::to_string(c.pairs) + " points; " +
                (saved ? "saved to " + opt_.calibration_save : "not saved: " + error));
      feedback_.set_status("calibration", residual + (saved ? ", saved" : ", NOT saved: " + error));
    }
  }
  if (events.empty()) return;
  if (cm.done()) {
    markers_.clear();
    return;
  }
  if (events.back().kind != CalibrationMode::Event::Refused)
    feedback_.set_status("calibration", cm.guidance());
  for (size_t i = 0; i < markers_.size(); ++i)
    markers_[i].colour = marker_colour(static_cast<int>(i), cm.current());
}

}  // namespace drape::app
