// External hands (XrAppOptions::hands udp or trace): a tracking::HandSource polled every frame
// instead of the runtime's hands. Each hand's palm goes through tracking::HandFilter (One-Euro;
// frames below its confidence threshold count as untracked), then the calibration into the stage,
// then the palm-only gestures (palm_push, dwell); the runtime still gives the head and the frame
// loop. The source's troubles (no packets yet, dropped packets, an unreadable trace) are log
// lines and the feedback panel's "hands" status, never a failed session.
#include <chrono>

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
  if (opt_.hands == "trace") {
    auto trace = std::make_unique<tracking::TraceSource>(opt_.hands_trace);
    ext_->trace = trace.get();
    ext_->source = std::move(trace);
  } else {
    auto udp = std::make_unique<tracking::UdpSkeletonSource>(static_cast<uint16_t>(opt_.hands_port),
                                                             opt_.hands_address);
    ext_->udp = udp.get();
    ext_->source = std::move(udp);
  }
  rep_.note("hands: " + opt_.hands + " source " +
            (opt_.hands == "trace" ? opt_.hands_trace
                                   : opt_.hands_address + ":" + std::to_string(opt_.hands_port)));
  if (!opt_.calibration_path.empty()) {
    std::string error;
    if (auto c = tracking::load_calibration(opt_.calibration_path, &error)) {
      ext_->calibration = *c;
      rep_.note("hands: calibration " + opt_.calibration_path);
    } else {
      rep_.note("hands: calibration " + opt_.calibration_path + " not used (identity): " + error);
      feedback_.set_status("calibration", "calibration not loaded: " + error);
    }
  }
}

// The source's status into the log and the panel when it changes: a trace that does not load, a
// UDP port with no packets yet, UDP packets dropped (malformed or out of order, with the reason).
void DrapingSession::note_external_status() {
  const tracking::SourceStatus st = ext_->source->status();
  std::string shown = st.state == tracking::SourceState::Ok ? "" : st.message;
  if (ext_->udp && st.state != tracking::SourceState::Unavailable) {
    const tracking::UdpStats& s = ext_->udp->stats();
    const uint64_t dropped = s.malformed + s.stale;
    if (dropped > 0)
      shown = "udp: " + std::to_string(dropped) + " packets dropped (" +
              std::to_string(s.malformed) + " malformed, " + std::to_string(s.stale) +
              " out of order), last: " + s.last_error;
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
  for (auto& raw : frames) {
    const int h = static_cast<int>(raw.hand);
    tracking::HandFrame f = ext_->calibration.apply(ext_->filter[h].update(raw));
    gestures_.update(f, trig);
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
    hand.tracked = f.tracked;
    if (!hand.tracked) continue;
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

}  // namespace drape::app
