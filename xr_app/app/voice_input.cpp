// The live voice input of a draping session (see voice_input.hpp).
#include "xr_app/app/voice_input.hpp"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <thread>

namespace drape::app {

namespace {
double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// Wraps the microphone or the recording: never delivers audio faster than real time (a WAV file
// reads at disk speed, and an ALSA device with no clock of its own, such as the `null` slave of
// the `file` plugin, returns at once), and records when each block was read.
class ClockedInput : public tracking::AudioInput {
 public:
  ClockedInput(std::unique_ptr<tracking::AudioInput> in, std::shared_ptr<AudioClock> clock)
      : in_(std::move(in)), clock_(std::move(clock)) {}
  bool ok() const override { return in_->ok(); }
  std::string error() const override { return in_->error(); }
  long read(int16_t* buf, long n) override {
    // A device that reports samples without writing them gives silence, not the last block again.
    std::memset(buf, 0, static_cast<size_t>(n) * sizeof(int16_t));
    if (t0_ < 0) t0_ = now_s();  // the capture starts with the first read
    const long got = in_->read(buf, n);
    if (got <= 0) return got;
    total_ += got;
    const double wait = t0_ + static_cast<double>(total_) / tracking::kVoiceRate - now_s();
    if (wait > 0) std::this_thread::sleep_for(std::chrono::duration<double>(wait));
    clock_->read(total_, now_s());
    return got;
  }

 private:
  std::unique_ptr<tracking::AudioInput> in_;
  std::shared_ptr<AudioClock> clock_;
  double t0_ = -1;
  long total_ = 0;
};

// The source's status message without its "voice: " prefix.
std::string plain(const std::string& message) {
  const std::string prefix = "voice: ";
  return message.rfind(prefix, 0) == 0 ? message.substr(prefix.size()) : message;
}
}  // namespace

void AudioClock::read(long samples_total, double when) {
  std::lock_guard lock(m_);
  reads_.emplace_back(samples_total, when);
  // About a minute of 50 ms blocks: an utterance is decoded seconds after it ends at most.
  if (reads_.size() > 1200) reads_.pop_front();
}

double AudioClock::time_of(long sample) const {
  std::lock_guard lock(m_);
  auto it = std::lower_bound(reads_.begin(), reads_.end(), sample,
                             [](const std::pair<long, double>& r, long s) { return r.first < s; });
  return it == reads_.end() ? -1.0 : it->second;
}

VoiceInput::VoiceInput(const std::string& spec)
    : VoiceInput(spec == "mic" ? "microphone (ALSA 'default')" : "recording '" + spec + "'",
                 spec == "mic" ? tracking::open_alsa_input("default")
                               : tracking::open_wav_input(spec, false)) {}  // ClockedInput paces

VoiceInput::VoiceInput(std::string name, std::unique_ptr<tracking::AudioInput> input)
    : name_(std::move(name)) {
  source_ = std::make_unique<tracking::VoiceSource>(
      tracking::VoiceConfig{}, std::make_unique<ClockedInput>(std::move(input), clock_));
}

VoiceInput::~VoiceInput() = default;

int64_t VoiceInput::frame_at(double when) const {
  int64_t frame = -1;
  for (const auto& [f, t] : frames_)
    if (t <= when) frame = f;
  return frame;
}

std::vector<VoiceInput::Heard> VoiceInput::poll(int64_t frame) {
  const double now = now_s();
  frames_.emplace_back(frame, now);
  while (frames_.size() > 2 && frames_.front().second < now - 60.0) frames_.pop_front();
  // The events carry every utterance with its command; the source's trigger queue holds the
  // accepted ones again and is drained so that it does not grow.
  source_->take_triggers();
  std::vector<Heard> out;
  for (auto& ev : source_->take_events()) {
    Heard h;
    h.result = std::move(ev.result);
    h.vad_decode_ms = ev.latency_ms;
    const double end = clock_->time_of(ev.speech_end);
    if (end >= 0) {
      h.latency_ms = (now - end) * 1e3;
      h.speech_end_frame = frame_at(end);
      if (h.speech_end_frame >= 0) h.latency_frames = static_cast<int>(frame - h.speech_end_frame);
    }
    out.push_back(std::move(h));
  }
  return out;
}

std::optional<std::string> VoiceInput::status_change() {
  const tracking::SourceStatus st = source_->status();
  std::string msg;
  switch (st.state) {
    case tracking::SourceState::Ok:
      msg = "";
      break;
    case tracking::SourceState::NoData:
      if (st.message == "voice: starting") return std::nullopt;
      msg = name_ + ": ended (" + plain(st.message) + "); voice commands are off";
      break;
    case tracking::SourceState::Unavailable:
    case tracking::SourceState::Error:
      msg = plain(st.message) + "; voice commands are off, the session goes on";
      break;
  }
  if (msg == last_status_) return std::nullopt;
  last_status_ = msg;
  return msg;
}

}  // namespace drape::app
